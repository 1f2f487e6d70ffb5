# buckle.trace: the continuation core on problems defined in Python, with known bifurcation
# points: the fold normal form λ + u² and the pitchfork normal form λu − u³.
import os
import signal
import threading
import time

import numpy as np
import pytest

import buckle


def fold_residual(u, lam):
    return np.array([lam + u[0] ** 2])


def fold_jacobian(u, lam):
    return np.array([[2 * u[0]]]), np.array([1.0])


def test_fold_normal_form_is_located_at_the_origin():
    # from (u, λ) = (−1, −1) along λ = −u²: λ grows to the fold at (0, 0), then decreases
    r = buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, lambda_min=-2, lambda_max=2,
                     max_step=0.05)
    assert not r["interrupted"]
    (branch,) = r["branches"]
    folds = [s for s in branch["special_points"] if s["type"] == "LP"]
    assert len(folds) == 1
    lp = folds[0]
    # location target: |Δλ| ≤ locationTolerance·max(λ scale 1, |λ|) = 1e-12
    assert abs(lp["lambda"]) < 1e-11
    assert abs(lp["u"][0]) < 1e-6  # u ~ sqrt(|Δλ|) on the branch, refined by the fold system
    assert lp["accuracy"] <= 1e-11
    # every traced point solves the equation, on both sides of the fold
    u, lam = branch["u"][:, 0], branch["lambda"]
    assert np.max(np.abs(lam + u ** 2)) < 1e-9
    assert u.min() < -0.5 and u.max() > 0.5
    assert branch["stop_reason"] == "parameter range end"


def test_tracer_options_are_the_library_settings_and_the_keywords_their_short_forms():
    opts = buckle.TracerOptions()
    assert opts.validate() == ""
    # the keyword and the options field are one setting: the same branch, point for point
    opts.step.max_step = 0.05
    opts.lambda_min, opts.lambda_max = -2.0, 2.0
    by_options = buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, options=opts)["branches"][0]
    by_keywords = buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, lambda_min=-2, lambda_max=2,
                               max_step=0.05)["branches"][0]
    assert np.array_equal(by_options["lambda"], by_keywords["lambda"])
    steps = np.diff(by_options["arclength"])
    assert steps.max() <= 0.05 * (1 + 1e-12)
    # a keyword overrides the options' value; what it does not name keeps it
    shorter = buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, options=opts, max_points=5)
    assert len(shorter["branches"][0]["lambda"]) == 5
    assert opts.max_points != 5
    # the nested groups reach the tracer: no fold looked for, none reported
    opts.detection.folds = False
    none = buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, options=opts)["branches"][0]
    assert [s for s in none["special_points"] if s["type"] == "LP"] == []
    # a bad setting names the field as Python spells it
    opts.step.min_step = 1.0
    assert opts.validate() == "step.min_step must not exceed max_step"
    with pytest.raises(ValueError, match="step.min_step"):
        buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, options=opts)
    bad = buckle.CorrectorOptions()
    bad.tolerance = -1.0
    assert bad.validate() == "corrector.tolerance must be positive and finite"


def test_pitchfork_normal_form_branch_point_and_switching():
    # F = λu − u³: the trivial branch u = 0 meets u² = λ at the branch point λ = 0
    res = lambda u, lam: np.array([lam * u[0] - u[0] ** 3])
    jac = lambda u, lam: (np.array([[lam - 3 * u[0] ** 2]]), np.array([u[0]]))
    hess = lambda u, lam: np.array([[3 * u[0] ** 2 - lam]])  # F = −dΠ/du with Π = u⁴/4 − λu²/2
    r = buckle.trace(res, jac, np.array([0.0]), -0.5, lambda_min=-0.5, lambda_max=0.5, branch_switching=1,
                     stability=hess, max_step=0.05)
    trivial = r["branches"][0]
    bps = [s for s in trivial["special_points"] if s["type"] == "BP"]
    assert len(bps) == 1
    assert abs(bps[0]["lambda"]) < 1e-11
    assert (bps[0]["inertia_before"], bps[0]["inertia_after"]) == (0, 1)
    children = [b for b in r["branches"] if b["parent"] == 0]
    assert len(children) == 2
    for child in children:
        u, lam = child["u"][1:, 0], child["lambda"][1:]
        assert np.max(np.abs(u ** 2 - lam)) < 1e-9 * max(1.0, np.max(lam))
        assert np.all(lam >= -1e-12)
        assert np.all(child["negative"][1:] == 0)  # the supercritical pitchfork's branches are stable


def test_a_callback_exception_is_raised_in_python():
    def bad(u, lam):
        if u[0] > 0.5:  # past the fold, on the upper half of the branch
            raise RuntimeError("residual refused")
        return fold_residual(u, lam)

    with pytest.raises(RuntimeError, match="residual refused"):
        buckle.trace(bad, fold_jacobian, np.array([-1.0]), -1.0)


def test_a_callback_returning_no_numbers_is_named():
    for returned, shown in ((None, "None"), ("abc", "the str 'abc'")):
        with pytest.raises(TypeError) as e:
            buckle.trace(lambda u, lam: returned, fold_jacobian, np.array([-1.0]), -1.0)
        assert str(e.value).startswith("residual(u, lam) returned " + shown + "; expected an array of N numbers")
        assert "PYBIND11" not in str(e.value)
    with pytest.raises(TypeError, match=r"jacobian\(u, lam\) returned None; expected a pair \(F_u, F_lambda\)"):
        buckle.trace(fold_residual, lambda u, lam: None, np.array([-1.0]), -1.0)
    with pytest.raises(TypeError, match=r"jacobian\(u, lam\): F_u returned the str 'x'"):
        buckle.trace(fold_residual, lambda u, lam: ("x", np.array([1.0])), np.array([-1.0]), -1.0)


def test_wrong_shapes_and_options_are_value_errors():
    with pytest.raises(ValueError, match="residual returned 2 values, expected 1"):
        buckle.trace(lambda u, lam: np.zeros(2), fold_jacobian, np.array([-1.0]), -1.0)
    with pytest.raises(ValueError, match="direction"):
        buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, direction=0)
    with pytest.raises(ValueError, match="time_limit"):
        buckle.trace(fold_residual, fold_jacobian, np.array([-1.0]), -1.0, time_limit=0)
    with pytest.raises(ValueError, match="u0"):
        buckle.trace(fold_residual, fold_jacobian, np.zeros(0), -1.0)


def slow_line(u, lam):
    time.sleep(0.002)
    return np.array([u[0] - lam])


def slow_line_jacobian(u, lam):
    return np.array([[1.0]]), np.array([-1.0])


def test_time_limit_stops_the_trace_and_keeps_the_points():
    started = time.monotonic()
    r = buckle.trace(slow_line, slow_line_jacobian, np.array([0.0]), 0.0, max_points=10 ** 6, initial_step=1e-3, max_step=1e-3,
                     time_limit=0.3)
    elapsed = time.monotonic() - started
    assert r["interrupted"]
    assert r["branches"][0]["stop_reason"] == "interrupted"
    assert elapsed < 5
    assert len(r["branches"][0]["lambda"]) > 1


def test_keyboard_interrupt_stops_the_trace():
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    started = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            buckle.trace(slow_line, slow_line_jacobian, np.array([0.0]), 0.0, max_points=10 ** 6, initial_step=1e-3, max_step=1e-3)
    finally:
        timer.cancel()
    assert time.monotonic() - started < 5
    # Python's own handler is back: the next Ctrl-C would raise KeyboardInterrupt in Python code
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
