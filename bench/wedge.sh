#!/bin/sh
# Wedge model benchmark: equilibrium costs at 10k, 50k and 200k elements (bench_wedge, with the cost
# per fracture event of local versus global relaxation), then whole runs of the mud-remove preset
# with CHOLMOD and with the CG baseline, each with global relaxation (CHOLMOD: factor reuse and
# updates) and with local relaxation (thesis §5.8), and the CG / CHOLMOD ratio of the global runs.
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
# Whole runs: wall seconds, and CPU seconds (user + system, all threads) where /usr/bin/time exists;
# the issue's figure is the ratio of the CG baseline to CHOLMOD, both with global relaxation.
timer=
[ -x /usr/bin/time ] && timer="/usr/bin/time -f %U+%S -o"
for run in cholmod:global cg:global cholmod:local cg:local; do
    method=${run%:*} relax=${run#*:} name=$method-$relax
    start=$(date +%s.%N)
    ${timer:+$timer "$out/$name.cpu"} "$build/fissure" -v -o "$out/$name" --size 256x256 \
        --set solver.method=$method --set solver.relax=$relax "$src/presets/mud-remove.ini" \
        2>"$out/$name.log" >/dev/null
    end=$(date +%s.%N)
    wall=$(awk "BEGIN { print $end - $start }")
    cpu=$( [ -n "$timer" ] && awk -F+ 'END { print $1 + $2 }' "$out/$name.cpu" || echo 0)
    echo "$wall $cpu" >"$out/$name.times"
    printf 'mud-remove %-8s %-6s %7.1f s wall %7.1f s cpu  %s\n' "$method" "$relax" "$wall" "$cpu" \
        "$(sed -n 's/^fissure: wedge: \([0-9]* removals\)/\1/p' "$out/$name.log")"
done
read -r chol_wall chol_cpu <"$out/cholmod-global.times"
read -r cg_wall cg_cpu <"$out/cg-global.times"
printf 'mud-remove CG / CHOLMOD (global relaxation): %.2fx wall, %.2fx cpu\n' \
    "$(awk "BEGIN { print $cg_wall / $chol_wall }")" \
    "$(awk "BEGIN { print ($chol_cpu > 0 ? $cg_cpu / $chol_cpu : 0) }")"
