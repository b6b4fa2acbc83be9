//! The linearly implicit (Rosenbrock-) Euler step (Hairer & Wanner, *Solving ODEs II*, §IV.7,
//! eq. 7.4 with gamma = 1; the derivation is in the header of `sim/mod.rs`):
//!
//! ```text
//! (I - h A_v - h^2 A_q) dv = h (qdd_k + h A_q qd_k),   qd_{k+1} = qd_k + dv,   q_{k+1} = q_k ⊕ h qd_{k+1}
//! ```
//!
//! | symbol | here         | meaning                                                  |
//! |--------|--------------|----------------------------------------------------------|
//! | `A_q`  | `s.a_q`      | `dqdd/dq` (n x n, row-major), controller gains included  |
//! | `A_v`  | `s.a_v`      | `dqdd/dqd`                                               |
//! | `M^-1` | `s.minv`     | inverse mass matrix                                      |
//! | `h`    | `h`          | step (s)                                                 |

use super::integrate::{singular_joint, step_configuration};
use super::{Failure, FailureKind, TorqueFn};
use crate::algorithms::derivatives::aba_derivatives;
use crate::data::Data;
use crate::model::Model;

/// Scratch of the implicit step (n x n matrices row-major, allocated once per trajectory).
pub(super) struct ImplicitScratch {
    a_q: Vec<f64>,
    a_v: Vec<f64>,
    minv: Vec<f64>,
    k_q: Vec<f64>,
    k_v: Vec<f64>,
    lu: Vec<f64>,
    pivot: Vec<usize>,
    rhs: Vec<f64>,
    v0: Vec<f64>,
    /// The next configuration (nq numbers).
    q_next: Vec<f64>,
}

impl ImplicitScratch {
    pub(super) fn new(n: usize, nq: usize) -> Self {
        let m = || vec![0.0; n * n];
        ImplicitScratch {
            a_q: m(),
            a_v: m(),
            minv: m(),
            k_q: m(),
            k_v: m(),
            lu: m(),
            pivot: vec![0; n],
            rhs: vec![0.0; n],
            v0: vec![0.0; n],
            q_next: vec![0.0; nq],
        }
    }
}

/// LU factorisation with partial pivoting of the row-major n x n `a`, in place (Golub & Van Loan,
/// *Matrix Computations*, 4th ed., Algorithm 3.4.1): `P a = L U`, `pivot[k]` the row swapped into
/// row k. `Err(k)` if column k has no usable pivot (the matrix is singular).
fn lu_factor(a: &mut [f64], n: usize, pivot: &mut [usize]) -> std::result::Result<(), usize> {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .unwrap_or(k);
        pivot[k] = p;
        let size = a[p * n + k].abs();
        if size.is_nan() || size <= 1e-300_f64.max(1e-15 * scale) {
            return Err(k);
        }
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
        }
        // below the pivot: l_ik = a_ik / a_kk ; a_ij -= l_ik a_kj
        let akk = a[k * n + k];
        for i in k + 1..n {
            let l = a[i * n + k] / akk;
            a[i * n + k] = l;
            if l != 0.0 {
                for j in k + 1..n {
                    a[i * n + j] -= l * a[k * n + j];
                }
            }
        }
    }
    Ok(())
}

/// Solve `a x = b` in place in `b` with the factors of [`lu_factor`].
fn lu_solve(lu: &[f64], n: usize, pivot: &[usize], b: &mut [f64]) {
    for (k, &p) in pivot[..n].iter().enumerate() {
        b.swap(k, p);
    }
    // L y = P b (unit lower) ; U x = y
    for i in 0..n {
        let s: f64 = (0..i).map(|j| lu[i * n + j] * b[j]).sum();
        b[i] -= s;
    }
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| lu[i * n + j] * b[j]).sum();
        b[i] = (b[i] - s) / lu[i * n + i];
    }
}

/// `out += a b` for row-major n x n matrices.
fn add_product(out: &mut [f64], a: &[f64], b: &[f64], n: usize) {
    for r in 0..n {
        for k in 0..n {
            let c = a[r * n + k];
            if c != 0.0 {
                for j in 0..n {
                    out[r * n + j] += c * b[k * n + j];
                }
            }
        }
    }
}

