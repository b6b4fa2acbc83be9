"""Configuration spaces: ``q`` (length nq) and velocities ``v`` (length nv) of joints that are not
plain angles, and the operations that replace ``q + v dt`` and ``q1 - q0`` on them.

Conventions (Pinocchio's, so that numbers move between the two unchanged; docs/conventions.md):
``q`` is the joints' blocks in body order (``robot.tree.bodies``), ``v`` likewise;

| kind | q block | v block | q ⊕ v |
|------|---------|---------|-------|
| revolute, prismatic | the angle / displacement (1) | its rate (1) | q + v |
| spherical | unit quaternion (qx, qy, qz, qw) (4) | angular velocity, child frame (3) | R(q) Exp(ω) |
| floating | (x, y, z, qx, qy, qz, qw) (7) | [linear; angular], child frame (6) | M(q) Exp(v) in SE(3) |
| planar | (x, y, cos θ, sin θ) (4) | (vx, vy, ω), child frame (3) | M(q) Exp(v) in SE(2) |

``integrate(q, v, dt) = q ⊕ (v dt)`` multiplies the joint's pose by the group exponential on the
right (the velocity is expressed in the moving frame), ``difference(q0, q1) = Log(M(q0)⁻¹ M(q1))``
is its inverse: ``difference(q0, integrate(q0, v)) == v`` for every rotation angle |ω| < π.

Sources of the formulas (derived again here, not transcribed): Solà, Deray & Atchuthan, "A micro Lie
theory for state estimation in robotics" (2018), §§ 4–5 and appendices A–C (SO(3) by quaternions,
SE(2), SE(3), their left Jacobians V); Murray, Li & Sastry, *A Mathematical Introduction to Robotic
Manipulation* (1994), §2.3 eq. 2.36 (the exponential of a twist) and Prop. 2.9; Shoemake, "Uniform
random rotations", *Graphics Gems III* (1992) for random quaternions.

Everything here is NumPy and vectorised: ``q`` may be (nq,) or a batch (..., nq), ``v`` (nv,) or
(..., nv), broadcast against each other. Nothing needs the native core.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .description.joint import Joint

if TYPE_CHECKING:
    from ._typing import ArrayLike, SeedLike
    from .robot import Robot

__all__ = [
    "ConfigurationSpace",
    "UNIT_TOLERANCE",
    "space",
    "neutral",
    "integrate",
    "difference",
    "interpolate",
    "random_configuration",
    "normalize",
    "check_configuration",
    "default_configuration",
    "integrate_jacobians",
    "difference_jacobians",
    "quaternion_multiply",
    "quaternion_rotate",
    "quaternion_to_matrix",
    "exp3",
    "log3",
    "COORDINATE_NAMES",
]

#: How far from 1 the norm of a quaternion or of a planar joint's (cos θ, sin θ) may be before
#: :func:`check_configuration` refuses it (normalise with :func:`normalize` / ``robot.normalize(q)``).
UNIT_TOLERANCE = 1e-6

# below this rotation angle the series of (1 - (θ/2)cot(θ/2))/θ² replaces the closed form, whose
# error ε/θ² there multiplies θ²; at 1e-2 the first omitted term of the series is below 1e-17
_SERIES_BELOW = 1e-2

_Q_NAMES = {
    "revolute": ("angle",),
    "prismatic": ("displacement",),
    "spherical": ("qx", "qy", "qz", "qw"),
    "floating": ("x", "y", "z", "qx", "qy", "qz", "qw"),
    "planar": ("x", "y", "cos theta", "sin theta"),
}
#: The names of a joint kind's q coordinates, in order (docs/conventions.md).
COORDINATE_NAMES = _Q_NAMES


# ----------------------------------------------------------------------------- SO(3) by quaternions
def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        axis=-1,
    )


def quaternion_multiply(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Hamilton product a ⊗ b of quaternions (x, y, z, w): R(a ⊗ b) = R(a) R(b) (Solà et al. eq. 107)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    av, aw, bv, bw = a[..., :3], a[..., 3:], b[..., :3], b[..., 3:]
    # (a_v, a_w)(b_v, b_w) = (a_w b_v + b_w a_v + a_v × b_v, a_w b_w - a_v · b_v)
    vec = aw * bv + bw * av + _cross(av, bv)
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([vec, w], axis=-1)


def quaternion_rotate(quat: ArrayLike, p: ArrayLike) -> np.ndarray:
    """R(quat) p for a unit quaternion (x, y, z, w): p + 2w (u × p) + 2 u × (u × p), u the vector part."""
    quat, p = np.asarray(quat, dtype=float), np.asarray(p, dtype=float)
    u, w = quat[..., :3], quat[..., 3:]
    t = 2.0 * _cross(u, p)
    return p + w * t + _cross(u, t)


def quaternion_to_matrix(quat: ArrayLike) -> np.ndarray:
    """The rotation matrix (..., 3, 3) of unit quaternions (..., 4) in (x, y, z, w) order."""
    quat = np.asarray(quat, dtype=float)
    x, y, z, w = (quat[..., i] for i in range(4))
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def _norm(x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.sum(x * x, axis=-1))


def exp3(omega: ArrayLike) -> np.ndarray:
    """The unit quaternion of the rotation vector ω: (sin(θ/2) ω/θ, cos(θ/2)), θ = |ω| (Solà et al.
    eq. 101). sin(θ/2)/θ is computed as sinc, exact at θ = 0."""
    omega = np.asarray(omega, dtype=float)
    theta = _norm(omega)
    half_sinc = 0.5 * np.sinc(theta / (2 * np.pi))  # sin(θ/2)/θ
    return np.concatenate([half_sinc[..., None] * omega, np.cos(theta / 2)[..., None]], axis=-1)


def _log3_with_angle(quat: np.ndarray) -> tuple:
    # q and -q are the same rotation: take the representative with w >= 0, so θ = 2 atan2(|u|, w) lies in
    # [0, π] (the short way). atan2 keeps every digit near θ = π, where w -> 0 and acos would lose them.
    sign = np.where(quat[..., 3] < 0, -1.0, 1.0)[..., None]
    u, w = sign * quat[..., :3], sign[..., 0] * quat[..., 3]
    n = _norm(u)
    theta = 2.0 * np.arctan2(n, w)
    # ω = θ u/|u|; at |u| = 0 the limit of 2 atan2(n, w)/n is 2/w
    safe_n = np.where(n > 0, n, 1.0)
    factor = np.where(n > 0, theta / safe_n, 2.0 / np.where(w > 0, w, 1.0))
    return factor[..., None] * u, theta


def log3(quat: ArrayLike) -> np.ndarray:
    """The rotation vector ω in [0, π] of a quaternion (x, y, z, w), the inverse of :func:`exp3`
    (Solà et al. eq. 105, taking w >= 0 so that q and -q give the same, short, rotation)."""
    return _log3_with_angle(np.asarray(quat, dtype=float))[0]


# ------------------------------------------------------------------- left Jacobians V of SE(3), SE(2)
# the series of (θ - sin θ)/θ³ in θ², highest power first (for np.polyval)
_B_SERIES = [(-1) ** k / math.factorial(2 * k + 3) for k in range(7, -1, -1)]


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
    wxr = _cross(omega, rho)
    return rho + a[..., None] * wxr + b[..., None] * _cross(omega, wxr)


def _se3_left_jacobian_inverse_times(omega: np.ndarray, theta: np.ndarray, p: np.ndarray) -> np.ndarray:
    """V(ω)⁻¹ p = p - ½ ω × p + (1 - (θ/2) cot(θ/2))/θ² ω × (ω × p) (Solà et al. eq. 175 inverted in
    closed form: V⁻¹ is a polynomial of degree 2 in [ω]× since [ω]×³ = -θ² [ω]×). For θ in [0, π]."""
    small = theta < _SERIES_BELOW
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    half = t / 2
    c = np.where(small, 1 / 12 + t2 / 720 + t2 * t2 / 30240, (1.0 - half * np.cos(half) / np.sin(half)) / (t * t))
    wxp = _cross(omega, p)
    return p - 0.5 * wxp + c[..., None] * _cross(omega, wxp)


# ------------------------------------------------------------- Jacobians of integrate, difference
# Perturbations act on the right, as velocities do: q ⊕ δ. With the group's adjoint Ad and its right
# Jacobian Jr(τ) (Exp(τ + δ) ≈ Exp(τ) Exp(Jr(τ) δ)), and Jl(τ) = Jr(-τ) = Σ ad_τᵏ/(k+1)!:
#   ∂(q ⊕ v)/∂q = Ad(Exp(v))⁻¹ = Ad(Exp(-v)),   ∂(q ⊕ v)/∂v = Jr(v) = Jl(-v);
#   ∂Log(q0⁻¹ q1)/∂q1 = Jr⁻¹(d) = Jl⁻¹(-d),     ∂Log(q0⁻¹ q1)/∂q0 = -Jl⁻¹(d)     (d = the difference)
# (Solà, Deray & Atchuthan 2018, eqs. 72-81). Jl of SE(3) and SE(2) is a function of the block
# upper-triangular matrix ad_τ, so its off-diagonal block is the Fréchet derivative of that function
# (Higham, *Functions of Matrices*, 2008, Thm 3.6 / eq. 3.16): for SE(3), ad = [[ω×, ρ×], [0, ω×]] and
# Q(ρ, ω) = D Jl_SO(3)(ω)[ρ], the derivative of SO(3)'s Jl = I + a W + b W² along ρ (W = ω×).
def _skew(w: np.ndarray) -> np.ndarray:
    z = np.zeros(w.shape[:-1])
    return np.stack(
        [
            np.stack([z, -w[..., 2], w[..., 1]], -1),
            np.stack([w[..., 2], z, -w[..., 0]], -1),
            np.stack([-w[..., 1], w[..., 0], z], -1),
        ],
        -2,
    )


# coefficients of the series of a'(θ)/θ and b'(θ)/θ in θ², highest power first (for np.polyval)
_DA_SERIES = [(-1) ** k * 2 * k / math.factorial(2 * k + 2) for k in range(8, 0, -1)]
_DB_SERIES = [(-1) ** k * 2 * k / math.factorial(2 * k + 3) for k in range(8, 0, -1)]


def _so3_coefficients(theta: np.ndarray) -> tuple:
    """a = (1 - cos θ)/θ², b = (θ - sin θ)/θ³, c = (1 - (θ/2) cot(θ/2))/θ², and a'(θ)/θ, b'(θ)/θ,
    each by its Taylor series below 1e-2 where the closed form cancels."""
    small = theta < _SERIES_BELOW
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    a = 0.5 * np.sinc(theta / (2 * np.pi)) ** 2
    b = _theta_minus_sin_over_cube(theta)
    half = t / 2
    c = np.where(small, 1 / 12 + t2 / 720 + t2 * t2 / 30240, (1.0 - half * np.cos(half) / np.sin(half)) / (t * t))
    # a' = sin θ/θ² - 2(1 - cos θ)/θ³, b' = (1 - cos θ)/θ³ - 3(θ - sin θ)/θ⁴: their closed forms lose
    # digits as ε/θ, so below θ = 0.5 the series (k >= 1, 8 terms, the first omitted < 1e-18)
    # a'/θ = Σ (-1)ᵏ 2k θ²⁽ᵏ⁻¹⁾/(2k+2)!,  b'/θ = Σ (-1)ᵏ 2k θ²⁽ᵏ⁻¹⁾/(2k+3)!
    near = theta < 0.5
    u = np.where(near, 1.0, theta)
    one_minus_cos = 2 * np.sin(u / 2) ** 2
    da = np.where(near, np.polyval(_DA_SERIES, t2), (u * np.sin(u) - 2 * one_minus_cos) / u**4)
    db = np.where(near, np.polyval(_DB_SERIES, t2), (u * one_minus_cos - 3 * (u - np.sin(u))) / u**5)
    return a, b, c, da, db


def _so3_left_jacobian(omega: np.ndarray) -> tuple:
    """Jl(ω) = I + a W + b W², Jl(ω)⁻¹ = I - ½ W + c W², and the coefficients."""
    theta = _norm(omega)
    a, b, c, da, db = _so3_coefficients(theta)
    w = _skew(omega)
    w2 = w @ w
    eye = np.eye(3)
    jl = eye + a[..., None, None] * w + b[..., None, None] * w2
    jl_inv = eye - 0.5 * w + c[..., None, None] * w2
    return jl, jl_inv, (a, b, da, db, w, w2)


def _se3_left_jacobian(tau: np.ndarray) -> tuple:
    """Jl(τ) and Jl(τ)⁻¹ (6x6) of SE(3), τ = [ρ; ω]: [[Jl(ω), Q], [0, Jl(ω)]] with
    Q = (ω·ρ)(a'/θ) W + a P + (ω·ρ)(b'/θ) W² + b (P W + W P), P = ρ×."""
    rho, omega = tau[..., :3], tau[..., 3:]
    jl, jl_inv, (a, b, da, db, w, w2) = _so3_left_jacobian(omega)
    p = _skew(rho)
    dot = np.sum(omega * rho, axis=-1)
    e = lambda x: x[..., None, None]  # noqa: E731 - a scalar per state against 3x3 blocks
    q = e(dot * da) * w + e(a) * p + e(dot * db) * w2 + e(b) * (p @ w + w @ p)
    out = np.zeros(tau.shape[:-1] + (6, 6))
    out[..., :3, :3] = out[..., 3:, 3:] = jl
    out[..., :3, 3:] = q
    inv = np.zeros_like(out)
    inv[..., :3, :3] = inv[..., 3:, 3:] = jl_inv
    inv[..., :3, 3:] = -jl_inv @ q @ jl_inv
    return out, inv


def _se3_adjoint_of_exp(tau: np.ndarray) -> np.ndarray:
    """Ad(Exp(τ)) = [[R, p× R], [0, R]] for Exp(τ) = (R, p), in the [linear; angular] order."""
    rho, omega = tau[..., :3], tau[..., 3:]
    r = quaternion_to_matrix(exp3(omega))
    p = _se3_left_jacobian_times(omega, _norm(omega), rho)
    out = np.zeros(tau.shape[:-1] + (6, 6))
    out[..., :3, :3] = out[..., 3:, 3:] = r
    out[..., :3, 3:] = _skew(p) @ r
    return out


def _se2_left_jacobian(tau: np.ndarray) -> tuple:
    """Jl(τ) and its inverse (3x3) of SE(2), τ = (ρ, θ): ad = [[θ J, -J ρ], [0, 0]] (J the 90° rotation),
    so Jl = [[V(θ), h(θ J)(-J ρ)], [0, 1]] with h(x) = (eˣ - 1 - x)/x²: the top right is
    (θ - sin θ)/θ² ρ - (1 - cos θ)/θ² J ρ."""
    theta = tau[..., 2]
    a = np.sinc(theta / np.pi)  # sin θ/θ
    half = 0.5 * np.sinc(theta / (2 * np.pi)) ** 2  # (1 - cos θ)/θ²
    b = half * theta  # (1 - cos θ)/θ
    d = theta * _theta_minus_sin_over_cube(np.abs(theta))  # (θ - sin θ)/θ²
    rx, ry = tau[..., 0], tau[..., 1]
    corner = np.stack([d * rx + half * ry, d * ry - half * rx], axis=-1)  # J ρ = (-ρy, ρx)
    out = np.zeros(tau.shape[:-1] + (3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = a, -b, b, a
    out[..., :2, 2] = corner
    out[..., 2, 2] = 1.0
    alpha = np.cos(theta / 2) / np.sinc(theta / (2 * np.pi))  # V⁻¹ = [[α, θ/2], [-θ/2, α]]
    inv = np.zeros_like(out)
    inv[..., 0, 0], inv[..., 0, 1], inv[..., 1, 0], inv[..., 1, 1] = alpha, theta / 2, -theta / 2, alpha
    inv[..., :2, 2] = -np.einsum("...ij,...j->...i", inv[..., :2, :2], corner)
    inv[..., 2, 2] = 1.0
    return out, inv


def _se2_adjoint_of_exp(tau: np.ndarray) -> np.ndarray:
    """Ad(Exp(τ)) = [[R, (t_y, -t_x)ᵀ], [0, 1]] for Exp(τ) = (R, t) in SE(2)."""
    m = np.stack([np.zeros_like(tau[..., 0])] * 2 + [np.ones_like(tau[..., 0]), np.zeros_like(tau[..., 0])], axis=-1)
    m = _integrate_planar(m, tau)
    out = np.zeros(tau.shape[:-1] + (3, 3))
    c, s = m[..., 2], m[..., 3]
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 0, 2], out[..., 1, 2] = m[..., 1], -m[..., 0]
    out[..., 2, 2] = 1.0
    return out


def _block_jacobians(kind: str, v: np.ndarray) -> tuple:
    """(Ad(Exp(v)), Jl(v), Jl(v)⁻¹) of one joint kind's group at its tangent vector v."""
    if kind == "floating":
        jl, inv = _se3_left_jacobian(v)
        return _se3_adjoint_of_exp(v), jl, inv
    if kind == "spherical":
        jl, inv, _ = _so3_left_jacobian(v)
        return quaternion_to_matrix(exp3(v)), jl, inv
    jl, inv = _se2_left_jacobian(v)
    return _se2_adjoint_of_exp(v), jl, inv


