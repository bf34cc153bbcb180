# The tetrahedral model's presets through the real binary, small and fast: each runs, writes its
# maps and fractures; the same seed gives identical bytes, and so do -j 1 and -j 2.
. "$top_srcdir/tests/lib.sh"

# fractures N from a sidecar
fractures() { sed -n 's/^ *"fractures": *\([0-9]*\),*$/\1/p' "$1"; }

mud="--size 128x128 --set mesh.elements=800"
expect_status 0 "mud-thick runs" "$FISSURE" -q -j 1 -o "$tmp/mud-a" -n x $mud mud-thick
for map in height normal basecolor crackmask crackdist cellid occlusion; do
    [ -s "$tmp/mud-a/x_$map.png" ] && ok "mud-thick writes its $map map" || not_ok "mud-thick writes its $map map"
done
n=$(fractures "$tmp/mud-a/x.json")
[ "${n:-0}" -gt 20 ] && ok "mud-thick: fracture events ($n)" || not_ok "mud-thick: fracture events (got '$n')"

# Same seed, identical files; -j 2 gives the same bytes as -j 1.
expect_status 0 "mud-thick runs again" "$FISSURE" -q -j 1 -o "$tmp/mud-b" -n x $mud mud-thick
expect_status 0 "mud-thick runs on 2 threads" "$FISSURE" -q -j 2 -o "$tmp/mud-j2" -n x $mud mud-thick
for map in height normal basecolor crackmask cellid occlusion; do
    cmp -s "$tmp/mud-a/x_$map.png" "$tmp/mud-b/x_$map.png" && ok "mud-thick $map: same seed, identical bytes" \
        || not_ok "mud-thick $map: same seed, identical bytes"
    cmp -s "$tmp/mud-a/x_$map.png" "$tmp/mud-j2/x_$map.png" && ok "mud-thick $map: -j 1 and -j 2 identical" \
        || not_ok "mud-thick $map: -j 1 and -j 2 identical"
done
cmp -s "$tmp/mud-a/x_cracks.json" "$tmp/mud-j2/x_cracks.json" && ok "mud-thick crack graph: -j 1 and -j 2 identical" \
    || not_ok "mud-thick crack graph: -j 1 and -j 2 identical"

# Bark (the direction of its fissures is test_tet's: their walls within 20 degrees of the axis).
expect_status 0 "bark-tet runs" "$FISSURE" -q -o "$tmp/bark" -n x --size 128x128 --set mesh.elements=800 bark-tet
n=$(fractures "$tmp/bark/x.json")
[ "${n:-0}" -gt 20 ] && ok "bark-tet: nodes split ($n)" || not_ok "bark-tet: nodes split (got '$n')"

# The glaze on a growing sphere crazes into pieces.
expect_status 0 "glaze-tet runs" "$FISSURE" -q -o "$tmp/glaze" -n x --size 128x64 --set mesh.elements=800 glaze-tet
n=$(fractures "$tmp/glaze/x.json")
[ "${n:-0}" -gt 20 ] && ok "glaze-tet: nodes split ($n)" || not_ok "glaze-tet: nodes split (got '$n')"
finish
