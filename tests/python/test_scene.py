# buckle.run_scene against `buckle run`: the same scene gives the same special points, branches
# and summary through the module as through the command line; time limits and Ctrl-C.
import csv
import json
import os
import pathlib
import signal
import threading
import time

import numpy as np
import pytest

import buckle

# Every shipped scene (each runs in well under 3 s in a release build).
SCENES = sorted(p.name for p in (pathlib.Path(__file__).resolve().parents[2] / "data" / "scenes").glob("*.json"))


def read_branches_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def close(a, b, rel=1e-9):
    """Equal to rounding: both None/NaN, or relatively close against the larger magnitude and 1."""
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= rel * max(1.0, abs(a), abs(b))


def run_shipped_scene(name, source_dir, run_cli, tmp_path):
    """`buckle run` of data/scenes/NAME into tmp_path/out: the scene's path and the output directory."""
    scene = source_dir / "data" / "scenes" / name
    out = tmp_path / "out"
    cli = run_cli("run", scene, "--out", out, "--quiet")
    assert cli.returncode == 0, cli.stderr
    return scene, out


@pytest.mark.parametrize("name", SCENES)
def test_module_results_equal_the_command_line(name, source_dir, run_cli, tmp_path):
    scene, out = run_shipped_scene(name, source_dir, run_cli, tmp_path)
    expected = json.loads((out / "special_points.json").read_text())
    summary = json.loads((out / "summary.json").read_text())

    r = buckle.run_scene(str(scene))
    assert r["complete"] is True and r["interrupted"] is False
    assert r["computed"] == summary["computed"]
    got = r["special_points"]
    assert len(got) == len(expected["special_points"])
    for g, e in zip(got, expected["special_points"]):
        for key in ("case", "type", "field", "branch", "shape", "stability_before", "stability_after"):
            assert g[key] == e[key], key
        assert close(g["parameter"], e["parameter"])
        assert all(close(x, y) for x, y in zip(g["q"], e["q"]))
        assert close(g["accuracy"]["parameter"], e["accuracy"]["parameter"], rel=1e-6) or \
            max(g["accuracy"]["parameter"], e["accuracy"]["parameter"]) <= 1e-12 * max(1.0, abs(e["parameter"]))
    for key in ("critical_loads", "energy_equilibria", "torque_zeros"):
        assert (key in r["results"]) == (key in expected)
        if key in expected:
            assert len(r["results"][key]) == len(expected[key])
    for c, case in enumerate(r["cases"]):
        s = summary["cases"][c]
        assert case["label"] == s["label"] and case["segments"] == s["segments"]
        if "branches" in s:
            assert set(np.unique(case["branches"]["branch"]).tolist()) <= {b["id"] for b in s["branches"]}
    if (out / "branches.csv").exists():
        rows = read_branches_csv(out / "branches.csv")
        for c, case in enumerate(r["cases"]):
            mine = [row for row in rows if int(row["case"]) == c]
            b = case["branches"]
            assert len(mine) == len(b["parameter"])
            csv_parameter = np.array([float(row["parameter"]) for row in mine])
            # branches.csv has 12 significant digits
            np.testing.assert_allclose(b["parameter"], csv_parameter, rtol=1e-11, atol=1e-11)
            if (out / "joint_angles.npy").exists():
                # a long chain's joint angles: every row of branches.csv, to the last bit
                first = next(k for k, row in enumerate(rows) if int(row["case"]) == c)
                q = np.load(out / "joint_angles.npy")
                assert q.shape == (len(rows), max(cs["segments"] for cs in summary["cases"]))
                np.testing.assert_array_equal(b["q"], q[first:first + len(mine), :case["segments"]])
                np.testing.assert_allclose([float(row["max_abs_q"]) for row in mine], np.abs(b["q"]).max(axis=1),
                                           rtol=1e-11)
            for i in range(case["segments"] if "q1" in mine[0] else 0):
                csv_q = np.array([float(row[f"q{i + 1}"]) for row in mine])
                np.testing.assert_allclose(b["q"][:, i], csv_q, rtol=1e-11, atol=1e-11)
            np.testing.assert_array_equal(b["stable"], [row["stable"] == "1" for row in mine])
            # the natural frequencies (`frequencies`): the same columns as the CSV's, same values
            omega = [k for k in mine[0] if k.startswith("omega")]
            assert sorted(k for k in b if str(k).startswith("omega")) == sorted(omega)
            for k in omega:
                csv_omega = np.array([float(row[k]) if row[k] not in ("", "nan") else np.nan for row in mine])
                np.testing.assert_allclose(b[k], csv_omega, rtol=1e-11, atol=1e-11 * np.nanmax(np.abs(csv_omega)))
            # a task path's inputs (`path.task`): the CSV's input columns, same values
            inputs = [k for k in mine[0] if k.split("[")[0] in ("L1_0", "L2_0", "L0", "dL0")]
            assert sorted(k for k in b if str(k).split("[")[0] in ("L1_0", "L2_0", "L0", "dL0")) == sorted(inputs)
            for k in inputs:
                csv_input = np.array([float(row[k]) if row[k] not in ("", "nan") else np.nan for row in mine])
                np.testing.assert_allclose(b[k], csv_input, rtol=1e-11, atol=1e-11)


