//! Lie groups of joint configurations: SO(3) by unit quaternions, SE(3), SE(2), and per joint block
//! `integrate` (q ⊕ v dt) and `difference` (the v with q0 ⊕ v = q1). Pure functions on slices; no
//! `Model`. The same conventions and formulas as `python/kinedyn/configuration.py` (Pinocchio's):
//!
//! | block       | q                               | v                                  | q ⊕ v          |
//! |-------------|---------------------------------|------------------------------------|----------------|
//! | `Scalar`    | angle or displacement (1)       | its rate (1)                       | q + v          |
//! | `Spherical` | quaternion (qx, qy, qz, qw) (4) | angular velocity, child frame (3)  | R Exp(ω)       |
//! | `FreeFlyer` | (x, y, z, qx, qy, qz, qw) (7)   | [linear; angular], child frame (6) | M Exp(v), SE(3)|
//! | `Planar`    | (x, y, cos θ, sin θ) (4)        | (vx, vy, ω), child frame (3)       | M Exp(v), SE(2)|
//!
//! Sources (derived again, not transcribed): Solà, Deray & Atchuthan, "A micro Lie theory for state
//! estimation in robotics" (2018), SO(3) by quaternions eqs. 101-107, SE(2) eqs. 156-158, SE(3) eqs.
//! 169-175; Murray, Li & Sastry, *A Mathematical Introduction to Robotic Manipulation* (1994), §2.3
//! eq. 2.36 (exponential of a twist). `log3` takes the quaternion with w >= 0 and the angle by
//! `atan2(|u|, w)`, which keeps every digit at θ = π (where `acos` of a matrix trace loses half).
//!
//! Symbols: `omega` ω rotation vector (rad), `theta` θ = |ω|, `rho` ρ linear part of a twist, `quat`
//! a quaternion stored (x, y, z, w), `p` a translation.

use crate::spatial::{Mat3, Real};

mod jacobians;
pub use jacobians::{difference_jacobians_block, integrate_jacobians_block, GroupJacobians, Square};

/// A quaternion (x, y, z, w), w the scalar part (Pinocchio's and Eigen's storage order).
pub type Quat = [f64; 4];

/// Below this angle the series of (1 - (θ/2)cot(θ/2))/θ² replaces the closed form, whose error ε/θ²
/// there multiplies θ²; the first omitted series term is below 1e-17 at 1e-2.
const SERIES_BELOW: f64 = 1e-2;

/// The kind of a joint's block of q and v ([`crate::model::Coordinates::Head`] has the multi-DOF ones).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// Revolute or prismatic: nq = nv = 1.
    Scalar,
    /// SO(3): nq = 4, nv = 3.
    Spherical,
    /// SE(3): nq = 7, nv = 6.
    FreeFlyer,
    /// SE(2): nq = 4, nv = 3.
    Planar,
}

impl Block {
    /// Length of the block in q.
    pub const fn nq(self) -> usize {
        match self {
            Block::Scalar => 1,
            Block::Spherical | Block::Planar => 4,
            Block::FreeFlyer => 7,
        }
    }

    /// Length of the block in v.
    pub const fn nv(self) -> usize {
        match self {
            Block::Scalar => 1,
            Block::Spherical | Block::Planar => 3,
            Block::FreeFlyer => 6,
        }
    }

    /// The identity: 0; (0, 0, 0, 1); (0, 0, 0, 0, 0, 0, 1); (0, 0, 1, 0).
    pub fn neutral(self, out: &mut [f64]) {
        out[..self.nq()].fill(0.0);
        match self {
            Block::Scalar => {}
            Block::Spherical => out[3] = 1.0,
            Block::FreeFlyer => out[6] = 1.0,
            Block::Planar => out[2] = 1.0,
        }
    }
}

// ------------------------------------------------------------------------------ small 3-vectors
#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
fn norm3(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

#[inline]
fn axpy(a: f64, x: [f64; 3], y: [f64; 3]) -> [f64; 3] {
    [a * x[0] + y[0], a * x[1] + y[1], a * x[2] + y[2]]
}

/// sin(x)/x, exact at 0 (the quotient itself has no cancellation elsewhere).
#[inline]
fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        x.sin() / x
    }
}

#[inline]
fn quat(s: &[f64]) -> Quat {
    [s[0], s[1], s[2], s[3]]
}

// ------------------------------------------------------------------------ SO(3) by quaternions
/// Hamilton product a ⊗ b: R(a ⊗ b) = R(a) R(b) (Solà et al. eq. 107).
pub fn quat_mul(a: Quat, b: Quat) -> Quat {
    let (av, bv) = ([a[0], a[1], a[2]], [b[0], b[1], b[2]]);
    // (a_v, a_w)(b_v, b_w) = (a_w b_v + b_w a_v + a_v × b_v, a_w b_w - a_v · b_v)
    let c = cross(av, bv);
    [
        a[3] * bv[0] + b[3] * av[0] + c[0],
        a[3] * bv[1] + b[3] * av[1] + c[1],
        a[3] * bv[2] + b[3] * av[2] + c[2],
        a[3] * b[3] - (av[0] * bv[0] + av[1] * bv[1] + av[2] * bv[2]),
    ]
}

/// The conjugate (x, y, z, w) -> (-x, -y, -z, w): the inverse of a unit quaternion.
pub fn quat_conj(q: Quat) -> Quat {
    [-q[0], -q[1], -q[2], q[3]]
}

