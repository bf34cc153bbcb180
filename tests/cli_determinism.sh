# Same seed, same machine: byte-identical maps. Another seed: different maps.
. "$top_srcdir/tests/lib.sh"

for preset in voronoi-tile voronoi-sphere; do
    for run in a b; do
        "$FISSURE" -q -o "$tmp/$preset-$run" -n x --size 96x96 --set mesh.elements=400 --seed 11 "$preset" >/dev/null
    done
    "$FISSURE" -q -o "$tmp/$preset-c" -n x --size 96x96 --set mesh.elements=400 --seed 12 "$preset" >/dev/null
    for map in height normal basecolor crackmask crackdist cellid; do
        f=x_$map.png
        cmp -s "$tmp/$preset-a/$f" "$tmp/$preset-b/$f" && ok "$preset $map: same seed, identical bytes" \
            || not_ok "$preset $map: same seed, identical bytes"
    done
    cmp -s "$tmp/$preset-a/x_cellid.png" "$tmp/$preset-c/x_cellid.png" \
        && not_ok "$preset: another seed gives another pattern" || ok "$preset: another seed gives another pattern"
    # The sidecars differ only in the wall time.
    grep -v wall_seconds "$tmp/$preset-a/x.json" > "$tmp/ja"
    grep -v wall_seconds "$tmp/$preset-b/x.json" > "$tmp/jb"
    if cmp -s "$tmp/ja" "$tmp/jb"; then
        ok "$preset: sidecars agree but for the wall time"
    else
        not_ok "$preset: sidecars agree but for the wall time"
    fi
done
finish
