//! Inverse dynamics by the recursive Newton-Euler algorithm.
//!
//! Source: R. Featherstone, *Rigid Body Dynamics Algorithms* (RBDA), Springer 2008, Table 5.1
//! (gravity as a fictitious base acceleration `a_0 = -g`, §5.3), with external forces as in
//! eq. 5.20 and the drive terms of docs/architecture.md: `tau = M qdd + C qd + g + friction - J^T f_ext`.
//!
//! | symbol      | here                       | meaning                                            |
//! |-------------|----------------------------|----------------------------------------------------|
//! | `^iX_λ(i)`  | `x_up[i]` (`parent_from_body`, used inverted) | parent -> body i motion transform |
//! | `s_i`       | `data.s[i]`                | joint motion subspace, body coordinates            |
//! | `v_i, a_i`  | `data.v[i], data.a[i]`     | body twist / acceleration (gravity included)       |
//! | `f_i`       | `data.f[i]`                | force transmitted by joint i onto body i           |
//! | `I_i`       | `model.inertia[i]`         | body inertia about its origin                      |
//! | `f^x_i`     | `f_ext` (base axes, link origin) | external wrench on body i (`Model::body_wrench`) |
//! | `J_m r^2`   | `model.armature[i]`        | reflected rotor inertia, adds `armature qdd`       |

use super::kinematics::{forward_kinematics, joint_transforms};
use crate::data::Data;
use crate::model::Model;
use crate::spatial::{splat3, Motion, Real, Vec3};

/// Joint friction `viscous qd + coulomb sign(qd)` of joint i (with direction-dependent Coulomb
/// levels: [`Model::coulomb_torque`]).
#[inline(always)]
pub(crate) fn friction<T: Real>(model: &Model, i: usize, qd: T) -> T {
    T::splat(model.viscous[i]) * qd + model.coulomb_torque(i, qd)
}

/// What `rnea_with` includes besides the rigid-body terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RneaTerms {
    /// Gravity as the base acceleration `-g`.
    pub gravity: bool,
    /// Joint friction and reflected rotor inertia (`armature qdd`).
    pub drives: bool,
}

impl RneaTerms {
    pub const ALL: Self = Self {
        gravity: true,
        drives: true,
    };
    pub const RIGID: Self = Self {
        gravity: true,
        drives: false,
    };
}

/// `tau = rnea(q, qd, qdd, f_ext)` with gravity, friction and armature (written to `data.tau`).
///
/// `f_ext`: `n * 6` numbers, per body `[force; moment]` in base axes, the moment about the body's
/// link-frame origin ([`Model::link_origin`]; the body-frame origin unless the model sets one).
#[inline(always)]
pub fn rnea<'d, T: Real>(
    model: &Model,
    data: &'d mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    f_ext: Option<&[T]>,
) -> &'d [T] {
    rnea_with(model, data, q, qd, qdd, f_ext, RneaTerms::ALL)
}

/// RNEA with a choice of terms (the bias `C qd + g` is `rnea_with(q, qd, 0, None, RIGID)`).
#[inline(always)]
pub fn rnea_with<'d, T: Real>(
    model: &Model,
    data: &'d mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    f_ext: Option<&[T]>,
    terms: RneaTerms,
) -> &'d [T] {
    let n = model.n;
    if f_ext.is_some() {
        // world_from_body rotations are needed to bring f_ext into body axes
        forward_kinematics(model, data, q);
    } else {
        joint_transforms(model, data, q);
    }
    // every per-body array sliced to n once: the loops below index them without bounds checks
    let (parent, joints, inertia) = (&model.parent[..n], &model.joints[..n], &model.inertia[..n]);
    let (qd, qdd) = (&qd[..n], &qdd[..n]);
    let (x_up, v, a, f) = (
        &mut data.parent_from_body[..n],
        &mut data.v[..n],
        &mut data.a[..n],
        &mut data.f[..n],
    );
    // a_0 = -g (a fictitious upward acceleration of the base replaces gravity)
    let a0 = if terms.gravity {
        Motion::new(-splat3::<T>(&model.gravity), Vec3::zeros())
    } else {
        Motion::zero()
    };
    for i in 0..n {
        // X_J, s = jcalc(q_i);  ^iX_λ = X_J X_T (stored as its inverse, parent_from_body)
        let x = x_up[i];
        let joint = &joints[i];
        // v_i = ^iX_λ v_λ + s_i qd_i ;  a_i = ^iX_λ a_λ + s_i qdd_i + v_i x s_i qd_i
        let (vp, ap) = match parent[i] {
            Some(p) => (x.inv_act_motion(&v[p]), x.inv_act_motion(&a[p])),
            None => (Motion::zero(), x.inv_act_motion(&a0)),
        };
        let vi = vp + joint.motion(qd[i]);
        let ai = ap + joint.motion(qdd[i]) + model.velocity_product(i, &vi, qd);
        // f_i = I_i a_i + v_i x* I_i v_i - ^iX_0^* f^x_i
        let body = &inertia[i].splat::<T>();
        let mut fi = body.mul_motion(&ai) + vi.cross_force(&body.mul_motion(&vi));
        if let Some(fx) = f_ext {
            // ^iX_0^* f^x_i, the moment moved from the link-frame origin to the body origin
            fi -= model.body_wrench(i, &data.world_from_body[i].rot, fx);
        }
        v[i] = vi;
        a[i] = ai;
        f[i] = fi;
    }
    let tau = &mut data.tau[..n];
    for i in (0..n).rev() {
        // tau_i = s_i^T f_i (+ armature qdd_i + friction(qd_i))
        let mut t = joints[i].project(&f[i]);
        if terms.drives {
            t += T::splat(model.armature[i]) * qdd[i] + friction(model, i, qd[i]);
        }
        tau[i] = t;
        // f_λ(i) += ^λX_i^* f_i
        if let Some(p) = parent[i] {
            let fp = x_up[i].act_force(&f[i]);
            f[p] += fp;
        }
    }
    &data.tau
}

/// The bias torque `C(q, qd) qd + g(q)`: RNEA at `qdd = 0` without friction (written to `data.tau`).
#[inline(always)]
pub fn bias_torque<'d, T: Real>(model: &Model, data: &'d mut Data<T>, q: &[T], qd: &[T]) -> &'d [T] {
    let n = model.n;
    // qdd = 0 is passed through data.x (no allocation)
    let mut zero = std::mem::take(&mut data.x);
    zero[..n].fill(T::zero());
    rnea_with(model, data, q, qd, &zero, None, RneaTerms::RIGID);
    data.x = zero;
    &data.tau
}
