#!/usr/bin/env bash
# Instructions per buckle run of the work-precision tasks (issue 17), load-independent: each
# setting of work_precision run once under callgrind, counting only the timed runs (the
# reference runs and the error measures excluded by --toggle-collect on timeRuns, which calls the
# task twice in --quick mode: once to size the batch, once timed).
#
#   benchmarks/callgrind_work_precision.sh [TASK] [SETTING...]
#     TASK     diagram (default), fold or long
#     SETTING  MAXSTEP:NEWTON:LOCATION[:RULE[:PREDICTOR]]  RULE curvature|count, PREDICTOR euler|p2
#   BUILD=build-dir (default build-bench); WPARGS="--growth 2 ..." extra work_precision arguments
# Prints one line per setting: points, instructions per run (M), instructions per point (k),
# special-point and branch errors.
set -euo pipefail
command -v valgrind > /dev/null || { echo "needs valgrind (apt-get install -y valgrind)"; exit 1; }
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
BUILD=${BUILD:-$ROOT/build-bench}
WP=$(cd "$BUILD/bin" && pwd)/work_precision
[ -x "$WP" ] || { echo "missing $WP: cmake --build $BUILD --target work_precision"; exit 1; }
TASK=${1:-diagram}
shift || true
SETTINGS=("$@")
if (( ${#SETTINGS[@]} == 0 )); then
  SETTINGS=(0.4:1e-4:1e-3:count 0.4:1e-4:1e-3 1.6:1e-4:1e-3 0.4:1e-7:1e-6:count 0.8:1e-7:1e-6
            0.4:1e-10:1e-12:count 0.8:1e-10:1e-12 0.4:1e-13:1e-14:count 0.8:1e-13:1e-14 0.8:1e-13:1e-14:curvature:p2)
fi
WORK=$(mktemp -d "${TMPDIR:-/tmp}/buckle-cgwp.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
echo "callgrind_work_precision $(date -u +%FT%TZ), git $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?'), task $TASK"
printf "%-36s %7s %12s %12s %10s %10s\n" setting points "M instr/run" "k instr/pt" special branch
for s in "${SETTINGS[@]}"; do
  IFS=: read -r h newton location rule predictor <<< "$s"
  rule=${rule:-curvature}; predictor=${predictor:-euler}
  valgrind --tool=callgrind --toggle-collect='*timeRuns*' --callgrind-out-file="$WORK/cg" \
    "$WP" --quick --buckle-only --out "$WORK" --task "$TASK" --max-step "$h" --tolerances "$newton:$location" \
    --rule "$rule" --predictor "$predictor" ${WPARGS:-} > "$WORK/out.txt" 2> /dev/null
  total=$(callgrind_annotate "$WORK/cg" 2>/dev/null | awk '/PROGRAM TOTALS/{gsub(",", "", $1); print $1}')
  row=$(awk -v t="$TASK" '/^## /{sec=$2} sec==t && $1 ~ /^buckle/ {print; exit}' "$WORK/out.txt")
  read -r _ _ points _ _ special branch <<< "$row"
  awk -v s="$s" -v p="$points" -v t="$total" -v e1="$special" -v e2="$branch" 'BEGIN{
    printf "%-36s %7d %12.3f %12.2f %10s %10s\n", s, p, t / 2 / 1e6, t / 2 / p / 1e3, e1, e2 }'
done
