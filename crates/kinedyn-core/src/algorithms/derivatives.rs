//! Analytical partial derivatives of inverse and forward dynamics.
//!
//! Inverse dynamics: `dtau/dq` and `dtau/dqd`, exact and O(n^2), by two derivations that the
//! tests hold against each other (and against finite differences and Pinocchio):
//! - in world coordinates ([`rnea_derivatives`]; the derivation is at `rnea_derivatives_world`),
//!   where each entry is three dot products of subtree-composite
//!   quantities: the organisation of Carpentier & Mansard, "Analytical Derivatives of Rigid Body
//!   Dynamics Algorithms", RSS 2018;
//! - by differentiating the recursive Newton-Euler algorithm (RBDA Table 5.1, as in `rnea.rs`)
//!   line by line along each coordinate in body coordinates: one tangent ("forward-mode") sweep per
//!   coordinate over the subtree it moves and back to the root ([`rnea_derivatives_tangent`]; below).
//!
//! `dtau/dqdd = M`.
//!
//! Derivation (body coordinates; body i's frame moves with q_i, `s_i` is constant in it). For a
//! motion `m` given in the parent, `d(^iX_λ m)/dq_i = -s_i x ^iX_λ m = (^iX_λ m) x s_i`; for a
//! force `f` given in body i, `d(^λX_i^* f)/dq_i = ^λX_i^* (s_i x* f)`; for a wrench given in base
//! axes, `d(R_i^T u)/dq_j = (R_i^T u) x w_ij` with `w_ij` the angular part of `s_j` in body i's
//! axes (`psi_i` below). Differentiating each line of the RNEA along `q_j`:
//!
//! ```text
//! dv_i  = ^iX_λ dv_λ + [i=j] (^iX_λ v_λ) x s_i
//! da_i  = ^iX_λ da_λ + [i=j] (^iX_λ a_λ) x s_i + dv_i x s_i qd_i          (a_0 = -g)
//! df_i  = I_i da_i + dv_i x* I_i v_i + v_i x* I_i dv_i - d(R_i^T f^x_i)
//! df^c_λ += ^λX_i^* (df^c_i + [i=j] s_i x* f^c_i) ;   dtau_i/dq_j = s_i^T df^c_i
//! ```
//!
//! and along `qd_j` (the transforms do not depend on qd):
//!
//! ```text
//! dv_i  = ^iX_λ dv_λ + [i=j] s_i
//! da_i  = ^iX_λ da_λ + dv_i x s_i qd_i + [i=j] v_i x s_i
//! df_i  = I_i da_i + dv_i x* I_i v_i + v_i x* I_i dv_i
//! df^c_λ += ^λX_i^* df^c_i ;   dtau_i/dqd_j = s_i^T df^c_i + [i=j] viscous_i
//! ```
//!
//! Coulomb friction `coulomb sign(qd)` has derivative zero wherever it has one (qd != 0).
//!
//! Forward dynamics: `qdd = M^-1 (tau - b(q, qd))`, so with that `qdd`,
//! `dqdd/dq = -M^-1 dtau/dq`, `dqdd/dqd = -M^-1 dtau/dqd` (both at that `qdd`) and
//! `dqdd/dtau = M^-1` (Carpentier & Mansard 2018, §IV-B).

use super::coriolis::inertia_rate;
use super::kinematics::forward_kinematics;
use super::minv::inverse_of_mass_matrix;
use super::rnea::rnea;
use crate::data::{Data, Tangent};
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{cross, mv, outer, splat3, Force, Motion, Real, Vec3};

/// `dtau/dq` and `dtau/dqd` (row-major n x n: `[i * n + j] = dtau_i / dx_j`) at `(q, qd, qdd)`,
/// for the same `tau` as [`rnea`] (gravity, friction, armature, `f_ext`), and when asked for,
/// `dtau/dqdd = M` (a by-product of the pass: the CRBA in world coordinates).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn rnea_derivatives<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    f_ext: Option<&[T]>,
    dtau_dq: &mut [T],
    dtau_dqd: &mut [T],
    mass_matrix: Option<&mut [T]>,
) {
    rnea_derivatives_world(model, data, q, qd, qdd, f_ext, dtau_dq, dtau_dqd);
    if let Some(m) = mass_matrix {
        mass_matrix_from_world(model, data, m);
    }
}

