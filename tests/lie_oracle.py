"""The NumPy Lie-group operations kinedyn used before its configuration space called the core's
(crates/kinedyn-core/src/lie.rs and lie/jacobians.rs: ``kinedyn._core.lie_integrate``,
``lie_difference``, ``lie_quaternion``, ``lie_group_jacobians``, ``lie_integrate_jacobians``,
``lie_difference_jacobians``), kept as a test oracle: unit quaternions (SO(3)), SE(3) for a
free-flyer, SE(2) for a planar joint, and the Jacobians of integrate and difference, vectorised over
batches.

Sources of the formulas (derived again here, not transcribed): Solà, Deray & Atchuthan, "A micro Lie
theory for state estimation in robotics" (2018), §§ 4–5 and appendices A–C; Murray, Li & Sastry,
*A Mathematical Introduction to Robotic Manipulation* (1994), §2.3 eq. 2.36 and Prop. 2.9; Higham,
*Functions of Matrices* (2008), Thm 3.6 for the Fréchet derivative in the SE(3) Jacobian."""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "block_jacobians",
    "exp3",
    "log3",
    "quaternion_multiply",
    "quaternion_rotate",
    "quaternion_to_matrix",
    "difference_floating",
    "difference_planar",
    "integrate_floating",
    "integrate_planar",
    "integrate_rotation",
]

_SERIES_BELOW = 1e-2  # below this angle, series instead of closed forms that cancel
_B_SERIES = [(-1) ** k / math.factorial(2 * k + 3) for k in range(7, -1, -1)]


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


def quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a ⊗ b of quaternions (x, y, z, w): R(a ⊗ b) = R(a) R(b) (Solà et al. eq. 107)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    av, aw, bv, bw = a[..., :3], a[..., 3:], b[..., :3], b[..., 3:]
    # (a_v, a_w)(b_v, b_w) = (a_w b_v + b_w a_v + a_v × b_v, a_w b_w - a_v · b_v)
    vec = aw * bv + bw * av + _cross(av, bv)
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([vec, w], axis=-1)


def quaternion_rotate(quat: np.ndarray, p: np.ndarray) -> np.ndarray:
    """R(quat) p for a unit quaternion (x, y, z, w): p + 2w (u × p) + 2 u × (u × p), u the vector part."""
    quat, p = np.asarray(quat, dtype=float), np.asarray(p, dtype=float)
    u, w = quat[..., :3], quat[..., 3:]
    t = 2.0 * _cross(u, p)
    return p + w * t + _cross(u, t)


def quaternion_to_matrix(quat: np.ndarray) -> np.ndarray:
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


def vector_norm(x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.sum(x * x, axis=-1))


def exp3(omega: np.ndarray) -> np.ndarray:
    """The unit quaternion of the rotation vector ω: (sin(θ/2) ω/θ, cos(θ/2)), θ = |ω| (Solà et al.
    eq. 101). sin(θ/2)/θ is computed as sinc, exact at θ = 0."""
    omega = np.asarray(omega, dtype=float)
    theta = vector_norm(omega)
    half_sinc = 0.5 * np.sinc(theta / (2 * np.pi))  # sin(θ/2)/θ
    return np.concatenate([half_sinc[..., None] * omega, np.cos(theta / 2)[..., None]], axis=-1)


def _log3_with_angle(quat: np.ndarray) -> tuple:
    # q and -q are the same rotation: take the representative with w >= 0, so θ = 2 atan2(|u|, w) lies in
    # [0, π] (the short way). atan2 keeps every digit near θ = π, where w -> 0 and acos would lose them.
    sign = np.where(quat[..., 3] < 0, -1.0, 1.0)[..., None]
    u, w = sign * quat[..., :3], sign[..., 0] * quat[..., 3]
    n = vector_norm(u)
    theta = 2.0 * np.arctan2(n, w)
    # ω = θ u/|u|; at |u| = 0 the limit of 2 atan2(n, w)/n is 2/w
    safe_n = np.where(n > 0, n, 1.0)
    factor = np.where(n > 0, theta / safe_n, 2.0 / np.where(w > 0, w, 1.0))
    return factor[..., None] * u, theta


def log3(quat: np.ndarray) -> np.ndarray:
    """The rotation vector ω in [0, π] of a quaternion (x, y, z, w), the inverse of :func:`exp3`
    (Solà et al. eq. 105, taking w >= 0 so that q and -q give the same, short, rotation)."""
    return _log3_with_angle(np.asarray(quat, dtype=float))[0]


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
    theta = vector_norm(omega)
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
    p = _se3_left_jacobian_times(omega, vector_norm(omega), rho)
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
    # Exp(τ) = (R(θ), t = V(θ) ρ), V = [[A, -B], [B, A]], A = sin θ/θ, B = (1 - cos θ)/θ (Solà et al.
    # eqs. 156-158)
    theta = tau[..., 2]
    a = np.sinc(theta / np.pi)
    b = 0.5 * theta * np.sinc(theta / (2 * np.pi)) ** 2
    tx = a * tau[..., 0] - b * tau[..., 1]
    ty = b * tau[..., 0] + a * tau[..., 1]
    out = np.zeros(tau.shape[:-1] + (3, 3))
    c, s = np.cos(theta), np.sin(theta)
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 0, 2], out[..., 1, 2] = ty, -tx
    out[..., 2, 2] = 1.0
    return out


def block_jacobians(kind: str, v: np.ndarray) -> tuple:
    """(Ad(Exp(v)), Jl(v), Jl(v)⁻¹) of one joint kind's group at its tangent vector v."""
    if kind == "floating":
        jl, inv = _se3_left_jacobian(v)
        return _se3_adjoint_of_exp(v), jl, inv
    if kind == "spherical":
        jl, inv, _ = _so3_left_jacobian(v)
        return quaternion_to_matrix(exp3(v)), jl, inv
    jl, inv = _se2_left_jacobian(v)
    return _se2_adjoint_of_exp(v), jl, inv
