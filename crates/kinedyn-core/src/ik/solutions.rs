//! Closed-form solutions as joint vectors: a chain's screws read from the model, the candidates of
//! [`super::analytic`] mapped to q (`q = theta - offset`, revolute angles moved by 2 pi k into the
//! limits nearest the caller's reference), verified by forward kinematics and refined by a few
//! Gauss-Newton steps of the numeric solver.
//!
//! | symbol   | here        | meaning                                                     |
//! |----------|-------------|-------------------------------------------------------------|
//! | `theta`  | `theta`     | joint coordinate of the product of exponentials, q + offset |
//! | `q`      | `q`         | the model's joint vector                                    |

use super::analytic::Screw;
use super::chain::ChainIk;
use super::{numeric_ik, pose_error, residuals, subproblems, Settings};
use crate::algorithms::jacobian::{frame_jacobian, frame_pose_at, Reference};
use crate::algorithms::kinematics::parent_from_body;
use crate::data::Data;
use crate::joint::JointKind;
use crate::model::Model;
use crate::spatial::Transform;
use std::f64::consts::PI;

/// The chain's joints as screws at theta = 0 (q = -offset) and the home pose of `frame`, if
/// `frame` is carried by the last body of a serial chain moved by every joint (`parent[i] = i - 1`).
pub fn chain_screws(model: &Model, data: &mut Data, frame: usize) -> Option<(Vec<Screw>, Transform)> {
    let n = model.n;
    if !model.plain {
        return None; // a multi-DOF joint is no screw
    }
    if model.frames[frame].body != Some(n.checked_sub(1)?) || (0..n).any(|i| model.parent[i] != i.checked_sub(1)) {
        return None;
    }
    let zero: Vec<f64> = model.offset.iter().map(|o| -o).collect();
    let home = frame_pose_at(model, data, &zero, frame);
    let screws = (0..n)
        .map(|i| {
            // body frame = joint frame at theta = 0: the axis through its origin
            let x = &data.world_from_body[i];
            let w = x.rot * model.joints[i].axis;
            match model.joints[i].kind {
                JointKind::Revolute => Screw::Revolute(subproblems::Axis { w, r: x.trans }),
                JointKind::Prismatic => Screw::Prismatic(w),
            }
        })
        .collect();
    Some((screws, home))
}

/// The closed-form solver of `frame`'s chain, if its geometry has one, from either end (see
/// `analytic` and `chain`).
pub fn detect_analytic(model: &Model, data: &mut Data, frame: usize) -> Option<ChainIk> {
    let (screws, home) = chain_screws(model, data, frame)?;
    ChainIk::detect(screws, home)
}

/// Solutions of a closed-form solve after mapping, checking and limits, with the statement of
/// completeness every result carries (`docs/ik.md`, "Completeness").
#[derive(Clone, Debug, Default)]
pub struct AnalyticOutcome {
    /// Joint vectors (q, offsets removed), nearest to the reference first.
    pub solutions: Vec<Vec<f64>>,
    pub position_error: Vec<f64>,
    pub orientation_error: Vec<f64>,
    /// Distinct verified solutions before the joint-limit filter.
    pub found: usize,
    /// A non-isolated solution set was met (a free joint was set from the reference).
    pub singular: bool,
    /// The most real solutions the method can have for one target (its structure's bound).
    pub max_solutions: usize,
    /// The largest position or orientation residual among the found solutions (0 when none).
    pub worst_residual: f64,
    /// Branches merge at this target: a subproblem met a double root, two candidates coincide
    /// or nearly do (closer than `MERGE_DISTANCE`), or a solution's Jacobian (the solved joints' columns) is singular
    /// (Hadamard ratio below `MERGE_RATIO`; tested only when fewer than `max_solutions` were found
    /// or the solver met a free joint: all `max_solutions` roots found distinct are simple).
    pub merged: bool,
}

/// Two solutions closer than this (rad or m, largest coordinate difference, angles modulo 2 pi)
/// count as branches that merge.
pub const MERGE_DISTANCE: f64 = 1e-6;
/// A Jacobian whose Hadamard ratio `sqrt(det(A^T A)) / prod |a_i|` (A: the solved columns, or
/// rows when there are more columns than rows) is below this counts as singular: the ratio is 1
/// for orthogonal columns, scale-free, and goes to 0 linearly in the distance to the singularity.
pub const MERGE_RATIO: f64 = 1e-6;

