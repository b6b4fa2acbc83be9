"""The core's errors as the messages users read: the core knows bodies by index, the user by name."""

from __future__ import annotations

from collections.abc import Callable

from .._core import NonFiniteResultError, SingularMassMatrixError

__all__ = ["SingularMassMatrixError", "singular_mass_matrix_error"]


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
