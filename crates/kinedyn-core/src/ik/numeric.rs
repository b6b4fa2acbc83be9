//! The numeric solver: Levenberg-Marquardt with Sugihara's damping on the configuration manifold
//! (the derivation, the step and the symbol table are in the header of `ik/mod.rs`).
//!
//! | symbol   | here          | meaning                                                  |
//! |----------|---------------|----------------------------------------------------------|
//! | `e`      | `e: [f64; 6]` | pose error `[p_d - p; log(R_d R^T)]`, base axes          |
//! | `W`      | `weights`     | diagonal weights (mask) of the six error components      |
//! | `J`      | `jac`         | world-aligned geometric Jacobian, 6 x nv row-major        |
//! | `lambda` | `lambda`      | damping                                                  |
//! | `mu`     | `mu`          | adaptive part of the damping (Marquardt)                 |

use super::{cost, pose_error, residuals, Reduction};
use crate::algorithms::jacobian::{frame_jacobian, frame_pose_at, Reference};
use crate::data::Data;
use crate::joint::JointKind;
use crate::lie;
use crate::model::{Coordinates, Model};
use crate::rng::Rng;
use crate::spatial::Transform;
use nalgebra::{Matrix6, Vector6};
use std::f64::consts::PI;

/// Settings of the numeric solver.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Weights of `[x, y, z, rx, ry, rz]`; a zero drops the component (position-only: `[1,1,1,0,0,0]`).
    pub weights: [f64; 6],
    /// Iterations per attempt.
    pub max_iterations: usize,
    /// Random restarts after the first attempt.
    pub restarts: usize,
    /// Success: position error (m) and orientation error (rad) below these.
    pub position_tolerance: f64,
    pub orientation_tolerance: f64,
    /// Sugihara's bias damping `w_bar`.
    pub lambda_min: f64,
    /// Largest change of one joint in one step (rad or m).
    pub max_step: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            weights: [1.0; 6],
            max_iterations: 50,
            restarts: 50,
            position_tolerance: 1e-10,
            orientation_tolerance: 1e-10,
            lambda_min: 1e-6,
            max_step: 0.5,
        }
    }
}

/// Result of one numeric solve.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub q: Vec<f64>,
    pub success: bool,
    pub position_error: f64,
    pub orientation_error: f64,
    /// Iterations over all attempts.
    pub iterations: usize,
    /// Attempts made (1 + restarts used).
    pub attempts: usize,
}

/// The coordinates the solver works in: the model's own (q of size nq, steps of size nv), or
/// reduced ones; with the scratch space to go to the full ones.
struct Space<'a> {
    model: &'a Model,
    reduction: Option<&'a Reduction>,
    nq: usize,
    nv: usize,
    /// (q index, v index) of every independent 1-DOF coordinate: the ones with position limits.
    scalars: Vec<(usize, usize)>,
    /// Whether each of `scalars` is a revolute joint.
    revolute: Vec<bool>,
    /// (block, q index of its first entry) of every multi-DOF joint, in the solver's q, and its head body.
    blocks: Vec<(lie::Block, usize)>,
    block_body: Vec<usize>,
    full_q: Vec<f64>,
    full_trial: Vec<f64>,
    full_v: Vec<f64>,
    full_jac: Vec<f64>,
}

impl<'a> Space<'a> {
    fn new(model: &'a Model, reduction: Option<&'a Reduction>) -> Self {
        // a full q index in the solver's q (None: a follower)
        let solver_q = |i: usize| match reduction {
            None => Some(i),
            Some(r) => {
                let k = r.q_source[i].0;
                (r.q_keep[k] == i).then_some(k)
            }
        };
        let solver_v = |i: usize| reduction.map_or(i, |r| r.v_source[i].0);
        // (the full v index of a 1-DOF coordinate is its body's index)
        let (scalars, revolute) = model
            .scalar_coordinates()
            .filter_map(|(qi, vi)| {
                solver_q(qi).map(|k| ((k, solver_v(vi)), model.joints[vi].kind == JointKind::Revolute))
            })
            .unzip();
        let (blocks, block_body) = model
            .coordinates
            .iter()
            .enumerate()
            .filter_map(|(i, c)| match *c {
                Coordinates::Head { block, at } => solver_q(at).map(|k| ((block, k), i)),
                _ => None,
            })
            .unzip();
        let (nq, nv, full) = match reduction {
            None => (model.nq, model.n, (0, 0)),
            Some(r) => (r.q_keep.len(), r.nv, (model.nq, model.n)),
        };
        Self {
            model,
            reduction,
            nq,
            nv,
            scalars,
            revolute,
            blocks,
            block_body,
            full_q: vec![0.0; full.0],
            full_trial: vec![0.0; full.0],
            full_v: vec![0.0; full.1],
            full_jac: vec![0.0; 6 * full.1],
        }
    }