/// The integer nearest `x` (ties to even): adding and removing 1.5 2^52 rounds without a call to
/// `round`, which baseline x86-64 lacks as an instruction; `|x| >= 2^51` is already an integer.
#[inline]
fn round(x: f64) -> f64 {
    const ROUND: f64 = 6_755_399_441_055_744.0;
    if x.abs() < 2_251_799_813_685_248.0 {
        (x + ROUND) - ROUND
    } else {
        x
    }
}

/// Pose of `frame` at `q`: the products of `world_from_body` along the frame body's support, in
/// the order `forward_kinematics` takes them (the same numbers), without filling `Data`.
fn frame_pose_lean(model: &Model, q: &[f64], frame: usize) -> Transform {
    let f = &model.frames[frame];
    let Some(body) = f.body else { return f.body_from_frame };
    let mut support = model.support[body].iter();
    let first = support.next().copied().unwrap_or(body);
    let mut world_from_body = parent_from_body(model, q, first);
    for &i in support {
        world_from_body = world_from_body * parent_from_body(model, q, i);
    }
    if f.body_from_frame == Transform::identity() {
        world_from_body
    } else {
        world_from_body * f.body_from_frame
    }
}

/// Move a revolute angle by 2 pi k: inside `[lo, hi]` nearest `reference` when possible, else
/// nearest `reference`.
#[inline]
fn wrap_angle(x: f64, lo: f64, hi: f64, reference: f64) -> f64 {
    let two_pi = 2.0 * PI;
    let near = x + two_pi * round((reference - x) / two_pi);
    if near >= lo && near <= hi {
        return near;
    }
    // the representatives inside [lo, hi], if any: the one nearest reference
    let mut best: Option<f64> = None;
    if lo.is_finite() {
        let first = x + two_pi * ((lo - x) / two_pi).ceil();
        let mut v = first;
        while v <= hi + 1e-12 && v <= first + 4.0 * two_pi {
            if best.is_none_or(|b| (v - reference).abs() < (b - reference).abs()) {
                best = Some(v);
            }
            v += two_pi;
        }
    } else if hi.is_finite() {
        let v = x - two_pi * ((x - hi) / two_pi).ceil();
        best = Some(v);
    }
    best.unwrap_or(near)
}

/// Closed-form solutions of `solver` for `frame` at `target`, as joint vectors.
///
/// `reference`: the caller's q0 (wrapping, ordering and free joints at singular targets);
/// `respect_limits`: drop solutions outside `[lower, upper]` (revolute angles are first moved by
/// 2 pi k into them); `tolerance`: largest accepted position (m) / orientation (rad) error after
/// refinement.
#[allow(clippy::too_many_arguments)]
pub fn analytic_solutions(
    model: &Model,
    data: &mut Data,
    solver: &ChainIk,
    frame: usize,
    target: &Transform,
    position_only: bool,
    reference: &[f64],
    lower: &[f64],
    upper: &[f64],
    respect_limits: bool,
    tolerance: f64,
) -> AnalyticOutcome {
    let n = model.n;
    let theta_ref: Vec<f64> = (0..n).map(|i| reference[i] + model.offset[i]).collect();
    let mut candidates = Vec::with_capacity(8);
    let met = solver.solve(target, position_only, &theta_ref, &mut candidates);
    Check {
        frame,
        target,
        position_only,
        reference,
        lower,
        upper,
        respect_limits,
        tolerance,
        held: None,
        most: solver.max_solutions(),
        singular: met.singular,
        merged: met.merged,
    }
    .finish(model, data, candidates.as_flattened(), 6)
}

