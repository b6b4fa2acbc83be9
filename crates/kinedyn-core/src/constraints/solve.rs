//! The loop computations of one state that need a rank-revealing factorisation (the singular value
//! decomposition, nalgebra's Golub-Kahan bidiagonalisation and implicit QR; Golub & Van Loan §8.6):
//! inverse dynamics with actuated joints, and projections of a configuration or a velocity onto
//! the loops' manifold (Gauss-Newton on the closure). Definitions in `constraints/mod.rs`.

use nalgebra::{DMatrix, DVector};

use super::kinematics::{loop_gamma, loop_jacobian, loop_residual};
use crate::algorithms::rnea;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;

/// Singular values below this times the largest count as zero.
const RANK_TOLERANCE: f64 = 1e-10;

/// `J(q)` as a matrix.
fn jacobian(model: &Model, data: &mut Data, q: &[f64]) -> DMatrix<f64> {
    let (n, m) = (model.n, model.loop_rows());
    let mut j = vec![0.0; m * n];
    loop_jacobian(model, data, q, &mut j);
    DMatrix::from_row_slice(m, n, &j)
}

/// The least-norm `x` of `a x = b` (least squares when inconsistent).
fn least_norm(a: DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let svd = a.svd(true, true);
    let eps = RANK_TOLERANCE * svd.singular_values.max().max(f64::MIN_POSITIVE);
    svd.solve(b, eps).expect("U and V were computed")
}

/// The loop and row of the largest entry of a constraint vector, for an error.
fn worst(model: &Model, v: &[f64]) -> (String, usize, f64) {
    let k = (0..v.len()).fold(0, |b, k| if v[k].abs() > v[b].abs() { k } else { b });
    let (l, row) = model.loop_of_row(k);
    (l.name.clone(), row, v[k])
}

/// The torques `tau` (n; zero on the joints not in `actuated`, a list of velocity indices) that
/// produce the accelerations `qdd` of a closed motion: `M qdd + h = tau + J^T lambda` with `tau`
/// nonzero only on the actuated columns. Solved as the least-norm solution of
/// `[S | J^T] (tau_a; lambda) = M qdd + h` (`S` selects the actuated columns) by the SVD.
/// Errors: `qdd` does not keep a loop closed (`|J qdd + gamma|` above `1e-8` of its terms); the
/// actuators cannot produce the motion (the system is inconsistent); or they do not determine their
/// torques (a null vector of `[S | J^T]` moves an actuator: the actuators fight through a loop).
#[allow(clippy::too_many_arguments)]
pub fn constrained_inverse_dynamics(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    f_ext: Option<&[f64]>,
    actuated: &[usize],
    out: &mut [f64],
) -> Result<()> {
    let (n, m, na) = (model.n, model.loop_rows(), actuated.len());
    if let Some(&k) = actuated.iter().find(|&&k| k >= n) {
        return Err(Error::InvalidInput(format!(
            "actuated column {k} does not exist (n = {n})"
        )));
    }
    // the motion keeps the loops closed: J qdd + gamma = 0
    let j = jacobian(model, data, q);
    let mut gamma = vec![0.0; m];
    loop_gamma(model, data, q, qd, &mut gamma);
    let jqdd = &j * DVector::from_column_slice(qdd);
    let violation: Vec<f64> = (0..m).map(|k| jqdd[k] + gamma[k]).collect();
    // the size of the terms: |J| |qdd| + |gamma| (largest entries)
    let qdd_size = qdd[..n].iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let size = j.amax() * qdd_size + gamma.iter().fold(0.0f64, |a, g| a.max(g.abs()));
    let (name, row, value) = if m > 0 {
        worst(model, &violation)
    } else {
        (String::new(), 0, 0.0)
    };
    if value.abs() > 1e-8 * size.max(f64::MIN_POSITIVE) {
        return Err(Error::InvalidInput(format!(
            "constrained inverse dynamics: qdd does not keep loop '{name}' closed (row {row}: J qdd + gamma = {value:e}); \
             a closed motion has J qdd + gamma = 0"
        )));
    }
    let tau_full = DVector::from_column_slice(rnea(model, data, q, qd, qdd, f_ext));
    // B = [S | J^T], padded with zero rows to be at least square (the SVD then gives all of V)
    let cols = na + m;
    let mut b = DMatrix::zeros(n.max(cols), cols);
    for (c, &k) in actuated.iter().enumerate() {
        b[(k, c)] = 1.0;
    }
    b.view_mut((0, na), (n, m)).copy_from(&j.transpose());
    let mut rhs = DVector::zeros(n.max(cols));
    rhs.rows_mut(0, n).copy_from(&tau_full);
    let svd = b.clone().svd(true, true);
    let eps = RANK_TOLERANCE * svd.singular_values.max().max(f64::MIN_POSITIVE);
    let x = svd.solve(&rhs, eps).expect("U and V were computed");
    let miss = &b * &x - &rhs;
    let scale = tau_full.amax().max(1e-12);
    if miss.amax() > 1e-8 * scale {
        let k = miss.iamax();
        return Err(Error::InvalidInput(format!(
            "constrained inverse dynamics: the actuated joints cannot produce this motion (joint column {k} misses \
             {:e} of torque that neither an actuator nor a loop force can give): actuate other joints",
            miss[k]
        )));
    }
    let v_t = svd.v_t.as_ref().expect("V was computed");
    for (s, sigma) in svd.singular_values.iter().enumerate() {
        if *sigma <= eps && (0..na).any(|c| v_t[(s, c)].abs() > 1e-6) {
            return Err(Error::InvalidInput(
                "constrained inverse dynamics: the actuated joints do not determine their torques (they can push \
                 against each other through a loop without moving it): actuate fewer joints"
                    .into(),
            ));
        }
    }
    out[..n].fill(0.0);
    for (c, &k) in actuated.iter().enumerate() {
        out[k] += x[c];
    }
    Ok(())
}

