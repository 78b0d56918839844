#!/usr/bin/env bash
# Fuzzes attsync's inputs from elsewhere (docs/fuzzing.md): installs
# cargo-fuzz if absent, builds every target of fuzz/ once, runs each for
# SECONDS (default 60) from its committed corpus (fuzz/corpus/<target>/,
# read only: new inputs go to a scratch directory), and prints per target
# the inputs executed and the result. Exits non-zero on any crash (a
# panic, an abort, an allocation over fuzz's MAX_ALLOCATION), timeout
# (an input over 10 s) or out-of-memory (RSS over 2 GiB).
#
# Usage: tools/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_EACH=${1:-60}
shift || true
# cargo-fuzz and libfuzzer-sys (fuzz/Cargo.toml) are pinned.
CARGO_FUZZ_VERSION=0.13.1
# Longest input: the largest seed (tree-30.toml, 23 KB) with room to grow.
MAX_LEN=${FUZZ_MAX_LEN:-32768}
# cargo fuzz passes nightly-only flags (-Zsanitizer, -Cpasses=sancov-module…):
# this machine has stable Rust only.
export RUSTC_BOOTSTRAP=1
export CARGO_TERM_COLOR=never
# Rust is memory-safe: no sanitizer (we look for panics, hangs and unbounded
# allocations); release with debug assertions (overflow checks on).
FLAGS=(--sanitizer none --release --debug-assertions)

if ! cargo fuzz --version 2>/dev/null | grep -qF "$CARGO_FUZZ_VERSION"; then
    echo "== installing cargo-fuzz $CARGO_FUZZ_VERSION"
    cargo install cargo-fuzz --version "$CARGO_FUZZ_VERSION" --locked
fi

cd fuzz
echo "== building the fuzz targets"
built=$(date +%s)
cargo fuzz build "${FLAGS[@]}"
echo "built in $(($(date +%s) - built)) s"
if [ $# -gt 0 ]; then targets=("$@"); else mapfile -t targets < <(cargo fuzz list); fi

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
failed=0
passed=0
printf '%-14s %12s %8s %8s %9s  %s\n' target executions seconds corpus peak_rss result
for t in "${targets[@]}"; do
    mkdir -p "$scratch/$t" artifacts logs
    log="logs/$t.log"
    start=$(date +%s)
    set +e
    cargo fuzz run "${FLAGS[@]}" "$t" "$scratch/$t" "corpus/$t" -- \
        -max_total_time="$SECONDS_EACH" -rss_limit_mb=2048 -timeout=10 \
        -max_len="$MAX_LEN" -print_final_stats=1 >"$log" 2>&1
    rc=$?
    set -e
    took=$(($(date +%s) - start))
    execs=$(awk '/stat::number_of_executed_units/ {print $2}' "$log" | tail -1)
    rss=$(awk '/stat::peak_rss_mb/ {print $2}' "$log" | tail -1)
    units=$(grep -oE 'corp: [0-9]+/[0-9]+[a-zA-Z]*' "$log" | tail -1 | cut -d' ' -f2)
    if [ "$rc" -eq 0 ]; then
        result=ok
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
        result=$(grep -oE 'ERROR: libFuzzer: [a-z-]+|panicked at [^ ]+' "$log" | head -1)
        result="FAILED (${result:-exit $rc}; see fuzz/$log, fuzz/artifacts/$t/)"
    fi
    printf '%-14s %12s %8s %8s %9s  %s\n' "$t" "${execs:-?}" "$took" "${units:-?}" "${rss:-?}MB" "$result"
    if [ "$rc" -ne 0 ]; then grep -v '^Output of\|^\s*\[' "$log" | tail -30 | cut -c1-300; fi
done
echo "fuzz: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
