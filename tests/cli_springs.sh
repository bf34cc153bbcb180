# The springs model through the real binary: every springs preset runs and cracks, periodic maps tile,
# the same seed gives the same bytes, bad [springs] keys are rejected.
. "$top_srcdir/tests/lib.sh"
EDGES="$(dirname "$FISSURE")/tests/tile_edges"

for preset in mud-springs hex-springs bark-springs multilayer-springs curl-springs; do
    case $preset in
        multilayer-springs) n=400 ;;
        *) n=700 ;;
    esac
    if "$FISSURE" -q -o "$tmp/$preset" -n x --size 128x128 --set mesh.elements=$n "$preset" >/dev/null 2>"$tmp/err"; then
        ok "$preset runs"
    else
        not_ok "$preset runs: $(head -3 "$tmp/err")"; continue
    fi
    expect_png "$tmp/$preset/x_height.png" 128 128 16 0
    expect_png "$tmp/$preset/x_basecolor.png" 128 128 8 2
    f=$(fractures "$tmp/$preset/x.json")
    if [ "${f:-0}" -gt 0 ]; then ok "$preset: $f springs broke"; else not_ok "$preset: no spring broke"; fi
done

# Periodic runs are seamless: the tile (both ways) and the trunk (around and along the axis).
for map in height crackmask normal; do
    "$EDGES" xy "$tmp/mud-springs/x_$map.png" > "$tmp/edges" && ok "mud-springs $map tiles in x and y: $(cat "$tmp/edges")" \
        || not_ok "mud-springs $map tiles in x and y: $(cat "$tmp/edges")"
done
"$EDGES" xy "$tmp/bark-springs/x_height.png" > "$tmp/edges" && ok "bark-springs wraps around and along the trunk: $(cat "$tmp/edges")" \
    || not_ok "bark-springs wraps around and along the trunk: $(cat "$tmp/edges")"

# Same seed, same bytes; another seed, another pattern.
for run in a b; do
    "$FISSURE" -q -o "$tmp/det-$run" -n x --size 96x96 --set mesh.elements=500 --seed 3 mud-springs >/dev/null
done
"$FISSURE" -q -o "$tmp/det-c" -n x --size 96x96 --set mesh.elements=500 --seed 4 mud-springs >/dev/null
for map in height normal basecolor crackmask cellid; do
    cmp -s "$tmp/det-a/x_$map.png" "$tmp/det-b/x_$map.png" && ok "mud-springs $map: same seed, identical bytes" \
        || not_ok "mud-springs $map: same seed, identical bytes"
done
cmp -s "$tmp/det-a/x_height.png" "$tmp/det-c/x_height.png" && not_ok "another seed gives another pattern" \
    || ok "another seed gives another pattern"

# Bad [springs] values exit 65 naming the key, and write nothing.
expect_status 65 "layers = 0 is rejected" "$FISSURE" -o "$tmp/bad" --set springs.layers=0 mud-springs
grep -q 'springs.layers' "$tmp/stderr" && ok "the message names springs.layers" || not_ok "the message names springs.layers"
expect_status 65 "an unknown post mode is rejected" "$FISSURE" -o "$tmp/bad" --set springs.post=melt mud-springs
grep -q 'glue, curl or flat' "$tmp/stderr" && ok "the message lists the post modes" || not_ok "the message lists the post modes"
[ ! -e "$tmp/bad" ] && ok "nothing written for bad values" || not_ok "nothing written for bad values"
finish
