//! The Jacobians of `integrate` and `difference` per joint block, in the tangent spaces
//! (Pinocchio's `dIntegrate` and `dDifference`, ARG0 and ARG1).
//!
//! Perturbations act on the right, as velocities do: `q ⊕ δ`. With the group's adjoint `Ad` and its
//! right Jacobian `Jr(τ)` (`Exp(τ + δ) ≈ Exp(τ) Exp(Jr(τ) δ)`), and `Jl(τ) = Jr(-τ) = Σ ad_τᵏ/(k+1)!`:
//!
//! - `∂(q ⊕ v)/∂q = Ad(Exp(v))⁻¹ = Ad(Exp(-v))`, `∂(q ⊕ v)/∂v = Jr(v) = Jl(-v)`;
//! - `∂Log(q0⁻¹ q1)/∂q1 = Jr⁻¹(d) = Jl⁻¹(-d)`, `∂Log(q0⁻¹ q1)/∂q0 = -Jl⁻¹(d)` (d the difference).
//!
//! (Solà, Deray & Atchuthan, "A micro Lie theory for state estimation in robotics", 2018, eqs.
//! 72-81.) `Jl` of SE(3) and SE(2) is a function of the block upper-triangular `ad_τ`, so its
//! off-diagonal block is the Fréchet derivative of that function (Higham, *Functions of Matrices*,
//! 2008, Thm 3.6): for SE(3), `ad = [[ω×, ρ×], [0, ω×]]` and `Q(ρ, ω) = D Jl_SO(3)(ω)[ρ]`, the
//! derivative of SO(3)'s `Jl = 1 + a W + b W²` along ρ (`W = ω×`, `θ = |ω|`, `dθ = ω·ρ/θ`):
//! `Q = (ω·ρ)(a'/θ) W + a P + (ω·ρ)(b'/θ) W² + b (P W + W P)`, `P = ρ×`. For SE(2), `ad = [[θ J,
//! -J ρ], [0, 0]]` (J the quarter turn), so `Jl = [[V(θ), h(θ J)(-J ρ)], [0, 1]]` with `h(x) = (eˣ - 1
//! - x)/x²`. The tests check every matrix against central differences of `integrate_block` and
//! `difference_block`, and `Jl Jl⁻¹ = 1`.
//!
//! Symbols: `tau` τ a tangent vector (`[ρ; ω]` for SE(3), `(ρx, ρy, θ)` for SE(2)), `a = (1 - cos θ)/θ²`,
//! `b = (θ - sin θ)/θ³`, `c = (1 - (θ/2) cot(θ/2))/θ²`; every matrix is `nv × nv` in the top-left of a
//! [`Square`].

use super::{
    difference_block, exp3, left_jacobian_times, quaternion_matrix, sinc, theta_minus_sin_over_cube, Block,
    SERIES_BELOW,
};
use crate::spatial::{skew, Mat3, Vec3};

/// A block's Jacobian: its top-left `nv × nv` (6 for a free-flyer, 3 for SO(3) and SE(2), 1 for a
/// 1-DOF joint), zeros elsewhere.
pub type Square = nalgebra::SMatrix<f64, 6, 6>;

/// The Jacobians of a block's group at a tangent vector τ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroupJacobians {
    /// `Ad(Exp(τ))`.
    pub ad: Square,
    /// The left Jacobian `Jl(τ)`.
    pub jl: Square,
    /// Its inverse `Jl(τ)⁻¹`, in closed form.
    pub jl_inv: Square,
}

/// `Σ_{k=1..8} (-1)ᵏ 2k θ²⁽ᵏ⁻¹⁾/(2k+p)!` in `t2` = θ² by Horner's rule: `a'(θ)/θ` for `p = 2`,
/// `b'(θ)/θ` for `p = 3` (the series of a and b differentiated term by term; the first omitted term
/// is below 1e-18 for θ < 0.5).
fn derivative_series(t2: f64, p: u32) -> f64 {
    let factorial = |m: u32| (1..=m).map(f64::from).product::<f64>();
    (1..=8u32).rev().fold(0.0, |acc, k| {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        acc * t2 + sign * f64::from(2 * k) / factorial(2 * k + p)
    })
}

