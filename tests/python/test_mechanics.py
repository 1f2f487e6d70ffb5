# buckle.Segment / Chain / EndCondition / linear_buckling against closed forms and finite
# differences of the module's own functions.
import math

import numpy as np
import pytest

import buckle


def central_difference(f, x, h):
    """Derivative of the scalar or vector function f at the vector x, column by column."""
    x = np.asarray(x, dtype=float)
    columns = []
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        columns.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h))
    return np.array(columns).T


def test_segment_torque_and_stiffness_are_derivatives_of_the_energy():
    s = buckle.Segment(a=0.4, b=1.1, k=2.0, L0=2.4, k2=1.5)
    q = np.linspace(-0.8, 0.8, 17)
    h = 1e-5
    dE = (s.energy(q + h) - s.energy(q - h)) / (2 * h)
    dM = (s.torque(q + h) - s.torque(q - h)) / (2 * h)
    scale = np.max(np.abs(s.stiffness(q)))
    assert np.max(np.abs(s.torque(q) + dE)) < 1e-7 * scale
    assert np.max(np.abs(s.stiffness(q) + dM)) < 1e-7 * scale
    assert s.energy(0.3) == pytest.approx(float(s.energy(np.array([0.3]))[0]), rel=0, abs=0)


def test_straight_stiffness_is_kappa():
    a, b, k, L0 = 0.5, 1.0, 1.0, 2.25
    s = buckle.Segment(a, b, k, L0)
    kappa = k * (b * L0 - 2 * (b * b - a * a))  # eq 17
    assert s.straight_stiffness == pytest.approx(kappa, rel=1e-14)
    assert s.lower_limit == pytest.approx(-s.upper_limit, rel=1e-14)


