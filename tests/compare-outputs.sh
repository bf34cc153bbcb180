#!/bin/sh
# Compares two output trees file by file (as bench/presets.sh writes them): every file must exist in
# both and be byte-identical, except the sidecars (NAME.json), which are compared without their
# timing fields (wall and phase seconds) and the mesh comment naming the version.
# Prints one line per difference and a summary; exits 1 if anything differs.
# usage: tests/compare-outputs.sh DIR_A DIR_B
set -u
a=${1:?usage: compare-outputs.sh DIR_A DIR_B}
b=${2:?usage: compare-outputs.sh DIR_A DIR_B}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/fissure-compare.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
strip_times() { # drops every "..._seconds": line of a sidecar
    grep -v -E '"[a-z_]*seconds"' "$1"
}
same=0 differ=0
(cd "$a" && find . -type f | sort) > "$tmp/a"
(cd "$b" && find . -type f | sort) > "$tmp/b"
comm -23 "$tmp/a" "$tmp/b" | while read -r f; do echo "only in $a: $f"; done
comm -13 "$tmp/a" "$tmp/b" | while read -r f; do echo "only in $b: $f"; done
missing=$(comm -3 "$tmp/a" "$tmp/b" | wc -l)
for f in $(comm -12 "$tmp/a" "$tmp/b"); do
    case "$f" in
    *.json)
        case "$f" in *_cracks.json) strip=false ;; *) strip=true ;; esac
        if $strip; then
            strip_times "$a/$f" > "$tmp/ja"
            strip_times "$b/$f" > "$tmp/jb"
            cmp -s "$tmp/ja" "$tmp/jb"
        else
            cmp -s "$a/$f" "$b/$f"
        fi
        ;;
    *) cmp -s "$a/$f" "$b/$f" ;;
    esac
    if [ $? -eq 0 ]; then same=$((same + 1)); else differ=$((differ + 1)); echo "differs: $f"; fi
done
echo "$same identical, $differ differ, $missing missing"
[ "$differ" -eq 0 ] && [ "$missing" -eq 0 ]