    /// `full_q = expand(q)`.
    fn expand(&mut self, q: &[f64]) {
        if let Some(r) = self.reduction {
            for (x, &(k, m, b)) in self.full_q.iter_mut().zip(&r.q_source) {
                *x = m * q[k] + b;
            }
        }
    }

    fn pose(&mut self, data: &mut Data, q: &[f64], frame: usize) -> Transform {
        if self.reduction.is_none() {
            return frame_pose_at(self.model, data, q, frame);
        }
        self.expand(q);
        frame_pose_at(self.model, data, &self.full_q, frame)
    }

    /// The world-aligned Jacobian (6 x nv, row-major) in the solver's coordinates: `J G` when reduced.
    fn jacobian(&mut self, data: &mut Data, q: &[f64], frame: usize, out: &mut [f64]) {
        let Some(r) = self.reduction else {
            frame_jacobian(self.model, data, q, frame, Reference::World, None, out);
            return;
        };
        self.expand(q);
        frame_jacobian(
            self.model,
            data,
            &self.full_q,
            frame,
            Reference::World,
            None,
            &mut self.full_jac,
        );
        let (nf, nv) = (self.model.n, self.nv);
        out[..6 * nv].fill(0.0);
        for (i, &(k, m)) in r.v_source.iter().enumerate() {
            for row in 0..6 {
                out[row * nv + k] += m * self.full_jac[row * nf + i];
            }
        }
    }

    /// `out = q ⊕ scale dq` (the Lie-group exponential on multi-DOF joints, `q_full ⊕ G dq` when reduced).
    fn integrate(&mut self, q: &[f64], dq: &[f64], scale: f64, out: &mut [f64]) {
        let Some(r) = self.reduction else {
            self.model.integrate_configuration(q, dq, scale, out);
            return;
        };
        self.expand(q);
        for (x, &(k, m)) in self.full_v.iter_mut().zip(&r.v_source) {
            *x = m * dq[k];
        }
        self.model
            .integrate_configuration(&self.full_q, &self.full_v, scale, &mut self.full_trial);
        for (x, &i) in out.iter_mut().zip(&r.q_keep) {
            *x = self.full_trial[i];
        }
    }

    /// Quaternions and (cos, sin) pairs divided by their norms.
    fn normalize(&self, q: &mut [f64]) {
        for &(block, at) in &self.blocks {
            lie::normalize_block(block, &mut q[at..at + block.nq()]);
        }
    }

    /// 1-DOF coordinates moved into `[lower, upper]`.
    #[inline]
    fn clamp(&self, q: &mut [f64], lower: &[f64], upper: &[f64]) {
        for &(k, _) in &self.scalars {
            q[k] = q[k].clamp(lower[k], upper[k]);
        }
    }