/// R(q) p = p + 2w (u × p) + 2 u × (u × p), u the vector part of the unit quaternion q.
pub fn quat_rotate(q: Quat, p: [f64; 3]) -> [f64; 3] {
    let u = [q[0], q[1], q[2]];
    let t = cross(u, p);
    let t = [2.0 * t[0], 2.0 * t[1], 2.0 * t[2]];
    let ut = cross(u, t);
    [
        p[0] + q[3] * t[0] + ut[0],
        p[1] + q[3] * t[1] + ut[1],
        p[2] + q[3] * t[2] + ut[2],
    ]
}

/// Exp of SO(3) as a quaternion: (sin(θ/2) ω/θ, cos(θ/2)), θ = |ω| (Solà et al. eq. 101).
pub fn exp3(omega: [f64; 3]) -> Quat {
    let theta = norm3(omega);
    let half_sinc = 0.5 * sinc(theta / 2.0); // sin(θ/2)/θ
    [
        half_sinc * omega[0],
        half_sinc * omega[1],
        half_sinc * omega[2],
        (theta / 2.0).cos(),
    ]
}

/// Log of SO(3) and the angle θ in [0, π]: ω = θ u/|u| with θ = 2 atan2(|u|, w), taking the sign of
/// q with w >= 0 (q and -q are one rotation: the short way). Solà et al. eq. 105.
pub fn log3_with_angle(q: Quat) -> ([f64; 3], f64) {
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 };
    let (u, w) = ([sign * q[0], sign * q[1], sign * q[2]], sign * q[3]);
    let n = norm3(u);
    let theta = 2.0 * n.atan2(w);
    // the limit of 2 atan2(n, w)/n at n = 0 is 2/w
    let factor = if n > 0.0 { theta / n } else { 2.0 / w };
    ([factor * u[0], factor * u[1], factor * u[2]], theta)
}

/// Log of SO(3): the rotation vector of q, angle in [0, π].
pub fn log3(q: Quat) -> [f64; 3] {
    log3_with_angle(q).0
}

// ---------------------------------------------------------------------------------------- SE(3)
/// (θ - sin θ)/θ³: the closed form loses digits as ε/θ², so below θ = 0.5 its series
/// Σ (-1)ᵏ θ²ᵏ/(2k+3)!, k = 0..7 (the first omitted term is below 1e-21), by Horner's rule in θ².
fn theta_minus_sin_over_cube(theta: f64) -> f64 {
    if theta < 0.5 {
        let t2 = theta * theta;
        // 1/(2k+3)! for k = 7 down to 0, alternating in sign
        const C: [f64; 8] = [
            -1.0 / 355_687_428_096_000.0, // 1/17!
            1.0 / 1_307_674_368_000.0,    // 1/15!
            -1.0 / 6_227_020_800.0,       // 1/13!
            1.0 / 39_916_800.0,           // 1/11!
            -1.0 / 362_880.0,             // 1/9!
            1.0 / 5040.0,                 // 1/7!
            -1.0 / 120.0,                 // 1/5!
            1.0 / 6.0,                    // 1/3!
        ];
        C.iter().fold(0.0, |acc, c| acc * t2 + c)
    } else {
        (theta - theta.sin()) / (theta * theta * theta)
    }
}

/// V(ω) ρ = ρ + (1 - cos θ)/θ² ω × ρ + (θ - sin θ)/θ³ ω × (ω × ρ), the left Jacobian of SO(3) times ρ
/// (Solà et al. eq. 174; Murray, Li & Sastry eq. 2.36).
fn left_jacobian_times(omega: [f64; 3], theta: f64, rho: [f64; 3]) -> [f64; 3] {
    let s = sinc(theta / 2.0);
    let a = 0.5 * s * s; // (1 - cos θ)/θ² = 2 sin²(θ/2)/θ²
    let b = theta_minus_sin_over_cube(theta);
    let wxr = cross(omega, rho);
    axpy(b, cross(omega, wxr), axpy(a, wxr, rho))
}

/// V(ω)⁻¹ p = p - ½ ω × p + (1 - (θ/2) cot(θ/2))/θ² ω × (ω × p), for θ in [0, π] (the inverse of eq.
/// 174 in closed form: V is a polynomial in [ω]× and [ω]×³ = -θ² [ω]×).
fn left_jacobian_inverse_times(omega: [f64; 3], theta: f64, p: [f64; 3]) -> [f64; 3] {
    let c = if theta < SERIES_BELOW {
        let t2 = theta * theta;
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    } else {
        let half = theta / 2.0;
        (1.0 - half * half.cos() / half.sin()) / (theta * theta)
    };
    let wxp = cross(omega, p);
    axpy(c, cross(omega, wxp), axpy(-0.5, wxp, p))
}

/// Exp of SE(3) for the twist v = [ρ; ω]: (translation V(ω) ρ, rotation Exp(ω)).
pub fn exp6(v: [f64; 6]) -> ([f64; 3], Quat) {
    let (rho, omega) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
    (left_jacobian_times(omega, norm3(omega), rho), exp3(omega))
}

/// Log of SE(3) of (translation p, rotation q): [V(ω)⁻¹ p; ω], ω = Log(q), the short way.
pub fn log6(p: [f64; 3], q: Quat) -> [f64; 6] {
    let (omega, theta) = log3_with_angle(q);
    let rho = left_jacobian_inverse_times(omega, theta, p);
    [rho[0], rho[1], rho[2], omega[0], omega[1], omega[2]]
}

