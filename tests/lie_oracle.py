"""The NumPy Lie-group operations kinedyn used before its configuration space called the core's
(crates/kinedyn-core/src/lie.rs, ``kinedyn._core.lie_integrate`` / ``lie_difference``), kept as a
test oracle: unit quaternions (SO(3)), SE(3) for a free-flyer, SE(2) for a planar joint, vectorised
over batches.

Sources of the formulas (derived again here, not transcribed): Solà, Deray & Atchuthan, "A micro Lie
theory for state estimation in robotics" (2018), §§ 4–5 and appendices A–C; Murray, Li & Sastry,
*A Mathematical Introduction to Robotic Manipulation* (1994), §2.3 eq. 2.36 and Prop. 2.9."""

from __future__ import annotations

import math

import numpy as np

# the quaternion helpers kinedyn.lie still keeps (public, NumPy; not the core code under test)
from kinedyn.lie import exp3, log3, quaternion_multiply, quaternion_rotate, vector_norm

__all__ = [
    "log3",
    "quaternion_multiply",
    "difference_floating",
    "difference_planar",
    "integrate_floating",
    "integrate_planar",
    "integrate_rotation",
]

_SERIES_BELOW = 1e-2  # below this angle, series instead of closed forms that cancel
_B_SERIES = [(-1) ** k / math.factorial(2 * k + 3) for k in range(7, -1, -1)]


def _log3_with_angle(quat: np.ndarray) -> tuple:
    omega = log3(quat)
    return omega, vector_norm(omega)


def _theta_minus_sin_over_cube(theta: np.ndarray) -> np.ndarray:
    """(θ - sin θ)/θ³: the closed form loses digits as ε/θ², so below θ = 0.5 its series
    Σ (-1)ᵏ θ²ᵏ/(2k+3)! (8 terms; the first omitted is below 1e-21)."""
    near = theta < 0.5
    t = np.where(near, 1.0, theta)
    return np.where(near, np.polyval(_B_SERIES, theta * theta), (t - np.sin(t)) / (t * t * t))


def _se3_left_jacobian_times(omega: np.ndarray, theta: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """V(ω) ρ = ρ + (1 - cos θ)/θ² ω × ρ + (θ - sin θ)/θ³ ω × (ω × ρ) (Solà et al. eq. 174;
    Murray, Li & Sastry eq. 2.36)."""
    a = 0.5 * np.sinc(theta / (2 * np.pi)) ** 2  # (1 - cos θ)/θ² = 2 sin²(θ/2)/θ²
    b = _theta_minus_sin_over_cube(theta)
    wxr = np.cross(omega, rho)
    return rho + a[..., None] * wxr + b[..., None] * np.cross(omega, wxr)


def _se3_left_jacobian_inverse_times(omega: np.ndarray, theta: np.ndarray, p: np.ndarray) -> np.ndarray:
    """V(ω)⁻¹ p = p - ½ ω × p + (1 - (θ/2) cot(θ/2))/θ² ω × (ω × p) (Solà et al. eq. 175 inverted in
    closed form: V⁻¹ is a polynomial of degree 2 in [ω]× since [ω]×³ = -θ² [ω]×). For θ in [0, π]."""
    small = theta < _SERIES_BELOW
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    half = t / 2
    c = np.where(small, 1 / 12 + t2 / 720 + t2 * t2 / 30240, (1.0 - half * np.cos(half) / np.sin(half)) / (t * t))
    wxp = np.cross(omega, p)
    return p - 0.5 * wxp + c[..., None] * np.cross(omega, wxp)


# ---------------------------------------------------------------------------------- per joint kind
def integrate_rotation(quat0: np.ndarray, omega: np.ndarray, same_hemisphere: bool = False) -> np.ndarray:
    """quat0 ⊗ Exp(ω), normalised. Either sign is the same rotation; the one returned is Pinocchio's:
    for a free-flyer the quaternion in quat0's hemisphere (``same_hemisphere``), for a spherical
    joint the product itself (w = cos(θ/2) < 0 past θ = π)."""
    quat = quaternion_multiply(quat0, exp3(omega))
    if same_hemisphere:
        flip = np.sum(quat * quat0, axis=-1, keepdims=True) < 0
        quat = np.where(flip, -quat, quat)
    return quat / vector_norm(quat)[..., None]


def integrate_floating(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    # M(q) Exp(v): p1 = p0 + R0 V(ω) ρ, R1 = R0 Exp(ω)  (v = [ρ; ω], both in the child's frame)
    p0, quat0, rho, omega = q[..., :3], q[..., 3:], v[..., :3], v[..., 3:]
    theta = vector_norm(omega)
    p1 = p0 + quaternion_rotate(quat0, _se3_left_jacobian_times(omega, theta, rho))
    return np.concatenate([p1, integrate_rotation(quat0, omega, same_hemisphere=True)], axis=-1)


def difference_floating(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    # Log(M0⁻¹ M1): rotation R0ᵀ R1 = conj(quat0) ⊗ quat1, translation R0ᵀ (p1 - p0)
    quat0_inverse = q0[..., 3:] * np.array([-1.0, -1.0, -1.0, 1.0])
    omega, theta = _log3_with_angle(quaternion_multiply(quat0_inverse, q1[..., 3:]))
    p = quaternion_rotate(quat0_inverse, q1[..., :3] - q0[..., :3])
    return np.concatenate([_se3_left_jacobian_inverse_times(omega, theta, p), omega], axis=-1)


def integrate_planar(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    # M(q) Exp(v) in SE(2): t = V(θ) (vx, vy), V = [[A, -B], [B, A]], A = sin θ/θ, B = (1 - cos θ)/θ
    # (Solà et al. eqs. 156-158); p1 = p0 + R0 t, (c1, s1) = R0 (cos θ, sin θ)
    c0, s0, theta = q[..., 2], q[..., 3], v[..., 2]
    a = np.sinc(theta / np.pi)
    b = 0.5 * theta * np.sinc(theta / (2 * np.pi)) ** 2
    tx = a * v[..., 0] - b * v[..., 1]
    ty = b * v[..., 0] + a * v[..., 1]
    ct, st = np.cos(theta), np.sin(theta)
    c1, s1 = c0 * ct - s0 * st, s0 * ct + c0 * st
    n = np.sqrt(c1 * c1 + s1 * s1)
    return np.stack([q[..., 0] + c0 * tx - s0 * ty, q[..., 1] + s0 * tx + c0 * ty, c1 / n, s1 / n], axis=-1)


def difference_planar(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    # Log(M0⁻¹ M1) in SE(2): θ = atan2 of the relative rotation, (vx, vy) = V(θ)⁻¹ R0ᵀ (p1 - p0) with
    # V⁻¹ = [[α, θ/2], [-θ/2, α]], α = (θ/2) cot(θ/2) = cos(θ/2) / sinc(θ/2): no cancellation, θ in (-π, π]
    c0, s0, c1, s1 = q0[..., 2], q0[..., 3], q1[..., 2], q1[..., 3]
    theta = np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
    dx, dy = q1[..., 0] - q0[..., 0], q1[..., 1] - q0[..., 1]
    px, py = c0 * dx + s0 * dy, -s0 * dx + c0 * dy
    alpha = np.cos(theta / 2) / np.sinc(theta / (2 * np.pi))
    return np.stack([alpha * px + theta / 2 * py, -theta / 2 * px + alpha * py, theta], axis=-1)