EQUILIBRIA_SCENES = [name for name in SCENES if "equilibria" in json.loads(
    (pathlib.Path(__file__).resolve().parents[2] / "data" / "scenes" / name).read_text()).get("analyses", {})]


@pytest.mark.parametrize("name", EQUILIBRIA_SCENES)
def test_module_equilibria_equal_equilibria_csv(name, source_dir, run_cli, tmp_path):
    scene, out = run_shipped_scene(name, source_dir, run_cli, tmp_path)
    with open(out / "equilibria.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    summary = json.loads((out / "summary.json").read_text())
    r = buckle.run_scene(str(scene))
    assert len(rows) > 0
    for c, case in enumerate(r["cases"]):
        e = case["equilibria"]
        mine = [row for row in rows if int(row["case"]) == c]
        assert len(mine) == len(e["potential"]) == e["q"].shape[0]
        np.testing.assert_array_equal(e["rank"], [int(row["rank"]) for row in mine])
        np.testing.assert_allclose(e["at"], [float(row["at"]) for row in mine], rtol=1e-14)
        for value in np.unique(e["at"]):  # ranked by potential within each set
            ranks = e["rank"][e["at"] == value]
            assert list(ranks) == list(range(1, len(ranks) + 1))
            assert (np.diff(e["potential"][e["at"] == value]) >= 0).all()
        # equilibria.csv has 15 significant digits
        np.testing.assert_allclose(e["potential"], [float(row["potential"]) for row in mine], rtol=1e-13)
        for i in range(case["segments"]):
            np.testing.assert_allclose(e["q"][:, i], [float(row[f"q{i + 1}"]) for row in mine], rtol=1e-13,
                                       atol=1e-14)
        np.testing.assert_array_equal(e["index"], [int(row["index"]) for row in mine])
        np.testing.assert_array_equal(e["stable"], [row["stable"] == "1" for row in mine])
        assert e["shape"] == [row["shape"] for row in mine]
        # with "branches": the branch through each, and the disconnected branches as in summary.json
        if "branch" in rows[0]:
            np.testing.assert_array_equal(e["branch"], [int(row["branch"]) if row["branch"] else -1 for row in mine])
        else:
            assert (e["branch"] == -1).all()
        seeds = {b["id"]: (b["from_equilibrium"], b["from_equilibrium_at"])
                 for b in summary["cases"][c].get("branches", []) if "from_equilibrium" in b}
        assert {b["id"]: (b["from_equilibrium"], b["from_equilibrium_at"]) for b in e["disconnected_branches"]} == seeds
        for b in e["disconnected_branches"]:
            assert b["from_equilibrium"] in set(e["rank"][e["at"] == b["from_equilibrium_at"]].tolist())
            assert b["id"] in set(np.unique(case["branches"]["branch"]).tolist())


WORKSPACE_SCENES = [name for name in SCENES if "workspace" in json.loads(
    (pathlib.Path(__file__).resolve().parents[2] / "data" / "scenes" / name).read_text()).get("analyses", {})]


@pytest.mark.parametrize("name", WORKSPACE_SCENES)
def test_module_workspace_equals_workspace_csvs(name, source_dir, run_cli, tmp_path):
    scene, out = run_shipped_scene(name, source_dir, run_cli, tmp_path)
    with open(out / "workspace_map.csv", newline="") as f:
        grid = list(csv.DictReader(f))
    with open(out / "workspace_curves.csv", newline="") as f:
        points = list(csv.DictReader(f))
    r = buckle.run_scene(str(scene))
    assert len(WORKSPACE_SCENES) >= 2
    for c, case in enumerate(r["cases"]):
        w = case["workspace"]
        mine = [row for row in grid if int(row["case"]) == c]
        rows, cols = w["u1"].shape
        assert rows * cols == len(mine) > 0
        # row-major: u2 outer, u1 inner, as the CSV
        np.testing.assert_allclose(w["u1"].ravel(), [float(row["u1"]) for row in mine], rtol=1e-14)
        np.testing.assert_allclose(w["u2"].ravel(), [float(row["u2"]) for row in mine], rtol=1e-14, atol=1e-15)
        np.testing.assert_array_equal(w["reached"].ravel(), [int(row["reached"]) for row in mine])
        reached = w["reached"].ravel() == 1
        for key in ("x", "y", "min_eig"):
            np.testing.assert_allclose(w[key].ravel()[reached], [float(row[key]) for row in mine if row["reached"] == "1"],
                                       rtol=1e-13, atol=1e-14)
        assert np.isnan(w["x"].ravel()[~reached]).all()
        np.testing.assert_array_equal(w["stable"].ravel(), [int(row["stable"] or 0) for row in mine])
        # a stable grid value has no negative eigenvalue and a positive definite end stiffness
        stable = w["stable"].ravel() == 1
        assert (w["negative_eigenvalues"].ravel()[stable] == 0).all()
        assert (w["stiffness_min"].ravel()[stable] > 0).all()
        curves = [row for row in points if int(row["case"]) == c]
        assert sum(len(cu["u1"]) for cu in w["curves"]) == len(curves)
        for k, cu in enumerate(w["curves"]):
            mine_k = [row for row in curves if int(row["curve"]) == k]
            assert cu["cause"] == mine_k[0]["cause"] and cu["name"] == mine_k[0]["name"]
            np.testing.assert_allclose(cu["x"], [float(row["x"]) for row in mine_k], rtol=1e-13, atol=1e-14)


def test_a_dict_runs_like_its_file(source_dir):
    path = source_dir / "data" / "scenes" / "fig2.json"
    from_file = buckle.run_scene(path)
    from_dict = buckle.run_scene(json.loads(path.read_text()))
    assert len(from_file["special_points"]) == len(from_dict["special_points"])
    for a, b in zip(from_file["special_points"], from_dict["special_points"]):
        assert a["type"] == b["type"] and a["parameter"] == b["parameter"]
    assert from_dict["summary"]["scene"] == "<dict>"


def test_out_writes_the_command_lines_directory_with_the_report(source_dir, tmp_path):
    out = tmp_path / "run"
    r = buckle.run_scene(source_dir / "data" / "scenes" / "fig2.json", out=str(out))
    assert r["complete"]
    for f in ("summary.json", "special_points.json", "report.html"):
        assert (out / f).is_file(), f
    written = json.loads((out / "special_points.json").read_text())
    assert [p["parameter"] for p in written["special_points"]] == [p["parameter"] for p in r["special_points"]]
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(ValueError, match="not a buckle output"):
        buckle.run_scene(source_dir / "data" / "scenes" / "fig2.json", out=str(tmp_path / "mine"))
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def long_run(source_dir):
    """The long-chain scene at 1000 segments: about a minute of work in a release build, so a time
    limit or an interrupt after a fraction of a second always meets it mid-run (the shipped
    50-segment scene now finishes in half a second, which a fast machine beats)."""
    s = json.loads((source_dir / "data" / "scenes" / "long_chain_jumps.json").read_text())
    s["chain"]["segments"] = 1000
    return s


def test_time_limit_returns_what_was_computed(source_dir):
    started = time.monotonic()
    r = buckle.run_scene(long_run(source_dir), time_limit=0.5)
    assert time.monotonic() - started < 10
    assert r["interrupted"] is True and r["complete"] is False
    assert "time limit" in r["interruption"]
    assert r["summary"]["solver"]["time_limit"] == 0.5


def interrupt_after(seconds):
    """A timer that sends this process SIGINT (Ctrl-C) after `seconds`."""
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_keyboard_interrupt_stops_a_run(source_dir):
    timer = interrupt_after(0.1)
    started = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt) as raised:
            buckle.run_scene(long_run(source_dir))
    finally:
        timer.cancel()
    assert time.monotonic() - started < 10
    # the partial result rides on the exception
    r = raised.value.result
    assert isinstance(r, buckle.RunResult)
    assert r["interrupted"] is True and r["complete"] is False and "KeyboardInterrupt" in r["interruption"]


