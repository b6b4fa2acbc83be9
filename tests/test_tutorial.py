"""`kinedyn tutorial`: every answer is present and equals an independent computation made here
(closed forms written in this file), never a string copied from the seed."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
from kinedyn.cli import main  # noqa: E402
from kinedyn.report import tutorial  # noqa: E402

SYMS = sp.symbols("th1 th2 thd1 thd2 thdd1 thdd2 l1 l2 m1 m2 g")
NS = {str(s): s for s in SYMS}


@pytest.fixture(scope="module")
def doc():
    return tutorial.to_json(tutorial.work())


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def evaluate(expr_str, **values):
    e = sp.sympify(expr_str, locals=NS)
    return float(e.subs({NS[k]: v for k, v in values.items()}))


def J2(q, l1, l2):
    """The 2R tool Jacobian, written by hand."""
    s1, c1, s12, c12 = math.sin(q[0]), math.cos(q[0]), math.sin(q[0] + q[1]), math.cos(q[0] + q[1])
    return np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12]])


def test_q1a_jacobian_equals_the_hand_derivative(doc):
    J = doc["1a"]["result"]["J"]
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, (l1, l2) = rng.uniform(-3, 3, 2), rng.uniform(0.5, 3, 2)
        got = np.array([[evaluate(e, th1=q[0], th2=q[1], l1=l1, l2=l2) for e in row] for row in J])
        np.testing.assert_allclose(got, J2(q, l1, l2), atol=1e-12)
    assert doc["1a"]["misprints"] == []


def test_q1b_inverse_is_the_inverse(doc):
    Jinv = doc["1b"]["result"]["J_inv"]
    q, l1, l2 = np.array([0.3, 1.1]), 2.0, 3.0
    got = np.array([[evaluate(e, th1=q[0], th2=q[1], l1=l1, l2=l2) for e in row] for row in Jinv])
    np.testing.assert_allclose(got, np.linalg.inv(J2(q, l1, l2)), atol=1e-12)
    assert evaluate(doc["1b"]["result"]["det"], th2=0.7, l1=2.0, l2=3.0) == pytest.approx(6 * math.sin(0.7))
    assert doc["1b"]["result"]["singular_at_theta2_zero"] is True


def test_q2_velocity_and_torques_equal_closed_forms(doc):
    q = np.radians([167.028, -156.44])
    J = J2(q, 2.0, 3.0)
    v = J @ [1.0, 3.0]
    tau = J.T @ [30.0, -20.0]
    np.testing.assert_allclose(doc["2a"]["result"]["v"], v, atol=1e-12)
    np.testing.assert_allclose(doc["2b"]["result"]["tau"], tau, atol=1e-12)
    np.testing.assert_allclose(doc["2b"]["result"]["tau_virtual_work"], tau, atol=1e-6)
    assert doc["2a"]["misprints"] == []
    # kinedyn flags exactly the one torque that a hand computation with J disagrees with at 0.1 N m
    assert doc["2b"]["misprints"] == ["tau2 [N m]"]
    fix = [c for c in doc["2b"]["comparisons"] if not c["agrees"]][0]
    assert float(fix["correction"]) == pytest.approx(round(tau[1], 1))
    assert "virtual work" in fix["check"]


def test_q2_text_output_shows_the_values(capsys):
    q = np.radians([167.028, -156.44])
    v = J2(q, 2.0, 3.0) @ [1.0, 3.0]
    code, out, _ = run(capsys, "tutorial", "--question", "2a")
    assert code == 0
    for x in v:
        assert f"{x:.6g}" in out
    assert "agrees" in out
    code, out, _ = run(capsys, "tutorial", "--question", "2b")
    assert code == 0 and "MISPRINT" in out and "deciding check" in out
    assert f"{(J2(q, 2.0, 3.0).T @ [30.0, -20.0])[1]:.6g}" in out


def rod_arm_tau(th, thd, thdd, l1, l2, m1, m2, g):
    """Spong's planar elbow (eqs. 9.82-9.86) with uniform rods: lc = l/2, I = m l^2/12."""
    lc1, lc2, I1, I2 = l1 / 2, l2 / 2, m1 * l1**2 / 12, m2 * l2**2 / 12
    c2, s2 = math.cos(th[1]), math.sin(th[1])
    d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
    d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
    d22 = m2 * lc2**2 + I2
    h = -m2 * l1 * lc2 * s2
    C = np.array([[h * thd[1], h * (thd[0] + thd[1])], [-h * thd[0], 0.0]])
    phi = np.array(
        [
            (m1 * lc1 + m2 * l1) * g * math.cos(th[0]) + m2 * lc2 * g * math.cos(th[0] + th[1]),
            m2 * lc2 * g * math.cos(th[0] + th[1]),
        ]
    )
    return np.array([[d11, d12], [d12, d22]]) @ thdd + C @ thd + phi


