//! The gravity torque `g(q)` (= RNEA at `qd = qdd = 0`, without friction), by composite masses.
//!
//! Source: RBDA Table 5.1 specialised to `v = a_J = 0`: every body's acceleration is the uniform
//! field `a_0 = -g`, so the force a joint transmits is gravity on its whole subtree, which depends
//! only on the subtree's mass `m^c` and first moment `h^c = m^c c^c` (RBDA eq. 2.63's `h`):
//! `tau_i = s_i . [-m^c_i g_i; -h^c_i x g_i]`, `g_i` = gravity in body i's axes. No inertia
//! tensors, no spatial forces: one rotation per body down, one 3-vector per body up.
//!
//! | symbol        | here                    | meaning                                        |
//! |---------------|-------------------------|------------------------------------------------|
//! | `^iX_λ(i)`    | `x_up` (`parent_from_body`) | parent -> body i transform (used inverted)  |
//! | `g_i`         | `data.g_b[i]`           | gravity acceleration in body i's axes          |
//! | `m^c_i`, `h^c_i` | `data.mc[i]`, `data.hc[i]` | subtree mass and first moment (body i frame) |

use super::kinematics::joint_transforms;
use crate::data::Data;
use crate::joint::JointKind;
use crate::model::Model;
use crate::spatial::{cross, mtv, mv, splat3, Real};

/// `g(q)` written to `data.tau`.
#[inline(always)]
pub fn gravity_torque<'d, T: Real>(model: &Model, data: &'d mut Data<T>, q: &[T]) -> &'d [T] {
    let n = model.n;
    joint_transforms(model, data, q);
    for i in 0..n {
        // g_i = R_λ,i^T g_λ  (g_0 = model.gravity) ;  m^c_i = m_i ;  h^c_i = h_i
        let x_up = data.parent_from_body[i];
        let g_parent = match model.parent[i] {
            Some(p) => data.g_b[p],
            None => splat3(&model.gravity),
        };
        data.g_b[i] = mtv(&x_up.rot, &g_parent);
        data.mc[i] = T::splat(model.inertia[i].mass);
        data.hc[i] = splat3(&model.inertia[i].h);
    }
    for i in (0..n).rev() {
        // tau_i = s_i . [-m^c_i g_i ; -h^c_i x g_i]
        let axis = &splat3::<T>(&model.joints[i].axis);
        data.tau[i] = match model.joints[i].kind {
            JointKind::Revolute => -axis.dot(&cross(&data.hc[i], &data.g_b[i])),
            JointKind::Prismatic => -(data.mc[i] * axis.dot(&data.g_b[i])),
        };
        // m^c_λ += m^c_i ;  h^c_λ += R h^c_i + m^c_i t   (first moment moved to the parent frame)
        if let Some(p) = model.parent[i] {
            let x = &data.parent_from_body[i];
            let h = mv(&x.rot, &data.hc[i]) + x.trans * data.mc[i];
            data.hc[p] += h;
            let m = data.mc[i];
            data.mc[p] += m;
        }
    }
    &data.tau
}
