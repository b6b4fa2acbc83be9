"""Editing a description: new descriptions with symbols substituted or joints locked.

``Robot.subs`` and ``Robot.lock_joints`` read their arguments (names, indices, configurations) and
call these; every field not named is carried over by ``dataclasses.replace``, so a field added to
``Joint``, ``DHRow`` or ``Description`` later is kept without touching this module.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np
import sympy as sp

from .._math import as_value, is_symbolic, matmul, rot_axis, translation
from .description import Description
from .joint import Joint

__all__ = ["substitute", "lock"]


def substitute(description: Description, mapping: Mapping) -> Description:
    """``description`` with the SymPy symbols of ``mapping`` (symbol -> value) replaced everywhere they
    may stand: joint axes, offsets and drive parameters, placements, inertias, frames, gravity and
    the DH table. A matrix left without symbols becomes a float array (the numeric engine's input)."""

    def f(v):
        if isinstance(v, (sp.Basic, sp.MatrixBase)):
            out = v.subs(mapping)
            if isinstance(out, sp.MatrixBase):
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
        description, links=links, frames=frames, gravity=tuple(f(g) for g in description.gravity), dh=dh
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
    return dataclasses.replace(description, links=links, dh=None)