def test_q3_equations_of_motion_equal_spong(doc):
    res = doc["3"]["result"]
    rng = np.random.default_rng(5)
    for _ in range(4):
        th, thd, thdd = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2)
        l1, l2, m1, m2 = rng.uniform(0.5, 3, 4)
        values = dict(
            th1=th[0],
            th2=th[1],
            thd1=thd[0],
            thd2=thd[1],
            thdd1=thdd[0],
            thdd2=thdd[1],
            l1=l1,
            l2=l2,
            m1=m1,
            m2=m2,
            g=9.81,
        )
        expected = rod_arm_tau(th, thd, thdd, l1, l2, m1, m2, 9.81)
        assert evaluate(res["tau1"], **values) == pytest.approx(expected[0], rel=1e-10)
        assert evaluate(res["tau2"], **values) == pytest.approx(expected[1], rel=1e-10)
        # dL/dtheta1 = -dP/dtheta1 (kinetic energy does not depend on theta1)
        dP1 = (m1 * l1 / 2 + m2 * l1) * 9.81 * math.cos(th[0]) + m2 * l2 / 2 * 9.81 * math.cos(th[0] + th[1])
        assert evaluate(res["dL/dth1"], **values) == pytest.approx(-dP1, rel=1e-10)
    assert res["kinedyn_agrees_with_finite_differences"] is True
    flagged = set(doc["3"]["misprints"])
    assert {"tau2", "dL/dth1"} <= flagged and not {"tau1", "K", "P"} & flagged
    # each correction is kinedyn's value, which matched Spong above; the tau2 check names the energy balance
    tau2 = [c for c in doc["3"]["comparisons"] if c["quantity"] == "tau2"][0]
    assert "energy balance" in tau2["check"] and "finite differences" in tau2["check"]


def test_challenge_four_solutions_reach_the_target(doc):
    res = doc["challenge"]["result"]
    L1, L2, L3 = 3.0, 2.0, 1.0

    def fk(t):
        r = L2 * math.cos(t[1]) + L3 * math.cos(t[1] + t[2])
        return np.array([r * math.cos(t[0]), r * math.sin(t[0]), L1 + L2 * math.sin(t[1]) + L3 * math.sin(t[1] + t[2])])

    sols = np.array(res["solutions_rad"])
    assert sols.shape == (4, 3)
    for t in sols:
        np.testing.assert_allclose(fk(t), [1.0, 0.2, 0.5], atol=1e-12)
    wrapped = np.round((sols + math.pi) % (2 * math.pi), 9)
    assert len({tuple(r) for r in wrapped}) == 4
    # Jacobian at the first solution: columns z_{i-1} x (o3 - o_{i-1}) by hand
    t = sols[0]
    c1, s1 = math.cos(t[0]), math.sin(t[0])
    r, z = L2 * math.cos(t[1]) + L3 * math.cos(t[1] + t[2]), L2 * math.sin(t[1]) + L3 * math.sin(t[1] + t[2])
    Jv = np.array(
        [
            [-s1 * r, -c1 * z, -L3 * c1 * math.sin(t[1] + t[2])],
            [c1 * r, -s1 * z, -L3 * s1 * math.sin(t[1] + t[2])],
            [0, r, L3 * math.cos(t[1] + t[2])],
        ]
    )
    np.testing.assert_allclose(np.array(res["jacobians"][0])[:3], Jv, atol=1e-12)
    np.testing.assert_allclose(np.array(res["jacobians"][0])[3:], [[0, s1, s1], [0, -c1, -c1], [1, 0, 0]], atol=1e-12)
    assert res["symbolic_vs_numeric_max_difference"] < 1e-12


