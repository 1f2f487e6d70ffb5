#!/usr/bin/env bash
# Speed against error, side by side (issue 17): AUTO-07p, buckle and the naive load grid on the same
# tasks and axes, in one command.
#
#   benchmarks/work_precision.sh             # full sweep, REPS=5; writes benchmarks/results/work_precision_*
#   benchmarks/work_precision.sh --quick     # two AUTO settings, one repetition (CI smoke run)
#   BUILD=build-dir AUTO_PEER=dir OUT=dir REPS=n STEP="--rule count --growth 1.5" ...
#
# buckle's step control: STEP (default "--rule curvature --growth 3": TracerOptions::stepRule =
# Curvature, stepGrowth = 3, the rule that needs the fewest points at every tolerance,
# benchmarks/RESULTS.md section 3, "Step control from curvature"; the library's default rule is
# the Newton-iteration count with growth 1.5, STEP="" runs that).
#
# AUTO (shared/peers/auto07p beside the checkout; chain.f90 compiled as in compare_auto.sh, JAC=1,
# IID=0) sweeps its accuracy knobs: DSMAX (DS = ±min(0.01, DSMAX)) × (EPSL = EPSU, EPSS), on
#   diagram: c.A_auto (trivial branch, both BPs, automatic switching onto U and Z, qmax = 1.5);
#   fold   : c.I_up restarted from I_home, stopped at the geometric joint limit qmax = 2 atan 2
#            (where buckle stops);
#   long   : c.A_U restarted from the A_triv run of the same setting (only A_U is timed).
# Per setting: "Total Time" (AUTO's in-process wall clock, omp_get_wtime: start-up excluded, its
# fort.7 output included; median of K runs) and an in-process CPU time: Total Time × the process's
# (user + sys)/real over the K runs (the share of the wall time the process was on a CPU; a CPU
# time measured from outside would include the start-up, ≈ 3 ms here); the b-files go to
# $WORK/auto, listed in index.txt, which work_precision --auto reads (errors are computed there,
# with the same measures as for buckle and the naive method). Without AUTO (not installed) the
# quick mode skips it and says so; the full mode installs it (apt-get install auto-07p gfortran).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
. "$HERE/auto_lib.sh"   # auto_peer, auto_build
PEER=$(auto_peer "$ROOT")
BUILD=${BUILD:-$ROOT/build-bench}
OUT=${OUT:-$HERE/results}
REPS=${REPS:-5}
read -r -a STEP_ARGS <<< "${STEP---rule curvature --growth 3}"
AUTO_DIR=${AUTO_DIR:-/usr/lib/auto-07p}
QUICK=0
[ "${1:-}" = "--quick" ] && QUICK=1
export OMP_NUM_THREADS=1   # AUTO is built with -fopenmp
WP="$BUILD/bin/work_precision"
[ -x "$WP" ] || { echo "missing $WP: cmake --build $BUILD --target work_precision"; exit 1; }
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

if (( QUICK )); then
  DSMAXES="0.05 0.01"; EPS="1e-7:1e-5"; REPS=1; K=3
else
  DSMAXES="0.2 0.1 0.05 0.02 0.01 0.005 0.002 0.001"; EPS="1e-4:1e-3 1e-7:1e-5 1e-10:1e-8"; K=20
fi

have_auto=1
if [ ! -d "$AUTO_DIR/lib" ] || ! command -v gfortran > /dev/null || [ ! -f "$PEER/chain.f90" ]; then
  if (( QUICK )); then
    have_auto=0
  else
    echo "installing AUTO-07p (apt-get install -y auto-07p gfortran)"
    apt-get -o DPkg::Lock::Timeout=900 install -y auto-07p gfortran > /dev/null || { echo "could not install auto-07p"; exit 1; }
    [ -f "$PEER/chain.f90" ] || { echo "no AUTO harness at $PEER (set AUTO_PEER)"; exit 1; }
  fi
fi

