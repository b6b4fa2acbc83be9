"""Joints: the kind, the axis in the joint frame, the offset, limits and drive-train data.

A joint connects a parent link to a child link. Its frame sits at ``placement`` in the parent link's
frame (at q = 0); the joint moves the child by a rotation about / translation along ``axis`` by the
joint coordinate ``q + offset``. ``gear_ratio`` r and ``rotor_inertia`` J_m give the reflected rotor
inertia r^2 J_m on the diagonal of M (Spong §9.1's single link generalised); ``viscous`` and
``coulomb`` friction act at the joint: tau_f = viscous * qd + coulomb * sign(qd).

Coulomb friction may differ with the direction of motion (Corke's PUMA 560 motors have
``Tc = [Tc+, Tc-]`` per joint): ``coulomb_negative`` is the level (a magnitude, >= 0) for qd < 0,
``coulomb`` the level for qd > 0; then tau_f = viscous * qd + (coulomb if qd > 0, -coulomb_negative
if qd < 0, 0 at rest). ``coulomb=(positive, negative)`` is accepted as a shorthand for both levels.
Unset (None), ``coulomb_negative`` equals ``coulomb``: the symmetric case.

``mimic`` (a :class:`Mimic`, URDF's ``<mimic joint multiplier offset>``): this revolute or prismatic
joint follows another 1-DOF joint, its leader, with ``q = multiplier * q_leader + offset`` (both in
kinedyn's coordinates ``q``, before the joint's ``offset`` is added). Whether the robot removes the
follower's coordinate or keeps it independent is the Robot's choice (``Robot(..., mimic=...)``,
:mod:`kinedyn.description.mimic`); the joint only records the relation.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._core import planar_basis as core_planar_basis
from .._math import is_symbolic
from .checks import number, real, vector

__all__ = ["Joint", "Mimic", "JOINT_KINDS", "JOINT_SIZES", "MULTI_DOF_KINDS", "planar_basis"]

JOINT_KINDS = ("revolute", "prismatic", "fixed", "floating", "spherical", "planar")

#: Configuration and velocity sizes (nq, nv) of each kind (Pinocchio's conventions, docs/conventions.md):
#: floating (free-flyer): q = (x, y, z, qx, qy, qz, qw), v = [linear; angular] in the child's frame;
#: spherical: q = (qx, qy, qz, qw), v = angular velocity in the child's frame;
#: planar: q = (x, y, cos theta, sin theta) in the plane normal to ``axis``, v = (vx, vy, omega) in the
#: child's frame.
JOINT_SIZES = {
    "revolute": (1, 1),
    "prismatic": (1, 1),
    "fixed": (0, 0),
    "floating": (7, 6),
    "spherical": (4, 3),
    "planar": (4, 3),
}
MULTI_DOF_KINDS = ("floating", "spherical", "planar")


@dataclass(frozen=True)
class Mimic:
    """``q_follower = multiplier * q_leader + offset`` (URDF ``<mimic joint multiplier offset>``;
    the URDF defaults are multiplier 1, offset 0)."""

    leader: str
    multiplier: float = 1.0
    offset: float = 0.0

    def __post_init__(self):
        if not isinstance(self.leader, str) or not self.leader:
            raise ValueError(f"a mimic relation names its leader joint (a non-empty string), got {self.leader!r}")
        what = f"mimic of joint '{self.leader}'"
        multiplier = real(self.multiplier, f"{what}: multiplier")
        if multiplier == 0:
            raise ValueError(f"{what}: multiplier must be non-zero (a follower with multiplier 0 is a fixed joint)")
        object.__setattr__(self, "multiplier", multiplier)
        object.__setattr__(self, "offset", real(self.offset, f"{what}: offset"))

    @classmethod
    def of(cls, value) -> Mimic:
        """A Mimic from a Mimic, a mapping ``{leader (or joint), multiplier, offset}`` or a tuple
        ``(leader[, multiplier[, offset]])``."""
        if isinstance(value, Mimic):
            return value
        if isinstance(value, str):
            return cls(value)
        if isinstance(value, Mapping):
            unknown = sorted(set(value) - {"leader", "joint", "multiplier", "offset"})
            if unknown or ("leader" in value) == ("joint" in value):
                raise ValueError(
                    f"mimic must be a mapping with 'leader' (or 'joint'), optional 'multiplier' and 'offset'; got keys {sorted(value)}"
                )
            return cls(value.get("leader", value.get("joint")), value.get("multiplier", 1.0), value.get("offset", 0.0))
        if isinstance(value, (tuple, list)) and 1 <= len(value) <= 3:
            return cls(*value)
        raise ValueError(
            f"mimic must be a Mimic, a leader name, a mapping or a tuple (leader, multiplier, offset), got {value!r}"
        )

    def then(self, outer: Mimic) -> Mimic:
        """The relation of a follower of a follower: ``outer`` follows the joint this relation
        describes, which follows ``self.leader``; the result follows ``self.leader`` directly."""
        return Mimic(self.leader, outer.multiplier * self.multiplier, outer.multiplier * self.offset + outer.offset)


@dataclass(frozen=True)
class Joint:
    name: str
    kind: str = "revolute"  # "revolute" | "prismatic" | "fixed" | "floating" | "spherical" | "planar"
    axis: tuple = (0.0, 0.0, 1.0)
    offset: Any = 0.0
    lower: float = -math.inf
    upper: float = math.inf
    velocity_limit: float = math.inf
    effort_limit: float = math.inf
    gear_ratio: Any = 1.0
    rotor_inertia: Any = 0.0
    viscous: Any = 0.0
    coulomb: Any = 0.0
    #: Coulomb level for qd < 0 (magnitude); None = the same as ``coulomb`` (symmetric friction)
    coulomb_negative: Any = None
    #: this joint follows another (URDF <mimic>): q = multiplier * q_leader + offset; None = independent
    mimic: Mimic | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"a joint's name must be a non-empty string, got {self.name!r}")
        what = f"joint '{self.name}'"
        if self.kind == "continuous":
            object.__setattr__(self, "kind", "revolute")
        if self.kind not in JOINT_KINDS:
            raise ValueError(f"{what}: unknown kind '{self.kind}' (expected one of {JOINT_KINDS})")
        axis = vector(self.axis, 3, f"{what}: axis")
        if not is_symbolic(axis):
            norm = math.sqrt(sum(a * a for a in axis))
            if norm < 1e-12:
                if self.kind != "fixed":
                    raise ValueError(f"{what}: axis {axis} has zero or non-finite length")
            else:
                axis = tuple(a / norm for a in axis)
        object.__setattr__(self, "axis", axis)
        # coulomb=(positive, negative): the two levels of direction-dependent Coulomb friction
        if isinstance(self.coulomb, (tuple, list)):
            if len(self.coulomb) != 2:
                raise ValueError(
                    f"{what}: coulomb must be one level or a pair (positive, negative) of levels, got {list(self.coulomb)!r}"
                )
            if self.coulomb_negative is not None:
                raise ValueError(
                    f"{what}: give the negative-direction Coulomb level once, as coulomb=(positive, negative) or coulomb_negative=..."
                )
            positive, negative = self.coulomb
            object.__setattr__(self, "coulomb", positive)
            object.__setattr__(self, "coulomb_negative", negative)
        # offset, drive train and friction: numbers (checked: real, finite, sane size) or symbols
        for name in ("offset", "gear_ratio", "rotor_inertia", "viscous", "coulomb"):
            object.__setattr__(self, name, number(getattr(self, name), f"{what}: {name}"))
        if not is_symbolic(self.gear_ratio) and self.gear_ratio == 0:
            raise ValueError(f"{what}: gear_ratio must be non-zero")
        if self.coulomb_negative is not None:
            object.__setattr__(self, "coulomb_negative", number(self.coulomb_negative, f"{what}: coulomb_negative"))
            if self.coulomb_negative == self.coulomb:  # one description of symmetric friction
                object.__setattr__(self, "coulomb_negative", None)
        for name in ("rotor_inertia", "viscous", "coulomb", "coulomb_negative"):
            v = getattr(self, name)
            if v is not None and not is_symbolic(v) and v < 0:
                hint = ""
                if name == "coulomb_negative":
                    hint = (
                        " (a level, not a signed torque: Corke's Tc = [Tc+, Tc-] with Tc- < 0 is coulomb=(Tc+, -Tc-))"
                    )
                raise ValueError(f"{what}: {name} must be >= 0, got {v}{hint}")
        if self.is_multi_dof:
            # a multi-DOF joint has one scalar of each per degree of freedom in no file format kinedyn
            # reads; refusing them beats silently applying one number to 3 or 6 coordinates
            for name, default in (("offset", 0), ("rotor_inertia", 0), ("viscous", 0), ("coulomb", 0)):
                if getattr(self, name) != default:
                    raise ValueError(f"{what}: a {self.kind} joint takes no {name} (got {getattr(self, name)})")
            if self.coulomb_negative is not None:
                raise ValueError(f"{what}: a {self.kind} joint takes no coulomb_negative")
        if self.mimic is not None:
            mimic = Mimic.of(self.mimic)
            if self.kind not in ("revolute", "prismatic"):
                raise ValueError(
                    f"{what}: only a revolute or prismatic joint can mimic another; this one is {self.kind}"
                )
            if mimic.leader == self.name:
                raise ValueError(f"{what}: a joint cannot mimic itself")
            object.__setattr__(self, "mimic", mimic)
        # limits: numbers, +-inf allowed (no limit), never NaN
        for name in ("lower", "upper", "velocity_limit", "effort_limit"):
            object.__setattr__(self, name, real(getattr(self, name), f"{what}: {name}", infinite=True))
        if self.lower > self.upper:
            raise ValueError(f"{what}: lower limit {self.lower} exceeds upper limit {self.upper}")
        if self.lower == math.inf or self.upper == -math.inf:
            raise ValueError(f"{what}: limits [{self.lower}, {self.upper}] admit no position")
        for name in ("velocity_limit", "effort_limit"):
            if getattr(self, name) < 0:
                raise ValueError(f"{what}: {name} is negative")

    @property
    def coulomb_levels(self) -> tuple:
        """(level for qd > 0, level for qd < 0), both >= 0; equal for symmetric friction."""
        return (self.coulomb, self.coulomb if self.coulomb_negative is None else self.coulomb_negative)

    @property
    def coulomb_is_symmetric(self) -> bool:
        return self.coulomb_negative is None or self.coulomb_negative == self.coulomb

    def coulomb_torque(self, qd, convert=None):
        """The Coulomb friction torque at joint rate ``qd``: a number for a number, or a SymPy
        expression in the symbol ``qd``, written with ``sign`` only so that every printer and code
        generator takes it: ``c sign(qd)`` when symmetric, else
        ``(c+ + c-)/2 sign(qd) + (c+ - c-)/2 sign(qd)^2`` (= c+ for qd > 0, -c- for qd < 0, 0 at
        rest). ``convert``: applied to each level first (the symbolic engine's exact numbers)."""
        positive, negative = self.coulomb_levels
        if not (is_symbolic(qd) or is_symbolic(positive) or is_symbolic(negative)):
            return positive if qd > 0 else (-negative if qd < 0 else 0.0)
        import sympy as sp

        if convert is not None:
            positive, negative = convert(positive), convert(negative)
        s = sp.sign(qd)
        if self.coulomb_is_symmetric:
            return positive * s
        return (positive + negative) / 2 * s + (positive - negative) / 2 * s**2

    @property
    def is_moving(self) -> bool:
        return self.kind != "fixed"

    @property
    def nq(self) -> int:
        """Number of configuration coordinates (7 floating, 4 spherical and planar, 1, 0 fixed)."""
        return JOINT_SIZES[self.kind][0]

    @property
    def nv(self) -> int:
        """Number of velocity coordinates, the joint's degrees of freedom (6, 3, 3, 1, 0 fixed)."""
        return JOINT_SIZES[self.kind][1]

    @property
    def is_multi_dof(self) -> bool:
        return self.kind in MULTI_DOF_KINDS

    @property
    def armature(self):
        """Reflected rotor inertia r^2 J_m added to M[i, i]."""
        return self.gear_ratio**2 * self.rotor_inertia


def planar_basis(normal) -> tuple:
    """The in-plane unit axes (e1, e2) of a planar joint with unit ``normal`` (its axis), e1 x e2 =
    normal: x and y for the normal z (Pinocchio's JointModelPlanar), else e1 along the coordinate axis
    most orthogonal to the normal, projected into the plane. The planar joint's q = (x, y, cos, sin)
    moves along x e1 + y e2 (docs/conventions.md). Computed by the core (``joint::planar_basis``), so
    the description, the compiled model and the viewer agree to the bit."""
    e1, e2 = core_planar_basis(np.asarray(normal, dtype=float))
    return np.array(e1), np.array(e2)