def test_json_and_markdown(capsys):
    code, out, _ = run(capsys, "tutorial", "--question", "1b", "--json")
    assert code == 0
    d = json.loads(out)
    assert set(d["questions"]) == {"1b"} and d["misprints"] == {"1b": []}
    code, out, _ = run(capsys, "tutorial", "--question", "2b", "--format", "markdown")
    assert code == 0 and out.startswith("# ") and "## Q2b" in out and "misprint" in out


def test_bad_question(capsys):
    assert main(["tutorial", "--question", "4"]) == 1  # a bad argument is the user's mistake: one line, status 1
    assert "argument --question/-q: invalid choice" in capsys.readouterr().err
    with pytest.raises(ValueError, match="unknown question"):
        tutorial.answer("9")


def test_whole_tutorial_json(capsys):
    """`kinedyn tutorial --json` (every question) prints valid JSON: it once exited 1 on a numpy.bool."""
    code, out, err = run(capsys, "tutorial", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert {"1a", "1b", "2a", "2b"} <= set(d["questions"])


def _branch_by_hand(t, target, L1, L2):
    """Front: the arm's plane faces the target; elbow up: the elbow (c1 L2 c2, s1 L2 c2, L1 + L2 s2) lies
    above the shoulder-target line, measured in the arm's vertical plane by its signed radial coordinate."""
    x, y, z = target
    heading = math.atan2(y, x)
    front = math.cos(t[0] - heading) > 0
    r_target = math.hypot(x, y)  # the target's radial coordinate along the heading
    r_elbow = L2 * math.cos(t[1]) * math.cos(t[0] - heading)  # the elbow's, along the same heading
    z_elbow = L1 + L2 * math.sin(t[1])
    z_line = L1 + (z - L1) * r_elbow / r_target
    return f"{'front' if front else 'back'}, elbow {'up' if z_elbow > z_line else 'down'}"


def _symbolic_name(t, target, L1, L2, L3):
    """The label kd.ik.symbolic_elbow_solution gives the branch whose angles are t."""
    sol = kd.ik.symbolic_elbow_solution(L1, L2, L3)
    wrap = lambda a: (a + math.pi) % (2 * math.pi) - math.pi
    xyz = dict(zip((sol.x, sol.y, sol.z), target))
    for b in sol.branches:
        angles = [float(b[k].subs(xyz).evalf()) for k in ("theta1", "theta2", "theta3")]
        if all(abs(wrap(a - v)) < 1e-9 for a, v in zip(angles, t)):
            return b["name"].replace("shoulder ", "")
    raise AssertionError(f"no symbolic branch at {t}")


def test_challenge_branch_labels_are_geometric(doc):
    """The tutorial once labelled the back-shoulder branches the other way round (its 'back, elbow down'
    put the elbow where 'front, elbow up' does). Every branch's label equals the geometric test written
    here and symbolic_elbow_solution's label, at the tutorial's target and at random reachable targets."""
    res = doc["challenge"]["result"]
    L1, L2, L3 = 3.0, 2.0, 1.0
    target = (1.0, 0.2, 0.5)
    names = res["branches"]
    assert sorted(names) == ["back, elbow down", "back, elbow up", "front, elbow down", "front, elbow up"]
    for name, t in zip(names, res["solutions_rad"]):
        assert name == _branch_by_hand(t, target, L1, L2) == _symbolic_name(t, target, L1, L2, L3)
    robot = kd.robots.elbow_3r(L1=L1, L2=L2, L3=L3)
    rng = np.random.default_rng(12)
    for _ in range(4):
        q = rng.uniform(-math.pi, math.pi, 3)
        p = robot.pose(q)[:3, 3]
        for t in tutorial.elbow_ik(*p, L1, L2, L3):
            assert (
                tutorial.elbow_branch_name(robot, t)
                == _branch_by_hand(t, p, L1, L2)
                == _symbolic_name(t, p, L1, L2, L3)
            )
