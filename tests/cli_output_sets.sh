# Whole output sets (issue 16): the outputs are checked before the run, a signal removes the
# staged files, a failed commit leaves nothing of its run, and at no moment of a run killed with
# SIGKILL does a sidecar sit beside files of another run.
#
# The reader's rule (fissure(1), OUTPUT SETS): a set is whole when its sidecar NAME.json exists;
# then every file its "files" list names exists and is of the sidecar's run. Files it does not list
# are not part of the set, whatever their names.
. "$top_srcdir/tests/lib.sh"
shim="$(dirname "$FISSURE")/tests/kill_rename.so"
small="--size 48x48 --set mesh.elements=500"

# ---- the outputs are checked before the run (73 for the directory, 64 for the name) ----
printf 'x' > "$tmp/plain"
expect_status 73 "-o naming a regular file: exit 73" "$FISSURE" -v -o "$tmp/plain" $small "$PRESETS/mud.ini"
grep -q "plain: output path is not a directory" "$tmp/stderr" && ok "the message names the path" \
    || not_ok "the message names the path"
grep -q "sampled" "$tmp/stderr" && not_ok "-o: checked before the run (no sampling)" \
    || ok "-o: checked before the run (no sampling)"
expect_status 73 "-o below a regular file: exit 73" "$FISSURE" -v -o "$tmp/plain/sub" $small "$PRESETS/mud.ini"
grep -q "sampled" "$tmp/stderr" && not_ok "-o below a file: checked before the run" \
    || ok "-o below a file: checked before the run"
expect_status 73 "--mesh below a regular file: exit 73" "$FISSURE" -v -o "$tmp/m" --mesh "$tmp/plain/x.obj" \
    $small "$PRESETS/mud.ini"
grep -q "sampled" "$tmp/stderr" && not_ok "--mesh: checked before the run" || ok "--mesh: checked before the run"
[ ! -e "$tmp/m" ] && ok "nothing created" || not_ok "nothing created"

long=$(printf '%0300d' 0)
expect_status 64 "-n of 300 bytes: usage error" "$FISSURE" -o "$tmp/n" -n "$long" $small "$PRESETS/mud.ini"
grep -q -- "--name: expected a file name prefix of 1 to 128 bytes" "$tmp/stderr" && ok "the message gives the limit" \
    || not_ok "the message gives the limit"
nl='a
b'
expect_status 64 "-n with a newline: usage error" "$FISSURE" -o "$tmp/n" -n "$nl" $small "$PRESETS/mud.ini"
expect_status 64 "-n with a byte that is not UTF-8: usage error" "$FISSURE" -o "$tmp/n" -n "$(printf 'a\377b')" \
    $small "$PRESETS/mud.ini"
expect_status 64 "-n with an overlong UTF-8 '/': usage error" "$FISSURE" -o "$tmp/n" -n "$(printf 'a\300\257b')" \
    $small "$PRESETS/mud.ini"
expect_status 64 "-o with a newline: usage error" "$FISSURE" -o "$tmp/$nl" $small "$PRESETS/mud.ini"
[ ! -e "$tmp/n" ] && ok "bad names write nothing" || not_ok "bad names write nothing"
# The longest name, with the longest suffixes (frames, the glTF packed map), fits every file name.
n128=$(printf 'é%0126d' 0)
expect_status 0 "-n of 128 bytes of UTF-8 with frames and --target gltf" "$FISSURE" -q -o "$tmp/n128" -n "$n128" \
    --frames 1 --target gltf --size 32x32 --set mesh.elements=300 "$PRESETS/mud-springs.ini"
[ "$(wc -l < "$tmp/stdout")" -eq "$(ls "$tmp/n128" | wc -l)" ] && ok "one path a line for each file written" \
    || not_ok "one path a line for each file written"

