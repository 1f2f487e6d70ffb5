# Bad input raises Python exceptions carrying the command line's messages.
import json

import numpy as np
import pytest

import buckle


def cli_message(run_cli, scene_file, tmp_path):
    r = run_cli("run", scene_file, "--out", tmp_path / "out", "--quiet")
    assert r.returncode == 2
    prefix = "buckle run: bad scene: "
    assert r.stderr.startswith(prefix), r.stderr
    return r.stderr[len(prefix):].strip()


def test_malformed_scene_file(run_cli, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"chain": {"segments": 3,, "a": 0.5}}')
    with pytest.raises(buckle.SceneError) as e:
        buckle.run_scene(str(bad))
    assert str(e.value) == cli_message(run_cli, bad, tmp_path)
    assert isinstance(e.value, ValueError)


def test_negative_stiffness_in_a_scene(run_cli, source_dir, tmp_path):
    scene = json.loads((source_dir / "data" / "scenes" / "default.json").read_text())
    scene["chain"]["k"] = -1.0
    path = tmp_path / "negative_k.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(buckle.SceneError) as e:
        buckle.run_scene(str(path))
    message = str(e.value)
    assert "/chain/k" in message
    assert message == cli_message(run_cli, path, tmp_path)
    with pytest.raises(buckle.SceneError, match="/chain/k"):
        buckle.run_scene(scene)


def test_zero_segments(run_cli, source_dir, tmp_path):
    scene = json.loads((source_dir / "data" / "scenes" / "default.json").read_text())
    scene["chain"]["segments"] = 0
    path = tmp_path / "n0.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(buckle.SceneError) as e:
        buckle.run_scene(str(path))
    assert "/chain/segments" in str(e.value)
    assert str(e.value) == cli_message(run_cli, path, tmp_path)
    with pytest.raises(ValueError, match="at least 1"):
        buckle.Chain.uniform(0)
    with pytest.raises(ValueError):
        buckle.Chain([])


def test_missing_scene_file(run_cli, tmp_path):
    missing = tmp_path / "nowhere.json"
    with pytest.raises(buckle.SceneError) as e:
        buckle.run_scene(str(missing))
    assert str(e.value) == cli_message(run_cli, missing, tmp_path)


def test_bad_segment_and_state_arguments():
    with pytest.raises(ValueError, match="k1"):
        buckle.Segment(k=-1.0)
    with pytest.raises(ValueError, match="3 segments"):
        buckle.Chain.uniform(3).energy(np.zeros(2))
    with pytest.raises(ValueError, match="3 values"):
        buckle.Chain.uniform(3).total_potential(np.zeros(3), np.zeros(2))
    with pytest.raises(ValueError, match="load.*held"):
        buckle.EndCondition(x="pinned")
    with pytest.raises(ValueError, match="dict or a file path"):
        buckle.run_scene(42)
    with pytest.raises(ValueError, match="time_limit"):
        buckle.run_scene({"analyses": {}}, time_limit=-1)
