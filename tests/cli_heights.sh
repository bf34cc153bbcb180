# Height maps of real runs: the float EXR is the 16-bit PNG within quantisation; normals follow the height gradient.
# (The normal is that of the height field the sidecar describes: height scale, texel size, wrap.)
. "$top_srcdir/tests/lib.sh"
HC="$(dirname "$FISSURE")/tests/height_check"

bit() { [ "$1" = true ] && echo 1 || echo 0; }

# extent_of SIDECAR: the texture's extent in cm along u and v, from the resolved [domain] parameters.
extent_of() {
    case $(json_get "$1" parameters.domain.type) in
    plane) "$HC" extent plane "$(json_get "$1" parameters.domain.width)" "$(json_get "$1" parameters.domain.height)" ;;
    cylinder) "$HC" extent cylinder "$(json_get "$1" parameters.domain.radius)" \
        "$(json_get "$1" parameters.domain.height)" ;;
    sphere) "$HC" extent sphere "$(json_get "$1" parameters.domain.radius)" ;;
    esac
}

# normal_args DIR NAME CONVENTION: the arguments of `height_check normal` for DIR/NAME's maps, all
# read from its sidecar (height range, height scale, domain extent, tileability of the normal map).
normal_args() {
    j="$1/$2.json"
    echo "$1/$2_normal.png $1/$2_height.png $(json_get "$j" maps.height.height_min_cm)" \
        "$(json_get "$j" maps.height.height_max_cm) $(json_get "$j" maps.normal.height_scale) $(extent_of "$j")" \
        "$(bit "$(json_get "$j" maps.normal.tileable.u)") $(bit "$(json_get "$j" maps.normal.tileable.v)") $3"
}

# check WHAT CMD...: passes when the helper exits 0, showing its measurement either way.
check() {
    what=$1; shift
    if out=$("$@" 2>&1); then ok "$what: $out"
    else not_ok "$what"; printf '%s\n' "$out" | sed 's/^/    /' | head -5; fi
}

# Each case: a plane tiling in x and y with a height range away from 0 and a height scale of 2.5,
# a cylinder whose pixels are twice as long around (0.20 cm) as along the axis (0.09 cm), a plane
# that does not tile (one-sided differences at its borders), and a sphere (tiles in u only).
# The normal map's 8 bits allow sqrt(3)/255 rad = 0.39 degrees; the PNG heights' 16 bits hardly add.
while read -r name preset elements size opts; do
    d="$tmp/$name"
    # shellcheck disable=SC2086 # the options are words
    expect_status 0 "$name: 16-bit height and normal" "$FISSURE" -q -o "$d" -n p -s 5 --size "$size" \
        --set mesh.elements="$elements" $opts --maps height,normal "$PRESETS/$preset.ini"
    # shellcheck disable=SC2086
    expect_status 0 "$name: EXR height" "$FISSURE" -q -o "$d" -n e -s 5 --size "$size" \
        --set mesh.elements="$elements" $opts --maps height --format exr "$PRESETS/$preset.ini"
    lo=$(json_get "$d/p.json" maps.height.height_min_cm)
    hi=$(json_get "$d/p.json" maps.height.height_max_cm)
    [ -n "$lo" ] && [ -n "$hi" ] && ok "$name: the sidecar gives the height range [$lo, $hi] cm" \
        || not_ok "$name: the sidecar gives the height range"
    e_range="$(json_get "$d/e.json" maps.height.height_min_cm) $(json_get "$d/e.json" maps.height.height_max_cm)"
    [ "$e_range" = "$lo $hi" ] && ok "$name: the EXR run's sidecar gives the same range" \
        || not_ok "$name: the EXR run's sidecar gives the same range ($e_range)"
    e_kind="$(json_get "$d/e.json" maps.height.sample_format) $(json_get "$d/e.json" maps.height.encoding)"
    [ "$e_kind" = "float height in cm" ] && ok "$name: the sidecar calls the EXR float height in cm" \
        || not_ok "$name: the sidecar calls the EXR float height in cm ($e_kind)"
    check "$name: every EXR height is the PNG's within half a 16-bit step" \
        "$HC" exr "$d/e_height.exr" "$d/p_height.png" "$lo" "$hi"
    # shellcheck disable=SC2046 # the arguments are words
    check "$name: the OpenGL normal map is the height field's normal (max 0.6, mean 0.35 degrees)" \
        "$HC" normal $(normal_args "$d" p opengl) 0.6 0.35
done <<EOF
tile mud-springs 400 96x96 --set render.height_scale=2.5
trunk bark-remove 500 64x128
plane voronoi-plane 150 80x80
sphere voronoi-sphere 200 128x64
EOF

# DirectX: the same field, green pointing down the image.
d="$tmp/trunk"
expect_status 0 "trunk: DirectX normal map" "$FISSURE" -q -o "$d/dx" -n p -s 5 --size 64x128 \
    --set mesh.elements=500 --normal directx --maps height,normal "$PRESETS/bark-remove.ini"
[ "$(json_get "$d/dx/p.json" maps.normal.normal_convention)" = directx ] \
    && ok "the sidecar calls the normal map DirectX" || not_ok "the sidecar calls the normal map DirectX"
# shellcheck disable=SC2046
check "trunk: the DirectX normal map is the height field's normal" "$HC" normal $(normal_args "$d/dx" p directx) 0.6 0.35

# The comparison can fail: the wrong convention, a height scale off by 20 %, or the texel's width
# and height swapped (extents giving 0.09 cm around, 0.20 cm along) are far outside the bounds.
# shellcheck disable=SC2046
set -- $(normal_args "$tmp/trunk" p opengl)
swapped=$(echo "$6 $7" | awk '{ printf "%.9g %.9g", $2 / 128 * 64, $1 / 64 * 128 }')
for wrong in "opengl read as DirectX|$1 $2 $3 $4 $5 $6 $7 $8 $9 directx" \
    "a height scale of 1.2|$1 $2 $3 $4 1.2 $6 $7 $8 $9 opengl" \
    "the texel's sides swapped|$1 $2 $3 $4 $5 $swapped $8 $9 opengl"; do
    # shellcheck disable=SC2086
    if "$HC" normal ${wrong#*|} 0.6 0.35 >"$tmp/out" 2>&1; then
        not_ok "height_check rejects ${wrong%%|*}: $(cat "$tmp/out")"
    else ok "height_check rejects ${wrong%%|*}: $(cat "$tmp/out")"; fi
done
hi=$(json_get "$tmp/tile/p.json" maps.height.height_max_cm)
if "$HC" exr "$tmp/tile/e_height.exr" "$tmp/tile/p_height.png" 0 "$hi" >"$tmp/out" 2>&1; then
    not_ok "height_check rejects a height range starting at 0: $(cat "$tmp/out")"
else ok "height_check rejects a height range starting at 0"; fi
finish
