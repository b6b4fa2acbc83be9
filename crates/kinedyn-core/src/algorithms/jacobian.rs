//! Frame Jacobians, frame twists and the acceleration drift `dJ/dt qd`.
//!
//! Column j of the spatial Jacobian is joint j's motion subspace in world coordinates,
//! `world_from_body[j] . s_j` (RBDA eq. 3.39 / Murray, Li & Sastry eq. 3.54), for the joints that
//! support the frame's body. The three references of DESIGN.md:
//! - `World` (Pinocchio's LOCAL_WORLD_ALIGNED, the textbook `[J_v; J_w]`): velocity of the frame
//!   origin and angular velocity, both in base axes: `[v_o + w x p; w]`;
//! - `Local`: the same twist in the frame's own axes;
//! - `Spatial` (Pinocchio's WORLD): the twist at the base origin in base axes.

use super::kinematics::{forward_acceleration, forward_kinematics, forward_velocity, frame_pose};
use crate::data::Data;
use crate::model::Model;
use crate::spatial::{Mat3, Motion, Transform, Vec3};

/// How a frame's twist and Jacobian are expressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    World,
    Local,
    Spatial,
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
pub fn frame_jacobian(model: &Model, data: &mut Data, q: &[f64], frame: usize, reference: Reference, point: Option<&Vec3>, out: &mut [f64]) {
    let n = model.n;
    out[..6 * n].fill(0.0);
    forward_kinematics(model, data, q);
    let Some(body) = model.frames[frame].body else { return };
    let world_from_frame = data.world_from_body[body] * body_from_point(model, frame, point);
    let (r, p) = (world_from_frame.rot, world_from_frame.trans);
    for &j in &model.support[body] {
        // spatial column: s_j in world coordinates
        let sw = data.world_from_body[j].act_motion(&data.s[j]);
        let col = match reference {
            Reference::Spatial => sw,
            Reference::World => Motion::new(sw.lin + sw.ang.cross(&p), sw.ang),
            Reference::Local => {
                let rt = r.transpose();
                Motion::new(rt * (sw.lin + sw.ang.cross(&p)), rt * sw.ang)
            }
        };
        for (k, value) in col.to_array().iter().enumerate() {
            out[k * n + j] = *value;
        }
    }
}

/// Twist `J qd` of `frame` (or a point fixed in it), by the recursive velocity pass.
pub fn frame_velocity(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], frame: usize, reference: Reference, point: Option<&Vec3>) -> Motion {
    forward_velocity(model, data, q, qd);
    let Some(body) = model.frames[frame].body else { return Motion::zero() };
    let body_from_frame = body_from_point(model, frame, point);
    let world_from_frame = data.world_from_body[body] * body_from_frame;
    express(reference, &world_from_frame, &body_from_frame.inv_act_motion(&data.v[body]))
}

/// Acceleration drift `dJ/dt qd`: the frame's acceleration at `qdd = 0`, as the time derivative
/// of `J qd` in the chosen reference. In `World` it is the classical acceleration of the origin,
/// `R (a_lin + w x v)` (the spatial acceleration plus the `w x v` term), and `R a_ang`.
pub fn jacobian_dot_qd(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], frame: usize, reference: Reference, point: Option<&Vec3>) -> Motion {
    forward_acceleration(model, data, q, qd, None);
    let Some(body) = model.frames[frame].body else { return Motion::zero() };
    let body_from_frame = body_from_point(model, frame, point);
    let world_from_frame = data.world_from_body[body] * body_from_frame;
    let v = body_from_frame.inv_act_motion(&data.v[body]);
    let a = body_from_frame.inv_act_motion(&data.a[body]);
    match reference {
        Reference::World => Motion::new(world_from_frame.rot * (a.lin + v.ang.cross(&v.lin)), world_from_frame.rot * a.ang),
        _ => express(reference, &world_from_frame, &a),
    }
}

/// Pose of `frame` at `q` (runs forward kinematics).
pub fn frame_pose_at(model: &Model, data: &mut Data, q: &[f64], frame: usize) -> Transform {
    forward_kinematics(model, data, q);
    frame_pose(model, data, frame)
}
