//! Frame Jacobians, frame twists and the acceleration drift `dJ/dt qd`.
//!
//! Column j of the spatial Jacobian is joint j's motion subspace in world coordinates,
//! `world_from_body[j] . s_j` (RBDA eq. 3.39 / Murray, Li & Sastry eq. 3.54), for the joints that
//! support the frame's body. The three references of docs/architecture.md:
//! - `World` (Pinocchio's LOCAL_WORLD_ALIGNED, the textbook `[J_v; J_w]`): velocity of the frame
//!   origin and angular velocity, both in base axes: `[v_o + w x p; w]`;
//! - `Local`: the same twist in the frame's own axes;
//! - `Spatial` (Pinocchio's WORLD): the twist at the base origin in base axes.
//!
//! `frame_jacobian_hessian` gives the kinematic Hessian `dJ/dq` of each of these Jacobians.

use super::kinematics::{forward_acceleration, forward_kinematics, forward_velocity, frame_pose};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::{cross, mtv, Mat3, Motion, Real, Transform, Vec3};

/// How a frame's twist and Jacobian are expressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    World,
    Local,
    Spatial,
}

impl Reference {
    /// "world" (Pinocchio's LOCAL_WORLD_ALIGNED), "local" or "spatial" (Pinocchio's WORLD).
    pub fn from_name(name: &str) -> Result<Reference> {
        match name {
            "world" => Ok(Reference::World),
            "local" => Ok(Reference::Local),
            "spatial" => Ok(Reference::Spatial),
            _ => Err(Error::InvalidInput(format!(
                "reference must be one of ['world', 'local', 'spatial'], got '{name}'"
            ))),
        }
    }
}

/// `body_from_frame` of a frame, moved to a point given in the frame's axes.
#[inline]
fn body_from_point(model: &Model, frame: usize, point: Option<&Vec3>) -> Transform {
    let f = model.frames[frame].body_from_frame;
    match point {
        Some(p) => f * Transform::new(Mat3::identity(), *p),
        None => f,
    }
}

/// Re-express a twist given at the frame in its own axes (`local`) per `reference`.
#[inline]
fn express(reference: Reference, world_from_frame: &Transform, local: &Motion) -> Motion {
    match reference {
        Reference::Local => *local,
        Reference::World => Motion::new(world_from_frame.rot * local.lin, world_from_frame.rot * local.ang),
        Reference::Spatial => world_from_frame.act_motion(local),
    }
}

/// The Jacobian of `frame` (or of a point fixed in it) at `q`, written row-major `6 x n` to `out`.
#[inline(always)]
pub fn frame_jacobian<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    q: &[T],
    frame: usize,
    reference: Reference,
    point: Option<&Vec3>,
    out: &mut [T],
) {
    let n = model.n;
    out[..6 * n].fill(T::zero());
    forward_kinematics(model, data, q);
    let Some(body) = model.frames[frame].body else { return };
    let world_from_frame = data.world_from_body[body] * body_from_point(model, frame, point).splat();
    let (r, p) = (world_from_frame.rot, world_from_frame.trans);
    for &j in &model.support[body] {
        // spatial column: s_j in world coordinates
        let sw = data.world_from_body[j].act_motion(&data.s[j]);
        let col = match reference {
            Reference::Spatial => sw,
            Reference::World => Motion::new(sw.lin + cross(&sw.ang, &p), sw.ang),
            Reference::Local => Motion::new(mtv(&r, &(sw.lin + cross(&sw.ang, &p))), mtv(&r, &sw.ang)),
        };
        let values = [col.lin.x, col.lin.y, col.lin.z, col.ang.x, col.ang.y, col.ang.z];
        for (k, value) in values.iter().enumerate() {
            out[k * n + j] = *value;
        }
    }
}

/// Twist `J qd` of `frame` (or a point fixed in it), by the recursive velocity pass.
pub fn frame_velocity(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    frame: usize,
    reference: Reference,
    point: Option<&Vec3>,
) -> Motion {
    forward_velocity(model, data, q, qd);
    let Some(body) = model.frames[frame].body else {
        return Motion::zero();
    };
    let body_from_frame = body_from_point(model, frame, point);
    let world_from_frame = data.world_from_body[body] * body_from_frame;
    express(
        reference,
        &world_from_frame,
        &body_from_frame.inv_act_motion(&data.v[body]),
    )
}

/// Acceleration drift `dJ/dt qd`: the frame's acceleration at `qdd = 0`, as the time derivative
/// of `J qd` in the chosen reference. In `World` it is the classical acceleration of the origin,
/// `R (a_lin + w x v)` (the spatial acceleration plus the `w x v` term), and `R a_ang`.
pub fn jacobian_dot_qd(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    frame: usize,
    reference: Reference,
    point: Option<&Vec3>,
) -> Motion {
    forward_acceleration(model, data, q, qd, None);
    let Some(body) = model.frames[frame].body else {
        return Motion::zero();
    };
    let body_from_frame = body_from_point(model, frame, point);
    let world_from_frame = data.world_from_body[body] * body_from_frame;
    let v = body_from_frame.inv_act_motion(&data.v[body]);
    let a = body_from_frame.inv_act_motion(&data.a[body]);
    match reference {
        Reference::World => Motion::new(
            world_from_frame.rot * (a.lin + v.ang.cross(&v.lin)),
            world_from_frame.rot * a.ang,
        ),
        _ => express(reference, &world_from_frame, &a),
    }
}

