# -j/--threads N: validated (1 to 256, or 0 for one per processor), and the same seed gives the same
# files whatever N: parallel sampling and Delaunay blocks (over 20000 points), llvmpipe's rasteriser
# threads, and the BLAS under CHOLMOD, which runs on one thread whatever -j and OPENBLAS_NUM_THREADS
# say (its threaded kernels round otherwise; CHOLMOD's rank updates of element removal).
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
# family NAME PRESET OPTIONS...: every model family (voronoi, springs, wedge split and removal, tet,
# shell), small, every output (all maps, the preview, the crack graph, the mesh, frames where the
# model has time) at -j 1 and -j 2, compared byte for byte
# but for the sidecars' timing fields (tests/compare-outputs.sh). The springs and wedge cases ran
# into BLAS supernodes large enough for OpenBLAS's threaded kernels, which changed the fracture
# sequence (mud-springs: 2934 fractures at -j 1, 2933 at -j 2).
family() {
    name=$1 preset=$2
    shift 2
    for j in 1 2; do
        "$FISSURE" -q -j $j -o "$tmp/f-$name-j$j" -n o --mesh "$tmp/f-$name-j$j/o.obj" --maps all \
            --set render.preview_size=160x120 "$@" "$PRESETS/$preset.ini" >/dev/null 2>"$tmp/stderr" \
            || { not_ok "$name -j $j runs"; sed 's/^/    /' "$tmp/stderr" | head -3; return; }
    done
    if out=$(sh "$top_srcdir/tests/compare-outputs.sh" "$tmp/f-$name-j1" "$tmp/f-$name-j2"); then
        ok "$name ($preset): -j 1 and -j 2 write the same files ($(printf '%s' "$out" | tail -1))"
    else
        not_ok "$name ($preset): -j 1 and -j 2 differ"; printf '%s\n' "$out" | sed 's/^/    /' | head -6
    fi
}
family voronoi-sphere voronoi-sphere --size 128x64 --set mesh.elements=2000 -s 4
family springs mud-springs --size 256x256 --set mesh.elements=1500 -s 11 --frames 2
family wedge-split bark-a --size 64x64 --set mesh.elements=1300
family wedge-remove mud-remove --size 64x64 --set mesh.elements=3000 -s 5 --frames 2
family tet mud-thick --size 64x64 --set mesh.elements=600 --frames 2
family shell eggshell --size 128x64 --set mesh.elements=600 --frames 2
# large enough that the shell's whole-shell passes (bending angles, triangle terms, fracture ratios)
# run on two threads (energy.c: from 4096 items)
family shell-passes eggshell --size 128x64 --set mesh.elements=4200
# a thickening wedge layer large enough that its refills (element systems, from 256 elements) and
# its whole-layer stress passes (from 2048 elements) run on two threads
family wedge-passes bark-j --size 64x64 --set mesh.elements=2600
# Without -j the BLAS's and the rasteriser's own settings do not matter either.
OPENBLAS_NUM_THREADS=2 OMP_NUM_THREADS=2 LP_NUM_THREADS=3 "$FISSURE" -q -o "$tmp/f-springs-env" -n o \
    --mesh "$tmp/f-springs-env/o.obj" --maps all --set render.preview_size=160x120 --size 256x256 \
    --set mesh.elements=1500 -s 11 --frames 2 "$PRESETS/mud-springs.ini" >/dev/null 2>&1
if out=$(sh "$top_srcdir/tests/compare-outputs.sh" "$tmp/f-springs-j1" "$tmp/f-springs-env"); then
    ok "springs: OPENBLAS_NUM_THREADS=2 LP_NUM_THREADS=3 without -j writes the files of -j 1"
else
    not_ok "springs: OPENBLAS_NUM_THREADS=2 LP_NUM_THREADS=3 without -j writes other files"
    printf '%s\n' "$out" | sed 's/^/    /' | head -6
fi

same sampling voronoi-tile no --size 32x32 --set mesh.elements=21000 --maps height,cellid --seed 5
same cholmod mud-remove yes --size 64x64 --set mesh.elements=3000 --maps height,normal,cellid --seed 3
same render voronoi-tile yes --size 96x96 --set mesh.elements=300 --set render.preview_size=160x120 --maps all
finish