WORK=$(mktemp -d "${TMPDIR:-/tmp}/buckle-wp.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
AUTO_ARGS=()
if (( have_auto )); then
  auto_build "$WORK"      # cd's into $WORK
  mkdir -p auto
  TIMEFORMAT='%3R %3U %3S'
  # cfile SRC DSMAX EPSL EPSS: the constants file with the setting applied (stdout)
  cfile() {
    local src=$1 dsmax=$2 epsl=$3 epss=$4
    sed -e 's/JAC=0/JAC=1/' -e 's/IID=2/IID=0/' \
        -e "s/EPSL=[^,]*, EPSU=[^,]*, EPSS=.*/EPSL=$epsl, EPSU=$epsl, EPSS=$epss/" \
        -e "s/DSMIN=[^,]*, DSMAX=[^,]*,/DSMIN=1e-5, DSMAX=$dsmax,/" \
        -e "s/NMX=[0-9]*, DS=\(-\{0,1\}\)[0-9.e-]*/NMX=50000, DS=\1$(awk -v d="$dsmax" 'BEGIN{print (d < 0.01) ? d : 0.01}')/" \
        "$PEER/cases/$src"
  }
  # timed NAME CFILE: K runs; echoes "wall_ms cpu_ms" (Total Time median, scaled by CPU/real)
  timed() {
    local name=$1 cf=$2 i t
    t=$( { time (for ((i = 1; i <= K; i++)); do ./chain.exe < "$cf" > "out.$name.$i" 2>&1; done) ; } 2>&1 )
    local wall
    wall=$(for ((i = 1; i <= K; i++)); do awk '/Total Time/{printf "%.6f\n", $3*1000}' "out.$name.$i"; done | sort -g \
           | awk '{v[NR]=$1} END{print v[int((NR+1)/2)]}')
    rm -f out."$name".*
    echo "$wall $(awk -v t="$t" -v w="$wall" 'BEGIN{split(t, a, " "); printf "%.6f", w*(a[2]+a[3])/a[1]}')"
  }
  # set-up run for the fold task (untimed): Fy0 homotopy to 0.01
  sed -e 's/JAC=0/JAC=1/' -e 's/IID=2/IID=0/' "$PEER/cases/c.I_home" > c.I_home
  ./chain.exe < c.I_home > /dev/null 2>&1; mv fort.8 s.I_home; rm -f fort.7 fort.9
  QGEOM=$(awk 'BEGIN{printf "%.15f", 2*atan2(2, 1)}')
  : > auto/index.txt
  for eps in $EPS; do
    epsl=${eps%:*}; epss=${eps#*:}
    for dsmax in $DSMAXES; do
      cfg="dsmax${dsmax}_eps${epsl}_epss${epss}"
      # diagram
      cfile c.A_auto "$dsmax" "$epsl" "$epss" > c.diag
      read -r w c <<< "$(timed diag c.diag)"
      ./chain.exe < c.diag > /dev/null 2>&1; mv fort.7 "auto/diagram_$cfg.b"; rm -f fort.8 fort.9
      echo "diagram $cfg $w $c diagram_$cfg.b" >> auto/index.txt
      # fold (UZSTOP qmax moved to the geometric joint limit)
      cfile c.I_up "$dsmax" "$epsl" "$epss" | sed "s/'qmax':3.0/'qmax':$QGEOM/" > c.fold
      read -r w c <<< "$(timed fold c.fold)"
      ./chain.exe < c.fold > /dev/null 2>&1; mv fort.7 "auto/fold_$cfg.b"; rm -f fort.8 fort.9
      echo "fold $cfg $w $c fold_$cfg.b" >> auto/index.txt
      # long: A_U restarted from this setting's A_triv
      cfile c.A_triv "$dsmax" "$epsl" "$epss" > c.triv
      ./chain.exe < c.triv > /dev/null 2>&1; mv fort.8 s.A_triv; rm -f fort.7 fort.9
      cfile c.A_U "$dsmax" "$epsl" "$epss" > c.long
      read -r w c <<< "$(timed long c.long)"
      ./chain.exe < c.long > /dev/null 2>&1; mv fort.7 "auto/long_$cfg.b"; rm -f fort.8 fort.9
      echo "long $cfg $w $c long_$cfg.b" >> auto/index.txt
    done
  done
  AUTO_ARGS=(--auto "$WORK/auto")
  cd "$ROOT"
else
  echo "AUTO-07p not installed: skipped (quick mode); buckle and the naive grid only"
fi

echo "work_precision $(date -u +%FT%TZ), git $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?'), load $(cut -d' ' -f1-3 /proc/loadavg), CPUs $(grep -c ^processor /proc/cpuinfo), buckle step control: ${STEP_ARGS[*]:-library defaults}"
QARGS=()
(( QUICK )) && QARGS=(--quick)
"$WP" --reps "$REPS" --out "$OUT" "${STEP_ARGS[@]}" "${AUTO_ARGS[@]}" "${QARGS[@]}"
echo "load at end $(cut -d' ' -f1-3 /proc/loadavg)"
if command -v gnuplot > /dev/null; then
  for t in diagram fold long; do gnuplot "$OUT/work_precision_$t.gp"; done
  echo "plots: $OUT/work_precision_{diagram,fold,long}.png"
else
  echo "gnuplot not installed: no plots"
fi