/// One linearly implicit Euler step from `(q, qd)` at `t` (see the module header), `qdd` the ABA's
/// acceleration there and `tau` the torque applied; `q`, `qd` are overwritten with the new state.
// r, j, k: row and column indices of the n x n row-major matrices and of the joint vectors alike
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
pub(super) fn implicit_step(
    model: &Model,
    data: &mut Data,
    source: &mut dyn TorqueFn,
    s: &mut ImplicitScratch,
    step: usize,
    t: f64,
    h: f64,
    q: &mut [f64],
    qd: &mut [f64],
    qdd: &[f64],
    tau: &[f64],
    f_ext: Option<&[f64]>,
) -> std::result::Result<(), Failure> {
    let n = model.n;
    let fail = |joint, kind| Failure { step, t, joint, kind };
    // A_q = dqdd/dq, A_v = dqdd/dqd, M^-1 at (q, qd, tau, f_ext), the wrenches held in base axes
    aba_derivatives(model, data, q, qd, tau, f_ext, &mut s.a_q, &mut s.a_v, &mut s.minv)
        .map_err(|e| fail(singular_joint(&e), FailureKind::Singular(e.to_string())))?;
    // the torque's own dependence on the state: A_q += M^-1 dtau/dq ; A_v += M^-1 dtau/dqd
    let known = source
        .jacobian(step, t, q, qd, &mut s.k_q, &mut s.k_v)
        .map_err(|m| fail(None, FailureKind::Source(m)))?;
    if known {
        if let Some(j) = s.k_q.iter().chain(s.k_v.iter()).position(|x| !x.is_finite()) {
            return Err(fail(
                Some((j % (n * n)) / n.max(1)),
                FailureKind::Source("the torque's Jacobian has a non-finite entry".into()),
            ));
        }
        add_product(&mut s.a_q, &s.minv, &s.k_q, n);
        add_product(&mut s.a_v, &s.minv, &s.k_v, n);
    }
    // LU of I - h A_v - h^2 A_q
    for r in 0..n {
        for c in 0..n {
            let identity = if r == c { 1.0 } else { 0.0 };
            s.lu[r * n + c] = identity - h * s.a_v[r * n + c] - h * h * s.a_q[r * n + c];
        }
    }
    lu_factor(&mut s.lu, n, &mut s.pivot).map_err(|k| {
        fail(
            Some(k),
            FailureKind::Singular(format!(
                "the implicit step's matrix I - h dqdd/dqd - h^2 dqdd/dq is singular at joint {k}"
            )),
        )
    })?;
    // without Coulomb friction: a0 = qdd + M^-1 coulomb_torque(qd) (the ABA's qdd includes it)
    let coulomb = (0..n).any(|k| model.has_coulomb(k));
    // dv0 = (I - h A_v - h^2 A_q)^-1 h (a0 + h A_q qd)
    for r in 0..n {
        let mut a0 = qdd[r];
        if coulomb {
            a0 += (0..n)
                .map(|k| s.minv[r * n + k] * model.coulomb_torque(k, qd[k]))
                .sum::<f64>();
        }
        let spring: f64 = (0..n).map(|k| s.a_q[r * n + k] * qd[k]).sum();
        s.rhs[r] = h * (a0 + h * spring);
    }
    lu_solve(&s.lu, n, &s.pivot, &mut s.rhs);
    for j in 0..n {
        s.v0[j] = qd[j] + s.rhs[j];
    }
    if coulomb {
        // Coulomb along the predicted velocity: dvc = (I - h A_v - h^2 A_q)^-1 (-h M^-1 coulomb_torque(v0))
        for r in 0..n {
            s.rhs[r] = -h
                * (0..n)
                    .map(|k| s.minv[r * n + k] * model.coulomb_torque(k, s.v0[k]))
                    .sum::<f64>();
        }
        lu_solve(&s.lu, n, &s.pivot, &mut s.rhs);
        for j in 0..n {
            let v1 = s.v0[j] + s.rhs[j];
            // friction stops a joint, it does not reverse it
            qd[j] = if model.has_coulomb(j) && v1 * s.v0[j] < 0.0 {
                0.0
            } else {
                v1
            };
        }
    } else {
        qd.copy_from_slice(&s.v0);
    }
    // q_{k+1} = q_k ⊕ h qd_{k+1}
    step_configuration(model, q, qd, h, &mut s.q_next);
    Ok(())
}
