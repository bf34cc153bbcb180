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
finish