/// What a set of closed-form candidates is checked against (`Check::finish`).
pub struct Check<'a> {
    pub frame: usize,
    pub target: &'a Transform,
    pub position_only: bool,
    /// The caller's q0.
    pub reference: &'a [f64],
    pub lower: &'a [f64],
    pub upper: &'a [f64],
    pub respect_limits: bool,
    pub tolerance: f64,
    /// A joint held at its candidate value (a 7R arm's redundancy parameter): kept there by the
    /// refinement, its column left out of the merge test.
    pub held: Option<usize>,
    /// The most solutions the solver has (its structure's bound) and whether it met a
    /// non-isolated solution set: when every one of the `most` roots is found, distinct, they are
    /// all simple (no two branches meet) and the Jacobian test is skipped.
    pub most: usize,
    pub singular: bool,
    /// The closed form met a double root (a subproblem's discriminant at zero within tolerance):
    /// two branches merge at this target, and their one candidate stands for both.
    pub merged: bool,
}

impl Check<'_> {
    /// One candidate `theta` mapped to q (revolute angles moved by 2 pi k next to the reference,
    /// inside the limits when possible), checked by forward kinematics and refined near tangency:
    /// `(q, position error, orientation error)`, or None when its residual exceeds the tolerance.
    pub fn one(&self, model: &Model, data: &mut Data, theta: &[f64]) -> Option<(Vec<f64>, f64, f64)> {
        let n = model.n;
        let (reference, lower, upper, target) = (self.reference, self.lower, self.upper, self.target);
        let weights = if self.position_only {
            [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
        } else {
            [1.0; 6]
        };
        let mut q: Vec<f64> = (0..n).map(|i| theta[i] - model.offset[i]).collect();
        if q.iter().any(|x| !x.is_finite()) {
            return None;
        }
        for i in 0..n {
            if model.joints[i].kind == JointKind::Revolute {
                q[i] = wrap_angle(q[i], lower[i], upper[i], reference[i]);
            }
        }
        let e = pose_error(&frame_pose_lean(model, &q, self.frame), target);
        let (mut ep, mut er) = residuals(&e, &weights);
        // refine near-tangent candidates (residuals of the order of the square root of rounding)
        // by a few damped Gauss-Newton steps (no limits; a held joint stays where it is held);
        // not those at rounding level already, well inside the tolerance: refining them gains
        // nothing the caller asked for and costs a Jacobian per step (docs/ik.md, "Speed")
        let refine_above = (0.01 * self.tolerance).min(1e-10);
        if (ep > refine_above || er > refine_above) && ep < 1e-4 && er < 1e-4 {
            let refine = Settings {
                weights,
                max_iterations: 8,
                restarts: 0,
                position_tolerance: 1e-13,
                orientation_tolerance: 1e-13,
                lambda_min: 1e-12,
                max_step: 0.1,
            };
            let mut lo = vec![f64::NEG_INFINITY; n];
            let mut hi = vec![f64::INFINITY; n];
            if let Some(k) = self.held {
                (lo[k], hi[k]) = (q[k], q[k]);
            }
            let r = numeric_ik(model, data, self.frame, target, &q, &lo, &hi, &refine, 0);
            if r.position_error <= ep && r.orientation_error <= er {
                q = r.q;
                ep = r.position_error;
                er = r.orientation_error;
            }
        }
        (ep <= self.tolerance && er <= self.tolerance).then_some((q, ep, er))
    }

    /// Candidates (rows of `theta`, `stride` slots of which the model's n are used) mapped to q,
    /// verified by forward kinematics, refined, deduplicated, filtered by the limits and sorted by
    /// their distance to the reference.
    pub fn finish(&self, model: &Model, data: &mut Data, candidates: &[f64], stride: usize) -> AnalyticOutcome {
        let n = model.n;
        let (reference, lower, upper) = (self.reference, self.lower, self.upper);
        let mut out = AnalyticOutcome {
            merged: self.merged,
            ..Default::default()
        };
        // (q, position error, orientation error, inside the limits, squared distance to the reference)
        let mut kept: Vec<(Vec<f64>, f64, f64, bool, f64)> = Vec::with_capacity(candidates.len() / stride.max(1));
        for theta in candidates.chunks_exact(stride.max(1)) {
            let Some((q, ep, er)) = self.one(model, data, theta) else {
                continue;
            };
            // distinct modulo 2 pi; a near-duplicate is a merge of branches
            let gap = kept
                .iter()
                .map(|(k, ..)| distance(model, k, &q))
                .fold(f64::INFINITY, f64::min);
            if gap < MERGE_DISTANCE {
                out.merged = true;
            }
            if gap < 1e-7 {
                continue;
            }
            let inside = (0..n).all(|i| q[i] >= lower[i] - 1e-12 && q[i] <= upper[i] + 1e-12);
            let dist = (0..n).map(|i| (q[i] - reference[i]).powi(2)).sum::<f64>();
            out.worst_residual = out.worst_residual.max(ep).max(er);
            kept.push((q, ep, er, inside, dist));
        }
        out.found = kept.len();
        out.max_solutions = self.most;
        out.singular = self.singular;
        if !out.merged && (out.found < self.most || self.singular) {
            out.merged = kept
                .iter()
                .any(|k| hadamard_ratio(model, data, self.frame, &k.0, self.position_only, self.held) < MERGE_RATIO);
        }
        if self.respect_limits {
            kept.retain(|k| k.3);
        }
        kept.sort_by(|a, b| a.4.partial_cmp(&b.4).unwrap_or(std::cmp::Ordering::Equal));
        out.solutions.reserve_exact(kept.len());
        out.position_error.reserve_exact(kept.len());
        out.orientation_error.reserve_exact(kept.len());
        for (q, ep, er, ..) in kept {
            out.solutions.push(q);
            out.position_error.push(ep);
            out.orientation_error.push(er);
        }
        out
    }
}

