"""The core's errors as the messages users read: the core knows bodies by index, the user by name."""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .._core import NonFiniteResultError, SingularMassMatrixError
from .compile import dof_links

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["SingularMassMatrixError", "dof_label", "nonphysical_note", "robot_error", "singular_mass_matrix_error"]


def _name_joints(message: str, joint: int, name: str, body: str | None) -> str:
    """``message`` (the core's, which counts joints from 0) with every ``joint <joint>`` (not
    ``joint <joint>0``) replaced by the joint's name, the first followed by its moving body: a
    0-based number beside a 1-based name ("joint 2 ('q3')") reads as two different joints."""
    pattern = re.compile(rf"(?<![\w]){re.escape(f'joint {joint}')}(?!\d)")
    first = f"joint '{name}'" + (f" (moving body '{body}')" if body is not None else "")
    message, count = pattern.subn(first, message, count=1)
    if not count:  # the message does not name the joint: say which it is
        return f"{first}: {message}"
    return pattern.sub(f"joint '{name}'", message)


def singular_mass_matrix_error(
    error: SingularMassMatrixError,
    robot: str,
    label: Callable[[int], tuple[str, str] | None],
    note: Callable[[int], str],
) -> Exception:
    """The user's error for the core's ``SingularMassMatrixError``: the joint named (``label(joint)``,
    its name and moving body ``('elbow', 'forearm')``, None when it has none) and the robot's note on it
    (``note(joint)``, '' when none); a NonFiniteResultError (a ValueError) when the core found
    numbers too large for float64 (finite inputs that overflowed on the way), else a RuntimeError."""
    message = str(error)
    named = label(error.joint)
    if named is not None:
        message = _name_joints(message, error.joint, *named)
    if error.overflow:
        return NonFiniteResultError(f"robot '{robot}': {message}")
    if named is not None:
        message += note(error.joint)
    return RuntimeError(f"robot '{robot}': {message}")


def robot_error(robot: Robot, error: RuntimeError) -> Exception:
    """The core's singular-mass-matrix error with the joint's name added
    (:func:`kinedyn.native.singular_mass_matrix_error`); other RuntimeErrors unchanged."""
    if not isinstance(error, SingularMassMatrixError):
        return error
    return singular_mass_matrix_error(
        error,
        robot.name,
        lambda dof: dof_label(robot, dof),
        lambda dof: nonphysical_note(robot, int(dof_links(robot.description)[dof])),
    )


def dof_label(robot: Robot, dof: int) -> tuple[str, str] | None:
    """How a message names the native body (a degree of freedom) ``dof``: its link's joint and body."""
    if not 0 <= dof < robot.n:
        return None
    i = int(dof_links(robot.description)[dof])
    return robot.joint_names[i], robot.body_names[i]


def nonphysical_note(robot: Robot, joint: int) -> str:
    """For a singular-mass-matrix error at ``joint``: the links it moves whose inertia is not
    positive semi-definite (kept by inertia='warn'), which can make its D <= 0; else ''."""
    if not np.any(robot.inertial_parameters()) and not np.any(robot.armature):
        return (
            f"; robot '{robot.name}' has no mass or inertia on any link (M = 0): give its links inertias "
            "(Robot.from_dh: DHRow(..., inertia=kd.Inertia(...)))"
        )
    subtree, parents = {joint}, robot.parents
    for i in range(joint + 1, len(robot.tree.bodies)):  # parent[i] < i
        if parents[i] in subtree:
            subtree.add(i)
    bad = [
        f"link '{f.name}' ({robot.nonphysical[f.name].describe()})"
        for f in robot.tree.frames
        if f.body in subtree and f.name in robot.nonphysical and not robot.nonphysical[f.name].positive
    ]
    if not bad:
        return ""
    return (
        f"; the bodies it moves include inertias no rigid body has, kept by inertia='warn': "
        f"{', '.join(bad)}; load the robot with inertia='repair'"
    )
