//! Forward kinematics: positions, velocities and (bias) accelerations of every body.
//!
//! RBDA Table 5.1's forward pass: `X_J, S = jcalc(q_i)`, `parent_from_body = X_T X_J`,
//! `v_i = ^iX_p v_p + S_i qd_i`, `a_i = ^iX_p a_p + S_i qdd_i + v_i x S_i qd_i`.

use crate::data::Data;
use crate::model::Model;
use crate::spatial::Transform;

/// Joint coordinate seen by `jcalc`: q plus the model's offset.
#[inline]
fn joint_coordinate(model: &Model, q: &[f64], i: usize) -> f64 {
    q[i] + model.offset[i]
}

/// `parent_from_body` of body i at q: `parent_from_joint[i] * joint_from_body(q_i + offset_i)`.
#[inline(always)]
pub fn parent_from_body(model: &Model, q: &[f64], i: usize) -> Transform {
    model.joints[i].compose(&model.parent_from_joint[i], joint_coordinate(model, q, i))
}

/// Fills `data.parent_from_body` and `data.world_from_body` at `q`.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    for i in 0..model.n {
        // parent_from_body = parent_from_joint * joint_from_body(q_i)
        let parent_from_body = parent_from_body(model, q, i);
        data.parent_from_body[i] = parent_from_body;
        data.world_from_body[i] = match model.parent[i] {
            Some(p) => data.world_from_body[p] * parent_from_body,
            None => parent_from_body,
        };
    }
}

/// Forward kinematics, then body twists `v_i` (body coordinates) at `(q, qd)`.
pub fn forward_velocity(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) {
    forward_kinematics(model, data, q);
    for i in 0..model.n {
        // v_i = ^iX_p v_p + S_i qd_i
        let vj = data.s[i] * qd[i];
        data.v[i] = match model.parent[i] {
            Some(p) => data.parent_from_body[i].inv_act_motion(&data.v[p]) + vj,
            None => vj,
        };
    }
}

/// Forward kinematics, twists, and accelerations `a_i` (body coordinates) at `(q, qd, qdd)`,
/// without gravity. With `qdd = None` the accelerations are the velocity-product (drift) terms.
pub fn forward_acceleration(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], qdd: Option<&[f64]>) {
    forward_velocity(model, data, q, qd);
    for i in 0..model.n {
        // a_i = ^iX_p a_p + S_i qdd_i + v_i x S_i qd_i
        let mut ai = data.v[i].cross_motion(&(data.s[i] * qd[i]));
        if let Some(qdd) = qdd {
            ai += data.s[i] * qdd[i];
        }
        if let Some(p) = model.parent[i] {
            ai += data.parent_from_body[i].inv_act_motion(&data.a[p]);
        }
        data.a[i] = ai;
    }
}

/// Pose of a named frame in the base, after `forward_kinematics`.
#[inline]
pub fn frame_pose(model: &Model, data: &Data, frame: usize) -> Transform {
    let f = &model.frames[frame];
    match f.body {
        // a link frame of a URDF robot is its body frame: skip the product with the identity
        Some(b) if f.body_from_frame == Transform::identity() => data.world_from_body[b],
        Some(b) => data.world_from_body[b] * f.body_from_frame,
        None => f.body_from_frame,
    }
}