# ---- a termination signal removes the staged files ----
# The frames are staged while the model runs, so a signal during the run meets temporary files.
# (env --default-signal: a background job of a script starts with SIGINT ignored.)
for sig in TERM INT HUP; do
    d="$tmp/sig-$sig"
    env --default-signal=INT "$FISSURE" -q -o "$d" --frames 40 --size 128x128 --set mesh.elements=2500 \
        "$PRESETS/mud-springs.ini" >/dev/null 2>&1 &
    pid=$!
    i=0
    while [ $i -lt 600 ] && ! ls -A "$d" 2>/dev/null | grep -q '\.tmp-'; do sleep 0.1; i=$((i + 1)); done
    staged=$(ls -A "$d" 2>/dev/null | grep -c '\.tmp-')
    kill -s "$sig" "$pid"
    wait "$pid"
    status=$?
    left=$(ls -A "$d" 2>/dev/null | wc -l)
    if [ "$staged" -gt 0 ] && [ "$left" -eq 0 ]; then
        ok "SIG$sig with $staged staged files: none left (exit status $status)"
    else
        not_ok "SIG$sig with $staged staged files: $left files left"; ls -A "$d" | head -3 | sed 's/^/    /'
    fi
    [ "$status" -gt 128 ] && ok "SIG$sig ends the run by the signal" || not_ok "SIG$sig: exit status $status"
done

# The file size limit: SIGXFSZ is blocked, so the write fails with a reason and the run cleans up.
(ulimit -f 20; exec "$FISSURE" -q -o "$tmp/fsize" --size 256x256 --set mesh.elements=300 \
    "$PRESETS/voronoi-tile.ini") >/dev/null 2>"$tmp/stderr"
status=$?
[ "$status" -eq 74 ] && grep -q "cannot write image: File too large" "$tmp/stderr" \
    && ok "past the file size limit: exit 74, File too large" || { not_ok "past the file size limit: exit status $status"; head -2 "$tmp/stderr"; }
[ -z "$(ls -A "$tmp/fsize" 2>/dev/null)" ] && ok "past the file size limit: nothing left" \
    || not_ok "past the file size limit: files left"

# ---- a failed commit leaves nothing of its run and no sidecar beside another run's files ----
d="$tmp/fail"
"$FISSURE" -q -o "$d" -n s -s 1 $small "$PRESETS/mud.ini" >/dev/null 2>&1
cp -R "$d" "$tmp/fail-old"
rm "$d/s_crackdist.png" && mkdir "$d/s_crackdist.png"   # an obstacle: renaming onto it fails
expect_status 74 "a commit that cannot move a file: exit 74" "$FISSURE" -q -o "$d" -n s -s 2 $small "$PRESETS/mud.ini"
grep -q "s_crackdist.png: cannot move into place: Is a directory" "$tmp/stderr" && ok "the message says why" \
    || not_ok "the message says why"
[ ! -e "$d/s.json" ] && ok "no sidecar is left (the old one went before the first file moved)" \
    || not_ok "a sidecar is left beside files of another run"
for f in s_height.png s_normal.png s_basecolor.png s_crackmask.png; do
    [ ! -e "$d/$f" ] && ok "the new run's $f is removed again" || not_ok "the new run's $f is left"
done
ls -A "$d" | grep -q '\.tmp-' && not_ok "temporary files are left" || ok "no temporary file is left"
cmp -s "$d/s_cellid.png" "$tmp/fail-old/s_cellid.png" && ok "files the run did not reach are untouched" \
    || not_ok "files the run did not reach are untouched"

