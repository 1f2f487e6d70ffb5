#!/usr/bin/env bash
# CI smoke run of the benchmark programs: builds nothing, runs each binary once in a quick mode
# (small n, --benchmark_min_time=0.01, one repetition) so they don't rot. < 2 minutes; exits
# non-zero if any program fails.
#   benchmarks/run_quick.sh [BUILD_DIR]        (default: ./build-bench, then ./build)
set -uo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
BUILD=${1:-${BUILD:-}}
if [ -z "$BUILD" ]; then
  for d in "$ROOT/build-bench" "$ROOT/build"; do [ -x "$d/bin/bench_kernels" ] && BUILD=$d && break; done
fi
BIN=${BUILD:+$BUILD/bin}
[ -n "$BIN" ] && [ -x "$BIN/bench_kernels" ] || { echo "run_quick: no built benchmarks (pass the build dir)"; exit 1; }
OUT=$(mktemp -d "${TMPDIR:-/tmp}/buckle-bench-quick.XXXXXX")
trap 'rm -rf "$OUT"' EXIT
status=0
run() {
  local name=$1; shift
  local t0=$(date +%s%N)
  if timeout 100 "$@" > "$OUT/$name.log" 2>&1; then
    echo "ok    $name ($(( ($(date +%s%N) - t0) / 1000000 )) ms)"
  else
    echo "FAIL  $name (exit $?)"; tail -20 "$OUT/$name.log"; status=1
  fi
}
BUCKLE_BENCH_MAX_N=30 run bench_kernels "$BIN/bench_kernels" --benchmark_min_time=0.01
run bench_cases "$BIN/bench_cases" --reps 1
BUILD=$BUILD OUT=$OUT run work_precision "$HERE/work_precision.sh" --quick   # AUTO only if installed
run hard_cases "$BIN/hard_cases" --quick
run critical_loads "$BIN/critical_loads" --quick
run jump_timing "$BIN/jump_timing" --quick
command -v mpirun > /dev/null && BUILD=$BUILD run atlas_mpi "$HERE/atlas_mpi.sh" --quick   # issue 15
run long_tree "$BIN/long_tree" --quick
run vibration_timing "$BIN/vibration_timing" --quick
run actuation_path "$BIN/actuation_path" --quick   # issue 29
run task_path "$BIN/task_path" --quick   # issue 29, task-space paths
run gravity_path "$BIN/gravity_path" --quick   # issue 31, weight
run wall_path "$BIN/wall_path" --quick   # issue 31, the base wall
run wall_sliding bash "$HERE/wall_sliding.sh" "$BUILD" 3 50   # issue 31, the wall in the dynamics
run self_contact_hook bash "$HERE/self_contact_hook.sh" "$BUILD" 8 50   # issue 31, self contact along a branch
exit $status
