# The command line: help, version, usage errors, preset lookup, listing and dumping presets.
. "$top_srcdir/tests/lib.sh"

expect_status 0 "--help exits 0" "$FISSURE" --help
grep -q '^Usage: fissure' "$tmp/stdout" && ok "--help prints usage on stdout" || not_ok "--help prints usage on stdout"
expect_status 0 "--version exits 0" "$FISSURE" --version
grep -q '^fissure [0-9]' "$tmp/stdout" && ok "--version prints the version" || not_ok "--version prints the version"
expect_status 64 "an unknown option is a usage error" "$FISSURE" --no-such-option voronoi-tile
expect_status 64 "no preset is a usage error" "$FISSURE"
expect_status 64 "two presets are a usage error" "$FISSURE" voronoi-tile voronoi-sphere
expect_status 64 "a bad --size is a usage error" "$FISSURE" --size 10x99999 voronoi-tile
expect_status 64 "a bad --seed is a usage error" "$FISSURE" --seed -3 voronoi-tile
expect_status 64 "a bad --maps is a usage error" "$FISSURE" --maps height,colour voronoi-tile
expect_status 64 "a malformed --set is a usage error" "$FISSURE" --set nodot voronoi-tile
expect_status 66 "a missing preset exits 66" "$FISSURE" -o "$tmp/none" no-such-preset
grep -q 'no-such-preset' "$tmp/stderr" && ok "the message names the missing preset" || not_ok "the message names the missing preset"
[ ! -e "$tmp/none" ] && ok "nothing written for a missing preset" || not_ok "nothing written for a missing preset"

# --list-presets: one preset a line, name first, then its description.
expect_status 0 "--list-presets exits 0" env FISSURE_PRESET_PATH= "$FISSURE" --list-presets
for p in voronoi-tile voronoi-sphere; do
    grep -q "^$p[[:space:]]\+[^[:space:]]" "$tmp/stdout" && ok "$p is listed with a description" \
        || not_ok "$p is listed with a description"
done

# A preset given by path, and the preset path variable.
mkdir -p "$tmp/mine"
sed 's/^name *=.*/name = mine/' "$PRESETS/voronoi-tile.ini" > "$tmp/mine/my-preset.ini"
expect_status 0 "a preset is found on FISSURE_PRESET_PATH" env FISSURE_PRESET_PATH="$tmp/mine" "$FISSURE" --dump-preset my-preset
grep -q '^name = mine' "$tmp/stdout" && ok "the preset found is the one on the path" || not_ok "the preset found is the one on the path"
expect_status 0 "--list-presets shows the path's presets" env FISSURE_PRESET_PATH="$tmp/mine" "$FISSURE" --list-presets
grep -q '^mine[[:space:]]' "$tmp/stdout" && ok "listed by its [preset] name" || not_ok "listed by its [preset] name"

# --dump-preset prints INI that parses back to the same configuration.
expect_status 0 "--dump-preset exits 0" "$FISSURE" --dump-preset --set mesh.elements=777 --seed 9 "$PRESETS/voronoi-tile.ini"
cp "$tmp/stdout" "$tmp/dump1.ini"
grep -q '^elements = 777' "$tmp/dump1.ini" && ok "--set is applied" || not_ok "--set is applied"
grep -q '^seed = 9' "$tmp/dump1.ini" && ok "--seed is applied" || not_ok "--seed is applied"
expect_status 0 "the dump parses back" "$FISSURE" --dump-preset "$tmp/dump1.ini"
cmp -s "$tmp/dump1.ini" "$tmp/stdout" && ok "the dump round-trips exactly" || not_ok "the dump round-trips exactly"
expect_status 65 "a bad --set value exits 65" "$FISSURE" --dump-preset --set mesh.elements=many voronoi-tile
grep -q 'mesh.elements' "$tmp/stderr" && ok "the message names the key" || not_ok "the message names the key"

# An output directory that cannot be created.
touch "$tmp/file"
expect_status 73 "an uncreatable output directory exits 73" "$FISSURE" -q --size 32x32 --set mesh.elements=50 -o "$tmp/file/sub" voronoi-tile
finish
