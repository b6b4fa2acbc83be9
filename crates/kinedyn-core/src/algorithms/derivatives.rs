//! Analytical partial derivatives of inverse and forward dynamics.
//!
//! Inverse dynamics: `dtau/dq` and `dtau/dqd` by differentiating the recursive Newton-Euler
//! algorithm (RBDA Table 5.1, as in `rnea.rs`) along each coordinate direction: one tangent
//! ("forward-mode") sweep per direction, over the subtree the coordinate moves and back to the
//! root, O(n^2) in all and exact (no finite differences). `dtau/dqdd = M`. This is the
//! differentiation of RNEA that Carpentier & Mansard ("Analytical Derivatives of Rigid Body
//! Dynamics Algorithms", RSS 2018) organise into one pass; here it is kept one direction at a
//! time, which reads line by line against the RNEA.
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
//! Forward dynamics: `qdd = M^-1 (tau - b(q, qd))`, so with `qdd` from the ABA,
//! `dqdd/dq = -M^-1 dtau/dq`, `dqdd/dqd = -M^-1 dtau/dqd` (both at that `qdd`) and
//! `dqdd/dtau = M^-1` (Carpentier & Mansard 2018, §IV-B).

use super::minv::mass_matrix_inverse;
use super::rnea::rnea;
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{Force, Motion};

/// Which coordinate a tangent sweep differentiates along.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Direction {
    Position,
    Velocity,
}

/// `dtau/dq` and `dtau/dqd` (row-major n x n: `[i * n + j] = dtau_i / dx_j`) at `(q, qd, qdd)`,
/// for the same `tau` as [`rnea`] (gravity, friction, armature, `f_ext`). Leaves `rnea`'s
/// results in `data` (`data.tau` is tau).
#[allow(clippy::too_many_arguments)]
pub fn rnea_derivatives(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], qdd: &[f64], f_ext: Option<&[f64]>, dtau_dq: &mut [f64], dtau_dqd: &mut [f64]) {
    // the RNEA's own pass: parent_from_body, v_i, a_i and the composite forces f^c_i in data.f
    // (and world_from_body when f_ext is given)
    rnea(model, data, q, qd, qdd, f_ext);
    for j in 0..model.n {
        tangent_sweep(model, data, qd, f_ext, j, Direction::Position, dtau_dq);
        tangent_sweep(model, data, qd, f_ext, j, Direction::Velocity, dtau_dqd);
    }
}

/// Column j of `dtau/dq` or `dtau/dqd` (see the module documentation for each line).
fn tangent_sweep(model: &Model, data: &mut Data, qd: &[f64], f_ext: Option<&[f64]>, j: usize, direction: Direction, out: &mut [f64]) {
    let n = model.n;
    let a0 = Motion::new(-model.gravity, Default::default());
    let (x_up, s, v, a, fc) = (&data.parent_from_body[..n], &data.s[..n], &data.v[..n], &data.a[..n], &data.f[..n]);
    let (dv, da, psi, dfc, moved) = (&mut data.dv[..n], &mut data.da[..n], &mut data.dpsi[..n], &mut data.dfc[..n], &mut data.moved[..n]);
    // forward: only the subtree of j moves with coordinate j (every other tangent is zero)
    dfc.fill(Force::zero());
    moved.fill(false);
    for i in j..n {
        let p = model.parent[i];
        if i != j && !p.is_some_and(|p| moved[p]) {
            continue;
        }
        moved[i] = true;
        let (x, joint, inertia) = (&x_up[i], &model.joints[i], &model.inertia[i]);
        let (dvi, mut dai, psi_i) = if i == j {
            let vp = p.map_or(Motion::zero(), |p| x.inv_act_motion(&v[p]));
            match direction {
                // (^iX_λ v_λ) x s_i ;  (^iX_λ a_λ) x s_i
                Direction::Position => {
                    let ap = x.inv_act_motion(&p.map_or(a0, |p| a[p]));
                    (vp.cross_motion(&s[i]), ap.cross_motion(&s[i]), s[i])
                }
                // s_i ;  v_i x s_i
                Direction::Velocity => (s[i], v[i].cross_motion(&s[i]), s[i]),
            }
        } else {
            let p = p.expect("a moved body below j has a parent");
            (x.inv_act_motion(&dv[p]), x.inv_act_motion(&da[p]), x.inv_act_motion(&psi[p]))
        };
        // + dv_i x s_i qd_i
        dai += joint.cross(&dvi, qd[i]);
        // df_i = I da + dv x* I v + v x* I dv (- d(R^T f^x) along q)
        let mut dfi = inertia.mul_motion(&dai) + dvi.cross_force(&inertia.mul_motion(&v[i])) + v[i].cross_force(&inertia.mul_motion(&dvi));
        if let (Some(fx), Direction::Position) = (f_ext, direction) {
            let r = &data.world_from_body[i].rot;
            let w = &psi_i.ang;
            let fw = Force::from_slice(&fx[6 * i..6 * i + 6]);
            let (lin, ang) = (r.tr_mul(&fw.lin), r.tr_mul(&fw.ang));
            dfi -= Force::new(lin.cross(w), ang.cross(w));
        }
        (dv[i], da[i], psi[i], dfc[i]) = (dvi, dai, psi_i, dfi);
    }
    // backward: df^c_λ += ^λX_i^* (df^c_i + [i=j, along q] s_i x* f^c_i) ;  dtau_i = s_i^T df^c_i
    for i in (0..n).rev() {
        let mut dti = model.joints[i].project(&dfc[i]);
        if i == j && direction == Direction::Velocity {
            dti += model.viscous[i];
        }
        out[i * n + j] = dti;
        if let Some(p) = model.parent[i] {
            let mut g = dfc[i];
            if i == j && direction == Direction::Position {
                g += s[i].cross_force(&fc[i]);
            } else if !moved[i] && i > j {
                continue; // a branch that coordinate j does not move: nothing to carry up
            }
            let up = x_up[i].act_force(&g);
            dfc[p] += up;
        }
    }
}

