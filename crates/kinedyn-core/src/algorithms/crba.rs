//! The joint-space mass matrix by the composite-rigid-body algorithm.
//!
//! Source: RBDA Table 6.2 (Featherstone 2008, §6.2). Reflected rotor inertia is added on the
//! diagonal (DESIGN.md: `M` includes `r^2 J_m`). Only the lower triangle is computed; the upper is
//! its mirror image, so `M` is symmetric to the last bit.
//!
//! | symbol      | here                       | meaning                                          |
//! |-------------|----------------------------|--------------------------------------------------|
//! | `^iX_λ(i)`  | `x_up` (`parent_from_body`)| parent -> body i transform (used inverted)       |
//! | `I^c_i`     | `data.ic[i]`               | composite inertia of the subtree rooted at i     |
//! | `s_i`       | `data.s[i]`                | joint motion subspace, body coordinates          |
//! | `F`         | `f`                        | `I^c_i s_i`, carried up to the ancestors of i    |
//! | `H`         | `data.m` (row-major n x n) | mass matrix `M(q)`                               |

use super::kinematics::parent_from_body;
use crate::data::Data;
use crate::model::Model;

/// `M(q)` written row-major to `data.m` (n x n), armature included.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d [f64] {
    let n = model.n;
    // per-body arrays sliced to n once (no bounds checks in the loops below)
    let (parent, joints, armature) = (&model.parent[..n], &model.joints[..n], &model.armature[..n]);
    let (x_up, ic, m) = (&mut data.parent_from_body[..n], &mut data.ic[..n], &mut data.m[..n * n]);
    for i in 0..n {
        // X_J = jcalc(q_i);  ^iX_λ(i) = X_J X_T(i);  I^c_i = I_i
        x_up[i] = parent_from_body(model, q, i);
        ic[i] = model.inertia[i];
    }
    for i in (0..n).rev() {
        // I^c_λ(i) += ^λX_i^* I^c_i ^iX_λ
        if let Some(p) = parent[i] {
            let add = x_up[i].act_inertia(&ic[i]);
            ic[p] += add;
        }
        // F = I^c_i s_i ;  H_ii = s_i^T F (+ armature_i)
        let mut f = joints[i].inertia_times_s(&ic[i]);
        m[i * n + i] = joints[i].project(&f) + armature[i];
        // j = i; while λ(j) != 0: F = ^λX_j^* F; j = λ(j); H_ij = H_ji = F^T s_j
        let mut j = i;
        while let Some(p) = parent[j] {
            f = x_up[j].act_force(&f);
            j = p;
            let h = joints[j].project(&f);
            m[i * n + j] = h;
            m[j * n + i] = h;
        }
    }
    // zero the entries of joints on different branches (no common subtree)
    if model.support.iter().any(|s| s.len() != s.last().map_or(0, |&l| l + 1)) {
        zero_unrelated(model, &mut data.m);
    }
    &data.m
}

/// Zero `M[i][j]` for joints i, j where neither supports the other (branching trees only).
fn zero_unrelated(model: &Model, m: &mut [f64]) {
    let n = model.n;
    for i in 0..n {
        for j in 0..i {
            if !is_ancestor(model, j, i) {
                m[i * n + j] = 0.0;
                m[j * n + i] = 0.0;
            }
        }
    }
}

/// Whether joint `a` supports body `b` (a == b or an ancestor), for `a <= b`.
#[inline]
pub(crate) fn is_ancestor(model: &Model, a: usize, b: usize) -> bool {
    model.support[b].binary_search(&a).is_ok()
}
