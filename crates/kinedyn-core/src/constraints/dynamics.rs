//! Forward dynamics of a model with closed loops: `qdd` and the loop forces `lambda` of
//!
//! ```text
//! M qdd + h = tau + J^T lambda,     J qdd + gamma = 0
//! ```
//!
//! (`h = C qd + g + friction - sum_i J_i^T f_ext_i`, the RNEA at `qdd = 0`; `J`, `gamma` of
//! `kinematics.rs`), solved by the proximal method of multipliers of Carpentier, Budhiraja &
//! Mansard, "Proximal and sparse resolution of constrained dynamic equations", RSS 2021 (§IV,
//! Algorithm 1; Pinocchio's `constraintDynamics`), with the Delassus matrix formed densely (a
//! robot's loops have few rows):
//!
//! ```text
//! qdd_free = M^-1 (tau - h)                 (CRBA, sparse L^T D L: RBDA §6.5)
//! A = J M^-1 J^T,   b = -(J qdd_free + gamma)
//! (A + mu 1) lambda_{k+1} = b + mu lambda_k  (the proximal point step on the dual)
//! qdd = qdd_free + M^-1 J^T lambda
//! ```
//!
//! `A + mu 1` is positive definite for any `mu > 0`, so redundant rows (a planar four-bar's
//! out-of-plane row, which is always zero; a Delta robot's loops sharing directions) need no
//! pivoting: along a direction `v` with `J^T v = 0`, `lambda` keeps its start (zero), so the
//! iteration converges to the multipliers of least norm, and `qdd` (which `M^-1 J^T v = 0` leaves
//! alone) is the unique constrained acceleration. Each step shrinks the error along an eigen
//! direction of `A` with eigenvalue `s` by `mu / (s + mu)`; the residual `A lambda_{k+1} - b`
//! equals `mu (lambda_k - lambda_{k+1})` exactly, which is the stopping test.
//!
//! `lambda` is the force (a weld: force then moment) that the loop applies to frame a's link, in
//! base axes, the moment about frame a's origin; frame b's link receives the opposite.

use super::dense::{dot, lane_max_abs, ldlt, ldlt_solve};
use super::kinematics::{gamma_after_accelerations, jacobian_after_kinematics};
use super::LoopData;
use crate::algorithms::crba::crba;
use crate::algorithms::kinematics::world_poses;
use crate::algorithms::minv::{ltdl, ltdl_solve};
use crate::algorithms::rnea;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::scalar::Real;
use crate::spatial::splat3;

/// Settings of the proximal iteration.
#[derive(Clone, Copy, Debug)]
pub struct Proximal {
    /// The proximal weight, relative to the largest diagonal entry of `A`.
    pub mu: f64,
    /// Iterations before the constraints are declared inconsistent.
    pub max_iter: usize,
    /// Stop when `|J qdd + gamma|` is below this times `|J qdd_free + gamma|` (largest entries).
    pub accuracy: f64,
}

/// The defaults: `mu = 1e-9` relative (two or three steps on a well-posed loop), 200 steps at most.
pub const PROXIMAL: Proximal = Proximal {
    mu: 1e-9,
    max_iter: 200,
    accuracy: 1e-12,
};

/// `[qdd (n); lambda (m)]` written to `out`; `f_ext` as in `algorithms::rnea`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn constrained_forward_dynamics<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    q: &[T],
    qd: &[T],
    tau: &[T],
    f_ext: Option<&[T]>,
    settings: &Proximal,
    out: &mut [T],
) -> Result<()> {
    let mut scratch = std::mem::take(&mut data.loops);
    scratch.fit(model);
    let result = solve(model, data, &mut scratch, [q, qd, tau], f_ext, settings, out);
    data.loops = scratch;
    result
}

