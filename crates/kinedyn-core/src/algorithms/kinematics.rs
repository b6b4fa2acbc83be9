//! Forward kinematics: positions, velocities and (bias) accelerations of every body.
//!
//! RBDA Table 5.1's forward pass: `X_J, S = jcalc(q_i)`, `parent_from_body = X_T X_J`,
//! `v_i = ^iX_p v_p + S_i qd_i`, `a_i = ^iX_p a_p + S_i qdd_i + v_i x S_i qd_i`.

use crate::data::Data;
use crate::joint::JointKind;
use crate::model::{Coordinates, Model};
use crate::spatial::{AxisRotation, Inertia, Real, Transform};

/// Joint coordinate seen by `jcalc`: q plus the model's offset (0 for the bodies of a multi-DOF
/// joint, whose transform [`parent_from_body_trig`] takes from the joint's block of q).
#[inline(always)]
fn joint_coordinate<T: Real>(model: &Model, q: &[T], i: usize) -> T {
    if model.plain {
        return q[i] + T::splat(model.offset[i]);
    }
    match model.coordinates[i] {
        Coordinates::Scalar { at } => q[at] + T::splat(model.offset[i]),
        _ => T::zero(),
    }
}

/// `parent_from_body` of body i at q: `parent_from_joint[i] * joint_from_body(q_i + offset_i)`.
#[inline(always)]
pub fn parent_from_body<T: Real>(model: &Model, q: &[T], i: usize) -> Transform<T> {
    if !model.plain {
        if let Coordinates::Head { block, at } = model.coordinates[i] {
            return model.parent_from_joint[i].splat() * model.block_transform(i, block, &q[at..at + block.nq()]);
        }
    }
    let x = joint_coordinate(model, q, i);
    let (s, c) = x.sin_cos();
    model.joints[i].compose_trig(&model.parent_from_joint[i], x, s, c)
}

/// `sin` and `cos` of every joint coordinate `q_i + offset_i`, into `data.sin` / `data.cos`.
///
/// One loop before the tree passes: each `sin_cos` is a chain of about 14 dependent floating-point
/// steps, and evaluated here back to back the chains of different joints overlap in the CPU;
/// interleaved with a pass's other work they stalled it (profiled: 30 % of the CRBA).
#[inline(always)]
pub fn joint_trig<T: Real>(model: &Model, data: &mut Data<T>, q: &[T]) {
    let n = model.n;
    if model.plain {
        let (q, offset, sin, cos) = (&q[..n], &model.offset[..n], &mut data.sin[..n], &mut data.cos[..n]);
        for i in 0..n {
            sin[i] = q[i] + T::splat(offset[i]);
        }
        T::sin_cos_in_place(sin, cos);
        return;
    }
    for i in 0..n {
        data.sin[i] = joint_coordinate(model, q, i);
    }
    T::sin_cos_in_place(&mut data.sin[..n], &mut data.cos[..n]);
}

/// `parent_from_body` of body i with the joint's sine and cosine from `joint_trig`.
#[inline(always)]
pub fn parent_from_body_trig<T: Real>(model: &Model, q: &[T], sin: &[T], cos: &[T], i: usize) -> Transform<T> {
    if !model.plain {
        if let Coordinates::Head { block, at } = model.coordinates[i] {
            return model.parent_from_joint[i].splat() * model.block_transform(i, block, &q[at..at + block.nq()]);
        }
    }
    model.joints[i].compose_trig(
        &model.parent_from_joint[i],
        joint_coordinate(model, q, i),
        sin[i],
        cos[i],
    )
}

