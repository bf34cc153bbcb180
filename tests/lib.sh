# Shared helpers of the shell tests: a scratch directory, outcome counting, PNG header checks.
# The harness exports FISSURE (the binary) and top_srcdir (the source tree).
set -u
: "${FISSURE:?FISSURE must name the fissure binary}"
: "${top_srcdir:?top_srcdir must name the source tree}"
PRESETS="$top_srcdir/presets"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/fissure-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
failures=0

ok() { printf 'ok %s\n' "$*"; }
not_ok() { printf 'FAIL %s\n' "$*"; failures=$((failures + 1)); }
# expect_status WANT DESCRIPTION CMD...: runs CMD, checks its exit status, keeps stdout/stderr in $tmp.
expect_status() {
    want=$1; what=$2; shift 2
    "$@" >"$tmp/stdout" 2>"$tmp/stderr"; got=$?
    if [ "$got" -eq "$want" ]; then ok "$what"; else
        not_ok "$what: exit status $got, expected $want"; sed 's/^/    stderr: /' "$tmp/stderr" | head -5
    fi
}
# png_header FILE: prints "WIDTH HEIGHT BITDEPTH COLORTYPE" from the IHDR chunk.
png_header() {
    od -An -tu1 -j16 -N10 "$1" | awk '{ printf "%d %d %d %d\n", \
        (($1*256+$2)*256+$3)*256+$4, (($5*256+$6)*256+$7)*256+$8, $9, $10 }'
}
# expect_png FILE W H DEPTH COLORTYPE (0 grey, 2 RGB)
expect_png() {
    if [ ! -f "$1" ]; then not_ok "$1 exists"; return; fi
    got=$(png_header "$1")
    if [ "$got" = "$2 $3 $4 $5" ]; then ok "$(basename "$1") is ${2}x$3, $4-bit, colour type $5"
    else not_ok "$(basename "$1"): header '$got', expected '$2 $3 $4 $5'"; fi
}
# json_get FILE PATH: prints the value at PATH (keys joined by dots: maps.height.height_min_cm) of a
# sidecar as fissure writes it (jansson, one key a line), without quotes; prints nothing when missing.
json_get() {
    awk -v want="$2" '
        function key(line) { sub(/^[ \t]*"/, "", line); sub(/".*/, "", line); return line }
        /^[ \t]*"[^"]*": *\{[ \t]*$/ { path = path "." key($0); next }
        /^[ \t]*\},?[ \t]*$/ { sub(/\.[^.]*$/, "", path); next }
        /^[ \t]*"[^"]*": / {
            v = $0; sub(/^[ \t]*"[^"]*": */, "", v); sub(/,[ \t]*$/, "", v); gsub(/^"|"$/, "", v)
            if (substr(path "." key($0), 2) == want) { print v; exit }
        }' "$1"
}
# fractures SIDECAR: the run's fracture count; fragments CRACKS.json: the crack graph's fragments
fractures() { sed -n 's/^ *"fractures": *\([0-9]*\),*$/\1/p' "$1" | head -n 1; }
fragments() { sed -n 's/^ *"fragments": *\([0-9]*\),*$/\1/p' "$1" | head -n 1; }
# awk_true EXPR: exit 0 if the awk expression is true (compares decimals)
awk_true() { awk "BEGIN { exit !($1) }"; }
finish() {
    if [ "$failures" -eq 0 ]; then exit 0; fi
    printf '%d failure(s)\n' "$failures"; exit 1
}
# in_ci: whether this is a CI run (.ci/run sets CI=1; CI services set CI=true).
in_ci() { case "${CI:-}" in "" | 0 | false | no) return 1 ;; *) return 0 ;; esac; }
# missing WHAT: a client the test drives is not installed: the test fails in CI, where .ci/setup
# installs it, and is skipped (exit 77) on a developer's machine without it.
missing() {
    if in_ci; then printf 'FAIL %s is missing (.ci/setup installs it)\n' "$1"; exit 1; fi
    printf 'SKIP: %s is not installed (.ci/setup installs it)\n' "$1"; exit 77
}
# need COMMAND...: each COMMAND must be on PATH (see missing).
need() {
    for c in "$@"; do command -v "$c" >/dev/null 2>&1 || missing "$c"; done
}
