"""Numeric IK leaves alone the joints a target does not need: the other arm of a two-armed robot,
fingers beyond the tool, a wrist roll about the tool's axis for a position target (kinedyn.ik.idle)."""

from __future__ import annotations

import numpy as np
import pytest
from reference import PANDA, erd

import kinedyn as kd

pytest.importorskip("kinedyn._core", reason="the native module is not built")

BAXTER = ("baxter_description", "urdf", "baxter.urdf")


def test_baxter_left_arm_target_leaves_the_right_arm_and_fingers_at_q0():
    robot = kd.load(erd(*BAXTER))
    names = robot.joint_names
    target = np.array([0.7, 0.3, 0.2])
    result = robot.inverse_kinematics(target, frame="left_gripper")
    assert result.success
    q = result.solutions[0]
    np.testing.assert_allclose(robot.pose(q, "left_gripper")[:3, 3], target, atol=1e-8)
    others = [k for k, n in enumerate(names) if not n.startswith("left_")]
    assert others and "r_gripper_l_finger_joint" in [names[k] for k in others]
    rest = np.clip(robot.neutral(), robot.lower_limits, robot.upper_limits)
    np.testing.assert_array_equal(q[others], rest[others])
    # a given q0: the right arm stays exactly there
    q0 = rest.copy()
    q0[others] = np.clip(0.3, robot.lower_limits[others], robot.upper_limits[others])
    q = robot.inverse_kinematics(target, q0=q0, frame="left_gripper").solutions[0]
    np.testing.assert_array_equal(q[others], q0[others])


def test_panda_position_target_keeps_the_finger_and_the_tool_roll_at_q0():
    robot = kd.load(erd(*PANDA))
    target = np.array([0.4, 0.2, 0.5])
    result = robot.inverse_kinematics(target)
    assert result.success
    q = result.solutions[0]
    np.testing.assert_allclose(robot.pose(q)[:3, 3], target, atol=1e-8)
    finger, roll = robot.joint_names.index("panda_finger_joint1"), robot.joint_names.index("panda_joint7")
    assert q[finger] == 0.0  # the finger cannot move the hand's TCP
    assert q[roll] == 0.0  # the TCP lies on joint 7's axis: a position target does not need it
    # a pose target needs the roll
    T = robot.pose(robot.random_configuration(1))
    q = robot.inverse_kinematics(T, method="numeric").solutions[0]
    np.testing.assert_allclose(robot.pose(q), T, atol=1e-8)
    assert q[finger] == 0.0


def test_a_batch_keeps_idle_joints_at_q0():
    robot = kd.load(erd(*BAXTER))
    targets = np.array([[0.7, 0.3, 0.2], [0.6, 0.4, 0.3]])
    batch = robot.inverse_kinematics(targets, frame="left_gripper")
    others = [k for k, n in enumerate(robot.joint_names) if not n.startswith("left_")]
    rest = np.clip(robot.neutral(), robot.lower_limits, robot.upper_limits)
    np.testing.assert_array_equal(batch.q[:, others], np.broadcast_to(rest[others], (2, len(others))))


def test_cli_ik_on_baxter_moves_only_the_left_arm(capsys):
    import json

    from kinedyn.cli import main

    path = erd(*BAXTER)
    code = main(["ik", path, "--xyz", "0.7", "0.3", "0.2", "--frame", "left_gripper", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0
    moved = {n for n, v in zip(doc["coordinate_labels"], doc["solutions"][0]) if v != 0.0}
    assert moved and all(n.startswith("left_") for n in moved)
