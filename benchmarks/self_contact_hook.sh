#!/usr/bin/env bash
# Self contact along a branch (issue 31): the hook of data/scenes/self_contact_hook.json with n
# segments — the first n/5 straight, the last 4n/5 curled by 4.5 rad in all, the free end under an
# end moment Me from 0 to 1.5/n (0.27 at n = 8, 0.01 at 200, 0.001 at 1000), self contact traced as a constraint, the loaded
# stiffness at every point — until the end's corner is held on the straight part. The whole process
# (wall, peak memory), the continuation's own time, the points, the points holding a self contact,
# and the contact events, for each n. Usage (from the repository root):
#   bash benchmarks/self_contact_hook.sh [BUILD_DIR] [n ...]
# defaults: build, n = 8 50 200 1000. Record the machine's load (printed) beside the figures.
set -Eeuo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/sizes_lib.sh"
sizes_setup hook 8 50 200 1000 -- "$@"
for n in "${SIZES[@]}"; do
  python3 - "$ROOT/data/scenes/self_contact_hook.json" "$n" "$TMP/hook_$n.json" <<'PY'
import json, sys
shipped, n, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
scene = json.load(open(shipped))
if n != 8:
    straight = n // 5
    scene["chain"]["segments"] = n
    scene["chain"]["q0"] = [0.0] * straight + [4.5 / (n - straight)] * (n - straight)
    scene["path"]["to"] = {200: 0.01, 1000: 0.001}.get(n, 1.5 / n)
scene["description"] = f"benchmarks/self_contact_hook.sh: the hook with {n} segments"
scene["analyses"] = {"continuation": {"branch_switching": 0, "self": True}, "stiffness": True}
scene["plots"] = []
json.dump(scene, open(path, "w"))
PY
  status=0
  /usr/bin/time -v "$BUCKLE" run "$TMP/hook_$n.json" -o "$TMP/out_$n" --force -q >/dev/null 2>"$TMP/time_$n.txt" || status=$?
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$TMP/time_$n.txt")
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$TMP/time_$n.txt")
  python3 - "$TMP/out_$n" "$n" "$wall" "$rss" "$status" <<'PY'
import csv, json, os, sys
out, n, wall, rss, status = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5]
summary = json.load(open(os.path.join(out, "summary.json")))
seconds = summary["timings_seconds"]["continuation"]
rows = list(csv.DictReader(open(os.path.join(out, "branches.csv"))))
held = sum(1 for r in rows if r.get("self", ""))
events = [s["type"] for s in json.load(open(os.path.join(out, "special_points.json")))["special_points"]
          if s["type"] in ("SH", "SR", "SC")]
print(f"n = {n}: exit {status}, {wall} wall, {rss / 1024:.0f} MB; continuation {seconds:.3g} s, "
      f"{len(rows)} points ({held} holding a self contact, {seconds / max(len(rows), 1) * 1e3:.3g} ms a point), "
      f"events {' '.join(events) or '-'}")
PY
done
