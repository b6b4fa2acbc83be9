"""Numeric inverse kinematics on the configuration manifold (issue 14 §1): floating, spherical and
planar joints (q of size nq, steps of size nv, q ⊕ dq), and robots with reduced mimic joints (the
solver in the reduced coordinates, Jacobian J G).

Every target is the pose of a frame at a random configuration; a solution is checked by the
robot's forward kinematics (and Pinocchio's for Solo-12, or the robot with independent joints for
the mimic ones), its quaternions for unit norm, and its 1-DOF joints for their limits."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.testing import example_robot_data_dir, random_robot

pytest.importorskip("kinedyn._core", reason="the native module is not built")


def unit_parts(robot, q) -> list:
    """The norms of every quaternion and planar (cos, sin) pair of q (docs/conventions.md layout)."""
    norms, at = [], 0
    for j in robot.joints:
        part = {"floating": q[at + 3 : at + 7], "spherical": q[at : at + 4], "planar": q[at + 2 : at + 4]}.get(j.kind)
        if part is not None:
            norms.append(float(np.linalg.norm(part)))
        at += j.nq
    return norms


def assert_solves(robot, result, target, frame, atol=1e-9):
    assert result.success, result.message
    assert result.solver == "numeric:lm"
    q = result.q
    assert q.shape == (robot.nq,)
    np.testing.assert_allclose(robot.pose(q, frame), target, atol=atol)
    norms = unit_parts(robot, q)
    np.testing.assert_allclose(norms, np.ones(len(norms)), atol=1e-12)
    assert np.all(q >= robot.lower_limits - 1e-12) and np.all(q <= robot.upper_limits + 1e-12)


# ------------------------------------------------------------------ random trees of every joint kind
@pytest.mark.parametrize(
    "kind, options",
    [
        ("floating", dict(floating=True)),
        ("spherical", dict(spherical=0.5)),
        ("planar", dict(planar=0.5)),
        ("mixed tree", dict(floating=True, spherical=0.3, planar=0.3, branching=True)),
    ],
)
def test_random_robots_with_multi_dof_joints(kind, options):
    robot = random_robot(3, n=6, **options)
    assert any(j.is_multi_dof for j in robot.joints) and robot.nq > robot.nv
    rng = np.random.default_rng(7)
    for _ in range(3):
        q_goal = robot.random_configuration(rng)
        target = robot.pose(q_goal)
        result = robot.inverse_kinematics(target, q0=robot.random_configuration(rng))
        assert_solves(robot, result, target, robot.tool)
        # near the goal, Gauss-Newton steps q ⊕ dq with the Jacobian of the same velocity: few iterations
        near = robot.inverse_kinematics(target, q0=robot.integrate(q_goal, 0.05 * rng.normal(size=robot.nv)))
        assert_solves(robot, near, target, robot.tool)
        assert near.iterations <= 5, near.iterations


def test_a_batch_and_no_limits_keep_quaternions_whole():
    """A batch gives (N, nq); without limits only revolute angles are wrapped, never a quaternion."""
    robot = random_robot(5, n=5, floating=True, spherical=0.4)
    rng = np.random.default_rng(1)
    targets = robot.pose(robot.random_configuration(rng, size=3))
    revolute = np.array([j.kind == "revolute" for j in robot.joints for _ in range(j.nq)])
    assert revolute.any()
    start = robot.neutral()
    start[revolute] = 2 * np.pi + 0.3  # solutions near the start need wrapping
    batch = robot.inverse_kinematics(targets, q0=start, respect_limits=False)
    assert batch.q.shape == (3, robot.nq) and batch.success.all()
    np.testing.assert_allclose(robot.pose(batch.q), targets, atol=1e-9)
    for q in batch.q:
        np.testing.assert_allclose(unit_parts(robot, q), 1.0, atol=1e-12)
    assert np.all(np.abs(batch.q[:, revolute]) <= np.pi)


def test_random_restarts_draw_unit_quaternions():
    """An unreachable target for a fixed-base arm with spherical joints: every attempt fails and the
    best iterate (from a random restart or the start) still has unit quaternions."""
    robot = random_robot(3, n=6, spherical=0.5)
    assert any(j.kind == "spherical" for j in robot.joints)
    far = np.eye(4)
    far[:3, 3] = [50.0, 0.0, 0.0]
    result = robot.inverse_kinematics(far, method="numeric", max_iterations=3, restarts=6, seed=3)
    assert not result.success and result.nearest_q is not None
    assert result.iterations > 3  # restarts happened
    np.testing.assert_allclose(unit_parts(robot, result.nearest_q), 1.0, atol=1e-12)


FLOATING_ARM = """<robot name="floating_arm">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"/>
  <joint name="swing" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.1" upper="0.1" effort="10" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="arm"/><child link="tip"/><origin xyz="0.3 0 0"/></joint>
