# Batches on a real Slurm: a one-node cluster on localhost (munged, slurmctld, slurmd, configured
# in a scratch directory, started and stopped here; root, as slurmd must be) runs a 4-task array of
# contrib/slurm/fissure-array.sh over a jobs file; every task ends with exit code 0 and its outputs
# are byte-identical (sidecar timings aside) to the same job run here, and to the same run made
# alone with the options --list-jobs prints.
. "$top_srcdir/tests/lib.sh"
need sbatch squeue scontrol sinfo slurmctld slurmd munged
[ "$(id -u)" -eq 0 ] || missing "root (slurmd runs as root)"
s="$tmp/slurm"
mkdir -p "$s/state" "$s/spool" "$s/munge"
chmod 700 "$s/munge"
pids=
stop() { # the daemons started here, by their pids
    for p in $pids; do kill "$p" 2>/dev/null; done
    for p in $pids; do
        for _ in 1 2 3 4 5 6 7 8 9 10; do kill -0 "$p" 2>/dev/null || break; sleep 0.5; done
        kill -9 "$p" 2>/dev/null
    done
    rm -rf "$tmp"
}
trap stop EXIT
# dump_logs: what the daemons said, when something went wrong
dump_logs() { for f in "$s"/*.log; do echo "---- $f"; tail -15 "$f"; done | sed 's/^/    /'; }

# munge with its own key and socket
dd if=/dev/urandom of="$s/munge/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$s/munge/munge.key"
munged --force --socket="$s/munge/munge.socket" --key-file="$s/munge/munge.key" \
    --pid-file="$s/munge/munged.pid" --log-file="$s/munged.log" --seed-file="$s/munge/munge.seed" \
    || { not_ok "munged starts"; dump_logs; finish; }
for _ in $(seq 50); do [ -s "$s/munge/munged.pid" ] && break; sleep 0.1; done
pids="$(cat "$s/munge/munged.pid")"
ok "munged runs"

host=$(hostname -s)
# ports from the pid, away from the usual 6817/6818 so that a real cluster on the machine is not hit
port=$((20000 + $$ % 20000 * 2))
cat >"$s/slurm.conf" <<EOC
ClusterName=fissuretest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$s/munge/munge.socket
StateSaveLocation=$s/state
SlurmdSpoolDir=$s/spool
SlurmctldPidFile=$s/slurmctld.pid
SlurmdPidFile=$s/slurmd.pid
SlurmctldLogFile=$s/slurmctld.log
SlurmdLogFile=$s/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=fissure Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOC
SLURM_CONF="$s/slurm.conf"
export SLURM_CONF
slurmctld -D -f "$s/slurm.conf" >"$s/slurmctld.out" 2>&1 &
pids="$pids $!"
slurmd -D -f "$s/slurm.conf" -N "$host" >"$s/slurmd.out" 2>&1 &
pids="$pids $!"
up=false
for _ in $(seq 60); do
    [ "$(sinfo -h -n "$host" -o %t 2>/dev/null)" = idle ] && { up=true; break; }
    sleep 0.5
done
$up && ok "a one-node Slurm cluster is up ($host, idle)" || { not_ok "the Slurm cluster comes up"; dump_logs; finish; }

# The batch: four small jobs, two presets, overrides.
cat >"$tmp/jobs.txt" <<'EOJ'
# fissure jobs: PRESET SEED NAME [SECTION.KEY=VALUE]...
voronoi-tile 1 tile-1 mesh.elements=40

voronoi-tile 2 tile-2 mesh.elements=60 voronoi.warp=0.3
voronoi-trunk 3 trunk-3 mesh.elements=40
voronoi-sphere 4 sphere-4 mesh.elements=40
EOJ
COMMON="-q --size 48x48"
id=$(cd "$tmp" && sbatch --parsable --array=1-4 --output="$s/task-%a.log" \
    "$top_srcdir/contrib/slurm/fissure-array.sh" "$tmp/jobs.txt" $COMMON -o "$tmp/slurm-out" 2>"$s/sbatch.err")
[ -n "$id" ] && ok "sbatch --array=1-4 accepted the array (job $id)" || { not_ok "sbatch"; cat "$s/sbatch.err"; finish; }
done_=false
for _ in $(seq 240); do
    [ -z "$(squeue -h -j "$id" 2>/dev/null)" ] && { done_=true; break; }
    sleep 0.5
done
$done_ && ok "the array finished" || { not_ok "the array finished within 120 s"; squeue; dump_logs; }
codes=$(scontrol -o show job "$id" 2>/dev/null | grep -o 'ExitCode=[0-9:]*' | sort | uniq -c | sed 's/^ *//')
[ "$codes" = "4 ExitCode=0:0" ] && ok "its 4 tasks exited 0" \
    || { not_ok "its 4 tasks exited 0: $codes"; cat "$s"/task-*.log | head -20; dump_logs; }

# The same jobs here, and alone.
for n in 1 2 3 4; do
    "$FISSURE" $COMMON -o "$tmp/local" --job "$tmp/jobs.txt:$n" >/dev/null 2>"$tmp/stderr" || cat "$tmp/stderr"
done
"$FISSURE" --list-jobs "$tmp/jobs.txt" | while IFS="$(printf '\t')" read -r n name opts; do
    "$FISSURE" $COMMON -o "$tmp/alone" $opts >/dev/null
done
if sh "$top_srcdir/tests/compare-outputs.sh" "$tmp/slurm-out" "$tmp/local" >"$tmp/cmp"; then
    ok "the array's outputs are those of the same jobs run here: $(tail -1 "$tmp/cmp")"
else
    not_ok "the array's outputs are those of the same jobs run here"; sed 's/^/    /' "$tmp/cmp" | head
fi
if sh "$top_srcdir/tests/compare-outputs.sh" "$tmp/slurm-out" "$tmp/alone" >"$tmp/cmp"; then
    ok "and those of the runs made alone: $(tail -1 "$tmp/cmp")"
else
    not_ok "and those of the runs made alone"; sed 's/^/    /' "$tmp/cmp" | head
fi
[ "$(ls "$tmp/slurm-out" | wc -l)" -eq 40 ] && ok "40 files: 10 per job" || not_ok "40 files: $(ls "$tmp/slurm-out" | wc -l)"
finish