    /// A random configuration: 1-DOF joints uniform inside the limits (an infinite side: +-pi for a
    /// revolute joint, +-1 m around `center` for a prismatic one), free-flyer and planar positions
    /// within 1 m of `center`'s, rotations uniform (quaternions by Shoemake's method, planar angles
    /// in [-pi, pi)).
    fn random(&self, lower: &[f64], upper: &[f64], center: &[f64], rng: &mut Rng, out: &mut [f64]) {
        // 1-DOF coordinates first, in order: the same draws as for a model of 1-DOF joints only
        for (&(k, _), &revolute) in self.scalars.iter().zip(&self.revolute) {
            let span = if revolute { PI } else { 1.0 };
            let lo = if lower[k].is_finite() {
                lower[k]
            } else if upper[k].is_finite() {
                upper[k] - 2.0 * span
            } else {
                center[k] - span
            };
            let hi = if upper[k].is_finite() {
                upper[k]
            } else {
                lo + 2.0 * span
            };
            out[k] = lo + (hi - lo) * rng.uniform(0.0, 1.0);
        }
        let quaternion = |rng: &mut Rng, out: &mut [f64]| {
            out[..4].copy_from_slice(&lie::uniform_quaternion([
                rng.uniform(0.0, 1.0),
                rng.uniform(0.0, 1.0),
                rng.uniform(0.0, 1.0),
            ]));
        };
        for &(block, at) in &self.blocks {
            match block {
                lie::Block::FreeFlyer => {
                    for j in at..at + 3 {
                        out[j] = center[j] + rng.uniform(-1.0, 1.0);
                    }
                    quaternion(rng, &mut out[at + 3..at + 7]);
                }
                lie::Block::Spherical => quaternion(rng, &mut out[at..at + 4]),
                lie::Block::Planar => {
                    for j in at..at + 2 {
                        out[j] = center[j] + rng.uniform(-1.0, 1.0);
                    }
                    let (s, c) = rng.uniform(-PI, PI).sin_cos();
                    (out[at + 2], out[at + 3]) = (c, s);
                }
                lie::Block::Scalar => {}
            }
        }
    }
}

pub use crate::model::UNIT_TOLERANCE;

/// The checks of a start or reference `q` (configuration coordinates, reduced ones with a
/// reduction): finite, each multi-DOF joint's quaternion or (cos, sin) pair of unit norm to within
/// [`UNIT_TOLERANCE`]; and of the limits: a multi-DOF joint's entries of `lower` / `upper` must be
/// infinite (the solver keeps limits on 1-DOF joints only). The error names the entries and body.
pub fn check_start(
    model: &Model,
    reduction: Option<&Reduction>,
    q: &[f64],
    lower: &[f64],
    upper: &[f64],
) -> Result<(), String> {
    if let Some(k) = q.iter().position(|x| !x.is_finite()) {
        return Err(format!("q0[{k}] is {}: a configuration must be finite", q[k]));
    }
    let space = Space::new(model, reduction);
    for (&(block, at), &body) in space.blocks.iter().zip(&space.block_body) {
        if block == lie::Block::Scalar {
            continue; // a 1-DOF coordinate: no unit part, and limits of its own
        }
        // the model's one unit check (`Block::not_unit`), named in the solver's own terms
        if let Some((unit, what, norm)) = block.not_unit(&q[at..at + block.nq()]) {
            return Err(format!(
                "q0[{}:{}], the {what} of the {} joint at body {body}, has norm {norm:.9}, not 1 to within {UNIT_TOLERANCE:e}: normalise it",
                at + unit.start,
                at + unit.end,
                block.kind_name()
            ));
        }
        if let Some(j) = (at..at + block.nq()).find(|&j| lower[j].is_finite() || upper[j].is_finite()) {
            return Err(format!(
                "limits of coordinate {j} ([{}, {}]): it belongs to the multi-DOF joint at body {body}, whose coordinates inverse kinematics does not limit (give -inf, inf)",
                lower[j], upper[j]
            ));
        }
    }
    Ok(())
}

/// Size of a configuration (nq) and of a step (nv) in the solver's coordinates.
pub fn solver_sizes(model: &Model, reduction: Option<&Reduction>) -> (usize, usize) {
    reduction.map_or((model.nq, model.n), |r| (r.q_keep.len(), r.nv))
}

/// Levenberg-Marquardt towards `target` for `frame`, from `q0`, within `[lower, upper]`, in the
/// model's own coordinates (see [`numeric_ik_reduced`]).
#[allow(clippy::too_many_arguments)]
pub fn numeric_ik(
    model: &Model,
    data: &mut Data,
    frame: usize,
    target: &Transform,
    q0: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: &Settings,
    seed: u64,
) -> Outcome {
    numeric_ik_reduced(model, None, data, frame, target, q0, lower, upper, settings, seed)
}

