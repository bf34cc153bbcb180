#!/bin/sh
# Rewrites the golden images listed in tests/golden/cases, on purpose (`make regen-golden`).
# Usage: tests/regen-golden.sh BINARY SRCDIR. Prints, per case, whether its image is new, unchanged
# or changed (with how much, as `fissure diff` measures it); review the changes before committing.
set -eu
if [ $# -ne 2 ]; then
    echo "usage: $0 BINARY SRCDIR" >&2
    exit 64
fi
bin=$1
golden="$2/tests/golden"
presets="$2/presets"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/fissure-golden.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
FISSURE_PRESET_PATH=
export FISSURE_PRESET_PATH
while IFS='|' read -r name preset map opts tol; do
    case $name in '' | '#'*) continue ;; esac
    # shellcheck disable=SC2086 # the options are words
    "$bin" -q -o "$tmp/$name" -n g --maps "$map" $opts "$presets/$preset.ini" >/dev/null
    new="$tmp/$name/g_$map.png"
    if [ ! -f "$golden/$name.png" ]; then
        echo "new       $name"
    elif cmp -s "$new" "$golden/$name.png"; then
        echo "unchanged $name"
        continue
    else
        echo "changed   $name: $("$bin" diff --min-psnr 0 --min-ssim -1 "$new" "$golden/$name.png" || true)"
    fi
    cp "$new" "$golden/$name.png"
done <"$golden/cases"
