# Jobs files and machine-readable progress: --job FILE:N runs job N as the same run made alone
# would (preset paths relative to the jobs file); bad files, bad lines and bad numbers fail with the
# documented status and a message naming the file and line, before anything is written;
# --progress json writes one JSON object a line (phase, fraction, message, elapsed), ending with
# "done" or "failed".
. "$top_srcdir/tests/lib.sh"
need python3
COMMON="-q --size 32x32"
mkdir -p "$tmp/batch/presets" "$tmp/elsewhere"
cp "$PRESETS/voronoi-tile.ini" "$tmp/batch/presets/my-tile.ini"
cat >"$tmp/batch/jobs.txt" <<'EOJ'
# comment lines and blank lines are not jobs
   # not even indented

presets/my-tile.ini 5 mine mesh.elements=30
voronoi-tile 6 named mesh.elements=30	voronoi.warp=0.2
EOJ
# a preset path with a '/' is relative to the jobs file, wherever fissure runs
expect_status 0 "--job FILE:1 runs from another directory" sh -c \
    "cd '$tmp/elsewhere' && '$FISSURE' $COMMON -o out --job ../batch/jobs.txt:1"
[ -f "$tmp/elsewhere/out/mine.json" ] && ok "job 1 wrote mine.json" || not_ok "job 1 wrote mine.json"
expect_status 0 "--job FILE:2 (tab-separated override)" "$FISSURE" $COMMON -o "$tmp/job" --job "$tmp/batch/jobs.txt:2"
expect_status 0 "the same run alone" "$FISSURE" $COMMON -o "$tmp/alone" -s 6 -n named --set mesh.elements=30 \
    --set voronoi.warp=0.2 voronoi-tile
sh "$top_srcdir/tests/compare-outputs.sh" "$tmp/job" "$tmp/alone" >"$tmp/cmp" \
    && ok "job 2 writes what the run alone writes: $(tail -1 "$tmp/cmp")" || not_ok "job 2 = the run alone"
[ "$(json_get "$tmp/job/named.json" seed)" = 6 ] && [ "$(json_get "$tmp/job/named.json" parameters.voronoi.warp)" = 0.2 ] \
    && ok "the sidecar has the job's seed and override" || not_ok "the sidecar has the job's seed and override"
printf '1\tmine\t-s 5 -n mine --set mesh.elements=30 %s\n2\tnamed\t-s 6 -n named --set mesh.elements=30 --set voronoi.warp=0.2 voronoi-tile\n' \
    "$tmp/batch/presets/my-tile.ini" >"$tmp/want"
"$FISSURE" --list-jobs "$tmp/batch/jobs.txt" >"$tmp/got" && cmp -s "$tmp/want" "$tmp/got" \
    && ok "--list-jobs prints each job as the options of the run alone" || { not_ok "--list-jobs"; cat "$tmp/got"; }

# expect_error STATUS MESSAGE_PATTERN DESCRIPTION ARGS...: fails as documented, writing nothing.
expect_error() {
    st=$1 pattern=$2 what=$3; shift 3
    rm -rf "$tmp/none"
    expect_status "$st" "$what" "$FISSURE" $COMMON -o "$tmp/none" "$@"
    grep -q -- "$pattern" "$tmp/stderr" && ok "  the message: $(head -1 "$tmp/stderr")" \
        || not_ok "  the message matches '$pattern': $(head -1 "$tmp/stderr")"
    [ ! -e "$tmp/none" ] || not_ok "  nothing written"
}
j="$tmp/batch/jobs.txt"
expect_error 64 "jobs.txt has 2 jobs, numbered 1 to 2" "job 3 of 2" --job "$j:3"
expect_error 64 "expected FILE:N" "job 0" --job "$j:0"
expect_error 64 "expected FILE:N" "no job number" --job "$j"
expect_error 64 "expected FILE:N" "a job number that is not one" --job "$j:two"
expect_error 64 "expected no PRESET argument" "--job and a PRESET" --job "$j:1" voronoi-tile
expect_error 64 "expected no --seed or --name" "--job and --seed" -s 3 --job "$j:1"
expect_error 64 "expected no --seed or --name" "--job and --name" -n x --job "$j:1"
expect_error 66 "nope.txt: cannot open the jobs file" "a missing jobs file" --job "$tmp/nope.txt:1"
bad() { # NAME CONTENT: a jobs file
    printf '%b' "$2" >"$tmp/$1.txt"
}
bad seed 'voronoi-tile 1 a\nvoronoi-tile -2 b\n'
expect_error 65 "seed.txt:2: SEED: expected a non-negative integer, got '-2'" "a bad seed, on another line" \
    --job "$tmp/seed.txt:1"
