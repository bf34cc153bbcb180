#!/bin/sh
# The look of the cracks, preset by preset (issue: crack appearance at full resolution): each preset
# named is run at its defaults and again with SET (default: fracture.direction_radius=0, the
# per-element tip directions), and a table gives for both the staircase (tests/crack_paths.py: a
# crack's length over its length sampled every 40 px, median over the cracks of 160 px or more, and
# how many), the crack graph's fragments, the crack mask's cover and the pieces of the mask under
# half intensity that join two fragments (tests/crack_stats pieces).
# usage: bench/cracks.sh FISSURE OUT_DIR PRESET...   (run from a built tree: it uses tests/crack_stats)
#   environment: SET another --set assignment for the second run; FISSURE_ARGS extra options for
#   every run (e.g. "--size 4096x4096" for presets whose cells are small at 1024)
set -eu
fissure=${1:?usage: cracks.sh FISSURE OUT_DIR PRESET...}
out=${2:?usage: cracks.sh FISSURE OUT_DIR PRESET...}
shift 2
src=$(cd "$(dirname "$0")/.." && pwd)
stats="$(dirname "$fissure")/tests/crack_stats"
set_other=${SET:-fracture.direction_radius=0}
mkdir -p "$out"
echo "# $(date -u +%Y-%m-%dT%H:%MZ), $fissure ${FISSURE_ARGS:-}; second row of each preset: --set $set_other"
printf '%-22s %-8s %10s %6s %9s %7s %6s\n' preset run staircase cracks fragments cover joined
for p in "$@"; do
    for run in default other; do
        d="$out/$p-$run"
        rm -rf "$d"
        extra=
        [ "$run" = other ] && extra="--set $set_other"
        # shellcheck disable=SC2086
        if ! "$fissure" -q -o "$d" -n c --maps cracks,crackmask,cellid ${FISSURE_ARGS:-} $extra \
            "$src/presets/$p.ini" >/dev/null 2>"$out/$p-$run.err"; then
            printf '%-22s %-8s failed (%s)\n' "$p" "$run" "$out/$p-$run.err"
            continue
        fi
        rm -f "$out/$p-$run.err"
        stair=$(python3 "$src/tests/crack_paths.py" staircase "$d/c_cracks.json" 2>/dev/null || echo "- 0")
        frags=$(sed -n 's/^ *"fragments": *\([0-9]*\),*$/\1/p' "$d/c_cracks.json" | head -n 1)
        wrap=$(python3 -c 'import json, sys; t = json.load(open(sys.argv[1]))["tileable"]
print(("x" if t["u"] else "") + ("y" if t["v"] else "") or "none")' "$d/c_cracks.json")
        set -- $("$stats" pieces "$d/c_crackmask.png" "$d/c_cellid.png" "$wrap")
        printf '%-22s %-8s %10s %6s %9s %7s %6s\n' "$p" "$run" "${stair% *}" "${stair#* }" "$frags" "$4" "$3"
    done
done
