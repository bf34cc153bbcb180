# 3-D assets with the real clients: --asset writes a glTF 2.0 asset (.gltf with .bin, or .glb)
# that the Khronos glTF validator passes with no error and no warning for every domain, whose
# material binds the maps and whose tangents follow them (gltf_check.js); --mesh writes an OBJ with
# an MTL binding the maps; Blender imports the .gltf, the .glb and the .obj, finds the material with
# its textures bound and renders a frame of each, and Blender's own MikkTSpace agrees with the
# .gltf's tangents (blender_check.py). Bad --asset requests fail
# before any output is written.
. "$top_srcdir/tests/lib.sh"
need node npm blender
NODE_PATH="$(npm root -g)${NODE_PATH:+:$NODE_PATH}"
export NODE_PATH
node -e "require('gltf-validator')" 2>/dev/null || missing "the npm package gltf-validator"
SMALL="--size 64x64 --set mesh.elements=30"

# blender_check MODE FILE: Blender imports FILE and renders one frame.
blender_check() {
    if blender -b --factory-startup --python-exit-code 1 --python "$top_srcdir/tests/blender_check.py" -- \
        "$1" "$2" "$tmp/render-$1.png" >"$tmp/blender.log" 2>&1; then
        ok "Blender imports $(basename "$2"), finds its textures bound and renders a frame"
    else
        not_ok "Blender imports $(basename "$2"), finds its textures bound and renders a frame"
        grep -E '^(ok|FAIL)|Error' "$tmp/blender.log" | sed 's/^/    /' | tail -20
    fi
}

# facts FILE DOMAIN SIZES...: gltf_check.js and the validator on one asset.
facts() {
    f=$1; shift
    if node "$top_srcdir/tests/gltf_check.js" "$f" "$@" >"$tmp/facts" 2>&1; then
        ok "$(basename "$f"): the material binds the maps, positions in metres, tangents follow the maps"
    else
        not_ok "$(basename "$f"): gltf_check"; grep -v '^ok' "$tmp/facts" | sed 's/^/    /'
    fi
    if node "$top_srcdir/tests/gltf_validate.js" "$f" >"$tmp/valid" 2>&1; then
        ok "the glTF validator finds no error and no warning in $(basename "$f"): $(head -1 "$tmp/valid" | sed 's/.*: validator //')"
    else
        not_ok "the glTF validator on $(basename "$f")"; sed 's/^/    /' "$tmp/valid" | head -20
    fi
}

for spec in "voronoi-tile plane 20 20" "voronoi-trunk cylinder 5 40" "voronoi-sphere sphere 10"; do
    set -- $spec
    preset=$1; shift
    d="$tmp/$1"
    # the asset and the mesh beside a maps directory: paths relative to them
    expect_status 0 "$preset: --mesh and --asset FILE.gltf run" "$FISSURE" -q -o "$d/maps" -n t $SMALL \
        --mesh "$d/mesh/t.obj" --asset "$d/t.gltf" "$preset"
    for f in "$d/t.gltf" "$d/t.bin" "$d/mesh/t.obj" "$d/mesh/t.mtl"; do
        grep -qx "$f" "$tmp/stdout" && [ -s "$f" ] && ok "$preset: $(basename "$f") written and listed" \
            || not_ok "$preset: $(basename "$f") written and listed"
    done
    [ "$(json_get "$d/maps/t.json" maps.asset.file)" = "../t.gltf" ] && \
        [ "$(json_get "$d/maps/t.json" maps.mesh_material.file)" = "../mesh/t.mtl" ] && \
        ok "$preset: the sidecar names the asset and the material file" || not_ok "$preset: sidecar entries"
    grep -q '"uri": "maps/t_baseColor.png"' "$d/t.gltf" && ok "$preset: the asset names the maps relative to itself" \
        || not_ok "$preset: the asset names the maps relative to itself"
    facts "$d/t.gltf" "$@"
    # the OBJ uses its MTL, whose maps resolve from the MTL's directory
    grep -qx 'mtllib t.mtl' "$d/mesh/t.obj" && grep -qx 'usemtl t' "$d/mesh/t.obj" && \
        grep -qx 'newmtl t' "$d/mesh/t.mtl" && ok "$preset: the OBJ loads t.mtl and uses its material" \
        || not_ok "$preset: the OBJ loads t.mtl and uses its material"
    bound=0
    for key in map_Kd map_Bump disp; do
        f=$(awk -v k=$key '$1 == k { print $NF }' "$d/mesh/t.mtl")
        [ -n "$f" ] && [ -f "$d/mesh/$f" ] && bound=$((bound + 1))
    done
    [ "$bound" -eq 3 ] && ok "$preset: the MTL binds base colour, normal and height maps that exist" \
        || not_ok "$preset: the MTL binds base colour, normal and height maps that exist ($bound of 3)"
    # the same run as one .glb: images embedded, the maps still written
    expect_status 0 "$preset: --asset FILE.glb runs" "$FISSURE" -q -o "$d/glb" -n t $SMALL --asset "$d/glb/t.glb" \
        "$preset"
    [ -s "$d/glb/t.glb" ] && [ ! -e "$d/glb/t.bin" ] && cmp -s "$d/glb/t_baseColor.png" "$d/maps/t_baseColor.png" \
        && ok "$preset: one .glb, the maps beside it as with .gltf" || not_ok "$preset: one .glb, the maps beside it"
    facts "$d/glb/t.glb" "$@"
done

blender_check gltf "$tmp/plane/t.gltf"
blender_check obj "$tmp/cylinder/mesh/t.obj"
blender_check gltf "$tmp/sphere/glb/t.glb"

# Bad requests: the right status, a message naming the option, and nothing written.
expect_status 64 "--asset needs .gltf or .glb" "$FISSURE" -q -o "$tmp/bad" --asset "$tmp/bad/t.obj" voronoi-tile
grep -q -- "--asset: expected a file name ending in .gltf or .glb" "$tmp/stderr" && ok "the message says so" \
    || not_ok "the message says so"
expect_status 64 "--asset with another --target" "$FISSURE" -q -o "$tmp/bad" --target unreal --asset "$tmp/bad/t.gltf" \
    voronoi-tile
grep -q -- "--target unreal" "$tmp/stderr" && ok "the message names the target" || not_ok "the message names the target"
: >"$tmp/file"
expect_status 73 "--asset in a directory that cannot be made" "$FISSURE" -q -o "$tmp/bad" $SMALL \
    --asset "$tmp/file/t.gltf" voronoi-tile
[ -z "$(ls -A "$tmp/bad" 2>/dev/null)" ] && ok "no map is written when the asset cannot be" \
    || not_ok "no map is written when the asset cannot be: $(ls -A "$tmp/bad")"
finish
