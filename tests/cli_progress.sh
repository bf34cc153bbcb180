# Progress on stderr: a line rewritten in place on a terminal (through script(1)), nothing otherwise.
. "$top_srcdir/tests/lib.sh"
args="-o $tmp/p -n p --size 64x64 --set mesh.elements=400 --frames 2 --maps crackmask $PRESETS/mud-springs.ini"

# Not a terminal: log lines only, no carriage return, no escape code.
expect_status 0 "a run with stderr in a file" "$FISSURE" $args
if grep -q "$(printf '\r')" "$tmp/stderr" || grep -q "$(printf '\033')" "$tmp/stderr"; then
    not_ok "no progress line when stderr is not a terminal"
else ok "no progress line when stderr is not a terminal"; fi
grep -q '^fissure: done in' "$tmp/stderr" && ok "log lines still go to stderr" || not_ok "log lines still go to stderr"

if ! command -v script >/dev/null 2>&1 || ! script -qec true /dev/null >/dev/null 2>&1; then
    ok "# SKIP script(1) is not available: terminal progress not checked"
    finish
fi

# A terminal: the progress line shows phase, percentage, simulated time, fractures, elapsed and ETA,
# is rewritten with \r, and is cleared before the file list goes to stdout.
script -qec "\"$FISSURE\" $args" /dev/null >"$tmp/tty" 2>&1
status=$?
[ "$status" -eq 0 ] && ok "the run on a terminal succeeds" || not_ok "the run on a terminal succeeds (exit $status)"
tr '\r' '\n' < "$tmp/tty" > "$tmp/lines"
grep -q 'springs .*%  t = .*springs broken .*elapsed, ETA ' "$tmp/lines" \
    && ok "progress shows the phase, the simulated time, the fractures, elapsed time and ETA" \
    || not_ok "progress shows the phase, the simulated time, the fractures, elapsed time and ETA"
grep -q 'frames .*frame 2 of 2' "$tmp/lines" && ok "progress shows the frames" || not_ok "progress shows the frames"
n=$(tr -cd '\r' < "$tmp/tty" | wc -c)
[ "$n" -ge 5 ] && ok "the line is rewritten in place ($n carriage returns)" || not_ok "the line is rewritten in place ($n)"
grep -a -q "^$tmp/p/p_crackmask.png$(printf '\r')\$" "$tmp/tty" \
    && ok "the progress line is cleared before the file list" || not_ok "the progress line is cleared before the file list"

# Quiet: nothing but the file list, even on a terminal.
script -qec "\"$FISSURE\" -q $args" /dev/null >"$tmp/quiet" 2>&1
if grep -q 'elapsed' "$tmp/quiet" || grep -q "$(printf '\033')" "$tmp/quiet"; then not_ok "-q shows no progress"
else ok "-q shows no progress"; fi
finish
