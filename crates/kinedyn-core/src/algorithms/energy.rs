//! Kinetic and potential energy.
//!
//! Sources: RBDA eq. 2.71 (`T = 1/2 v . I v` per body) and Spong, Hutchinson & Vidyasagar,
//! *Robot Modeling and Control* (2006) §7.1: `K = 1/2 qd^T M qd`, `P = -sum_i m_i g . c_i`.
//! The reflected rotor inertia is part of `M` (docs/architecture.md), so `K` counts `1/2 armature qd^2`.
//!
//! | symbol   | here                      | meaning                                        |
//! |----------|---------------------------|------------------------------------------------|
//! | `v_i`    | `data.v[i]`               | body twist, body coordinates                   |
//! | `I_i`    | `model.inertia[i]`        | body inertia about its origin                  |
//! | `m_i c_i`| `world_from_body . h_i`   | first moment in the base frame                 |
//! | `g`      | `model.gravity`           | gravity acceleration, base coordinates         |

use super::kinematics::{forward_kinematics, forward_velocity};
use crate::data::Data;
use crate::model::Model;
use crate::spatial::{mv, splat3, Real};

/// `K(q, qd) = 1/2 sum_i v_i . I_i v_i + 1/2 sum_i armature_i qd_i^2 (= 1/2 qd^T M qd)`.
// i: the body number, indexing the model's and the data's per-body arrays together
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub fn kinetic_energy<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T]) -> T {
    forward_velocity(model, data, q, qd);
    // K = sum_i 1/2 v_i . I_i v_i + 1/2 J_m r^2 qd_i^2
    let mut k = T::zero();
    for i in 0..model.n {
        k += model.inertia[i].splat::<T>().kinetic_energy(&data.v[i])
            + T::splat(0.5 * model.armature[i]) * qd[i] * qd[i];
    }
    k
}

/// `P(q) = -sum_i m_i g . c_i` (zero at the base origin), so that `g(q) = dP/dq`.
#[inline(always)]
pub fn potential_energy<T: Real>(model: &Model, data: &mut Data<T>, q: &[T]) -> T {
    forward_kinematics(model, data, q);
    // P = -g . sum_i (R_i h_i + m_i p_i)
    let g = splat3::<T>(&model.gravity);
    let mut p = T::zero();
    for i in 0..model.n {
        let x = &data.world_from_body[i];
        let inertia = &model.inertia[i];
        p += g.dot(&(mv(&x.rot, &splat3(&inertia.h)) + x.trans * T::splat(inertia.mass)));
    }
    -p
}
