"""A robot description compiled into the native ``_core.Model``: one record per joint of the
description's tree, taken whole (kind, axis, placement, inertia, drive data); the core's model
builder expands multi-DOF joints (crates/kinedyn-core/src/model/builder.rs)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._arrays import real_array
from .._core import Model, joint_transform
from .._math import to_float_array
from ..description.joint import planar_basis
from .mimic import ReducedModel

if TYPE_CHECKING:
    from ..description.description import Description

__all__ = [
    "compile_model",
    "dof_links",
    "joint_record",
    "locked_block",
    "planar_basis",
]


def locked_block(joint, block) -> np.ndarray:
    """The 4x4 joint motion of a multi-DOF ``joint`` at its q ``block``: what :meth:`Robot.lock_joints`
    folds into the placement. The core's ``JointType::transform`` (``_core.joint_transform``), which
    checks the block (length, finite, unit quaternion / (cos, sin) pair)."""
    axis = None if joint.kind in ("floating", "spherical") else to_float_array(joint.axis, (3,), "axis")
    try:
        return joint_transform(joint.kind, axis, real_array(block, f"value of joint '{joint.name}'").ravel())
    except ValueError as e:
        raise ValueError(f"lock_joints: joint '{joint.name}': {e}") from None


def joint_record(body, inertia, link_origin=None) -> dict:
    """The record ``_core.Model`` takes for a moving body of the description's tree: its joint
    whole (kind, axis, offset, drive and friction data), the parent body's index, the joint's
    placement, the link's 10 inertial parameters and its frame's origin in the joint frame
    (``link_origin``, about which the core takes the moments of ``f_ext``; zero when None); the
    core expands a multi-DOF joint and places the link on its last body."""
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
        "link_origin": link_origin,
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
    # a link's frame in its joint frame (a standard-DH link frame sits at Tx(a), a URDF one at the joint frame)
    link_frames = {f.name: f for f in reversed(tree.frames)}  # the first of a name
    joints = [
        joint_record(
            body,
            to_float_array(body.inertia.parameters(), (10,), f"inertia of '{body.name}'"),
            to_float_array(link_frames[body.name].placement, (4, 4), f"frame '{body.name}'")[:3, 3],
        )
        for body in tree.bodies
    ]
    frames = [(int(f.body), to_float_array(f.placement, (4, 4), f"frame '{f.name}'")) for f in tree.frames]
    native = Model(joints, to_float_array(description.gravity, (3,), "gravity"), frames)
    if description.loops:
        # the core checks and names them (crates/kinedyn-core/src/constraints/mod.rs); with reduced
        # mimic joints they stay on the full model and ReducedModel composes them with G
        index = {f.name: k for k, f in enumerate(tree.frames)}
        native = native.with_loops(
            [(index[lp.frame_a], index[lp.frame_b], lp.kind, lp.name) for lp in description.loops]
        )
    if description.mimic_map is None:
        return native
    loops = tuple((lp.name, lp.rows) for lp in description.loops)
    return ReducedModel(native, description.mimic_map, description.name, loops)


def dof_links(description: Description) -> np.ndarray:
    """(nv,) the moving link (index into ``description.body_names``) each degree of freedom of the
    full tree belongs to, velocity coordinates in joint order (a multi-DOF joint's nv of them on its
    one link): how a native body index, which the core's errors carry, names a joint and a link."""
    return np.repeat(np.arange(len(description.tree.bodies)), [b.joint.nv for b in description.tree.bodies])
