#!/usr/bin/env bash
# Instructions per continuation point of numerics (issue 17), load-independent: buckle's switched
# A_Ufine branch (bench_cases, inertia only per point, like AUTO's IPS = 0 run) against AUTO-07p's
# A_Ufine run (JAC=1, IID=0, restarted from A_triv) counting AUTO's numerics alone: its continuation
# driver minus the routine that writes every point to fort.7. Also buckle with --second-order and with
# --no-certified (certified counting off: the like-for-like run, AUTO IPS = 0 computes no eigenvalues),
# and that with --lean-newton (the corrector's opt-in reproduction of KINSOL's plain full Newton).
#
#   benchmarks/callgrind_points.sh          (BUILD=build-bench, AUTO_PEER=..., needs valgrind)
set -euo pipefail
command -v valgrind > /dev/null || { echo "needs valgrind (apt-get install -y valgrind)"; exit 1; }
export OMP_NUM_THREADS=1
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
BUILD=${BUILD:-$ROOT/build-bench}
AUTO_DIR=${AUTO_DIR:-/usr/lib/auto-07p}
. "$HERE/auto_lib.sh"   # auto_peer, auto_build
PEER=$(auto_peer "$ROOT")
BC=$(cd "$BUILD/bin" && pwd)/bench_cases
[ -x "$BC" ] || { echo "missing $BC"; exit 1; }
WORK=$(mktemp -d "${TMPDIR:-/tmp}/buckle-cg.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
auto_build "$WORK"
for r in A_triv A_Ufine; do sed -e 's/JAC=0/JAC=1/' -e 's/IID=2/IID=0/' "$PEER/cases/c.$r" > "c.$r"; done
./chain.exe < c.A_triv > /dev/null 2>&1; mv fort.8 s.A_triv
valgrind --tool=callgrind --callgrind-out-file=auto.cg ./chain.exe < c.A_Ufine > /dev/null 2>&1
apts=$(awk '$1!=0' fort.7 | wc -l)
valgrind --tool=callgrind --callgrind-out-file=buckle.cg "$BC" --reps 1 A_Ufine > buckle.txt 2>/dev/null
bpts=$(sed -nE 's/^case=A_Ufine points=([0-9]+).*/\1/p' buckle.txt)
valgrind --tool=callgrind --callgrind-out-file=p2.cg "$BC" --reps 1 --second-order A_Ufine > p2.txt 2>/dev/null
ppts=$(sed -nE 's/^case=A_Ufine points=([0-9]+).*/\1/p' p2.txt)
valgrind --tool=callgrind --callgrind-out-file=nc.cg "$BC" --reps 1 --no-certified A_Ufine > nc.txt 2>/dev/null
npts=$(sed -nE 's/^case=A_Ufine points=([0-9]+).*/\1/p' nc.txt)
valgrind --tool=callgrind --callgrind-out-file=ln.cg "$BC" --reps 1 --no-certified --lean-newton A_Ufine > ln.txt 2>/dev/null
lpts=$(sed -nE 's/^case=A_Ufine points=([0-9]+).*/\1/p' ln.txt)
incl() {  # incl FILE REGEX: the largest inclusive count of a function whose name matches
  callgrind_annotate --inclusive=yes --threshold=100 "$1" 2>/dev/null | awk -v re="$2" '
    $0 ~ re { gsub(",", "", $1); if ($1 + 0 > best) best = $1 + 0 } END { print best + 0 }'
}
total() { callgrind_annotate "$1" 2>/dev/null | awk '/PROGRAM TOTALS/{gsub(",", "", $1); print $1}'; }
a_total=$(total auto.cg); a_drv=$(incl auto.cg 'autoae'); a_out=$(incl auto.cg 'stplae'); a_wr=$(incl auto.cg 'wrline')
b_total=$(total buckle.cg); b_sw=$(incl buckle.cg 'switchBranch'); p_sw=$(incl p2.cg 'switchBranch'); n_sw=$(incl nc.cg 'switchBranch'); l_sw=$(incl ln.cg 'switchBranch')
awk -v at="$a_total" -v ad="$a_drv" -v ao="$a_out" -v aw="$a_wr" -v ap="$apts" -v bt="$b_total" -v bs="$b_sw" -v bp="$bpts" \
    -v ps="$p_sw" -v pp="$ppts" -v ns="$n_sw" -v np="$npts" -v ls="$l_sw" -v lp="$lpts" 'BEGIN{
  printf "AUTO A_Ufine  : %d points; process %.1f M instructions; driver (autoae) %.1f M, of which output (stplae) %.1f M (wrline %.1f M)\n", ap, at/1e6, ad/1e6, ao/1e6, aw/1e6
  printf "                numerics alone (autoae - stplae) %.1f M = %.1f k per point\n", (ad-ao)/1e6, (ad-ao)/ap/1e3
  printf "buckle A_Ufine: %d points; process %.1f M instructions; switchBranch %.2f M = %.2f k per point\n", bp, bt/1e6, bs/1e6, bs/bp/1e3
  printf "ratio AUTO numerics / buckle per point: %.3f (target >= 2)\n", ((ad-ao)/ap) / (bs/bp)
  printf "buckle --second-order (TracerOptions::secondOrderPredictor): %d points; switchBranch %.2f M = %.2f k per point; ratio %.3f\n", pp, ps/1e6, ps/pp/1e3, ((ad-ao)/ap) / (ps/pp)
  printf "buckle --no-certified (TracerOptions::certifiedCounting = false, like for like): %d points; switchBranch %.2f M = %.2f k per point; ratio %.3f\n", np, ns/1e6, ns/np/1e3, ((ad-ao)/ap) / (ns/np)
  printf "buckle --no-certified --lean-newton (TracerOptions::leanNewton, KINSOL only where Newton does not converge plainly): %d points; switchBranch %.2f M = %.2f k per point; ratio %.3f\n", lp, ls/1e6, ls/lp/1e3, ((ad-ao)/ap) / (ls/lp) }'
