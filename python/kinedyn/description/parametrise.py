"""Multi-DOF joints as chains of 1-DOF joints: the parametrisation the symbolic engine uses.

A symbolic derivation needs one scalar coordinate per degree of freedom, each with its rate as the
generalised velocity (Lagrange's equations in minimal coordinates). kinedyn's numeric engine keeps
Pinocchio's conventions (a unit quaternion in q, body-frame velocities in v), which are no such
coordinates. :func:`euler_parametrised` rewrites every multi-DOF joint as a chain of 1-DOF joints
meeting at the joint frame, with massless links in between:

- ``floating`` (free-flyer) ``J``: ``J_x``, ``J_y``, ``J_z`` prismatic along the joint frame's axes, then
  ``J_yaw``, ``J_pitch``, ``J_roll`` revolute about z, y and x: position ``(x, y, z)`` in the parent's
  frame, orientation ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (ZYX Euler angles);
- ``spherical`` ``J``: ``J_yaw``, ``J_pitch``, ``J_roll`` (the same ZYX angles);
- ``planar`` ``J`` with normal ``n``: ``J_x``, ``J_y`` prismatic along the plane's axes (e1, e2; x and y
  when n = z), then ``J_theta`` revolute about n.

The last joint of each chain carries the link (its name, inertia and frame), so every frame and link
keeps its meaning. The Euler angles are singular where ``pitch = ±pi/2`` (gimbal lock): there the
chain's Jacobian loses rank and M is singular, as for any three-angle parametrisation; the numeric
engine's quaternions have no such point.

Numerically, the two descriptions give the same motion: with ``v = T(q_e) qd_e`` (the body twist of
each multi-DOF joint's child in its own frame as a function of the Euler rates, identity for 1-DOF
joints), ``M_e = T^T M T``, ``g_e = T^T g``; the tests hold them to this.
"""

from __future__ import annotations

import numpy as np

from .joint import Joint, planar_basis
from .link import Link

__all__ = ["euler_parametrised", "EULER_SUFFIXES"]

#: the names added to a multi-DOF joint's name for its chain's joints, in order
EULER_SUFFIXES = {
    "floating": ("x", "y", "z", "yaw", "pitch", "roll"),
    "spherical": ("yaw", "pitch", "roll"),
    "planar": ("x", "y", "theta"),
}


def _chain(joint: Joint) -> list:
    """(suffix, kind, axis) of each 1-DOF joint replacing the multi-DOF ``joint``."""
    e = np.eye(3)
    if joint.kind == "floating":
        kinds = ["prismatic"] * 3 + ["revolute"] * 3
        axes = [e[0], e[1], e[2], e[2], e[1], e[0]]
    elif joint.kind == "spherical":
        kinds, axes = ["revolute"] * 3, [e[2], e[1], e[0]]
    else:  # planar, in the plane normal to the joint's axis
        n = np.asarray(joint.axis, dtype=float)
        e1, e2 = planar_basis(n)
        kinds, axes = ["prismatic", "prismatic", "revolute"], [e1, e2, np.cross(e1, e2)]
    return [
        (suffix, kind, tuple(float(a) for a in axis))
        for suffix, kind, axis in zip(EULER_SUFFIXES[joint.kind], kinds, axes)
    ]


def euler_parametrised(robot):
    """The same robot with each multi-DOF joint replaced by its chain of 1-DOF joints (see the module
    documentation); a robot without multi-DOF joints is returned as it is."""
    if not robot.has_multi_dof_joints:
        return robot
    links = []
    for link in robot.links:
        if not link.joint.is_multi_dof:
            links.append(link)
            continue
        chain = _chain(link.joint)
        parent, placement = link.parent, link.placement
        for k, (suffix, kind, axis) in enumerate(chain):
            joint = Joint(f"{link.joint.name}_{suffix}", kind, axis)
            if k + 1 < len(chain):
                name = f"{link.name}_{suffix}"
                links.append(Link(name, parent, joint, placement))  # massless, at the joint frame
                parent, placement = name, np.eye(4)
            else:
                links.append(Link(link.name, parent, joint, placement, link.post, link.inertia))
    return robot.replace(links=links, name=robot.name)


def euler_to_native(robot, q_euler, qd_euler=None):
    """``(q, v)`` of ``robot`` (quaternions, body-frame velocities) at the state ``(q_euler, qd_euler)``
    of :func:`euler_parametrised`'s robot (``v`` None when ``qd_euler`` is None)."""
    q_euler = np.asarray(q_euler, dtype=float)
    values: list = []
    k = 0
    for joint in robot.joints:
        block = q_euler[k : k + joint.nv]
        k += joint.nv
        if joint.kind == "planar":
            x, y, th = block
            values.extend([x, y, np.cos(th), np.sin(th)])
        elif joint.kind == "floating":
            values.extend([*block[:3], *_quaternion_zyx(*block[3:])])
        elif joint.kind == "spherical":
            values.extend(_quaternion_zyx(*block))
        else:
            values.extend(block)
    q = np.array(values)
    if qd_euler is None:
        return q, None
    return q, euler_velocity_map(robot, q_euler) @ np.asarray(qd_euler, dtype=float)


def euler_velocity_map(robot, q_euler) -> np.ndarray:
    """T(q_e), (nv, nv): ``v = T qd_e``. For each multi-DOF joint the columns of its chain in the
    local Jacobian of its child link (the chain's twist in the child's own frame); identity else."""
    expanded = euler_parametrised(robot)
    T = np.eye(robot.nv)
    k = 0
    for joint, body in zip(robot.joints, robot.body_names):
        if joint.is_multi_dof:
            J = expanded.jacobian(q_euler, frame=body, reference="local")
            rows = [0, 1, 5] if joint.kind == "planar" else (list(range(6)) if joint.kind == "floating" else [3, 4, 5])
            if joint.kind == "planar":
                e1, e2 = planar_basis(np.asarray(joint.axis, dtype=float))
                basis = np.array([[*e1, 0, 0, 0], [*e2, 0, 0, 0], [0, 0, 0, *np.cross(e1, e2)]])
                T[k : k + 3, k : k + 3] = basis @ J[:, k : k + 3]
            else:
                T[k : k + joint.nv, k : k + joint.nv] = J[rows, k : k + joint.nv]
        k += joint.nv
    return T


def _quaternion_zyx(yaw: float, pitch: float, roll: float) -> tuple:
    """The unit quaternion (x, y, z, w) of Rz(yaw) Ry(pitch) Rx(roll)."""
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    cp, sp_ = np.cos(pitch / 2), np.sin(pitch / 2)
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    return (
        sr * cp * cy - cr * sp_ * sy,
        cr * sp_ * cy + sr * cp * sy,
        cr * cp * sy - sr * sp_ * cy,
        cr * cp * cy + sr * sp_ * sy,
    )
