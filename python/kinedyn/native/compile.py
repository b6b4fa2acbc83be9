"""A robot description compiled into the native ``_core.Model``: one record per joint of the
description's tree, taken whole (kind, axis, placement, inertia, drive data); the core's model
builder expands multi-DOF joints (crates/kinedyn-core/src/model/builder.rs)."""

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
    from ..description.description import Description

__all__ = [
    "body_wrenches",
    "compile_model",
    "joint_record",
    "link_bodies",
    "link_origins",
    "locked_block",
    "planar_basis",
]


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


def joint_record(body, inertia) -> dict:
    """The record ``_core.Model`` takes for a moving body of the description's tree: its joint
    whole (kind, axis, offset, drive and friction data), the parent body's index, the joint's
    placement and the link's 10 inertial parameters; the core expands a multi-DOF joint."""
    joint = body.joint
    levels = joint.coulomb_levels
    return {
        "name": joint.name,
        "kind": joint.kind,
        "parent": int(body.parent),
        "placement": to_float_array(body.placement, (4, 4), f"placement of '{body.name}'"),
        # the joint's axis (a planar joint's normal); the core does not read it for floating and spherical joints
        "axis": to_float_array(joint.axis, (3,), f"axis of joint '{joint.name}'"),
        "inertia": inertia,
        "offset": float(joint.offset),
        "armature": float(joint.armature),
        "viscous": float(joint.viscous),
        "coulomb": float(levels[0]),
        # the level for qd < 0 travels only when it differs
        "coulomb_negative": None if joint.coulomb_is_symmetric else float(levels[1]),
    }


def compile_model(description: Description):
    """The native model of a robot ``description`` (numeric parameters only): a ``_core.Model`` of its
    tree's joints, taken whole (the core's model builder lays out multi-DOF joints,
    docs/architecture.md "The joint seam"), or a :class:`~kinedyn.native.mimic.ReducedModel` over it
    when the robot has reduced mimic joints."""
    if description.symbols:
        raise ValueError(
            f"robot '{description.name}' has symbolic parameters {sorted(map(str, description.symbols))}: "
            "use robot.subs({...}) to give them values before numeric computation"
        )
    tree = description.tree
    joints = [
        joint_record(body, to_float_array(body.inertia.parameters(), (10,), f"inertia of '{body.name}'"))
        for body in tree.bodies
    ]
    frames = [(int(f.body), to_float_array(f.placement, (4, 4), f"frame '{f.name}'")) for f in tree.frames]
    native = Model(joints, to_float_array(description.gravity, (3,), "gravity"), frames)
    origins = link_origins(description)
    if np.any(origins):
        native = native.with_link_origins(origins)
    if description.mimic_map is None:
        if description.loops:
            # the core checks and names them (crates/kinedyn-core/src/constraints/mod.rs)
            index = {f.name: k for k, f in enumerate(tree.frames)}
            native = native.with_loops(
                [(index[lp.frame_a], index[lp.frame_b], lp.kind, lp.name) for lp in description.loops]
            )
        return native
    return ReducedModel(native, description.mimic_map, description.name)


def link_bodies(description: Description) -> np.ndarray:
    """(links,) the native body that carries each moving link of the tree: the core's builder lays a
    multi-DOF joint out as one body per degree of freedom with the link on the last
    (crates/kinedyn-core/src/model/builder.rs), a 1-DOF joint as one body."""
    return np.cumsum([body.joint.nv for body in description.tree.bodies], dtype=np.int64) - 1


def link_origins(description: Description) -> np.ndarray:
    """(n, 3) per native body: the origin of its link frame in its body frame, about which the core
    takes an external wrench's moment (``_core.Model.with_link_origins``). A standard-DH link frame
    sits at ``Tx(a)`` from its joint frame; a URDF link frame is its joint frame (zero). A multi-DOF
    joint's link is on its last body; the bodies before it carry no link (zero)."""
    tree = description.tree
    last = link_bodies(description)
    u = np.zeros((int(last[-1]) + 1 if len(last) else 0, 3))
    for b, body in enumerate(tree.bodies):
        frame = next(f for f in tree.frames if f.name == body.name)
        u[last[b]] = to_float_array(frame.placement, (4, 4), f"frame '{body.name}'")[:3, 3]
    return u


def body_wrenches(description: Description, q, f_ext):
    """``f_ext`` (one wrench per moving link, ``body_names``; or (N, links, 6)) laid out as the
    native model's bodies: one set for a batch of states is repeated for each, and the wrench of a
    multi-DOF joint's link acts on the joint's last body. The core moves each moment from the link
    frame's origin to the body's (:func:`link_origins`)."""
    if f_ext is None:
        return None
    f = real_array(f_ext, "f_ext")
    links = len(description.tree.bodies)
    if f.shape == (links, 6) and np.ndim(q) == 2:
        # one set of wrenches for every state of a batch
        f = np.ascontiguousarray(np.broadcast_to(f, (len(q), links, 6)))
    if not description.has_multi_dof_joints:
        return f  # (wrong shapes are reported by the core)
    if f.shape[-2:] != (links, 6):
        raise ValueError(
            f"f_ext must have shape ({links}, 6): one wrench per moving link {description.body_names}, got {f.shape}"
        )
    last = link_bodies(description)
    full = np.zeros(f.shape[:-2] + (int(last[-1]) + 1, 6))  # every native body
    full[..., last, :] = f
    return full