# ---------------------------------------------------------------------------------- per joint kind
def _integrate_rotation(quat0: np.ndarray, omega: np.ndarray, same_hemisphere: bool = False) -> np.ndarray:
    """quat0 ⊗ Exp(ω), normalised. Either sign is the same rotation; the one returned is Pinocchio's:
    for a free-flyer the quaternion in quat0's hemisphere (``same_hemisphere``), for a spherical
    joint the product itself (w = cos(θ/2) < 0 past θ = π)."""
    quat = quaternion_multiply(quat0, exp3(omega))
    if same_hemisphere:
        flip = np.sum(quat * quat0, axis=-1, keepdims=True) < 0
        quat = np.where(flip, -quat, quat)
    return quat / _norm(quat)[..., None]


def _integrate_floating(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    # M(q) Exp(v): p1 = p0 + R0 V(ω) ρ, R1 = R0 Exp(ω)  (v = [ρ; ω], both in the child's frame)
    p0, quat0, rho, omega = q[..., :3], q[..., 3:], v[..., :3], v[..., 3:]
    theta = _norm(omega)
    p1 = p0 + quaternion_rotate(quat0, _se3_left_jacobian_times(omega, theta, rho))
    return np.concatenate([p1, _integrate_rotation(quat0, omega, same_hemisphere=True)], axis=-1)


def _difference_floating(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    # Log(M0⁻¹ M1): rotation R0ᵀ R1 = conj(quat0) ⊗ quat1, translation R0ᵀ (p1 - p0)
    quat0_inverse = q0[..., 3:] * np.array([-1.0, -1.0, -1.0, 1.0])
    omega, theta = _log3_with_angle(quaternion_multiply(quat0_inverse, q1[..., 3:]))
    p = quaternion_rotate(quat0_inverse, q1[..., :3] - q0[..., :3])
    return np.concatenate([_se3_left_jacobian_inverse_times(omega, theta, p), omega], axis=-1)


def _integrate_planar(q: np.ndarray, v: np.ndarray) -> np.ndarray:
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


def _difference_planar(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    # Log(M0⁻¹ M1) in SE(2): θ = atan2 of the relative rotation, (vx, vy) = V(θ)⁻¹ R0ᵀ (p1 - p0) with
    # V⁻¹ = [[α, θ/2], [-θ/2, α]], α = (θ/2) cot(θ/2) = cos(θ/2) / sinc(θ/2): no cancellation, θ in (-π, π]
    c0, s0, c1, s1 = q0[..., 2], q0[..., 3], q1[..., 2], q1[..., 3]
    theta = np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
    dx, dy = q1[..., 0] - q0[..., 0], q1[..., 1] - q0[..., 1]
    px, py = c0 * dx + s0 * dy, -s0 * dx + c0 * dy
    alpha = np.cos(theta / 2) / np.sinc(theta / (2 * np.pi))
    return np.stack([alpha * px + theta / 2 * py, -theta / 2 * px + alpha * py, theta], axis=-1)


# -------------------------------------------------------------------------------- the whole space
@dataclass(frozen=True)
class _Block:
    joint: Joint
    iq: int  # first index of the joint's block in q
    iv: int  # first index of the joint's block in v


def _indices(blocks, kind: str, size: int, attr: str) -> np.ndarray:
    return np.array(
        [[getattr(b, attr) + k for k in range(size)] for b in blocks if b.joint.kind == kind], dtype=np.intp
    ).reshape(-1, size)


class ConfigurationSpace:
    """The configuration space of a sequence of moving joints (a robot's, in body order): sizes, and
    every operation vectorised over the joints of one kind and over a batch of states."""

    def __init__(self, joints: Sequence[Joint]):
        blocks, iq, iv = [], 0, 0
        for joint in joints:
            if not isinstance(joint, Joint):
                raise ValueError(f"a configuration space is made of Joint objects, got {type(joint).__name__}")
            if joint.kind == "fixed":
                continue
            blocks.append(_Block(joint, iq, iv))
            iq, iv = iq + joint.nq, iv + joint.nv
        self.blocks: tuple = tuple(blocks)
        self.nq, self.nv = iq, iv
        self._scalar_q = np.array([b.iq for b in blocks if b.joint.nq == 1], dtype=np.intp)
        self._scalar_v = np.array([b.iv for b in blocks if b.joint.nv == 1], dtype=np.intp)
        self._kinds = {}  # kind -> (q indices (k, nq), v indices (k, nv)) for the multi-DOF kinds present
        for kind in ("floating", "spherical", "planar"):
            nq, nv = {"floating": (7, 6), "spherical": (4, 3), "planar": (4, 3)}[kind]
            qi = _indices(blocks, kind, nq, "iq")
            if len(qi):
                self._kinds[kind] = (qi, _indices(blocks, kind, nv, "iv"))
        # where the unit-norm parts sit: quaternions (k, 4) and planar (cos, sin) pairs (k, 2), with their joints
        self._unit_parts = []
        for b in blocks:
            if b.joint.kind in ("floating", "spherical"):
                start = b.iq + (3 if b.joint.kind == "floating" else 0)
                self._unit_parts.append((b, np.arange(start, start + 4), "quaternion"))
            elif b.joint.kind == "planar":
                self._unit_parts.append((b, np.arange(b.iq + 2, b.iq + 4), "(cos theta, sin theta) pair"))

    @classmethod
    def of(cls, robot: Robot) -> ConfigurationSpace:
        """The configuration space of ``robot`` (built once per robot and remembered)."""
        found = _SPACES.get(robot)
        if found is None:
            found = _SPACES[robot] = cls(list(robot.joints))  # the coordinates' joints (no reduced mimic followers)
        return found

    # ------------------------------------------------------------------------------ arguments
    def _array(self, x, size: int, name: str, what: str) -> np.ndarray:
        try:
            a = np.asarray(x)
            if a.dtype.kind not in "fiubO":  # complex numbers would lose their imaginary part, text is no number
                raise TypeError(f"an array of dtype {a.dtype}")
            a = a.astype(float, copy=False)
        except (TypeError, ValueError) as e:
            raise TypeError(f"{name} must be real numbers, got {e}") from None
        if a.ndim == 0 or a.shape[-1] != size:
            raise ValueError(f"{name} must have {size} entries ({what}) along its last axis, got shape {a.shape}")
        return a

    def _velocity(self, v, name: str = "v") -> np.ndarray:
        a = self._array(v, self.nv, name, "nv: one per degree of freedom")
        if not np.all(np.isfinite(a)):
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
            raise ValueError(f"{name}{list(bad)} is {a[bad]}: a velocity must be finite")
        return a

    def check(self, q, name: str = "q") -> np.ndarray:
        """``q`` as a float array after the checks of :func:`check_configuration`."""
        a = self._array(q, self.nq, name, "nq: a free-flyer takes 7, a spherical or planar joint 4")
        if not np.all(np.isfinite(a)):
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
            raise ValueError(
                f"{name}{list(bad)} ({self._describe(bad[-1])}) is {a[bad]}: a configuration must be finite{self._at(bad[:-1])}"
            )
        for block, columns, what in self._unit_parts:
            norm = _norm(a[..., columns])
            off = np.abs(norm - 1.0) > UNIT_TOLERANCE
            if np.any(off):
                state = tuple(int(i) for i in np.argwhere(np.atleast_1d(off))[0]) if a.ndim > 1 else ()
                values = a[state + (slice(None),)][columns] if a.ndim > 1 else a[columns]
                joint = block.joint
                names = ", ".join(_Q_NAMES[joint.kind][i - block.iq] for i in columns)
                raise ValueError(
                    f"{name}[{columns[0]}:{columns[-1] + 1}] of {joint.kind} joint '{joint.name}' is the {what} "
                    f"({names}) = {tuple(float(x) for x in values)} of norm {float(np.sqrt(np.sum(values**2))):.9g}, not 1 to within "
                    f"{UNIT_TOLERANCE:g}{self._at(state)}: normalise it (robot.normalize(q) divides each by its norm"
                    + ("; q and -q are the same rotation" if what == "quaternion" else "")
                    + ")"
                )
        return a

    def _describe(self, index: int) -> str:
        for b in self.blocks:
            if b.iq <= index < b.iq + b.joint.nq:
                return f"{_Q_NAMES[b.joint.kind][index - b.iq]} of {b.joint.kind} joint '{b.joint.name}'"
        return "?"

    @staticmethod
    def _at(state: tuple) -> str:
        if not state:
            return ""
        return f" at state {state[0] if len(state) == 1 else state} of the batch"

    # ------------------------------------------------------------------------------ operations
    def neutral(self) -> np.ndarray:
        """The identity of every joint: zeros, quaternions (0, 0, 0, 1), planar (0, 0, 1, 0)."""
        q = np.zeros(self.nq)
        for b in self.blocks:
            if b.joint.kind == "floating":
                q[b.iq + 6] = 1.0
            elif b.joint.kind == "spherical":
                q[b.iq + 3] = 1.0
            elif b.joint.kind == "planar":
                q[b.iq + 2] = 1.0
        return q

    def integrate(self, q, v, dt=1.0) -> np.ndarray:
        """q ⊕ (v dt): each joint's pose times the exponential of its velocity (module docstring)."""
        q = self.check(q)
        v = self._velocity(v)
        dt = np.asarray(dt, dtype=float)
        if not np.all(np.isfinite(dt)):
            raise ValueError(f"dt must be finite, got {dt}")
        vdt = v * (dt[..., None] if dt.ndim else dt)
        shape = np.broadcast_shapes(q.shape[:-1], vdt.shape[:-1])
        q = np.broadcast_to(q, shape + (self.nq,))
        vdt = np.broadcast_to(vdt, shape + (self.nv,))
        out = np.array(q, dtype=float)
        # 1-DOF joints: q + v dt
        out[..., self._scalar_q] = q[..., self._scalar_q] + vdt[..., self._scalar_v]
        step: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {
            "floating": _integrate_floating,
            "spherical": _integrate_rotation,
            "planar": _integrate_planar,
        }
        for kind, (qi, vi) in self._kinds.items():
            out[..., qi] = step[kind](q[..., qi], vdt[..., vi])
        return out

    def difference(self, q0, q1) -> np.ndarray:
        """v with q0 ⊕ v = q1: Log(M(q0)⁻¹ M(q1)) per joint, q1 - q0 for 1-DOF joints; rotations the
        short way (angle in [0, π]; q and -q are the same rotation)."""
        q0, q1 = self.check(q0, "q0"), self.check(q1, "q1")
        shape = np.broadcast_shapes(q0.shape[:-1], q1.shape[:-1])
        q0 = np.broadcast_to(q0, shape + (self.nq,))
        q1 = np.broadcast_to(q1, shape + (self.nq,))
        out = np.empty(shape + (self.nv,))
        out[..., self._scalar_v] = q1[..., self._scalar_q] - q0[..., self._scalar_q]
        for kind, (qi, vi) in self._kinds.items():
            a, b = q0[..., qi], q1[..., qi]
            if kind == "floating":
                out[..., vi] = _difference_floating(a, b)
            elif kind == "spherical":
                conj = a * np.array([-1.0, -1.0, -1.0, 1.0])
                out[..., vi] = log3(quaternion_multiply(conj, b))
            else:
                out[..., vi] = _difference_planar(a, b)
        return out

    def interpolate(self, q0, q1, t) -> np.ndarray:
        """q0 ⊕ t · difference(q0, q1): the geodesic from q0 (t = 0) to q1 (t = 1) in each joint's group;
        ``t`` a number or an array of them (one configuration each). t = 1 returns q1 itself."""
        t = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(t)):
            raise ValueError(f"t must be finite, got {t}")
        q0, q1 = self.check(q0, "q0"), self.check(q1, "q1")
        tv = t[..., None]
        out = self.integrate(q0, tv * self.difference(q0, q1))
        # at t = 1 exactly, q1 (not -q1's quaternion sign, nor its last rounding)
        return np.where(tv == 1.0, np.broadcast_to(q1, out.shape), out)

    def integrate_jacobians(self, q, v, dt=1.0) -> tuple:
        """(∂(q ⊕ v dt)/∂q, ∂(q ⊕ v dt)/∂v), each (nv, nv) or (..., nv, nv), in the tangent spaces
        (perturbations on the right, as Pinocchio's ``dIntegrate`` ARG0 and ARG1): block diagonal,
        Ad(Exp(v dt))⁻¹ and Jr(v dt) dt per multi-DOF joint, 1 and dt for 1-DOF joints."""
        q = self.check(q)
        v = self._velocity(v)
        dt = np.asarray(dt, dtype=float)
        if dt.ndim or not np.isfinite(dt):
            raise ValueError(f"dt must be one finite number, got {dt}")
        vdt = np.asarray(v * dt)
        shape = np.broadcast_shapes(q.shape[:-1], vdt.shape[:-1])
        vdt = np.broadcast_to(vdt, shape + (self.nv,))
        d_q = np.zeros(shape + (self.nv, self.nv))
        d_v = np.zeros(shape + (self.nv, self.nv))
        d_q[..., self._scalar_v, self._scalar_v] = 1.0
        d_v[..., self._scalar_v, self._scalar_v] = float(dt)
        for kind, (_, vi) in self._kinds.items():
            for cols in vi:
                ad, jl, _ = _block_jacobians(kind, -vdt[..., cols])
                d_q[..., cols[:, None], cols[None, :]] = ad
                d_v[..., cols[:, None], cols[None, :]] = jl * float(dt)
        return d_q, d_v

    def difference_jacobians(self, q0, q1) -> tuple:
        """(∂ difference/∂q0, ∂ difference/∂q1), each (nv, nv) or (..., nv, nv), in the tangent spaces
        (as Pinocchio's ``dDifference`` ARG0 and ARG1): -Jl⁻¹(d) and Jr⁻¹(d) per multi-DOF joint,
        d = difference(q0, q1); -1 and 1 for 1-DOF joints."""
        d = self.difference(q0, q1)
        d_q0 = np.zeros(d.shape[:-1] + (self.nv, self.nv))
        d_q1 = np.zeros_like(d_q0)
        d_q0[..., self._scalar_v, self._scalar_v] = -1.0
        d_q1[..., self._scalar_v, self._scalar_v] = 1.0
        for kind, (_, vi) in self._kinds.items():
            for cols in vi:
                _, _, inv_plus = _block_jacobians(kind, d[..., cols])
                _, _, inv_minus = _block_jacobians(kind, -d[..., cols])
                d_q0[..., cols[:, None], cols[None, :]] = -inv_plus
                d_q1[..., cols[:, None], cols[None, :]] = inv_minus
        return d_q0, d_q1

    def normalize(self, q) -> np.ndarray:
        """``q`` with each quaternion and planar (cos, sin) pair divided by its norm (a copy)."""
        a = self._array(q, self.nq, "q", "nq")
        out = np.array(a, dtype=float)
        for block, columns, what in self._unit_parts:
            norm = _norm(out[..., columns])
            if not np.all(norm > 1e-12) or not np.all(np.isfinite(norm)):
                raise ValueError(
                    f"q[{columns[0]}:{columns[-1] + 1}] of joint '{block.joint.name}': a {what} of norm "
                    f"{np.min(norm) if np.all(np.isfinite(norm)) else 'nan/inf'} cannot be normalised"
                )
            out[..., columns] = out[..., columns] / norm[..., None]
        return out

    def random(self, rng: SeedLike = None, size: int | None = None) -> np.ndarray:
        """Random configurations: 1-DOF joints uniform within their limits (an infinite side replaced
        by ±π for revolute, ±1 for prismatic joints); quaternions uniform over rotations (Shoemake
        1992); free-flyer and planar positions uniform in the joint's limits when finite, else in
        [-1, 1]; planar angles uniform in [-π, π)."""
        if size is not None and not (isinstance(size, (int, np.integer)) and not isinstance(size, bool) and size >= 0):
            raise ValueError(f"size must be a whole number of configurations >= 0 (or None for one), got {size!r}")
        rng = np.random.default_rng(rng)
        lead = () if size is None else (int(size),)
        out = np.broadcast_to(self.neutral(), lead + (self.nq,)).copy()
        scalar = [b for b in self.blocks if b.joint.nq == 1]
        if scalar:
            # the same draws as before multi-DOF joints existed (one uniform call over the 1-DOF joints)
            lo, hi = _sampling_range([b.joint for b in scalar])
            out[..., self._scalar_q] = rng.uniform(lo, hi, size=lead + (len(scalar),))
        for b in self.blocks:
            kind = b.joint.kind
            if kind in ("floating", "planar"):
                k = 3 if kind == "floating" else 2
                lo, hi = _sampling_range([b.joint], position=True)
                out[..., b.iq : b.iq + k] = rng.uniform(lo[0], hi[0], size=lead + (k,))
                if kind == "planar":
                    theta = rng.uniform(-np.pi, np.pi, size=lead)
                    out[..., b.iq + 2], out[..., b.iq + 3] = np.cos(theta), np.sin(theta)
            if kind in ("floating", "spherical"):
                start = b.iq + (3 if kind == "floating" else 0)
                out[..., start : start + 4] = _uniform_quaternions(rng, lead)
        return out


def _sampling_range(joints, position: bool = False) -> tuple:
    lo = np.array([j.lower for j in joints], dtype=float)
    hi = np.array([j.upper for j in joints], dtype=float)
    for i, j in enumerate(joints):
        # an infinite side is replaced by one span beyond the finite side (or -span..span): a one-sided
        # limit such as lower=5 (upper inf) must not give lo > hi
        span = math.pi if (j.kind == "revolute" and not position) else 1.0
        if not math.isfinite(lo[i]):
            lo[i] = min(-span, hi[i] - 2 * span) if math.isfinite(hi[i]) else -span
        if not math.isfinite(hi[i]):
            hi[i] = max(span, lo[i] + 2 * span)
    return lo, hi


def _uniform_quaternions(rng: np.random.Generator, lead: tuple) -> np.ndarray:
    # Shoemake (1992): with u1, u2, u3 uniform in [0, 1), (√(1-u1) sin 2πu2, √(1-u1) cos 2πu2,
    # √u1 sin 2πu3, √u1 cos 2πu3) is uniform on the unit 3-sphere, hence over rotations
    u = rng.random(lead + (3,))
    a, b = np.sqrt(1.0 - u[..., 0]), np.sqrt(u[..., 0])
    t2, t3 = 2 * np.pi * u[..., 1], 2 * np.pi * u[..., 2]
    return np.stack([a * np.sin(t2), a * np.cos(t2), b * np.sin(t3), b * np.cos(t3)], axis=-1)


_SPACES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


# ---------------------------------------------------------------------- functions of a robot
def space(robot: Robot) -> ConfigurationSpace:
    """The :class:`ConfigurationSpace` of ``robot``'s moving joints, in body order."""
    return ConfigurationSpace.of(robot)


def neutral(robot: Robot) -> np.ndarray:
    """The neutral configuration (nq,): zeros, identity quaternions (0, 0, 0, 1), planar (0, 0, 1, 0)."""
    return space(robot).neutral()


def integrate(robot: Robot, q: ArrayLike, v: ArrayLike, dt: ArrayLike = 1.0) -> np.ndarray:
    """q ⊕ v dt: (nq,) or a batch (N, nq) (see the module docstring for each joint kind)."""
    return space(robot).integrate(q, v, dt)


def difference(robot: Robot, q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
    """v (nv,) or (N, nv) with integrate(q0, v) = q1, the short way round for rotations."""
    return space(robot).difference(q0, q1)


def interpolate(robot: Robot, q0: ArrayLike, q1: ArrayLike, t: ArrayLike) -> np.ndarray:
    """q0 ⊕ t · difference(q0, q1): the geodesic between two configurations."""
    return space(robot).interpolate(q0, q1, t)


def random_configuration(robot: Robot, rng: SeedLike = None, size: int | None = None) -> np.ndarray:
    """Random configurations (nq,) or (size, nq): see :meth:`ConfigurationSpace.random`."""
    return space(robot).random(rng, size)


def normalize(robot: Robot, q: ArrayLike) -> np.ndarray:
    """``q`` with its quaternions and planar (cos, sin) pairs made unit."""
    return space(robot).normalize(q)


def check_configuration(robot: Robot, q: ArrayLike) -> np.ndarray:
    """``q`` as a float array if it is a configuration of ``robot``, else a ValueError naming the joint
    and block: the length is not nq, a number is NaN or infinite, or a quaternion or planar
    (cos θ, sin θ) pair has a norm further than :data:`UNIT_TOLERANCE` (1e-6) from 1."""
    return space(robot).check(q)


def integrate_jacobians(robot: Robot, q: ArrayLike, v: ArrayLike, dt: float = 1.0) -> tuple:
    """(∂(q ⊕ v dt)/∂q, ∂(q ⊕ v dt)/∂v): see :meth:`ConfigurationSpace.integrate_jacobians`."""
    return space(robot).integrate_jacobians(q, v, dt)


def difference_jacobians(robot: Robot, q0: ArrayLike, q1: ArrayLike) -> tuple:
    """(∂ difference/∂q0, ∂ difference/∂q1): see :meth:`ConfigurationSpace.difference_jacobians`."""
    return space(robot).difference_jacobians(q0, q1)


def default_configuration(robot: Robot) -> np.ndarray:
    """A generic (non-singular) configuration: 0.5, -0.7, 0.5, -0.7, ... rad (m for prismatic joints,
    x 0.2), clipped to the joint limits; a multi-DOF joint keeps its neutral block (identity rotation).
    The report, the viewer and the notebook drawings start here, where the structure shows (q = 0 is
    often singular)."""
    q, start = robot.neutral(), 0
    for i, j in enumerate(robot.joints):
        if not j.is_multi_dof:
            q[start] = (0.5 if i % 2 == 0 else -0.7) * (1.0 if j.kind == "revolute" else 0.2)
        start += j.nq
    return np.clip(q, robot.lower_limits, robot.upper_limits)
