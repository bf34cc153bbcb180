#!/bin/sh
# Runs the libFuzzer harnesses that make fuzz builds, each for SECONDS seconds (and at most RUNS
# inputs when given), on corpora seeded from presets/ (and three presets with a --set after a NUL)
# and from textures/ and tests/fuzz/greymap-seeds/ (a small image in every format read). A crash, a
# sanitizer report or a failed check stops the fuzzer with the input saved in WORK; the script then
# exits non-zero.
# usage: tests/fuzz/run.sh SRCDIR BUILDDIR SECONDS [RUNS]
set -eu
srcdir=$1 builddir=$2 seconds=$3 runs=${4:--1}
work=${FUZZ_WORK:-$builddir/tests/fuzz/work}
mkdir -p "$work/preset-corpus" "$work/preset-seeds" "$work/greymap-corpus" "$work/greymap-seeds"
cp "$srcdir"/presets/*.ini "$work/preset-seeds/"
for p in voronoi-tile mud bark-a; do
    { cat "$srcdir/presets/$p.ini"; printf '\000mesh.elements=500'; } > "$work/preset-seeds/$p-set"
done
cp "$srcdir"/textures/*.png "$srcdir"/tests/fuzz/greymap-seeds/* "$work/greymap-seeds/"
status=0
for f in preset greymap; do
    echo "fuzz: $f, ${seconds} s"
    "$builddir/tests/fuzz/fuzz_$f" -max_total_time="$seconds" -runs="$runs" -max_len=65536 -print_final_stats=1 \
        -artifact_prefix="$work/$f-" "$work/$f-corpus" "$work/$f-seeds" 2>"$work/$f.log" || status=1
    grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb|^Done|ERROR|SUMMARY' "$work/$f.log" | sed "s/^/fuzz: $f: /"
done
exit $status
