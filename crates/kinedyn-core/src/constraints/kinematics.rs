//! The closure residual `r(q)`, its Jacobian `J(q)` and the drift `gamma = dJ/dt qd` of a model's
//! loops (definitions and frames in the module header, `constraints/mod.rs`).
//!
//! `J` is built from the `World` frame Jacobians (`algorithms/jacobian.rs`: column k of a frame at
//! `p` is `[v_k + w_k x p; w_k]` for the spatial column `S_k = [v_k; w_k]` of each supporting joint,
//! RBDA eq. 3.39), frame a's with a plus sign, frame b's with a minus. `gamma` is the frame
//! accelerations at `qdd = 0` (RBDA Table 5.1's forward pass with `qdd = 0`), taken as the time
//! derivatives of the world twists: the classical acceleration of the origin,
//! `R (a_lin + w x v)` for the body-axes spatial acceleration `a` and twist `(v, w)`, and `R a_ang`.

use crate::algorithms::{forward_acceleration, forward_kinematics};
use crate::data::Data;
use crate::model::Model;
use crate::spatial::{cross, mv, Real, Transform, Vec3};

use super::LoopKind;

/// `world_from_frame` of `frame` after forward kinematics.
#[inline(always)]
fn world_from_frame<T: Real>(model: &Model, data: &Data<T>, frame: usize) -> Transform<T> {
    let f = &model.frames[frame];
    match f.body {
        Some(b) => data.world_from_body[b] * f.body_from_frame.splat(),
        None => f.body_from_frame.splat(),
    }
}

/// `r(q)` (m rows) written to `out`: per loop `p_a - p_b` and, for a weld, `R_b log3(R_b^T R_a)`.
pub fn loop_residual(model: &Model, data: &mut Data, q: &[f64], out: &mut [f64]) {
    forward_kinematics(model, data, q);
    let mut row = 0;
    for l in &model.loops {
        let (a, b) = (
            world_from_frame(model, data, l.frame_a),
            world_from_frame(model, data, l.frame_b),
        );
        let dp = a.trans - b.trans;
        out[row..row + 3].copy_from_slice(dp.as_slice());
        if l.kind == LoopKind::Weld {
            // the rotation vector by the quaternion (robust at zero and near pi, Solà eq. 105)
            let relative = nalgebra::Rotation3::from_matrix_unchecked(b.rot.transpose() * a.rot);
            let u = nalgebra::UnitQuaternion::from_rotation_matrix(&relative);
            let e = b.rot * Vec3::from(crate::lie::log3([u.i, u.j, u.k, u.w]));
            out[row + 3..row + 6].copy_from_slice(e.as_slice());
        }
        row += l.kind.rows();
    }
}

/// `J(q)`, row-major m x n, written to `out` (runs forward kinematics).
#[inline(always)]
pub fn loop_jacobian<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], out: &mut [T]) {
    forward_kinematics(model, data, q);
    jacobian_after_kinematics(model, data, out);
}

/// `J` from the poses `data.world_from_body` of a forward pass already run at `q`.
#[inline(always)]
pub(super) fn jacobian_after_kinematics<T: Real>(model: &Model, data: &Data<T>, out: &mut [T]) {
    let n = model.n;
    out[..model.loop_rows() * n].fill(T::zero());
    let mut row = 0;
    for l in &model.loops {
        let rows = l.kind.rows();
        for (frame, sign) in [(l.frame_a, T::one()), (l.frame_b, -T::one())] {
            let Some(body) = model.frames[frame].body else { continue };
            let p = world_from_frame(model, data, frame).trans;
            for &k in &model.support[body] {
                // the World column of joint k at p: [v_k + w_k x p; w_k]
                let sw = data.world_from_body[k].act_motion(&data.s[k]);
                let lin = sw.lin + cross(&sw.ang, &p);
                let column = [lin.x, lin.y, lin.z, sw.ang.x, sw.ang.y, sw.ang.z];
                for (r, value) in column[..rows].iter().enumerate() {
                    out[(row + r) * n + k] += sign * *value;
                }
            }
        }
        row += rows;
    }
}

/// `gamma = dJ/dt qd` (m rows) written to `out` (runs the forward pass at `qdd = 0`).
#[inline(always)]
pub fn loop_gamma<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], out: &mut [T]) {
    forward_acceleration(model, data, q, qd, None);
    gamma_after_accelerations(model, data, Vec3::zeros(), out);
}

/// `gamma` from the poses, twists and accelerations of a forward pass already run at `(q, qd)` with
/// `qdd = 0`, whose base moved with the linear acceleration `base` (zero; or `-g`, RNEA's fictitious
/// upward acceleration that stands for gravity, RBDA §5.3). That acceleration reaches every body
/// as `^iX_0 (base, 0)`, whose classical linear acceleration in base axes is `base` itself (no
/// angular part, so no transport term): it is taken off each frame's row (it would cancel between
/// the two frames of a loop, except where one of them is on the base).
#[inline(always)]
pub(super) fn gamma_after_accelerations<T: Real>(model: &Model, data: &Data<T>, base: Vec3<T>, out: &mut [T]) {
    out[..model.loop_rows()].fill(T::zero());
    let mut row = 0;
    for l in &model.loops {
        let rows = l.kind.rows();
        for (frame, sign) in [(l.frame_a, T::one()), (l.frame_b, -T::one())] {
            let f = &model.frames[frame];
            let Some(body) = f.body else { continue };
            let body_from_frame = f.body_from_frame.splat::<T>();
            let rot = (data.world_from_body[body] * body_from_frame).rot;
            // twist and spatial acceleration of the frame in its own axes
            let v = body_from_frame.inv_act_motion(&data.v[body]);
            let a = body_from_frame.inv_act_motion(&data.a[body]);
            // d/dt of the world twist: classical acceleration of the origin, angular acceleration
            let lin: Vec3<T> = mv(&rot, &(a.lin + cross(&v.ang, &v.lin))) - base;
            let ang: Vec3<T> = mv(&rot, &a.ang);
            let values = [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z];
            for (r, value) in values[..rows].iter().enumerate() {
                out[row + r] += sign * *value;
            }
        }
        row += rows;
    }
}