/// `(a, b, c, a'/θ, b'/θ)` of SO(3) at θ >= 0, each without cancellation: `a = sinc²(θ/2)/2`, b by
/// its series below 0.5, c by its series below [`SERIES_BELOW`], the derivatives by theirs below 0.5.
fn so3_coefficients(theta: f64) -> (f64, f64, f64, f64, f64) {
    let t2 = theta * theta;
    let s = sinc(theta / 2.0);
    let a = 0.5 * s * s;
    let b = theta_minus_sin_over_cube(theta);
    let c = if theta < SERIES_BELOW {
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    } else {
        let half = theta / 2.0;
        (1.0 - half * half.cos() / half.sin()) / t2
    };
    let (da, db) = if theta < 0.5 {
        (derivative_series(t2, 2), derivative_series(t2, 3))
    } else {
        // a' = sin θ/θ² - 2(1 - cos θ)/θ³, b' = (1 - cos θ)/θ³ - 3(θ - sin θ)/θ⁴, over θ
        let one_minus_cos = 2.0 * (theta / 2.0).sin().powi(2);
        (
            (theta * theta.sin() - 2.0 * one_minus_cos) / t2.powi(2),
            (theta * one_minus_cos - 3.0 * (theta - theta.sin())) / (t2 * t2 * theta),
        )
    };
    (a, b, c, da, db)
}

/// `Jl(ω) = 1 + a W + b W²`, `Jl(ω)⁻¹ = 1 - W/2 + c W²` of SO(3) (`W = ω×`).
fn so3_left_jacobians(omega: Vec3) -> (Mat3, Mat3) {
    let (a, b, c, _, _) = so3_coefficients(omega.norm());
    let w = skew(&omega);
    let w2 = w * w;
    (Mat3::identity() + w * a + w2 * b, Mat3::identity() - w * 0.5 + w2 * c)
}

fn set3(m: &mut Square, row: usize, col: usize, block: &Mat3) {
    m.fixed_view_mut::<3, 3>(row, col).copy_from(block);
}

/// SO(3) at ω: `Ad = R(Exp(ω))`, `Jl`, `Jl⁻¹`.
fn so3(tau: &[f64]) -> GroupJacobians {
    let omega = Vec3::new(tau[0], tau[1], tau[2]);
    let (jl, jl_inv) = so3_left_jacobians(omega);
    let (mut out, r) = (
        GroupJacobians::zero(),
        quaternion_matrix(&exp3([tau[0], tau[1], tau[2]])[..]),
    );
    set3(&mut out.ad, 0, 0, &r);
    set3(&mut out.jl, 0, 0, &jl);
    set3(&mut out.jl_inv, 0, 0, &jl_inv);
    out
}

/// SE(3) at τ = [ρ; ω]: `Ad(Exp(τ)) = [[R, (Jl(ω) ρ)× R], [0, R]]`, `Jl = [[Jl(ω), Q], [0, Jl(ω)]]`,
/// `Jl⁻¹ = [[Jl(ω)⁻¹, -Jl(ω)⁻¹ Q Jl(ω)⁻¹], [0, Jl(ω)⁻¹]]` (module documentation).
fn se3(tau: &[f64]) -> GroupJacobians {
    let (rho, omega) = (Vec3::new(tau[0], tau[1], tau[2]), Vec3::new(tau[3], tau[4], tau[5]));
    let (a, b, _, da, db) = so3_coefficients(omega.norm());
    let (jl3, jl3_inv) = so3_left_jacobians(omega);
    let (w, p) = (skew(&omega), skew(&rho));
    let dot = omega.dot(&rho);
    let q = w * (dot * da) + p * a + w * w * (dot * db) + (p * w + w * p) * b;
    let r = quaternion_matrix(&exp3([tau[3], tau[4], tau[5]])[..]);
    let mut out = GroupJacobians::zero();
    for k in [0, 3] {
        set3(&mut out.ad, k, k, &r);
        set3(&mut out.jl, k, k, &jl3);
        set3(&mut out.jl_inv, k, k, &jl3_inv);
    }
    // Exp(τ) = (R, p) with p = V(ω) ρ = Jl(ω) ρ (as `exp6`)
    let p_exp = left_jacobian_times([tau[3], tau[4], tau[5]], omega.norm(), [tau[0], tau[1], tau[2]]);
    set3(&mut out.ad, 0, 3, &(skew(&Vec3::from(p_exp)) * r));
    set3(&mut out.jl, 0, 3, &q);
    set3(&mut out.jl_inv, 0, 3, &(-(jl3_inv * q * jl3_inv)));
    out
}

