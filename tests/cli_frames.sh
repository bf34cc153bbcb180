# Time-lapse frames (--frames N): files, sizes, depths, monotone crack growth, the sidecar, errors.
. "$top_srcdir/tests/lib.sh"
PNG="$(dirname "$FISSURE")/tests/png_check"

# frames_grow NAME DIR N: the crack mask coverage of frames 1..N never decreases, grows overall, and the
# last frame is the final crack mask.
frames_grow() {
    name=$1 d=$2 n=$3 prev=-1 first= last=
    k=1
    while [ "$k" -le "$n" ]; do
        f=$(printf '%s/%s_frame_%04d_crackmask.png' "$d" "$name" "$k")
        c=$("$PNG" coverage "$f") || { not_ok "$name frame $k crack mask readable"; return; }
        [ -z "$first" ] && first=$c
        if awk -v a="$prev" -v b="$c" 'BEGIN { exit !(b + 1e-6 >= a) }'; then :; else
            not_ok "$name: crack coverage drops from $prev to $c at frame $k"; return
        fi
        prev=$c last=$c k=$((k + 1))
    done
    ok "$name: crack coverage never decreases over $n frames ($first .. $last)"
    awk -v a="$first" -v b="$last" 'BEGIN { exit !(b > a + 1e-3) }' && ok "$name: the cracks grow between the frames" \
        || not_ok "$name: the cracks grow between the frames ($first .. $last)"
    cmp -s "$(printf '%s/%s_frame_%04d_crackmask.png' "$d" "$name" "$n")" "$d/${name}_crackmask.png" \
        && ok "$name: the last frame is the final state" || not_ok "$name: the last frame is the final state"
}

# Springs, default frame maps (basecolor and crackmask) next to the default maps.
expect_status 0 "springs with --frames 4" "$FISSURE" -q -o "$tmp/s" -n s --size 96x96 \
    --set mesh.elements=500 --frames 4 "$PRESETS/mud-springs.ini"
for k in 0001 0002 0003 0004; do
    expect_png "$tmp/s/s_frame_${k}_basecolor.png" 96 96 8 2
    expect_png "$tmp/s/s_frame_${k}_crackmask.png" 96 96 8 0
done
[ ! -e "$tmp/s/s_frame_0001_height.png" ] && [ ! -e "$tmp/s/s_frame_0005_basecolor.png" ] \
    && ok "frames carry only the basecolor and crack mask by default" \
    || not_ok "frames carry only the basecolor and crack mask by default"
n=$(grep -c '_frame_' "$tmp/stdout")
[ "$n" -eq 8 ] && ok "stdout lists the 8 frame files" || not_ok "stdout lists the 8 frame files (got $n)"
frames_grow s "$tmp/s" 4
grep -q '"file_pattern": "s_frame_NNNN_KIND.png"' "$tmp/s/s.json" && ok "the sidecar names the frame files" \
    || not_ok "the sidecar names the frame files"
times=$(sed -n '/"frames": \[/,/\]/p' "$tmp/s/s.json" | grep -c '"time"')
[ "$times" -eq 4 ] && ok "the sidecar lists the time of each frame" || not_ok "the sidecar lists 4 frame times (got $times)"
leftovers=$(find "$tmp/s" -name '.*tmp*' | wc -l)
[ "$leftovers" -eq 0 ] && ok "no temporary file is left" || not_ok "no temporary file is left"

# Wedge (element removal), the frame maps picked by --maps.
expect_status 0 "wedge with --frames 3 --maps crackmask,height" "$FISSURE" -q -o "$tmp/w" -n w --size 64x64 \
    --set mesh.elements=1500 --frames 3 --maps crackmask,height "$PRESETS/mud-remove.ini"
for k in 0001 0002 0003; do
    expect_png "$tmp/w/w_frame_${k}_height.png" 64 64 16 0
    expect_png "$tmp/w/w_frame_${k}_crackmask.png" 64 64 8 0
done
[ ! -e "$tmp/w/w_frame_0001_basecolor.png" ] && ok "--maps picks the frames' maps" || not_ok "--maps picks the frames' maps"
frames_grow w "$tmp/w" 3

# Same seed, same frames: identical frames.
"$FISSURE" -q -o "$tmp/w2" -n w --size 64x64 --set mesh.elements=1500 --frames 3 --maps crackmask,height \
    "$PRESETS/mud-remove.ini" >/dev/null 2>&1
cmp -s "$tmp/w/w_frame_0002_crackmask.png" "$tmp/w2/w_frame_0002_crackmask.png" && ok "frames are deterministic" \
    || not_ok "frames are deterministic"

# The voronoi model has no time: a usage error, and nothing is written.
expect_status 64 "--frames on the voronoi model is a usage error" "$FISSURE" -q -o "$tmp/v" --frames 3 \
    --set mesh.elements=100 --size 32x32 "$PRESETS/voronoi-tile.ini"
grep -q 'voronoi model has no time' "$tmp/stderr" && ok "the message says why" || not_ok "the message says why"
[ ! -e "$tmp/v" ] || [ -z "$(ls -A "$tmp/v")" ] && ok "nothing is written" || not_ok "nothing is written"
expect_status 64 "--frames 0 is a usage error" "$FISSURE" --frames 0 "$PRESETS/mud-springs.ini"
expect_status 64 "--frames x is a usage error" "$FISSURE" --frames x "$PRESETS/mud-springs.ini"
finish