/// Largest coordinate difference of two joint vectors, revolute angles modulo 2 pi.
fn distance(model: &Model, a: &[f64], b: &[f64]) -> f64 {
    (0..model.n)
        .map(|i| {
            let d = a[i] - b[i];
            if model.joints[i].kind == JointKind::Revolute {
                (d - 2.0 * PI * round(d / (2.0 * PI))).abs()
            } else {
                d.abs()
            }
        })
        .fold(0.0, f64::max)
}

/// The Hadamard ratio of the frame's Jacobian at `q` (its target rows, the joints other than
/// `held`): `sqrt(det(G)) / prod sqrt(G_ii)` with `G` the Gram matrix of the columns (or of the
/// rows, when there are more columns than rows). 1 for orthogonal columns, 0 at a singularity.
pub fn hadamard_ratio(
    model: &Model,
    data: &mut Data,
    frame: usize,
    q: &[f64],
    position_only: bool,
    held: Option<usize>,
) -> f64 {
    let n = model.n;
    let mut jac = vec![0.0; 6 * n];
    frame_jacobian(model, data, q, frame, Reference::World, None, &mut jac);
    let rows: &[usize] = if position_only { &[0, 1, 2] } else { &[0, 1, 2, 3, 4, 5] };
    let mut cols = [0usize; 16];
    let mut k_cols = 0;
    // (closed forms have at most seven joints)
    for j in (0..n).filter(|&j| Some(j) != held).take(16) {
        cols[k_cols] = j;
        k_cols += 1;
    }
    let cols = &cols[..k_cols];
    // the Gram matrix of the smaller side
    let by_cols = cols.len() <= rows.len();
    let (a, b) = if by_cols { (cols, rows) } else { (rows, cols) };
    let entry = |x: usize, y: usize| if by_cols { jac[y * n + x] } else { jac[x * n + y] };
    let gram = |i: usize, j: usize| b.iter().map(|&m| entry(a[i], m) * entry(a[j], m)).sum::<f64>();
    let k = a.len();
    let (det, norms) = if k == 6 {
        // the common case (six solved joints, a pose): a fixed-size LU, no allocation
        let g = nalgebra::Matrix6::from_fn(gram);
        (g.determinant(), (0..6).map(|i| g[(i, i)].sqrt()).product::<f64>())
    } else {
        let g = nalgebra::DMatrix::from_fn(k, k, gram);
        (g.determinant(), (0..k).map(|i| g[(i, i)].sqrt()).product::<f64>())
    };
    if norms <= 0.0 {
        return 0.0;
    }
    det.max(0.0).sqrt() / norms
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_prefers_the_reference_inside_limits() {
        assert!((wrap_angle(3.0 * PI / 2.0, -PI, PI, 0.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(-PI / 2.0, -2.0 * PI, 2.0 * PI, 4.0) - 3.0 * PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(3.0, -1.0, 1.0, 0.0) - 3.0).abs() < 1e-12 || wrap_angle(3.0, -1.0, 1.0, 0.0) < -1.0);
    }
}