def test_chain_parameters_lists_and_limits():
    segs = [buckle.Segment(a=0.3 + 0.1 * i, b=1.0, k=1.0 + i, L0=2.25, q_max=0.5) for i in range(3)]
    c = buckle.Chain(segs)
    assert len(c) == 3 and c.n == 3
    np.testing.assert_array_equal(c.parameters["k1"], [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(c.parameters["a2"], [0.3, 0.4, 0.5])
    assert np.all(c.upper_limits <= 0.5)
    assert c.length == pytest.approx(np.sum(c.link_lengths), rel=1e-15)
    np.testing.assert_allclose(c.unloaded_shape(), np.zeros(3), atol=1e-12)


def test_chain_with_unloaded_shape_has_that_shape():
    q0 = np.array([0.2, -0.1, 0.05])
    c = buckle.Chain.with_unloaded_shape([buckle.Segment()] * 3, q0)
    np.testing.assert_allclose(c.unloaded_shape(), q0, atol=1e-12)
    assert np.max(np.abs(c.torques(q0))) < 1e-12 * np.max(c.joint_stiffness(q0))


def test_chain_kinematics_and_energy_derivatives():
    c = buckle.Chain([buckle.Segment(a=0.5, b=1.0 + 0.1 * i, k=1.0, L0=2.3) for i in range(4)])
    q = np.array([0.3, -0.2, 0.4, 0.1])
    F = np.array([-0.4, 0.2, 0.1])
    h = 1e-6
    J = c.end_jacobian(q)
    np.testing.assert_allclose(J, central_difference(c.end_pose, q, h), atol=1e-8 * c.length)
    g = c.total_potential_gradient(q, F)
    np.testing.assert_allclose(g, central_difference(lambda x: c.total_potential(x, F), q, h), atol=1e-8)
    H = c.total_potential_hessian(q, F)
    np.testing.assert_allclose(H, central_difference(lambda x: c.total_potential_gradient(x, F), q, h), atol=1e-7)
    np.testing.assert_allclose(-c.torques(q) - J.T @ F, g, atol=1e-13)
    P = c.joint_positions(q)
    assert P.shape == (6, 2)
    np.testing.assert_allclose(P[-1], c.end_pose(q)[:2], atol=1e-14 * c.length)


def test_unloaded_stiffness_is_the_inverse_of_the_compliance_eq21():
    c = buckle.Chain.uniform(3)
    q = np.array([0.3, -0.2, 0.25])
    r = c.stiffness(q)
    J = c.end_jacobian(q)[:2]
    C = J @ np.diag(1 / c.joint_stiffness(q)) @ J.T  # eq 21, rotation free
    np.testing.assert_allclose(r["compliance"], C, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(r["stiffness"] @ C, np.eye(2), atol=1e-10)
    assert r["positive_definite"] and not r["singular"]


def test_linear_buckling_matches_the_closed_form_eq17():
    a, b, k, L0 = 0.5, 1.0, 1.0, 2.25
    c = buckle.Chain.uniform(3, buckle.Segment(a, b, k, L0))
    kappa = k * (b * L0 - 2 * (b * b - a * a))
    r = buckle.linear_buckling(c, end=buckle.EndCondition.clamped_pinned())
    compressive = sorted(x for x in r["loads"] if x < 0)[::-1]
    FxU = (math.sqrt(21) - 14) / 10 * kappa / b
    FxZ = -(math.sqrt(21) + 14) / 10 * kappa / b
    assert compressive[0] == pytest.approx(FxU, rel=1e-12)
    assert compressive[1] == pytest.approx(FxZ, rel=1e-12)
    assert r["unloaded_stable"]
    mode = next(m for m in r["modes"] if m["load_factor"] == compressive[0])
    assert mode["shape"] == "U"
    # the mode is a null vector of the loaded Hessian on ker J_y (y held)
    H = c.total_potential_hessian(np.zeros(3), np.array([compressive[0], 0, 0]))
    z = mode["mode"]
    Jy = c.end_jacobian(np.zeros(3))[1]
    residual = H @ z
    residual -= Jy * (Jy @ residual) / (Jy @ Jy)
    assert np.linalg.norm(residual) < 1e-10 * np.linalg.norm(H)


def test_end_condition_controls():
    e = buckle.EndCondition.clamped_pinned(-0.5)
    assert e.control == ("load", "held", "load")
    assert e.value[0] == -0.5
    e = buckle.EndCondition(x="held", y="held", value=[2.5, 0.1, 0])
    assert e.control == ("held", "held", "load")


# Values a fixed-point format hides (1e-7 as 0.000000), spells out (1e308 in 309 digits) or rounds
# (0.1 and -2.5e-12 must read back to the same double).
REPR_VALUES = [1e-7, 1e308, 0.1, -2.5e-12]


@pytest.mark.parametrize("value", REPR_VALUES)
def test_reprs_write_every_number_as_python_does(value):
    # Segment: any positive stiffness keeps the geometry valid
    k = abs(value)
    s = buckle.Segment(a=0.5, b=1.0, k=k, L0=2.25)
    text = repr(s)
    assert text == f"Segment(a=0.5, b=1.0, k={k!r}, L0=2.25)"
    assert len(text) < 120
    again = eval(text, {"Segment": buckle.Segment})
    assert again.parameters == s.parameters  # the digits read back to the same doubles
    e = buckle.EndCondition("load", "held", "load", value=(value, -value, 0.0))
    assert repr(e) == f"EndCondition(x='load', y='held', phi='load', value=({value!r}, {-value!r}, 0.0))"
    again = eval(repr(e), {"EndCondition": buckle.EndCondition})
    assert list(again.value) == [value, -value, 0.0] and again.control == e.control


def test_an_asymmetric_segments_repr_names_each_side_and_the_user_limits():
    s = buckle.Segment(a=0.5, b=1.0, k=1.0, L0=2.25, k2=1e-7, L1_0=2.3, q_min=-2.5e-12)
    text = repr(s)
    assert text.startswith("Segment(a1=0.5, b1=1.0, a2=0.5, b2=1.0, k1=1.0, k2=1e-07, L1_0=2.3, L2_0=2.25")
    assert "q_min=-2.5e-12" in text and "q_max" not in text
    assert eval(text, {"Segment": buckle.Segment}).parameters == s.parameters


def test_a_non_finite_end_value_is_named_as_python_writes_it():
    with pytest.raises(ValueError, match=r"value\[1\] must be a finite number .*got inf"):
        buckle.EndCondition(value=(0.0, math.inf, 0.0))


def test_all_equilibria_held_end_every_one_is_an_equilibrium_with_its_index():
    # the paper's chain with its end held at (5.5b, 0), rotation free (Fig 4): two U minima and two Z
    # saddles; each returned q balances the springs against the reactions, sits at the held end, and
    # its index is the count of negative eigenvalues of the Hessian on ker J_h (numpy, independently)
    chain = buckle.Chain.uniform(3, buckle.Segment(a=0.5, b=1, k=1, L0=2.25))
    end = buckle.EndCondition.held_position(5.5, 0.0)
    r = buckle.all_equilibria(chain, end, starts=16, smooth_starts=16, seed=3)
    found = r["equilibria"]
    assert len(found) == 4
    assert r["morse"]["applies"] and r["morse"]["holds"]
    assert [e["stable"] for e in found].count(True) == 2
    potentials = [e["potential"] for e in found]
    assert potentials == sorted(potentials)
    for e in found:
        q, F = e["q"], e["wrench"]
        assert np.max(np.abs(chain.total_potential_gradient(q, F))) < 1e-10
        np.testing.assert_allclose(chain.end_pose(q)[:2], [5.5, 0.0], atol=1e-12)
        assert F[2] == 0.0  # phi free: no end torque
        J = chain.end_jacobian(q)[:2]
        Z = np.linalg.svd(J)[2][2:].T  # orthonormal basis of ker J_h
        eig = np.linalg.eigvalsh(Z.T @ chain.total_potential_hessian(q, F) @ Z)
        assert e["index"] == int((eig < 0).sum())
        assert e["stable"] == (e["index"] == 0)


def test_all_equilibria_equal_the_scene_analysis_and_name_bad_options():
    chain = buckle.Chain.uniform(4, buckle.Segment(a=0.5, b=1, k=1, L0=2.25))
    end = buckle.EndCondition.clamped_pinned(-0.9)
    mine = buckle.all_equilibria(chain, end, starts=24, seed=3, starts_q=[np.zeros(4)])
    scene = {"chain": {"segments": 4, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
             "end": {"x": {"load": -0.9}, "y": {"held": 0.0}, "phi": "free"},
             "analyses": {"equilibria": {"starts": 24, "seed": 3}}}
    theirs = buckle.run_scene(scene)["cases"][0]["equilibria"]
    assert len(mine["equilibria"]) == len(theirs["potential"])
    for k, e in enumerate(mine["equilibria"]):
        np.testing.assert_allclose(e["q"], theirs["q"][k], atol=1e-12)
        assert e["index"] == theirs["index"][k]
    for key, value in (("starts", -1), ("smooth_starts", -2), ("seed", -1), ("sweep_points", 2)):
        with pytest.raises(ValueError, match=key):
            buckle.all_equilibria(chain, end, **{key: value})
    with pytest.raises(ValueError, match=r"starts_q\[0\]"):
        buckle.all_equilibria(chain, end, starts_q=[np.zeros(3)])
