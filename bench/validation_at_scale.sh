#!/usr/bin/env bash
# Validation at scale (BENCHMARKS.md "Validation at scale"): wall time, CPU
# time and peak RSS of `attsync gen tree` and `attsync check` on random trees
# of 10², 10³, 10⁴, 10⁵ agents (seed 1, one leader link, --duration 40 as
# in session 5: without it a deep tree's horizon is clamped to the 2⁴⁰-step
# limit, which changes nothing `check` does), every scheme, as a Markdown
# table on stdout. Usage: bench/validation_at_scale.sh [ATTSYNC] [N…]
# (default: target/release/attsync, 100 1000 10000 100000). One run each.
set -euo pipefail
bin=$(realpath "${1:-target/release/attsync}")
shift || true
sizes=("${@:-100 1000 10000 100000}")
read -r -a sizes <<<"${sizes[*]}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Runs "$@" under /usr/bin/time -v; prints "wall s | CPU s | peak RSS MiB".
measure() {
    /usr/bin/time -v -o "$work/time" "$@" >"$work/stdout" 2>"$work/stderr"
    awk -F': ' '
        /Elapsed \(wall clock\)/ { n = split($2, t, ":"); w = 0; for (i = 1; i <= n; i++) w = w * 60 + t[i] }
        /User time/ { u = $2 } /System time/ { s = $2 } /Maximum resident/ { m = $2 }
        END { printf "%.2f | %.2f | %.0f", w, u + s, m / 1024 }' "$work/time"
}

echo "| agents | scheme | step | wall s | CPU s | peak RSS MiB | TOML MiB |"
echo "|---:|---|---|---:|---:|---:|---:|"
for n in "${sizes[@]}"; do
    for scheme in observer-time-varying observer-constant observerless; do
        f="$work/tree-$n-$scheme.toml"
        g=$(measure "$bin" gen tree --agents "$n" --seed 1 --scheme "$scheme" --duration 40 --out "$f")
        size=$(awk -v b="$(stat -c %s "$f")" 'BEGIN { printf "%.1f", b / 1048576 }')
        echo "| $n | $scheme | gen tree | $g | $size |"
        c=$(measure "$bin" check "$f")
        grep -a "eigenvalues in\|gain condition" "$work/stdout" | sed 's/^/<!-- /; s/$/ -->/' >&2
        echo "| $n | $scheme | check | $c | |"
    done
done