// ---------------------------------------------------------------------------------------- SE(2)
/// Exp of SE(2) for v = (vx, vy, θ): (x, y, cos θ, sin θ) with (x, y) = V(θ) (vx, vy),
/// V = [[sin θ/θ, -(1 - cos θ)/θ], [(1 - cos θ)/θ, sin θ/θ]] (Solà et al. eqs. 156-158).
pub fn exp_se2(v: [f64; 3]) -> [f64; 4] {
    let theta = v[2];
    let a = sinc(theta);
    let s = sinc(theta / 2.0);
    let b = 0.5 * theta * s * s; // (1 - cos θ)/θ = 2 sin²(θ/2)/θ
    let (st, ct) = theta.sin_cos();
    [a * v[0] - b * v[1], b * v[0] + a * v[1], ct, st]
}

/// Log of SE(2) of (x, y, cos θ, sin θ): θ = atan2(sin, cos) in (-π, π], (vx, vy) = V(θ)⁻¹ (x, y) with
/// V⁻¹ = [[α, θ/2], [-θ/2, α]], α = (θ/2) cot(θ/2) = cos(θ/2)/sinc(θ/2) (no cancellation).
pub fn log_se2(m: [f64; 4]) -> [f64; 3] {
    let theta = m[3].atan2(m[2]);
    let alpha = (theta / 2.0).cos() / sinc(theta / 2.0);
    [
        alpha * m[0] + theta / 2.0 * m[1],
        -theta / 2.0 * m[0] + alpha * m[1],
        theta,
    ]
}

// ------------------------------------------------------------------------------- joint blocks
/// `out = q ⊕ (v dt)` for one joint's block: `q`, `out` of length `block.nq()`, `v` of `block.nv()`.
/// The velocity is in the child's frame (right multiplication by the exponential). Quaternions and
/// (cos, sin) pairs come out normalised; the quaternion's sign is Pinocchio's (a free-flyer's in
/// q's hemisphere, a spherical joint's the plain product). Panics if a slice is too short.
pub fn integrate_block(block: Block, q: &[f64], v: &[f64], dt: f64, out: &mut [f64]) {
    match block {
        Block::Scalar => out[0] = q[0] + v[0] * dt,
        Block::Spherical => {
            let omega = [v[0] * dt, v[1] * dt, v[2] * dt];
            out[..4].copy_from_slice(&integrate_rotation(quat(q), omega, false));
        }
        Block::FreeFlyer => {
            // M0 Exp(v dt): p1 = p0 + R0 V(ω) ρ, R1 = R0 Exp(ω)
            let quat0 = quat(&q[3..7]);
            let (t, _) = exp6([v[0] * dt, v[1] * dt, v[2] * dt, v[3] * dt, v[4] * dt, v[5] * dt]);
            let p = quat_rotate(quat0, t);
            for k in 0..3 {
                out[k] = q[k] + p[k];
            }
            let omega = [v[3] * dt, v[4] * dt, v[5] * dt];
            out[3..7].copy_from_slice(&integrate_rotation(quat0, omega, true));
        }
        Block::Planar => {
            let (c0, s0) = (q[2], q[3]);
            let m = exp_se2([v[0] * dt, v[1] * dt, v[2] * dt]);
            out[0] = q[0] + c0 * m[0] - s0 * m[1];
            out[1] = q[1] + s0 * m[0] + c0 * m[1];
            let (c1, s1) = (c0 * m[2] - s0 * m[3], s0 * m[2] + c0 * m[3]);
            let n = c1.hypot(s1);
            out[2] = c1 / n;
            out[3] = s1 / n;
        }
    }
}

/// quat0 ⊗ Exp(ω), normalised; in quat0's hemisphere when `same_hemisphere`.
fn integrate_rotation(quat0: Quat, omega: [f64; 3], same_hemisphere: bool) -> Quat {
    let mut r = quat_mul(quat0, exp3(omega));
    let dot: f64 = (0..4).map(|k| r[k] * quat0[k]).sum();
    let n = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]).sqrt();
    let scale = if same_hemisphere && dot < 0.0 {
        -1.0 / n
    } else {
        1.0 / n
    };
    for x in r.iter_mut() {
        *x *= scale;
    }
    r
}

/// `out = difference(q0, q1)`: the v (length `block.nv()`) with q0 ⊕ v = q1, Log(M0⁻¹ M1), rotations
/// the short way (angle in [0, π]). Panics if a slice is too short.
pub fn difference_block(block: Block, q0: &[f64], q1: &[f64], out: &mut [f64]) {
    match block {
        Block::Scalar => out[0] = q1[0] - q0[0],
        Block::Spherical => out[..3].copy_from_slice(&log3(quat_mul(quat_conj(quat(q0)), quat(q1)))),
        Block::FreeFlyer => {
            let inv0 = quat_conj(quat(&q0[3..7]));
            let dp = [q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]];
            let v = log6(quat_rotate(inv0, dp), quat_mul(inv0, quat(&q1[3..7])));
            out[..6].copy_from_slice(&v);
        }
        Block::Planar => {
            let (c0, s0, c1, s1) = (q0[2], q0[3], q1[2], q1[3]);
            let (dx, dy) = (q1[0] - q0[0], q1[1] - q0[1]);
            // M0⁻¹ M1 = (R0ᵀ (p1 - p0), R0ᵀ R1)
            let rel = [
                c0 * dx + s0 * dy,
                -s0 * dx + c0 * dy,
                c0 * c1 + s0 * s1,
                c0 * s1 - s0 * c1,
            ];
            out[..3].copy_from_slice(&log_se2(rel));
        }
    }
}