/// SE(2) at τ = (ρx, ρy, θ): `Jl = [[V, u], [0, 1]]` with `V = [[A, -B], [B, A]]` (A = sin θ/θ,
/// B = (1 - cos θ)/θ) and `u = h(θ J)(-J ρ) = d ρ - e J ρ` (d = (θ - sin θ)/θ², e = (1 - cos θ)/θ²);
/// `Jl⁻¹ = [[V⁻¹, -V⁻¹ u], [0, 1]]`, `V⁻¹ = [[α, θ/2], [-θ/2, α]]`, α = (θ/2) cot(θ/2);
/// `Ad(Exp(τ)) = [[R, (t_y, -t_x)], [0, 1]]` for `Exp(τ) = (R, t = V ρ)` (Solà et al. eqs. 156-159).
fn se2(tau: &[f64]) -> GroupJacobians {
    let (rx, ry, theta) = (tau[0], tau[1], tau[2]);
    let big_a = sinc(theta);
    let s = sinc(theta / 2.0);
    let e = 0.5 * s * s;
    let big_b = e * theta;
    let d = theta * theta_minus_sin_over_cube(theta.abs());
    let u = [d * rx + e * ry, d * ry - e * rx]; // J ρ = (-ρy, ρx)
    let alpha = (theta / 2.0).cos() / s;
    let (c, sn) = (theta.cos(), theta.sin());
    let (tx, ty) = (big_a * rx - big_b * ry, big_b * rx + big_a * ry);
    let mut out = GroupJacobians::zero();
    let rows = |m: &mut Square, entries: [[f64; 3]; 3]| {
        for (i, row) in entries.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                m[(i, j)] = *x;
            }
        }
    };
    let inv_u = [
        -(alpha * u[0] + theta / 2.0 * u[1]),
        -(-theta / 2.0 * u[0] + alpha * u[1]),
    ];
    rows(&mut out.ad, [[c, -sn, ty], [sn, c, -tx], [0.0, 0.0, 1.0]]);
    rows(
        &mut out.jl,
        [[big_a, -big_b, u[0]], [big_b, big_a, u[1]], [0.0, 0.0, 1.0]],
    );
    rows(
        &mut out.jl_inv,
        [
            [alpha, theta / 2.0, inv_u[0]],
            [-theta / 2.0, alpha, inv_u[1]],
            [0.0, 0.0, 1.0],
        ],
    );
    out
}

impl GroupJacobians {
    fn zero() -> Self {
        Self {
            ad: Square::zeros(),
            jl: Square::zeros(),
            jl_inv: Square::zeros(),
        }
    }

    /// `(Ad(Exp(τ)), Jl(τ), Jl(τ)⁻¹)` of `block`'s group at the tangent vector `tau` (`block.nv()`
    /// numbers); for a 1-DOF joint (the real line) all three are 1.
    pub fn at(block: Block, tau: &[f64]) -> Self {
        match block {
            Block::Spherical => so3(tau),
            Block::FreeFlyer => se3(tau),
            Block::Planar => se2(tau),
            Block::Scalar => {
                let mut one = Self::zero();
                (one.ad[(0, 0)], one.jl[(0, 0)], one.jl_inv[(0, 0)]) = (1.0, 1.0, 1.0);
                one
            }
        }
    }
}

