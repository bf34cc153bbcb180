#!/bin/sh
# Mesh benchmark: sampling, Delaunay and Voronoi timings at several sizes, with peak memory.
# Usage: bench/run.sh BUILDDIR   (BUILDDIR holds bench/bench_mesh; run `make bench/bench_mesh` first)
set -eu

if [ $# -ne 1 ]; then
    echo "usage: $0 BUILDDIR" >&2
    exit 64
fi
bench="$1/bench/bench_mesh"
if [ ! -x "$bench" ]; then
    echo "$0: $bench not found: build it with 'make bench/bench_mesh' in $1" >&2
    exit 66
fi

# GNU time reports the peak resident set; without it, only the timings are printed.
timer=
if [ -x /usr/bin/time ] && /usr/bin/time -v true >/dev/null 2>&1; then
    timer=/usr/bin/time
fi

echo "# $(uname -m), $(getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?') processors, $(date -u +%Y-%m-%dT%H:%MZ)"
run() {
    if [ -n "$timer" ]; then
        log=$(mktemp)
        if line=$("$timer" -v "$bench" "$@" 2>"$log"); then
            peak=$(sed -n 's/.*Maximum resident set size (kbytes): *//p' "$log")
            echo "$line peak_rss=${peak}kB"
            rm -f "$log"
        else
            cat "$log" >&2
            rm -f "$log"
            return 1
        fi
    else
        "$bench" "$@"
    fi
}

for n in 10000 100000 1000000; do
    run "$n" plane
done
run 100000 plane uniform
run 100000 periodic
run 100000 cylinder
run 100000 sphere
# the speed target: a million points on the periodic plane, on one thread and on two (same mesh hash)
for j in 1 2; do
    run -j "$j" 1000000 periodic
done
