# Bad presets: every tests/bad-presets/*.ini must exit 65, name its file and line, say what was wrong, write nothing.
# Each file's first line states what to expect: "# expect-line: LINE expect: TEXT", where TEXT is part of the message.
. "$top_srcdir/tests/lib.sh"

n=0
for preset in "$top_srcdir"/tests/bad-presets/*.ini; do
    [ -f "$preset" ] || continue
    n=$((n + 1))
    base=$(basename "$preset")
    header=$(sed -n 1p "$preset")
    line=$(printf '%s\n' "$header" | sed -n 's/^# expect-line: \([0-9][0-9]*\) expect: .*$/\1/p')
    expect=$(printf '%s\n' "$header" | sed -n 's/^# expect-line: [0-9][0-9]* expect: //p')
    if [ -z "$line" ] || [ -z "$expect" ]; then
        not_ok "$base: its first line must read '# expect-line: LINE expect: TEXT'"
        continue
    fi
    out="$tmp/out-$n"
    "$FISSURE" "$preset" -o "$out" >"$tmp/stdout" 2>"$tmp/stderr"
    status=$?
    problems=
    [ "$status" -eq 65 ] || problems="$problems; exit status $status, expected 65"
    grep -q "^fissure: " "$tmp/stderr" || problems="$problems; no 'fissure: ' message on stderr"
    grep -qF "$base:$line: " "$tmp/stderr" || problems="$problems; stderr does not name '$base:$line:'"
    grep -qF -- "$expect" "$tmp/stderr" || problems="$problems; stderr does not say \"$expect\""
    if [ -e "$out" ] && [ -n "$(ls -A "$out")" ]; then
        problems="$problems; files were written to the output directory"
    fi
    if [ -z "$problems" ]; then
        ok "$base: exit 65, error at line $line"
    else
        not_ok "$base${problems}"
        sed 's/^/    stderr: /' "$tmp/stderr" | head -3
    fi
done
if [ "$n" -ge 12 ]; then ok "$n bad presets checked"; else not_ok "only $n bad presets found, expected at least 12"; fi
finish