/// `(∂(q ⊕ v dt)/∂q, ∂(q ⊕ v dt)/∂v)` of one block (neither depends on q): `Ad(Exp(-v dt))` and
/// `Jr(v dt) dt = Jl(-v dt) dt`; 1 and dt for a 1-DOF joint.
pub fn integrate_jacobians_block(block: Block, v: &[f64], dt: f64) -> (Square, Square) {
    let mut minus = [0.0; 6];
    for (m, x) in minus.iter_mut().zip(&v[..block.nv()]) {
        *m = -(x * dt);
    }
    let j = GroupJacobians::at(block, &minus[..block.nv()]);
    (j.ad, j.jl * dt)
}

/// `(∂ difference(q0, q1)/∂q0, ∂ difference(q0, q1)/∂q1)` of one block: `-Jl⁻¹(d)` and
/// `Jr⁻¹(d) = Jl⁻¹(-d)`, `d = difference(q0, q1)`; -1 and 1 for a 1-DOF joint.
pub fn difference_jacobians_block(block: Block, q0: &[f64], q1: &[f64]) -> (Square, Square) {
    let nv = block.nv();
    let mut d = [0.0; 6];
    difference_block(block, q0, q1, &mut d[..nv]);
    let minus: Vec<f64> = d[..nv].iter().map(|x| -x).collect();
    (
        -GroupJacobians::at(block, &d[..nv]).jl_inv,
        GroupJacobians::at(block, &minus).jl_inv,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lie::integrate_block;
    use crate::rng::Rng;

    const BLOCKS: [Block; 4] = [Block::Scalar, Block::Spherical, Block::FreeFlyer, Block::Planar];

    fn random_q(block: Block, rng: &mut Rng) -> Vec<f64> {
        let (mut q, mut out) = (vec![0.0; block.nq()], vec![0.0; block.nq()]);
        block.neutral(&mut q);
        let v = rng.vector(block.nv(), -2.0, 2.0);
        integrate_block(block, &q, &v, 1.0, &mut out);
        out
    }

    /// A tangent vector whose rotation angle is `angle` (the series branches below 1e-2 and 0.5,
    /// the closed forms up to near π).
    fn tangent(block: Block, rng: &mut Rng, angle: f64) -> Vec<f64> {
        let mut v = rng.vector(block.nv(), -1.0, 1.0);
        let rot = match block {
            Block::Spherical => 0..3,
            Block::FreeFlyer => 3..6,
            Block::Planar => 2..3,
            Block::Scalar => return v,
        };
        let norm = v[rot.clone()].iter().map(|x| x * x).sum::<f64>().sqrt();
        v[rot].iter_mut().for_each(|x| *x *= angle / norm);
        v
    }

    fn close(got: &Square, want: &Square, nv: usize, tol: f64, what: &str) {
        let err = (0..nv)
            .flat_map(|i| (0..nv).map(move |j| (i, j)))
            .map(|(i, j)| (got[(i, j)] - want[(i, j)]).abs())
            .fold(0.0, f64::max);
        assert!(err < tol, "{what}: max error {err:.3e}\ngot {got}\nwant {want}");
    }

    /// Column j of `∂f/∂x` by central differences along `x ⊕ (±h e_j)`, read back in f's tangent
    /// space at `f(x)` with `difference`.
    fn numeric(nv_in: usize, out: Block, f: &dyn Fn(usize, f64) -> Vec<f64>, at: &[f64]) -> Square {
        let h = 1e-6;
        let mut m = Square::zeros();
        for j in 0..nv_in {
            let (mut plus, mut minus) = (vec![0.0; out.nv()], vec![0.0; out.nv()]);
            difference_block(out, at, &f(j, h), &mut plus);
            difference_block(out, at, &f(j, -h), &mut minus);
            for i in 0..out.nv() {
                m[(i, j)] = (plus[i] - minus[i]) / (2.0 * h);
            }
        }
        m
    }

    fn step(block: Block, q: &[f64], j: usize, h: f64) -> Vec<f64> {
        let mut e = vec![0.0; block.nv()];
        e[j] = h;
        let mut out = vec![0.0; block.nq()];
        integrate_block(block, q, &e, 1.0, &mut out);
        out
    }

    #[test]
    fn integrate_jacobians_match_central_differences() {
        let mut rng = Rng::new(21);
        for block in BLOCKS {
            for angle in [1e-3, 0.3, 1.2, 2.9] {
                let (q, v, dt) = (random_q(block, &mut rng), tangent(block, &mut rng, angle), 0.7);
                let mut f0 = vec![0.0; block.nq()];
                integrate_block(block, &q, &v, dt, &mut f0);
                let (d_q, d_v) = integrate_jacobians_block(block, &v, dt);
                let along_q = |j: usize, h: f64| {
                    let mut out = vec![0.0; block.nq()];
                    integrate_block(block, &step(block, &q, j, h), &v, dt, &mut out);
                    out
                };
                let along_v = |j: usize, h: f64| {
                    let mut w = v.clone();
                    w[j] += h;
                    let mut out = vec![0.0; block.nq()];
                    integrate_block(block, &q, &w, dt, &mut out);
                    out
                };
                let what = format!("{block:?} at angle {angle}");
                close(
                    &d_q,
                    &numeric(block.nv(), block, &along_q, &f0),
                    block.nv(),
                    1e-8,
                    &format!("dq {what}"),
                );
                close(
                    &d_v,
                    &numeric(block.nv(), block, &along_v, &f0),
                    block.nv(),
                    1e-8,
                    &format!("dv {what}"),
                );
            }
        }
    }

    #[test]
    fn difference_jacobians_match_central_differences() {
        let mut rng = Rng::new(22);
        for block in BLOCKS {
            for angle in [1e-3, 0.3, 1.2, 2.9] {
                let q0 = random_q(block, &mut rng);
                let mut q1 = vec![0.0; block.nq()];
                integrate_block(block, &q0, &tangent(block, &mut rng, angle), 1.0, &mut q1);
                let (d0, d1) = difference_jacobians_block(block, &q0, &q1);
                // the difference is a tangent vector: finite differences of it directly
                let numeric_of = |moved: &dyn Fn(usize, f64) -> Vec<f64>| {
                    let h = 1e-6;
                    let mut m = Square::zeros();
                    for j in 0..block.nv() {
                        let (p, n) = (moved(j, h), moved(j, -h));
                        for i in 0..block.nv() {
                            m[(i, j)] = (p[i] - n[i]) / (2.0 * h);
                        }
                    }
                    m
                };
                let diff = |a: &[f64], b: &[f64]| {
                    let mut d = vec![0.0; block.nv()];
                    difference_block(block, a, b, &mut d);
                    d
                };
                let what = format!("{block:?} at angle {angle}");
                let n0 = numeric_of(&|j, h| diff(&step(block, &q0, j, h), &q1));
                let n1 = numeric_of(&|j, h| diff(&q0, &step(block, &q1, j, h)));
                close(&d0, &n0, block.nv(), 1e-8, &format!("dq0 {what}"));
                close(&d1, &n1, block.nv(), 1e-8, &format!("dq1 {what}"));
            }
        }
    }

    #[test]
    fn the_inverse_left_jacobian_inverts_it_on_every_branch() {
        let mut rng = Rng::new(23);
        for block in BLOCKS {
            for angle in [0.0, 1e-7, 5e-3, 0.2, 0.7, 2.0, 3.1] {
                let j = GroupJacobians::at(block, &tangent(block, &mut rng, angle));
                let nv = block.nv();
                let product = j.jl * j.jl_inv;
                let identity = Square::identity();
                close(
                    &product,
                    &identity,
                    nv,
                    1e-14,
                    &format!("Jl Jl^-1 {block:?} at {angle}"),
                );
            }
        }
    }
}
