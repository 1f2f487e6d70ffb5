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
    with pytest.raises(ValueError, match="Segment: k: expected a number > 0"):
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


def test_segment_values_refused_like_the_cli(run_cli, tmp_path):
    # the same rule and words as a scene's /chain/L0 (one validator)
    scene = {"chain": {"segments": 3, "L0": 1e308}, "end": {"y": {"held": 0.0}},
             "path": {"parameter": "Fx", "from": 0.0, "to": -1.0}, "analyses": {"continuation": True}}
    path = tmp_path / "huge_L0.json"
    path.write_text(json.dumps(scene))
    cli = cli_message(run_cli, path, tmp_path)
    rule = cli.split("/chain/L0: ", 1)[1]
    with pytest.raises(ValueError) as e:
        buckle.Segment(L0=1e308)
    assert str(e.value) == "Segment: L0: " + rule
    with pytest.raises(ValueError) as e:
        buckle.Segment(a=1e300)
    assert str(e.value).startswith("Segment: a: expected a smaller half-height a against the half-length b")
    assert "qMinUser" not in str(e.value)
    with pytest.raises(ValueError, match="Segment: q_min: expected a finite number"):
        buckle.Segment(q_min=float("nan"))
    with pytest.raises(ValueError, match="Segment: L1_0: "):
        buckle.Segment(L1_0=-1.0)
    # the defaults and per-side values still build the same segment
    s = buckle.Segment(a=0.4, k2=2.0, q_min=-1.0)
    assert s.parameters["a1"] == 0.4 and s.parameters["k2"] == 2.0 and s.parameters["k1"] == 1.0
    assert s.lower_limit == -1.0


def test_end_condition_values_must_be_finite():
    for bad in ([float("nan"), 0, 0], [0, float("inf"), 0], [0, 0, -float("inf")]):
        with pytest.raises(ValueError, match=r"EndCondition: value\[\d\] must be a finite number"):
            buckle.EndCondition(value=np.array(bad, dtype=float))


def test_numpy_numbers_in_a_scene_dict(source_dir):
    scene = json.loads((source_dir / "data" / "scenes" / "default.json").read_text())
    plain = buckle.run_scene(scene)
    scene["chain"]["segments"] = np.int64(3)
    scene["chain"]["a"] = np.float64(0.5)
    scene["path"]["to"] = np.float32(-2.5)
    scene["solver"]["step"]["max_step"] = np.array(0.05)
    with_numpy = buckle.run_scene(scene)
    assert with_numpy["summary"]["complete"] == plain["summary"]["complete"]
    assert len(with_numpy["special_points"]) == len(plain["special_points"])
    # an array where a list of numbers goes: the per-segment q0
    scene["chain"]["q0"] = np.zeros(3)
    assert buckle.run_scene(scene)["summary"]["complete"]
    scene["chain"]["a"] = object()
    with pytest.raises(TypeError, match="a scene dict holds numbers, strings, lists and dicts; got a value of type object"):
        buckle.run_scene(scene)
