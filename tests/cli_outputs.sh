# The 3-D outputs of SPEC §6: the lit preview of every domain, and the --mesh OBJ, checked as geometry.
. "$top_srcdir/tests/lib.sh"
helpers="$(dirname "$FISSURE")/tests"
small="--set mesh.elements=150 --size 96x96"

# check NAME CMD...: runs a helper, passing when it exits 0 and showing its findings when not.
check() {
    what=$1; shift
    if out=$("$@" 2>&1); then ok "$what ($(printf '%s' "$out" | tail -1))"
    else not_ok "$what"; printf '%s\n' "$out" | sed 's/^/    /' | head -8; fi
}

# Each domain: the preview is 8-bit RGB at [render] preview_size and shows a shaded object in the
# middle of the frame; the OBJ is a correctly bounded lift (obj_check: edges shared by at most two
# triangles running opposite ways, boundary only on a plane's four sides or a cylinder's two ends,
# none on a sphere, one piece with Euler characteristic 1, 0 or 2, corners where their texture
# coordinates say, heights within [0, voronoi.depth], texture coordinates in [0, 1]).
# (The voronoi sphere has 300 cells: with fewer, some seeds fold a few triangles near the poles.)
while read -r name preset elements geometry; do
    d="$tmp/$name"
    expect_status 0 "$preset: maps, preview and mesh" "$FISSURE" -q -o "$d" -n "$name" --size 96x96 \
        --set mesh.elements="$elements" --set render.preview_size=160x120 --mesh "$d/$name.obj" \
        "$PRESETS/$preset.ini"
    expect_png "$d/${name}_preview.png" 160 120 8 2
    check "$name preview shows a shaded object" "$helpers/preview_check" "$d/${name}_preview.png"
    check "$name.obj is a closed or correctly bounded $geometry" "$helpers/obj_check" "$d/$name.obj" $geometry
    grep -qx "$d/$name.obj" "$tmp/stdout" && ok "stdout lists the mesh" || not_ok "stdout lists the mesh"
    sed -n '/"preview": {/,/}/p' "$d/$name.json" | grep -q '"color_space": "srgb"' \
        && ok "the sidecar calls the preview sRGB" || not_ok "the sidecar calls the preview sRGB"
done <<EOF
tile voronoi-tile 150 plane 20 20 0.4
plane voronoi-plane 150 plane 20 20 0.4
trunk voronoi-trunk 150 cylinder 5 40 0.5
sphere voronoi-sphere 300 sphere 10 0.3
EOF

# The helpers can fail: a flat map filling the frame is no preview.
if "$helpers/preview_check" "$tmp/tile/tile_basecolor.png" >/dev/null 2>&1; then
    not_ok "preview_check rejects a texture map"
else ok "preview_check rejects a texture map"; fi

# Default size, alone with --maps preview (and the sidecar).
expect_status 0 "--maps preview" "$FISSURE" -q -o "$tmp/only" -n only --set mesh.elements=40 --size 64x64 \
    --maps preview "$PRESETS/voronoi-sphere.ini"
expect_png "$tmp/only/only_preview.png" 1024 768 8 2
n=$(wc -l < "$tmp/stdout")
[ "$n" -eq 2 ] && ok "only the preview and the sidecar are written" \
    || not_ok "only the preview and the sidecar are written (got $n files)"

# Same seed, same files.
"$FISSURE" -q -o "$tmp/again" -n tile $small --set render.preview_size=160x120 --mesh "$tmp/again/tile.obj" \
    "$PRESETS/voronoi-tile.ini" >/dev/null 2>&1
cmp -s "$tmp/tile/tile_preview.png" "$tmp/again/tile_preview.png" && ok "the preview is deterministic" \
    || not_ok "the preview is deterministic"
cmp -s "$tmp/tile/tile.obj" "$tmp/again/tile.obj" && ok "the mesh is deterministic" || not_ok "the mesh is deterministic"

# --mesh in another directory than -o: created and written there, atomically.
expect_status 0 "--mesh elsewhere" "$FISSURE" -q -o "$tmp/maps" -n m --set mesh.elements=40 --size 32x32 \
    --maps height --mesh "$tmp/elsewhere/sub/m.obj" "$PRESETS/voronoi-trunk.ini"
[ -s "$tmp/elsewhere/sub/m.obj" ] && ok "the mesh is written in its own directory" \
    || not_ok "the mesh is written in its own directory"
left=$(find "$tmp/maps" "$tmp/elsewhere" -name '.*tmp*' | wc -l)
[ "$left" -eq 0 ] && ok "no temporary file is left" || not_ok "no temporary file is left ($left)"

# A mesh that cannot be created fails the whole set: exit 73, no map written.
: > "$tmp/plain-file"
expect_status 73 "--mesh under a file" "$FISSURE" -q -o "$tmp/none" -n x --set mesh.elements=40 --size 32x32 \
    --maps height --mesh "$tmp/plain-file/m.obj" "$PRESETS/voronoi-tile.ini"
[ ! -e "$tmp/none/x_height.png" ] && ok "no map is written when the mesh fails" \
    || not_ok "no map is written when the mesh fails"
expect_status 64 "--mesh without a file name" "$FISSURE" --mesh "$tmp/dir/" "$PRESETS/voronoi-tile.ini"
expect_status 65 "a preview size out of range" "$FISSURE" -q -o "$tmp/bad" --set render.preview_size=8x8 \
    "$PRESETS/voronoi-tile.ini"
finish
