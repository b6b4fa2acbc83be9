//! Closed-form solutions as joint vectors: a chain's screws read from the model, the candidates of
//! [`super::analytic`] mapped to q (`q = theta - offset`, revolute angles moved by 2 pi k into the
//! limits nearest the caller's reference), verified by forward kinematics and refined by a few
//! Gauss-Newton steps of the numeric solver.
//!
//! | symbol   | here        | meaning                                                     |
//! |----------|-------------|-------------------------------------------------------------|
//! | `theta`  | `theta`     | joint coordinate of the product of exponentials, q + offset |
//! | `q`      | `q`         | the model's joint vector                                    |

use super::analytic::{AnalyticIk, Screw};
use super::{numeric_ik, pose_error, residuals, subproblems, Settings};
use crate::algorithms::jacobian::frame_pose_at;
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

/// The closed-form solver of `frame`'s chain, if its geometry has one (see `analytic`).
pub fn detect_analytic(model: &Model, data: &mut Data, frame: usize) -> Option<AnalyticIk> {
    let (screws, home) = chain_screws(model, data, frame)?;
    AnalyticIk::detect(screws, home)
}

/// Solutions of a closed-form solve after mapping, checking and limits.
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
}

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
    solver: &AnalyticIk,
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
    let singular = solver.solve(target, position_only, &theta_ref, &mut candidates);
    let weights = if position_only {
        [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
    } else {
        [1.0; 6]
    };
    let refine = Settings {
        weights,
        max_iterations: 8,
        restarts: 0,
        position_tolerance: 1e-13,
        orientation_tolerance: 1e-13,
        lambda_min: 1e-12,
        max_step: 0.1,
    };
    let mut out = AnalyticOutcome {
        singular,
        ..Default::default()
    };
    // (q, position error, orientation error, inside the limits, squared distance to the reference)
    let mut kept: Vec<(Vec<f64>, f64, f64, bool, f64)> = Vec::with_capacity(candidates.len());
    for theta in &candidates {
        let mut q: Vec<f64> = (0..n).map(|i| theta[i] - model.offset[i]).collect();
        for i in 0..n {
            if model.joints[i].kind == JointKind::Revolute {
                q[i] = wrap_angle(q[i], lower[i], upper[i], reference[i]);
            }
        }
        let e = pose_error(&frame_pose_lean(model, &q, frame), target);
        let (mut ep, mut er) = residuals(&e, &weights);
        if ep > 1e-12 || er > 1e-12 {
            // refine near-tangent candidates by a few damped Gauss-Newton steps (no limits)
            if ep < 1e-4 && er < 1e-4 {
                let (free, neg_free) = (vec![f64::INFINITY; n], vec![f64::NEG_INFINITY; n]);
                let r = numeric_ik(model, data, frame, target, &q, &neg_free, &free, &refine, 0);
                if r.position_error <= ep && r.orientation_error <= er {
                    q = r.q;
                    ep = r.position_error;
                    er = r.orientation_error;
                }
            }
        }
        if ep > tolerance || er > tolerance {
            continue;
        }
        // distinct modulo 2 pi
        let same = kept.iter().any(|(k, ..)| {
            (0..n).all(|i| {
                let d = k[i] - q[i];
                let d = if model.joints[i].kind == JointKind::Revolute {
                    d - 2.0 * PI * round(d / (2.0 * PI))
                } else {
                    d
                };
                d.abs() < 1e-7
            })
        });
        if same {
            continue;
        }
        let inside = (0..n).all(|i| q[i] >= lower[i] - 1e-12 && q[i] <= upper[i] + 1e-12);
        let distance = (0..n).map(|i| (q[i] - reference[i]).powi(2)).sum::<f64>();
        kept.push((q, ep, er, inside, distance));
    }
    out.found = kept.len();
    if respect_limits {
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
