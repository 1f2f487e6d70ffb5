#!/usr/bin/env bash
# A workspace map's rows under MPI (`mpirun -np N buckle-mpi run`, issue 29) against `buckle run` on
# threads: data/scenes/workspace_n10.json on a finer grid (no plots), four ways: the wall clock of the
# whole command (mpirun start-up included) and the workspace stage rank 0 reports (summary.json
# timings_seconds); every workspace_map.csv and workspace_curves.csv must equal the 1-thread run's
# byte for byte (exit 1 otherwise).
#
#   benchmarks/workspace_mpi.sh            # n = 10, 201 x 201 grid (COUNT=m: m x m)
#   benchmarks/workspace_mpi.sh --quick    # 11 x 11 (a smoke run)
#   BUILD=build-dir RANKS=2 ...            # default ./build; RANKS default 2
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
BUILD=${BUILD:-$ROOT/build}
BUCKLE=$BUILD/bin/buckle
BUCKLE_MPI=$BUILD/bin/buckle-mpi
[ -x "$BUCKLE" ] || { echo "workspace_mpi: no $BUCKLE (pass BUILD=dir)"; exit 1; }
[ -x "$BUCKLE_MPI" ] || { echo "workspace_mpi: no $BUCKLE_MPI (built when CMake finds MPI: libopenmpi-dev)"; exit 1; }
command -v mpirun > /dev/null || { echo "workspace_mpi: mpirun not found (Debian: openmpi-bin)"; exit 1; }
RANKS=${RANKS:-2}
COUNT=${COUNT:-201}
[ "${1:-}" = --quick ] && COUNT=11
WORK=$(mktemp -d "${TMPDIR:-/tmp}/buckle-workspace-mpi.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
MPIRUN=(mpirun --oversubscribe --bind-to none)
scene() {  # threads per process
  python3 - "$ROOT/data/scenes/workspace_n10.json" "$COUNT" "$1" > "$WORK/scene_$1.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
w = d["analyses"]["workspace"]
w["first"]["count"] = w["second"]["count"] = int(sys.argv[2])
w["threads"] = int(sys.argv[3])
d["plots"] = []
print(json.dumps(d))
PY
}
echo "workspace_n10.json, ${COUNT} x ${COUNT} grid, on $(nproc) cores; load: $(uptime | sed 's/.*load average: //')"
printf '%-20s %10s %14s\n' way wall_s workspace_s
way() {  # name, threads per process, launcher... (none: buckle alone; under mpirun buckle-mpi)
  local name=$1 threads=$2; shift 2
  local program=$BUCKLE
  [ $# -gt 0 ] && program=$BUCKLE_MPI
  scene "$threads"
  local t0=$(date +%s%N)
  "$@" "$program" run "$WORK/scene_$threads.json" --quiet --out "$WORK/$name"
  local wall=$(( ($(date +%s%N) - t0) / 1000000 ))
  local stage=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["timings_seconds"]["workspace"])' \
                "$WORK/$name/summary.json")
  printf '%-20s %10.2f %14.2f\n' "$name" "$(echo "$wall / 1000" | bc -l)" "$stage"
  for f in workspace_map.csv workspace_curves.csv; do
    cmp -s "$WORK/$name/$f" "$WORK/threads_1/$f" || { echo "workspace_mpi: $name/$f differs"; exit 1; }
  done
}
way threads_1 1
way "threads_$RANKS" "$RANKS"
way mpi_1_rank 1 "${MPIRUN[@]}" -np 1
way "mpi_${RANKS}_ranks" 1 "${MPIRUN[@]}" -np "$RANKS"
