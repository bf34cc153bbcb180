#!/bin/sh
# Regenerates the README gallery: a small, fast run of one preset of each family, its base colour map
# written to doc/gallery/PRESET.png (256 pixels on the longer side).
# Usage: sh doc/gallery.sh [FISSURE]   (default: $FISSURE, else ./fissure; run from the source tree)
set -eu
fissure=${1:-${FISSURE:-./fissure}}
top=$(cd "$(dirname "$0")/.." && pwd)
out="$top/doc/gallery"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/fissure-gallery.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"

# preset, map size, overrides that make the run small (fewer elements than the preset's default;
# none where the default is what shows the pattern)
while read -r preset size sets; do
    set --
    for s in $sets; do set -- "$@" --set "$s"; done
    start=$(date +%s)
    "$fissure" -q -o "$tmp" -n "$preset" --size "$size" --maps basecolor "$@" "$top/presets/$preset.ini" >/dev/null
    mv "$tmp/${preset}_basecolor.png" "$out/$preset.png"
    echo "$out/$preset.png ($size, $(($(date +%s) - start)) s)"
done <<LIST
voronoi-tile 256x256 mesh.elements=150
voronoi-trunk 197x256 mesh.elements=300
voronoi-sphere 256x128 mesh.elements=300
mud-springs 256x256 mesh.elements=1500
hex-springs 256x256 mesh.elements=1500
curl-springs 256x256 mesh.elements=1500
mud-remove 256x256 mesh.elements=5000
bark-remove 171x256 mesh.elements=4000
mud 256x256 mesh.elements=10000
mud-gradient 256x171 mesh.elements=4000
heart 256x256 mesh.elements=6000
sphere-elongated 256x128 mesh.elements=3000
bark-siberian-elm 256x256 mesh.elements=3000
bark-flowering-dogwood 256x256 mesh.elements=3000
bark-black-hickory 256x256 mesh.elements=4000
mud-thick 256x256
bark-tet 256x163
glaze-tet 256x128 mesh.elements=3000
eggshell 256x128
bark-shell 197x256 mesh.elements=2000
LIST