def test_keyboard_interrupt_writes_what_was_computed_to_out(source_dir, tmp_path):
    # as `buckle run` on SIGINT: the output directory holds the partial results, marked interrupted,
    # before KeyboardInterrupt reaches the caller
    out = tmp_path / "partial"
    timer = interrupt_after(1.0)
    try:
        with pytest.raises(KeyboardInterrupt, match="written to " + str(out)) as raised:
            buckle.run_scene(long_run(source_dir), out=str(out))
    finally:
        timer.cancel()
    r = raised.value.result
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["complete"] is False
    assert summary["interruption"] == r["interruption"]
    rows = read_branches_csv(out / "branches.csv")
    assert len(rows) == len(r["cases"][0]["branches"]["parameter"]) > 0
    np.testing.assert_allclose([float(row["Fx"]) for row in rows], r["cases"][0]["branches"]["Fx"], rtol=1e-11)
    written = json.loads((out / "special_points.json").read_text())["special_points"]
    assert len(written) == len(r["special_points"])
    assert not summary["plots"]["files"]  # after Ctrl-C no plot is drawn, as on the command line
    assert (out / "report.html").is_file()


def test_the_gil_is_released_while_a_scene_runs(source_dir):
    # while another thread computes, this one keeps running Python code: with the GIL held for
    # the whole computation it could not count at all until the run is over
    worker = threading.Thread(target=buckle.run_scene, args=(long_run(source_dir),), kwargs={"time_limit": 1.0})
    counted = 0
    worker.start()
    time.sleep(0.05)
    while worker.is_alive():
        counted += 1
    worker.join()
    assert counted > 10000
