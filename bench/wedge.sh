#!/bin/sh
# Wedge model benchmark: equilibrium costs at 10k, 50k and 200k elements (bench_wedge), then whole
# runs of the mud-remove preset with CHOLMOD (factor reuse and updates) and with the CG baseline.
# usage: bench/wedge.sh BUILD_DIR [SIZES]   (SIZES defaults to "10000 50000 200000")
set -eu
build=${1:?usage: wedge.sh BUILD_DIR [SIZES]}
sizes=${2:-"10000 50000 200000"}
src=$(cd "$(dirname "$0")/.." && pwd)
for n in $sizes; do
    "$build/bench/bench_wedge" "$n" periodic
done
out=$(mktemp -d "${TMPDIR:-/tmp}/fissure-bench.XXXXXX")
trap 'rm -rf "$out"' EXIT
for method in cholmod cg; do
    start=$(date +%s.%N)
    "$build/fissure" -v -o "$out/$method" --size 256x256 --set solver.method=$method \
        "$src/presets/mud-remove.ini" 2>"$out/$method.log" >/dev/null
    end=$(date +%s.%N)
    printf 'mud-remove %-8s %7.1f s  %s\n' "$method" "$(awk "BEGIN { print $end - $start }")" \
        "$(sed -n 's/^fissure: wedge: //p' "$out/$method.log")"
done
