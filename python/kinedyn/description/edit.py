"""Editing a description: new descriptions with symbols substituted or joints locked.

``Robot.subs`` and ``Robot.lock_joints`` read their arguments (names, indices, configurations) and
call these; every field not named is carried over by ``dataclasses.replace``, so a field added to
``Joint``, ``DHRow`` or ``Description`` later is kept without touching this module.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from .._arrays import real_array
from .._lazy import LazyModule, sympy_instance
from .._math import as_value, is_symbolic, matmul, rot_axis, translation
from .._ui.names import did_you_mean
from .description import Description
from .joint import Joint
from .mimic import lock_followers

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = ["substitute", "lock", "lock_joints"]


def substitute(description: Description, mapping: Mapping) -> Description:
    """``description`` with the SymPy symbols of ``mapping`` (symbol -> value) replaced everywhere they
    may stand: joint axes, offsets and drive parameters, placements, inertias, frames, gravity and
    the DH table. A matrix left without symbols becomes a float array (the numeric engine's input)."""

    def f(v):
        if sympy_instance(v):
            out = v.subs(mapping)
            if sympy_instance(out, "MatrixBase"):
                return out if is_symbolic(out) else np.array(out.tolist(), dtype=float)
            return as_value(out)
        return v

    def drive(item) -> dict:
        return {
            k: f(getattr(item, k)) for k in ("gear_ratio", "rotor_inertia", "viscous", "coulomb", "coulomb_negative")
        }

    links = []
    for link in description.links:
        j = link.joint
        joint = dataclasses.replace(j, axis=tuple(f(a) for a in j.axis), offset=f(j.offset), **drive(j))
        try:
            inertia = link.inertia.subs(mapping)
        except ValueError as e:
            raise ValueError(f"robot '{description.name}', link '{link.name}': {e}") from None
        links.append(
            dataclasses.replace(link, joint=joint, placement=f(link.placement), post=f(link.post), inertia=inertia)
        )
    frames = [dataclasses.replace(fr, placement=f(fr.placement)) for fr in description.frames]
    dh = None
    if description.dh is not None:
        dh = [
            dataclasses.replace(
                r,
                theta=f(r.theta),
                d=f(r.d),
                a=f(r.a),
                alpha=f(r.alpha),
                inertia=r.inertia.subs(mapping),
                **drive(r),
            )
            for r in description.dh
        ]
    return dataclasses.replace(
        description,
        links=tuple(links),
        frames=tuple(frames),
        gravity=tuple(f(g) for g in description.gravity),
        dh=None if dh is None else tuple(dh),
    )


def lock(description: Description, values: Mapping) -> Description:
    """``description`` with the joints named in ``values`` made fixed: a 1-DOF joint at its value
    (a number: the motion by ``value + offset`` is folded into its placement), a multi-DOF joint at
    its 4x4 joint motion (folded the same way). The DH table is dropped (the links no longer follow it)."""
    links = []
    for link in description.links:
        j = link.joint
        if j.name in values and j.is_multi_dof:
            link = dataclasses.replace(
                link, joint=Joint(j.name, "fixed"), placement=matmul(link.placement, values[j.name])
            )
        elif j.name in values and j.is_moving:
            x = values[j.name] + j.offset
            motion = rot_axis(j.axis, x) if j.kind == "revolute" else translation(*(a * x for a in j.axis))
            link = dataclasses.replace(
                link, joint=Joint(j.name, "fixed", j.axis), placement=matmul(link.placement, motion)
            )
        links.append(link)
    reference = description.reference_configuration  # a locked joint is no longer a coordinate
    if reference is not None:
        reference = {name: v for name, v in reference.items() if name not in values}
    return dataclasses.replace(description, links=tuple(links), dh=None, reference_configuration=reference)


def lock_joints(description: Description, joints, at, block_motion) -> Description:
    """``Robot.lock_joints``: ``description`` with ``joints`` fixed (see :meth:`kinedyn.Robot.lock_joints`).

    ``joints``: a mapping ``{joint: value}`` or a sequence of joint names or indices locked at their
    value in the configuration ``at`` (nq,). ``block_motion(joint, block)``: the 4x4 motion of a
    multi-DOF joint at its block of q (the native model's convention, given by the caller).
    Reduced mimic followers are locked with their leader (:func:`kinedyn.description.mimic.lock_followers`).
    """
    names = description.joint_names
    n_joints = len(names)
    starts = np.cumsum([0] + [j.nq for j in description.joints])
    if isinstance(joints, (str, bytes)) or not hasattr(joints, "__iter__"):
        raise TypeError(
            f"lock_joints takes a mapping {{joint: value}} or a sequence of joint names or indices, got {joints!r}"
        )
    if isinstance(joints, Mapping):
        items = list(joints.items())
    else:
        q_at = real_array(at, "at")
        if q_at.shape != (description.nq,) or not np.all(np.isfinite(q_at)):
            raise ValueError(f"lock_joints: at must be {description.nq} finite joint values, got shape {q_at.shape}")
        items = [(j, None) for j in joints]
    followers = (
        {} if description.mimic_map is None else description.mimic_map.relations
    )  # reduced mimic followers: locked with their leader (description/mimic.py)
    unknown = sorted(str(key) for key, _ in items if isinstance(key, str) and key not in names and key not in followers)
    if unknown:
        raise ValueError(
            f"lock_joints: unknown joints {unknown}{did_you_mean(unknown[0], names + list(followers))} "
            f"(moving joints: {names + list(followers)})"
        )
    values: dict = {}
    follower_values: dict = {}
    for key, value in items:
        if isinstance(key, str) and key in followers:
            follower_values[key] = value
            continue
        if isinstance(key, str):
            i = names.index(key)
        elif isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if not -n_joints <= key < n_joints:
                raise ValueError(f"lock_joints: joint index {key} is out of range for {n_joints} joints")
            i = int(key) % n_joints
        else:
            raise TypeError(f"lock_joints: a joint is a name or an index, got {key!r}")
        if description.joints[i].is_multi_dof:
            block = q_at[starts[i] : starts[i + 1]] if value is None else value
            values[names[i]] = block_motion(description.joints[i], block)
            continue
        if value is None:
            value = q_at[starts[i]]
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"lock_joints: the value of joint '{names[i]}' must be a number, got {value!r}") from None
        if not math.isfinite(v):
            raise ValueError(f"lock_joints: the value of joint '{names[i]}' must be finite, got {v}")
        values[names[i]] = v
    if followers:
        values = lock_followers(followers, values, follower_values)
    return lock(description, values)
