# Hostile input (issue 16): degenerate domains, huge or special input files, bad names and output
# paths. Every case ends in bounded time and memory with a message and its documented exit status,
# and writes nothing.
. "$top_srcdir/tests/lib.sh"

# bounded SECONDS WANT WHAT CMD...: expect_status under a time limit (timeout's 124 is a failure).
bounded() {
    limit=$1; shift
    want=$1; what=$2; shift 2
    expect_status "$want" "$what (within ${limit} s)" timeout "$limit" "$@"
}

# Degenerate domains: a period far below the point spacing asked the Delaunay blocks for billions of
# periodic copies (an int overflow made the count check pass, and the copy loop spun), and a
# sphere too small for its point spacing asked the sampler's grid for a million cells a side.
i=0
while read -r preset sets; do
    i=$((i + 1))
    opts=
    for s in $sets; do opts="$opts --set $s"; done
    # shellcheck disable=SC2086 # the options are words
    bounded 30 65 "$preset$opts: exit 65" "$FISSURE" -q -o "$tmp/degenerate-$i" --size 64x64 \
        --set mesh.elements=300 $opts "$PRESETS/$preset.ini"
    grep -q '^fissure: delaunay: ' "$tmp/stderr" && ok "$preset$opts: the message says what the mesh lacks" \
        || { not_ok "$preset$opts: the message says what the mesh lacks"; head -2 "$tmp/stderr"; }
    [ ! -e "$tmp/degenerate-$i" ] && ok "$preset$opts: nothing written" || not_ok "$preset$opts: nothing written"
done <<EOF
voronoi-tile domain.width=1e-20 mesh.min_size=1e-300
voronoi-tile domain.height=1e-300 mesh.min_size=1e-301
mud domain.width=1e-300 mesh.min_size=1e-301
voronoi-trunk domain.radius=1e-300 mesh.min_size=1e-301
voronoi-sphere domain.radius=1e-300 mesh.min_size=1e-301
sphere domain.radius=1e-300 mesh.min_size=1e-301
EOF
# Special files: a device (/dev/zero) was read without end, growing 250 MB/s; a FIFO named *.ini on the
# preset path blocked --list-presets and name look-ups. Only regular files are read, opened without
# blocking.
bounded 10 66 "/dev/zero as the preset: exit 66" "$FISSURE" -q -o "$tmp/special" /dev/zero
grep -q "/dev/zero: cannot open preset: not a regular file" "$tmp/stderr" && ok "/dev/zero: the message says why" \
    || not_ok "/dev/zero: the message says why"
mkdir "$tmp/path"
cp "$PRESETS/voronoi-tile.ini" "$tmp/path/mine.ini"
if mkfifo "$tmp/path/fifo.ini"; then
    FISSURE_PRESET_PATH="$tmp/path" bounded 10 0 "a FIFO on the preset path: --list-presets" "$FISSURE" --list-presets
    grep -q "^voronoi-tile" "$tmp/stdout" && ok "--list-presets lists the regular files" \
        || not_ok "--list-presets lists the regular files"
    grep -q "fifo" "$tmp/stdout" && not_ok "--list-presets skips the FIFO" || ok "--list-presets skips the FIFO"
    FISSURE_PRESET_PATH="$tmp/path" bounded 10 66 "a FIFO on the preset path: a look-up by name" "$FISSURE" \
        --dump-preset no-such-preset
    FISSURE_PRESET_PATH="$tmp/path" bounded 10 66 "the FIFO named: exit 66" "$FISSURE" --dump-preset fifo
    grep -q "not a regular file" "$tmp/stderr" && ok "the FIFO named: the message says why" \
        || not_ok "the FIFO named: the message says why"
fi
# Input maps: the size in the header is checked before decoding (a valid 30000 x 30000 grey PNG as a
# threshold map was decoded at 8 GB peak); the decoder's complaint is part of fissure's one-line
# message (raw "libpng error:" lines came first); special files are refused without blocking.
printf '\211PNG\r\n\032\n\0\0\0\rIHDR\0\0u0\0\0u0\010\0\0\0\0\0\0\0\0\0\0\0\0IDATx' > "$tmp/huge.png"
bounded 30 65 "a 30000 x 30000 threshold map: exit 65" "$FISSURE" -q -o "$tmp/map" --size 32x32 \
    --set mesh.elements=200 --set material.threshold_map="$tmp/huge.png" "$PRESETS/heart.ini"
