#!/bin/sh
# Runs every shipped preset (or the ones named) at its defaults and prints a table: name, wall
# seconds, fractures, peak resident memory (MB). The outputs stay in OUT_DIR/NAME/ (every map, the
# preview, the crack graph, the sidecar and --mesh NAME.obj), so two builds can be compared file by
# file with tests/compare-outputs.sh.
# usage: bench/presets.sh FISSURE OUT_DIR [PRESET...]
#   environment: FISSURE_ARGS extra options for every run (e.g. "--size 512x512 -j 2")
set -eu
fissure=${1:?usage: presets.sh FISSURE OUT_DIR [PRESET...]}
out=${2:?usage: presets.sh FISSURE OUT_DIR [PRESET...]}
shift 2
src=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -eq 0 ]; then
    set -- $(cd "$src/presets" && ls *.ini | sed 's/\.ini$//')
fi
mkdir -p "$out"
OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
export OPENBLAS_NUM_THREADS
echo "# $(uname -m), $(getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?') processors, $(date -u +%Y-%m-%dT%H:%MZ), $fissure ${FISSURE_ARGS:-}"
printf '%-26s %8s %9s %8s %s\n' preset seconds fractures peak_MB status
for p in "$@"; do
    rm -rf "$out/$p"
    mkdir -p "$out/$p"
    start=$(date +%s.%N)
    status=0
    # shellcheck disable=SC2086
    /usr/bin/time -f %M -o "$out/$p.rss" "$fissure" -q -o "$out/$p" -n "$p" --maps all --mesh "$out/$p/$p.obj" \
        ${FISSURE_ARGS:-} "$src/presets/$p.ini" >/dev/null 2>"$out/$p.err" || status=$?
    end=$(date +%s.%N)
    fractures=$(sed -n 's/.*"fractures": *\([0-9]*\).*/\1/p' "$out/$p/$p.json" 2>/dev/null | head -1)
    rss=$(tail -1 "$out/$p.rss" 2>/dev/null || echo 0)
    printf '%-26s %8.1f %9s %8.0f %s\n' "$p" "$(awk "BEGIN { print $end - $start }")" "${fractures:--}" \
        "$(awk "BEGIN { print ${rss:-0} / 1024 }")" "$([ $status -eq 0 ] && echo ok || echo "exit $status")"
    rm -f "$out/$p.rss"
    [ -s "$out/$p.err" ] || rm -f "$out/$p.err"
done
