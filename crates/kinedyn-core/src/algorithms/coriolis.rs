//! The Christoffel-consistent Coriolis matrix `C(q, qd)` and the Christoffel symbols `c_ijk(q)`.
//!
//! Source: S. Echeandia and P. M. Wensing, "Numerical methods to compute the Coriolis matrix and
//! Christoffel symbols for rigid-body systems", J. Comput. Nonlinear Dyn. 16(9), 2021: with every
//! quantity in world (ground) coordinates,
//! `C = sum_i J_i^T (I_i dJ_i/dt + B_i(v_i) J_i)`, with the body-level factorisation
//! `B(I, v) = 1/2 [(v x*) I - I (v x) + (I v) xbar*]`, where `(f xbar*) m = m x* f`.
//! `dI/dt = (v x*) I - I (v x)` is again a rigid-body inertia (with zero mass rate), and `B` is
//! linear in the body's inertia, so subtree sums need only the composite inertia `I^c`, its rate
//! `dI^c/dt` and the composite momentum `h^c = sum I_k v_k` (16 numbers, no 6x6 matrices):
//! `B^c s = 1/2 (dI^c/dt s + s x* h^c)`, `B^c^T s = 1/2 (dI^c/dt s - s x* h^c)`.
//! Because `J_i`'s column j is `s_j` (world) for the joints supporting i, and `ds_j/dt = v_j x s_j`:
//! - j supports k (j <= k): `C[j][k] = s_j . (I^c_k ds_k/dt + B^c_k s_k)`;
//! - k supports j, k != j: `C[j][k] = ds_k/dt . (I^c_j s_j) + s_k . (B^c_j^T s_j)`.
//!
//! The armature is constant and adds nothing to `C`. The Christoffel symbols follow from
//! linearity in qd: `c_ijk = C(q, e_i)[k][j]`, with `C[k][j] = sum_i c_ijk qd_i` (docs/architecture.md).
//!
//! | symbol             | here                 | meaning (world coordinates)                      |
//! |--------------------|----------------------|--------------------------------------------------|
//! | `s_j`, `ds_j/dt`   | `data.s_w`, `data.sd_w` | joint subspace and its rate                    |
//! | `v_i`              | `data.v_w[i]`        | body twist                                       |
//! | `I_i`              | `data.i_w[i]`        | body inertia about the world origin              |
//! | `I^c_i`, `dI^c_i/dt` | `data.ic_w`, `data.icd_w` | composite inertia of subtree i and its rate |
//! | `h^c_i`            | `data.hc_w[i]`       | composite momentum of subtree i                  |
//! | `C`                | `out` (row-major n x n) | Coriolis matrix                               |

use super::kinematics::{forward_kinematics, forward_velocity};
use crate::data::Data;
use crate::model::Model;
use crate::spatial::{cross, outer, Inertia, Mat3, Motion, Real, Vec3};

/// `dI/dt` of a rigid body with inertia `i` (about the world origin) moving with twist `v`
/// (world coordinates): `(v x*) I - I (v x)` in parameters: mass rate 0,
/// `dh/dt = m v_o + w x h`, `dI_o/dt = 2 (h . v_o) 1 - v_o h^T - h v_o^T + [w]x I_o - I_o [w]x`.
#[inline(always)]
pub(crate) fn inertia_rate<T: Real>(i: &Inertia<T>, v: &Motion<T>) -> Inertia<T> {
    let (vo, w, h) = (&v.lin, &v.ang, &i.h);
    // [w]x I_o - I_o [w]x = A + A^T with A = [w]x I_o (I_o symmetric): columns w x (I_o e_k)
    let io = &i.i_o;
    let c0 = cross(w, &Vec3::new(io[(0, 0)], io[(1, 0)], io[(2, 0)]));
    let c1 = cross(w, &Vec3::new(io[(0, 1)], io[(1, 1)], io[(2, 1)]));
    let c2 = cross(w, &Vec3::new(io[(0, 2)], io[(1, 2)], io[(2, 2)]));
    let a = Mat3::new(c0.x, c1.x, c2.x, c0.y, c1.y, c2.y, c0.z, c1.z, c2.z);
    let sym = a - outer(vo, h);
    let io_dot = Mat3::from_diagonal_element(T::splat(2.0) * h.dot(vo)) + sym + sym.transpose();
    Inertia::new(T::zero(), vo * i.mass + cross(w, h), io_dot)
}

/// World-coordinate kinematics shared by `coriolis_matrix` and `christoffel`: `s_w`, `i_w`.
#[inline(always)]
fn world_subspaces_and_inertias<T: Real>(model: &Model, data: &mut Data<T>) {
    for i in 0..model.n {
        let x = &data.world_from_body[i];
        data.s_w[i] = x.act_motion(&data.s[i]);
        data.i_w[i] = x.act_inertia(&model.inertia[i].splat());
    }
}