grep -q "huge.png: PNG image of 30000 x 30000 pixels: expected at most 67108864 pixels" "$tmp/stderr" \
    && ok "the message gives the size and the limit" || { not_ok "the message gives the size and the limit"; head -3 "$tmp/stderr"; }
[ "$(wc -l < "$tmp/stderr")" -eq 1 ] && ok "one line on stderr (nothing decoded)" || not_ok "one line on stderr"
cp "$top_srcdir/textures/heart.png" "$tmp/broken.png"
printf '\377\377\377\377' | dd of="$tmp/broken.png" bs=1 seek=200 conv=notrunc 2>/dev/null
expect_status 65 "a corrupt PNG map: exit 65" "$FISSURE" -q -o "$tmp/map" --size 32x32 --set mesh.elements=200 \
    --set material.threshold_map="$tmp/broken.png" "$PRESETS/heart.ini"
grep -q "^fissure: .*broken.png: cannot decode the PNG image: libpng error: " "$tmp/stderr" \
    && ok "the decoder's complaint is in fissure's message" || { not_ok "the decoder's complaint is in fissure's message"; head -3 "$tmp/stderr"; }
grep -v -q '^fissure: ' "$tmp/stderr" && not_ok "no raw decoder line on stderr" || ok "no raw decoder line on stderr"
# Bytes that only look like a PNM header (no white space after P7) with DICM at byte 128: OpenCV's
# PNM readers do not claim them and its DICOM reader did, aborting the process (the fuzzer's find).
expect_status 65 "a P7 file without white space and with a DICOM marker: exit 65" "$FISSURE" -q -o "$tmp/map" \
    --size 32x32 --set mesh.elements=200 \
    --set material.threshold_map="$top_srcdir/tests/fuzz/greymap-seeds/pam-dicm" "$PRESETS/heart.ini"
grep -q "pam-dicm: not an image fissure reads" "$tmp/stderr" \
    && ok "it is not an image fissure reads" || { not_ok "it is not an image fissure reads"; head -3 "$tmp/stderr"; }
if mkfifo "$tmp/map.png"; then
    bounded 10 66 "a FIFO as a map: exit 66" "$FISSURE" -q -o "$tmp/map" --size 32x32 --set mesh.elements=200 \
        --set material.threshold_map="$tmp/map.png" "$PRESETS/heart.ini"
fi
[ ! -e "$tmp/map" ] && ok "bad maps write nothing" || not_ok "bad maps write nothing"

# A full disk (a small tmpfs, where a mount namespace can be had): exit 74 with the system's reason,
# and nothing left (libpng printed "libpng error: Write Error" and fissure gave no reason).
if unshare -rm true 2>/dev/null || unshare -m true 2>/dev/null; then
    u=-m; unshare -m true 2>/dev/null || u=-rm
    for size in 16k 60k; do
        mkdir -p "$tmp/full"
        unshare $u sh -c 'mount -t tmpfs -o size="$1" tmpfs "$2" || exit 99; shift 2; "$@"; s=$?; ls -A "$0/o" > "$0.left" 2>/dev/null; exit $s' \
            "$tmp/full" "$size" "$tmp/full" "$FISSURE" -q -o "$tmp/full/o" --size 128x128 --set mesh.elements=300 \
            "$PRESETS/voronoi-tile.ini" >/dev/null 2>"$tmp/stderr"
        status=$?
        if [ "$status" -eq 99 ]; then ok "full disk: no tmpfs here (skipped)"; break; fi
        [ "$status" -eq 74 ] && ok "a full disk ($size): exit 74" || not_ok "a full disk ($size): exit status $status"
        grep -q "^fissure: .*: cannot write .*: No space left on device$" "$tmp/stderr" && ok "the message says why" \
            || { not_ok "the message says why"; head -3 "$tmp/stderr"; }
        grep -v -q '^fissure: ' "$tmp/stderr" && not_ok "no raw library line" || ok "no raw library line"
        [ ! -s "$tmp/full.left" ] && ok "nothing left in the output directory" || not_ok "files left: $(cat "$tmp/full.left")"
    done
