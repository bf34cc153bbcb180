#!/bin/sh
# Shell-model benchmark (the eggshell preset, Gingold et al. discrete shells): whole runs at the
# preset's default mesh and at larger ones (wall and CPU time, peak memory, fractures, and the
# model's own account of where the time goes: assembly, factorization, local relaxations).
# usage: bench/shell.sh BUILD_DIR [SIZES]   (SIZES: mesh.elements = triangles, default "default 20000")
set -eu
build=${1:?usage: shell.sh BUILD_DIR [SIZES]}
sizes=${2:-"default 20000"}
src=$(cd "$(dirname "$0")/.." && pwd)
preset="$src/presets/eggshell.ini"
out=$(mktemp -d "${TMPDIR:-/tmp}/fissure-bench.XXXXXX")
trap 'rm -rf "$out"' EXIT
echo "# $(uname -m), $(getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?') processors, $(date -u +%Y-%m-%dT%H:%MZ)"
timer=
[ -x /usr/bin/time ] && timer="/usr/bin/time -f %U+%S+%M -o"
for n in $sizes; do
    set --
    [ "$n" = default ] || set -- --set mesh.elements="$n"
    start=$(date +%s.%N)
    ${timer:+$timer "$out/cpu"} "$build/fissure" -v -o "$out/run" --size 512x256 "$@" "$preset" 2>"$out/log" >/dev/null
    end=$(date +%s.%N)
    wall=$(awk "BEGIN { print $end - $start }")
    cpu=0 mb=0
    if [ -n "$timer" ]; then
        cpu=$(awk -F+ 'END { print $1 + $2 }' "$out/cpu")
        mb=$(awk -F+ 'END { printf "%.0f", $3 / 1024 }' "$out/cpu")
    fi
    tris=$(sed -n 's/^fissure: meshed [0-9]* nodes, \([0-9]*\) triangles.*/\1/p' "$out/log")
    printf 'eggshell %s elements (%s triangles): %6.1f s wall %6.1f s cpu, peak %s MB\n' "$n" "$tris" "$wall" "$cpu" "$mb"
    sed -n 's/^fissure: shell: /    /p' "$out/log"
done