bad short '# header\nvoronoi-tile 1\n'
expect_error 65 "short.txt:2: expected PRESET SEED NAME" "a line with two fields" --job "$tmp/short.txt:1"
bad slash 'voronoi-tile 1 out/a\n'
expect_error 65 "slash.txt:1: NAME: expected a file name prefix without '/'" "a name with a '/'" \
    --job "$tmp/slash.txt:1"
bad override 'voronoi-tile 1 a mesh.elements 30\n'
expect_error 65 "override.txt:1: expected an override SECTION.KEY=VALUE, got 'mesh.elements'" \
    "an override without '='" --job "$tmp/override.txt:1"
bad dup 'voronoi-tile 1 a\n\nvoronoi-tile 2 a\n'
expect_error 65 "dup.txt:3: NAME 'a' is already the name of the job on line 1" "two jobs of one name" \
    --job "$tmp/dup.txt:1"
bad empty '# nothing\n\n'
expect_error 65 "empty.txt: no job in the file" "a file without jobs" --job "$tmp/empty.txt:1"
bad key 'voronoi-tile 1 a mesh.nonsense=1\n'
expect_error 65 "key.txt:1: --set mesh.nonsense: unknown key" "an unknown preset key in a job" --job "$tmp/key.txt:1"

# --progress json
expect_status 0 "--progress json" "$FISSURE" $COMMON -o "$tmp/p" --set mesh.elements=200 --progress json mud
python3 - "$tmp/stderr" <<'EOP' >"$tmp/json-check" 2>&1 && ok "$(cat "$tmp/json-check")" || { not_ok "progress lines"; cat "$tmp/json-check"; }
import json, sys
lines = open(sys.argv[1]).read().splitlines()
objs = [json.loads(l) for l in lines]
assert len(objs) >= 4, lines
last = 0.0
for o in objs:
    assert list(o) == ["phase", "fraction", "message", "elapsed"], o
    assert o["fraction"] is None or 0.0 <= o["fraction"] <= 1.0, o
    assert isinstance(o["message"], str) and o["elapsed"] >= last, o
    last = o["elapsed"]
phases = [o["phase"] for o in objs]
assert "wedge" in phases and "render" in phases, phases
assert any(o["fraction"] is not None and o["fraction"] > 0 for o in objs if o["phase"] == "wedge"), objs
assert objs[-1]["phase"] == "done" and objs[-1]["fraction"] == 1.0, objs[-1]
print("%d progress lines, each one JSON object (phases %s), the last one done" % (len(objs), " ".join(dict.fromkeys(phases))))
EOP
expect_status 65 "--progress json on a failing run" "$FISSURE" $COMMON -o "$tmp/p2" --set mesh.elements=-5 --progress json mud
grep '^{' "$tmp/stderr" | tail -1 | python3 -c 'import json, sys; o = json.loads(sys.stdin.read()); assert o["phase"] == "failed" and o["fraction"] is None and "elements" in o["message"], o' 2>/dev/null \
    && ok "the last progress line says failed, with the error" || not_ok "the last progress line says failed: $(tail -1 "$tmp/stderr")"
expect_status 64 "--progress with a bad mode" "$FISSURE" --progress loud voronoi-tile
finish
