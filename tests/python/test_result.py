# RunResult (python/buckle/_result.py): the arrays, labels and DataFrames of a run against the
# files `buckle run` writes for the same scene (branches.csv, special_points.json,
# equilibria.csv, report.html's labels).
import csv
import json
import math
import sys

import numpy as np
import pytest

import buckle


def run_both(name, source_dir, run_cli, tmp_path):
    """run_scene of data/scenes/NAME and the output directory `buckle run` writes for it."""
    scene = source_dir / "data" / "scenes" / name
    out = tmp_path / "out"
    cli = run_cli("run", scene, "--out", out, "--quiet")
    assert cli.returncode == 0, cli.stderr
    return buckle.run_scene(scene), out


def csv_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    return float(text) if text not in ("", "nan") else math.nan


@pytest.mark.parametrize("name", ["si_chain.json", "default.json"])
def test_special_point_arrays_are_special_points_json(name, source_dir, run_cli, tmp_path):
    r, out = run_both(name, source_dir, run_cli, tmp_path)
    written = json.loads((out / "special_points.json").read_text())["special_points"]
    sp = r["cases"][0]["special_points"]
    assert sp["type"] == [p["type"] for p in written]
    np.testing.assert_array_equal(sp["index"], range(len(written)))
    np.testing.assert_array_equal(sp["branch"], [p["branch"] for p in written])
    np.testing.assert_allclose(sp["parameter"], [p["parameter"] for p in written], rtol=1e-15)
    for column in ("Fx", "Fy", "Me"):
        np.testing.assert_allclose(sp[column], [p["loads"][column] for p in written], rtol=1e-15)
    for column in ("x", "y", "phi"):
        np.testing.assert_allclose(sp[column], [p["position"][column] for p in written], rtol=1e-15)
    np.testing.assert_allclose(sp["q"], [p["q"] for p in written], rtol=1e-15)
    x0 = r["cases"][0]["chain"].length  # straight start: the end at (x0, 0)
    np.testing.assert_allclose(sp["dx"], x0 - sp["x"], rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(r.column("q2", 0, "special_points"), sp["q"][:, 1])


def test_labels_are_in_the_scenes_units(source_dir, run_cli, tmp_path):
    r, out = run_both("si_chain.json", source_dir, run_cli, tmp_path)
    assert r.units["system"] == "named" and r.units["stiffness"] == "N/m"
    expected = {"parameter": "Fx (N)", "Fx": "Fx (N)", "Me": "Me (N·m)", "x": "x (m)", "phi": "φ (rad)",
                "q10": "q10 (rad)", "Kxx": "Kxx (N/m)", "Cyy": "Cyy (m/N)", "Ky_xfree": "1/Cyy (x free) (N/m)"}
    for column, label in expected.items():
        assert r.label(column) == label, column
    # the labels report.html writes (the same column dictionary) for every column both have
    page = (out / "report.html").read_text()
    start = page.index('id="buckle-data">') + len('id="buckle-data">')
    data = json.loads(page[start:page.index("</script>", start)])
    shared = set(data["labels"]) & set(r["labels"])
    assert {"parameter", "Fx", "dx", "Kxx", "q5"} <= shared
    for column in shared:
        assert r["labels"][column] == data["labels"][column], column
    with pytest.raises(KeyError, match="no column 'Fz'; the columns are parameter, Fx"):
        r.label("Fz")


def test_columns_by_name(source_dir):
    r = buckle.run_scene(source_dir / "data" / "scenes" / "default.json")
    b = r["cases"][0]["branches"]
    np.testing.assert_array_equal(r.column("q3"), b["q"][:, 2])
    np.testing.assert_array_equal(r.column("Fx"), b["Fx"])
    with pytest.raises(KeyError, match=r"no column 'q4' in case 0's branches; the columns are branch, point, .* q1 … q3"):
        r.column("q4")
    with pytest.raises(IndexError, match=r"case 1: the run has 1 case\(s\)"):
        r.column("Fx", 1)
    assert repr(r).startswith("<RunResult '") and "complete>" in repr(r)


@pytest.fixture
def pandas():
    return pytest.importorskip("pandas", reason="python3-pandas is not installed: the DataFrames are not tested")


@pytest.mark.parametrize("name", ["si_chain.json", "fig6.json"])
def test_branches_frame_is_branches_csv(name, source_dir, run_cli, tmp_path, pandas):
    r, out = run_both(name, source_dir, run_cli, tmp_path)
    frame = r.branches_frame()
    rows = csv_rows(out / "branches.csv")
    assert len(frame) == len(rows)
    # every column of the CSV is in the frame, in the CSV's order (the frame has q1 … qn where a long
    # chain's CSV has max_abs_q and sign_changes)
    header = [c for c in rows[0] if c not in ("max_abs_q", "sign_changes")]
    assert [c for c in frame.columns if c in header] == header
    for column in header:
        if column in ("locked", "wall"):
            assert frame[column].tolist() == [row[column] for row in rows]
            continue
        csv_values = np.array([number(row[column]) for row in rows])
        np.testing.assert_allclose(frame[column].to_numpy(dtype=float), csv_values, rtol=1e-11, atol=1e-300,
                                   equal_nan=True, err_msg=column)
    assert frame.attrs["labels"]["Fx"] == r.label("Fx")


def test_special_points_frame(source_dir, pandas):
    r = buckle.run_scene(source_dir / "data" / "scenes" / "default.json")
    frame = r.special_points_frame()
    points = r["special_points"]
    assert len(frame) == len(points)
    assert frame["type"].tolist() == [p["type"] for p in points]
    assert frame["stability_after"].tolist() == [p["stability_after"] for p in points]
    np.testing.assert_array_equal(frame["Fx"], [p["loads"]["Fx"] for p in points])
    np.testing.assert_array_equal(frame["q2"], [p["q"][1] for p in points])


def test_equilibria_frame_is_equilibria_csv(source_dir, run_cli, tmp_path, pandas):
    r, out = run_both("equilibria_n3_held.json", source_dir, run_cli, tmp_path)
    frame = r.equilibria_frame()
    rows = csv_rows(out / "equilibria.csv")
    assert frame["rank"].tolist() == [int(row["rank"]) for row in rows]
    np.testing.assert_allclose(frame["potential"], [float(row["potential"]) for row in rows], rtol=1e-13)
    np.testing.assert_allclose(frame["q2"], [float(row["q2"]) for row in rows], rtol=1e-13, atol=1e-14)
    assert frame["stable"].tolist() == [row["stable"] == "1" for row in rows]


def test_frames_without_pandas_name_what_to_install(source_dir, monkeypatch):
    r = buckle.run_scene(source_dir / "data" / "scenes" / "fig2.json")
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match="branches_frame needs pandas.*python3-pandas"):
        r.branches_frame()
