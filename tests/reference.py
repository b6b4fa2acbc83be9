"""A small pure-NumPy forward kinematics used as a reference until the native engine exists.

It walks ``robot.tree.bodies`` (parents come first):

    world_from_body[i] = world_from_body[parent(i)] @ placement_i @ motion(axis_i, q_i + offset_i)
    world_from_frame    = world_from_body[frame.body] @ frame.placement   (body -1 = the base)

with motion a rotation about (revolute) or a translation along (prismatic) the unit axis, written
out here with Rodrigues' formula rather than borrowed from kinedyn._math.
"""

from __future__ import annotations

import os

import numpy as np


def rotation(axis, angle) -> np.ndarray:
    """R = I + sin(a) [k]x + (1 - cos(a)) [k]x^2 (Rodrigues)."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def joint_motion(kind: str, axis, x) -> np.ndarray:
    T = np.eye(4)
    if kind == "revolute":
        T[:3, :3] = rotation(axis, x)
    elif kind == "prismatic":
        k = np.asarray(axis, dtype=float)
        T[:3, 3] = x * k / np.linalg.norm(k)
    else:
        raise AssertionError(f"unexpected joint kind {kind}")
    return T


def body_poses(robot, q) -> list:
    """world_from_body for every body of the compiled tree (a reduced mimic follower at
    multiplier * q[leader] + offset)."""
    q = np.asarray(q, dtype=float)
    assert q.shape == (robot.n,)
    names, follows = robot.joint_names, robot.mimic_joints
    poses = []
    for body in robot.tree.bodies:
        parent = np.eye(4) if body.parent < 0 else poses[body.parent]
        relation = follows.get(body.joint.name)
        value = (
            q[names.index(body.joint.name)]
            if relation is None
            else relation.multiplier * q[names.index(relation.leader)] + relation.offset
        )
        x = value + float(body.joint.offset)
        poses.append(
            parent @ np.asarray(body.placement, dtype=float) @ joint_motion(body.joint.kind, body.joint.axis, x)
        )
    return poses


def frame_pose(robot, q, frame: str | None = None) -> np.ndarray:
    """world_from_frame of a named frame (default: the robot's tool)."""
    name = frame or robot.tool
    named = robot.tree.frames[robot.tree.frame_index(name)]
    bodies = body_poses(robot, q)
    world_from_body = np.eye(4) if named.body < 0 else bodies[named.body]
    return world_from_body @ np.asarray(named.placement, dtype=float)


def all_frame_poses(robot, q) -> dict:
    bodies = body_poses(robot, q)
    out = {}
    for f in robot.tree.frames:
        world_from_body = np.eye(4) if f.body < 0 else bodies[f.body]
        out[f.name] = world_from_body @ np.asarray(f.placement, dtype=float)
    return out


def rpy(roll, pitch, yaw) -> np.ndarray:
    """URDF rpy as a rotation matrix, composed from elementary rotations: Rz(yaw) Ry(pitch) Rx(roll)."""
    return rotation([0, 0, 1], yaw) @ rotation([0, 1, 0], pitch) @ rotation([1, 0, 0], roll)


def pose(R=None, p=(0.0, 0.0, 0.0)) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def random_q(robot, rng) -> np.ndarray:
    lo = np.where(np.isfinite(robot.lower_limits), robot.lower_limits, -np.pi)
    hi = np.where(np.isfinite(robot.upper_limits), robot.upper_limits, np.pi)
    return rng.uniform(lo, hi)


# ------------------------------------------------------------------ example-robot-data's URDFs
UR5 = ("ur_description", "urdf", "ur5_robot.urdf")
PANDA = ("panda_description", "urdf", "panda.urdf")


def _find_robots():
    from kinedyn.testing import example_robot_data_dir

    return example_robot_data_dir()


def erd(*parts) -> str:
    """Path of a file shipped by example-robot-data (skips the test when it is not installed)."""
    import pytest

    root = _find_robots()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    return os.path.join(root, *parts)


def symbolic_backend_robots() -> dict:
    """The robots the symbolic backends (CasADi, JAX) are checked on against the core: name -> maker.
    ``puma560_drives`` has viscous and direction-dependent Coulomb friction (sign(qd)) and rotor inertia."""
    import kinedyn as kd

    return {
        "planar_2r": kd.robots.planar_2r,
        "puma560": kd.robots.puma560,
        "ur5": lambda: kd.Robot.from_urdf(erd(*UR5)),
        "puma560_drives": lambda: kd.robots.puma560(friction=True, motors=True),
    }
