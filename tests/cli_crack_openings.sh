# Cracks drawn open ([render] opening_scale): a crack's width in the maps follows its simulated
# opening times the scale, and at the mud presets' default every fragment stands apart in the crack
# mask. tests/crack_stats pieces counts the 4-connected pieces of the mask under half intensity
# (wrapping on the periodic tile) and the fragments of the cell-id map.
. "$top_srcdir/tests/lib.sh"
STATS="$(dirname "$FISSURE")/tests/crack_stats"

# run NAME OPTIONS...: renders the crack mask and cell ids into $tmp/NAME; sets pieces, frags, joined
# (pieces holding more than one fragment) and cover (empty when something fails).
run() {
    name=$1
    shift
    pieces='' frags='' joined='' cover=''
    if ! "$FISSURE" -q -o "$tmp/$name" -n c --maps crackmask,cellid "$@" >/dev/null 2>"$tmp/stderr"; then
        not_ok "$name: fissure runs"; sed 's/^/    /' "$tmp/stderr" | head -5; return
    fi
    set -- $("$STATS" pieces "$tmp/$name/c_crackmask.png" "$tmp/$name/c_cellid.png" xy)
    pieces=${1:-} frags=${2:-} joined=${3:-} cover=${4:-}
}
# apart WHAT: no piece of the last run's mask joins two fragments, and (an open crack may cut a
# fragment nearly through) there are at least as many pieces as fragments.
apart() {
    if [ "${joined:-1}" -eq 0 ] && [ "${pieces:-0}" -ge "${frags:-1}" ]; then
        ok "$1: $frags fragments apart in $pieces pieces of the mask"
    else not_ok "$1: '$joined' pieces of the mask join fragments ('$frags' fragments, '$pieces' pieces)"; fi
}
# covers WHAT LO HI: the last run's mean mask value is within [LO, HI].
covers() {
    if [ -n "$cover" ] && awk_true "$cover >= $2 && $cover <= $3"; then ok "$1: cracks cover $cover of the tile"
    else not_ok "$1: cracks cover '$cover' of the tile, expected $2 to $3"; fi
}

# mud at its default (opening_scale 4), seed 11: open gaps over 5-15 % of the tile, every fragment
# apart, at 1024 x 1024 and at 4096 x 4096, and with the layer half as thick (smaller cells).
run mud --seed 11 "$PRESETS/mud.ini"
covers "mud, seed 11" 0.05 0.15
apart "mud, seed 11"
mud_cover=$cover
run mud-4k --seed 11 --size 4096x4096 "$PRESETS/mud.ini"
covers "mud, seed 11, 4096 x 4096" 0.05 0.15
apart "mud, seed 11, 4096 x 4096"
run mud-thin --seed 11 --set material.thickness=0.2 "$PRESETS/mud.ini"
covers "mud, seed 11, thickness 0.2" 0.05 0.15
apart "mud, seed 11, thickness 0.2"

# The width follows the scale: the same simulation drawn at 1 and 2 covers a quarter and a half of
# what it covers at 4 (within 20 %); at 1, the hairlines no longer keep every fragment apart.
run mud-1 --seed 11 --set render.opening_scale=1 "$PRESETS/mud.ini"
cover1=$cover joined1=$joined
run mud-2 --seed 11 --set render.opening_scale=2 "$PRESETS/mud.ini"
cover2=$cover
if [ -n "$cover1" ] && [ -n "$cover2" ] && [ -n "$mud_cover" ] &&
    awk_true "$cover1 < $cover2 && $cover2 < $mud_cover && $cover1 * 4 / $mud_cover > 0.8 && $cover1 * 4 / $mud_cover < 1.2 && $cover2 * 2 / $mud_cover > 0.8 && $cover2 * 2 / $mud_cover < 1.2"
then ok "crack cover grows with opening_scale: $cover1 at 1, $cover2 at 2, $mud_cover at 4"
else not_ok "crack cover at opening_scale 1, 2, 4: '$cover1' '$cover2' '$mud_cover', expected in proportion"; fi
if [ "${joined1:-0}" -gt 0 ]; then ok "at opening_scale 1 hairlines join fragments ($joined1 pieces hold two or more)"
else not_ok "at opening_scale 1: '$joined1' pieces join fragments: the measure sees no joined fragment"; fi

