# Engine targets: every --target writes its documented files (names, size, depth, channels, PNG
# colour chunk), DirectX normals are the OpenGL ones with green inverted, packed maps hold what
# their channels are documented to hold, and the crack graph comes with every target.
. "$top_srcdir/tests/lib.sh"
PNG="$(dirname "$FISSURE")/tests/png_check"
W=96 H=64
MAPS=height,normal,basecolor,crackmask,crackdist,cellid,occlusion,cracks

# expect_file DIR FILE W H DEPTH COLORTYPE TAGS: png_check info checks CRCs and chunk order too.
expect_file() {
    got=$("$PNG" info "$1/$2" 2>&1)
    if [ "$got" = "$3 $4 $5 $6 $7" ]; then ok "$2 is ${3}x$4, $5-bit, colour type $6, $7"
    else not_ok "$2: '$got', expected '$3 $4 $5 $6 $7'"; fi
}

# run_target TARGET FILE...: runs the target; the directory holds exactly FILE... plus the crack
# graph and the sidecar, and stdout lists each of them once.
run_target() {
    target=$1; shift
    d="$tmp/$target"
    expect_status 0 "--target $target runs" "$FISSURE" -q -o "$d" -n t --size ${W}x$H --set mesh.elements=150 \
        --maps "$MAPS" --target "$target" voronoi-tile
    want=$(printf '%s\n' "$@" t_cracks.json t_cracks.svg t.json | sort)
    have=$(ls -A "$d" | sort)
    listed=$(sed 's|.*/||' "$tmp/stdout" | sort)
    [ "$have" = "$want" ] && ok "$target writes exactly its documented files" \
        || not_ok "$target writes exactly its documented files: got $(echo $have)"
    [ "$listed" = "$want" ] && ok "$target lists its files on stdout" || not_ok "$target lists its files on stdout"
    grep -q "\"target\": \"$target\"" "$d/t.json" && ok "the sidecar names target $target" \
        || not_ok "the sidecar names target $target"
}

run_target generic t_height.png t_normal.png t_basecolor.png t_crackmask.png t_crackdist.png t_cellid.png \
    t_occlusion.png
expect_file "$tmp/generic" t_height.png $W $H 16 0 untagged
expect_file "$tmp/generic" t_normal.png $W $H 8 2 untagged
expect_file "$tmp/generic" t_basecolor.png $W $H 8 2 sRGB
expect_file "$tmp/generic" t_crackmask.png $W $H 8 0 untagged
expect_file "$tmp/generic" t_crackdist.png $W $H 16 0 untagged
expect_file "$tmp/generic" t_cellid.png $W $H 16 0 untagged
expect_file "$tmp/generic" t_occlusion.png $W $H 8 0 untagged

run_target gltf t_height.png t_normal.png t_baseColor.png t_crackmask.png t_crackdist.png t_cellid.png \
    t_occlusionRoughnessMetallic.png
expect_file "$tmp/gltf" t_normal.png $W $H 8 2 untagged
expect_file "$tmp/gltf" t_baseColor.png $W $H 8 2 sRGB
expect_file "$tmp/gltf" t_occlusionRoughnessMetallic.png $W $H 8 2 untagged
expect_file "$tmp/gltf" t_height.png $W $H 16 0 untagged

run_target unreal T_t_H.png T_t_N.png T_t_BC.png T_t_CrackMask.png T_t_CrackDist.png T_t_CellID.png T_t_ORM.png
expect_file "$tmp/unreal" T_t_BC.png $W $H 8 2 sRGB
expect_file "$tmp/unreal" T_t_N.png $W $H 8 2 untagged
expect_file "$tmp/unreal" T_t_ORM.png $W $H 8 2 untagged
expect_file "$tmp/unreal" T_t_H.png $W $H 16 0 untagged
expect_file "$tmp/unreal" T_t_CellID.png $W $H 16 0 untagged
grep -q '"normal_convention": "directx"' "$tmp/unreal/t.json" && ok "unreal normals are DirectX" \
    || not_ok "unreal normals are DirectX"

run_target unity-hdrp t_Height.png t_Normal.png t_BaseColor.png t_crackmask.png t_crackdist.png t_cellid.png \
    t_MaskMap.png
expect_file "$tmp/unity-hdrp" t_BaseColor.png $W $H 8 2 sRGB
expect_file "$tmp/unity-hdrp" t_Normal.png $W $H 8 2 untagged
expect_file "$tmp/unity-hdrp" t_MaskMap.png $W $H 8 6 untagged
expect_file "$tmp/unity-hdrp" t_Height.png $W $H 16 0 untagged

run_target blender t_height.png t_normal.png t_basecolor.png t_crackmask.png t_crackdist.png t_cellid.png \
    t_ao.png t_roughness.png
expect_file "$tmp/blender" t_basecolor.png $W $H 8 2 sRGB
expect_file "$tmp/blender" t_normal.png $W $H 8 2 untagged
expect_file "$tmp/blender" t_ao.png $W $H 8 0 untagged
expect_file "$tmp/blender" t_roughness.png $W $H 8 0 untagged
for tg in gltf unity-hdrp blender; do
    grep -q '"normal_convention": "opengl"' "$tmp/$tg/t.json" && ok "$tg normals are OpenGL" \
        || not_ok "$tg normals are OpenGL"
done

# Normals: the OpenGL targets agree byte for byte; DirectX differs only in green, as 255 - g.
for f in gltf/t_normal.png unity-hdrp/t_Normal.png blender/t_normal.png; do
    cmp -s "$tmp/generic/t_normal.png" "$tmp/$f" && ok "$f is the OpenGL normal map" \
        || not_ok "$f is the OpenGL normal map"