# ---- the kill test ----
# whole DIR: prints A or B when DIR holds a whole set of that reference run (tests/compare-outputs.sh
# compares the sidecar, all but its timings, and every file it lists), "none" when it holds no
# sidecar, and MIXED when a sidecar sits beside a file that is not of its run.
whole() {
    [ -f "$1/k.json" ] || { echo none; return; }
    seed=$(json_get "$1/k.json" seed)
    case "$seed" in 1) ref=$tmp/ref-A; r=A ;; 2) ref=$tmp/ref-B; r=B ;; *) echo "MIXED (seed '$seed')"; return ;; esac
    rm -rf "$tmp/listed" && mkdir "$tmp/listed"
    sed -n '/^  "files": \[/,/^  \]/p' "$1/k.json" | sed -n 's/^ *"\(.*\)",\{0,1\}$/\1/p' > "$tmp/list"
    [ -s "$tmp/list" ] || { echo "MIXED (no file list)"; return; }
    cp "$1/k.json" "$tmp/listed/"
    while read -r f; do cp "$1/$f" "$tmp/listed/" 2>/dev/null; done < "$tmp/list"
    rm -rf "$tmp/ref-listed" && mkdir "$tmp/ref-listed"
    cp "$ref/k.json" "$tmp/ref-listed/"
    while read -r f; do cp "$ref/$f" "$tmp/ref-listed/"; done < "$tmp/list"
    if sh "$top_srcdir/tests/compare-outputs.sh" "$tmp/ref-listed" "$tmp/listed" >/dev/null; then echo "$r"
    else echo "MIXED (files of another run beside the sidecar of run $r)"; fi
}
kopts="-n k --frames 2 --size 64x64 --set mesh.elements=600"
start=$(date +%s%N)
"$FISSURE" -q -o "$tmp/ref-B" -s 2 $kopts "$PRESETS/mud.ini" >/dev/null 2>&1
run_ms=$(( ($(date +%s%N) - start) / 1000000 ))
"$FISSURE" -q -o "$tmp/ref-A" -s 1 $kopts "$PRESETS/mud.ini" >/dev/null 2>&1
[ "$(whole "$tmp/ref-A")" = A ] && [ "$(whole "$tmp/ref-B")" = B ] && ok "the reference runs are whole sets" \
    || not_ok "the reference runs are whole sets"
# the commit renames every listed file, then the sidecar
n_renames=$(( $(sed -n '/^  "files": \[/,/^  \]/p' "$tmp/ref-B/k.json" | grep -c '^    "') + 1 ))
moments=0 mixed=0 summary=
# kill_at WHAT CMD...: run B over a copy of run A's set, killed as CMD arranges; checks the set.
kill_at() {
    what=$1; shift
    d="$tmp/kill"
    rm -rf "$d" && cp -R "$tmp/ref-A" "$d"
    "$@"
    got=$(whole "$d")
    temps=$(ls -A "$d" | grep -c '\.tmp-')
    moments=$((moments + 1))
    summary="$summary $got"
    case "$got" in
    MIXED*) mixed=$((mixed + 1)); not_ok "SIGKILL $what: $got" ;;
    *) ok "SIGKILL $what: set $got, $temps temporary files left" ;;
    esac
}
timed() { # FRACTION_PERMILLE: SIGKILL at that fraction of the reference run's time
    "$FISSURE" -q -o "$d" -s 2 $kopts "$PRESETS/mud.ini" >/dev/null 2>&1 &
    pid=$!
    sleep "$(awk -v ms="$run_ms" -v f="$1" 'BEGIN { printf "%.3f", ms * f / 1e6 }')"
    kill -KILL "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
}
at_rename() { # N: SIGKILL before the Nth rename of the commit (after it, for -N)
    FISSURE_KILL_RENAME=$1 LD_PRELOAD="$shim" "$FISSURE" -q -o "$d" -s 2 $kopts "$PRESETS/mud.ini" >/dev/null 2>&1
}
for f in 100 200 300 400 500 600 700 800 900 950; do kill_at "at $f/1000 of the run" timed "$f"; done
for k in 1 2 3 5 7 9 11 12 "$n_renames" "-$n_renames"; do
    case "$k" in
    -*) kill_at "mid-commit, after its last rename (of $n_renames)" at_rename "$k" ;;
    *) kill_at "mid-commit, before rename $k of $n_renames" at_rename "$k" ;;
    esac
done
[ "$moments" -eq 20 ] && [ "$mixed" -eq 0 ] && ok "kill test: 20 moments, never a sidecar beside another run's files:$summary" \
    || not_ok "kill test: $moments moments, $mixed with a sidecar beside another run's files"
finish
