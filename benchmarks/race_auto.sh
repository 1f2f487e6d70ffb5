#!/usr/bin/env bash
# The race: AUTO-07p and buckle on the same task T for clamped–pinned chains of n segments, as a
# user runs them (whole processes), side by side (issue 32). Task T (shared/peers/auto07p-n/README.md):
# trivial branch Fx 0 -> 1.25 x the 5th critical load, the first 5 branch points switched, every
# child to max|q| = 1.5, the Fx range or 200 points; Newton tolerance 1e-10; the same steps for both.
#
#   benchmarks/race_auto.sh                  # n = 3 10 30 100 300 1000 (AUTO n = 1000 runs into its limit: ~10 min)
#   benchmarks/race_auto.sh 3 10 30 100 300  # about 1.5 min
#   benchmarks/race_auto.sh brief            # only the start-up and the n = 3 diagram (below)
#   benchmarks/race_auto.sh table            # the table of the stored results again
#
# First, always: start-up (`buckle --help`) and the full n = 3 diagram as processes: AUTO's
# c.A_auto (shared/peers/auto07p, with JAC = 1, IID = 0) against `buckle run
# benchmarks/scenes/diagram_n3.json` (the same task, no plots), REPS_FAST alternating runs.
#
# For every n: the critical loads from `buckle critical` (the BP references), the AUTO constants
# file and the buckle scene (race_auto.py gen), then both programs alternately as processes
# (race_auto.py time: wall, user+sys CPU, peak RSS; REPS_FAST runs when the first is under 1 s,
# REPS otherwise, one from SLOW s on, killed at LIMIT s), then the outputs parsed (points, branch
# points and their error against `buckle critical`, the children compared). Results:
# benchmarks/results/race_auto/n<N>.json and table.md, the log in benchmarks/results/race_auto.txt.
#
# Environment: BUILD (build dir with bin/buckle; default build-bench, then build), REPS (3),
#   REPS_FAST (21), SLOW (20 s), LIMIT (570 s: every process under 10 min), AUTO_MAX_N (AUTO not
#   run above this n), AUTO_DIR (/usr/lib/auto-07p), AUTO_PEER_N (the harness: chain_n.f90 and its
#   checks; default shared/peers/auto07p-n beside the checkout), KEEP=1 (keep the work dir).
# Needs: auto-07p and gfortran (Debian), python3 (stdlib only), objcopy (binutils), GNU time.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
RES=$HERE/results/race_auto
mkdir -p "$RES"
PY=${PY:-python3}
table() {
  local f
  : > "$RES/all.jsonl"
  for f in $(ls "$RES"/n*.json 2>/dev/null | sed 's/.*\/n\([0-9]*\)\.json/\1/' | sort -n); do
    cat "$RES/n$f.json" >> "$RES/all.jsonl"
  done
  "$PY" "$HERE/race_auto.py" table "$RES/all.jsonl" | tee "$RES/table.md"
  rm -f "$RES/all.jsonl"
}
if [ "${1:-}" = table ]; then table; exit 0; fi

AUTO_DIR=${AUTO_DIR:-/usr/lib/auto-07p}
BUILD=${BUILD:-}
if [ -z "$BUILD" ]; then
  for d in "$ROOT/build-bench" "$ROOT/build"; do [ -x "$d/bin/buckle" ] && BUILD=$d && break; done
