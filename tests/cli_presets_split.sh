# The element-splitting preset library through the real binary, each preset small and fast: it runs,
# writes its maps, fractures, and shows what it is for: bark cracks along the trunk, the breaking
# heart cracks inside the heart, thin mud cracks more densely than thick mud, the elongated sphere
# cracks along its parallels where the isogonic one has no direction, the perturbation maps change
# the pattern, thinner bark splits more. The alias presets of Fig. 5.34 are their letters under
# another name.
. "$top_srcdir/tests/lib.sh"

STATS="$(dirname "$FISSURE")/tests/crack_stats"
TEXTURES="$top_srcdir/textures"

# run PRESET SIZE ELEMENTS [--set ...]: runs it into $tmp/PRESET (name x) and checks its outputs.
run() {
    preset=$1; size=$2; elements=$3; shift 3
    expect_status 0 "$preset runs at $size, $elements elements" "$FISSURE" -q -o "$tmp/$preset" -n x \
        --size "$size" --set mesh.elements="$elements" "$@" "$preset"
    for map in height normal basecolor crackmask crackdist cellid occlusion; do
        [ -s "$tmp/$preset/x_$map.png" ] || not_ok "$preset writes its $map map"
    done
    [ -s "$tmp/$preset/x_cracks.json" ] || not_ok "$preset writes its crack graph"
    w=${size%x*}; h=${size#*x}
    expect_png "$tmp/$preset/x_crackmask.png" "$w" "$h" 8 0
    n=$(fractures "$tmp/$preset/x.json")
    [ "${n:-0}" -gt 0 ] && ok "$preset: nodes split ($n)" || not_ok "$preset: nodes split (got '$n')"
}

# Bark (Fig. 5.33): the trunk grows in girth only, so the fissures run along its axis (up and down
# the map): crack pixels form vertical runs well over twice as long as their horizontal ones.
for letter in a b c d e f g h i j k l m n; do
    run "bark-$letter" 64x64 450
    set -- $("$STATS" runs "$tmp/bark-$letter/x_crackmask.png")
    awk_true "$1 > 2 * $2" && ok "bark-$letter: cracks along the trunk (runs $1 px along, $2 px across)" \
        || not_ok "bark-$letter: cracks along the trunk (runs $1 px along, $2 px across)"
done

# The presets take overrides of their thickness: thinner bark breaks into narrower ridges, so more
# nodes split for the same growth (SPEC §9).
expect_status 0 "bark-h runs with half its thickness" "$FISSURE" -q -o "$tmp/bark-h-thin" -n x --size 64x64 \
    --set mesh.elements=450 --set material.thickness=0.35 bark-h
thick=$(fractures "$tmp/bark-h/x.json"); thin=$(fractures "$tmp/bark-h-thin/x.json")
[ "${thin:-0}" -gt "${thick:-0}" ] && ok "thinner bark splits more ($thin > $thick splits)" \
    || not_ok "thinner bark splits more (got $thin, thicker $thick)"

# The four barks of Fig. 5.34 are letters of Fig. 5.33 under another name: the same resolved preset
# but for [preset] name and description.
for pair in siberian-elm:h spruce-pine:i flowering-dogwood:k black-hickory:n; do
    alias=bark-${pair%:*} letter=bark-${pair#*:}
    "$FISSURE" --dump-preset "$alias" | grep -v '^name = \|^description = ' > "$tmp/alias.ini"
    "$FISSURE" --dump-preset "$letter" | grep -v '^name = \|^description = ' > "$tmp/letter.ini"
    cmp -s "$tmp/alias.ini" "$tmp/letter.ini" && [ -s "$tmp/alias.ini" ] && ok "$alias has the parameters of $letter" \
        || not_ok "$alias has the parameters of $letter"
done

# The breaking heart (Fig. 5.26): the threshold is lowered inside textures/heart.png (grey 0.45
# there, 1 outside): the crack mask covers the heart several times more densely than the rest.
run heart 64x64 1200
set -- $("$STATS" inside "$tmp/heart/x_crackmask.png" "$TEXTURES/heart.png" 0.7)
awk_true "$1 > 4 * $2" && ok "heart: cracks inside the heart (coverage $1 inside, $2 outside)" \
    || not_ok "heart: cracks inside the heart (coverage $1 inside, $2 outside)"

# Thickness rising across the tile (Fig. 5.29): more cracks in the thin left third than in the thick
# right third, counted as fragment changes along the rows and columns of the cell-id map.
run mud-gradient 96x64 1000
set -- $("$STATS" crossings "$tmp/mud-gradient/x_cellid.png" 0 0.333) $("$STATS" crossings "$tmp/mud-gradient/x_cellid.png" 0.667 1)
awk_true "$1 + $2 > 1.5 * ($3 + $4)" && ok "mud-gradient: thin mud cracks more (crossings per 100 px $1 + $2 left, $3 + $4 right)" \
    || not_ok "mud-gradient: thin mud cracks more (crossings per 100 px $1 + $2 left, $3 + $4 right)"

# Perturbation maps (Fig. 5.31): the same mud without its maps cracks differently.
run mud-perturbed 64x64 900
expect_status 0 "mud-perturbed runs without its maps" "$FISSURE" -q -o "$tmp/mud-uniform" -n x --size 64x64 \
    --set mesh.elements=900 --set material.young_map= --set material.threshold_map= --set material.thickness_map= mud-perturbed
cmp -s "$tmp/mud-perturbed/x_cellid.png" "$tmp/mud-uniform/x_cellid.png" \
    && not_ok "mud-perturbed: the maps change the pattern" || ok "mud-perturbed: the maps change the pattern"

# Growing spheres (Fig. 5.32), in the band of latitudes within 45 degrees of the equator (the
# equirectangular map stretches cells near the poles): isogonic growth has no preferred direction,
# growth four times faster along the axis stretches the meridians, and the cracks run along the
# parallels (horizontal runs longer than vertical ones, unlike the isogonic sphere's).
run sphere 128x64 1000
run sphere-elongated 128x64 1000
set -- $("$STATS" runs "$tmp/sphere/x_crackmask.png" 0.25 0.75) $("$STATS" runs "$tmp/sphere-elongated/x_crackmask.png" 0.25 0.75)
awk_true "$6 / $5 > 1.5 * ($2 / $1) && $6 > $5" \
    && ok "sphere-elongated cracks along the parallels (runs across/along $6/$5 px; isogonic $2/$1 px)" \
    || not_ok "sphere-elongated cracks along the parallels (runs across/along $6/$5 px; isogonic $2/$1 px)"
finish
