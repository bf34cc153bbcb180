#!/bin/sh
# Element-splitting benchmark (the mud preset, thesis §5.7-5.8): whole runs at 10k and 40k elements
# (wall and CPU time, fracture events per second, where the time goes), then the mean cost of one
# fracture event relaxed locally against one relaxed by a global solve (bench_split).
# With THESIS=1 in the environment each size also runs the thesis's algorithm in the same binary
# (conjugate gradients, a global solve after every event: solver.method=cg, solver.relax=global) and
# prints the whole-run wall-time ratio of the two; at 40k elements that run takes about 8 minutes.
# usage: bench/split.sh BUILD_DIR [SIZES]   (SIZES defaults to "10000 40000")
set -eu
build=${1:?usage: split.sh BUILD_DIR [SIZES]}
sizes=${2:-"10000 40000"}
src=$(cd "$(dirname "$0")/.." && pwd)
preset="$src/presets/mud.ini"
out=$(mktemp -d "${TMPDIR:-/tmp}/fissure-bench.XXXXXX")
trap 'rm -rf "$out"' EXIT
# One BLAS thread: the factorizations here are small, and spinning BLAS threads only burn CPU.
OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
export OPENBLAS_NUM_THREADS
echo "# $(uname -m), $(getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?') processors, $(date -u +%Y-%m-%dT%H:%MZ)"
timer=
[ -x /usr/bin/time ] && timer="/usr/bin/time -f %U+%S -o"
# run LABEL N [OPTIONS...]: one whole run of the mud preset at N elements; prints its figures and
# leaves its wall seconds in $wall.
run() {
    label=$1 n=$2
    shift 2
    start=$(date +%s.%N)
    ${timer:+$timer "$out/cpu"} "$build/fissure" -v -o "$out/run" --maps height --set mesh.elements="$n" "$@" \
        "$preset" 2>"$out/log" >/dev/null
    end=$(date +%s.%N)
    wall=$(awk "BEGIN { print $end - $start }")
    cpu=$([ -n "$timer" ] && awk -F+ 'END { print $1 + $2 }' "$out/cpu" || echo 0)
    splits=$(sed -n 's/^fissure: wedge: \([0-9]*\) splits.*/\1/p' "$out/log")
    printf 'mud %6d elements%s: %6.1f s wall %6.1f s cpu, %5d splits, %6.1f events/s\n' "$n" "$label" "$wall" \
        "$cpu" "$splits" "$(awk "BEGIN { print $splits / $wall }")"
    sed -n 's/^fissure: wedge: /    /p' "$out/log"
}
for n in $sizes; do
    run "" "$n"
    if [ "${THESIS:-0}" = 1 ]; then
        ours=$wall
        run " (thesis: cg, global)" "$n" --set solver.method=cg --set solver.relax=global
        printf 'mud %6d elements: the thesis algorithm / this one: %.1fx wall\n' "$n" \
            "$(awk "BEGIN { print $wall / $ours }")"
    fi
done
for n in $sizes; do
    "$build/bench/bench_split" "$preset" "$n"
done