/// `M` from the world-coordinate pass: `H_jk = S_j . (I^c_k S_k) = S_j . alpha_k` for j supporting
/// k (the CRBA in world coordinates, RBDA §6.2), plus the armature on the diagonal.
#[inline(always)]
fn mass_matrix_from_world<T: Real>(model: &Model, data: &Data<T>, m: &mut [T]) {
    let n = model.n;
    m[..n * n].fill(T::zero());
    for k in 0..n {
        for &j in &model.support[k] {
            let h = data.s_w[j].dot(&data.alpha[k]);
            m[j * n + k] = h;
            m[k * n + j] = h;
        }
        m[k * n + k] += T::splat(model.armature[k]);
    }
}

/// [`rnea_derivatives`] (without `M`) by tangent sweeps in body coordinates: the second, independent
/// derivation, about 2.5 times slower, kept as the reference the world-coordinate form is tested
/// against (and for anyone who wants to cross-check a result).
#[allow(clippy::too_many_arguments)]
pub fn rnea_derivatives_tangent(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    f_ext: Option<&[f64]>,
    dtau_dq: &mut [f64],
    dtau_dqd: &mut [f64],
) {
    assert!(
        model.plain,
        "the tangent-sweep derivatives are written for 1-DOF joints; use rnea_derivatives"
    );
    // the RNEA's own pass: parent_from_body, v_i, a_i and the composite forces f^c_i in data.f
    // (and world_from_body when f_ext is given)
    rnea(model, data, q, qd, qdd, f_ext);
    // the body momenta I_i v_i, which every sweep uses
    for i in 0..model.n {
        data.iv[i] = model.inertia[i].mul_motion(&data.v[i]);
    }
    for j in 0..model.n {
        tangent_sweeps(model, data, qd, f_ext, j, dtau_dq, dtau_dqd);
    }
}

/// [`rnea_derivatives`] without external wrenches, in world coordinates, where a coordinate's
/// effect on its subtree is a rotation about its axis and needs no transform down the tree
/// (the observation behind Carpentier & Mansard 2018). With `S_j` the joint axis, `p = λ(j)`,
/// `v`, `a` twists and accelerations (`a_0 = -g`), `I^c_k`, `dI^c_k/dt`, `h^c_k = sum I_i v_i`,
/// `F_k` the composite inertia, its rate, momentum and force of subtree k (as in `coriolis.rs`):
/// moving q_j turns the subtree rigidly except that `v_p`, `a_p` stay put, so
/// `dv_i/dq_j = S_j x (v_i - v_p)`, `da_i/dq_j = S_j x (a_i - a_p) - u x (v_i - v_p)` with
/// `u = S_j x v_p`, and summing `df_i` over subtree k (using `I (u x v) + v x* I u = dI/dt u`)
///
/// ```text
/// dF_k/dq_j  = S_j x* F_k + I^c_k w - u x* h^c_k - dI^c_k/dt u,       w = u x v_p - S_j x a_p
/// dF_k/dqd_j = 2 I^c_k dS_j/dt + dI^c_k/dt S_j + S_j x* h^c_k,        dS_j/dt = v_p x S_j
/// ```
///
/// for k in the subtree of j; an ancestor k of j sees `dF_j`. Then `dtau_k = S_k . dF_k`, plus
/// `(S_j x S_k) . F_k` along q_j for k below j, which cancels the first term of `dF_k/dq_j`. With
/// `alpha_k = I^c_k S_k`, `beta_k = dI^c_k/dt S_k` (both operators symmetric) and
/// `sigma_k = S_k x* h^c_k`, each entry below j is three dot products:
/// `dtau_k/dq_j = alpha_k . w + u . (sigma_k - beta_k)`, `dtau_k/dqd_j = 2 alpha_k . dS_j/dt + S_j . (beta_k - sigma_k)`.
///
/// External wrenches `(f_i, n_i)` (base axes, moment about body i's link-frame origin `p_i`, a
/// point fixed in body i: [`Model::link_origin`]) are the world force `(f_i, n_i + p_i x f_i)`,
/// subtracted from `f_i`. They do not turn with the subtree; only their point moves,
/// `dp_i/dq_j = S_j,lin + w_j x p_i`. Removing the rigid turn `S_j x* F^x` that
/// the formula above applies to them, and adding the true change `(0, dp_i x f_i)`, adds
/// `E_k(w_j) = (w_j x sum f_i, w_j x sum n_i + w_j tr(P_k) - P_k w_j)`, `P_k = sum f_i p_i^T` over
/// subtree k, to `dF_k/dq_j` (Jacobi: `w x (p x f) - (w x p) x f = p x (w x f)`).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn rnea_derivatives_world<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    f_ext: Option<&[T]>,
    dtau_dq: &mut [T],
    dtau_dqd: &mut [T],
) {
    world_pass(model, data, q, qd, Some(qdd), f_ext);
    world_derivatives(model, data, f_ext.is_some(), dtau_dq, dtau_dqd);
}