</robot>"""


def test_limits_hold_the_one_dof_joints_while_the_base_moves():
    """A yaw of 1 rad of the tip: without limits the least-squares steps share it between the base and
    the joint (which then leaves its +-0.1 rad); with limits the joint stays inside and the base turns."""
    robot = kd.Robot.from_urdf(FLOATING_ARM, floating_base=True)
    assert (robot.nq, robot.nv) == (8, 7)
    q_goal = np.r_[0.1, -0.2, 0.3, 0.0, 0.0, np.sin(0.5), np.cos(0.5), 0.05]
    target = robot.pose(q_goal, "tip")
    free = robot.inverse_kinematics(target, frame="tip", respect_limits=False)
    assert free.success and abs(free.q[7]) > 0.1  # the limit matters for this target
    result = robot.inverse_kinematics(target, frame="tip")
    assert_solves(robot, result, target, "tip")
    assert -0.1 <= result.q[7] <= 0.1


# ------------------------------------------------------------------ a real floating robot
ERD = example_robot_data_dir()
needs_erd = pytest.mark.skipif(ERD is None, reason="example-robot-data is not installed")


@needs_erd
def test_solo12_foot_with_a_floating_base_agrees_with_pinocchio():
    pin = pytest.importorskip("pinocchio")
    from pinocchio_pairs import PinPair

    path = os.path.join(ERD, "solo_description", "robots", "solo12.urdf")
    solo = kd.Robot.from_urdf(path, floating_base=True)
    pair = PinPair(solo, pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer()))
    fid = pair.model.getFrameId("FR_FOOT")
    rng = np.random.default_rng(11)
    for _ in range(2):
        target = solo.pose(solo.random_configuration(rng), "FR_FOOT")
        result = solo.inverse_kinematics(target, frame="FR_FOOT")
        assert_solves(solo, result, target, "FR_FOOT")
        pin.framesForwardKinematics(pair.model, pair.data, pair.to_pin_q(result.q))
        np.testing.assert_allclose(pair.data.oMf[fid].homogeneous, target, atol=1e-9)


# ------------------------------------------------------------------ mimic joints, reduced
def gripper(floating: bool = False):
    from test_mimic import gripper_urdf  # right_finger = -left_finger + 0.01, knuckle_joint = 0.5 wrist + 0.2

    return kd.Robot.from_urdf(gripper_urdf(), floating_base=floating), kd.Robot.from_urdf(
        gripper_urdf(), floating_base=floating, mimic="independent"
    )


def expand_by_hand(robot, full, q):
    """The independent robot's configuration of a reduced one, from the file's relations."""
    values = dict(zip(robot.joint_names, np.split(q, np.cumsum([j.nq for j in robot.joints])[:-1])))
    values["right_finger"] = -values["left_finger"] + 0.01
    values["knuckle_joint"] = 0.5 * values["wrist"] + 0.2
    return np.concatenate([values[name] for name in full.joint_names])


@pytest.mark.parametrize("floating", [False, True])
@pytest.mark.parametrize("frame", ["right", "knuckle"])
def test_a_frame_a_mimic_follower_moves_is_solved_in_reduced_coordinates(frame, floating):
    robot, full = gripper(floating)
    assert robot.mimic_joints and robot.nq == full.nq - 2
    rng = np.random.default_rng(5)
    q_goal = robot.random_configuration(rng)
    target = robot.pose(q_goal, frame)
    result = robot.inverse_kinematics(target, frame=frame)
    assert_solves(robot, result, target, frame)
    # the same pose on the robot with independent joints, the followers set from the relations
    np.testing.assert_allclose(full.pose(expand_by_hand(robot, full, result.q), frame), target, atol=1e-9)
    # near the goal the steps are Gauss-Newton steps with the exact Jacobian J G: a few iterations
    # (a Jacobian that misses the followers' multipliers takes from 13 to over a thousand)
    near = robot.inverse_kinematics(target, frame=frame, q0=robot.integrate(q_goal, 0.05 * rng.normal(size=robot.nv)))
    assert_solves(robot, near, target, frame)
    assert near.iterations <= 5, near.iterations
    with pytest.raises(
        ValueError, match="closed forms solve chains of revolute and prismatic joints only; use method='numeric'"
    ):
        robot.inverse_kinematics(target, frame=frame, method="analytic")


@needs_erd
def test_panda_finger_in_reduced_coordinates():
    path = os.path.join(ERD, "panda_description", "urdf", "panda.urdf")
    panda, full = kd.Robot.from_urdf(path), kd.Robot.from_urdf(path, mimic="independent")
    assert list(panda.mimic_joints) == ["panda_finger_joint2"] and panda.nq == 8
    rng = np.random.default_rng(4)
    q_goal = panda.random_configuration(rng)
    target = panda.pose(q_goal, "panda_rightfinger")
    result = panda.inverse_kinematics(target, frame="panda_rightfinger", q0=np.r_[q_goal[:7] + 0.2, 0.02])
    assert_solves(panda, result, target, "panda_rightfinger")
    np.testing.assert_allclose(full.pose(np.r_[result.q, result.q[7]], "panda_rightfinger"), target, atol=1e-9)


# ------------------------------------------------------------------ bad starts
def test_bad_starts_are_named():
    robot = random_robot(1, n=3, floating=True)
    target = robot.pose(robot.neutral())
    with pytest.raises(
        ValueError, match=r"q0 must have shape \(9,\) \(nq: a configuration; a free-flyer takes 7 entries.*got \(8,\)"
    ):
        robot.inverse_kinematics(target, q0=np.zeros(robot.nv))
    bad = robot.neutral()
    bad[6] = 2.0
    with pytest.raises(
        ValueError, match=r"q0\[3:7\] of floating joint 'j1' is the quaternion \(qx, qy, qz, qw\) = .* of norm 2, not 1"
    ):
        robot.inverse_kinematics(target, q0=bad)
    with pytest.raises(
        ValueError,
        match=r"robot 'random_chain_1' has floating, spherical or planar joints: the closed forms .*method='numeric'",
    ):
        robot.inverse_kinematics(target, method="analytic")
    # the native solver checks on its own: the quaternion, and limits on a multi-DOF joint's coordinates
    from kinedyn import _core

    model, frame = robot._model, robot.frame_index(robot.tool)
    lower, upper, w = robot.lower_limits, robot.upper_limits, np.ones(6)
    with pytest.raises(
        ValueError,
        match=r"q0\[3:7\], the quaternion \(qx, qy, qz, qw\) of the floating joint at body 0, has norm 2\.0+, not 1",
    ):
        _core.solve_ik(model, frame, target, bad, lower, upper, w)
    limited = lower.copy()
    limited[0] = -1.0
    with pytest.raises(
        ValueError, match=r"limits of coordinate 0 \(\[-1, inf\]\): it belongs to the multi-DOF joint at body 0"
    ):
        _core.solve_ik(model, frame, target, robot.neutral(), limited, upper, w)


# ------------------------------------------------------------------ the command line
@needs_erd
def test_cli_ik_of_a_floating_robot(capsys):
    from kinedyn.cli import main

    path = os.path.join(ERD, "solo_description", "robots", "solo12.urdf")
    code = main(
        [
            "ik",
            path,
            "--floating-base",
            "--frame",
            "FR_FOOT",
            "--xyz",
            "0.2",
            "-0.1",
            "-0.2",
            "--rpy",
            "0",
            "0",
            "0.3",
            "--json",
        ]
    )
    out = capsys.readouterr()
    assert code == 0, out.err
    doc = json.loads(out.out)
    solo = kd.Robot.from_urdf(path, floating_base=True)
    q = np.array(doc["solutions"][0])
    assert q.shape == (solo.nq,)
    T = solo.pose(q, "FR_FOOT")
    np.testing.assert_allclose(T[:3, 3], [0.2, -0.1, -0.2], atol=1e-9)
    assert main(["ik", path, "--floating-base", "--frame", "FR_FOOT", "--xyz", "0.2", "-0.1", "-0.2", "--deg"]) == 0
    table = capsys.readouterr().out
    assert "root_joint.qw" in table and "FR_KFE" in table  # kinedyn.coordinates' names, as every CLI table
    bad = ["0"] * 6 + ["2"] + ["0"] * 12  # a quaternion of norm 2
    assert (
        main(["ik", path, "--floating-base", "--frame", "FR_FOOT", "--xyz", "0.2", "-0.1", "-0.2", "--q0", *bad]) == 1
    )
    assert "--q0[3:7] of floating joint 'root_joint' is the quaternion" in capsys.readouterr().err
