//! Inverse kinematics: closed forms where the geometry has one, Levenberg-Marquardt everywhere.
//!
//! **Pose error** (base axes, `[linear; angular]` as everywhere in kinedyn):
//!
//! ```text
//! e(q) = [ p_d - p(q) ;  log(R_d R(q)^T) ]          (6,)
//! ```
//!
//! the log map of the pose error on R^3 x SO(3) expressed in base axes; to first order
//! `de = J(q) dq` with `J` the world-aligned geometric Jacobian (`Reference::World`), which is why
//! masks and weights act on base-axis components (x, y, z, rx, ry, rz).
//!
//! **Numeric solver** (`numeric_ik`): Levenberg-Marquardt with Sugihara's damping, "Solvability-
//! unconcerned inverse kinematics by the Levenberg-Marquardt method", IEEE T-RO 27(5), 2011:
//!
//! ```text
//! (J^T W J + lambda I) dq = J^T W e,     lambda = E + mu,     E = 1/2 e^T W e
//! ```
//!
//! where Sugihara's constant bias `w_bar` (`lambda_min`) is made adaptive as in Marquardt's method:
//! `mu` starts at `lambda_min`, shrinks tenfold after an accepted step (to 1e-14, so that the last
//! steps are Gauss-Newton steps even near a singularity) and grows tenfold after a rejected one.
//! The system is solved in task space, `dq = A^T (A A^T + lambda I)^-1 W^1/2 e` with `A = W^1/2 J` (a 6 x 6
//! Cholesky solve whatever n is). A step is accepted only if it lowers E; joint limits are kept by
//! projecting q on its box after each step, holding the joints that rest on a limit the step
//! would cross (an active set); a run that stalls restarts from a random
//! configuration inside the limits (seeded, so batches are reproducible).
//!
//! **On the configuration manifold** (floating, spherical, planar joints): q has nq entries, the
//! step `dq` and the Jacobian's columns nv (one per velocity coordinate, the joint's velocity in its
//! child frame), and the update is `q ⊕ dq` ([`crate::Model::integrate_configuration`]: `M Exp(dq)` on
//! SE(3), SO(3) or SE(2)), so quaternions stay unit; `e` is unchanged, and to first order
//! `e(q ⊕ dq) = e(q) - J dq`. Only 1-DOF coordinates have limits; restarts draw uniform rotations.
//! With a [`Reduction`] (mimic joints) the solver works in the reduced coordinates, with `J G`.
//!
//! **Closed forms** (`analytic`, `subproblems`): candidates from the Paden-Kahan subproblems, mapped
//! to q (`q = theta - offset`, revolute angles moved by 2 pi k into the limits, nearest the caller's
//! reference), verified by forward kinematics and refined by a few Gauss-Newton steps
//! (`analytic_solutions`).
//!
//! Files: `numeric.rs` (the solver, its settings and start checks), `reduction.rs` (mimic joints),
//! `analytic.rs` (structures and their closed forms), `prismatic.rs` (arms
//! whose first joint is prismatic), `general6r.rs` (any 6R chain: Raghavan & Roth's
//! elimination as an eigenvalue problem), `chain.rs` (a structure found from either end of the
//! chain, and the most solutions it has), `redundant.rs` (seven-joint arms: a held joint, the arm
//! angle of SRS arms), `self_motion.rs` (an SRS arm's arm-angle intervals inside the joint limits, in
//! closed form), `subproblems.rs` (Paden-Kahan), `solutions.rs` (closed-form candidates to
//! checked joint vectors, with the statement of completeness); the pose error is here.
//!
//! | symbol   | here          | meaning                                                  |
//! |----------|---------------|----------------------------------------------------------|
//! | `e`      | `e: [f64; 6]` | pose error `[p_d - p; log(R_d R^T)]`, base axes          |
//! | `W`      | `weights`     | diagonal weights (mask) of the six error components      |
//! | `J`      | `jac`         | world-aligned geometric Jacobian, 6 x nv row-major        |
//! | `lambda` | `lambda`      | damping                                                  |