/// The world-coordinate quantities of [`rnea_derivatives_world`] at `(q, qd, qdd)` (`qdd = None`:
/// zero), composite over each subtree, and `alpha`, `beta`, `sigma`; body inertias kept in `i_w`.
#[inline(always)]
fn world_pass<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], qdd: Option<&[T]>, f_ext: Option<&[T]>) {
    let n = model.n;
    forward_kinematics(model, data, q);
    let a0 = Motion::new(-splat3::<T>(&model.gravity), Vec3::zeros());
    let parent = &model.parent[..n];
    let (s_w, v_w, a_w, i_w) = (
        &mut data.s_w[..n],
        &mut data.v_w[..n],
        &mut data.a_w[..n],
        &mut data.i_w[..n],
    );
    let (ic, icd, hc, fc) = (
        &mut data.ic_w[..n],
        &mut data.icd_w[..n],
        &mut data.hc_w[..n],
        &mut data.fc_w[..n],
    );
    // forward, world coordinates: S_i, v_i = v_p + S_i qd_i, a_i = a_p + S_i qdd_i + (v_p x S_i) qd_i,
    // I_i, dI_i/dt, h_i = I_i v_i, f_i = I_i a_i + v_i x* h_i
    for i in 0..n {
        let x = &data.world_from_body[i];
        let s = x.act_motion(&data.s[i]);
        let (vp, ap) = parent[i].map_or((Motion::zero(), a0), |p| (v_w[p], a_w[p]));
        let v = vp + s * qd[i];
        // the velocity product of a multi-DOF joint's column is v_λ x s with λ the joint's parent
        // (summed over the joint: v_λ x v_J = v_child x v_J), not the partial twist of the body before
        let v_lambda = if model.plain {
            vp
        } else {
            parent[model.group_first[i]].map_or(Motion::zero(), |p| v_w[p])
        };
        let mut a = ap + v_lambda.cross_motion(&s) * qd[i];
        if let Some(qdd) = qdd {
            a += s * qdd[i];
        }
        let inertia = x.act_inertia(&model.inertia[i].splat());
        let h = inertia.mul_motion(&v);
        (s_w[i], v_w[i], a_w[i], i_w[i]) = (s, v, a, inertia);
        (ic[i], icd[i], hc[i], fc[i]) = (
            inertia,
            inertia_rate(&inertia, &v),
            h,
            inertia.mul_motion(&a) + v.cross_force(&h),
        );
        if let Some(fx) = f_ext {
            // the wrench about the world origin, and its parts for the composite sums E_k
            let (f, m) = (
                Vec3::new(fx[6 * i], fx[6 * i + 1], fx[6 * i + 2]),
                Vec3::new(fx[6 * i + 3], fx[6 * i + 4], fx[6 * i + 5]),
            );
            // the point of application: body i's link-frame origin, fixed in the body like its origin
            let p = x.act_point(&splat3::<T>(&model.link_origin[i]));
            fc[i] -= Force::new(f, m + cross(&p, &f));
            (data.ext_f[i], data.ext_n[i], data.ext_p[i]) = (f, m, outer(&f, &p));
        }
    }
    // backward: composite sums over each subtree
    for i in (0..n).rev() {
        if let Some(p) = parent[i] {
            let (c, cd, h, f) = (ic[i], icd[i], hc[i], fc[i]);
            ic[p] += c;
            icd[p] += cd;
            hc[p] += h;
            fc[p] += f;
            if f_ext.is_some() {
                let (ef, en, ep) = (data.ext_f[i], data.ext_n[i], data.ext_p[i]);
                data.ext_f[p] += ef;
                data.ext_n[p] += en;
                data.ext_p[p] += ep;
            }
        }
    }
    let (alpha, beta, sigma) = (&mut data.alpha[..n], &mut data.beta[..n], &mut data.sigma[..n]);
    for k in 0..n {
        (alpha[k], beta[k], sigma[k]) = (
            ic[k].mul_motion(&s_w[k]),
            icd[k].mul_motion(&s_w[k]),
            s_w[k].cross_force(&hc[k]),
        );
    }
}

