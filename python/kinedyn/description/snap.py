"""Right angles a file wrote with a few digits, made exact: ``1.570796325`` -> pi/2.

Robot files write rotations as decimal roll-pitch-yaw angles (URDF's ``<origin rpy>``), and a right
angle written with eight or nine digits (UR5's ``1.570796325``) is 1.8e-9 rad short of pi/2. The
numeric engine does not care; a symbolic derivation does: cos(1.570796325) = 1.8e-9 is not zero, so
every product that should vanish survives as a term of 1e-12 and the printed equations grow by
hundreds of pages. :func:`snap_right_angles` reads each numeric rotation of a description (the joints'
placements and post-transforms, the extra frames) as URDF's fixed-axis angles R = Rz(yaw) Ry(pitch)
Rx(roll) (:func:`kinedyn._math.rpy_from_matrix`), moves every angle that lies within ``tol`` of a
multiple of pi/2 onto it, and rebuilds the rotation with the exact cosines and sines of those angles
(0, 1, -1 as floats, which the symbolic engine reads as exact integers). Each changed entry of a
rotation moves by at most ``3 tol`` (three angles, each rotation matrix 1-Lipschitz in its angle), so
the snapped model equals the file's to that tolerance; the report lists what moved.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .._math import is_symbolic, rpy_from_matrix
from .description import Description

__all__ = ["SNAP_TOLERANCE", "SnappedAngle", "snap_right_angles", "snap_rotation"]

#: the default: an angle within 1e-6 rad of a multiple of pi/2 is taken as that multiple (seven
#: printed digits of pi/2 are 3.3e-8 from it; a deliberate angle this close to a right angle is
#: below any manufacturing tolerance)
SNAP_TOLERANCE = 1e-6

_QUARTER = math.pi / 2
_RIGHT = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))  # (cos, sin) of k pi/2, k = 0..3


@dataclass(frozen=True)
class SnappedAngle:
    """One angle moved: ``where`` (the link or frame and which transform), ``axis`` ("roll", "pitch",
    "yaw"), the angle read from the file and the multiple of pi/2 it became (radians)."""

    where: str
    axis: str
    value: float
    snapped: float

    @property
    def change(self) -> float:
        return abs(self.value - self.snapped)


def _cos_sin(angle: float, tol: float) -> tuple[float, float, float]:
    """(cos, sin, angle) with the angle moved onto a multiple of pi/2 when within ``tol`` of one; then
    cos and sin are exactly 0 or +-1."""
    k = round(angle / _QUARTER)
    if abs(angle - k * _QUARTER) <= tol:
        c, s = _RIGHT[k % 4]
        return c, s, k * _QUARTER
    return math.cos(angle), math.sin(angle), angle


def _rzyx(yaw: tuple, pitch: tuple, roll: tuple) -> np.ndarray:
    (cy, sy), (cp, sp_), (cr, sr) = yaw, pitch, roll
    Rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    Ry = np.array([[cp, 0.0, sp_], [0.0, 1.0, 0.0], [-sp_, 0.0, cp]])
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return Rz @ Ry @ Rx


def snap_rotation(R, tol: float = SNAP_TOLERANCE) -> tuple[np.ndarray, list[tuple[str, float, float]]]:
    """(R', moved): the 3x3 rotation ``R`` with its roll, pitch and yaw angles within ``tol`` of a
    multiple of pi/2 put on it, and [(axis, angle, snapped angle)] for each angle that moved by more
    than rounding. Pitch is snapped first: at pitch = +-pi/2 (gimbal lock) only roll - yaw (or
    roll + yaw) is defined, so yaw is taken as 0 and that combination, read into roll, is snapped."""
    R = np.asarray(R, dtype=float)[:3, :3]
    roll, pitch, yaw = rpy_from_matrix(R)
    cp, sp_, pitch_s = _cos_sin(pitch, tol)
    if cp == 0.0:  # locked: R = Rz(yaw) Ry(+-pi/2) Rx(roll) depends on roll -+ yaw alone
        yaw = 0.0
    cy, sy, yaw_s = _cos_sin(yaw, tol)
    # roll from what remains, Rx(roll) = Ry(pitch)^T Rz(yaw)^T R, with the snapped pitch and yaw
    rest = _rzyx((cy, sy), (cp, sp_), (1.0, 0.0)).T @ R
    roll = math.atan2(rest[2, 1], rest[1, 1])
    cr, sr, roll_s = _cos_sin(roll, tol)
    out = _rzyx((cy, sy), (cp, sp_), (cr, sr))
    moved = [
        (axis, value, snapped)
        for axis, value, snapped in (("roll", roll, roll_s), ("pitch", pitch, pitch_s), ("yaw", yaw, yaw_s))
        if snapped != value and abs(value - snapped) > 4 * np.finfo(float).eps * max(1.0, abs(value))
    ]
    return out, moved


def _snap_pose(T, where: str, tol: float, moved: list[SnappedAngle]):
    """The 4x4 pose ``T`` with its rotation snapped (symbolic poses and poses with nothing to snap are
    returned as they are)."""
    if is_symbolic(T):
        return T
    T = np.asarray(T, dtype=float)
    R, angles = snap_rotation(T[:3, :3], tol)
    if np.array_equal(R, T[:3, :3]):
        return T
    if np.max(np.abs(R - T[:3, :3])) > 3 * tol + 1e-12:  # cannot happen for a rotation; never widen the change
        return T
    moved += [SnappedAngle(where, axis, value, snapped) for axis, value, snapped in angles]
    out = T.copy()
    out[:3, :3] = R
    return out


def snap_right_angles(description: Description, tol: float = SNAP_TOLERANCE) -> tuple[Description, list[SnappedAngle]]:
    """(description', moved): ``description`` with every numeric rotation's roll, pitch and yaw that
    lies within ``tol`` radians of a multiple of pi/2 put exactly on it (the module docstring), and the
    angles that moved. Inertias, axes and DH tables are kept as they are."""
    if not tol > 0:
        return description, []
    moved: list[SnappedAngle] = []
    links = []
    for link in description.links:
        placement = _snap_pose(link.placement, f"joint '{link.joint.name}' placement", tol, moved)
        post = _snap_pose(link.post, f"link '{link.name}' post-transform", tol, moved)
        links.append(
            link
            if placement is link.placement and post is link.post
            else dataclasses.replace(link, placement=placement, post=post)
        )
    frames = []
    for frame in description.frames:
        placement = _snap_pose(frame.placement, f"frame '{frame.name}' placement", tol, moved)
        frames.append(frame if placement is frame.placement else dataclasses.replace(frame, placement=placement))
    if not moved:
        return description, []
    return dataclasses.replace(description, links=tuple(links), frames=tuple(frames)), moved


def snap_note(moved: list[SnappedAngle], tol: float) -> str:
    """The sentence a document and the terminal print about the snapped angles ("" when none moved)."""
    if not moved:
        return ""
    largest = max(a.change for a in moved)
    n = len(moved)
    return (
        f"{n} angle{'s' if n != 1 else ''} of the robot's rotations within {tol:g} rad of a multiple of pi/2 "
        f"{'were' if n != 1 else 'was'} set to that multiple (largest change {largest:.2g} rad), so that terms "
        f"such as cos(pi/2) vanish exactly; the equations are those of this snapped model, whose rotation "
        f"entries differ from the file's by at most {3 * tol:g}."
    )