/// `^λX_i^* I ^iX_λ`: an inertia given in body i's frame, expressed in its parent's, where
/// `x = parent_from_body` of body i and `(s, c)` the sine and cosine of its joint coordinate.
///
/// `x.rot = R_T R_J(q)`. When the joint turns about a coordinate axis and the placement rotation
/// `R_T` is the identity or about a coordinate axis (DH tables, most URDFs), the two factors are
/// applied one after the other, 17 products each (`Inertia::rotated_about`) instead of 54.
#[inline(always)]
pub fn inertia_to_parent<T: Real>(
    model: &Model,
    i: usize,
    x: &Transform<T>,
    s: T,
    c: T,
    inertia: &Inertia<T>,
) -> Inertia<T> {
    let (joint, placement) = (&model.joints[i], &model.placement_rotation[i]);
    if matches!(placement, AxisRotation::General)
        || (!model.plain && matches!(model.coordinates[i], Coordinates::Head { .. }))
    {
        return x.act_inertia(inertia);
    }
    let a = &joint.axis;
    let in_joint_frame = match joint.kind {
        JointKind::Prismatic => *inertia,
        JointKind::Revolute if a.x == 0.0 && a.y == 0.0 => inertia.rotated_about::<0, 1>(c, s * T::splat(a.z)),
        JointKind::Revolute if a.y == 0.0 && a.z == 0.0 => inertia.rotated_about::<1, 2>(c, s * T::splat(a.x)),
        JointKind::Revolute if a.x == 0.0 && a.z == 0.0 => inertia.rotated_about::<2, 0>(c, s * T::splat(a.y)),
        JointKind::Revolute => return x.act_inertia(inertia),
    };
    placement
        .rotate_inertia(&model.parent_from_joint[i].rot, &in_joint_frame)
        .translated(&x.trans)
}

/// Fills `data.parent_from_body` at `q` (RBDA's `X_J X_T`, inverted), every joint's trigonometry first.
#[inline(always)]
pub fn joint_transforms<T: Real>(model: &Model, data: &mut Data<T>, q: &[T]) {
    let n = model.n;
    joint_trig(model, data, q);
    let (sin, cos, x_up) = (&data.sin[..n], &data.cos[..n], &mut data.parent_from_body[..n]);
    for (i, x) in x_up.iter_mut().enumerate() {
        // parent_from_body = parent_from_joint * joint_from_body(q_i)
        *x = parent_from_body_trig(model, q, sin, cos, i);
    }
}

/// Fills `data.parent_from_body` and `data.world_from_body` at `q`.
#[inline(always)]
pub fn forward_kinematics<T: Real>(model: &Model, data: &mut Data<T>, q: &[T]) {
    joint_transforms(model, data, q);
    world_poses(model, data);
}

/// `data.world_from_body` from `data.parent_from_body` (the second half of `forward_kinematics`,
/// for a pass that already has the joint transforms, e.g. RNEA's).
#[inline(always)]
pub fn world_poses<T: Real>(model: &Model, data: &mut Data<T>) {
    let n = model.n;
    let (parent, x_up, world) = (
        &model.parent[..n],
        &data.parent_from_body[..n],
        &mut data.world_from_body[..n],
    );
    for i in 0..n {
        world[i] = match parent[i] {
            Some(p) => world[p] * x_up[i],
            None => x_up[i],
        };
    }
}

/// Forward kinematics, then body twists `v_i` (body coordinates) at `(q, qd)`.
// i: the body number, indexing the model's and the data's per-body arrays together
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub fn forward_velocity<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T]) {
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
#[inline(always)]
pub fn forward_acceleration<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], qdd: Option<&[T]>) {
    forward_velocity(model, data, q, qd);
    for i in 0..model.n {
        // a_i = ^iX_p a_p + S_i qdd_i + v_i x S_i qd_i
        let mut ai = model.velocity_product(i, &data.v[i], qd);
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
#[inline(always)]
pub fn frame_pose<T: Real>(model: &Model, data: &Data<T>, frame: usize) -> Transform<T> {
    let f = &model.frames[frame];
    match f.body {
        // a link frame of a URDF robot is its body frame: skip the product with the identity
        Some(b) if f.body_from_frame == Transform::identity() => data.world_from_body[b],
        Some(b) => data.world_from_body[b] * f.body_from_frame.splat(),
        None => f.body_from_frame.splat(),
    }
}