pub mod analytic;
pub mod chain;
// index loops keep the equations' subscripts (q: equation, m: sample, p: power)
#[allow(clippy::needless_range_loop, clippy::manual_memcpy)]
pub mod general6r;
mod numeric;
mod prismatic;
mod reduction;
pub mod redundant;
mod self_motion;
mod solutions;
pub mod subproblems;

pub use analytic::{AnalyticIk, Met, Screw, Structure};
pub use chain::ChainIk;
pub use numeric::{check_start, numeric_ik, numeric_ik_reduced, solver_sizes, Outcome, Settings, UNIT_TOLERANCE};
pub use reduction::Reduction;
pub use redundant::{Redundant, SRS_MAX_SOLUTIONS};
pub use solutions::{
    analytic_solutions, chain_screws, detect_analytic, hadamard_ratio, AnalyticOutcome, Check, MERGE_DISTANCE,
    MERGE_RATIO,
};

use crate::spatial::{Mat3, Transform, Vec3};
use std::f64::consts::PI;

/// `log(R)` of a rotation matrix as a rotation vector (angle in [0, pi]), accurate near 0 and pi.
pub fn log_so3(r: &Mat3) -> Vec3 {
    // vee(R - R^T) = 2 sin(theta) w,  trace(R) = 1 + 2 cos(theta)
    let v = Vec3::new(r[(2, 1)] - r[(1, 2)], r[(0, 2)] - r[(2, 0)], r[(1, 0)] - r[(0, 1)]);
    let s = 0.5 * v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    let theta = s.atan2(c);
    if theta < 1e-6 {
        // theta / (2 sin theta) = 1/2 + theta^2 / 12 + ...
        return v * (0.5 + theta * theta / 12.0);
    }
    if theta < PI - 1e-4 {
        return v * (theta / (2.0 * s));
    }
    // near pi: (R + R^T)/2 - cos(theta) I = (1 - cos(theta)) w w^T; w from its largest column, sign from v
    let b = ((r + r.transpose()) * 0.5 - Mat3::identity() * c) / (1.0 - c);
    let k = (0..3)
        .max_by(|&i, &j| b[(i, i)].partial_cmp(&b[(j, j)]).unwrap())
        .unwrap();
    let mut w = b.column(k).into_owned() / b[(k, k)].max(1e-300).sqrt();
    w.normalize_mut();
    if w.dot(&v) < 0.0 {
        w = -w;
    }
    w * theta
}

/// Pose error `[p_d - p; log(R_d R^T)]` of `current` towards `target` (base axes).
#[inline]
pub fn pose_error(current: &Transform, target: &Transform) -> [f64; 6] {
    let dp = target.trans - current.trans;
    let dr = log_so3(&(target.rot * current.rot.transpose()));
    [dp.x, dp.y, dp.z, dr.x, dr.y, dr.z]
}

/// Norms of the weighted position and orientation parts (components with weight 0 are ignored).
#[inline]
fn residuals(e: &[f64; 6], weights: &[f64; 6]) -> (f64, f64) {
    let mut sq = [0.0; 2];
    for k in 0..6 {
        if weights[k] > 0.0 {
            sq[k / 3] += e[k] * e[k];
        }
    }
    (sq[0].sqrt(), sq[1].sqrt())
}

/// Weighted cost `E = 1/2 e^T W e`.
#[inline]
fn cost(e: &[f64; 6], weights: &[f64; 6]) -> f64 {
    0.5 * (0..6).map(|k| weights[k] * e[k] * e[k]).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::axis_angle;

    #[test]
    fn log_is_the_inverse_of_exp() {
        for &(x, y, z) in &[
            (0.3, -0.2, 0.5),
            (1e-8, 0.0, 2e-8),
            (0.0, 0.0, PI - 1e-9),
            (PI / 3f64.sqrt(), -PI / 3f64.sqrt(), PI / 3f64.sqrt() - 1e-7),
        ] {
            let v = Vec3::new(x, y, z);
            let r = axis_angle(&v.normalize(), v.norm());
            let back = log_so3(&r);
            assert!((back - v).norm() < 1e-7, "{v:?} -> {back:?}");
        }
    }
}
