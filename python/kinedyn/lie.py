"""The core's Lie-group helpers (crates/kinedyn-core/src/lie.rs and lie/jacobians.rs) on NumPy arrays,
vectorised over batches: the quaternion operations of SO(3) and the Jacobians of each joint kind's
group that :mod:`kinedyn.configuration` offers (``integrate`` and ``difference`` themselves are
``kinedyn._core.lie_integrate`` / ``lie_difference``, their Jacobians ``lie_integrate_jacobians`` /
``lie_difference_jacobians``). The NumPy versions they replaced are the test oracle
tests/lie_oracle.py.

Quaternions are (x, y, z, w); arguments broadcast against each other as NumPy's do. Sources: Solà,
Deray & Atchuthan, "A micro Lie theory for state estimation in robotics" (2018), §§ 4–5 and
appendices A–C (the core's modules cite the equations)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._core import lie_group_jacobians, lie_quaternion

if TYPE_CHECKING:
    from ._typing import ArrayLike

__all__ = [
    "quaternion_multiply",
    "quaternion_rotate",
    "quaternion_to_matrix",
    "exp3",
    "log3",
    "block_jacobians",
    "vector_norm",
]


def _quaternion(op: str, *arrays: ArrayLike, widths: tuple) -> np.ndarray:
    """``lie_quaternion(op, ...)`` of float arrays broadcast over their leading axes."""
    a = [np.asarray(x, dtype=float) for x in arrays]
    for x, w in zip(a, widths):
        if x.ndim == 0 or x.shape[-1] != w:
            raise ValueError(f"{op}: expected arrays of {widths} numbers along the last axis, got shape {x.shape}")
    lead = np.broadcast_shapes(*(x.shape[:-1] for x in a))
    a = [np.ascontiguousarray(np.broadcast_to(x, lead + x.shape[-1:])) for x in a]
    return lie_quaternion(op, *a)


def quaternion_multiply(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Hamilton product a ⊗ b of quaternions (x, y, z, w): R(a ⊗ b) = R(a) R(b) (Solà et al. eq. 107)."""
    return _quaternion("multiply", a, b, widths=(4, 4))


def quaternion_rotate(quat: ArrayLike, p: ArrayLike) -> np.ndarray:
    """R(quat) p for a unit quaternion (x, y, z, w): p + 2w (u × p) + 2 u × (u × p), u the vector part."""
    return _quaternion("rotate", quat, p, widths=(4, 3))


def quaternion_to_matrix(quat: ArrayLike) -> np.ndarray:
    """The rotation matrix (..., 3, 3) of unit quaternions (..., 4) in (x, y, z, w) order."""
    return _quaternion("matrix", quat, widths=(4,))


def vector_norm(x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.sum(x * x, axis=-1))


def exp3(omega: ArrayLike) -> np.ndarray:
    """The unit quaternion of the rotation vector ω: (sin(θ/2) ω/θ, cos(θ/2)), θ = |ω| (Solà et al.
    eq. 101), exact at θ = 0."""
    return _quaternion("exp", omega, widths=(3,))


def log3(quat: ArrayLike) -> np.ndarray:
    """The rotation vector ω in [0, π] of a quaternion (x, y, z, w), the inverse of :func:`exp3`
    (Solà et al. eq. 105, taking w >= 0 so that q and -q give the same, short, rotation)."""
    return _quaternion("log", quat, widths=(4,))


def block_jacobians(kind: str, v: np.ndarray) -> tuple:
    """(Ad(Exp(v)), Jl(v), Jl(v)⁻¹) of one joint kind's group ("floating", "spherical", "planar") at
    its tangent vectors v (..., nv): the core's ``GroupJacobians`` (crates/kinedyn-core/src/lie/jacobians.rs)."""
    return tuple(lie_group_jacobians(kind, np.ascontiguousarray(v, dtype=float)))
