#!/usr/bin/env bash
# Sliding on the base wall in the dynamics (issue 31): a chain of n paper segments (a = 0.5, b = 1,
# k = 1, L0 = 2.25) curled by 170°/n per joint (its end in front of the clamp's wall) hit at once
# by an end force Fx = −20/n² with the wall traced: the gradient flow pushes the last triangle
# onto the wall, holds it there and comes to rest on the constrained equilibrium. The whole
# process, the dynamics' own time, the number of contact events, the rest's wall vertices and
# forces and the integration's duration, for each n. Usage (from the repository root):
#   bash benchmarks/wall_sliding.sh [BUILD_DIR] [n ...]
# defaults: build, n = 3 50 1000. Record the machine's load (printed) beside the figures.
set -Eeuo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/sizes_lib.sh"
sizes_setup wall 3 50 1000 -- "$@"
for n in "${SIZES[@]}"; do
  python3 - "$n" "$TMP/wall_$n.json" <<'PY'
import json, math, sys
n, path = int(sys.argv[1]), sys.argv[2]
fx = -20.0 / n**2
scene = {"units": "nondimensional",
         "description": f"benchmarks/wall_sliding.sh: {n} curled segments pushed onto the base wall",
         "chain": {"segments": n, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25, "q0": [math.radians(170) / n] * n},
         "end": {"x": {"load": 0.0}, "y": {"load": 0.0}, "phi": "free"},
         "path": {"parameter": "Fx", "from": 0.0, "to": fx},
         "analyses": {"continuation": {"wall": True, "branch_switching": 0}, "sudden_load": {"value": fx}}}
json.dump(scene, open(path, "w"))
PY
  /usr/bin/time -v "$BUCKLE" run "$TMP/wall_$n.json" -o "$TMP/out_$n" --force -q >/dev/null 2>"$TMP/time_$n.txt"
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$TMP/time_$n.txt")
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$TMP/time_$n.txt")
  python3 - "$TMP/out_$n" "$n" "$wall" "$rss" <<'PY'
import json, os, sys
out, n, wall, rss = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
sudden = json.load(open(os.path.join(out, "special_points.json")))["sudden_load"][0]
seconds = json.load(open(os.path.join(out, "summary.json")))["timings_seconds"]["sudden_load"]
rest = ", ".join(f"{w['vertex']} {w['wall_force']:.6g}" for w in sudden["rest"]["wall"])
print(f"n = {n}: {wall} wall, {rss / 1024:.0f} MB; dynamics {seconds:.3g} s to rest at t = {sudden['duration']:.4g}, "
      f"{len(sudden['contact_events'])} contact events, success {sudden['success']}, on the wall: {rest}")
PY
done
