# The wedge model through the real binary: the mud and bark presets at a small size crack, are
# deterministic, agree between the CHOLMOD and CG solvers, and bad wedge settings fail cleanly.
. "$top_srcdir/tests/lib.sh"

small="--size 64x64 --set mesh.elements=900"

for preset in mud-remove bark-remove; do
    expect_status 0 "$preset runs" "$FISSURE" -q -o "$tmp/$preset-a" -n x $small "$preset"
    for map in height normal basecolor crackmask crackdist cellid; do
        [ -s "$tmp/$preset-a/x_$map.png" ] && ok "$preset writes its $map map" || not_ok "$preset writes its $map map"
    done
    expect_png "$tmp/$preset-a/x_cellid.png" 64 64 16 0
    n=$(fractures "$tmp/$preset-a/x.json")
    [ "${n:-0}" -gt 0 ] && ok "$preset: elements fractured ($n)" || not_ok "$preset: elements fractured (got '$n')"
    "$FISSURE" -q -o "$tmp/$preset-b" -n x $small "$preset" >/dev/null 2>&1
    for map in height cellid; do
        cmp -s "$tmp/$preset-a/x_$map.png" "$tmp/$preset-b/x_$map.png" && ok "$preset $map: same seed, identical bytes" \
            || not_ok "$preset $map: same seed, identical bytes"
    done
done

# The conjugate-gradient baseline solves the same equilibria to its tolerance: the same cracks.
expect_status 0 "mud-remove runs with the CG baseline" "$FISSURE" -q -o "$tmp/mud-cg" -n x $small \
    --set solver.method=cg mud-remove
cmp -s "$tmp/mud-remove-a/x_cellid.png" "$tmp/mud-cg/x_cellid.png" && ok "CG and CHOLMOD crack the same elements" \
    || not_ok "CG and CHOLMOD crack the same elements"
[ "$(fractures "$tmp/mud-remove-a/x.json")" = "$(fractures "$tmp/mud-cg/x.json")" ] \
    && ok "CG and CHOLMOD count the same fractures" || not_ok "CG and CHOLMOD count the same fractures"

# Adaptive local relaxation (thesis §5.8) after each removal reaches the same equilibria to its
# tolerance: at a tight one, the same cracks as the global solves.
expect_status 0 "mud-remove runs with global relaxation" "$FISSURE" -q -o "$tmp/mud-global" -n x $small \
    --set solver.relax=global mud-remove
expect_status 0 "mud-remove runs with local relaxation" "$FISSURE" -q -o "$tmp/mud-local" -n x $small \
    --set solver.relax=local --set solver.relax_tolerance=1e-4 mud-remove
cmp -s "$tmp/mud-global/x_cellid.png" "$tmp/mud-local/x_cellid.png" \
    && ok "local and global relaxation crack the same elements" || not_ok "local and global relaxation crack the same elements"

# Thicker mud cracks into fewer pieces (SPEC §9): fewer elements removed for the same shrinkage.
expect_status 0 "thick mud runs" "$FISSURE" -q -o "$tmp/mud-thick" -n x $small --set material.thickness=0.8 mud-remove
thin=$(fractures "$tmp/mud-remove-a/x.json"); thick=$(fractures "$tmp/mud-thick/x.json")
[ "${thick:-0}" -lt "${thin:-0}" ] && ok "thicker mud breaks less ($thick < $thin removals)" \
    || not_ok "thicker mud breaks less (got $thick, thinner $thin)"

# Fracture by element splitting (the mud preset): maps, splits, a seamless tile, more fragments when
# thinner, identical bytes for the same seed.
EDGES="$(dirname "$FISSURE")/tests/tile_edges"
mud="--size 128x128 --set mesh.elements=1200"
expect_status 0 "mud (element splitting) runs" "$FISSURE" -q -o "$tmp/mud-a" -n x $mud mud
for map in height normal basecolor crackmask crackdist cellid; do
    [ -s "$tmp/mud-a/x_$map.png" ] && ok "mud writes its $map map" || not_ok "mud writes its $map map"
done
expect_png "$tmp/mud-a/x_cellid.png" 128 128 16 0
n=$(fractures "$tmp/mud-a/x.json")
[ "${n:-0}" -gt 20 ] && ok "mud: nodes split ($n)" || not_ok "mud: nodes split (got '$n')"
for map in height basecolor crackmask; do
    "$EDGES" xy "$tmp/mud-a/x_$map.png" > "$tmp/edges" && ok "mud $map tiles in x and y: $(cat "$tmp/edges")" \
        || not_ok "mud $map tiles in x and y: $(cat "$tmp/edges")"
done
"$FISSURE" -q -o "$tmp/mud-b" -n x $mud mud >/dev/null 2>&1
cmp -s "$tmp/mud-a/x_cellid.png" "$tmp/mud-b/x_cellid.png" && ok "mud cellid: same seed, identical bytes" \
    || not_ok "mud cellid: same seed, identical bytes"
expect_status 0 "thin mud runs" "$FISSURE" -q -o "$tmp/mud-thin" -n x $mud --set material.thickness=0.2 mud
thin=$(fractures "$tmp/mud-thin/x.json"); thick=$(fractures "$tmp/mud-a/x.json")
[ "${thin:-0}" -gt "${thick:-0}" ] && ok "thinner mud splits more ($thin > $thick splits)" \
    || not_ok "thinner mud splits more (got $thin, thicker $thick)"

# Bad wedge settings: exit 65, a message naming the key, nothing written.
expect_status 65 "an unknown solver is a bad preset" "$FISSURE" -q -o "$tmp/bad" $small --set solver.method=lu mud-remove
grep -q 'solver.method' "$tmp/stderr" && ok "the message names solver.method" || not_ok "the message names solver.method"
finish
