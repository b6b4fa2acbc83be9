//! The joint-torque regressor `Y(q, qd, qdd)`, linear in the inertial parameters: `tau = Y pi`.
//!
//! Source: Atkeson, An & Hollerbach, "Estimation of inertial parameters of manipulator loads and
//! links", IJRR 5(3), 1986, in spatial form (RBDA Table 5.1 with `f_i` written as `A_i pi_i`):
//! `f_i = I_i a_i + v_i x* I_i v_i` is linear in body i's parameters
//! `pi_i = [m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (about the body origin, body axes;
//! docs/architecture.md's order), and joint j carries body i's force when j supports i:
//! `Y[j][10 i + c] = s_j . ^jX_i^* A_i[:, c]`. Gravity enters as `a_0 = -g`; friction and the
//! armature are not inertial parameters of a body and are left out.
//!
//! | symbol      | here                   | meaning                                         |
//! |-------------|------------------------|-------------------------------------------------|
//! | `v_i`, `a_i`| `data.v`, `data.a`     | body twist and acceleration (gravity included)  |
//! | `A_i`       | `cols` (10 forces)     | `d f_i / d pi_i`, body coordinates               |
//! | `Y`         | `out` (row-major n x 10n) | regressor                                    |

use super::kinematics::joint_transforms;
use crate::data::Data;
use crate::model::Model;
use crate::spatial::{cross, mv, splat3, Force, Mat3, Motion, Real, Vec3};

/// Columns of `A_i = d f / d pi` for a body with twist `v` and acceleration `a`.
#[inline(always)]
fn body_columns<T: Real>(v: &Motion<T>, a: &Motion<T>) -> [Force<T>; 10] {
    let (vl, w, al, aw) = (&v.lin, &v.ang, &a.lin, &a.ang);
    let mut cols = [Force::zero(); 10];
    // m: f = [a_o + w x v_o; 0]
    cols[0] = Force::new(al + cross(w, vl), Vec3::zeros());
    // h = e_k: f = [a_w x e + w x (w x e); e x a_o + w x (e x v_o) + v_o x (w x e)]
    for k in 0..3 {
        let e = splat3::<T>(&Vec3::ith(k, 1.0));
        let we = cross(w, &e);
        cols[1 + k] = Force::new(
            cross(aw, &e) + cross(w, &we),
            cross(&e, al) + cross(w, &cross(&e, vl)) + cross(vl, &we),
        );
    }
    // I_o = E (Ixx, Ixy, Iyy, Ixz, Iyz, Izz): f = [0; E a_w + w x (E w)]
    const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)];
    for (c, &(r, s)) in PAIRS.iter().enumerate() {
        let mut e = Mat3::zeros();
        e[(r, s)] = T::one();
        e[(s, r)] = T::one();
        cols[4 + c] = Force::new(Vec3::zeros(), mv(&e, aw) + cross(w, &mv(&e, w)));
    }
    cols
}

/// `Y(q, qd, qdd)` written row-major to `out` (n x 10 n).
#[inline(always)]
pub fn regressor<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], qdd: &[T], out: &mut [T]) {
    let n = model.n;
    let w = 10 * n;
    out[..n * w].fill(T::zero());
    let a0 = Motion::new(-splat3::<T>(&model.gravity), Vec3::zeros());
    joint_transforms(model, data, q);
    for i in 0..n {
        // v_i = ^iX_λ v_λ + s_i qd_i ;  a_i = ^iX_λ a_λ + s_i qdd_i + v_i x s_i qd_i  (a_0 = -g)
        let x_up = data.parent_from_body[i];
        let vj = data.s[i] * qd[i];
        let (v, a) = match model.parent[i] {
            Some(p) => (x_up.inv_act_motion(&data.v[p]) + vj, x_up.inv_act_motion(&data.a[p])),
            None => (vj, x_up.inv_act_motion(&a0)),
        };
        data.v[i] = v;
        data.a[i] = a + data.s[i] * qdd[i] + model.velocity_product(i, &v, qd);
    }
    for i in 0..n {
        // A_i = d f_i / d pi_i ;  Y[i][10 i + c] = s_i . A_i[c]
        let mut cols = body_columns(&data.v[i], &data.a[i]);
        for (c, col) in cols.iter().enumerate() {
            out[i * w + 10 * i + c] = data.s[i].dot(col);
        }
        // for j supporting i: A = ^λX_j^* A ;  Y[λ][10 i + c] = s_λ . A[c]
        let mut j = i;
        while let Some(p) = model.parent[j] {
            let x = &data.parent_from_body[j];
            for (c, col) in cols.iter_mut().enumerate() {
                *col = x.act_force(col);
                out[p * w + 10 * i + c] = data.s[p].dot(col);
            }
            j = p;
        }
    }
}