/// A configuration near `q` that closes the loops (`|r|` below `tolerance`), moving only the
/// velocity columns not in `hold`: Gauss-Newton with the least-norm step `dq = -J_f^+ r` on the free
/// columns, `q <- q ⊕ dq` (the Lie-group step for multi-DOF joints), halving a step that does not
/// reduce `|r|` (Nocedal & Wright, Numerical Optimization, §10.3 and §3.1). Returns the iterations
/// taken; an error names the loop left open.
pub fn project_configuration(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    hold: &[usize],
    tolerance: f64,
    max_iter: usize,
    out: &mut [f64],
) -> Result<usize> {
    let (n, m, nq) = (model.n, model.loop_rows(), model.nq);
    let free: Vec<usize> = (0..n).filter(|k| !hold.contains(k)).collect();
    let mut current = q[..nq].to_vec();
    let mut r = vec![0.0; m];
    let mut trial = vec![0.0; nq];
    let mut step = vec![0.0; n];
    loop_residual(model, data, &current, &mut r);
    let norm = |r: &[f64]| r.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut size = norm(&r);
    for iteration in 0..=max_iter {
        if size <= tolerance {
            out[..nq].copy_from_slice(&current);
            return Ok(iteration);
        }
        if iteration == max_iter || free.is_empty() {
            break;
        }
        let j = jacobian(model, data, &current);
        let jf = DMatrix::from_fn(m, free.len(), |row, c| j[(row, free[c])]);
        let dq = least_norm(jf, &DVector::from_column_slice(&r));
        step.fill(0.0);
        for (c, &k) in free.iter().enumerate() {
            step[k] = -dq[c];
        }
        // backtracking: halve the step until |r| decreases
        let mut scale = 1.0;
        let mut improved = false;
        for _ in 0..40 {
            model.integrate_configuration(&current, &step, scale, &mut trial);
            let mut rt = vec![0.0; m];
            loop_residual(model, data, &trial, &mut rt);
            let nt = norm(&rt);
            if nt < size {
                (current, r, size, improved) = (trial.clone(), rt, nt, true);
                break;
            }
            scale *= 0.5;
        }
        if !improved {
            break;
        }
    }
    let (name, row, value) = worst(model, &r);
    Err(Error::InvalidInput(format!(
        "project_configuration: the loops do not close from this start{} (loop '{name}', row {row}: residual {value:e} \
         after Gauss-Newton, tolerance {tolerance:e}): the held joints or the geometry leave no closed configuration \
         near it",
        if hold.is_empty() { "" } else { " with the held joints fixed" }
    )))
}

/// The velocity nearest to `qd` (Euclidean norm) that keeps the loops closed: `qd - J^+ (J qd)`,
/// the orthogonal projection onto the null space of `J`.
pub fn project_velocity(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], out: &mut [f64]) {
    let n = model.n;
    let j = jacobian(model, data, q);
    let qd_v = DVector::from_column_slice(&qd[..n]);
    let correction = least_norm(j.clone(), &(&j * &qd_v));
    for i in 0..n {
        out[i] = qd[i] - correction[i];
    }
}