/// Levenberg-Marquardt on the configuration manifold: `q0`, `lower`, `upper` and the answer have
/// the size of a configuration (the model's nq, or the reduction's), the step `dq` that of a
/// velocity (nv), and the update is `q ⊕ dq` (the exponential of each multi-DOF joint's Lie group,
/// unit quaternions kept unit). Only 1-DOF coordinates have limits (a multi-DOF joint's entries of
/// `lower`/`upper` are not read). `q0`'s quaternions are normalised first.
#[allow(clippy::too_many_arguments)]
pub fn numeric_ik_reduced(
    model: &Model,
    reduction: Option<&Reduction>,
    data: &mut Data,
    frame: usize,
    target: &Transform,
    q0: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: &Settings,
    seed: u64,
) -> Outcome {
    let mut space = Space::new(model, reduction);
    let (nq, n) = (space.nq, space.nv);
    let w = &settings.weights;
    let w_sqrt: [f64; 6] = std::array::from_fn(|k| w[k].max(0.0).sqrt());
    let mut rng = Rng::new(seed);
    let mut jac = vec![0.0; 6 * n];
    let mut q = q0[..nq].to_vec();
    let mut trial = vec![0.0; nq];
    let mut dq = vec![0.0; n];
    let mut blocked = vec![false; n];
    let mut best = Outcome {
        q: q.clone(),
        success: false,
        position_error: f64::INFINITY,
        orientation_error: f64::INFINITY,
        iterations: 0,
        attempts: 0,
    };
    let mut best_cost = f64::INFINITY;
    let converged = |e: &[f64; 6]| {
        let (ep, er) = residuals(e, w);
        ep <= settings.position_tolerance && er <= settings.orientation_tolerance
    };
    for attempt in 0..=settings.restarts {
        if attempt > 0 {
            space.random(lower, upper, q0, &mut rng, &mut q);
        } else {
            space.normalize(&mut q);
        }
        space.clamp(&mut q, lower, upper);
        best.attempts = attempt + 1;
        let mut e = pose_error(&space.pose(data, &q, frame), target);
        let mut big_e = cost(&e, w);
        // adaptive part of the damping: shrinks after accepted steps (fast final convergence, also
        // near singular configurations), grows after rejected ones
        let mut mu = settings.lambda_min;
        let mut done = false;
        for _ in 0..settings.max_iterations {
            if converged(&e) {
                done = true;
                break;
            }
            best.iterations += 1;
            space.jacobian(data, &q, frame, &mut jac);
            // 1-DOF joints resting on a limit that the step would push further out are held (their
            // columns dropped) and the step recomputed: a projected LM with an active set
            let lambda = big_e + mu;
            blocked.fill(false);
            let mut solved = false;
            for _ in 0..=n {
                // S = A A^T + lambda I,  A = W^1/2 J (held columns zeroed)
                let mut s = Matrix6::<f64>::identity() * lambda;
                for a in 0..6 {
                    for b in a..6 {
                        let mut acc = 0.0;
                        for j in 0..n {
                            if !blocked[j] {
                                acc += jac[a * n + j] * jac[b * n + j];
                            }
                        }
                        let v = w_sqrt[a] * w_sqrt[b] * acc;
                        s[(a, b)] += v;
                        if a != b {
                            s[(b, a)] += v;
                        }
                    }
                }
                let rhs = Vector6::from_fn(|k, _| w_sqrt[k] * e[k]);
                let Some(chol) = s.cholesky() else { break };
                let y = chol.solve(&rhs);
                // dq = A^T y
                for j in 0..n {
                    dq[j] = if blocked[j] {
                        0.0
                    } else {
                        (0..6).map(|k| jac[k * n + j] * w_sqrt[k] * y[k]).sum()
                    };
                }
                let mut newly = false;
                for &(k, j) in &space.scalars {
                    let out_low = q[k] <= lower[k] + 1e-12 && dq[j] < 0.0;
                    let out_high = q[k] >= upper[k] - 1e-12 && dq[j] > 0.0;
                    if !blocked[j] && (out_low || out_high) {
                        blocked[j] = true;
                        newly = true;
                    }
                }
                solved = true;
                if !newly {
                    break;
                }
                solved = false;
            }
            if !solved {
                // every direction is blocked or the system is degenerate: take the last step projected
                if dq.iter().all(|d| *d == 0.0) {
                    break;
                }
            }
            // no coordinate moves more than max_step (rad or m; a rotation's angle for a multi-DOF joint's)
            let largest = dq.iter().fold(0.0f64, |m, d| m.max(d.abs()));
            let scale = if largest > settings.max_step {
                settings.max_step / largest
            } else {
                1.0
            };
            space.integrate(&q, &dq, scale, &mut trial);
            space.clamp(&mut trial, lower, upper);
            let e_new = pose_error(&space.pose(data, &trial, frame), target);
            let big_e_new = cost(&e_new, w);
            if big_e_new < big_e {
                let gain = big_e - big_e_new;
                q.copy_from_slice(&trial);
                e = e_new;
                big_e = big_e_new;
                mu = (mu * 0.1).max(1e-14);
                // stalled far from the target (a local minimum or a limit): restart
                if gain <= 1e-14 * big_e && !converged(&e) {
                    break;
                }
            } else {
                mu = (mu * 10.0).max(settings.lambda_min);
                if mu > 1e8 {
                    break;
                }
            }
        }
        if big_e < best_cost || done {
            best_cost = big_e;
            let (ep, er) = residuals(&e, w);
            best.q.copy_from_slice(&q);
            best.position_error = ep;
            best.orientation_error = er;
        }
        if done {
            best.success = true;
            return best;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{Mat3, Vec3};

    /// A free-flyer (bodies 0-5), a spherical joint (6-8) and a revolute joint (9) carrying frame 0:
    /// nq = 12, nv = 10.
    fn floating_model() -> Model {
        use crate::joint::Joint;
        use crate::lie::Block;
        use crate::model::Frame;
        use crate::spatial::Inertia;
        let mut rng = Rng::new(4);
        let unit = |k: usize| Vec3::ith(k, 1.0);
        let mut joints: Vec<Joint> = (0..6)
            .map(|k| Joint {
                kind: if k < 3 {
                    JointKind::Prismatic
                } else {
                    JointKind::Revolute
                },
                axis: unit(k % 3),
            })
            .collect();
        joints.extend((0..3).map(|k| Joint {
            kind: JointKind::Revolute,
            axis: unit(k),
        }));
        joints.push(Joint {
            kind: JointKind::Revolute,
            axis: rng.unit(),
        });
        let parent = (0..10).map(|i: usize| i.checked_sub(1)).collect();
        let mut placements = vec![Transform::identity(); 10];
        placements[6] = Transform::new(rng.rotation(), rng.vec3(-0.5, 0.5));
        placements[9] = Transform::new(rng.rotation(), rng.vec3(-0.5, 0.5));
        let mut inertia = vec![Inertia::zero(); 10];
        for i in [5, 8, 9] {
            inertia[i] = crate::testing::random_inertia(&mut rng);
        }
        let frames = vec![Frame {
            body: Some(9),
            body_from_frame: Transform::new(rng.rotation(), rng.vec3(-0.3, 0.3)),
        }];
        let coordinates = [Coordinates::Head {
            block: Block::FreeFlyer,
            at: 0,
        }]
        .into_iter()
        .chain([Coordinates::Member; 5])
        .chain([
            Coordinates::Head {
                block: Block::Spherical,
                at: 7,
            },
            Coordinates::Member,
            Coordinates::Member,
            Coordinates::Scalar { at: 11 },
        ])
        .collect();
        Model::new(
            parent,
            joints,
            vec![0.0; 10],
            placements,
            inertia,
            vec![0.0; 10],
            vec![0.0; 10],
            vec![0.0; 10],
            Vec3::new(0.0, 0.0, -9.81),
            frames,
        )
        .and_then(|m| m.with_coordinates(coordinates))
        .expect("a valid floating model")
    }

    #[test]
    fn levenberg_marquardt_on_the_manifold_reaches_poses_with_unit_quaternions() {
        let model = floating_model();
        assert_eq!((model.nq, model.n), (12, 10));
        let mut data = Data::new(&model);
        let space = Space::new(&model, None);
        let (lower, upper) = (vec![f64::NEG_INFINITY; 12], vec![f64::INFINITY; 12]);
        let mut neutral = vec![0.0; 12];
        (neutral[6], neutral[10]) = (1.0, 1.0);
        let mut rng = Rng::new(9);
        let mut goal = vec![0.0; 12];
        for trial in 0..5 {
            space.random(&lower, &upper, &neutral, &mut rng, &mut goal);
            let target = frame_pose_at(&model, &mut data, &goal, 0);
            let out = numeric_ik(
                &model,
                &mut data,
                0,
                &target,
                &neutral,
                &lower,
                &upper,
                &Settings::default(),
                trial,
            );
            assert!(out.success, "trial {trial}: {out:?}");
            let e = pose_error(&frame_pose_at(&model, &mut data, &out.q, 0), &target);
            assert!(e.iter().all(|x| x.abs() < 1e-9), "trial {trial}: {e:?}");
            for unit in [&out.q[3..7], &out.q[7..11]] {
                assert!(
                    (unit.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs() < 1e-12,
                    "{unit:?}"
                );
            }
        }
    }

    #[test]
    fn a_start_with_a_non_unit_quaternion_or_limits_on_a_free_flyer_is_refused() {
        let model = floating_model();
        let (lower, upper) = (vec![f64::NEG_INFINITY; 12], vec![f64::INFINITY; 12]);
        let mut q = vec![0.0; 12];
        (q[6], q[10]) = (1.0, 1.0);
        assert!(check_start(&model, None, &q, &lower, &upper).is_ok());
        q[10] = 1.1;
        let e = check_start(&model, None, &q, &lower, &upper).unwrap_err();
        assert!(
            e.contains("q0[7:11], the quaternion (qx, qy, qz, qw) of the spherical joint at body 6, has norm 1.1"),
            "{e}"
        );
        q[10] = 1.0;
        let mut limited = lower.clone();
        limited[2] = -1.0;
        let e = check_start(&model, None, &q, &limited, &upper).unwrap_err();
        assert!(e.contains("limits of coordinate 2") && e.contains("body 0"), "{e}");
    }

    #[test]
    fn a_mimic_reduction_solves_in_reduced_coordinates() {
        // three revolute joints; the second follows the first: q1 = -2 q0 + 0.1
        let model = crate::testing::random_model(3, 3, false);
        let reduction = Reduction::new(
            &model,
            vec![(0, 1.0, 0.0), (0, -2.0, 0.1), (1, 1.0, 0.0)],
            vec![(0, 1.0), (0, -2.0), (1, 1.0)],
            vec![0, 2],
            2,
        )
        .unwrap();
        let mut data = Data::new(&model);
        let (lower, upper) = (vec![f64::NEG_INFINITY; 2], vec![f64::INFINITY; 2]);
        let frame = 2; // on the last body
        for (trial, goal) in [[0.4, -0.7], [-1.2, 2.0], [2.5, 0.3]].iter().enumerate() {
            let full = [goal[0], -2.0 * goal[0] + 0.1, goal[1]];
            let target = frame_pose_at(&model, &mut data, &full, frame);
            let out = numeric_ik_reduced(
                &model,
                Some(&reduction),
                &mut data,
                frame,
                &target,
                &[0.0, 0.0],
                &lower,
                &upper,
                &Settings::default(),
                trial as u64,
            );
            assert!(out.success && out.q.len() == 2, "{out:?}");
            let reached = [out.q[0], -2.0 * out.q[0] + 0.1, out.q[1]];
            let e = pose_error(&frame_pose_at(&model, &mut data, &reached, frame), &target);
            assert!(e.iter().all(|x| x.abs() < 1e-9), "trial {trial}: {e:?}");
        }
        // a follower that is not copied back, or a kept coordinate that does not copy itself: refused
        assert!(Reduction::new(
            &model,
            vec![(0, 1.0, 0.0), (0, -2.0, 0.1), (1, 1.0, 0.0)],
            vec![(0, 1.0), (0, -2.0), (1, 1.0)],
            vec![1, 2],
            2
        )
        .is_err());
    }

    #[test]
    fn uniform_quaternions_are_unit_and_average_to_no_rotation() {
        // a uniform distribution over rotations has E[R] = 0 (each column is a uniform unit vector)
        let mut rng = Rng::new(1);
        let mut mean = Mat3::zeros();
        let count = 20_000;
        for _ in 0..count {
            let q = lie::uniform_quaternion([rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0)]);
            assert!(((q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt() - 1.0).abs() < 1e-14);
            mean += crate::model::quaternion_matrix(&q) / count as f64;
        }
        // each entry's standard deviation is 1/sqrt(3 count) ~ 0.004
        assert!(mean.abs().max() < 0.03, "{mean}");
    }
}