/// After `world_pass` at `qdd = 0`: the accelerations and composite forces at `qdd` (the
/// accelerations are linear in qdd: `a_i += sum over the joints k supporting i of S_k qdd_k`).
#[inline(always)]
fn add_joint_accelerations<T: Real>(model: &Model, data: &mut Data<T>, qdd: &[T]) {
    let n = model.n;
    let (s_w, a_w, i_w, fc) = (&data.s_w[..n], &mut data.a_w[..n], &data.i_w[..n], &mut data.fc_w[..n]);
    let (da, df) = (&mut data.dpsi[..n], &mut data.dfc_w[..n]);
    for i in 0..n {
        // da_i = da_p + S_i qdd_i ;  df_i = I_i da_i
        da[i] = model.parent[i].map_or(Motion::zero(), |p| da[p]) + s_w[i] * qdd[i];
        a_w[i] += da[i];
        df[i] = i_w[i].mul_motion(&da[i]);
    }
    for i in (0..n).rev() {
        if let Some(p) = model.parent[i] {
            let d = df[i];
            df[p] += d;
        }
        fc[i] += df[i];
    }
}

/// The derivative loops of [`rnea_derivatives_world`], from the quantities `world_pass` left in `data`.
#[inline(always)]
fn world_derivatives<T: Real>(model: &Model, data: &Data<T>, wrenches: bool, dtau_dq: &mut [T], dtau_dqd: &mut [T]) {
    let n = model.n;
    let a0 = Motion::new(-splat3::<T>(&model.gravity), Vec3::zeros());
    let parent = &model.parent[..n];
    let (s_w, v_w, a_w) = (&data.s_w[..n], &data.v_w[..n], &data.a_w[..n]);
    let (ic, icd, hc, fc) = (&data.ic_w[..n], &data.icd_w[..n], &data.hc_w[..n], &data.fc_w[..n]);
    let (alpha, beta, sigma) = (&data.alpha[..n], &data.beta[..n], &data.sigma[..n]);
    // E_k(w): how the subtree's wrenches change as coordinate j (axis w) turns it (see above)
    let (ext_f, ext_n, ext_p) = (&data.ext_f[..n], &data.ext_n[..n], &data.ext_p[..n]);
    let wrench_term = |k: usize, w: &Vec3<T>| -> Force<T> {
        let trace = ext_p[k][(0, 0)] + ext_p[k][(1, 1)] + ext_p[k][(2, 2)];
        Force::new(cross(w, &ext_f[k]), cross(w, &ext_n[k]) + w * trace - mv(&ext_p[k], w))
    };
    dtau_dq[..n * n].fill(T::zero());
    dtau_dqd[..n * n].fill(T::zero());
    for j in 0..n {
        let s = s_w[j];
        // a column of a multi-DOF joint moves the joint's child and subtree with the joint's parent λ
        // and its local velocity held (Pinocchio's q ⊕ δ): the 1-DOF formulas with p = λ, the columns
        // of the whole joint in the "subtree", and the rate 2 ds/dt = 2 v_p x s becoming
        // (v_λ + v_child) x s (equal for a 1-DOF joint)
        let head = model.group_first[j];
        let (vp, ap) = parent[head].map_or((Motion::zero(), a0), |p| (v_w[p], a_w[p]));
        let u = s.cross_motion(&vp);
        let w = u.cross_motion(&vp) - s.cross_motion(&ap);
        let sdot = if head == j && model.group_last[j] == j {
            vp.cross_motion(&s)
        } else {
            (vp + v_w[model.group_last[j]]).cross_motion(&s) * T::splat(0.5)
        };
        // the subtree of j: three dot products per entry
        for k in head..n {
            if k != head && model.support[k].binary_search(&head).is_err() {
                continue;
            }
            dtau_dq[k * n + j] = w.dot(&alpha[k]) + u.dot(&(sigma[k] - beta[k]));
            if wrenches {
                dtau_dq[k * n + j] += s_w[k].dot(&wrench_term(k, &s.ang));
            }
            dtau_dqd[k * n + j] = T::splat(2.0) * sdot.dot(&alpha[k]) + s.dot(&(beta[k] - sigma[k]));
        }
        dtau_dqd[j * n + j] += T::splat(model.viscous[j]);
        // the ancestors of j: dtau_k = S_k . dF_j
        if parent[head].is_none() {
            continue;
        }
        let mut df_q = s.cross_force(&fc[j]) + ic[j].mul_motion(&w) - u.cross_force(&hc[j]) - icd[j].mul_motion(&u);
        if wrenches {
            df_q += wrench_term(j, &s.ang);
        }
        let df_qd = ic[j].mul_motion(&sdot) * T::splat(2.0) + icd[j].mul_motion(&s) + s.cross_force(&hc[j]);
        let mut k = parent[head];
        while let Some(kk) = k {
            dtau_dq[kk * n + j] = s_w[kk].dot(&df_q);
            dtau_dqd[kk * n + j] = s_w[kk].dot(&df_qd);
            k = parent[kk];
        }
    }
}