done
"$PNG" greenflip "$tmp/gltf/t_normal.png" "$tmp/unreal/T_t_N.png" >/dev/null \
    && ok "the DirectX normal map is the OpenGL one with green = 255 - g" \
    || not_ok "the DirectX normal map is the OpenGL one with green = 255 - g"
expect_status 64 "--normal directx conflicts with --target gltf" "$FISSURE" -q -o "$tmp/x" --normal directx \
    --target gltf voronoi-tile
grep -q "conflicts with --target gltf" "$tmp/stderr" && ok "the conflict is explained" \
    || not_ok "the conflict is explained"
expect_status 64 "an unknown --target is a usage error" "$FISSURE" -q -o "$tmp/x" --target maya voronoi-tile

# Packed maps: occlusion, roughness 0.85 (217 of 255, smoothness 38) and metallic 0 where documented.
# channel_is WHAT FILE CHANNEL (OTHER_FILE OTHER_CHANNEL | =VALUE 0)
channel_is() {
    what=$1; shift
    "$PNG" channel "$@" >/dev/null && ok "$what" || not_ok "$what"
}
ao="$tmp/generic/t_occlusion.png"
mask="$tmp/generic/t_crackmask.png"
channel_is "glTF ORM red is the occlusion" "$tmp/gltf/t_occlusionRoughnessMetallic.png" 0 "$ao" 0
channel_is "glTF ORM green is the roughness" "$tmp/gltf/t_occlusionRoughnessMetallic.png" 1 =217 0
channel_is "glTF ORM blue is metallic 0" "$tmp/gltf/t_occlusionRoughnessMetallic.png" 2 =0 0
cmp -s "$tmp/gltf/t_occlusionRoughnessMetallic.png" "$tmp/unreal/T_t_ORM.png" && ok "Unreal's ORM is glTF's" \
    || not_ok "Unreal's ORM is glTF's"
channel_is "HDRP mask red is metallic 0" "$tmp/unity-hdrp/t_MaskMap.png" 0 =0 0
channel_is "HDRP mask green is the occlusion" "$tmp/unity-hdrp/t_MaskMap.png" 1 "$ao" 0
channel_is "HDRP mask blue is the crack mask" "$tmp/unity-hdrp/t_MaskMap.png" 2 "$mask" 0
channel_is "HDRP mask alpha is the smoothness" "$tmp/unity-hdrp/t_MaskMap.png" 3 =38 0
channel_is "Blender's ao is the occlusion" "$tmp/blender/t_ao.png" 0 "$ao" 0
channel_is "Blender's roughness is the roughness" "$tmp/blender/t_roughness.png" 0 =217 0
expect_status 0 "[render] roughness sets the packed roughness" "$FISSURE" -q -o "$tmp/rough" -n t --size ${W}x$H \
    --set mesh.elements=150 --set render.roughness=0.2 --maps occlusion --target gltf voronoi-tile
channel_is "roughness 0.2 is 51 of 255" "$tmp/rough/t_occlusionRoughnessMetallic.png" 1 =51 0
for key in '"usage"' '"channels_meaning"' '"png_color_chunk": "sRGB"' '"png_color_chunk": "none (raw values)"'; do
    grep -q "$key" "$tmp/unity-hdrp/t.json" && ok "the sidecar has $key" || not_ok "the sidecar has $key"
done

# The crack graph: its fragments are the cell-id map's, and the SVG is a whole drawing.
for tg in generic unreal; do
    j="$tmp/$tg/t_cracks.json"
    for key in '"nodes"' '"cracks"' '"polylines"' '"fragments"' '"adjacency"' '"junction_degrees"'; do
        grep -q "$key" "$j" && ok "$tg crack graph has $key" || not_ok "$tg crack graph has $key"
    done
done
cellid="$tmp/generic/t_cellid.png"
n_ids=$("$PNG" ids "$cellid")
grep -q "\"fragments\": $n_ids," "$tmp/generic/t_cracks.json" \
    && ok "the graph has the $n_ids fragments of the cell-id map" \
    || not_ok "the graph has the $n_ids fragments of the cell-id map"
svg="$tmp/generic/t_cracks.svg"
head -c 5 "$svg" | grep -q '<?xml' && tail -n 1 "$svg" | grep -q '</svg>' && grep -q '<polyline' "$svg" \
    && ok "the SVG is a complete drawing" || not_ok "the SVG is a complete drawing"

# Same seed, same machine: the crack graph and the packed maps are byte-identical.
"$FISSURE" -q -o "$tmp/again" -n t --size ${W}x$H --set mesh.elements=150 --maps "$MAPS" --target unity-hdrp \
    voronoi-tile >/dev/null
for f in t_cracks.json t_cracks.svg t_MaskMap.png; do
    cmp -s "$tmp/unity-hdrp/$f" "$tmp/again/$f" && ok "$f: same seed, identical bytes" \
        || not_ok "$f: same seed, identical bytes"
done

# The preview is a colour map: sRGB-tagged.
expect_status 0 "the preview renders" "$FISSURE" -q -o "$tmp/pv" -n t --size ${W}x$H --set mesh.elements=150 \
    --maps preview voronoi-tile
tags=$("$PNG" info "$tmp/pv/t_preview.png" | awk '{ print $4, $5 }')
[ "$tags" = "2 sRGB" ] && ok "the preview is RGB with an sRGB chunk" \
    || not_ok "the preview is RGB with an sRGB chunk ($tags)"
finish
