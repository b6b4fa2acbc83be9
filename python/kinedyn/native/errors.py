"""The core's errors as the messages users read: the core knows bodies by index, the user by name."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from .._core import NonFiniteResultError, SingularMassMatrixError

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["SingularMassMatrixError", "dof_label", "nonphysical_note", "robot_error", "singular_mass_matrix_error"]


def _name_first(message: str, joint: int, label: str) -> str:
    """``message`` with ``label`` after its first ``joint <joint>`` (not ``joint <joint>0``)."""
    token = f"joint {joint}"
    start = 0
    while (at := message.find(token, start)) >= 0:
        end = at + len(token)
        if (at == 0 or not message[at - 1].isalnum()) and (end == len(message) or not message[end].isdigit()):
            return f"{message[:end]} {label}{message[end:]}"
        start = end
    return message


def singular_mass_matrix_error(
    error: SingularMassMatrixError, robot: str, label: Callable[[int], str | None], note: Callable[[int], str]
) -> Exception:
    """The user's error for the core's ``SingularMassMatrixError``: the joint named (``label(joint)``,
    e.g. ``('elbow', moving body 'forearm')``, None when it has no name) and the robot's note on it
    (``note(joint)``, '' when none); a NonFiniteResultError (a ValueError) when the core found
    numbers too large for float64 (finite inputs that overflowed on the way), else a RuntimeError."""
    message = str(error)
    named = label(error.joint)
    if named is not None:
        message = _name_first(message, error.joint, named)
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
        lambda dof: nonphysical_note(robot, int(robot._dof_body[dof])),
    )


def dof_label(robot: Robot, dof: int) -> str | None:
    """How a message names the native body (a degree of freedom) ``dof``: its link's joint and body."""
    if not 0 <= dof < robot.n:
        return None
    i = int(robot._dof_body[dof])
    return f"('{robot.joint_names[i]}', moving body '{robot.body_names[i]}')"


def nonphysical_note(robot: Robot, joint: int) -> str:
    """For a singular-mass-matrix error at ``joint``: the links it moves whose inertia is not
    positive semi-definite (kept by inertia='warn'), which can make its D <= 0; else ''."""
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