fi
BUCKLE=$BUILD/bin/buckle
PEER_N=${AUTO_PEER_N:-$ROOT/../shared/peers/auto07p-n}
[ -d "$PEER_N" ] || PEER_N=$ROOT/../../shared/peers/auto07p-n
PEER3=$PEER_N/../auto07p   # the 3-segment template chain.f90, for the n = 3 check
REPS=${REPS:-3}
REPS_FAST=${REPS_FAST:-21}
SLOW=${SLOW:-20}
LIMIT=${LIMIT:-570}
AUTO_MAX_N=${AUTO_MAX_N:-1000000}
export OMP_NUM_THREADS=1   # AUTO's library is built with -fopenmp
NS=${*:-"3 10 30 100 300 1000"}
[ "$NS" = brief ] && NS=""
for need in gfortran "$PY" objcopy /usr/bin/time; do command -v "$need" > /dev/null || { echo "race_auto: missing $need"; exit 1; }; done
[ -d "$AUTO_DIR/lib" ] || { echo "race_auto: missing $AUTO_DIR/lib (apt-get install auto-07p gfortran)"; exit 1; }
[ -x "$BUCKLE" ] || { echo "race_auto: no $BUCKLE (pass BUILD=dir)"; exit 1; }
[ -f "$PEER_N/chain_n.f90" ] || { echo "race_auto: no $PEER_N/chain_n.f90 (set AUTO_PEER_N)"; exit 1; }

WORK=$(mktemp -d "${TMPDIR:-/tmp}/race_auto.XXXXXX")
if [ -z "${KEEP:-}" ]; then trap 'rm -rf "$WORK"' EXIT; else echo "work dir: $WORK"; fi
exec > >(tee "$HERE/results/race_auto.txt") 2>&1

