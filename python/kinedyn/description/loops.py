"""Closed kinematic loops: a constraint that closes the tree between two of its frames.

A robot description is a tree; a loop (a four-bar's coupler pinned to its rocker, a Delta robot's
forearm on its platform, a push-rod on a leg) is a constraint between two frames of that tree,
each fixed to a link. Two kinds, named as MuJoCo names its equalities:

- ``"point"``: the two frames' origins coincide (3 rows; MJCF ``<connect>``, a spherical pin);
- ``"weld"``: the two frames coincide, origin and axes (6 rows; MJCF ``<weld>``).

A reader that closes a loop at an anchor point adds a frame at that point on each side, so that the
constraint is always "these two frames coincide" (origins only for a point). LaValle, Planning
Algorithms, section 13.4 (holonomic constraints with Lagrange multipliers).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .._ui.names import did_you_mean

__all__ = ["LOOP_KINDS", "Loop", "check_loops", "check_reference"]

# kind -> constraint rows (translation; translation and rotation)
LOOP_KINDS = {"point": 3, "weld": 6}


@dataclass(frozen=True, repr=False)
class Loop:
    """A closure between the frames ``frame_a`` and ``frame_b`` (names in ``robot.frame_names``)."""

    name: str
    frame_a: str
    frame_b: str
    kind: str = "point"

    def __post_init__(self) -> None:
        for field_name in ("name", "frame_a", "frame_b"):
            value = getattr(self, field_name)
            if not isinstance(value, str) or not value:
                raise ValueError(f"loop {self.name!r}: {field_name} must be a non-empty string, got {value!r}")
        if self.kind not in LOOP_KINDS:
            raise ValueError(
                f"loop '{self.name}': kind must be one of {sorted(LOOP_KINDS)}, got {self.kind!r}"
                f"{did_you_mean(str(self.kind), list(LOOP_KINDS))}"
            )
        if self.frame_a == self.frame_b:
            raise ValueError(f"loop '{self.name}' closes frame '{self.frame_a}' on itself")

    def __repr__(self) -> str:  # one line a reader takes in at a glance (robot.loops prints a tuple of these)
        return f"Loop({self.name!r}: {self.frame_a} meets {self.frame_b}, {self.kind}, {self.rows} rows)"

    @property
    def rows(self) -> int:
        """Number of constraint rows: 3 for a point, 6 for a weld."""
        return LOOP_KINDS[self.kind]


def check_loops(loops, frame_names, robot: str) -> tuple:
    """``loops`` as a tuple of :class:`Loop`, each naming two frames of the robot, names unique."""
    out, seen = [], set()
    for loop in loops:
        if not isinstance(loop, Loop):
            raise ValueError(f"robot '{robot}': a loop must be a Loop, got {type(loop).__name__}")
        if loop.name in seen:
            raise ValueError(f"robot '{robot}': two loops are named '{loop.name}'")
        seen.add(loop.name)
        for frame in (loop.frame_a, loop.frame_b):
            if frame not in frame_names:
                raise ValueError(
                    f"robot '{robot}', loop '{loop.name}': unknown frame '{frame}'{did_you_mean(frame, frame_names)}"
                )
        out.append(loop)
    return tuple(out)


def check_reference(reference, joints, robot: str) -> dict | None:
    """``reference`` (a mapping joint name -> value, or None) as a dict of floats: a number for a 1-DOF
    joint, a tuple of its nq numbers (its block of q) for a multi-DOF one. The reference configuration
    is where the robot's loops close on the branch it is assembled in (a closed mechanism's assembly
    mode: MuJoCo's ``qpos0``); ``joints``: the moving joints of the tree."""
    if reference is None:
        return None
    if not hasattr(reference, "items"):
        raise ValueError(
            f"robot '{robot}': reference_configuration must map joint names to values, got {type(reference).__name__}"
        )
    by_name = {j.name: j for j in joints}
    out: dict = {}
    for name, value in reference.items():
        joint = by_name.get(name)
        if joint is None:
            names = list(by_name)
            raise ValueError(
                f"robot '{robot}': reference_configuration names joint '{name}', which is no moving joint"
                f"{did_you_mean(str(name), names)} (moving joints: {names})"
            )
        values = value if isinstance(value, (list, tuple)) else (value,)
        if len(values) != joint.nq or any(isinstance(v, bool) for v in values):
            raise ValueError(
                f"robot '{robot}': reference_configuration of joint '{name}' ({joint.kind}) needs {joint.nq} "
                f"number{'s' * (joint.nq > 1)} (its block of q), got {value!r}"
            )
        try:
            numbers = tuple(float(v) for v in values)
        except (TypeError, ValueError):
            raise ValueError(
                f"robot '{robot}': reference_configuration of joint '{name}' must be numbers, got {value!r}"
            ) from None
        if not all(math.isfinite(v) for v in numbers):
            raise ValueError(f"robot '{robot}': reference_configuration of joint '{name}' is not finite: {value!r}")
        out[name] = numbers[0] if joint.nq == 1 else numbers
    return out
