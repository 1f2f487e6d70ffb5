#!/usr/bin/env bash
# Every equilibrium at one state (issue 30) against n, in the shipped nondimensional units and in SI
# (b = 0.02 m, k = 2000 N/m: lengths × 0.02, forces × 40 N, torques × 0.8 N·m): the scenes
# data/scenes/equilibria_n3_held.json, equilibria_n5_load.json and benchmarks/scenes/equilibria_n10.json,
# equilibria_n50.json. Per scene and unit system: the equilibria stage (summary.json
# timings_seconds, median of REPS runs), the count found and stable per case, the starts and
# Newton runs, and the largest difference of the joint angles between the two unit systems (each
# equilibrium against its nearest: mirror images have the same potential, so their order may differ).
#
#   BUILD=build REPS=5 benchmarks/equilibria_units.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
BUILD=${BUILD:-build}
REPS=${REPS:-5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$BUILD/bin/buckle" "$REPS" "$work" <<'EOF'
import json, statistics, subprocess, sys, pathlib
buckle, reps, work = sys.argv[1], int(sys.argv[2]), pathlib.Path(sys.argv[3])
L, K = 0.02, 2000.0
scenes = ["data/scenes/equilibria_n3_held.json", "data/scenes/equilibria_n5_load.json",
          "benchmarks/scenes/equilibria_n10.json", "benchmarks/scenes/equilibria_n50.json"]

def si(doc):
    """The scene in b = 0.02 m, k = 2000 N/m (the shipped ones have b = k = 1)."""
    d = json.loads(json.dumps(doc))
    d["units"] = {"length": "m", "force": "N"}
    def chain(c):
        for key in ("a", "b", "L0", "L1_0", "L2_0"):
            if key in c:
                c[key] *= L
        if "k" in c:
            c["k"] *= K
    chain(d["chain"])
    for case in d.get("cases", []):
        chain(case.get("chain", {}))
    for key, unit in (("x", L), ("y", L), ("phi", 1.0)):
        e = d["end"].get(key)
        if isinstance(e, dict):
            scale = unit if "held" in e else (K * L * L if key == "phi" else K * L)
            for k in ("held", "load"):
                if isinstance(e.get(k), (int, float)):
                    e[k] *= scale
    ec = d["analyses"].get("energy_curves")
    if ec:
        ec["x"] *= L
        ec["y"] *= L
    return d

def run(doc, name):
    path = work / f"{name}.json"
    path.write_text(json.dumps(doc))
    times = []
    for r in range(reps):
        out = work / f"{name}_out"
        subprocess.run([buckle, "run", str(path), "--out", str(out), "--force", "--quiet"], check=True)
        summary = json.loads((out / "summary.json").read_text())
        times.append(summary["timings_seconds"]["equilibria"])
    sp = json.loads((out / "special_points.json").read_text())
    return statistics.median(times), sp["equilibria"]

print("| scene | n | units | equilibria found (stable) per case | starts, Newton runs | stage (median) | max |Δq| SI vs nondimensional |")
print("|---|---|---|---|---|---|---|")
for s in scenes:
    doc = json.loads(pathlib.Path(s).read_text())
    n = doc["chain"]["segments"]
    rows = {}
    for units, d in (("k b", doc), ("SI", si(doc))):
        rows[units] = run(d, pathlib.Path(s).stem + "_" + units.replace(" ", ""))
    dq = 0.0
    for a, b in zip(rows["k b"][1], rows["SI"][1]):
        if len(a["equilibria"]) != len(b["equilibria"]):
            dq = float("inf")
            continue
        for e in a["equilibria"]:  # mirror images share Π: match each to its nearest
            dq = max(dq, min(max(abs(x - y) for x, y in zip(e["q"], f["q"])) for f in b["equilibria"]))
    for units in ("k b", "SI"):
        t, sets = rows[units]
        found = ", ".join(f"{c['count']} ({c['stable_count']})" for c in sets)
        runs = ", ".join(f"{c['starts']}, {c['newton_runs']}" for c in sets)
        print(f"| `{s}` | {n} | {units} | {found} | {runs} | {t:.4f} s | {dq:.1e} |")
EOF
