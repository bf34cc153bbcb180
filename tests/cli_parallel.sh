# Batches with GNU Parallel, as the README's recipe runs them: `parallel -j 2` over the job numbers
# of a jobs file writes, for every job, the outputs of the same job run on its own, byte for byte
# (sidecar timings aside), and the same outputs as the runs made alone with the options that
# --list-jobs prints; --mesh with {name} gives each job its own OBJ and MTL.
. "$top_srcdir/tests/lib.sh"
need parallel
cat >"$tmp/jobs.txt" <<'EOJ'
# PRESET SEED NAME [SECTION.KEY=VALUE]...
voronoi-tile 11 tile-a mesh.elements=40
voronoi-tile 12 tile-b mesh.elements=50 render.roughness=0.5
voronoi-trunk 13 trunk-c mesh.elements=40
voronoi-sphere 14 sphere-d mesh.elements=40
EOJ
COMMON="-q --size 48x48"
n=$("$FISSURE" --list-jobs "$tmp/jobs.txt" | wc -l)
[ "$n" -eq 4 ] && ok "--list-jobs lists the 4 jobs" || not_ok "--list-jobs lists the 4 jobs: $n"
expect_status 0 "parallel -j 2 runs the batch" \
    parallel --will-cite --halt now,fail=1 -j 2 "$FISSURE" $COMMON -o "$tmp/parallel" \
    --mesh "$tmp/parallel/{name}.obj" --job "$tmp/jobs.txt:{}" \
    ::: $(seq "$n")
for k in $(seq "$n"); do
    "$FISSURE" $COMMON -o "$tmp/serial" --mesh "$tmp/serial/{name}.obj" --job "$tmp/jobs.txt:$k" >/dev/null
done
"$FISSURE" --list-jobs "$tmp/jobs.txt" | while IFS="$(printf '\t')" read -r k name opts; do
    "$FISSURE" $COMMON -o "$tmp/alone" --mesh "$tmp/alone/$name.obj" $opts >/dev/null
done
for other in serial alone; do
    if sh "$top_srcdir/tests/compare-outputs.sh" "$tmp/parallel" "$tmp/$other" >"$tmp/cmp"; then
        ok "the batch's outputs are those of the $other runs: $(tail -1 "$tmp/cmp")"
    else
        not_ok "the batch's outputs are those of the $other runs"; sed 's/^/    /' "$tmp/cmp" | head
    fi
done
[ "$(ls "$tmp/parallel" | wc -l)" -eq 48 ] && [ -f "$tmp/parallel/trunk-c.mtl" ] && ok "48 files, 12 per job (OBJ and MTL named after the job)" \
    || not_ok "48 files: $(ls "$tmp/parallel" | wc -l)"
finish
