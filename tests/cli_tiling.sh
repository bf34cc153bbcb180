# A periodic texture's opposite edges continue each other as well as neighbouring rows do.
. "$top_srcdir/tests/lib.sh"
EDGES="$(dirname "$FISSURE")/tests/tile_edges"

"$FISSURE" -q -o "$tmp/t" -n t --size 256x256 --set mesh.elements=600 voronoi-tile >/dev/null \
    && ok "voronoi-tile runs" || not_ok "voronoi-tile runs"
for map in height basecolor crackmask normal; do
    # tile_edges exits 0 when the seam (last->first column and row) differs no more than 1.5 times the
    # larger difference of the neighbouring pairs of columns (rows) on either side of it.
    "$EDGES" xy "$tmp/t/t_$map.png" > "$tmp/edges" && ok "$map tiles in x and y: $(cat "$tmp/edges")" \
        || not_ok "$map tiles in x and y: $(cat "$tmp/edges")"
done
"$FISSURE" -q -o "$tmp/c" -n c --size 256x128 --set mesh.elements=600 voronoi-trunk >/dev/null
"$EDGES" x "$tmp/c/c_height.png" > "$tmp/edges" && ok "the trunk wraps around: $(cat "$tmp/edges")" \
    || not_ok "the trunk wraps around: $(cat "$tmp/edges")"
"$FISSURE" -q -o "$tmp/s" -n s --size 256x128 --set mesh.elements=600 voronoi-sphere >/dev/null
"$EDGES" x "$tmp/s/s_height.png" > "$tmp/edges" && ok "the sphere wraps in longitude: $(cat "$tmp/edges")" \
    || not_ok "the sphere wraps in longitude: $(cat "$tmp/edges")"
# Control: a non-periodic plane must not pass as a tile (the check can fail).
"$FISSURE" -q -o "$tmp/p" -n p --size 256x256 --set mesh.elements=600 voronoi-plane >/dev/null
"$EDGES" xy "$tmp/p/p_height.png" > "$tmp/edges" && not_ok "a non-periodic plane is detected as seamed: $(cat "$tmp/edges")" \
    || ok "a non-periodic plane is detected as seamed: $(cat "$tmp/edges")"
finish
