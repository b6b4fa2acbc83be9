"""Every branch of the inverse kinematics of 6R arms without a special structure (issue 28): the
general-6R eigenvalue solver (crates/kinedyn-core/src/ik/general6r.rs) on a real non-Pieper arm
(the xArm 6) and a synthetic one,
checked by forward kinematics and against many random starts of the numeric solver."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.dh import MasslessRobotWarning

pytest.importorskip("kinedyn._core", reason="the native module is not built")


def massless(rows, name: str) -> kd.Robot:
    """Kinematics only: the arm without masses (their warning is expected here)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MasslessRobotWarning)
        return kd.Robot.from_dh(rows, name=name)


def xarm6() -> kd.Robot:
    """UFactory xArm 6, standard DH from UFactory's "Kinematic and Dynamic Parameters of xArm 6"
    (m): a2 = sqrt(0.2845^2 + 0.0535^2) with the joint offsets -/+ atan(0.2845/0.0535)."""
    a2 = math.hypot(0.2845, 0.0535)
    t2 = -math.atan(0.2845 / 0.0535)
    rows = [
        kd.DHRow(d=0.267, alpha=-math.pi / 2),
        kd.DHRow(theta=t2, a=a2),
        kd.DHRow(theta=-t2, a=0.0775, alpha=-math.pi / 2),
        kd.DHRow(d=0.3425, alpha=math.pi / 2),
        kd.DHRow(a=0.076, alpha=-math.pi / 2),
        kd.DHRow(d=0.097),
    ]
    return massless(rows, "xarm6")


def skew6r() -> kd.Robot:
    """A synthetic arm whose consecutive axes neither meet nor are parallel (no real arm's table)."""
    rows = [
        kd.DHRow(d=0.31, a=0.05, alpha=1.1),
        kd.DHRow(d=0.07, a=0.42, alpha=-0.4),
        kd.DHRow(d=-0.04, a=0.12, alpha=1.3),
        kd.DHRow(d=0.35, a=0.03, alpha=-1.2),
        kd.DHRow(d=0.06, a=0.08, alpha=0.9),
        kd.DHRow(d=0.11, a=0.02, alpha=0.3),
    ]
    return massless(rows, "skew6r")


ARMS = {"xarm6": xarm6, "skew6r": skew6r}


def same(a, b, tol=1e-6) -> bool:
    d = np.asarray(a) - np.asarray(b)
    return bool(np.all(np.abs((d + np.pi) % (2 * np.pi) - np.pi) < tol))


@pytest.fixture(params=sorted(ARMS), scope="module")
def arm(request):
    return ARMS[request.param]()


def test_the_arms_have_no_special_structure_and_get_the_general_solver(arm):
    assert kd.ik.analytic_structure(arm) == "general_6r"


def test_every_branch_reproduces_the_target_and_the_generating_q_is_among_them(arm):
    rng = np.random.default_rng(1)
    counts = []
    for _ in range(12):
        q = rng.uniform(-np.pi, np.pi, 6)
        target = arm.pose(q)
        result = arm.inverse_kinematics(target)
        assert result.solver == "analytic:general_6r"
        assert result.success and len(result) == result.found <= 16
        assert any(same(s, q) for s in result.solutions), f"{arm.name}: q {q} missing"
        for s in result.solutions:
            assert np.abs(arm.pose(s) - target).max() < 1e-9
        assert max(result.position_error) < 1e-9 and max(result.orientation_error) < 1e-9
        # branches are distinct
        for i in range(len(result)):
            for j in range(i):
                assert not same(result.solutions[i], result.solutions[j])
        counts.append(len(result))
    assert max(counts) > 2  # more than one posture


def test_every_numeric_solution_from_random_starts_is_a_branch_found(arm):
    rng = np.random.default_rng(2)
    for _ in range(2):
        target = arm.pose(rng.uniform(-np.pi, np.pi, 6))
        branches = arm.inverse_kinematics(target).solutions
        seen = []
        for k in range(60):
            r = arm.inverse_kinematics(target, q0=rng.uniform(-np.pi, np.pi, 6), method="numeric", restarts=0, seed=k)
            if r.success and not any(same(r.q, s, 1e-5) for s in seen):
                seen.append(r.q)
        assert len(seen) >= 2
        for s in seen:
            assert any(same(s, b, 1e-5) for b in branches), f"{arm.name}: numeric solution {s} not among {branches}"


def test_an_unreachable_pose_has_no_branch(arm):
    target = np.eye(4)
    target[0, 3] = 3.0
    result = arm.inverse_kinematics(target)
    assert not result.success and result.reachable is False and len(result) == 0


def singular_configuration(robot, rng) -> np.ndarray:
    """A configuration where the Jacobian is singular: det J changes sign along joint 5 (0-based 4)
    between two samples, found by bisection (det J is smooth in q)."""
    while True:
        q = rng.uniform(-np.pi, np.pi, 6)

        def det(x, q=q):
            p = q.copy()
            p[4] = x
            return np.linalg.det(robot.jacobian(p))

        grid = np.linspace(-np.pi, np.pi, 25)
        values = [det(x) for x in grid]
        for lo, hi, flo, fhi in zip(grid[:-1], grid[1:], values[:-1], values[1:]):
            if flo * fhi < 0:
                for _ in range(80):
                    mid = 0.5 * (lo + hi)
                    if (det(mid) < 0) == (flo < 0):
                        lo = mid
                    else:
                        hi = mid
                q[4] = 0.5 * (lo + hi)
                return q


def test_a_target_where_two_branches_merge_is_flagged(arm):
    # at a singular configuration two real branches meet (a double root of the elimination): the
    # result finds it, reproduces the target and says the branches merged; a regular target does not
    rng = np.random.default_rng(4)
    for _ in range(2):
        q = singular_configuration(arm, rng)
        J = arm.jacobian(q)
        assert np.linalg.svd(J, compute_uv=False)[-1] < 1e-9
        result = arm.inverse_kinematics(arm.pose(q), respect_limits=False)
        assert result.solver == "analytic:general_6r"
        assert any(same(s, q, 1e-5) for s in result.solutions), (q, result.solutions)
        assert result.merged and result.worst_residual < 1e-9
    regular = arm.inverse_kinematics(arm.pose(rng.uniform(-np.pi, np.pi, 6)), respect_limits=False)
    assert not regular.merged
