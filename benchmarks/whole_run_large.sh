#!/usr/bin/env bash
# The whole process on the default scene with more segments (issue 27, "Trust at every size"):
# wall time against the time limit, peak memory, output sizes and how many of the first branch
# points had their branches finished, for each n. Usage (from the repository root):
#   bash benchmarks/whole_run_large.sh [BUILD_DIR] [TIME_LIMIT] [n ...]
# defaults: build, 60 s, n = 200 1000 10000. Prints one line per n; record the machine's load
# (uptime) beside the figures in RESULTS.md.
set -Eeuo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${1:-build}
LIMIT=${2:-60}
shift $(( $# > 2 ? 2 : $# ))
SIZES=("$@")
((${#SIZES[@]})) || SIZES=(200 1000 10000)
BUCKLE=$ROOT/$BUILD/bin/buckle
[[ -x $BUCKLE ]] || { echo "no $BUCKLE: build it first" >&2; exit 2; }
TMP=$(mktemp -d "${TMPDIR:-/tmp}/buckle-large.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
echo "load: $(uptime)"
for n in "${SIZES[@]}"; do
  sed "s/\"segments\": 3/\"segments\": $n/" "$ROOT/data/scenes/default.json" >"$TMP/default_$n.json"
  set +e
  /usr/bin/time -v "$BUCKLE" run "$TMP/default_$n.json" -o "$TMP/out_$n" --force --time-limit "$LIMIT" \
    >/dev/null 2>"$TMP/time_$n.txt"
  rc=$?
  set -e
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$TMP/time_$n.txt")
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$TMP/time_$n.txt")
  python3 - "$TMP/out_$n" "$n" "$wall" "$rss" "$rc" <<'PY'
import json, os, sys
out, n, wall, rss, rc = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5]
s = json.load(open(os.path.join(out, "summary.json")))
c = s["cases"][0]
branches = c["branches"]
# the branches of the first 20 branch points of the straight branch: origins "BP k of branch 0"
first = {}
for b in branches:
    o = b["origin"]
    if o.startswith("BP ") and o.split()[4] == "0,":
        k = int(o.split()[1])
        if k <= 20:
            first.setdefault(k, []).append(b["finished"])
complete = sum(1 for k in first if len(first[k]) == 2 and all(first[k]))
size = lambda f: os.path.getsize(os.path.join(out, f)) / 1e6 if os.path.exists(os.path.join(out, f)) else 0.0
print(f"n = {n}: exit {rc}, wall {wall}, peak RSS {rss / 1024:.0f} MB, {len(branches)} branches, "
      f"first 20 BPs with both branches finished: {complete}, "
      f"{'interrupted (' + s['interruption'] + ')' if s['interrupted'] else 'not interrupted'}, "
      f"report.html {size('report.html'):.1f} MB, branches.csv {size('branches.csv'):.1f} MB, "
      f"joint_angles.npy {size('joint_angles.npy'):.1f} MB")
PY
done