/// The block's quaternion or (cos, sin) pair divided by its norm, in place (nothing for `Scalar`).
pub fn normalize_block(block: Block, q: &mut [f64]) {
    let part = match block {
        Block::Scalar => return,
        Block::Spherical => &mut q[0..4],
        Block::FreeFlyer => &mut q[3..7],
        Block::Planar => &mut q[2..4],
    };
    let n = part.iter().map(|x| x * x).sum::<f64>().sqrt();
    for x in part.iter_mut() {
        *x /= n;
    }
}

/// A unit quaternion from three numbers `u` uniform in [0, 1): uniformly distributed over rotations
/// (Shoemake, "Uniform random rotations", Graphics Gems III, 1992: with a = √(1-u0), b = √u0,
/// (a sin 2πu1, a cos 2πu1, b sin 2πu2, b cos 2πu2) is uniform on the unit 3-sphere).
pub fn uniform_quaternion(u: [f64; 3]) -> Quat {
    let (a, b) = ((1.0 - u[0]).sqrt(), u[0].sqrt());
    let (t1, t2) = (2.0 * std::f64::consts::PI * u[1], 2.0 * std::f64::consts::PI * u[2]);
    [a * t1.sin(), a * t1.cos(), b * t2.sin(), b * t2.cos()]
}

/// The rotation matrix of a unit quaternion `(x, y, z, w)`.
#[inline(always)]
pub fn quaternion_matrix<T: Real>(q: &[T]) -> Mat3<T> {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    let (one, two) = (T::one(), T::splat(2.0));
    Mat3::new(
        one - two * (y * y + z * z),
        two * (x * y - z * w),
        two * (x * z + y * w),
        two * (x * y + z * w),
        one - two * (x * x + z * z),
        two * (y * z - x * w),
        two * (x * z - y * w),
        two * (y * z + x * w),
        one - two * (x * x + y * y),
    )
}

