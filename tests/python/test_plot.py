# RunResult.plot* (python/buckle/_plot.py): matplotlib figures rendered headless (Agg) to PNG and
# checked against the run's own records — axis labels equal to the column dictionary's labels in
# the scene's units, one line collection per traced branch, the special-point markers at the
# special points of special_points.json, shapes at the joint positions of the chosen points.
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import buckle

matplotlib = pytest.importorskip("matplotlib", reason="python3-matplotlib is not installed: plots not tested")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def si_run(source_dir):
    return buckle.run_scene(source_dir / "data" / "scenes" / "si_chain.json")


@pytest.fixture(scope="module")
def default_run(source_dir):
    return buckle.run_scene(source_dir / "data" / "scenes" / "default.json")


def branch_collections(ax):
    return [c for c in ax.collections if (c.get_gid() or "").startswith("case ")]


def markers(ax, kind):
    found = [line for line in ax.lines if line.get_gid() == "special " + kind]
    assert len(found) == 1, kind
    return np.asarray(found[0].get_xdata(), dtype=float), np.asarray(found[0].get_ydata(), dtype=float)


def saved_png(fig, path):
    fig.savefig(path, dpi=80)
    assert path.stat().st_size > 1000
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    image = matplotlib.image.imread(path)
    width, height = fig.get_size_inches() * 80
    assert abs(image.shape[0] - height) < 1 and abs(image.shape[1] - width) < 1  # pixels truncated


def test_bifurcation_diagram_in_si_units(si_run, tmp_path):
    r = si_run
    fig = r.plot("bifurcation_q5")
    ax = fig.axes[0]
    assert ax.get_xlabel() == r.label("Fx") == "Fx (N)"
    assert ax.get_ylabel() == r.label("q5") == "q5 (rad)"
    assert ax.get_title() == "Ten-segment chain in SI units"
    # one collection per branch of summary.json
    summary_branches = [b["id"] for b in r["summary"]["cases"][0]["branches"]]
    gids = sorted(c.get_gid() for c in branch_collections(ax))
    assert gids == sorted(f"case 0 branch {b}" for b in summary_branches)
    # its segments run through the branch's points, in order
    b = r["cases"][0]["branches"]
    first = branch_collections(ax)[0]
    on = b["branch"] == summary_branches[0]
    segments = first.get_segments()
    np.testing.assert_array_equal(np.array([s[0] for s in segments]), np.column_stack([b["Fx"][on], b["q"][on, 4]])[:-1])
    # the markers of each type at the special points of special_points.json
    points = r["results"]["special_points"]
    for kind in {p["type"] for p in points}:
        x, y = markers(ax, kind)
        mine = [p for p in points if p["type"] == kind]
        np.testing.assert_array_equal(x, [p["loads"]["Fx"] for p in mine])
        np.testing.assert_array_equal(y, [p["q"][4] for p in mine])
    labels = [t.get_text() for t in ax.texts]
    assert sum(text.count("BP") for text in labels) == sum(p["type"] == "BP" for p in points)
    saved_png(fig, tmp_path / "bifurcation.png")


def test_force_deflection_marks_the_special_points_at_their_end_shortening(si_run, tmp_path):
    r = si_run
    fig = r.plot("force_deflection")
    ax = fig.axes[0]
    assert ax.get_xlabel() == r.label("dx") == "δx = x₀ − x (m)"
    assert ax.get_ylabel() == "Fx (N)"
    x0 = r["cases"][0]["chain"].length  # the straight unloaded chain's end
    for kind in {p["type"] for p in r["special_points"]}:
        x, y = markers(ax, kind)
        mine = [p for p in r["special_points"] if p["type"] == kind]
        np.testing.assert_allclose(x, [x0 - p["position"]["x"] for p in mine], rtol=1e-12, atol=1e-15)
        np.testing.assert_array_equal(y, [p["loads"]["Fx"] for p in mine])
    saved_png(fig, tmp_path / "force_deflection.png")


