#!/bin/sh
# A Slurm job array of fissure runs: task N of the array runs job N of a jobs file (fissure(1),
# JOBS FILES). Submit one task per job:
#
#     sbatch --array=1-$(fissure --list-jobs jobs.txt | wc -l) contrib/slurm/fissure-array.sh \
#         jobs.txt -o out --size 2048x2048
#
# The arguments after the jobs file are fissure options common to every job: the output
# directory, the map size, and --mesh or --asset paths with {name} in them (out/{name}.glb), which
# the job's output name replaces. Each task writes what the same run made alone would write, byte
# for byte (the sidecar's wall-clock seconds aside), so tasks can run on any node in any order.
# FISSURE names the binary (default: fissure on PATH); a task runs on the CPUs Slurm gave it.
#SBATCH --job-name=fissure
#SBATCH --cpus-per-task=1
#SBATCH --output=fissure-%A_%a.log
set -eu
if [ $# -lt 1 ]; then
    echo "usage: sbatch --array=1-K $0 JOBS_FILE [FISSURE_OPTION]..." >&2
    exit 64
fi
jobs=$1
shift
if [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
    echo "$0: SLURM_ARRAY_TASK_ID is not set: submit with sbatch --array=1-K" >&2
    exit 64
fi
exec "${FISSURE:-fissure}" -j "${SLURM_CPUS_PER_TASK:-1}" "$@" --job "$jobs:$SLURM_ARRAY_TASK_ID"