/// The Lie bracket `[a, b]` of two velocities of a multi-DOF joint (the first `block.nv()` entries):
/// so(3) `a x b`; se(3) `[a_lin; a_ang]`: `(a_ang x b_lin - b_ang x a_lin, a_ang x b_ang)`; se(2)
/// `(vx, vy, w)`: `(w_a J v_b - w_b J v_a, 0)` with `J` the quarter turn; zero for a 1-DOF joint.
pub fn lie_bracket(block: Block, a: &[f64], b: &[f64]) -> [f64; 6] {
    let cross = |x: &[f64], y: &[f64]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    match block {
        Block::Spherical => {
            let c = cross(a, b);
            [c[0], c[1], c[2], 0.0, 0.0, 0.0]
        }
        Block::FreeFlyer => {
            let (p, q) = (cross(&a[3..6], &b[0..3]), cross(&b[3..6], &a[0..3]));
            let w = cross(&a[3..6], &b[3..6]);
            [p[0] - q[0], p[1] - q[1], p[2] - q[2], w[0], w[1], w[2]]
        }
        Block::Scalar => [0.0; 6],
        Block::Planar => [
            -a[2] * b[1] + b[2] * a[1],
            a[2] * b[0] - b[2] * a[0],
            0.0,
            0.0,
            0.0,
            0.0,
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use std::f64::consts::PI;

    const BLOCKS: [Block; 4] = [Block::Scalar, Block::Spherical, Block::FreeFlyer, Block::Planar];
    type IntegrateVector = (Block, &'static [f64], &'static [f64], f64, &'static [f64]);
    type DifferenceVector = (Block, &'static [f64], &'static [f64], &'static [f64]);

    fn vec3(s: &[f64]) -> [f64; 3] {
        [s[0], s[1], s[2]]
    }

    // BEGIN SHARED VECTORS (written by kinedyn.configuration; tests/test_configuration.py reads them back)
    /// (block, q, v, dt, q ⊕ v dt)
    const INTEGRATE_VECTORS: &[IntegrateVector] = &[
        (
            Block::Scalar,
            &[-2.0173120613613755],
            &[2.405712835382749e-10],
            0.5,
            &[-2.01731206124109],
        ),
        (
            Block::Scalar,
            &[1.8253799738128214],
            &[-0.09358479845705271],
            0.5,
            &[1.778587574584295],
        ),
        (
            Block::Scalar,
            &[-1.26730108865027],
            &[1.4401356400182261],
            0.01,
            &[-1.2528997322500877],
        ),
        (
            Block::Scalar,
            &[0.09521348208206204],
            &[-0.6140183945189056],
            0.01,
            &[0.08907329813687298],
        ),
        (
            Block::Spherical,
            &[
                0.8403870848208201,
                0.12589810231375478,
                -0.08513740635257472,
                -0.5202411340327826,
            ],
            &[6.566216052935378e-10, -2.3228277208327798e-10, -1.4873281023632337e-10],
            0.5,
            &[
                0.8403870847257945,
                0.12589810236123805,
                -0.08513740640269919,
                -0.5202411341665913,
            ],
        ),
        (
            Block::Spherical,
            &[
                -0.33845628251552,
                0.10403503080018284,
                -0.5811037552926597,
                -0.7327635926934063,
            ],
            &[0.2501768990154755, 0.34131503539652047, -0.2656599463666488],
            0.5,
            &[
                -0.33896568038747577,
                -0.017809305877879412,
                -0.5633308241439733,
                -0.7532884432359729,
            ],
        ),
        (
            Block::Spherical,
            &[
                0.5416859538756861,
                0.07573267374741666,
                0.036228703962914346,
                -0.836378126513375,
            ],
            &[1.1878918214245937, 1.4394558728567843, 4.366976285425663],
            0.01,
            &[
                0.5379588170237727,
                0.05808086439685179,
                0.02140651966594491,
                -0.840695358196469,
            ],
        ),
        (
            Block::Spherical,
            &[
                0.3265242391891263,
                -0.562320564025328,
                0.008603304289283943,
                0.7596732769102157,
            ],
            &[-0.6755805089519974, 0.660220668263115, 2.9962148484201205],
            0.5,
            &[
                -0.26512685943179043,
                -0.5062431830068869,
                0.4814121175854085,
                0.664581041791612,
            ],
        ),
        (
            Block::FreeFlyer,
            &[
                0.46012915563816703,
                -0.3715237375642346,
                0.13409951672889786,
                -0.7550035519641578,
                0.1157526423304251,
                -0.1665343215592087,
                0.6235681855722307,
            ],
            &[
                1.6965057990044396e-10,
                -1.7407814485295513e-09,
                -6.987558974796816e-10,
                2.25453892712826e-09,
                -5.829696909767877e-10,
                1.1199763853913793e-09,
            ],
            0.01,
            &[
                0.46012915563638535,
                -0.37152373756778984,
                0.1340995167473077,
                -0.7550035519569658,
                0.11575264233095814,
                -0.16653432155482092,
                0.6235681855820117,
            ],
        ),
        (
            Block::FreeFlyer,
            &[
                0.31921453498189867,
                0.09212045980128503,
                0.8345265992856814,
                -0.511636102734347,
                -0.7106090994201171,
                -0.4441582151955763,
                0.18970157109106614,
            ],
            &[
                0.03517785904392071,
                0.6099517590116416,
                -0.1147069351403747,
                0.07519516496489217,
                -0.31893351147588656,
                -0.3140508647771033,
            ],
            1.0,
            &[
                0.781115504310281,
                0.15985776942473306,
                1.2393940336497684,
                -0.45104029119403855,
                -0.8185897162018856,
                -0.35492414925673826,
                0.022413846668838448,
            ],
        ),
        (
            Block::FreeFlyer,
            &[
                0.0321651752754637,
                0.3191390661456821,
                0.762372358699047,
                0.7294624546145609,
                -0.33589211470226726,
                0.54882563531652,
                -0.23205912308710677,
            ],
            &[
                1.8917350888170381,
                0.9214724778230956,
                2.237016318341957,
                -0.9167245571268181,
                -1.3630194094736885,
                2.0779655971223074,
            ],
            0.01,
            &[
                0.05461617588609345,
                0.29821873578887137,
                0.7611719365605554,
                0.7307125520946115,
                -0.34437550157692487,
                0.5398557492853955,
                -0.23668639607828224,
            ],
        ),
        (
            Block::FreeFlyer,
            &[
                0.9269694962409576,
                -0.5669529967744029,
                -0.7727240128236488,
                0.4713540815432375,
                0.640426346331507,
                0.6028286732780036,
                -0.0653988945693254,
            ],
            &[
                0.21709323165297403,
                -0.948896412364311,
                1.5526330652518097,
                2.9592358693438596,
                1.0532587957503083,
                -0.056327182906137134,
            ],
            0.01,
            &[
                0.9265537191833427,
                -0.5512921141857959,
                -0.7822296302253693,
                0.4669734156799287,
                0.6490548820321534,
                0.595779435403824,
                -0.07556754269095049,
            ],
        ),
        (
            Block::Planar,
            &[
                -0.7590618447522517,
                -0.06837493800924133,
                -0.2617212746333669,
                -0.965143499384566,
            ],
            &[2.663540206994202e-09, -9.20317973372787e-10, 7.887385690491208e-10],
            1.0,
            &[
                -0.7590618463375958,
                -0.06837494033907304,
                -0.261721273872121,
                -0.9651434995909957,
            ],
        ),
        (
            Block::Planar,
            &[
                0.4375864100550535,
                0.7011025195127101,
                -0.9918173190919921,
                0.12766520884396637,
            ],
            &[-0.1280186360818861, 0.013011026125519522, 0.5768270860988186],
            0.01,
            &[
                0.4388403471087567,
                0.7008136543664266,
                -0.9925372222147435,
                0.12194204573583692,
            ],
        ),
        (
            Block::Planar,
            &[
                0.15415966591981212,
                0.28383518080671366,
                0.9999650237054776,
                -0.008363693305214833,
            ],
            &[0.8461375478138122, 0.44863596941451833, -0.7342912469892587],
            0.01,
            &[
                0.16267440261677107,
                0.2882193734511052,
                0.9998766522717906,
                -0.015706057486105096,
            ],
        ),
        (
            Block::Planar,
            &[
                -0.8432541901556276,
                -0.5757217023484549,
                -0.7916354415308923,
                0.6109937214998116,
            ],
            &[0.07605711276741685, 0.13874089268518713, 3.1415925535897933],
            0.5,
            &[
                -0.8692338589720123,
                -0.6420387371176614,
                -0.6109937610815829,
                -0.7916354109812052,
            ],
        ),
    ];
    /// (block, q0, q1, difference(q0, q1))
    const DIFFERENCE_VECTORS: &[DifferenceVector] = &[
        (
            Block::Scalar,
            &[-0.8136691853622136],
            &[-0.8136691847239188],
            &[6.382947503880132e-10],
        ),
        (
            Block::Scalar,
            &[-2.027249684545811],
            &[0.9599752273915536],
            &[2.9872249119373646],
        ),
        (
            Block::Scalar,
            &[0.8537014402763488],
            &[1.5879625990200017],
            &[0.7342611587436529],
        ),
        (
            Block::Scalar,
            &[-0.32433459870669523],
            &[-1.012771225039295],
            &[-0.6884366263325998],
        ),
        (
            Block::Spherical,
            &[
                0.7503237526771891,
                0.2680176580675774,
                -0.3392467240181018,
                -0.500092452827852,
            ],
            &[
                0.7503237528577023,
                0.26801765867122673,
                -0.33924672349518786,
                -0.5000924525882262,
            ],
            &[-1.230012841579864e-09, 1.749775879744675e-10, -1.169529584288398e-09],
        ),
        (
            Block::Spherical,
            &[
                -0.4409683559108159,
                0.6105605371012442,
                0.5963910755895322,
                -0.27763361571883355,
            ],
            &[
                0.5076283928560397,
                -0.21521743570772978,
                0.8320660446985916,
                -0.06050592858079939,
            ],
            &[-2.299857741718181, -1.6389870672550413, 0.05752381267188132],
        ),
        (
            Block::Spherical,
            &[
                0.44276201166014195,
                -0.4271516608942621,
                0.3789536527824707,
                -0.6913012286035375,
            ],
            &[
                0.13330949287925586,
                -0.69813960007381,
                -0.6280483846699398,
                -0.31683576886225384,
            ],
            &[-1.262671938002417, 0.04869745536608841, 2.1006897364297124],
        ),
        (
            Block::Spherical,
            &[
                0.3917411224924119,
                0.5887137424395589,
                -0.3985217761975966,
                0.5840679894562847,
            ],
            &[
                -0.03654517581865518,
                -0.094489589584674,
                -0.7735489659577928,
                0.6255862569223631,
            ],
            &[0.5246105677622331, -1.7153703608580833, -0.43283775669075986],
        ),
        (
            Block::FreeFlyer,
            &[
                0.3436519634454094,
                -0.025273867854977095,
                -0.8142229024851055,
                -0.6055731479326134,
                -0.7876695212829139,
                0.006064948198940263,
                -0.11323031461704292,
            ],
            &[
                0.3436519639401347,
                -0.025273867731045063,
                -0.8142229027999284,
                -0.605573147783564,
                -0.7876695213083995,
                0.006064947925191071,
                -0.11323031525155813,
            ],
            &[
                5.7338979983278723e-11,
                4.6549914069690695e-10,
                3.7316014715980865e-10,
                -1.2338015331625485e-09,
                -6.640627553053391e-10,
                -1.9598013424777794e-10,
            ],
        ),
        (
            Block::FreeFlyer,
            &[
                0.7141573799732936,
                0.2566957247261812,
                -0.3573246090929585,
                0.49897294920621754,
                -0.30859348670793485,
                -0.7061668446486127,
                -0.3963892574741541,
            ],
            &[
                -0.743311197115893,
                -0.44001651160821464,
                -0.9345632436061693,
                -0.3229110544294463,
                -0.9010100232320238,
                0.2877580504355038,
                0.033236927840113686,
            ],
            &[
                -0.33412815103796867,
                1.012379018448889,
                2.053746824836885,
                -2.4734722277199706,
                -0.8367205151500055,
                -1.3561862223106023,
            ],
        ),
        (
            Block::FreeFlyer,
            &[
                0.49006977329530366,
                0.7789967146090568,
                -0.5684188478317622,
                -0.5790989521066955,
                -0.12032599614479222,
                -0.6746912918716143,
                0.44154016690817927,
            ],
            &[
                -0.31242890799621126,
                0.37758941142609537,
                0.2088012116052116,
                0.45829094170113,
                0.616934663422332,
                0.5103220592532365,
                -0.38591764621768926,
            ],
            &[
                0.858199492930684,
                -0.6169058162972391,
                -0.5413286968261557,
                0.7907109467357422,
                -0.5040047666526305,
                -0.5616958426499356,
            ],
        ),
        (
            Block::FreeFlyer,
            &[
                0.5796187665510097,
                -0.15410791045681438,
                -0.6326792258171374,
                -0.16446395925150767,
                -0.46335951534292186,
                0.32996816222457326,
                -0.8058353290633444,
            ],
            &[
                -0.5187479163724535,
                0.5627317863894354,
                -0.26942988659307887,
                0.21117595457123495,
                -0.9551513103044627,
                -0.039492506427704376,
                -0.20379164009019954,
            ],
            &[
                -0.0660371165951115,
                0.4013867918687807,
                -1.5028405222647083,
                -1.2666350565406592,
                1.4433020809632287,
                -0.36754410747697985,
            ],
        ),
        (
            Block::Planar,
            &[
                -0.8522080483095296,
                0.7066273125199987,
                -0.493691209006099,
                -0.8696372750463818,
            ],
            &[
                -0.8522080491790475,
                0.7066273123570788,
                -0.4936912078732804,
                -0.8696372756894805,
            ],
            &[5.709545616191973e-10, -6.757330570794244e-10, 1.3026334455545907e-09],
        ),
        (
            Block::Planar,
            &[
                -0.8407413248487865,
                0.3259226755376978,
                0.4343758596859439,
                -0.9007317095129366,
            ],
            &[
                -0.6770619146780983,
                0.09894311566951819,
                0.971458502154134,
                -0.23720956682319214,
            ],
            &[0.27898500829363815, -0.0758807910121474, 0.8819586689699724],
        ),
        (
            Block::Planar,
            &[
                0.5487640401573219,
                0.30419623373190885,
                -0.2703960448177169,
                -0.9627491775882934,
            ],
            &[
                0.48888378118783216,
                0.5430740758134884,
                -0.12683829831525664,
                0.9919234073659569,
            ],
            &[0.10797260286948217, -0.32699598011027003, -2.740607398153574],
        ),
        (
            Block::Planar,
            &[
                -0.16743045686773828,
                -0.9581103116751879,
                0.19823362534225114,
                -0.9801547988882511,
            ],
            &[
                -0.45863819710817966,
                0.8382609819041482,
                0.8510927451406735,
                0.52501537041206,
            ],
            &[-1.1515519793367854, 1.7967207897295165, 1.9239740465947666],
        ),
    ];
    // END SHARED VECTORS

    fn close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        assert_eq!(a.len(), b.len(), "{what}: lengths");
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= tol,
                "{what}: [{k}] {x} vs {y} (|diff| {:e} > {tol:e})",
                (x - y).abs()
            );
        }
    }

    fn random_q(block: Block, rng: &mut Rng) -> Vec<f64> {
        let mut q: Vec<f64> = (0..block.nq()).map(|_| rng.uniform(-1.0, 1.0)).collect();
        normalize_block(block, &mut q);
        q
    }

    fn random_v(block: Block, rng: &mut Rng, scale: f64) -> Vec<f64> {
        (0..block.nv()).map(|_| scale * rng.uniform(-1.0, 1.0)).collect()
    }

    /// v with every rotation angle set to `angle` (spherical, free-flyer and planar blocks).
    fn with_angle(block: Block, mut v: Vec<f64>, angle: f64) -> Vec<f64> {
        let range = match block {
            Block::Scalar => return v,
            Block::Spherical => 0..3,
            Block::FreeFlyer => 3..6,
            Block::Planar => {
                v[2] = angle;
                return v;
            }
        };
        let n = v[range.clone()].iter().map(|x| x * x).sum::<f64>().sqrt();
        for x in &mut v[range] {
            *x *= angle / n;
        }
        v
    }

    #[test]
    fn agrees_with_the_python_module_on_shared_vectors() {
        for (block, q, v, dt, expected) in INTEGRATE_VECTORS {
            let mut out = vec![0.0; block.nq()];
            integrate_block(*block, q, v, *dt, &mut out);
            close(&out, expected, 1e-14, &format!("integrate {block:?}"));
        }
        for (block, q0, q1, expected) in DIFFERENCE_VECTORS {
            let mut out = vec![0.0; block.nv()];
            difference_block(*block, q0, q1, &mut out);
            close(&out, expected, 1e-14, &format!("difference {block:?}"));
        }
    }

    #[test]
    fn difference_undoes_integrate() {
        let mut rng = Rng::new(1);
        for block in BLOCKS {
            for scale in [1e-12, 1e-6, 1e-2, 1.0] {
                for _ in 0..200 {
                    let q = random_q(block, &mut rng);
                    let v = random_v(block, &mut rng, scale);
                    let (mut q1, mut back) = (vec![0.0; block.nq()], vec![0.0; block.nv()]);
                    integrate_block(block, &q, &v, 1.0, &mut q1);
                    difference_block(block, &q, &q1, &mut back);
                    close(&back, &v, 1e-14, &format!("{block:?} at scale {scale}"));
                }
            }
        }
    }

    #[test]
    fn near_pi_rotations_round_trip() {
        // log3 by atan2 of the quaternion: every digit survives at θ = π - gap
        let mut rng = Rng::new(2);
        for block in BLOCKS {
            for gap in [1e-3, 1e-6, 1e-9, 1e-12] {
                for _ in 0..100 {
                    let q = random_q(block, &mut rng);
                    let v = with_angle(block, random_v(block, &mut rng, 1.0), PI - gap);
                    let (mut q1, mut back) = (vec![0.0; block.nq()], vec![0.0; block.nv()]);
                    integrate_block(block, &q, &v, 1.0, &mut q1);
                    difference_block(block, &q, &q1, &mut back);
                    close(&back, &v, 1e-13, &format!("{block:?} at pi - {gap}"));
                }
            }
        }
    }

    #[test]
    fn antipodal_quaternions_are_one_rotation() {
        let mut rng = Rng::new(3);
        for (block, part) in [(Block::Spherical, 0..4), (Block::FreeFlyer, 3..7)] {
            for _ in 0..100 {
                let (q0, q1) = (random_q(block, &mut rng), random_q(block, &mut rng));
                let mut flipped = q1.clone();
                for x in &mut flipped[part.clone()] {
                    *x = -*x;
                }
                let (mut a, mut b, mut zero) = (vec![0.0; block.nv()], vec![0.0; block.nv()], vec![0.0; block.nv()]);
                difference_block(block, &q0, &q1, &mut a);
                difference_block(block, &q0, &flipped, &mut b);
                difference_block(block, &q1, &flipped, &mut zero);
                close(&a, &b, 1e-13, &format!("{block:?}: q1 and -q1"));
                close(&zero, &vec![0.0; block.nv()], 1e-15, &format!("{block:?}: q and -q"));
            }
        }
    }

    #[test]
    fn velocity_is_in_the_child_frame_by_finite_differences() {
        // d/dt (q ⊕ v t) at t = 0 against the kinematic equations: ṗ = R v_lin, q̇uat = ½ quat ⊗ (ω, 0),
        // planar (ẋ, ẏ) = R(θ) (vx, vy), (ċ, ṡ) = ω (-s, c), scalar q̇ = v
        let mut rng = Rng::new(4);
        let h = 1e-6;
        for block in BLOCKS {
            for _ in 0..20 {
                let q = random_q(block, &mut rng);
                let v = random_v(block, &mut rng, 1.0);
                let (mut plus, mut minus) = (vec![0.0; block.nq()], vec![0.0; block.nq()]);
                integrate_block(block, &q, &v, h, &mut plus);
                integrate_block(block, &q, &v, -h, &mut minus);
                let numeric: Vec<f64> = plus.iter().zip(&minus).map(|(a, b)| (a - b) / (2.0 * h)).collect();
                let expected: Vec<f64> = match block {
                    Block::Scalar => vec![v[0]],
                    Block::Spherical => half_product(quat(&q), vec3(&v)).to_vec(),
                    Block::FreeFlyer => {
                        let p = quat_rotate(quat(&q[3..7]), vec3(&v));
                        let r = half_product(quat(&q[3..7]), vec3(&v[3..6]));
                        vec![p[0], p[1], p[2], r[0], r[1], r[2], r[3]]
                    }
                    Block::Planar => {
                        let (c, s) = (q[2], q[3]);
                        vec![c * v[0] - s * v[1], s * v[0] + c * v[1], -s * v[2], c * v[2]]
                    }
                };
                close(&numeric, &expected, 1e-8, &format!("{block:?}"));
            }
        }
    }

    fn half_product(q: Quat, omega: [f64; 3]) -> Quat {
        let r = quat_mul(q, [omega[0], omega[1], omega[2], 0.0]);
        [0.5 * r[0], 0.5 * r[1], 0.5 * r[2], 0.5 * r[3]]
    }

    #[test]
    fn exp3_is_the_axis_angle_rotation() {
        // R(exp3(θ a)) p == Rodrigues' rotation (crate::joint::axis_angle) p, and log3 inverts exp3
        let mut rng = Rng::new(5);
        for _ in 0..100 {
            let axis = rng.unit();
            let angle = rng.uniform(0.0, PI);
            let omega = [axis[0] * angle, axis[1] * angle, axis[2] * angle];
            let r = crate::joint::axis_angle(&axis, angle);
            let p = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
            let rp = r * crate::spatial::Vec3::new(p[0], p[1], p[2]);
            close(
                &quat_rotate(exp3(omega), p),
                &[rp[0], rp[1], rp[2]],
                1e-14,
                "exp3 vs axis_angle",
            );
            close(&log3(exp3(omega)), &omega, 1e-14, "log3(exp3)");
        }
        assert_eq!(exp3([0.0; 3]), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(log3([0.0, 0.0, 0.0, -1.0]), [0.0; 3]);
    }

    #[test]
    fn exp6_log6_and_se2_are_inverse() {
        let mut rng = Rng::new(6);
        for _ in 0..100 {
            let mut v = [0.0; 6];
            for x in &mut v {
                *x = rng.uniform(-1.5, 1.5);
            }
            let (p, q) = exp6(v);
            close(&log6(p, q), &v, 1e-14, "log6(exp6)");
            let w = [v[0], v[1], v[2] * 2.0];
            close(&log_se2(exp_se2(w)), &w, 1e-14, "log_se2(exp_se2)");
        }
    }

    #[test]
    fn neutral_and_normalize() {
        for (block, expected) in [
            (Block::Scalar, vec![0.0]),
            (Block::Spherical, vec![0.0, 0.0, 0.0, 1.0]),
            (Block::FreeFlyer, vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
            (Block::Planar, vec![0.0, 0.0, 1.0, 0.0]),
        ] {
            let mut q = vec![7.0; block.nq()];
            block.neutral(&mut q);
            assert_eq!(q, expected);
            assert_eq!(
                (block.nq(), block.nv()),
                (
                    expected.len(),
                    if block == Block::Scalar { 1 } else { expected.len() - 1 }
                )
            );
        }
        let mut q = [1.0, 2.0, 0.0, 3.0, 0.0, 0.0, 4.0];
        normalize_block(Block::FreeFlyer, &mut q);
        assert_eq!(q, [1.0, 2.0, 0.0, 0.6, 0.0, 0.0, 0.8]);
    }
}