/// `dqdd/dq`, `dqdd/dqd` and `dqdd/dtau = M^-1` (row-major n x n each) at `(q, qd, tau)`, for the
/// same `qdd` as the ABA (`f_ext` included). An error for a singular mass matrix.
#[allow(clippy::too_many_arguments)]
pub fn aba_derivatives(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    f_ext: Option<&[f64]>,
    dqdd_dq: &mut [f64],
    dqdd_dqd: &mut [f64],
    dqdd_dtau: &mut [f64],
) -> Result<()> {
    let n = model.n;
    // qdd from the ABA, kept in data.qdd_fd while the derivatives of tau are taken there
    super::aba::aba(model, data, q, qd, tau, f_ext)?;
    let mut qdd_fd = std::mem::take(&mut data.qdd_fd);
    qdd_fd[..n].copy_from_slice(&data.qdd[..n]);
    // dtau/dq and dtau/dqd at (q, qd, qdd), into the outputs first
    rnea_derivatives(model, data, q, qd, &qdd_fd[..n], f_ext, dqdd_dq, dqdd_dqd);
    data.qdd_fd = qdd_fd;
    dqdd_dtau[..n * n].copy_from_slice(mass_matrix_inverse(model, data, q)?);
    // dqdd/dx = -M^-1 dtau/dx, column by column through a scratch column
    let minv = &dqdd_dtau[..n * n];
    let column = &mut data.x[..n];
    for out in [dqdd_dq, dqdd_dqd] {
        for c in 0..n {
            for (r, value) in column.iter_mut().enumerate() {
                *value = -(0..n).map(|k| minv[r * n + k] * out[k * n + c]).sum::<f64>();
            }
            for (r, value) in column.iter().enumerate() {
                out[r * n + c] = *value;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::aba::aba;
    use crate::testing::{random_model, Rng};

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

    fn assert_close(what: &str, got: &[f64], expected: &[f64]) {
        let scale = expected.iter().fold(1.0f64, |s, x| s.max(x.abs()));
        for (k, (g, e)) in got.iter().zip(expected).enumerate() {
            assert!((g - e).abs() <= 1e-6 * scale, "{what}[{k}]: {g} vs finite difference {e}");
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
            let (q, qd, qdd) = (rng.vector(n, -2.0, 2.0), rng.vector(n, -2.0, 2.0), rng.vector(n, -2.0, 2.0));
            let fx = rng.vector(6 * n, -3.0, 3.0);
            for f_ext in [None, Some(&fx[..])] {
                let mut data = Data::new(&model);
                let (mut dq, mut dqd) = (vec![0.0; n * n], vec![0.0; n * n]);
                rnea_derivatives(&model, &mut data, &q, &qd, &qdd, f_ext, &mut dq, &mut dqd);
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
