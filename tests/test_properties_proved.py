"""Issue 12 §6: the properties of a symbolic model proved, not only sampled, and the inertia bounds of
Spong (9.120) from a global search that reports the configurations attaining them.

The planar 2R's bounds have a closed form derived here: D(q) = A + cos(q2) B with constant symmetric
A, B (Spong 9.82), and lambda_min of a symmetric matrix is concave in it (a minimum of the linear
functions v^T D v over unit v), lambda_max convex; so over cos q2 in [-1, 1] the least lambda_min and
the greatest lambda_max sit at cos q2 = +1 or -1, where the 2x2 eigenvalues are
tr/2 -+ sqrt(tr^2/4 - det).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.analysis import global_inertia_bounds, prove_properties
from kinedyn.symbolic import EquationsOfMotion

VALUES = dict(l1=1.3, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13)


def _closed_form_2r(l1, lc1, lc2, m1, m2, I1, I2):
    """(lambda_min, lambda_max) over all q of the planar elbow's D (Spong 9.82), by the argument above."""
    a = m1 * lc1**2 + m2 * (l1**2 + lc2**2) + I1 + I2
    b = m2 * l1 * lc2
    d = m2 * lc2**2 + I2
    lows, highs = [], []
    for c in (1.0, -1.0):
        d11, d12, d22 = a + 2 * b * c, d + b * c, d
        half_trace, det = (d11 + d22) / 2, d11 * d22 - d12**2
        root = math.sqrt(half_trace**2 - det)
        lows.append(half_trace - root)
        highs.append(half_trace + root)
    return min(lows), max(highs)


def _eom_2r():
    return kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)


def test_symbolic_2r_identities_are_proved_and_bounds_equal_the_closed_form():
    eom = _eom_2r()
    report = eom.check_properties(params=VALUES, seed=1)
    for name in ("D symmetric", "dD/dt - 2C skew", "dD/dt == C + C^T", "D qdd + C qd + g"):
        assert report[name].status == "proved" and report[name].passed, str(report)
    bounds = report["inertia bounds"]
    assert bounds.status == "searched"
    lo, hi = _closed_form_2r(**VALUES)
    assert bounds.data["lambda_min"] == pytest.approx(lo, rel=1e-10)
    assert bounds.data["lambda_max"] == pytest.approx(hi, rel=1e-10)
    # attained: the eigenvalue at the returned configuration is the reported bound
    D = sp.lambdify(
        [list(eom.q)], eom.M.xreplace({s: VALUES[s.name] for s in eom.M.free_symbols if s.name in VALUES}), "numpy"
    )
    assert np.linalg.eigvalsh(np.array(D(bounds.data["q_lambda_min"]), float))[0] == pytest.approx(
        bounds.data["lambda_min"], rel=1e-12
    )
    assert np.linalg.eigvalsh(np.array(D(bounds.data["q_lambda_max"]), float))[-1] == pytest.approx(
        bounds.data["lambda_max"], rel=1e-12
    )
    # and no sampled configuration does better
    Q = np.random.default_rng(7).uniform(-np.pi, np.pi, size=(2000, 2))
    eig = np.linalg.eigvalsh(np.array([np.array(D(q), float) for q in Q]))
    assert (
        bounds.data["lambda_min"] <= eig[:, 0].min() + 1e-12 and bounds.data["lambda_max"] >= eig[:, -1].max() - 1e-12
    )


def test_free_parameters_skip_the_bounds_and_say_which():
    check = _eom_2r().check_properties()["inertia bounds"]
    assert check.status == "skipped" and "lc2" in check.detail and "params=" in check.detail


