"""Inverse kinematics (kinedyn.ik): closed forms detected from geometry, the numeric solver, the
symbolic elbow solution, bad input and the CLI. Every solution is checked by forward kinematics."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn import ik
from kinedyn._math import rot_z, translation
from kinedyn.testing import example_robot_data_dir

pytest.importorskip("kinedyn._core", reason="the native module is not built")

TUTORIAL_TARGET = np.array([1.0, 0.2, 0.5])


def angle_diff(a, b, revolute):
    d = np.asarray(a) - np.asarray(b)
    return np.where(revolute, (d + np.pi) % (2 * np.pi) - np.pi, d)


def revolute_mask(robot):
    return np.array([j.kind == "revolute" for j in robot.joints])


def contains(solutions, q, robot, tol=1e-6) -> bool:
    rev = revolute_mask(robot)
    return any(np.max(np.abs(angle_diff(s, q, rev))) < tol for s in solutions)


def residuals(robot, q, target, frame=None):
    """(position error, orientation error) of q at a 4x4 target or a position."""
    T = robot.pose(q, frame)
    if np.shape(target) == (3,):
        return np.linalg.norm(T[:3, 3] - target), 0.0
    dR = T[:3, :3].T @ target[:3, :3]
    # rotation angle, atan2(sin, cos): acos alone loses half the digits near 0
    sin = np.linalg.norm([dR[2, 1] - dR[1, 2], dR[0, 2] - dR[2, 0], dR[1, 0] - dR[0, 1]]) / 2
    angle = math.atan2(sin, (np.trace(dR) - 1) / 2)
    return np.linalg.norm(T[:3, 3] - target[:3, 3]), angle


def check_all(robot, result, target, tol=1e-9, frame=None):
    for q in result.solutions:
        ep, er = residuals(robot, q, target, frame)
        assert ep < tol and er < tol, (q, ep, er)
    assert np.all(result.position_error < tol) and np.all(result.orientation_error < tol)


def panda():
    site = Path(example_robot_data_dir() or "/nonexistent") / "panda_description/urdf/panda.urdf"
    if not site.exists():
        pytest.skip("example-robot-data is not installed (no panda.urdf): pip install example-robot-data")
    robot = kd.Robot.from_urdf(str(site))
    return robot.lock_joints({"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0})


def dh_7dof():
    """An anthropomorphic 7R arm (offsets like a KUKA LBR iiwa 14: d1 = 0.36, d3 = 0.42, d5 = 0.4,
    d7 = 0.126 m, alternating +-90 deg twists), limits +-170 / +-120 deg."""
    h = math.pi / 2
    deg = math.pi / 180
    rows = []
    for d, alpha, lim in [
        (0.36, -h, 170),
        (0.0, h, 120),
        (0.42, h, 170),
        (0.0, -h, 120),
        (0.4, -h, 170),
        (0.0, h, 120),
        (0.126, 0.0, 175),
    ]:
        rows.append(kd.DHRow(d=d, alpha=alpha, lower=-lim * deg, upper=lim * deg))
    return kd.Robot.from_dh(rows, name="dh7")


# ------------------------------------------------------------------ the tutorial's challenge
def test_elbow_tutorial_target_has_four_solutions():
    robot = kd.robots.elbow_3r()
    result = robot.inverse_kinematics(TUTORIAL_TARGET)
    assert result.success and result.solver == "analytic:arm_intersecting_shoulder"
    assert len(result) == 4 and result.reachable and not result.singular
    check_all(robot, result, TUTORIAL_TARGET)
    # waist: atan2(y, x) and the opposite; elbow: cos(theta3) = (r^2 + (z - L1)^2 - L2^2 - L3^2) / (2 L2 L3)
    D = (1.0**2 + 0.2**2 + (0.5 - 3.0) ** 2 - 2.0**2 - 1.0**2) / (2 * 2.0 * 1.0)
    assert D == pytest.approx(229 / 400)
    theta1 = {round(v, 9) for v in np.mod(result.solutions[:, 0], 2 * np.pi)}
    assert theta1 == {round(math.atan2(0.2, 1.0), 9), round(math.atan2(0.2, 1.0) + math.pi, 9)}
    assert np.allclose(np.sort(np.abs(result.solutions[:, 2])), math.acos(D))
    # ordered by distance to q0 (zeros by default)
    d = np.linalg.norm(result.solutions, axis=1)
    assert np.all(np.diff(d) >= -1e-12)


def test_symbolic_elbow_solution_matches_the_numeric_one():
    robot = kd.robots.elbow_3r()
    sol = ik.symbolic_elbow_solution()
    assert {str(s) for s in sol.symbols} == {"x", "y", "z", "L1", "L2", "L3"}
    values = sol.evaluate(*TUTORIAL_TARGET, 3.0, 2.0, 1.0)
    numeric = robot.inverse_kinematics(TUTORIAL_TARGET).solutions
    assert len(values) == 4
    for q in values:
        assert contains(numeric, q, robot, 1e-9)
        assert np.linalg.norm(robot.pose(q)[:3, 3] - TUTORIAL_TARGET) < 1e-12
    assert sol.verify() < 1e-12
    # other lengths through the expressions: the robot built with them agrees
    other = kd.robots.elbow_3r(L1=0.5, L2=0.7, L3=0.4)
    p = other.pose(np.array([0.4, 0.3, -0.9]))[:3, 3]
    for q in sol.evaluate(*p, 0.5, 0.7, 0.4):
        assert np.linalg.norm(other.pose(q)[:3, 3] - p) < 1e-12
    f = sol.lambdify()
    assert np.allclose(np.array(f(*p, 0.5, 0.7, 0.4)), sol.evaluate(*p, 0.5, 0.7, 0.4))
    assert "theta" in sol.to_latex()
    # numbers substituted for the lengths
    assert ik.symbolic_elbow_solution(3, 2, 1).D.free_symbols == {sol.x, sol.y, sol.z}


# ------------------------------------------------------------------ round trips and counts
ROUND_TRIP = [
    ("planar_2r", "position", "planar_2r"),
    ("planar_3r", "pose", "planar_3r"),
    ("elbow_3r", "position", "arm_intersecting_shoulder"),
    ("puma560", "pose", "spherical_wrist"),
    ("stanford", "pose", "spherical_wrist"),
    ("ur5", "pose", "three_parallel"),
]


@pytest.mark.parametrize("name,kind,structure", ROUND_TRIP)
def test_round_trip_contains_the_original(name, kind, structure):
    robot = kd.robots.get(name)
    assert ik.analytic_structure(robot) == structure
    rng = np.random.default_rng(5)
    lower, upper = robot.lower_limits, robot.upper_limits
    for _ in range(25):
        q = robot.random_configuration(rng)
        T = robot.pose(q)
        target = T[:3, 3] if kind == "position" else T
        result = robot.inverse_kinematics(target)
        assert result.success and result.solver.startswith("analytic:")
        assert contains(result.solutions, q, robot), (q, result.solutions)
        check_all(robot, result, target)
        assert np.all(result.solutions >= lower - 1e-12) and np.all(result.solutions <= upper + 1e-12)


def distinct(solutions, robot, tol=1e-6) -> list:
    out = []
    for s in solutions:
        if not contains(out, s, robot, tol):
            out.append(s)
    return out


@pytest.mark.parametrize(
    "name,q",
    [
        ("puma560", [0.3, 0.6, -0.5, 0.4, 0.9, -0.3]),
        ("ur5", [0.5, -1.0, 1.2, -0.3, 0.8, 2.0]),
    ],
)
def test_eight_solutions_at_generic_poses(name, q):
    robot = kd.robots.get(name)
    rng = np.random.default_rng(11)
    poses = [np.array(q)] + [robot.random_configuration(rng) for _ in range(4)]
    for q in poses:
        T = robot.pose(q)
        result = robot.inverse_kinematics(T, respect_limits=False)
        check_all(robot, result, T)
        assert contains(result.solutions, q, robot)
        assert len(distinct(result.solutions, robot)) == len(result) == result.found <= 8
        # an independent count: the numeric solver from 400 random starts finds the same set
        starts = robot.random_configuration(rng, size=400)
        numeric = robot.inverse_kinematics(
            np.broadcast_to(T, (400, 4, 4)), q0=starts, method="numeric", respect_limits=False, restarts=0
        )
        found = distinct(numeric.q[numeric.success], robot, 1e-6)
        assert len(found) == len(result), (len(found), len(result))
        assert all(contains(result.solutions, s, robot, 1e-6) for s in found)
        limited = robot.inverse_kinematics(T)
        assert len(limited) <= len(result) and all(contains(result.solutions, s, robot) for s in limited.solutions)
    # at the first (generic) pose every branch exists
    assert len(robot.inverse_kinematics(robot.pose(np.array(poses[0])), respect_limits=False)) == 8


def test_a_rail_under_an_intersecting_shoulder_has_four():
    # joint 1 prismatic, axes 2 and 3 meeting: arm_prismatic_base (crates/kinedyn-core/src/ik/prismatic.rs);
    # every solution reproduces the target (FK), the original is one, and the numeric solver from
    # random starts finds none outside them (the Rust test checks the count by a dense search)
    rows = [kd.DHRow(kind="prismatic", a=0.1, theta=0.3), kd.DHRow(alpha=np.pi / 2), kd.DHRow(a=0.4)]
    rail = kd.Robot.from_dh(rows, name="rail")  # (massless: a kinematic model)
    assert ik.analytic_structure(rail) == "arm_prismatic_base"
    q = np.array([0.2, 0.5, -0.7])
    p = rail.pose(q)[:3, 3]
    res = rail.inverse_kinematics(p, respect_limits=False)
    assert (len(res), res.max_solutions, res.merged) == (4, 4, False)
    for s in res.solutions:
        np.testing.assert_allclose(rail.pose(s)[:3, 3], p, atol=1e-12)

    def gap(x):  # to the nearest closed-form solution, the revolute angles modulo 2 pi
        d = x - res.solutions
        d[:, 1:] -= 2 * np.pi * np.round(d[:, 1:] / (2 * np.pi))
        return np.abs(d).max(axis=1).min()

    assert gap(q) < 1e-9
    for seed in range(8):
        start = np.random.default_rng(seed).uniform(-2, 2, 3)
        num = rail.inverse_kinematics(p, start, method="numeric", respect_limits=False, seed=seed)
        if num.success:
            assert gap(num.solutions[0]) < 1e-6


def test_stanford_has_up_to_eight_and_limits_keep_the_prismatic_stroke():
    robot = kd.robots.stanford()
    q = np.array([0.3, -0.5, 0.6, 0.2, 0.7, -0.4])
    T = robot.pose(q)
    free = robot.inverse_kinematics(T, respect_limits=False)
    assert 1 <= len(free) <= 8
    check_all(robot, free, T)
    limited = robot.inverse_kinematics(T)
    assert contains(limited.solutions, q, robot)
    assert np.all(limited.solutions[:, 2] >= robot.lower_limits[2]) and np.all(
        limited.solutions[:, 2] <= robot.upper_limits[2]
    )


def test_solutions_are_wrapped_next_to_q0_within_limits():
    robot = kd.robots.ur5()  # limits +-2 pi: each angle has two representatives
    q = np.array([0.5, -1.0, 1.2, -0.3, 0.8, 2.0])
    T = robot.pose(q)
    shift = 2 * np.pi * np.array([-1, 0, 0, 0, 0, -1])
    near = robot.inverse_kinematics(T, q0=q + shift)
    assert np.allclose(near.solutions[0], q + shift, atol=1e-9)
    assert np.allclose(robot.inverse_kinematics(T, q0=q).solutions[0], q, atol=1e-9)
    assert np.all(np.abs(near.solutions) <= 2 * np.pi + 1e-12)


def test_planar_3r_pose_and_planar_2r_both_elbows():
    robot = kd.robots.planar_2r()
    result = robot.inverse_kinematics([1.0, 1.0, 0.0])
    assert len(result) == 2 and result.solutions[0][1] * result.solutions[1][1] < 0
    check_all(robot, result, np.array([1.0, 1.0, 0.0]))
    robot3 = kd.robots.planar_3r()
    T = robot3.pose(np.array([0.3, 0.9, -0.6]))
    assert len(robot3.inverse_kinematics(T)) == 2
    # a planar 3R position target is redundant: the numeric solver takes it
    assert robot3.inverse_kinematics(T[:3, 3]).solver == "numeric:lm"


# ------------------------------------------------------------------ unreachable and singular
def test_unreachable_position_reports_the_nearest_point():
    robot = kd.robots.elbow_3r()
    target = np.array([5.0, 0.2, 0.5])
    result = robot.inverse_kinematics(target)
    assert not result.success and len(result) == 0 and result.reachable is False
    assert "out of reach" in result.message
    # the reachable set is the ball of radius L2 + L3 = 3 about the shoulder (0, 0, L1 = 3)
    shoulder = np.array([0.0, 0.0, 3.0])
    expected = shoulder + 3.0 * (target - shoulder) / np.linalg.norm(target - shoulder)
    assert np.allclose(result.nearest, expected, atol=1e-6)
    assert np.allclose(robot.pose(result.nearest_q)[:3, 3], result.nearest)


def test_unreachable_pose_and_numeric_failure_are_reported():
    robot = kd.robots.ur5()
    T = robot.pose(np.zeros(6))
    T[:3, 3] = [3.0, 0.0, 0.0]
    result = robot.inverse_kinematics(T)
    assert len(result) == 0 and result.reachable is False and not result.success
    numeric = robot.inverse_kinematics(T, method="numeric", restarts=2)
    assert (
        not numeric.success
        and len(numeric) == 0
        and numeric.reachable is None
        and "did not converge" in numeric.message
    )
    # a 4x4 target for a 3-DOF arm: only the branches whose orientation matches survive
    arm = kd.robots.elbow_3r()
    q = np.array([0.2, -0.4, 0.9])
    one = arm.inverse_kinematics(arm.pose(q))
    assert len(one) == 1 and np.allclose(one.solutions[0], q)


def test_inside_the_inner_hole_is_unreachable():
    # |L2 - L3| = 1: the ball of radius 1 about the shoulder cannot be reached
    robot = kd.robots.elbow_3r()
    result = robot.inverse_kinematics([0.3, 0.0, 3.2])
    assert not result.success and result.reachable is False and result.nearest is not None
    assert np.linalg.norm(result.nearest - [0.0, 0.0, 3.0]) == pytest.approx(1.0, abs=1e-6)


def test_singular_targets_are_flagged():
    robot = kd.robots.elbow_3r()
    on_axis = np.array([0.0, 0.0, 4.5])  # on the waist axis: theta1 is free
    result = robot.inverse_kinematics(on_axis, q0=np.array([0.7, 0.0, 0.0]))
    assert result.success and result.singular
    assert np.allclose(result.solutions[:, 0], 0.7)  # the free waist keeps q0's value
    check_all(robot, result, on_axis)
    puma = kd.robots.puma560()
    q = np.array([0.2, 0.5, -0.4, 0.3, 0.0, 0.6])  # q5 = 0: axes 4 and 6 line up
    T = puma.pose(q)
    wrist = puma.inverse_kinematics(T, q0=q)
    assert wrist.success and wrist.singular
    check_all(puma, wrist, T)


# ------------------------------------------------------------------ geometry, not names
def test_detection_reads_geometry_not_names():
    ur = kd.robots.ur5()
    renamed = ur.replace(name="mystery")
    assert ik.analytic_structure(renamed) == "three_parallel"
    # the elbow arm in modified DH (Craig), with a base pose and a tool offset along the forearm
    h = math.pi / 2
    craig = kd.Robot.from_dh(
        [(0, 3.0, 0, 0), (0, 0, 0, h), (0, 0, 2.0, 0)],
        convention="modified",
        tool=np.array(translation(1.0, 0.0, 0.0)),
        base_pose=np.array(rot_z(0.3)),
    )
    assert ik.analytic_structure(craig) == "arm_intersecting_shoulder"
    res = craig.inverse_kinematics(craig.pose(np.array([0.1, 0.5, -0.7]))[:3, 3])
    assert len(res) == 4
    # break the wrist: a small offset between axes 5 and 6 of the PUMA leaves no special structure,
    # so the general 6R elimination takes it (the name stays the PUMA's: detection reads geometry)
    rows = list(kd.robots.puma560().dh)
    rows[4] = dataclasses.replace(rows[4], a=0.01)
    bent = kd.Robot.from_dh(rows, name="puma560")
    assert ik.analytic_structure(bent) == "general_6r"
    q = np.array([0.1, 0.4, -0.3, 0.5, 0.6, -0.2])
    T = bent.pose(q)
    res = bent.inverse_kinematics(T, respect_limits=False)
    assert res.solver == "analytic:general_6r" and res.max_solutions == 16
    assert np.min(np.max(np.abs(res.solutions - q), axis=1)) < 1e-8
    # with a prismatic joint in the chain no closed form is left
    prismatic = kd.Robot.from_dh([dataclasses.replace(rows[0], kind="prismatic"), *rows[1:]], name="puma560")
    assert ik.analytic_structure(prismatic) is None
    with pytest.raises(ValueError, match="no closed-form"):
        prismatic.inverse_kinematics(prismatic.pose(q), method="analytic")


def test_urdf_ur5_gets_the_closed_form():
    path = Path(example_robot_data_dir() or "/nonexistent") / "ur_description/urdf/ur5_robot.urdf"
    if not path.exists():
        pytest.skip("example-robot-data is not installed")
    robot = kd.Robot.from_urdf(str(path), tool="tool0")
    assert ik.analytic_structure(robot) == "three_parallel"
    q = np.array([0.4, -1.2, 1.1, -0.5, 1.3, 0.2])
    T = robot.pose(q)
    result = robot.inverse_kinematics(T, respect_limits=False)
    assert len(result) == 8 and contains(result.solutions, q, robot)
    check_all(robot, result, T)


# ------------------------------------------------------------------ numeric solver
def numeric_success(robot, frame, count=1000, seed=3):
    rng = np.random.default_rng(seed)
    Q = robot.random_configuration(rng, size=count)
    T = robot.pose(Q, frame)
    result = robot.inverse_kinematics(T, frame=frame, method="numeric")
    assert isinstance(result, ik.IKBatchResult) and result.q.shape == (count, robot.n)
    ok = result.success
    # every success reproduces its target and stays inside the limits
    P = robot.pose(result.q[ok], frame)
    assert np.max(np.linalg.norm(P[:, :3, 3] - T[ok, :3, 3], axis=1)) < 1e-9
    R_err = np.einsum("nji,njk->nik", P[:, :3, :3], T[ok, :3, :3])
    sin = np.linalg.norm(R_err - np.transpose(R_err, (0, 2, 1)), axis=(1, 2)) / (2 * math.sqrt(2))
    cos = (np.trace(R_err, axis1=1, axis2=2) - 1) / 2
    assert np.max(np.arctan2(sin, cos)) < 1e-9
    assert np.max(result.orientation_error[ok]) < 1e-9
    assert np.all(result.q >= robot.lower_limits - 1e-12) and np.all(result.q <= robot.upper_limits + 1e-12)
    return result.success_rate


def test_numeric_panda_1000_targets():
    robot = panda()
    assert robot.n == 7 and ik.analytic_structure(robot, "panda_hand_tcp") is None
    rate = numeric_success(robot, "panda_hand_tcp")
    assert rate >= 0.99, rate


def test_numeric_dh_7dof_1000_targets():
    robot = dh_7dof()
    rate = numeric_success(robot, "tool")
    assert rate >= 0.99, rate


def test_numeric_single_target_and_masks():
    robot = dh_7dof()
    q = np.array([0.3, 0.5, -0.2, -1.0, 0.4, 0.8, 0.1])
    T = robot.pose(q)
    one = robot.inverse_kinematics(T)
    assert one.success and one.solver == "numeric:lm" and len(one) == 1 and one.iterations > 0
    check_all(robot, one, T)
    # position only (a 3-vector, or a 4x4 with a position mask)
    pos = robot.inverse_kinematics(T[:3, 3])
    assert pos.success and np.linalg.norm(robot.pose(pos.q)[:3, 3] - T[:3, 3]) < 1e-9
    masked = robot.inverse_kinematics(T, mask=[1, 1, 1, 0, 0, 0])
    assert masked.success and masked.orientation_error[0] == 0.0
    # weighted: x, y and the rotation about z only
    T2 = T.copy()
    T2[2, 3] += 0.05
    w = robot.inverse_kinematics(T2, mask=[1, 1, 0, 0, 0, 1])
    P = robot.pose(w.q)
    assert w.success and np.allclose(P[:2, 3], T2[:2, 3], atol=1e-9)
    # a joint held by its limits is never left
    tight = robot.replace(
        links=[
            l
            if i != 1
            else kd.Link(
                l.name, l.parent, kd.Joint(l.joint.name, lower=-0.1, upper=0.1), l.placement, l.post, l.inertia
            )
            for i, l in enumerate(robot.links)
        ]
    )
    res = tight.inverse_kinematics(T, restarts=3)
    assert not res.success or abs(res.q[1]) <= 0.1
    if res.nearest_q is not None:
        assert abs(res.nearest_q[1]) <= 0.1 + 1e-12


def test_redundant_position_on_a_6r_goes_numeric():
    robot = kd.robots.puma560()
    p = robot.pose(np.array([0.1, 0.6, -0.3, 0.2, 0.5, 0.0]))[:3, 3]
    result = robot.inverse_kinematics(p)
    assert result.solver == "numeric:lm" and result.success
    assert np.linalg.norm(robot.pose(result.q)[:3, 3] - p) < 1e-9
    with pytest.raises(ValueError, match="position-only"):
        robot.inverse_kinematics(p, method="analytic")


@pytest.mark.parametrize(
    "name,kind", [("elbow_3r", "position"), ("puma560", "pose"), ("ur5", "pose"), ("stanford", "pose")]
)
def test_analytic_and_numeric_agree(name, kind):
    robot = kd.robots.get(name)
    rng = np.random.default_rng(21)
    for _ in range(10):
        q = robot.random_configuration(rng)
        T = robot.pose(q)
        target = T[:3, 3] if kind == "position" else T
        exact = robot.inverse_kinematics(target, respect_limits=False)
        start = q + rng.normal(scale=0.3, size=robot.n)
        numeric = robot.inverse_kinematics(target, q0=start, method="numeric", respect_limits=False)
        assert numeric.success
        # the numeric answer is one of the closed-form solutions
        assert contains(exact.solutions, numeric.q, robot, 1e-6), (numeric.q, exact.solutions)


def test_batches():
    robot = kd.robots.ur5()
    rng = np.random.default_rng(2)
    Q = robot.random_configuration(rng, size=50)
    T = robot.pose(Q)
    batch = robot.inverse_kinematics(T, q0=Q)
    assert isinstance(batch, ik.IKBatchResult) and batch.solver == "analytic:three_parallel"
    assert batch.success.all() and np.allclose(batch.q, Q, atol=1e-8)  # nearest q0 = the original
    numeric = robot.inverse_kinematics(T, q0=Q + 0.05, method="numeric")
    assert numeric.success_rate == 1.0
    assert np.allclose(robot.pose(numeric.q), T, atol=1e-9)
    T_out = T.copy()
    T_out[0, :3, 3] = [5.0, 0.0, 0.0]
    partial = robot.inverse_kinematics(T_out[:3])
    assert partial.success.tolist() == [False, True, True]
    # out of reach: the numeric solver's best attempt, finite, with its true residual (never a NaN row)
    assert np.isfinite(partial.q[0]).all() and partial.position_error[0] > 1.0
    assert partial.position_error[0] == pytest.approx(
        np.linalg.norm(robot.pose(partial.q[0])[:3, 3] - T_out[0, :3, 3]), rel=1e-9
    )
    elbow = kd.robots.elbow_3r()
    P = elbow.pose(elbow.random_configuration(rng, size=20))[:, :3, 3]
    pb = elbow.inverse_kinematics(P)
    assert pb.success.all() and np.allclose(elbow.pose(pb.q)[:, :3, 3], P, atol=1e-9)


# ------------------------------------------------------------------ bad input
def test_bad_input_gives_clear_errors():
    robot = kd.robots.ur5()
    T = robot.pose(np.zeros(6))
    scaled = T.copy()
    scaled[:3, :3] *= 1.1
    with pytest.raises(ValueError, match="not an SE\\(3\\) matrix"):
        robot.inverse_kinematics(scaled)
    sheared = T.copy()
    sheared[3] = [0, 0, 1, 1]
    with pytest.raises(ValueError, match="last row"):
        robot.inverse_kinematics(sheared)
    mirrored = T.copy()
    mirrored[:3, 0] *= -1
    with pytest.raises(ValueError, match="det"):
        robot.inverse_kinematics(mirrored)
    nan = T.copy()
    nan[0, 3] = np.nan
    for method in ("auto", "numeric"):
        with pytest.raises(ValueError, match="non-finite"):
            robot.inverse_kinematics(nan, method=method)
    with pytest.raises(ValueError, match="non-finite"):
        robot.inverse_kinematics([np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="6 weights"):
        robot.inverse_kinematics(T, mask=[1, 1, 1])
    with pytest.raises(ValueError, match=">= 0"):
        robot.inverse_kinematics(T, mask=[1, 1, 1, -1, 0, 0])
    with pytest.raises(ValueError, match="not all zero"):
        robot.inverse_kinematics(T, mask=[0] * 6)
    with pytest.raises(ValueError, match="shape"):
        robot.inverse_kinematics(np.ones((2, 3, 3)))
    with pytest.raises(ValueError, match="shape"):
        robot.inverse_kinematics(np.ones(6))
    with pytest.raises(ValueError, match="method"):
        robot.inverse_kinematics(T, method="fast")
    with pytest.raises(ValueError, match="q0"):
        robot.inverse_kinematics(T, q0=np.zeros(5))
    with pytest.raises(ValueError, match="numbers"):
        robot.inverse_kinematics("up")
    with pytest.raises(ValueError, match="unknown frame"):
        robot.inverse_kinematics(T, frame="nowhere")
    with pytest.raises(ValueError, match="weighted mask"):
        robot.inverse_kinematics(T, mask=[1, 1, 1, 1, 1, 0.5], method="analytic")


@pytest.mark.parametrize(
    "setting",
    [dict(tolerance=-1e-9), dict(tolerance=float("nan")), dict(max_iterations=-1), dict(restarts=-1), dict(seed=-1)],
)
def test_bad_solver_settings_give_clear_errors(setting):
    """A NaN tolerance used to report success; negative counts an OverflowError from the binding."""
    robot = kd.robots.ur5()
    T = robot.pose(np.zeros(6))
    name = next(iter(setting))
    for method in ("auto", "numeric"):
        with pytest.raises(ValueError, match=f"{name} must be"):
            robot.inverse_kinematics(T, method=method, **setting)


# ------------------------------------------------------------------ command line
def run_cli(argv, capsys):
    from kinedyn.cli import main

    code = main(argv)
    return code, capsys.readouterr().out


def test_cli_ik_tutorial(capsys):
    code, out = run_cli(["ik", "elbow_3r", "--xyz", "1.0", "0.2", "0.5", "--all", "--json"], capsys)
    payload = json.loads(out)
    assert code == 0 and payload["count"] == 4 and len(payload["solutions"]) == 4
    assert payload["solver"] == "analytic:arm_intersecting_shoulder"
    code, out = run_cli(["ik", "elbow_3r", "--xyz", "1.0", "0.2", "0.5", "--deg"], capsys)
    assert code == 0 and "11.3099" in out and "4 solution(s)" in out
    code, out = run_cli(["ik", "elbow_3r", "--xyz", "9", "0", "0"], capsys)
    assert code == 2 and "out of reach" in out
    code, out = run_cli(
        ["ik", "ur5", "--xyz", "0.3", "0.2", "0.4", "--rpy", "180", "0", "0", "--deg", "--all", "--json"], capsys
    )
    payload = json.loads(out)
    assert code == 0 and payload["count"] == 8
    robot = kd.robots.ur5()
    T = np.array(payload["target"])
    for q in np.radians(payload["solutions"]):
        assert np.allclose(robot.pose(q), T, atol=1e-9)


def test_cli_ik_parser_registers_standalone():
    import argparse

    from kinedyn.cli import build_parser
    from kinedyn.cli.commands import ik as ik_command

    parser = argparse.ArgumentParser()
    ik_command.add_arguments(parser)
    args = parser.parse_args(["puma560", "--xyz", "0.5", "0.1", "0.2", "--rpy", "0", "1.57", "0"])
    assert args.rpy == [0.0, 1.57, 0.0]
    args = build_parser(load=()).parse_args(["ik", "puma560", "--xyz", "0.5", "0.1", "0.2", "--rpy", "0", "1.57", "0"])
    assert args.func is ik_command.run and args.rpy == [0.0, 1.57, 0.0]