else
    ok "full disk: no mount namespace here (skipped)"
fi

# The preset size limit (1 MiB, fissure-preset(5)).
awk 'BEGIN { printf "#"; for (i = 0; i < 1048576; i++) printf "a"; print "" }' > "$tmp/big.ini"
expect_status 65 "a preset over 1 MiB: exit 65" "$FISSURE" --dump-preset "$tmp/big.ini"
grep -q "expected at most 1048576 bytes (1 MiB)" "$tmp/stderr" && ok "the message gives the limit" \
    || not_ok "the message gives the limit"

# A directory or a symlink loop given as a bare name says why it cannot be read (it said "no such
# file"); a directory named like a preset does not hide the preset.
mkdir "$tmp/cwd" "$tmp/cwd/adir" "$tmp/cwd/mud"
ln -s loop-b "$tmp/cwd/loop-a" && ln -s loop-a "$tmp/cwd/loop-b"
(cd "$tmp/cwd" && "$FISSURE" --dump-preset adir) >/dev/null 2>"$tmp/stderr"; status=$?
[ "$status" -eq 66 ] && grep -q "adir: cannot open preset: Is a directory, and not on the preset path" "$tmp/stderr" \
    && ok "a directory as a bare name: Is a directory" || { not_ok "a directory as a bare name"; head -2 "$tmp/stderr"; }
(cd "$tmp/cwd" && "$FISSURE" --dump-preset loop-a) >/dev/null 2>"$tmp/stderr"; status=$?
[ "$status" -eq 66 ] && grep -q "loop-a: cannot open preset: Too many levels of symbolic links, and not" "$tmp/stderr" \
    && ok "a symlink loop as a bare name: Too many levels of symbolic links" \
    || { not_ok "a symlink loop as a bare name"; head -2 "$tmp/stderr"; }
(cd "$tmp/cwd" && "$FISSURE" --dump-preset mud) >"$tmp/stdout" 2>&1 && grep -q "^name = mud$" "$tmp/stdout" \
    && ok "a directory named mud does not hide the preset mud" || not_ok "a directory named mud hides the preset"

# Numbers are decimal: hexadecimal, which strtod reads, is refused where fissure-preset(5) says decimal.
for v in 0x10 0x1p3; do
    expect_status 65 "--set voronoi.warp=$v: exit 65" "$FISSURE" --dump-preset --set voronoi.warp=$v voronoi-tile
    printf '[voronoi]\nwarp = %s\n' "$v" > "$tmp/hex.ini"
    expect_status 65 "warp = $v in a preset: exit 65" "$FISSURE" --dump-preset "$tmp/hex.ini"
    grep -q "hex.ini:2: \[voronoi\] warp: expected a number >= 0 (cm), got '$v'" "$tmp/stderr" \
        && ok "warp = $v: the message names the line" || not_ok "warp = $v: the message names the line"
done

# --dump-preset round-trips every value it accepts: one starting with ';' (dumped as "key = ;x", read
# back as a comment) is refused, '#' is kept.
printf '[preset]\ndescription =;x\n' > "$tmp/semi.ini"
expect_status 65 "description =;x: exit 65" "$FISSURE" --dump-preset "$tmp/semi.ini"
printf '[preset]\ndescription =#x ;y\n' > "$tmp/hash.ini"
"$FISSURE" --dump-preset "$tmp/hash.ini" > "$tmp/d1.ini" && "$FISSURE" --dump-preset "$tmp/d1.ini" > "$tmp/d2.ini" \
    && cmp -s "$tmp/d1.ini" "$tmp/d2.ini" && grep -q "^description = #x$" "$tmp/d1.ini" \
    && ok "description =#x: dump, parse, dump is stable" || not_ok "description =#x: dump, parse, dump is stable"
finish