def test_numeric_check_bounds_are_global_attained_and_match_the_closed_form():
    """`kinedyn check`'s bounds come from the global search: for the numeric planar_2r they equal the
    eigenvalues at cos q2 = +-1 (closed form above, evaluated with the engine's M), and they bound
    every sampled eigenvalue."""
    pytest.importorskip("kinedyn._core", reason="the native module is not built")
    robot = kd.robots.planar_2r()
    report = kd.analysis.check_properties(robot, samples=50, T=0.2)
    b = report["inertia bounds"]
    assert b.status == "searched" and b.passed
    ends = [np.linalg.eigvalsh(robot.mass_matrix(np.array([0.3, q2]))) for q2 in (0.0, math.pi)]
    assert b.data["lambda_min"] == pytest.approx(min(e[0] for e in ends), rel=1e-10)
    assert b.data["lambda_max"] == pytest.approx(max(e[-1] for e in ends), rel=1e-10)
    assert np.linalg.eigvalsh(robot.mass_matrix(b.data["q_lambda_min"]))[0] == pytest.approx(
        b.data["lambda_min"], rel=1e-12
    )
    assert np.linalg.eigvalsh(robot.mass_matrix(b.data["q_lambda_max"]))[-1] == pytest.approx(
        b.data["lambda_max"], rel=1e-12
    )
    eig = np.linalg.eigvalsh(robot.mass_matrix(robot.random_configuration(3, size=3000)))
    assert b.data["lambda_min"] <= eig[:, 0].min() and b.data["lambda_max"] >= eig[:, -1].max()


def test_the_search_finds_what_sampling_misses_on_the_elbow():
    """elbow_3r's least eigenvalue is reached only with the arm upright (q2 = +-pi/2), a set of measure
    zero: random samples stay well above it, the search reaches it."""
    eom = kd.robots.elbow_3r().equations_of_motion(steps=False)
    b = eom.check_properties(seed=0)["inertia bounds"]
    assert b.status == "searched"
    assert abs(abs(b.data["q_lambda_min"][1]) - math.pi / 2) < 1e-5
    assert b.data["lambda_min"] < 0.5 * b.data["sampled_min"]
    D = sp.lambdify([list(eom.q)], eom.M, "numpy")
    assert np.linalg.eigvalsh(np.array(D(b.data["q_lambda_min"]), float))[0] == pytest.approx(
        b.data["lambda_min"], rel=1e-12
    )


def test_global_inertia_bounds_rejects_a_bad_box():
    with pytest.raises(ValueError, match="finite with lower <= upper"):
        global_inertia_bounds(lambda q: np.eye(1), lambda q: np.zeros((1, 1, 1)), [0.0], [np.inf])


def _tampered(eom, C):
    return EquationsOfMotion(eom.q, eom.qd, eom.qdd, eom.M, C, eom.g, K=eom.K, P=eom.P, name="tampered")


def test_a_non_skew_C_is_reported_failed_not_proved():
    eom = _eom_2r()
    q1, qd1 = eom.q[0], eom.qd[0]
    bad = _tampered(eom, eom.C + sp.Matrix([[sp.cos(q1) * qd1, 0], [0, 0]]))
    report = bad.check_properties()
    skew = report["dD/dt - 2C skew"]
    assert skew.status == "failed" and not skew.passed and skew.data["witness"]
    assert not report.passed
    # a transposed C keeps both dD/dt identities (proved) but is not the Christoffel matrix of D
    transposed = _tampered(eom, eom.C.T).check_properties()
    assert transposed["dD/dt - 2C skew"].status == "proved"
    assert transposed["dD/dt == C + C^T"].status == "proved"
    assert transposed["D qdd + C qd + g"].status == "failed"


def test_undecidable_by_simplification_is_sampled_not_proved():
    """cosh^2 - sinh^2 - 1 is zero but outside the sin/cos normal form: the report says "sampled"."""
    eom = _eom_2r()
    q1, qd1 = eom.q[0], eom.qd[0]
    hidden_zero = sp.cosh(q1) ** 2 - sp.sinh(q1) ** 2 - 1
    report = _tampered(eom, eom.C + hidden_zero * qd1 * sp.eye(2)).check_properties()
    assert report["dD/dt - 2C skew"].status == "sampled" and report["dD/dt - 2C skew"].passed
    assert report["D symmetric"].status == "proved"