def test_stiffness_on_a_log_axis_with_the_special_points_on_their_branch(si_run, tmp_path):
    r = si_run
    fig = r.plot_stiffness(x="Fx", y="Ky_xfree")
    ax = fig.axes[0]
    assert ax.get_ylabel() == "1/Cyy (x free) (N/m)"
    values = r["cases"][0]["branches"]["Ky_xfree"]
    finite = values[np.isfinite(values)]
    assert ax.get_yscale() == ("log" if (finite > 0).all() else "symlog")
    assert ax.get_yscale() == "symlog"  # the lateral stiffness changes sign at the first branch point
    # special points without a stiffness of their own lie on their branch's curve: between the
    # values of two consecutive traced points of their branch
    b = r["cases"][0]["branches"]
    for kind in ("BP", "LP"):
        _, y = markers(ax, kind)
        mine = [p for p in r["special_points"] if p["type"] == kind]
        assert len(y) == len(mine) > 0
        for p, yi in zip(mine, y):
            v = values[b["branch"] == p["branch"]]
            v = v[np.isfinite(v)]
            between = [(min(u, w), max(u, w)) for u, w in zip(v[:-1], v[1:])]
            assert any(lo - 1e-12 * abs(lo) <= yi <= hi + 1e-12 * abs(hi) for lo, hi in between), (kind, yi)
    fig2 = r.plot("stiffness_free")
    assert fig2.axes[0].get_ylabel() == "1/Cyy (x free) (N/m), K1 (softest principal) (N/m)"
    assert len(branch_collections(fig2.axes[0])) == 2 * len(r["summary"]["cases"][0]["branches"])
    saved_png(fig, tmp_path / "stiffness.png")


def test_a_kmin_is_marked_at_its_located_stiffness(source_dir):
    r = buckle.run_scene(source_dir / "data" / "scenes" / "contact_release.json")
    kmin = [p for p in r["special_points"] if p["type"] == "KMIN"]
    assert kmin
    c = kmin[0]["case"]
    for column in ("Kxx", "Kyy"):
        fig = r.plot_stiffness(x="parameter", y=column, case=c)
        ax = fig.axes[0]
        assert ax.get_yscale() in ("log", "symlog")
        x, y = markers(ax, "KMIN")
        mine = [p for p in kmin if p["case"] == c]
        np.testing.assert_array_equal(y, [p["stiffness"][column] for p in mine])
        np.testing.assert_array_equal(x, [p["parameter"] for p in mine])


def test_jumps_are_arrows_to_where_the_chain_lands(default_run):
    r = default_run
    fig = r.plot_bifurcation(x="Fx", y="q2")
    ax = fig.axes[0]
    jumps = [p for p in r["special_points"] if (p.get("jump_to") or {}).get("success")]
    arrows = [t for t in ax.texts if t.get_gid() == "jump"]
    assert len(arrows) == len(jumps) > 0
    for a, p in zip(arrows, jumps):
        assert a.xy == (p["jump_to"]["loads"]["Fx"], p["jump_to"]["q"][1])
        assert a.xyann == (p["loads"]["Fx"], p["q"][1])


def test_nondimensional_labels_and_several_columns(default_run):
    fig = default_run.plot_bifurcation(x="parameter", y=["q1", "q2"])
    ax = fig.axes[0]
    assert ax.get_xlabel() == default_run.label("Fx") == "Fx (units of k b)"
    assert ax.get_ylabel() == "q1 (rad), q2 (rad)"
    branches = len(default_run["summary"]["cases"][0]["branches"])
    assert len(branch_collections(ax)) == 2 * branches


def test_shapes_draw_the_stable_point_nearest_each_value(si_run, tmp_path):
    r = si_run
    at = [-1.0, -2.5, -3.5]
    fig = r.plot("shapes")
    drawn = [ax for ax in fig.axes if ax.lines]
    assert len(drawn) == len(at)
    b = r["cases"][0]["branches"]
    stable = np.flatnonzero(b["stable"])
    chain = r["cases"][0]["chain"]
    for ax, value in zip(drawn, at):
        i = stable[np.argmin(np.abs(b["parameter"][stable] - value))]
        line = next(line for line in ax.lines if line.get_gid() == "chain")
        np.testing.assert_array_equal(np.column_stack([line.get_xdata(), line.get_ydata()]), chain.joint_positions(b["q"][i]))
        assert ax.get_xlabel() == "x (m)" and ax.get_ylabel() == "y (m)"
        assert ax.get_aspect() == 1.0
        assert f"= {b['parameter'][i]:.4g}" in ax.get_title()
    saved_png(fig, tmp_path / "shapes.png")


