# The wedge model through the real binary: the mud and bark presets at a small size crack, are
# deterministic, agree between the CHOLMOD and CG solvers, and bad wedge settings fail cleanly.
. "$top_srcdir/tests/lib.sh"

small="--size 64x64 --set mesh.elements=900"
# fractures N from a sidecar
fractures() { sed -n 's/^ *"fractures": *\([0-9]*\),*$/\1/p' "$1"; }

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

# Thicker mud cracks into fewer pieces (SPEC §9): fewer elements removed for the same shrinkage.
expect_status 0 "thick mud runs" "$FISSURE" -q -o "$tmp/mud-thick" -n x $small --set material.thickness=0.8 mud-remove
thin=$(fractures "$tmp/mud-remove-a/x.json"); thick=$(fractures "$tmp/mud-thick/x.json")
[ "${thick:-0}" -lt "${thin:-0}" ] && ok "thicker mud breaks less ($thick < $thin removals)" \
    || not_ok "thicker mud breaks less (got $thick, thinner $thin)"

# Bad wedge settings: exit 65, a message naming the key, nothing written.
expect_status 65 "the wedge model refuses fracture by splitting" "$FISSURE" -q -o "$tmp/split" $small \
    --set fracture.method=split mud-remove
grep -q '\[fracture\] method' "$tmp/stderr" && ok "the message names [fracture] method" \
    || not_ok "the message names [fracture] method"
[ ! -e "$tmp/split/mud-remove_height.png" ] && ok "nothing written for a refused method" \
    || not_ok "nothing written for a refused method"
expect_status 65 "an unknown solver is a bad preset" "$FISSURE" -q -o "$tmp/bad" $small --set solver.method=lu mud-remove
grep -q 'solver.method' "$tmp/stderr" && ok "the message names solver.method" || not_ok "the message names solver.method"
finish
