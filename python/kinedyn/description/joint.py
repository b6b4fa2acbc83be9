"""Joints: the kind, the axis in the joint frame, the offset, limits and drive-train data.

A joint connects a parent link to a child link. Its frame sits at ``placement`` in the parent link's
frame (at q = 0); the joint moves the child by a rotation about / translation along ``axis`` by the
joint coordinate ``q + offset``. ``gear_ratio`` r and ``rotor_inertia`` J_m give the reflected rotor
inertia r^2 J_m on the diagonal of M (Spong §9.1's single link generalised); ``viscous`` and
``coulomb`` friction act at the joint: tau_f = viscous * qd + coulomb * sign(qd).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .._math import is_symbolic
from .checks import number, real, vector

__all__ = ["Joint", "JOINT_KINDS"]

JOINT_KINDS = ("revolute", "prismatic", "fixed")


@dataclass(frozen=True)
class Joint:
    name: str
    kind: str = "revolute"  # "revolute" | "prismatic" | "fixed"
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
        # offset, drive train and friction: numbers (checked: real, finite, sane size) or symbols
        for name in ("offset", "gear_ratio", "rotor_inertia", "viscous", "coulomb"):
            object.__setattr__(self, name, number(getattr(self, name), f"{what}: {name}"))
        if not is_symbolic(self.gear_ratio) and self.gear_ratio == 0:
            raise ValueError(f"{what}: gear_ratio must be non-zero")
        for name in ("rotor_inertia", "viscous", "coulomb"):
            v = getattr(self, name)
            if not is_symbolic(v) and v < 0:
                raise ValueError(f"{what}: {name} must be >= 0, got {v}")
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
    def is_moving(self) -> bool:
        return self.kind != "fixed"

    @property
    def armature(self):
        """Reflected rotor inertia r^2 J_m added to M[i, i]."""
        return self.gear_ratio**2 * self.rotor_inertia
