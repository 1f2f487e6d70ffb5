#!/usr/bin/env bash
# Workspace and stability maps (issue 29) at n = 3 and 10: the scenes data/scenes/workspace.json and
# workspace_n10.json as `buckle run` processes (no plots), in their nondimensional units and in SI
# (b = 0.02 m, k = 2000 N/m: lengths and the inputs' ranges × 0.02, forces × 40 N). Per scene and unit
# system: the workspace stage (summary.json timings_seconds, median of REPS runs), the whole process's
# wall time and peak memory (GNU time), the grid's reached and stable counts, the curves by cause with
# their points and worst residual, and the largest difference of the stable grid's end positions
# between the two unit systems (in b).
#
#   BUILD=build REPS=3 benchmarks/workspace_map.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
BUILD=${BUILD:-build}
REPS=${REPS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$BUILD/bin/buckle" "$REPS" "$work" <<'PY'
import csv, json, statistics, subprocess, sys, pathlib
buckle, reps, work = sys.argv[1], int(sys.argv[2]), pathlib.Path(sys.argv[3])
L, K = 0.02, 2000.0
scenes = ["data/scenes/workspace.json", "data/scenes/workspace_n10.json"]

def si(doc):
    d = json.loads(json.dumps(doc))
    d["units"] = {"length": "m", "force": "N"}
    for key in ("a", "b", "L0", "L1_0", "L2_0"):
        if key in d["chain"]:
            d["chain"][key] *= L
    d["chain"]["k"] *= K
    for key in ("x", "y"):
        e = d["end"].get(key)
        if isinstance(e, dict) and "load" in e:
            e["load"] *= K * L
    w = d["analyses"]["workspace"]
    for axis in ("first", "second"):
        for key in ("from", "to"):
            w[axis][key] *= L
    d["solver"]["step"]["max_step"] *= 1.0
    return d

def run(doc, name):
    path = work / (name + ".json")
    doc = dict(doc)
    doc["plots"] = []
    path.write_text(json.dumps(doc))
    out = work / (name + "_out")
    times, walls, rss = [], [], []
    for _ in range(reps):
        r = subprocess.run(["/usr/bin/time", "-f", "%e %M", buckle, "run", str(path), "-o", str(out), "--force",
                            "--quiet"], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{name}: exit {r.returncode}: {r.stderr[-2000:]}")
        wall, kb = r.stderr.strip().split("\n")[-1].split()
        walls.append(float(wall))
        rss.append(int(kb) / 1024)
        s = json.loads((out / "summary.json").read_text())
        times.append(s["timings_seconds"]["workspace"])
    sp = json.loads((out / "special_points.json").read_text())["workspace"][0]
    cells = list(csv.DictReader(open(out / "workspace_map.csv")))
    return statistics.median(times), statistics.median(walls), max(rss), sp, cells

print("| scene | units | n | grid | workspace stage s | process s | peak MB | reached | stable | curves (points, worst residual) | max Δ(x, y)/b vs nondimensional |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for scene in scenes:
    doc = json.loads(pathlib.Path(scene).read_text())
    base = None
    for units, d, scale in (("nondimensional", doc, 1.0), ("SI (b = 0.02 m, k = 2000 N/m)", si(doc), L)):
        t, wall, mb, sp, cells = run(d, pathlib.Path(scene).stem + ("_si" if scale != 1.0 else ""))
        curves = ", ".join(f"{c['cause']} {c['points']} pts ({c['worst_residual']:.1e})" for c in sp["curves"])
        diff = ""
        if base is None:
            base = cells
        else:
            worst = 0.0
            for a, b in zip(base, cells):
                if a["stable"] == "1" and b["stable"] == "1":
                    worst = max(worst, abs(float(b["x"]) / scale - float(a["x"])), abs(float(b["y"]) / scale - float(a["y"])))
            diff = f"{worst:.1e}"
        print(f"| {pathlib.Path(scene).name} | {units} | {doc['chain']['segments']} | {sp['grid'][0]}×{sp['grid'][1]} | "
              f"{t:.3f} | {wall:.2f} | {mb:.0f} | {sp['reached']} | {sp['stable']} | {curves} | {diff} |")
PY
