#!/bin/sh
# Times a 16-job batch (four jobs each of voronoi-tile, voronoi-trunk, mud-springs and mud at
# mesh.elements=400, 256 x 256 maps, each job -j 1) run serially with --job and with GNU Parallel
# (parallel -j 2), RUNS times each in turn, prints each run's wall seconds and the medians, and
# checks that both ways wrote the same files (sidecars aside).
# usage: bench/batch.sh FISSURE [RUNS]   (default 5 runs)
set -eu
fissure=${1:?usage: batch.sh FISSURE [RUNS]}
runs=${2:-5}
command -v parallel >/dev/null || { echo "batch.sh: GNU Parallel is not installed" >&2; exit 1; }
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/fissure-batch.XXXXXX")
trap 'rm -rf "$work"' EXIT
{
    for seed in 1 2 3 4; do
        for p in voronoi-tile voronoi-trunk mud-springs mud; do
            echo "$src/presets/$p.ini $seed $p-$seed mesh.elements=400"
        done
    done
} > "$work/jobs.txt"
n=$("$fissure" --list-jobs "$work/jobs.txt" | wc -l)
now() { date +%s.%N; }
serial() {
    rm -rf "$work/serial"
    for k in $(seq "$n"); do
        "$fissure" -q -j 1 --size 256x256 -o "$work/serial" --job "$work/jobs.txt:$k" >/dev/null
    done
}
para() {
    rm -rf "$work/parallel"
    parallel -j 2 "$fissure" -q -j 1 --size 256x256 -o "$work/parallel" --job "$work/jobs.txt:{}" ::: \
        $(seq "$n") >/dev/null
}
median() { sort -n | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
echo "# $(uname -m), $(getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?') processors, $(date -u +%Y-%m-%dT%H:%MZ), $fissure, $n jobs"
: > "$work/s.txt"
: > "$work/p.txt"
for r in $(seq "$runs"); do
    t0=$(now); serial; t1=$(now); para; t2=$(now)
    s=$(awk "BEGIN {print $t1 - $t0}"); p=$(awk "BEGIN {print $t2 - $t1}")
    echo "$s" >> "$work/s.txt"
    echo "$p" >> "$work/p.txt"
    printf 'run %d: serial %.2f s, parallel -j 2 %.2f s\n' "$r" "$s" "$p"
done
ms=$(median < "$work/s.txt")
mp=$(median < "$work/p.txt")
printf 'median: serial %.2f s, parallel -j 2 %.2f s, speed-up %.2f\n' "$ms" "$mp" "$(awk "BEGIN {print $ms / $mp}")"
differ=0
for f in "$work/serial"/*; do
    case $f in *.json) [ "${f%_cracks.json}" = "$f" ] && continue ;; esac
    cmp -s "$f" "$work/parallel/$(basename "$f")" || { echo "differs: $(basename "$f")"; differ=1; }
done
[ "$differ" -eq 0 ] && echo "the same $(ls "$work/serial" | wc -l) files either way (sidecars aside)"
exit "$differ"
