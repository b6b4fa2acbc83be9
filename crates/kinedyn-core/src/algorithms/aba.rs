//! Forward dynamics by the articulated-body algorithm.
//!
//! Source: RBDA Table 7.1 (Featherstone 2008, §7.3), gravity as the base acceleration `a_0 = -g`.
//! Drives as in docs/architecture.md: the reflected rotor inertia adds to the joint's articulated inertia,
//! `D_i = s_i^T IA_i s_i + armature_i`, and friction is moved to the input side,
//! `tau_i - viscous_i qd_i - coulomb_i sign(qd_i)` (direction-dependent Coulomb levels:
//! `Model::coulomb_torque`). A joint whose `D_i` vanishes (a massless subtree, a point mass on the
//! axis) makes `M` singular: reported as an error naming the joint.
//!
//! | symbol        | here                         | meaning                                       |
//! |---------------|------------------------------|-----------------------------------------------|
//! | `^iX_λ(i)`    | `x_up` (`parent_from_body`)  | parent -> body i transform (used inverted)     |
//! | `v_i`, `c_i`  | `data.v[i]`, `data.c[i]`     | body twist, velocity-product acceleration      |
//! | `I^A_i`       | `data.ia[i]`                 | articulated inertia (3x3 blocks)               |
//! | `p^A_i`       | `data.pa[i]`                 | articulated bias force                         |
//! | `U_i`, `D_i`, `u_i` | `data.u_f`, `1/data.d_inv`, `data.u` | RBDA's joint-space projections  |
//! | `I^a`, `p^a`  | `ia`, `pa`                   | what body i passes to its parent               |
//! | `a_i`         | `data.a[i]`                  | body acceleration (gravity included)           |

use super::kinematics::{forward_kinematics, joint_transforms};
use super::rnea::friction;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::{splat3, ArticulatedInertia, Motion, Real, Vec3};

/// Relative size under which `D_i` counts as zero (`D_i <= EPS_D * trace(IA_i)`).
const EPS_D: f64 = 1e-13;
/// An articulated inertia whose trace exceeds this comes from a state or an inertia no robot has
/// (the description refuses parameters over 1e100): a failed pivot then says float64 overflowed.
const HUGE_TRACE: f64 = 1e200;