# Sloping walls ([render] wall_slope): the same cracks, mask and fragments, with walls that slope
# from the tops down to the floor over that share of each gap. The mean height over the pixels wholly
# inside the gaps, as a share of the tops' mean, is 0 with upright walls and about s / 2 with slopes
# (a trapezoid section; a little less, as the pixels at a gap's edges, where a slope is highest, are
# left out). mud seed 11 at 2048 x 2048, where its gaps are 6-10 pixels wide.
# slope_run NAME SLOPE UPRIGHT OPTIONS...: renders; sets gap (the share) and, unless NAME is UPRIGHT
# (the run with upright walls), compares its mask and cell ids with that run's.
slope_run() {
    name=$1 slope=$2 upright=$3
    shift 3
    gap=''
    if ! "$FISSURE" -q -o "$tmp/$name" -n c --maps crackmask,cellid,height --set render.wall_slope="$slope" "$@" \
        >/dev/null 2>"$tmp/stderr"; then
        not_ok "$name: fissure runs"; sed 's/^/    /' "$tmp/stderr" | head -5; return
    fi
    set -- $("$STATS" inside "$tmp/$name/c_height.png" "$tmp/$name/c_crackmask.png" 0.999) \
        $("$STATS" inside "$tmp/$name/c_height.png" "$tmp/$name/c_crackmask.png" 0.001)
    [ $# -eq 4 ] && gap=$(awk "BEGIN { print $2 / $3 }")
    if [ "$name" != "$upright" ]; then
        cmp -s "$tmp/$upright/c_crackmask.png" "$tmp/$name/c_crackmask.png" &&
            cmp -s "$tmp/$upright/c_cellid.png" "$tmp/$name/c_cellid.png" &&
            ok "$name: the same crack mask and fragments as with upright walls" ||
            not_ok "$name: the crack mask or the cell ids differ from upright walls'"
    fi
}
mud_slope() { slope_run "mud-slope-$1" "$1" mud-slope-0 --seed 11 --size 2048x2048 "$PRESETS/mud.ini"; }
mud_slope 0
gap0=$gap
mud_slope 1
gap1=$gap
mud_slope 0.6
if [ -n "$gap0" ] && awk_true "$gap0 < 0.02"; then ok "upright walls: the gaps' floor lies at the bottom ($gap0 of the tops' height)"
else not_ok "upright walls: the gaps hold '$gap0' of the tops' height, expected under 0.02"; fi
if [ -n "$gap1" ] && awk_true "$gap1 > 0.35 && $gap1 < 0.55"; then ok "wall_slope 1: V-shaped gaps hold $gap1 of the tops' height"
else not_ok "wall_slope 1: the gaps hold '$gap1' of the tops' height, expected 0.35 to 0.55"; fi
if [ -n "$gap" ] && [ -n "$gap1" ] && awk_true "$gap > 0.45 * $gap1 && $gap < 0.7 * $gap1"; then
    ok "wall_slope 0.6: the gaps hold $gap of the tops' height, 0.6 of a V's about"
else not_ok "wall_slope 0.6: the gaps hold '$gap' of the tops' height, expected 0.45-0.7 of a V's ('$gap1')"; fi
# The shell model slopes its walls too: eggshell drawn 4 times as open (gaps 3-6 pixels wide).
egg_slope() { slope_run "egg-slope-$1" "$1" egg-slope-0 --size 1024x512 --set render.opening_scale=4 "$PRESETS/eggshell.ini"; }
egg_slope 0
gap0=$gap
egg_slope 1
if [ -n "$gap0" ] && [ -n "$gap" ] && awk_true "$gap0 < 0.02 && $gap > 0.3 && $gap < 0.55"; then
    ok "eggshell: the gaps hold $gap0 of the tops' height with upright walls, $gap as Vs"
else not_ok "eggshell: the gaps hold '$gap0' of the tops' height upright, '$gap' as Vs: expected under 0.02, 0.3-0.55"; fi

# The shell model draws its openings to the same scale ([shell] gap_scale times opening_scale).
run egg-1 --size 512x256 "$PRESETS/eggshell.ini"
egg1=$cover
run egg-2 --size 512x256 --set render.opening_scale=2 "$PRESETS/eggshell.ini"
if [ -n "$egg1" ] && [ -n "$cover" ] && awk_true "$cover > 1.5 * $egg1"; then
    ok "eggshell: cracks cover $egg1 at opening_scale 1, $cover at 2"
else not_ok "eggshell: cracks cover '$egg1' at opening_scale 1, '$cover' at 2, expected at least 1.5 times"; fi
finish
