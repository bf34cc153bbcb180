# The tetrahedral model's presets through the real binary, small and fast: each runs, writes its
# maps and fractures; the same seed gives identical bytes, and so do -j 1 and -j 2.
. "$top_srcdir/tests/lib.sh"


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

# Thinner layers crack into smaller pieces: mud-thick at its own mesh and seed, its layer halved,
# breaks into 2 to 5 times as many fragments (the crack graph's closed pieces; 18 and 54 when
# this test was written).
expect_status 0 "mud-thick at its thickness" "$FISSURE" -q -o "$tmp/thick" -n x --size 256x256 mud-thick
expect_status 0 "mud-thick at half its thickness" "$FISSURE" -q -o "$tmp/thin" -n x --size 256x256 \
    --set material.thickness=0.3 mud-thick
f1=$(fragments "$tmp/thick/x_cracks.json"); f2=$(fragments "$tmp/thin/x_cracks.json")
if [ "${f1:-0}" -gt 0 ] && [ $((2 * f1)) -le "${f2:-0}" ] && [ "${f2:-0}" -le $((5 * f1)) ]; then
    ok "mud-thick: halving the thickness gives 2-5x the fragments ($f1 -> $f2)"
else
    not_ok "mud-thick: halving the thickness gives 2-5x the fragments (got '$f1' -> '$f2')"
fi

# [render] opening_scale draws the cracks as many times as open as simulated: the same small
# simulation drawn at 1, 2 and 4 covers (crack mask) about 1, 2 and 4 times as much of the tile
# (1.5 %, 3.0 % and 6.0 % when this test was written); the crack mask at 1 is what the tet model
# drew before it read the key.
STATS="$(dirname "$FISSURE")/tests/crack_stats"
for sc in 1 2 4; do
    expect_status 0 "mud-thick drawn at opening_scale $sc" "$FISSURE" -q -o "$tmp/open-$sc" -n x --maps crackmask,cellid \
        --size 256x256 --set mesh.elements=800 --set render.opening_scale=$sc mud-thick
    set -- $("$STATS" pieces "$tmp/open-$sc/x_crackmask.png" "$tmp/open-$sc/x_cellid.png" xy)
    eval "cover$sc=\${4:-}"
done
for sc in 2 4; do
    eval "c=\$cover$sc"
    if [ -n "$cover1" ] && [ -n "$c" ] && awk_true "$cover1 > 0.005 && $c >= 0.8 * $sc * $cover1 && $c <= 1.2 * $sc * $cover1"; then
        ok "mud-thick: opening_scale $sc covers $sc times as much ($cover1 -> $c)"
    else
        not_ok "mud-thick: opening_scale $sc covers $sc times as much (got '$cover1' -> '$c')"
    fi
done

# mud-thick at its default (opening_scale 4): open gaps over 5-15 % of the tile (8.2 % when this
# test was written; 2.1 % as simulated).
set -- $("$STATS" pieces "$tmp/thick/x_crackmask.png" "$tmp/thick/x_cellid.png" xy)
if [ -n "${4:-}" ] && awk_true "$4 >= 0.05 && $4 <= 0.15"; then ok "mud-thick: its cracks cover $4 of the tile"
else not_ok "mud-thick: its cracks cover '${4:-}' of the tile, expected 0.05 to 0.15"; fi

# Bark at its own mesh: the fissures (the crack graph's polylines at least 1 cm from end to end)
# run within 20 degrees of the trunk's axis for at least 90 % of their length (the texture spans
# the trunk's 31.4 cm girth across and its 20 cm height up).
expect_status 0 "bark-tet runs" "$FISSURE" -q -o "$tmp/bark" -n x --size 256x256 bark-tet
n=$(fractures "$tmp/bark/x.json")
[ "${n:-0}" -gt 20 ] && ok "bark-tet: nodes split ($n)" || not_ok "bark-tet: nodes split (got '$n')"
set -- $("$STATS" directions "$tmp/bark/x_cracks.json" 31.416 20 1 20)
awk_true "${1:-0} >= 0.9 && ${2:-0} >= 10" && ok "bark-tet: fissures along the axis ($1 of $3 cm in $2 chords within 20 degrees)" \
    || not_ok "bark-tet: fissures along the axis (got '$1' of '$3' cm in '$2' chords within 20 degrees)"

# The glaze on a growing sphere crazes into pieces.
expect_status 0 "glaze-tet runs" "$FISSURE" -q -o "$tmp/glaze" -n x --size 128x64 --set mesh.elements=800 glaze-tet
n=$(fractures "$tmp/glaze/x.json")
[ "${n:-0}" -gt 20 ] && ok "glaze-tet: nodes split ($n)" || not_ok "glaze-tet: nodes split (got '$n')"
finish