# ---- AUTO's problem: chain_n.f90 with the flags of AUTO's cmds.make, and its checks ----------
FFLAGS=$(awk -F'= ' '/^FFLAGS /{print $2}' "$AUTO_DIR/cmds/cmds.make")
OPT=$(awk -F'= ' '/^OPT /{print $2}' "$AUTO_DIR/cmds/cmds.make")
cp "$PEER_N/chain_n.f90" "$PEER_N/jaccheck_n.f90" "$PEER_N/cmp3.f90" "$WORK/"
cp "$PEER3/chain.f90" "$WORK/chain3.f90"
cd "$WORK"
gfortran $FFLAGS $OPT -c chain_n.f90 -o chain_n.o
gfortran $FFLAGS $OPT chain_n.o -o chain_n.exe "$AUTO_DIR"/lib/*.o
echo "race_auto.sh $NS: $(date -u +%FT%TZ), git $(git -C "$ROOT" rev-parse --short HEAD)$(git -C "$ROOT" diff --quiet HEAD -- || echo ' (modified)')"
echo "AUTO-07p $(dpkg-query -W -f='${Version}' auto-07p 2>/dev/null || echo '?'), $(gfortran --version | head -1)"
echo "buckle: $BUCKLE ($("$BUCKLE" --version 2>&1 | head -1)); $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
echo "load before: $(uptime)"
# analytic Jacobian vs central differences, the equations vs the model written independently,
# and n = 3 against the template chain.f90 (its symbols renamed): no AUTO involved
gfortran -O2 -fopenmp jaccheck_n.f90 chain_n.o -o jaccheck_n
echo "chain_n.f90 checks:"; ./jaccheck_n
gfortran -O2 -fopenmp -std=legacy -c chain3.f90 -o chain3.o
nm chain3.o | awk '$2 ~ /^[TDBC]$/ {print $3, "t3_" $3}' > syms
objcopy --redefine-syms=syms chain3.o chain3r.o
gfortran -O2 -fopenmp cmp3.f90 chain_n.o chain3r.o -o cmp3 && ./cmp3
echo

# ---- start-up and the n = 3 diagram -----------------------------------------------------------
mkdir -p "$WORK/d_auto" "$WORK/d_buckle"
gfortran $FFLAGS $OPT -std=legacy -c chain3.f90 -o chain3_auto.o
gfortran $FFLAGS $OPT chain3_auto.o -o d_auto/chain.exe "$AUTO_DIR"/lib/*.o
sed -e 's/JAC=0/JAC=1/' -e 's/IID=2/IID=0/' "$PEER3/cases/c.A_auto" > d_auto/c.A_auto
cp "$HERE/scenes/diagram_n3.json" d_buckle/scene.json
echo "=== start-up and the n = 3 diagram ($(date -u +%T), load $(cut -d' ' -f1-3 /proc/loadavg))"
"$PY" "$HERE/race_auto.py" time "$WORK/startup.json" "$REPS_FAST" "$REPS_FAST" "$SLOW" "$LIMIT" - -- \
  "$WORK/d_buckle" /dev/null "$BUCKLE" --help
"$PY" "$HERE/race_auto.py" time "$WORK/diagram.json" "$REPS_FAST" "$REPS_FAST" "$SLOW" "$LIMIT" \
  "$WORK/d_auto" d_auto/c.A_auto ./chain.exe -- "$WORK/d_buckle" /dev/null "$BUCKLE" run scene.json --out out --quiet
for f in startup diagram; do
  "$PY" - "$WORK/$f.json" "$(date -u +%FT%TZ)" "$(cut -d' ' -f1-3 /proc/loadavg)" <<'EOF'
import json, sys
t = json.load(open(sys.argv[1]))
t["date"], t["load"] = sys.argv[2], sys.argv[3]
json.dump(t, open(sys.argv[1], "w"))
EOF
  cp "$WORK/$f.json" "$RES/$f.json"
done
{
  echo "| process | AUTO-07p wall (CPU, peak RSS, runs) | buckle wall (CPU, peak RSS, runs) | AUTO / buckle wall | load after |"
  echo "|---|---|---|---|---|"
  "$PY" "$HERE/race_auto.py" brief "buckle --help" "$RES/startup.json"
  "$PY" "$HERE/race_auto.py" brief "n = 3 diagram (c.A_auto / diagram_n3.json)" "$RES/diagram.json"
} | tee "$RES/brief.md"
echo

for N in $NS; do
  echo "=== n = $N ($(date -u +%T), load $(cut -d' ' -f1-3 /proc/loadavg))"
  "$BUCKLE" critical --segments "$N" --a 0.5 --b 1 --k 1 --L0 2.25 --end pinned --count 5 --json > "$WORK/crit$N.json"
  mkdir -p "$WORK/a$N" "$WORK/b$N"
  read -r DSMAX FXEND < <("$PY" "$HERE/race_auto.py" gen "$N" "$WORK/crit$N.json" "$WORK/a$N/c.T" "$WORK/b$N/scene.json")
  echo "Fx_end = $FXEND, DSMAX = $DSMAX"
  ln -sf "$WORK/chain_n.exe" "$WORK/a$N/chain_n.exe"
  A=("$WORK/a$N" "$WORK/a$N/c.T" ./chain_n.exe)
  [ "$N" -le "$AUTO_MAX_N" ] || A=(-)
  "$PY" "$HERE/race_auto.py" time "$WORK/times$N.json" "$REPS" "$REPS_FAST" "$SLOW" "$LIMIT" "${A[@]}" -- \
    "$WORK/b$N" /dev/null "$BUCKLE" run scene.json --out out --quiet
  "$PY" - "$WORK/times$N.json" "$(date -u +%FT%TZ)" "$(cut -d' ' -f1-3 /proc/loadavg)" <<'EOF'
import json, sys
t = json.load(open(sys.argv[1]))
t["date"], t["load"] = sys.argv[2], sys.argv[3]
json.dump(t, open(sys.argv[1], "w"))
for k in ("auto", "buckle"):
    print(f"{k}: {t[k]['status']}, walls {t[k].get('walls')}")
EOF
  tail -1 "$WORK/b$N/buckle.err" 2> /dev/null || true
  "$PY" "$HERE/race_auto.py" parse "$N" "$WORK/crit$N.json" "$WORK/a$N" "$WORK/b$N/out" "$WORK/times$N.json" > "$RES/n$N.json"
done
echo "load after: $(uptime)"
echo
[ -z "$NS" ] || table