def test_prove_properties_on_a_lagrangian_system_model():
    """Any EquationsOfMotion works, here one from a LagrangianSystem (Spong's remotely driven arm,
    absolute angles p1, p2, eq. 9.92)."""
    p1, p2 = sp.symbols("p1 p2", real=True)
    m1, m2, l1, lc1, lc2, I1, I2, g = 2.0, 1.5, 1.3, 0.6, 0.35, 0.21, 0.13, 9.81
    bodies = [
        dict(
            mass=m1,
            position=[lc1 * sp.cos(p1), lc1 * sp.sin(p1)],
            inertia=I1,
            angular_velocity=sp.Symbol("pd1", real=True),
        ),
        dict(
            mass=m2,
            position=[l1 * sp.cos(p1) + lc2 * sp.cos(p2), l1 * sp.sin(p1) + lc2 * sp.sin(p2)],
            inertia=I2,
            angular_velocity=sp.Symbol("pd2", real=True),
        ),
    ]
    system = kd.symbolic.LagrangianSystem.from_bodies(
        [p1, p2], bodies, gravity=[0, -g], qd=sp.symbols("pd1 pd2", real=True)
    )
    report = prove_properties(system.equations_of_motion())
    assert all(report[n].status == "proved" for n in ("D symmetric", "dD/dt - 2C skew", "D qdd"))
    # D(p) = [[a, b cos(p2 - p1)], [b cos(p2 - p1), d]]: extremes at cos = +-1 give the same spectrum
    a, b, d = m1 * lc1**2 + m2 * l1**2 + I1, m2 * l1 * lc2, m2 * lc2**2 + I2
    lam = np.linalg.eigvalsh(np.array([[a, b], [b, d]]))
    assert report["inertia bounds"].data["lambda_min"] == pytest.approx(lam[0], rel=1e-10)
    assert report["inertia bounds"].data["lambda_max"] == pytest.approx(lam[1], rel=1e-10)


def test_cli_check_prove_reports_proved_and_searched(capsys):
    pytest.importorskip("kinedyn._core", reason="the native module is not built")
    from kinedyn.cli import main

    code = main(["check", "planar_2r", "--samples", "20", "--t", "0.2", "--prove", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["passed"]
    status = {c["name"]: c["status"] for c in doc["checks"]}
    assert status["symbolic model: dD/dt - 2C skew-symmetric"] == "proved"
    assert status["dM/dt - 2C skew-symmetric"] == "sampled"
    assert status["inertia bounds lambda_min I <= M(q) <= lambda_max I"] == "searched"
    bounds = [c for c in doc["checks"] if c["name"].startswith("inertia bounds")][0]
    assert len(bounds["q_lambda_min"]) == 2 and "at q =" in bounds["detail"]


def test_an_equal_C_in_another_trigonometric_form_is_still_proved():
    """Plain expansion does not see that sin(q2) = sin(q1 + q2) cos q1 - cos(q1 + q2) sin q1 or that
    sin^2 + cos^2 = 1; the normal form does, so the same C written so is proved, not merely sampled."""
    eom = _eom_2r()
    q1, q2 = eom.q
    disguised = eom.C.applyfunc(
        lambda e: (e * (sp.sin(q1) ** 2 + sp.cos(q1) ** 2)).xreplace(
            {sp.sin(q2): sp.sin(q1 + q2) * sp.cos(q1) - sp.cos(q1 + q2) * sp.sin(q1)}
        )
    )
    assert sp.expand(disguised - eom.C) != sp.zeros(2, 2)
    report = _tampered(eom, disguised).check_properties()
    for name in ("dD/dt - 2C skew", "dD/dt == C + C^T", "D qdd + C qd + g"):
        assert report[name].status == "proved", str(report)


def test_floating_point_residue_is_sampled_and_says_why():
    """A model whose numbers carry rounding (here a 1e-17 stray term in C, as a rounded cos(pi/2) leaves in
    a DH model) cannot be proved exactly: "sampled", and the detail says floating-point numbers are why."""
    eom = _eom_2r()
    report = _tampered(eom, eom.C + sp.Float(1e-17) * eom.qd[0] * sp.eye(2)).check_properties()
    skew = report["dD/dt - 2C skew"]
    assert skew.status == "sampled" and "floating-point" in skew.detail
    assert "floating-point" not in _eom_2r().check_properties()["dD/dt - 2C skew"].detail
