# -j/--threads N: validated (1 to 256, or 0 for one per processor), and the same seed gives the same
# files whatever N: parallel sampling and Delaunay blocks (over 20000 points), the BLAS under
# CHOLMOD (OpenBLAS, and CHOLMOD's rank updates of element removal), llvmpipe's rasteriser threads.
. "$top_srcdir/tests/lib.sh"

# Bad counts are usage errors (exit 64) that name the option and the range, and write nothing.
for bad in abc 100000 257 -1 2x ''; do
    expect_status 64 "-j '$bad' is a usage error" "$FISSURE" -q -j "$bad" -o "$tmp/bad" --size 32x32 \
        --set mesh.elements=40 "$PRESETS/voronoi-tile.ini"
    grep -q -- "--threads: expected a number of threads from 1 to 256, or 0 for one per processor, got '$bad'" \
        "$tmp/stderr" && ok "-j '$bad': the message names the option, the range and the value" \
        || { not_ok "-j '$bad': the message names the option, the range and the value"; head -2 "$tmp/stderr"; }
done
[ ! -e "$tmp/bad" ] && ok "a bad -j writes nothing" || not_ok "a bad -j writes nothing"
expect_status 64 "--threads=abc is a usage error too" "$FISSURE" -q --threads=abc -o "$tmp/bad" \
    "$PRESETS/voronoi-tile.ini"
# 0 is documented: one thread per processor, as without -j; so are the ends of the range.
for n in 0 1 256; do
    expect_status 0 "-j $n runs" "$FISSURE" -q -j "$n" -o "$tmp/ok-$n" -n o --size 32x32 --set mesh.elements=40 \
        --maps height "$PRESETS/voronoi-tile.ini"
done
cmp -s "$tmp/ok-0/o_height.png" "$tmp/ok-256/o_height.png" && ok "-j 0 and -j 256 give the same map" \
    || not_ok "-j 0 and -j 256 give the same map"
"$FISSURE" --help | grep -q -- '-j, --threads N' && ok "--help lists -j, --threads" || not_ok "--help lists -j, --threads"

# same NAME PRESET MESH OPTIONS...: runs with -j 1 and -j 2 (and --mesh if MESH is yes), then
# compares every file byte for byte (the sidecars but for their wall time).
same() {
    name=$1 preset=$2 mesh=$3
    shift 3
    for j in 1 2; do
        m=
        [ "$mesh" = yes ] && m="--mesh=$tmp/$name-j$j/o.obj"
        "$FISSURE" -q -j $j -o "$tmp/$name-j$j" -n o ${m:+"$m"} "$@" "$PRESETS/$preset.ini" \
            >/dev/null 2>"$tmp/stderr" || { not_ok "$name -j $j runs"; sed 's/^/    /' "$tmp/stderr" | head -3; return; }
    done
    differ=
    for f in "$tmp/$name-j1"/*; do
        b=$(basename "$f")
        if [ "$b" = o.json ]; then
            grep -v wall_seconds "$f" > "$tmp/j1.json"
            grep -v wall_seconds "$tmp/$name-j2/$b" > "$tmp/j2.json"
            cmp -s "$tmp/j1.json" "$tmp/j2.json" || differ="$differ $b"
        else
            cmp -s "$f" "$tmp/$name-j2/$b" || differ="$differ $b"
        fi
    done
    n=$(ls "$tmp/$name-j1" | wc -l)
    [ -z "$differ" ] && ok "$name: -j 1 and -j 2 write the same $n files" \
        || not_ok "$name: -j 1 and -j 2 differ in$differ"
}
same sampling voronoi-tile no --size 32x32 --set mesh.elements=21000 --maps height,cellid --seed 5
same cholmod mud-remove yes --size 64x64 --set mesh.elements=3000 --maps height,normal,cellid --seed 3
same render voronoi-tile yes --size 96x96 --set mesh.elements=300 --set render.preview_size=160x120 --maps all
finish
