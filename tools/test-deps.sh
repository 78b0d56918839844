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
# apt_install PACKAGE WHY COMMAND…: installs Debian's PACKAGE (as root, with
# apt) unless every COMMAND is there already; otherwise says WHY it is needed.
apt_install() {
    local package=$1 why=$2
    shift 2
    local c missing=
    for c in "$@"; do
        command -v "$c" >/dev/null 2>&1 || missing=1
    done
    [ -z "$missing" ] && return 0
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        apt-get update -qq >/dev/null
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$package" >/dev/null
    else
        echo "tools/test-deps.sh: $* missing ($why): install Debian's package '$package' as root" >&2
        exit 1
    fi
}
apt_install chromium "the browser test needs /usr/bin/chromium" chromium
apt_install iproute2 "the network namespace tests need them" ip tc
