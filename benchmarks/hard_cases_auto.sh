#!/usr/bin/env bash
# The hard-case suite (benchmarks/hard_cases.cpp) for buckle and, where its harness can run the
# case, for AUTO-07p (shared/peers/auto07p: chain.f90 is the 3-segment chain only, NDIM 3/4).
#
#   benchmarks/hard_cases_auto.sh [hard_cases args]    # BUILD=build dir (default ./build-bench)
#
# AUTO runs (JAC=1, IID=0), per unit scaling (lengths ×L, stiffness ×k, loads ×F0 = k·L):
#   units.bp    c.A_triv with a, b, k, L0 scaled, UZSTOP Fx = −2.5 F0: both BPs vs eq 17
#   units.fold  c.I_home (Fy0 → 0.01 F0) then c.I_up (Fx range ±3 F0): the LP vs ref.py × F0
#   units.limit c.A_U from BP1 of units.bp, UZSTOP qmax = 1.5: the UZ point vs buckle's
#               unscaled boundary value −1.2519370132295 × F0
#   variant raw:   the c-files' DS, DSMIN, DSMAX (absolute arclength, as the unscaled run uses)
#   variant steps: DS, DSMIN, DSMAX × F0 (AUTO's EPSL, EPSU, EPSS are already relative)
#   variant weights: arclength weights THL (Fx, Fy0) and THU (the reaction Fy) = 1/F0², steps as
#                  given: AUTO's way of nondimensionalising the pseudo-arclength (its weights multiply
#                  the squared components)
#   kappa0.n3   c.L_triv (κ = 0): AUTO's determinant test does not see the double zero
# Pass: every expected point found, relative error ≤ 1e-9 (AUTO prints 11 significant digits).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
# the harness beside the checkout (shared/ next to the repository), overridable
PEER=${AUTO_PEER:-$ROOT/../shared/peers/auto07p}
BUILD=${BUILD:-$ROOT/build-bench}
AUTO_DIR=${AUTO_DIR:-/usr/lib/auto-07p}
NPROC=$(nproc)             # before OMP_NUM_THREADS: GNU nproc honours that variable
export OMP_NUM_THREADS=1
HC="$BUILD/bin/hard_cases"
[ -x "$HC" ] || { echo "missing $HC: cmake --build $BUILD --target hard_cases"; exit 1; }

echo "hard cases, $(date -u +%FT%TZ), git $(git -C "$ROOT" rev-parse --short HEAD), nproc $NPROC ($(grep -c ^processor /proc/cpuinfo) CPUs)," \
  "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "== buckle: $HC $*"
"$HC" "$@"
echo
echo "== AUTO-07p $(dpkg-query -W -f='${Version}' auto-07p 2>/dev/null || echo '?') (JAC=1, IID=0)"
if [ ! -d "$AUTO_DIR/lib" ] || ! command -v gfortran > /dev/null; then
  echo "AUTO-07p not installed (apt-get install -y auto-07p gfortran): every AUTO entry n/a"
  exit 0
