#!/usr/bin/env bash
# Regenerates every figure of benchmarks/RESULTS.md: builds the benchmark targets, runs the
# kernels (all n), the AUTO-07p comparison, the side-by-side work-precision sweep and its plots,
# the instruction counts per point (callgrind, when valgrind is installed), the hard
# cases (hard_cases_auto.sh: buckle and AUTO), the whole-process race (race_auto.sh), and writes
# the raw outputs to benchmarks/results/. RESULTS.md quotes these files.
#   benchmarks/run_all.sh            (BUILD=build-bench by default; REPS=5; HARD_N=1000: large clustered case)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
BUILD=${BUILD:-$ROOT/build-bench}
REPS=${REPS:-5}
R="$HERE/results"
mkdir -p "$R"
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$BUILD" -j2 --target bench_kernels bench_cases work_precision hard_cases buckle
{
  echo "date: $(date -u +%FT%TZ)"
  echo "nproc: $(nproc)   CPUs: $(grep -c ^processor /proc/cpuinfo)   CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
  echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "git: $(git -C "$ROOT" rev-parse --short HEAD)"
} > "$R/machine.txt"
"$BUILD/bin/bench_kernels" --benchmark_min_time=0.2 | tee "$R/kernels.txt"
REPS=$REPS BUILD=$BUILD "$HERE/compare_auto.sh" | tee "$R/compare_auto.txt"
BUILD=$BUILD REPS=$REPS OUT=$R "$HERE/work_precision.sh" | tee "$R/work_precision.txt"   # and its plots
if command -v valgrind > /dev/null; then BUILD=$BUILD "$HERE/callgrind_points.sh" | tee "$R/callgrind_points.txt"; fi
BUILD=$BUILD "$HERE/hard_cases_auto.sh" --n "${HARD_N:-1000}" | tee "$R/hard_cases.txt"
# whole processes against AUTO-07p (writes results/race_auto*; n = 1000, where AUTO runs into its
# 10-minute limit, only by hand: benchmarks/race_auto.sh 1000)
BUILD=$BUILD "$HERE/race_auto.sh" 3 10 30 100 300
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)" >> "$R/machine.txt"
echo "results in $R"
