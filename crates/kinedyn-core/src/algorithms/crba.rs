//! The joint-space mass matrix by the composite-rigid-body algorithm.
//!
//! Source: RBDA Table 6.2 (Featherstone 2008, §6.2). Reflected rotor inertia is added on the
//! diagonal (docs/architecture.md: `M` includes `r^2 J_m`). Only the lower triangle is computed; the upper is
//! its mirror image, so `M` is symmetric to the last bit.
//!
//! | symbol      | here                       | meaning                                          |
//! |-------------|----------------------------|--------------------------------------------------|
//! | `^iX_λ(i)`  | `x_up` (`parent_from_body`)| parent -> body i transform (used inverted)       |
//! | `I^c_i`     | `data.ic[i]`               | composite inertia of the subtree rooted at i     |
//! | `s_i`       | `data.s[i]`                | joint motion subspace, body coordinates          |
//! | `F`         | `f`                        | `I^c_i s_i`, carried up to the ancestors of i    |
//! | `H`         | `data.m` (row-major n x n) | mass matrix `M(q)`                               |

use super::kinematics::{inertia_to_parent, joint_trig, parent_from_body_trig};
use crate::data::Data;
use crate::model::{Coordinates, Model};
use crate::spatial::Real;

/// `M(q)` written row-major to `data.m` (n x n), armature included.
#[inline(always)]
pub fn crba<'d, T: Real>(model: &Model, data: &'d mut Data<T>, q: &[T]) -> &'d [T] {
    if model.subtrees_contiguous {
        crba_blocks(model, data, q);
    } else {
        crba_chains(model, data, q);
    }
    &data.m
}

/// RBDA Table 6.2 with the force columns of a whole subtree carried together (Pinocchio's and
/// RBDA §6.2's "F" as a 6 x n block): when subtree i is the index range `i..end_i`, the columns
/// `F_k` (k in the subtree) are all in body i's frame after i's step, so row i of `M` is
/// `s_i^T F_k` over the range, and one transform `^λX_i^*` moves the block to the parent. The
/// transforms are computed in the same backward pass (no separate forward pass, nothing stored),
/// and the column loops have independent iterations (no chain of dependent transforms per entry).
#[inline(always)]
fn crba_blocks<T: Real>(model: &Model, data: &mut Data<T>, q: &[T]) {
    let n = model.n;
    joint_trig(model, data, q);
    let (parent, joints, armature, end) = (
        &model.parent[..n],
        &model.joints[..n],
        &model.armature[..n],
        &model.subtree_end[..n],
    );
    let (ic, m, f) = (&mut data.ic[..n], &mut data.m[..n * n], &mut data.f[..n]);
    let (sin, cos) = (&data.sin[..n], &data.cos[..n]);
    // I^c_i = I_i ;  H_rr = 0 for the roots r (their children add to it, see below)
    for (c, i) in ic.iter_mut().zip(&model.inertia[..n]) {
        *c = i.splat();
    }
    for (r, p) in parent.iter().enumerate() {
        if p.is_none() {
            m[r * n + r] = T::zero();
        }
    }
    for i in (0..n).rev() {
        let (joint, e) = (&joints[i], end[i]);
        // bodies after the subtree are on other branches: H_ik = H_ki = 0
        for k in e..n {
            m[i * n + k] = T::zero();
            m[k * n + i] = T::zero();
        }
        let p = match parent[i] {
            None => {
                // a root: its row beyond the diagonal came from its children;
                // H_ii += s_i^T I_i s_i (+ armature_i)
                m[i * n + i] += joint.project(&joint.inertia_times_s(&ic[i])) + T::splat(armature[i]);
                continue;
            }
            Some(p) => p,
        };
        // F_i = I^c_i s_i  (column i, body i's frame)
        f[i] = joint.inertia_times_s(&ic[i]);
        // H_ik = H_ki = s_i^T F_k for k in subtree(i) (+ armature_i on the diagonal)
        for k in i..e {
            let h = joint.project(&f[k]);
            m[i * n + k] = h;
            m[k * n + i] = h;
        }
        m[i * n + i] += T::splat(armature[i]);
        if !model.plain && model.coordinates[i] == Coordinates::Member && parent[p].is_some() {
            // a further body of a multi-DOF joint sits at the identity on the body before it: the
            // composite inertia and the subtree's force columns carry over unchanged
            let c = ic[i];
            ic[p] += c;
            continue;
        }
        // ^λX_i = X_T(i) X_J(q_i), used on forces (its dual inverse)
        let x = parent_from_body_trig(model, q, sin, cos, i);
        if parent[p].is_none() {
            // the parent is a root: only its row is left to compute, and s_λ^T ^λX_i^* F_k is
            // w^T F_k with w = ^iX_λ s_λ (s_λ in body i's frame); its composite inertia enters
            // only H_λλ = s_λ^T I_λ s_λ + sum over children of w^T I^c_i w
            let w = x.inv_act_motion(&joints[p].subspace::<T>());
            for k in i..e {
                let h = w.dot(&f[k]);
                m[p * n + k] = h;
                m[k * n + p] = h;
            }
            m[p * n + p] += w.dot(&ic[i].mul_motion(&w));
            continue;
        }
        // I^c_λ(i) += ^λX_i^* I^c_i ^iX_λ(i)
        let add = inertia_to_parent(model, i, &x, sin[i], cos[i], &ic[i]);
        ic[p] += add;
        // F_k = ^λX_i^* F_k for k in subtree(i)
        for fk in &mut f[i..e] {
            *fk = x.act_force(fk);
        }
    }
}