/// Pose of `frame` at `q` (runs forward kinematics).
pub fn frame_pose_at(model: &Model, data: &mut Data, q: &[f64], frame: usize) -> Transform {
    forward_kinematics(model, data, q);
    frame_pose(model, data, frame)
}

/// The kinematic Hessian `H[i] = dJ/dq_i` of the `reference` Jacobian of `frame` (or of a point
/// fixed in it) at `q`, written row-major `n x 6 x n` to `out`: `out[(i * 6 + r) * n + j]` is
/// `d J[r][j] / d q_i` (Robotics Toolbox's `(n, 6, n)` layout, `H[i, :, j]`).
///
/// Derivation (Haviland & Corke 2022, "Manipulator Differential Kinematics Part I", arXiv:2207.01796, its Hessian; there for
/// the `World` Jacobian of a serial chain of revolute joints; here for any tree and both joint
/// kinds). Let `S_j = [v_j; w_j]` be joint j's spatial column (`world_from_body[j] . s_j`, base
/// axes, at the base origin), `p` the frame point in base axes, and write `i <= j` when joint i
/// supports body j (i is j or an ancestor). Moving joint i turns everything it carries by the
/// twist `S_i`, so (RBDA eq. 2.31 for the spatial cross product `x`):
/// - `dS_j/dq_i = S_i x S_j` if `i <= j`, else 0;
/// - `dp/dq_i = v_i + w_i x p` (the linear part of the `World` column `J_i = [Jv_i; w_i]`), for
///   every joint i that supports the frame's body.
///
/// `World`, `J_j = [v_j + w_j x p; w_j]`: differentiating and simplifying with the Jacobi identity
/// `(w_i x w_j) x p = w_i x (w_j x p) - w_j x (w_i x p)` gives the cross-product formulas
/// - `i <= j`: `dJ_j/dq_i = [w_i x Jv_j; w_i x w_j]`,
/// - `j < i`:  `dJ_j/dq_i = [w_j x Jv_i; 0]`,
///
/// (a prismatic joint has `w = 0`, so it neither turns a column nor is turned.) The linear rows
/// are symmetric in (i, j), as second derivatives of the position must be.
/// `Spatial`: `dS_j/dq_i = S_i x S_j` for `i <= j`, else 0.
/// `Local`, `J^L = diag(R^T, R^T) J` with `dR/dq_i = [w_i]x R`: `dJ^L_j/dq_i =
/// diag(R^T, R^T) (dJ_j/dq_i - [w_i x Jv_j; w_i x w_j])`, which is 0 for `i <= j` and
/// `[R^T (w_j x Jv_i - w_i x Jv_j); R^T (w_j x w_i)]` for `j < i`.
/// Columns of joints that do not support the frame's body are zero, as are their derivatives.
pub fn frame_jacobian_hessian(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    frame: usize,
    reference: Reference,
    point: Option<&Vec3>,
    out: &mut [f64],
) {
    let n = model.n;
    out[..6 * n * n].fill(0.0);
    forward_kinematics(model, data, q);
    let Some(body) = model.frames[frame].body else { return };
    let world_from_frame = data.world_from_body[body] * body_from_point(model, frame, point);
    let (r, p) = (world_from_frame.rot, world_from_frame.trans);
    let support = &model.support[body];
    // spatial columns S_j and World columns J_j of the supporting joints, in support (chain) order
    let spatial: Vec<Motion> = support
        .iter()
        .map(|&j| data.world_from_body[j].act_motion(&data.s[j]))
        .collect();
    let world: Vec<Motion> = spatial
        .iter()
        .map(|s| Motion::new(s.lin + s.ang.cross(&p), s.ang))
        .collect();
    let rt = r.transpose();
    let mut put = |i: usize, j: usize, h: Motion| {
        for (k, value) in h.to_array().iter().enumerate() {
            out[(i * 6 + k) * n + j] = *value;
        }
    };
    for (a, &i) in support.iter().enumerate() {
        for (b, &j) in support.iter().enumerate() {
            // joint i supports joint j exactly when it comes first in the chain of supports
            let i_supports_j = a <= b;
            let (wi, wj) = (world[a].ang, world[b].ang);
            let h = match reference {
                Reference::World if i_supports_j => Motion::new(wi.cross(&world[b].lin), wi.cross(&wj)),
                Reference::World => Motion::new(wj.cross(&world[a].lin), Vec3::zeros()),
                Reference::Spatial if i_supports_j => spatial[a].cross_motion(&spatial[b]),
                Reference::Spatial => continue,
                Reference::Local if i_supports_j => continue,
                Reference::Local => Motion::new(
                    rt * (wj.cross(&world[a].lin) - wi.cross(&world[b].lin)),
                    rt * wj.cross(&wi),
                ),
            };
            put(i, j, h);
        }
    }
}
