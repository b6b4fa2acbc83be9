"""A robot description compiled into the native ``_core.Model``: one native body per degree of
freedom (a multi-DOF joint is a head body and members, crates/kinedyn-core/src/model/mod.rs), the
joint kinds' motion subspaces and the in-plane axes of planar joints."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._arrays import real_array
from .._core import Model
from .._math import to_float_array
from ..configuration import quaternion_to_matrix
from ..description.joint import planar_basis
from .mimic import ReducedModel

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["body_wrenches", "compile_model", "joint_columns", "link_origins", "locked_block", "planar_basis"]

# the joint kinds the core decodes into multi-DOF blocks (lie::Block::from_name)
MULTI_DOF_KINDS = ("floating", "spherical", "planar")


def locked_block(joint, block) -> np.ndarray:
    """The 4x4 joint motion of a multi-DOF ``joint`` at its q ``block`` (unit quaternion / (cos, sin)
    checked): what :meth:`Robot.lock_joints` folds into the placement."""
    b = real_array(block, f"value of joint '{joint.name}'").ravel()
    if b.shape != (joint.nq,) or not np.all(np.isfinite(b)):
        raise ValueError(
            f"lock_joints: the value of {joint.kind} joint '{joint.name}' must be its {joint.nq} finite q coordinates, got {block!r}"
        )
    T = np.eye(4)
    unit = b[-4:] if joint.kind != "planar" else b[2:]
    if abs(np.linalg.norm(unit) - 1.0) > 1e-6:
        raise ValueError(
            f"lock_joints: joint '{joint.name}': {'(cos, sin)' if joint.kind == 'planar' else 'quaternion'} {list(unit)} is not unit"
        )
    if joint.kind == "planar":
        e1, e2 = planar_basis(to_float_array(joint.axis, (3,), "axis"))
        n = np.cross(e1, e2)
        c, s = b[2], b[3]
        K = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
        T[:3, :3] = c * np.eye(3) + s * K + (1 - c) * np.outer(n, n)
        T[:3, 3] = b[0] * e1 + b[1] * e2
        return T
    T[:3, :3] = quaternion_to_matrix(b[-4:])
    if joint.kind == "floating":
        T[:3, 3] = b[:3]
    return T


def joint_columns(joint) -> list:
    """The native bodies' (kind, unit axis) of a joint's motion subspace, in its child's frame, kind
    "revolute" or "prismatic": 1-DOF: its own; free-flyer: linear x, y, z then angular x, y, z;
    spherical: angular x, y, z; planar: linear e1, e2, angular normal."""
    e = np.eye(3)
    if joint.kind == "floating":
        return [("prismatic", e[k]) for k in range(3)] + [("revolute", e[k]) for k in range(3)]
    if joint.kind == "spherical":
        return [("revolute", e[k]) for k in range(3)]
    axis = to_float_array(joint.axis, (3,), f"axis of joint '{joint.name}'")
    if joint.kind == "planar":
        e1, e2 = planar_basis(axis)
        return [("prismatic", e1), ("prismatic", e2), ("revolute", np.cross(e1, e2))]
    return [("revolute" if joint.kind == "revolute" else "prismatic", axis)]


def compile_model(robot: Robot):
    """The native model of ``robot`` (numeric parameters only): a ``_core.Model``, or a
    :class:`~kinedyn.native.mimic.ReducedModel` over it when the robot has reduced mimic joints."""
    if robot.symbols:
        raise ValueError(
            f"robot '{robot.name}' has symbolic parameters {sorted(map(str, robot.symbols))}: "
            "use robot.subs({...}) to give them values before numeric computation"
        )
    bodies = robot.tree.bodies
    last = robot._body_last_dof
    # one native body per degree of freedom: a multi-DOF joint is its head body (the joint's
    # transform, read from q) and members at the identity on it, the last carrying the link
    # (crates/kinedyn-core/src/model/mod.rs); a 1-DOF joint is one body
    parent: list = []
    kind: list = []
    axis: list = []
    offset: list = []
    placement: list = []
    blocks: list = []
    link_inertia = robot.inertial_parameters().reshape(len(bodies), 10)
    inertia = np.zeros((len(robot._dof_body), 10))  # every native body (mimic followers' too)
    for b, body in enumerate(bodies):
        joint = body.joint
        first = len(parent)
        parent.append(-1 if body.parent < 0 else int(last[body.parent]))
        placement.append(to_float_array(body.placement, (4, 4), f"placement of '{body.name}'"))
        offset.append(float(joint.offset))
        columns = joint_columns(joint)
        for m, (k, a) in enumerate(columns):
            if m > 0:
                parent.append(first + m - 1)
                placement.append(np.eye(4))
                offset.append(0.0)
            kind.append(k)
            axis.append(a)
        blocks.extend([joint.kind if joint.kind in MULTI_DOF_KINDS else ""] + [""] * (len(columns) - 1))
        inertia[last[b]] = link_inertia[b]

    # per degree of freedom of every moving joint, mimic followers included (the native model has them all)
    def per_dof(value):
        return np.array(
            [x for body in bodies for x in ([0.0] * body.joint.nv if body.joint.is_multi_dof else [value(body.joint)])]
        )

    armature, viscous, coulomb = (
        per_dof(lambda j, k=k: float(getattr(j, k))) for k in ("armature", "viscous", "coulomb")
    )
    gravity = to_float_array(robot.gravity, (3,), "gravity")
    frames = robot.tree.frames
    frame_body = np.array([-1 if f.body < 0 else last[f.body] for f in frames], dtype=np.int64)
    frame_placement = np.array([to_float_array(f.placement, (4, 4), f"frame '{f.name}'") for f in frames])
    # direction-dependent Coulomb friction: the level for qd < 0 travels only when it differs
    coulomb_negative = per_dof(lambda j: float(j.coulomb_levels[1]))
    asymmetric = None if np.array_equal(coulomb_negative, coulomb) else coulomb_negative
    native = Model(
        np.array(parent, dtype=np.int64),
        kind,
        np.array(axis, dtype=float).reshape(-1, 3),
        np.array(offset),
        np.array(placement).reshape(-1, 4, 4),
        inertia,
        armature,
        viscous,
        coulomb,
        gravity,
        frame_body,
        frame_placement,
        coulomb_negative=asymmetric,
        blocks=blocks if robot.has_multi_dof_joints else None,
    )
    origins = link_origins(robot)
    if np.any(origins):
        native = native.with_link_origins(origins)
    if robot._mimic is None:
        return native

    return ReducedModel(native, robot._mimic, robot.name)


def link_origins(robot: Robot) -> np.ndarray:
    """(n, 3) per native body: the origin of its link frame in its body frame, about which the core
    takes an external wrench's moment (``_core.Model.with_link_origins``). A standard-DH link frame
    sits at ``Tx(a)`` from its joint frame; a URDF link frame is its joint frame (zero). A multi-DOF
    joint's link is on its last body; the bodies before it carry no link (zero)."""
    u = np.zeros((len(robot._dof_body), 3))
    for b, name in enumerate(robot.body_names):
        T = to_float_array(robot.tree.frames[robot.frame_index(name)].placement, (4, 4), f"frame '{name}'")
        u[robot._body_last_dof[b]] = T[:3, 3]
    return u


def body_wrenches(robot: Robot, q, f_ext):
    """``f_ext`` (one wrench per moving link, ``robot.body_names``; or (N, links, 6)) laid out as the
    native model's bodies: one set for a batch of states is repeated for each, and the wrench of a
    multi-DOF joint's link acts on the joint's last body. The core moves each moment from the link
    frame's origin to the body's (:func:`link_origins`)."""
    if f_ext is None:
        return None
    f = real_array(f_ext, "f_ext")
    links = len(robot.tree.bodies)
    if f.shape == (links, 6) and np.ndim(q) == 2:
        # one set of wrenches for every state of a batch
        f = np.ascontiguousarray(np.broadcast_to(f, (len(q), links, 6)))
    if not robot.has_multi_dof_joints:
        return f  # (wrong shapes are reported by the core)
    if f.shape[-2:] != (links, 6):
        raise ValueError(
            f"f_ext must have shape ({links}, 6): one wrench per moving link {robot.body_names}, got {f.shape}"
        )
    full = np.zeros(f.shape[:-2] + (len(robot._dof_body), 6))  # every native body
    full[..., robot._body_last_dof, :] = f
    return full
