#!/usr/bin/env bash
# What the test suite needs besides cargo, installed if missing:
# - Python packages pinned in examples/python/requirements.txt (the Python
#   example agent's iceoryx2) and tests/requirements.txt (independent readers
#   of attsync's outputs), from PyPI;
# - Chromium (Debian's package `chromium`) for the browser test of view.html,
#   through apt when running as root;
# - `ip` and `tc` (Debian's package `iproute2`) for the tests across hosts in
#   network namespaces of their own (tests/tests/hosts_netem.rs).
# Safe to run again: it installs only what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
for req in examples/python/requirements.txt tests/requirements.txt; do
    if [ -f "$req" ]; then
        python3 -m pip install -q -r "$req"
    fi
done
if ! command -v chromium >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        apt-get update -qq >/dev/null
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
    else
        echo "tools/test-deps.sh: Chromium is missing (the browser test needs /usr/bin/chromium): install Debian's package 'chromium' as root" >&2
        exit 1
    fi
fi
if ! command -v ip >/dev/null 2>&1 || ! command -v tc >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        apt-get update -qq >/dev/null
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq iproute2 >/dev/null
    else
        echo "tools/test-deps.sh: ip/tc are missing (the network namespace tests need them): install Debian's package 'iproute2' as root" >&2
        exit 1
    fi
fi