/// RBDA Table 6.2 entry by entry, `F` carried up the support of each body (any numbering).
#[inline(always)]
fn crba_chains<T: Real>(model: &Model, data: &mut Data<T>, q: &[T]) {
    let n = model.n;
    joint_trig(model, data, q);
    // per-body arrays sliced to n once (no bounds checks in the loops below)
    let (parent, joints, armature) = (&model.parent[..n], &model.joints[..n], &model.armature[..n]);
    let (x_up, ic, m) = (&mut data.parent_from_body[..n], &mut data.ic[..n], &mut data.m[..n * n]);
    let (sin, cos) = (&data.sin[..n], &data.cos[..n]);
    for i in 0..n {
        // X_J = jcalc(q_i);  ^iX_λ(i) = X_J X_T(i);  I^c_i = I_i
        x_up[i] = parent_from_body_trig(model, q, sin, cos, i);
        ic[i] = model.inertia[i].splat();
    }
    for i in (0..n).rev() {
        // I^c_λ(i) += ^λX_i^* I^c_i ^iX_λ
        if let Some(p) = parent[i] {
            let add = inertia_to_parent(model, i, &x_up[i], sin[i], cos[i], &ic[i]);
            ic[p] += add;
        }
        // F = I^c_i s_i ;  H_ii = s_i^T F (+ armature_i)
        let mut f = joints[i].inertia_times_s(&ic[i]);
        m[i * n + i] = joints[i].project(&f) + T::splat(armature[i]);
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
    zero_unrelated(model, &mut data.m);
}

/// Zero `M[i][j]` for joints i, j where neither supports the other (branching trees only).
#[inline(always)]
fn zero_unrelated<T: Real>(model: &Model, m: &mut [T]) {
    let n = model.n;
    for i in 0..n {
        for j in 0..i {
            if !is_ancestor(model, j, i) {
                m[i * n + j] = T::zero();
                m[j * n + i] = T::zero();
            }
        }
    }
}

/// Whether joint `a` supports body `b` (a == b or an ancestor), for `a <= b`.
#[inline]
pub(crate) fn is_ancestor(model: &Model, a: usize, b: usize) -> bool {
    model.support[b].binary_search(&a).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::AxisRotation;
    use crate::testing::{dh_model, random_model, Rng, UR5_DH};

    /// The two-factor inertia transform (coordinate-axis joints and placements) gives the same M
    /// as the general one, on random models (half their axes and placements qualify) and a DH arm.
    #[test]
    fn coordinate_axis_fast_path_equals_general_transform() {
        let models = [
            random_model(11, 8, false),
            random_model(12, 9, true),
            dh_model(&UR5_DH, 3),
        ];
        let fast_paths: usize = models
            .iter()
            .map(|m| {
                m.placement_rotation
                    .iter()
                    .filter(|r| !matches!(r, AxisRotation::General))
                    .count()
            })
            .sum();
        assert!(
            fast_paths >= 8,
            "the models exercise the fast path ({fast_paths} placements)"
        );
        for model in models {
            let mut general = model.clone();
            general.placement_rotation.fill(AxisRotation::General);
            let q = Rng::new(2).vector(model.n, -3.0, 3.0);
            let m_fast = crba(&model, &mut Data::new(&model), &q).to_vec();
            let m_general = crba(&general, &mut Data::new(&general), &q).to_vec();
            let scale = m_general.iter().fold(0.0f64, |s, x| s.max(x.abs()));
            for (a, b) in m_fast.iter().zip(&m_general) {
                assert!((a - b).abs() <= 1e-13 * scale, "{a} {b}");
            }
        }
    }

    /// The block form (contiguous subtrees) equals the entry-by-entry form, on chains and on a
    /// depth-first-numbered tree.
    #[test]
    fn blocks_equal_chains() {
        let tree = random_model(7, 9, false);
        let parent = vec![
            None,
            Some(0),
            Some(1),
            Some(1),
            Some(3),
            Some(0),
            Some(5),
            Some(5),
            Some(0),
        ];
        let tree = Model::new(
            parent,
            tree.joints.clone(),
            tree.offset.clone(),
            tree.parent_from_joint.clone(),
            tree.inertia.clone(),
            tree.armature.clone(),
            tree.viscous.clone(),
            tree.coulomb.clone(),
            tree.gravity,
            vec![],
        )
        .unwrap();
        assert!(tree.subtrees_contiguous);
        for model in [random_model(3, 7, false), random_model(4, 1, false), tree] {
            let mut data = Data::new(&model);
            let q = Rng::new(5).vector(model.n, -3.0, 3.0);
            crba_blocks(&model, &mut data, &q);
            let blocks = data.m.clone();
            data.m.fill(f64::NAN);
            crba_chains(&model, &mut data, &q);
            let scale = blocks.iter().fold(0.0f64, |s, x| s.max(x.abs()));
            for (a, b) in blocks.iter().zip(&data.m) {
                assert!((a - b).abs() <= 1e-14 * scale, "{a} {b}");
            }
        }
    }
}
