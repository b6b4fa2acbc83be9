"""Small math helpers that work on plain numbers (NumPy) and on SymPy expressions alike.

A robot description may hold SymPy symbols; these helpers return a ``sympy.Matrix`` when any
input is symbolic and a float ``numpy.ndarray`` otherwise, so the description code is written once.
Poses are 4x4 homogeneous transforms ``a_from_b`` (a point in b's coordinates -> a's coordinates).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from ._lazy import LazyModule, sympy_instance
from .expressions import parse_expression

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = [
    "is_symbolic",
    "as_value",
    "identity",
    "rot_x",
    "rot_y",
    "rot_z",
    "rot_axis",
    "rpy_to_matrix",
    "rpy_from_matrix",
    "translation",
    "homogeneous",
    "pose_inverse",
    "matmul",
    "to_float_array",
    "by_name",
]


def is_symbolic(*values: Any) -> bool:
    """True if any value (scalar, sequence, array or matrix) contains a non-numeric SymPy expression."""
    for v in values:
        if sympy_instance(v, "MatrixBase"):
            if any(not e.is_number for e in v):
                return True
        elif sympy_instance(v, "Basic"):
            if not v.is_number:
                return True
        elif isinstance(v, np.ndarray):
            if v.dtype == object and any(is_symbolic(e) for e in v.flat):
                return True
        elif isinstance(v, (list, tuple)):
            if any(is_symbolic(e) for e in v):
                return True
    return False


def as_value(x: Any) -> Any:
    """A scalar as a float when it is a plain number, else as a SymPy expression."""
    if sympy_instance(x, "Basic"):
        return float(x) if x.is_number and x.is_real is not False and not x.free_symbols else x
    if isinstance(x, str):  # read as data by kinedyn's own parser, never evaluated as Python
        return parse_expression(x)
    return float(x)


def _has_sympy(v: Any) -> bool:
    if sympy_instance(v):
        return True
    if isinstance(v, (list, tuple)):
        return any(_has_sympy(e) for e in v)
    return False


def _module(*values: Any):
    """SymPy for symbols and for exact SymPy numbers (pi / 2 stays exact), NumPy otherwise."""
    return sp if any(_has_sympy(v) for v in values) else np


def identity():
    return np.eye(4)


def _hom(R, p, symbolic: bool):
    if symbolic:
        T = sp.eye(4)
        T[:3, :3] = sp.Matrix(R)
        T[:3, 3] = sp.Matrix(p)
        return T
    T = np.eye(4)
    T[:3, :3] = np.asarray(R, dtype=float)
    T[:3, 3] = np.asarray(p, dtype=float)
    return T


def rot_x(angle):
    m = _module(angle)
    c, s = m.cos(angle), m.sin(angle)
    return _hom([[1, 0, 0], [0, c, -s], [0, s, c]], [0, 0, 0], m is sp)


def rot_y(angle):
    m = _module(angle)
    c, s = m.cos(angle), m.sin(angle)
    return _hom([[c, 0, s], [0, 1, 0], [-s, 0, c]], [0, 0, 0], m is sp)


def rot_z(angle):
    m = _module(angle)
    c, s = m.cos(angle), m.sin(angle)
    return _hom([[c, -s, 0], [s, c, 0], [0, 0, 1]], [0, 0, 0], m is sp)


def rot_axis(axis: Iterable, angle):
    """Rotation by ``angle`` about the unit vector ``axis`` (Rodrigues' formula), as a 4x4 pose."""
    axis = list(axis)
    m = _module(angle, axis)
    x, y, z = axis
    c, s = m.cos(angle), m.sin(angle)
    v = 1 - c
    R = [
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ]
    return _hom(R, [0, 0, 0], m is sp)


def rpy_to_matrix(roll, pitch, yaw):
    """URDF's fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll), as a 4x4 pose."""
    return matmul(rot_z(yaw), rot_y(pitch), rot_x(roll))


def rpy_from_matrix(R) -> tuple[float, float, float]:
    """The inverse of :func:`rpy_to_matrix`: URDF's (roll, pitch, yaw) with R = Rz(yaw) Ry(pitch)
    Rx(roll), pitch in [-pi/2, pi/2], for a numeric rotation (3x3, or the rotation of a 4x4 pose).

    Pitch is read from the first column, (cos p cos y, cos p sin y, -sin p): its z and its length,
    which is well conditioned everywhere. Yaw is the direction of that column's (x, y) part, exact
    however short it is; at gimbal lock (cos p = 0) only yaw + roll (or yaw - roll) is defined, and
    the choice made is yaw = 0. Roll is then read off the rotation that remains,
    Rx(roll) = Ry(p)^T Rz(y)^T R, rather than from R's last row, so a yaw that rounding made
    uncertain near the lock is compensated by roll, and Rz Ry Rx reproduces R to rounding."""
    R = np.asarray(R, dtype=float)[:3, :3]
    cos_pitch = math.hypot(R[0, 0], R[1, 0])
    pitch = math.atan2(-R[2, 0], cos_pitch)
    yaw = math.atan2(R[1, 0], R[0, 0]) if cos_pitch > 0.0 else 0.0
    cy, sy, cp, sp_ = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    Rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    Ry = np.array([[cp, 0.0, sp_], [0.0, 1.0, 0.0], [-sp_, 0.0, cp]])
    Rx = Ry.T @ Rz.T @ R
    roll = math.atan2(Rx[2, 1], Rx[1, 1])
    return (roll + 0.0, pitch + 0.0, yaw + 0.0)  # + 0.0: no -0.0 in what is printed or written


def translation(x, y, z):
    symbolic = is_symbolic(x, y, z)
    return _hom(np.eye(3) if not symbolic else sp.eye(3), [x, y, z], symbolic)


def homogeneous(R, p):
    return _hom(R, p, is_symbolic(R, p))


def matmul(*poses):
    """Product of 4x4 poses; symbolic if any factor is."""
    if is_symbolic(*poses):
        out = sp.eye(4)
        for T in poses:
            out = out * sp.Matrix(T)
        return out
    out = np.eye(4)
    for T in poses:
        out = out @ np.asarray(T, dtype=float)
    return out


def pose_inverse(T):
    """Inverse of a 4x4 rigid transform: [R^T, -R^T p]."""
    if is_symbolic(T):
        T = sp.Matrix(T)
        R = T[:3, :3]
        return _hom(R.T, -R.T * T[:3, 3], True)
    T = np.asarray(T, dtype=float)
    R = T[:3, :3]
    return _hom(R.T, -R.T @ T[:3, 3], False)


def to_float_array(value, shape=None, what: str = "value") -> np.ndarray:
    """Convert numbers / numeric SymPy matrices to a float array; explain when symbols remain."""
    if is_symbolic(value):
        free = set()
        for e in value if sympy_instance(value, "MatrixBase") else np.asarray(value, dtype=object).flat:
            if sympy_instance(e, "Basic"):
                free |= e.free_symbols
        raise ValueError(
            f"{what} contains SymPy symbols {sorted(map(str, free))}; substitute numbers first "
            f"(robot.subs({{...}})) before numeric computation"
        )
    if sympy_instance(value, "MatrixBase"):
        value = np.array(value.tolist(), dtype=float)
    arr = np.asarray(value, dtype=float)
    if shape is not None and arr.shape != tuple(shape):
        raise ValueError(f"{what} must have shape {tuple(shape)}, got {arr.shape}")
    return arr


def by_name(mapping, symbols) -> dict:
    """``{symbol: value}`` from a mapping keyed by SymPy symbols or by names. A name is matched to the
    symbol of that name among ``symbols`` whatever its assumptions (``"m1"`` finds
    ``Symbol("m1", positive=True)``, which ``Symbol("m1")`` would not equal); other names become plain
    symbols. A value given as text is read by kinedyn's expression parser (SymPy's ``subs`` would
    hand it to ``eval``)."""
    named = {s.name: s for s in symbols if sympy_instance(s, "Symbol")}
    return {
        (named.get(k, sp.Symbol(k)) if isinstance(k, str) else k): (as_value(v) if isinstance(v, str) else v)
        for k, v in dict(mapping).items()
    }