/// Columns j of `dtau/dq` and `dtau/dqd`: the two tangent sweeps along q_j and qd_j, side by side
/// (see the module documentation for each line).
fn tangent_sweeps(
    model: &Model,
    data: &mut Data,
    qd: &[f64],
    f_ext: Option<&[f64]>,
    j: usize,
    dtau_dq: &mut [f64],
    dtau_dqd: &mut [f64],
) {
    let n = model.n;
    let a0 = Motion::new(-model.gravity, Default::default());
    let (x_up, s, v, a, fc, iv) = (
        &data.parent_from_body[..n],
        &data.s[..n],
        &data.v[..n],
        &data.a[..n],
        &data.f[..n],
        &data.iv[..n],
    );
    let (tq, tqd, psi, moved) = (
        &mut data.tangent_q[..n],
        &mut data.tangent_qd[..n],
        &mut data.dpsi[..n],
        &mut data.moved[..n],
    );
    // forward: only the subtree of j moves with coordinate j (every other tangent is zero)
    tq.fill(Tangent::default());
    tqd.fill(Tangent::default());
    moved.fill(false);
    for i in j..n {
        let p = model.parent[i];
        if i != j && !p.is_some_and(|p| moved[p]) {
            continue;
        }
        moved[i] = true;
        let (x, joint, inertia) = (&x_up[i], &model.joints[i], &model.inertia[i]);
        let (mut q_i, mut qd_i, psi_i);
        if i == j {
            // along q_j: (^iX_λ v_λ) x s_i, (^iX_λ a_λ) x s_i ;  along qd_j: s_i, v_i x s_i
            let vp = p.map_or(Motion::zero(), |p| x.inv_act_motion(&v[p]));
            let ap = x.inv_act_motion(&p.map_or(a0, |p| a[p]));
            q_i = Tangent {
                dv: vp.cross_motion(&s[i]),
                da: ap.cross_motion(&s[i]),
                dfc: Force::zero(),
            };
            qd_i = Tangent {
                dv: s[i],
                da: v[i].cross_motion(&s[i]),
                dfc: Force::zero(),
            };
            psi_i = s[i];
        } else {
            let p = p.expect("a moved body below j has a parent");
            let (tp, tdp) = (&tq[p], &tqd[p]);
            q_i = Tangent {
                dv: x.inv_act_motion(&tp.dv),
                da: x.inv_act_motion(&tp.da),
                dfc: Force::zero(),
            };
            qd_i = Tangent {
                dv: x.inv_act_motion(&tdp.dv),
                da: x.inv_act_motion(&tdp.da),
                dfc: Force::zero(),
            };
            // psi (the moved axis in body axes) is needed only for the external wrenches
            psi_i = if f_ext.is_some() {
                x.inv_act_motion(&psi[p])
            } else {
                Motion::zero()
            };
        }
        for t in [&mut q_i, &mut qd_i] {
            // da += dv_i x s_i qd_i ;  df_i = I da + dv x* I v + v x* I dv
            t.da += joint.cross(&t.dv, qd[i]);
            t.dfc = inertia.mul_motion(&t.da) + t.dv.cross_force(&iv[i]) + v[i].cross_force(&inertia.mul_motion(&t.dv));
        }
        if let Some(fx) = f_ext {
            // the body-axes wrench (R^T f, R^T n + u x R^T f) of `Model::body_wrench`, along q_j:
            // d(R_i^T x)/dq_j = (R^T x) x w (w = psi_i's angular part), u fixed in the body
            let r = &data.world_from_body[i].rot;
            let (w, u) = (&psi_i.ang, &model.link_origin[i]);
            let fw = Force::from_slice(&fx[6 * i..6 * i + 6]);
            let (lin, ang) = (r.tr_mul(&fw.lin), r.tr_mul(&fw.ang));
            let dlin = lin.cross(w);
            q_i.dfc -= Force::new(dlin, ang.cross(w) + u.cross(&dlin));
        }
        (tq[i], tqd[i], psi[i]) = (q_i, qd_i, psi_i);
    }
    // backward: df^c_λ += ^λX_i^* (df^c_i + [i=j, along q] s_i x* f^c_i) ;  dtau_i = s_i^T df^c_i
    for i in (0..n).rev() {
        let joint = &model.joints[i];
        dtau_dq[i * n + j] = joint.project(&tq[i].dfc);
        dtau_dqd[i * n + j] = joint.project(&tqd[i].dfc) + if i == j { model.viscous[i] } else { 0.0 };
        let Some(p) = model.parent[i] else { continue };
        if i > j && !moved[i] {
            continue; // a branch that coordinate j does not move: nothing to carry up
        }
        let mut g = tq[i].dfc;
        if i == j {
            g += s[i].cross_force(&fc[i]);
        }
        let (up_q, up_qd) = (x_up[i].act_force(&g), x_up[i].act_force(&tqd[i].dfc));
        tq[p].dfc += up_q;
        tqd[p].dfc += up_qd;
    }
}