#[inline(always)]
fn solve<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    s: &mut LoopData<T>,
    [q, qd, tau]: [&[T]; 3],
    f_ext: Option<&[T]>,
    settings: &Proximal,
    out: &mut [T],
) -> Result<()> {
    let (n, m) = (model.n, model.loop_rows());
    // tau - h, h = rnea(q, qd, 0, f_ext)
    s.free.fill(T::zero());
    let h = rnea(model, data, q, qd, &s.free, f_ext);
    for i in 0..n {
        s.free[i] = tau[i] - h[i];
    }
    if m > 0 {
        // J and gamma from RNEA's forward pass at qdd = 0 (its joint transforms, twists and
        // accelerations, gravity taken off), not from two more passes of forward kinematics
        if f_ext.is_none() {
            world_poses(model, data); // RNEA with f_ext has them already
        }
        jacobian_after_kinematics(model, data, &mut s.j);
        let gravity = -splat3::<T>(&model.gravity);
        gamma_after_accelerations(model, data, gravity, &mut s.gamma);
    }
    // qdd_free = M^-1 (tau - h)
    crba(model, data, q);
    ltdl(model, data)?;
    ltdl_solve(model, &data.m2, &mut s.free);
    if m == 0 {
        out[..n].copy_from_slice(&s.free);
        return Ok(());
    }
    // Y = M^-1 J^T, one column per constraint row
    for k in 0..m {
        let y = &mut s.y[k * n..(k + 1) * n];
        y.copy_from_slice(&s.j[k * n..(k + 1) * n]);
        ltdl_solve(model, &data.m2, y);
    }
    // A = J Y (symmetric), b = -(J qdd_free + gamma)
    for k in 0..m {
        let jk = &s.j[k * n..(k + 1) * n];
        for l in 0..=k {
            let v = dot(jk, &s.y[l * n..(l + 1) * n]);
            s.a[k * m + l] = v;
            s.a[l * m + k] = v;
        }
        s.b[k] = -(dot(jk, &s.free) + s.gamma[k]);
    }
    // mu per state, relative to A's largest diagonal entry
    let mut scale = [0.0f64; 16];
    for k in 0..m {
        for (l, x) in scale[..T::LANES].iter_mut().enumerate() {
            *x = x.max(s.a[k * m + k].lane(l));
        }
    }
    let size_b = lane_max_abs(&s.b);
    let mut mu = T::zero();
    for (l, a) in scale.iter().enumerate().take(T::LANES) {
        mu.set_lane(l, settings.mu * a.max(f64::MIN_POSITIVE));
    }
    for k in 0..m {
        s.a[k * m + k] += mu;
    }
    ldlt(&mut s.a, m);
    s.lambda.fill(T::zero());
    let mut converged = false;
    for _ in 0..settings.max_iter {
        // (A + mu 1) lambda_new = b + mu lambda
        for k in 0..m {
            s.rhs[k] = s.b[k] + mu * s.lambda[k];
        }
        ldlt_solve(&s.a, m, &mut s.rhs);
        // A lambda_new - b = mu (lambda - lambda_new)
        for k in 0..m {
            let new = s.rhs[k];
            s.rhs[k] = mu * (s.lambda[k] - new);
            s.lambda[k] = new;
        }
        let (residual, size) = (lane_max_abs(&s.rhs), lane_max_abs(&s.lambda));
        // the rounding floor of the residual: a few ulps of A lambda
        converged = (0..T::LANES)
            .all(|l| residual[l] <= (settings.accuracy * size_b[l]).max(64.0 * f64::EPSILON * scale[l] * size[l]));
        if converged {
            break;
        }
    }
    if !converged {
        let residual = lane_max_abs(&s.rhs);
        let l = (0..T::LANES).fold(0, |b, l| if residual[l] > residual[b] { l } else { b });
        let k = (0..m).fold(0, |b, k| {
            if s.rhs[k].lane(l).abs() > s.rhs[b].lane(l).abs() {
                k
            } else {
                b
            }
        });
        let (lp, row) = model.loop_of_row(k);
        return Err(Error::InvalidInput(format!(
            "constrained forward dynamics: the loop constraints cannot all hold at this state (loop '{}', row {row}: \
             J qdd + gamma = {:e} after {} proximal steps): the loops conflict here (a singular configuration of the \
             mechanism, or a state far from closed: project it first)",
            lp.name,
            s.rhs[k].lane(l),
            settings.max_iter
        )));
    }
    // qdd = qdd_free + Y lambda
    out[..n].copy_from_slice(&s.free);
    for k in 0..m {
        let (y, lk) = (&s.y[k * n..(k + 1) * n], s.lambda[k]);
        for i in 0..n {
            out[i] += y[i] * lk;
        }
    }
    out[n..n + m].copy_from_slice(&s.lambda);
    Ok(())
}