fi
WORK=$(mktemp -d "${TMPDIR:-/tmp}/buckle-hard-auto.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
. "$HERE/auto_lib.sh"   # auto_build, auto_points
auto_build "$WORK"

# c-file from the peer's, with constants, stops and steps replaced, EXTRA lines (e.g. THL) added:
#   cfile CASE OUT PAR UZSTOP STEPSCALE [EXTRA]
cfile() {
  sed -e 's/JAC=0/JAC=1/' -e 's/IID=2/IID=0/' -e "/^PAR=/d" -e "s/^UZSTOP=.*/UZSTOP=$4/" "$PEER/cases/c.$1" |
    awk -v par="$3" -v f="$5" -v extra="${6:-}" '
      /^NDIM=/ { print "PAR=" par; if (extra != "") print extra }
      { if ($0 ~ /DSMIN=/ || $0 ~ /DS=/) {
          n = split($0, kv, ", "); out = ""
          for (i = 1; i <= n; i++) { split(kv[i], p, "=")
            if (p[1] == "DS" || p[1] == "DSMIN" || p[1] == "DSMAX") kv[i] = sprintf("%s=%.6g", p[1], p[2] * f)
            out = out (i > 1 ? ", " : "") kv[i] }
          print out } else print }' > "$2"
}
# run NAME [RESTART]: AUTO on c.NAME (s.RESTART copied to fort.3), labelled points "TYPE Fx" in pts.NAME
run() {
  rm -f fort.2 fort.3 fort.7 fort.8 fort.9
  cp "c.$1" fort.2
  [ -n "${2:-}" ] && cp "s.$2" fort.3
  ./chain.exe < "c.$1" > "out.$1" 2>&1 || true
  [ -f fort.8 ] && mv fort.8 "s.$1"
  touch fort.7
  auto_points fort.7 > "pts.$1"
  PTS=$(awk '$1!=0' fort.7 | wc -l)
  MS=$(awk '/Total Time/{printf "%.2f", $3*1000}' "out.$1")
  [ -n "$MS" ] || MS=nan
}
row() {  # row PASS ID ERR MS NOTE
  printf "%-4s %-30s err %-8s %9s ms  %s\n" "$1" "$2" "$3" "$4" "$5"
}
rel() { awk -v x="$1" -v r="$2" 'BEGIN{d=x-r; if (d<0) d=-d; if (r<0) r=-r; printf "%.1e", d/r}'; }

for variant in raw steps weights; do
  for L in 1e-3 1 1e3; do
    for k in 1e-6 1 1e6; do
      F0=$(awk -v L="$L" -v k="$k" 'BEGIN{printf "%.17g", L*k}')
      f=1; [ $variant = steps ] && f=$F0
      w=$(awk -v F="$F0" 'BEGIN{printf "%.17g", 1/(F*F)}')
      thPinned=""; thFree=""
      if [ $variant = weights ]; then thPinned="THL={'Fx':$w}\nTHU={4:$w}"; thFree="THL={'Fx':$w, 'Fy0':$w}"; fi
      id="$L"x"$k".$variant
      par=$(awk -v L="$L" -v k="$k" 'BEGIN{printf "{\x27a\x27:%.17g, \x27b\x27:%.17g, \x27k\x27:%.17g, \x27L0\x27:%.17g}", 0.5*L, L, k, 2.25*L}')
      # branch points: eq 17 in the scaled constants, Fx = λ κ / b
      read -r refU refZ < <(awk -v L="$L" -v k="$k" 'BEGIN{a=0.5*L; b=L; kap=k*(b*2.25*L-2*(b*b-a*a));
        printf "%.17g %.17g\n", (sqrt(21)-14)/10*kap/b, -(sqrt(21)+14)/10*kap/b}')
      cfile A_triv c.bp "$par" "{'Fx':$(awk -v F="$F0" 'BEGIN{printf "%.17g", -2.5*F}')}" "$f" "$thPinned"
      run bp
      mapfile -t B < <(awk '$1=="BP"{print $2}' pts.bp)
      if [ "${#B[@]}" -eq 2 ]; then
        e=$(awk -v a="$(rel "${B[0]}" "$refU")" -v b="$(rel "${B[1]}" "$refZ")" 'BEGIN{print (a+0>b+0)?a:b}')
        ok=$(awk -v e="$e" 'BEGIN{print (e+0<=1e-9)?"PASS":"FAIL"}')
        row "$ok" "units.bp.$id" "$e" "$MS" "2 BP, $PTS points"
      else
        row FAIL "units.bp.$id" - "$MS" "${#B[@]} BP, $PTS points, $(grep -m1 -o -E 'NO CONVERGENCE.*|.*[Ee]rror.*' out.bp | head -c 60)"
      fi
      # joint limit: switch at BP1, stop at qmax = 1.5
      if [ "${#B[@]}" -ge 1 ]; then
        cfile A_U c.lim "$par" "{'Fx':$(awk -v F="$F0" 'BEGIN{printf "%.17g", -3*F}'), 'qmax':1.5}" "$f" "$thPinned"
        sed -i "s/^s=.*/s='bp'/" c.lim
        run lim bp
        end=$(awk '$1=="UZ"{v=$2} END{print v}' pts.lim)
        ref=$(awk -v F="$F0" 'BEGIN{printf "%.17g", -1.2519370132295*F}')
        if [ -n "$end" ]; then
          e=$(rel "$end" "$ref"); ok=$(awk -v e="$e" 'BEGIN{print (e+0<=1e-9)?"PASS":"FAIL"}')
          row "$ok" "units.limit.$id" "$e" "$MS" "UZ at Fx = $end, $PTS points (UZ located to EPSS = 1e-5)"
        else
          row FAIL "units.limit.$id" - "$MS" "no UZ (qmax = 1.5) point, $PTS points"
        fi
      else
        row FAIL "units.limit.$id" - - "no BP1 to restart from"
      fi
      # fold: set-up Fy0 -> 0.01 F0, then Fx increasing
      fpar=$(awk -v L="$L" -v k="$k" 'BEGIN{printf "{\x27a\x27:%.17g, \x27b\x27:%.17g, \x27k\x27:%.17g, \x27L0\x27:%.17g}", 0.5*L, L, k, 0.5*L}')
      cfile I_home c.home "$fpar" "{'Fy0':$(awk -v F="$F0" 'BEGIN{printf "%.17g", 0.01*F}')}" "$f" "$thFree"
      run home
      t_home=$MS
      if grep -q UZ pts.home; then
        cfile I_up c.up "$fpar" "{'Fx':[$(awk -v F="$F0" 'BEGIN{printf "%.17g,%.17g", -3*F, 3*F}')], 'qmax':3.0}" "$f" "$thFree"
        sed -i "s/^s=.*/s='home'/; /^PAR=/d" c.up
        run up home
        lp=$(awk '$1=="LP"{print $2; exit}' pts.up)
        nlp=$(awk '$1=="LP"' pts.up | wc -l)
        if [ -n "$lp" ]; then
          e=$(rel "$lp" "$(awk -v F="$F0" 'BEGIN{printf "%.17g", 0.1777097421507*F}')")
          ok=$(awk -v e="$e" 'BEGIN{print (e+0<=1e-9)?"PASS":"FAIL"}')
          row "$ok" "units.fold.$id" "$e" "$MS" "$nlp LP, $PTS points (+ set-up $t_home ms)"
        else
          row FAIL "units.fold.$id" - "$MS" "no LP, $PTS points"
        fi
      else
        row FAIL "units.fold.$id" - "$MS" "set-up Fy0 -> 0.01 F0 did not reach it ($PTS points)"
      fi
    done
  done
done
cfile L_triv c.k0 "{'L0':1.5, 'Fx':0.5}" "{'Fx':-2.5}" 1
run k0
nbp=$(awk '$1=="BP"' pts.k0 | wc -l)
row "$([ "$nbp" -eq 1 ] && echo PASS || echo FAIL)" kappa0.n3 - "$MS" "$nbp BP (double zero at Fx = 0; the determinant does not change sign)"
for id in kappa0.n4 kappa0.n5 kappa0.n10 cluster.low cluster.top limit.n10 limit.n100; do
  row "n/a" "$id" - - "chain.f90 is the 3-segment chain (NDIM 3/4)"
done
