# Every map of every domain exists with the documented size, bit depth and channels; the sidecar too.
. "$top_srcdir/tests/lib.sh"

run_small() { # NAME PRESET W H [extra options]
    name=$1 preset=$2 w=$3 h=$4; shift 4
    expect_status 0 "$preset runs" "$FISSURE" -q -o "$tmp/$name" -n "$name" --size "${w}x$h" \
        --set mesh.elements=300 "$@" "$preset"
    d="$tmp/$name"
    expect_png "$d/${name}_height.png" "$w" "$h" 16 0
    expect_png "$d/${name}_normal.png" "$w" "$h" 8 2
    expect_png "$d/${name}_basecolor.png" "$w" "$h" 8 2
    expect_png "$d/${name}_crackmask.png" "$w" "$h" 8 0
    expect_png "$d/${name}_crackdist.png" "$w" "$h" 16 0
    expect_png "$d/${name}_cellid.png" "$w" "$h" 16 0
    if [ -f "$d/$name.json" ]; then
        for key in '"version"' '"seed"' '"parameters"' '"stats"' '"maps"' '"color_space": "srgb"' '"normal_convention"' '"tileable"'; do
            grep -q "$key" "$d/$name.json" && ok "$name.json has $key" || not_ok "$name.json has $key"
        done
    else
        not_ok "$name.json exists"
    fi
    n=$(wc -l < "$tmp/stdout")
    # 7 maps (with the occlusion; the preview is opt-in), the crack graph's JSON and SVG, the sidecar.
    [ "$n" -eq 10 ] && ok "stdout lists the 10 files written" || not_ok "stdout lists the 10 files written (got $n lines)"
    leftovers=$(find "$d" -name '.*tmp*' | wc -l)
    [ "$leftovers" -eq 0 ] && ok "no temporary file is left" || not_ok "no temporary file is left"
}

run_small tile voronoi-tile 96 64
run_small sphere voronoi-sphere 128 64
run_small trunk voronoi-trunk 64 96
run_small plane voronoi-plane 80 80

# A subset of maps, EXR height and DirectX normals.
expect_status 0 "--maps subset with --format exr" "$FISSURE" -q -o "$tmp/sub" -n s --size 64x64 \
    --set mesh.elements=200 --maps height,crackmask --format exr voronoi-tile
[ -f "$tmp/sub/s_height.exr" ] && ok "the EXR height is written" || not_ok "the EXR height is written"
[ ! -e "$tmp/sub/s_normal.png" ] && ok "unselected maps are not written" || not_ok "unselected maps are not written"
expect_png "$tmp/sub/s_crackmask.png" 64 64 8 0
grep -q '"sample_format": "float"' "$tmp/sub/s.json" && ok "the sidecar says the height is float" \
    || not_ok "the sidecar says the height is float"
expect_status 0 "--normal directx" "$FISSURE" -q -o "$tmp/dx" -n dx --size 64x64 --set mesh.elements=200 \
    --normal directx --maps normal voronoi-tile
grep -q '"normal_convention": "directx"' "$tmp/dx/dx.json" && ok "the sidecar records DirectX normals" \
    || not_ok "the sidecar records DirectX normals"
finish