def test_plot_errors_name_what_there_is(si_run, source_dir):
    with pytest.raises(KeyError, match="no column 'Fz'.*Fx"):
        si_run.plot_bifurcation(x="Fz", y="q1")
    with pytest.raises(KeyError, match="no plot 'nothing'.*bifurcation_q5"):
        si_run.plot("nothing")
    with pytest.raises(ValueError, match="torque_angle plot is drawn by run_scene.*plots/torque_angle.png"):
        si_run.plot("torque_angle")
    without_shapes = buckle.run_scene(source_dir / "data" / "scenes" / "fig2.json")
    with pytest.raises(ValueError, match="plot_shapes needs `at`"):
        without_shapes.plot_shapes()


def test_the_package_imports_and_runs_without_matplotlib_and_pandas(source_dir):
    # both blocked: import buckle and run_scene work, the plot and frame methods name what to install
    code = f"""
import sys
sys.modules["matplotlib"] = None
sys.modules["pandas"] = None
import buckle
r = buckle.run_scene({str(source_dir / "data" / "scenes" / "default.json")!r})
assert len(r["cases"][0]["branches"]["Fx"]) > 0
for method in (r.plot, r.branches_frame):
    try:
        method()
    except ImportError as e:
        print(e)
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=os.environ, timeout=120)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 2
    assert "python3-matplotlib" in lines[0] and "python3-pandas" in lines[1]


def test_a_long_chains_diagram_is_a_summary(source_dir):
    # the default scene at 50 segments: thousands of special points on about a hundred branches
    scene = json.loads((source_dir / "data" / "scenes" / "default.json").read_text())
    scene["chain"]["segments"] = 50
    r = buckle.run_scene(scene)
    points = r["special_points"]
    assert len(points) > 60
    fig = r.plot("bifurcation_q2")
    ax = fig.axes[0]
    assert len(branch_collections(ax)) == len(r["summary"]["cases"][0]["branches"])
    assert all(c.get_linewidth()[0] < 1 and c.get_alpha() < 1 for c in branch_collections(ax))
    # every special point still marked, the key counting each type as special_points.json does
    kinds = {p["type"] for p in points}
    for kind in kinds:
        x, _ = markers(ax, kind)
        assert len(x) == sum(p["type"] == kind for p in points)
    key = {t.get_text() for t in ax.get_legend().get_texts()}
    assert {f"{kind} ({sum(p['type'] == kind for p in points)})" for kind in kinds} <= key
    # labelled: the branch points of the primary branch, full size, as ranges of their mode numbers
    primary = r["cases"][0]["branches"]["branch"][0]
    modes = sorted(int(p["shape"].split()[1]) for p in points if p["type"] == "BP" and p["branch"] == primary)
    big = [line for line in ax.lines if line.get_gid() == "labelled BP"]
    assert len(big) == len(modes)
    labels = [t.get_text() for t in ax.texts if t.get_gid() != "jump"]
    assert all(t.startswith("BP ") for t in labels) and 1 < len(labels) < len(modes)
    covered = []
    for text in labels:
        first, _, last = text[3:].partition("-")
        covered += [m for m in modes if int(first) <= m <= int(last or first)]
    assert sorted(covered) == modes  # each mode in exactly one label


def test_disconnected_branches_in_their_own_colour_and_keyed(source_dir):
    # the branches traced from equilibria the tree does not reach, as the gnuplot diagram draws them
    r = buckle.run_scene(source_dir / "data" / "scenes" / "disconnected_branch.json")
    ids = {d["id"] for d in r["cases"][0]["equilibria"]["disconnected_branches"]}
    assert len(ids) == 2
    ax = r.plot_bifurcation(x="Fx", y="q2").axes[0]
    drawn = branch_collections(ax)
    assert len(drawn) == len(np.unique(r["cases"][0]["branches"]["branch"]))
    for col in drawn:
        branch = int(col.get_gid().split()[3])
        colours = {matplotlib.colors.to_hex(c) for c in col.get_colors()}
        if branch in ids:
            assert col.get_gid().endswith("disconnected")
            assert colours == {"#c51b7d"}
        else:
            assert "#c51b7d" not in colours
    assert "disconnected branch" in [t.get_text() for t in ax.get_legend().get_texts()]
    # a run without them keys none
    plain = buckle.run_scene(source_dir / "data" / "scenes" / "default.json").plot_bifurcation(x="Fx", y="q2")
    assert "disconnected branch" not in [t.get_text() for t in plain.axes[0].get_legend().get_texts()]
