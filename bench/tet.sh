#!/bin/sh
# Tetrahedral-model benchmark (the mud-thick preset, O'Brien & Hodgins fracture of a thick layer):
# whole runs at the preset's default size and any further sizes (wall and CPU time, fracture
# events, where the time goes), then the mean cost of one fracture event (its local relaxation and
# the event searches it starts) against one global solve of the whole layer (assembly and CHOLMOD
# factorization and solve, which the model does once per run).
# usage: bench/tet.sh BUILD_DIR [SIZES]   (SIZES: mesh.elements, default: the preset's own)
set -eu
build=${1:?usage: tet.sh BUILD_DIR [SIZES]}
sizes=${2:-default}
src=$(cd "$(dirname "$0")/.." && pwd)
preset="$src/presets/mud-thick.ini"
out=$(mktemp -d "${TMPDIR:-/tmp}/fissure-bench.XXXXXX")
trap 'rm -rf "$out"' EXIT
echo "# $(uname -m), $(getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?') processors, $(date -u +%Y-%m-%dT%H:%MZ)"
timer=
[ -x /usr/bin/time ] && timer="/usr/bin/time -f %U+%S -o"
for n in $sizes; do
    set --
    [ "$n" = default ] || set -- --set mesh.elements="$n"
    start=$(date +%s.%N)
    ${timer:+$timer "$out/cpu"} "$build/fissure" -v -o "$out/run" "$@" "$preset" 2>"$out/log" >/dev/null
    end=$(date +%s.%N)
    wall=$(awk "BEGIN { print $end - $start }")
    cpu=$([ -n "$timer" ] && awk -F+ 'END { print $1 + $2 }' "$out/cpu" || echo 0)
    printf 'mud-thick %s elements: %6.1f s wall %6.1f s cpu\n' "$n" "$wall" "$cpu"
    sed -n 's/^fissure: tet: /    /p' "$out/log"
    # one event: its local solve and searches; one global solve: factor and solve of every unknown
    awk '
        / splits \(/ { for (i = 1; i <= NF; i++) if ($i == "splits" || $i == "bonds") events += $(i - 1) }
        /local solves/ { for (i = 1; i <= NF; i++) if ($i == "local" && $(i + 1) == "solves") { local = $(i - 1) }
                         for (i = 1; i <= NF; i++) if ($i == "global" && i == NF) { glob = $(i - 1) } }
        /seconds: set-up/ { for (i = 1; i <= NF; i++) { if ($i == "global") gs = $(i + 2); if ($i == "local") ls = $(i + 2); if ($i == "searches") ss = $(i + 1) } }
        END {
            gsub(",", "", gs); gsub(",", "", ls); gsub(",", "", ss)
            if (events > 0 && glob > 0)
                printf "    per event %.4f s (%d events: local solves %.1f s, searches %.1f s); per global solve %.4f s (%d)\n",
                       (ls + ss) / events, events, ls, ss, gs / glob, glob
        }' "$out/log"
done