/// `dqdd/dq`, `dqdd/dqd` and `dqdd/dtau = M^-1` (row-major n x n each) at `(q, qd, tau)`, for the
/// same `qdd` as the ABA (`f_ext` included). An error for a singular mass matrix.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn aba_derivatives<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    q: &[T],
    qd: &[T],
    tau: &[T],
    f_ext: Option<&[T]>,
    dqdd_dq: &mut [T],
    dqdd_dqd: &mut [T],
    dqdd_dtau: &mut [T],
) -> Result<()> {
    let n = model.n;
    // one world pass at qdd = 0 gives M (composite inertias) and the bias b = tau(q, qd, 0)
    // (composite forces, friction added); M^-1 by the sparse L^T D L factors (an error for a
    // singular M); qdd = M^-1 (tau - b); then the accelerations and forces at that qdd
    world_pass(model, data, q, qd, None, f_ext);
    let mut m = std::mem::take(&mut data.m);
    mass_matrix_from_world(model, data, &mut m);
    data.m = m;
    dqdd_dtau[..n * n].copy_from_slice(inverse_of_mass_matrix(model, data)?);
    let minv = &dqdd_dtau[..n * n];
    let qdd = &mut data.qdd_fd[..n];
    for (r, value) in qdd.iter_mut().enumerate() {
        let mut sum = T::zero();
        for k in 0..n {
            let bias = data.s_w[k].dot(&data.fc_w[k]) + super::rnea::friction(model, k, qd[k]);
            sum += minv[r * n + k] * (tau[k] - bias);
        }
        *value = sum;
    }
    let qdd = std::mem::take(&mut data.qdd_fd);
    add_joint_accelerations(model, data, &qdd[..n]);
    data.qdd_fd = qdd;
    // dtau/dq and dtau/dqd at (q, qd, qdd), into the outputs first
    world_derivatives(model, data, f_ext.is_some(), dqdd_dq, dqdd_dqd);
    // dqdd/dx = -M^-1 dtau/dx: row r of the product is -sum_k minv[r][k] row k of dtau/dx,
    // accumulated in a scratch matrix (data.m, free after the inverse) and copied back

    let scratch = &mut data.m[..n * n];
    for out in [dqdd_dq, dqdd_dqd] {
        scratch.fill(T::zero());
        for r in 0..n {
            let row = &mut scratch[r * n..(r + 1) * n];
            for k in 0..n {
                let c = -minv[r * n + k];
                for (value, d) in row.iter_mut().zip(&out[k * n..(k + 1) * n]) {
                    *value += c * *d;
                }
            }
        }
        out[..n * n].copy_from_slice(scratch);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::aba::aba;
    use crate::testing::{random_model, Rng};

    /// Forward-mode dual numbers through the generic RNEA and ABA (a second route, exact to
    /// rounding): each column of the analytical derivatives equals the dual part of tau (qdd) with
    /// the column's coordinate seeded. Chains and trees; the rate and torque columns also on
    /// floating bases (their configuration derivative is on the manifold, q ⊕ dq, not along q's
    /// coordinates, so it is left to the finite differences below).
    #[test]
    fn derivatives_equal_forward_mode_dual_numbers() {
        use crate::testing::{random_configuration, random_floating_model, Dual};
        let models = [
            random_model(31, 7, false),
            random_model(32, 8, true),
            random_floating_model(33, 5, false),
        ];
        for model in models {
            let n = model.n;
            let mut rng = Rng::new(5);
            // wrenches about link-frame origins off the body origins
            let origins = (0..n)
                .map(|_| Vec3::from_column_slice(&rng.vector(3, -0.8, 0.8)))
                .collect();
            let model = model.with_link_origins(origins).unwrap();
            let q = random_configuration(&model, &mut rng);
            let (qd, qdd) = (rng.vector(n, -2.0, 2.0), rng.vector(n, -2.0, 2.0));
            let fx = rng.vector(6 * n, -3.0, 3.0);
            let mut data = Data::new(&model);
            let (mut dq, mut dqd) = (vec![0.0; n * n], vec![0.0; n * n]);
            rnea_derivatives(&model, &mut data, &q, &qd, &qdd, Some(&fx), &mut dq, &mut dqd, None);
            let tau = crate::algorithms::rnea(&model, &mut data, &q, &qd, &qdd, Some(&fx)).to_vec();
            let (mut fq, mut fqd, mut minv) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
            aba_derivatives(
                &model,
                &mut data,
                &q,
                &qd,
                &tau,
                Some(&fx),
                &mut fq,
                &mut fqd,
                &mut minv,
            )
            .unwrap();
            let mut dual = Data::<Dual>::new(&model);
            let fx_d = Dual::seeded(&fx, None);
            let column = |m: &[f64], j: usize| -> Vec<f64> { (0..n).map(|i| m[i * n + j]).collect() };
            for j in 0..n {
                // rates: qd_j seeded
                let (qv, qdv, qddv, tauv) = (
                    Dual::seeded(&q, None),
                    Dual::seeded(&qd, Some(j)),
                    Dual::seeded(&qdd, None),
                    Dual::seeded(&tau, None),
                );
                let t: Vec<f64> = crate::algorithms::rnea(&model, &mut dual, &qv, &qdv, &qddv, Some(&fx_d))
                    .iter()
                    .map(|d| d.eps)
                    .collect();
                dual_close("dtau/dqd (dual)", &t, &column(&dqd, j));
                let a: Vec<f64> = crate::algorithms::aba(&model, &mut dual, &qv, &qdv, &tauv, Some(&fx_d))
                    .unwrap()
                    .iter()
                    .map(|d| d.eps)
                    .collect();
                dual_close("dqdd/dqd (dual)", &a, &column(&fqd, j));
                // torques: tau_j seeded
                let a: Vec<f64> = crate::algorithms::aba(
                    &model,
                    &mut dual,
                    &qv,
                    &Dual::seeded(&qd, None),
                    &Dual::seeded(&tau, Some(j)),
                    Some(&fx_d),
                )
                .unwrap()
                .iter()
                .map(|d| d.eps)
                .collect();
                dual_close("dqdd/dtau (dual)", &a, &column(&minv, j));
                if model.plain {
                    // configurations: q_j seeded (1-DOF joints: the coordinate itself)
                    let qv = Dual::seeded(&q, Some(j));
                    let t: Vec<f64> =
                        crate::algorithms::rnea(&model, &mut dual, &qv, &Dual::seeded(&qd, None), &qddv, Some(&fx_d))
                            .iter()
                            .map(|d| d.eps)
                            .collect();
                    dual_close("dtau/dq (dual)", &t, &column(&dq, j));
                    let a: Vec<f64> =
                        crate::algorithms::aba(&model, &mut dual, &qv, &Dual::seeded(&qd, None), &tauv, Some(&fx_d))
                            .unwrap()
                            .iter()
                            .map(|d| d.eps)
                            .collect();
                    dual_close("dqdd/dq (dual)", &a, &column(&fq, j));
                }
            }
        }
    }

    /// Central differences of `f` along each coordinate (columns of an n x n matrix).
    fn central_difference(n: usize, x: &[f64], mut f: impl FnMut(&[f64]) -> Vec<f64>) -> Vec<f64> {
        let h = 1e-6;
        let mut out = vec![0.0; n * n];
        for c in 0..n {
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[c] += h;
            xm[c] -= h;
            let (fp, fm) = (f(&xp), f(&xm));
            for r in 0..n {
                out[r * n + c] = (fp[r] - fm[r]) / (2.0 * h);
            }
        }
        out
    }

    /// Equal to rounding (1e-11 of the column's scale): two exact routes.
    fn dual_close(what: &str, got: &[f64], expected: &[f64]) {
        let scale = expected.iter().fold(1.0f64, |s, x| s.max(x.abs()));
        for (k, (g, e)) in got.iter().zip(expected).enumerate() {
            assert!((g - e).abs() <= 1e-11 * scale, "{what}[{k}]: {g} vs analytical {e}");
        }
    }

    fn assert_close(what: &str, got: &[f64], expected: &[f64]) {
        let scale = expected.iter().fold(1.0f64, |s, x| s.max(x.abs()));
        for (k, (g, e)) in got.iter().zip(expected).enumerate() {
            assert!(
                (g - e).abs() <= 1e-6 * scale,
                "{what}[{k}]: {g} vs finite difference {e}"
            );
        }
    }

    /// Every derivative against central differences of the RNEA / ABA themselves, on random
    /// chains and trees, with and without external wrenches (no Coulomb friction: not smooth).
    #[test]
    fn derivatives_match_finite_differences() {
        for (seed, n, branching) in [(1, 6, false), (2, 7, true), (3, 9, true)] {
            let mut model = random_model(seed, n, branching);
            model.coulomb.fill(0.0);
            let mut rng = Rng::new(seed + 100);
            let (q, qd, qdd) = (
                rng.vector(n, -2.0, 2.0),
                rng.vector(n, -2.0, 2.0),
                rng.vector(n, -2.0, 2.0),
            );
            let fx = rng.vector(6 * n, -3.0, 3.0);
            // wrenches about the body origins, and about link origins off them (as DH links)
            let origins = (0..n)
                .map(|_| Vec3::from_column_slice(&rng.vector(3, -0.8, 0.8)))
                .collect();
            let moved = model.clone().with_link_origins(origins).unwrap();
            for (model, f_ext) in [
                (model.clone(), None),
                (model.clone(), Some(&fx[..])),
                (moved, Some(&fx[..])),
            ] {
                let mut data = Data::new(&model);
                let (mut dq, mut dqd) = (vec![0.0; n * n], vec![0.0; n * n]);
                let mut m = vec![0.0; n * n];
                rnea_derivatives(&model, &mut data, &q, &qd, &qdd, f_ext, &mut dq, &mut dqd, Some(&mut m));
                // dtau/dqdd = M, from the world pass or the CRBA: against the CRBA on fresh Data
                let m_crba = crate::algorithms::crba(&model, &mut Data::new(&model), &q).to_vec();
                assert_close("M", &m, &m_crba);
                {
                    // the world-coordinate form against the tangent sweeps: two derivations, one answer
                    let (mut tq, mut tqd) = (vec![0.0; n * n], vec![0.0; n * n]);
                    rnea_derivatives_tangent(&model, &mut data, &q, &qd, &qdd, f_ext, &mut tq, &mut tqd);
                    let scale = tq.iter().chain(&tqd).fold(1.0f64, |s, x| s.max(x.abs()));
                    for (a, b) in dq.iter().chain(&dqd).zip(tq.iter().chain(&tqd)) {
                        assert!((a - b).abs() <= 1e-12 * scale, "world {a} vs tangent {b}");
                    }
                }
                let mut d = Data::new(&model);
                let fd_q = central_difference(n, &q, |x| rnea(&model, &mut d, x, &qd, &qdd, f_ext).to_vec());
                let fd_qd = central_difference(n, &qd, |x| rnea(&model, &mut d, &q, x, &qdd, f_ext).to_vec());
                assert_close("dtau/dq", &dq, &fd_q);
                assert_close("dtau/dqd", &dqd, &fd_qd);

                let tau = rnea(&model, &mut d, &q, &qd, &qdd, f_ext).to_vec();
                let (mut a_q, mut a_qd, mut a_tau) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
                aba_derivatives(&model, &mut data, &q, &qd, &tau, f_ext, &mut a_q, &mut a_qd, &mut a_tau).unwrap();
                let fd_q = central_difference(n, &q, |x| aba(&model, &mut d, x, &qd, &tau, f_ext).unwrap().to_vec());
                let fd_qd = central_difference(n, &qd, |x| aba(&model, &mut d, &q, x, &tau, f_ext).unwrap().to_vec());
                let fd_tau = central_difference(n, &tau, |x| aba(&model, &mut d, &q, &qd, x, f_ext).unwrap().to_vec());
                assert_close("dqdd/dq", &a_q, &fd_q);
                assert_close("dqdd/dqd", &a_qd, &fd_qd);
                assert_close("dqdd/dtau", &a_tau, &fd_tau);
            }
        }
    }
}