/// `C` from `data.s_w`, `data.v_w`, `data.i_w` (world), written to `out[j * rs + k * cs]`
/// (so that the Christoffel layout can be written without a transpose).
#[inline(always)]
fn coriolis_from_world<T: Real>(model: &Model, data: &mut Data<T>, out: &mut [T], rs: usize, cs: usize) {
    let n = model.n;
    for i in 0..n {
        // ds_i/dt = v_i x s_i ;  I^c_i = I_i ;  dI^c_i/dt = (v_i x*) I_i - I_i (v_i x) ;  h^c_i = I_i v_i
        // (a column of a multi-DOF joint is fixed in the joint's child, the group's last body)
        let v = data.v_w[i];
        let inertia = data.i_w[i];
        data.sd_w[i] = data.v_w[model.group_last[i]].cross_motion(&data.s_w[i]);
        data.ic_w[i] = inertia;
        data.icd_w[i] = inertia_rate(&inertia, &v);
        data.hc_w[i] = inertia.mul_motion(&v);
    }
    for i in (0..n).rev() {
        // composite sums over the subtree: I^c_λ += I^c_i, dI^c_λ/dt += dI^c_i/dt, h^c_λ += h^c_i
        if let Some(p) = model.parent[i] {
            let (ic, icd, hc) = (data.ic_w[i], data.icd_w[i], data.hc_w[i]);
            data.ic_w[p] += ic;
            data.icd_w[p] += icd;
            data.hc_w[p] += hc;
        }
    }
    for k in 0..n {
        for j in 0..n {
            out[j * rs + k * cs] = T::zero();
        }
    }
    for k in 0..n {
        let (s, sd) = (data.s_w[k], data.sd_w[k]);
        let (ic, icd, hc) = (&data.ic_w[k], &data.icd_w[k], &data.hc_w[k]);
        // B^c_k s_k = 1/2 (dI^c_k/dt s_k + s_k x* h^c_k) ;  B^c_k^T s_k = 1/2 (dI^c_k/dt s_k - s_k x* h^c_k)
        let icd_s = icd.mul_motion(&s);
        let s_h = s.cross_force(hc);
        let b_s = (icd_s + s_h) * T::splat(0.5);
        let bt_s = (icd_s - s_h) * T::splat(0.5);
        // F1 = I^c_k ds_k/dt + B^c_k s_k ;  F2 = I^c_k s_k
        let f1 = ic.mul_motion(&sd) + b_s;
        let f2 = ic.mul_motion(&s);
        // C[j][k] = s_j . F1 for the joints j supporting k (k included)
        // C[k][j] = ds_j/dt . F2 + s_j . B^c_k^T s_k for the joints j supporting k (k excluded)
        out[k * rs + k * cs] = s.dot(&f1);
        let mut j = model.parent[k];
        while let Some(jj) = j {
            out[jj * rs + k * cs] = data.s_w[jj].dot(&f1);
            out[k * rs + jj * cs] = data.sd_w[jj].dot(&f2) + data.s_w[jj].dot(&bt_s);
            j = model.parent[jj];
        }
    }
}

/// `C(q, qd)` written row-major to `data.m` (n x n).
#[inline(always)]
pub fn coriolis_matrix<'d, T: Real>(model: &Model, data: &'d mut Data<T>, q: &[T], qd: &[T]) -> &'d [T] {
    let n = model.n;
    // v_i (body) by the velocity pass, then everything in world coordinates
    forward_velocity(model, data, q, qd);
    world_subspaces_and_inertias(model, data);
    for i in 0..n {
        data.v_w[i] = data.world_from_body[i].act_motion(&data.v[i]);
    }
    let mut m = std::mem::take(&mut data.m);
    coriolis_from_world(model, data, &mut m, n, 1);
    data.m = m;
    &data.m
}

/// Christoffel symbols of the first kind, `out[i][j][k] = c_ijk` (n x n x n, row-major), with
/// `c_ijk = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k)`, from `C(q, e_i)[k][j] = c_ijk`.
#[inline(always)]
pub fn christoffel<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], out: &mut [T]) {
    let n = model.n;
    forward_kinematics(model, data, q);
    world_subspaces_and_inertias(model, data);
    for i in 0..n {
        // qd = e_i: v_k = s_i for the bodies k that joint i supports, 0 elsewhere
        for k in 0..n {
            data.v_w[k] = if model.support[k].binary_search(&i).is_ok() {
                data.s_w[i]
            } else {
                Motion::zero()
            };
        }
        // out[i][j][k] = C[k][j]: row stride 1, column stride n within block i
        coriolis_from_world(model, data, &mut out[i * n * n..(i + 1) * n * n], 1, n);
    }
}