/// `qdd = aba(q, qd, tau, f_ext)` written to `data.qdd`; `f_ext` as in [`super::rnea::rnea`].
// `!(a > b)` is the pivot test that NaN also fails, in one comparison per lane
#[allow(clippy::neg_cmp_op_on_partial_ord)]
#[inline(always)]
pub fn aba<'d, T: Real>(
    model: &Model,
    data: &'d mut Data<T>,
    q: &[T],
    qd: &[T],
    tau: &[T],
    f_ext: Option<&[T]>,
) -> Result<&'d [T]> {
    let n = model.n;
    if f_ext.is_some() {
        forward_kinematics(model, data, q);
    } else {
        joint_transforms(model, data, q);
    }
    // pass 1, root to leaves
    for i in 0..n {
        // X_J, s_i = jcalc(q_i);  ^iX_λ = X_J X_T
        let x_up = data.parent_from_body[i];
        // v_i = ^iX_λ v_λ + s_i qd_i ;  c_i = v_i x s_i qd_i
        let joint = &model.joints[i];
        let vj = joint.motion(qd[i]);
        let v = match model.parent[i] {
            Some(p) => x_up.inv_act_motion(&data.v[p]) + vj,
            None => vj,
        };
        data.v[i] = v;
        data.c[i] = model.velocity_product(i, &v, qd);
        // I^A_i = I_i ;  p^A_i = v_i x* I_i v_i - ^iX_0^* f^x_i
        let inertia = &model.inertia[i].splat::<T>();
        data.ia[i] = ArticulatedInertia::from(inertia);
        let mut pa = v.cross_force(&inertia.mul_motion(&v));
        if let Some(fx) = f_ext {
            // ^iX_0^* f^x_i, the moment moved from the link-frame origin to the body origin
            pa -= model.body_wrench(i, &data.world_from_body[i].rot, fx);
        }
        data.pa[i] = pa;
    }
    // pass 2, leaves to root
    for i in (0..n).rev() {
        let joint = &model.joints[i];
        let ia = data.ia[i];
        // U_i = I^A_i s_i ;  D_i = s_i^T U_i + armature_i ;  u_i = tau_i - friction_i - s_i^T p^A_i
        let u_f = ia.times_s(joint);
        let armature = model.armature[i];
        let d = joint.project(&u_f) + T::splat(armature);
        let trace = ia.trace() + T::splat(armature);
        // the pivot test lane by lane (one lane per state of a batch; a recording has no values
        // to test: the program's caller tests them, trace::record)
        let lanes = if T::RECORDING { 0 } else { T::LANES };
        if let Some(k) = (0..lanes).find(|&k| !(d.lane(k) > EPS_D * trace.lane(k)) || !d.lane(k).is_finite()) {
            let (d, trace) = (d.lane(k), trace.lane(k));
            let overflow = !d.is_finite() || !trace.is_finite() || trace.abs().max(d.abs()) > HUGE_TRACE;
            let why = if overflow {
                "an inertia or a state too large for float64".to_string()
            } else if d < 0.0 {
                "a negative inertia about the axis: M is indefinite, so some body of the subtree has an inertia \
                 no rigid body has (check the signs of the products of inertia)"
                    .to_string()
            } else if d == 0.0 || trace <= 0.0 {
                "a massless or inertia-free subtree: no inertia about the axis and no rotor inertia".to_string()
            } else {
                format!(
                    "{:.1e} times the trace {trace:e} of the subtree's articulated inertia: its inertia about this axis is \
                     negligible next to the rest (a missing mass, or a huge inertia elsewhere in the subtree: check the units)",
                    d / trace
                )
            };
            return Err(Error::SingularMassMatrix {
                joint: i,
                overflow,
                message: format!(
                    "joint {i} has articulated inertia D = {d:e} about its axis ({why}); forward dynamics is undefined"
                ),
            });
        }
        let d_inv = T::one() / d;
        let u = tau[i] - friction(model, i, qd[i]) - joint.project(&data.pa[i]);
        data.u_f[i] = u_f;
        data.d_inv[i] = d_inv;
        data.u[i] = u;
        if let Some(p) = model.parent[i] {
            // I^a = I^A_i - U_i D_i^-1 U_i^T ;  p^a = p^A_i + I^a c_i + U_i D_i^-1 u_i
            let ia_small = ia.sub_rank_one(&u_f, d_inv);
            let pa = data.pa[i] + ia_small.mul_motion(&data.c[i]) + u_f * (d_inv * u);
            // I^A_λ += ^λX_i^* I^a ^iX_λ ;  p^A_λ += ^λX_i^* p^a
            let x_up = &data.parent_from_body[i];
            let add = x_up.act_articulated(&ia_small);
            let padd = x_up.act_force(&pa);
            let parent = &mut data.ia[p];
            parent.a += add.a;
            parent.b += add.b;
            parent.c += add.c;
            data.pa[p] += padd;
        }
    }
    // pass 3, root to leaves
    let a0 = Motion::new(-splat3::<T>(&model.gravity), Vec3::zeros());
    for i in 0..n {
        // a'_i = ^iX_λ a_λ + c_i ;  qdd_i = D_i^-1 (u_i - U_i^T a'_i) ;  a_i = a'_i + s_i qdd_i
        let ap = match model.parent[i] {
            Some(p) => data.parent_from_body[i].inv_act_motion(&data.a[p]),
            None => data.parent_from_body[i].inv_act_motion(&a0),
        } + data.c[i];
        let qdd = data.d_inv[i] * (data.u[i] - ap.dot(&data.u_f[i]));
        data.qdd[i] = qdd;
        data.a[i] = ap + model.joints[i].motion(qdd);
    }
    Ok(&data.qdd)
}
