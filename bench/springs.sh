# Times the springs model at 10k and 100k masses: bench/springs.sh BUILD_DIR [MAX_BREAKS_100K]
# The 10k run goes to the end; the 100k run stops after MAX_BREAKS_100K breaks (default 5000) so
# that it gives seconds per break in minutes rather than hours. Prints one line per run.
set -eu
build=${1:?usage: springs.sh BUILD_DIR [MAX_BREAKS_100K]}
cap=${2:-5000}
bin="$build/bench/bench_springs"
[ -x "$bin" ] || { echo "springs.sh: build $bin first (make bench/bench_springs)" >&2; exit 66; }
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}" OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}"
"$bin" 10000
"$bin" 100000 "$cap"
