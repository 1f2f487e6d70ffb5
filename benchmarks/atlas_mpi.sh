#!/usr/bin/env bash
# `buckle-mpi atlas` under MPI against `buckle atlas` on threads (issue 15): one grid, four ways, wall clock of the
# whole command (mpirun start-up included) and the compute time rank 0 reports (summary.json
# "seconds"); every atlas.csv must equal the 1-thread one byte for byte (exit 1 otherwise).
#
#   benchmarks/atlas_mpi.sh            # n = 100..200 (11) x L0/b = 2..3 (8): 88 cells, seconds each way
#   benchmarks/atlas_mpi.sh --quick    # 3 x 2 cells (CI smoke run)
#   BUILD=build-dir RANKS=2 ...        # default ./build-bench, then ./build; RANKS default 2
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
BUILD=${BUILD:-}
if [ -z "$BUILD" ]; then
  for d in "$ROOT/build-bench" "$ROOT/build"; do [ -x "$d/bin/buckle" ] && BUILD=$d && break; done
fi
BUCKLE=$BUILD/bin/buckle
BUCKLE_MPI=$BUILD/bin/buckle-mpi   # `buckle` links no MPI
[ -x "$BUCKLE" ] || { echo "atlas_mpi: no $BUCKLE (pass BUILD=dir)"; exit 1; }
[ -x "$BUCKLE_MPI" ] || { echo "atlas_mpi: no $BUCKLE_MPI (built when CMake finds MPI: libopenmpi-dev)"; exit 1; }
command -v mpirun > /dev/null || { echo "atlas_mpi: mpirun not found (Debian: openmpi-bin)"; exit 1; }
RANKS=${RANKS:-2}
GRID=(--x n --x-range 100 200 11 --y L0 --y-range 2 3 8)
[ "${1:-}" = --quick ] && GRID=(--x n --x-range 20 40 3 --y L0 --y-range 2 3 2)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/buckle-atlas-mpi.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
# As root in a container: Open MPI's permissions; no single-copy transport (needs ptrace rights).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
MPIRUN=(mpirun --oversubscribe --bind-to none)
echo "atlas ${GRID[*]} on $(nproc) cores; load: $(uptime | sed 's/.*load average: //')"
printf '%-28s %10s %12s\n' way wall_s compute_s
way() {  # name, threads per process, launcher... (none: buckle alone; under mpirun buckle-mpi)
  local name=$1 threads=$2; shift 2
  local program=$BUCKLE
  [ $# -gt 0 ] && program=$BUCKLE_MPI
  local t0=$(date +%s%N)
  "$@" "$program" atlas "${GRID[@]}" -j "$threads" --quiet --out "$WORK/$name" || [ $? -eq 1 ]  # 1: failed cells
  local wall=$(( ($(date +%s%N) - t0) / 1000000 ))
  local compute=$(sed -n 's/.*"seconds": \([0-9.e+-]*\).*/\1/p' "$WORK/$name/summary.json")
  printf '%-28s %10.2f %12.2f\n' "$name" "$(echo "$wall / 1000" | bc -l)" "$compute"
  cmp -s "$WORK/$name/atlas.csv" "$WORK/threads_1/atlas.csv" || { echo "atlas_mpi: $name/atlas.csv differs"; exit 1; }
}
way threads_1 1
way "threads_$RANKS" "$RANKS"
way mpi_1_rank 1 "${MPIRUN[@]}" -np 1
way "mpi_${RANKS}_ranks" 1 "${MPIRUN[@]}" -np "$RANKS"
