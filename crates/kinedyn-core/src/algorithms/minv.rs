//! The inverse mass matrix `M(q)^-1` by the sparse `L^T D L` factorisation of the CRBA's `M`.
//!
//! Source: RBDA §6.5, Table 6.3 (`L^T D L` factorisation exploiting branch-induced sparsity:
//! `L[k][i] != 0` only when i supports k) and Table 6.4's back-substitutions. Column j of `M^-1`
//! solves `L^T D L x = e_j`; the lower triangle is computed and mirrored (symmetric to the bit).
//!
//! | symbol      | here                 | meaning                                                |
//! |-------------|----------------------|--------------------------------------------------------|
//! | `H`         | `data.m`             | `M(q)` from [`super::crba::crba`] (armature included)   |
//! | `L`, `D`    | `data.m2`            | unit lower `L` below the diagonal, `D` on the diagonal  |
//! | `λ(i)`      | `model.parent[i]`    | parent of joint i                                      |
//! | `x`         | `data.x`             | one column of `M^-1` being solved                       |

use super::crba::crba;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::Real;

/// Relative size under which a pivot `D_k` counts as zero: against its own diagonal entry `M_kk`
/// (the factorisation cancelled the joint's inertia away: `M` is singular to working precision).
const EPS_D: f64 = 1e-13;
/// Relative size under which a diagonal entry `M_kk` counts as zero against the largest one: a
/// subtree with no inertia about its joint's axis (the rounding of such an `M_kk` is ~1e-32 of the
/// scale). Well above it, bodies of very different sizes (1e20 kg next to 1 kg) factor exactly.
const EPS_M: f64 = 1e-26;
/// A diagonal entry of `M` beyond this (kg m^2) only comes from a configuration or an inertia no
/// robot has (the description refuses parameters over 1e100): a failed pivot then says so.
const HUGE_M: f64 = 1e200;

/// Factor `data.m` (= M) into `data.m2` as `L^T D L` (RBDA Table 6.3).
// `!(a > b && c > d)` is the pivot test that NaN also fails, one comparison per bound
#[allow(clippy::neg_cmp_op_on_partial_ord, clippy::nonminimal_bool)]
#[inline(always)]
pub fn ltdl<T: Real>(model: &Model, data: &mut Data<T>) -> Result<()> {
    let n = model.n;
    let h = &mut data.m2;
    h.copy_from_slice(&data.m[..n * n]);
    // the largest diagonal entry, lane by lane (one lane per state of a batch)
    let mut scale = [0.0f64; 16];
    for (l, s) in scale[..T::LANES].iter_mut().enumerate().filter(|_| !T::RECORDING) {
        *s = (0..n).map(|i| data.m[i * n + i].lane(l)).fold(0.0, f64::max);
    }
    for k in (0..n).rev() {
        let (hkk, mkk) = (h[k * n + k], data.m[k * n + k]);
        // D_k must be a positive part of M_kk, and M_kk a positive part of the scale of M (a
        // recording has no values to test: the program's caller tests them, trace::record)
        for l in (0..T::LANES).filter(|_| !T::RECORDING) {
            let (hkk, mkk, scale) = (hkk.lane(l), mkk.lane(l), scale[l]);
            if !(hkk > EPS_D * mkk && mkk > EPS_M * scale) || !hkk.is_finite() || !scale.is_finite() {
                let diagonal: Vec<f64> = (0..n).map(|i| data.m[i * n + i].lane(l)).collect();
                return Err(Error::SingularMassMatrix {
                    joint: k,
                    overflow: !hkk.is_finite() || !scale.is_finite() || scale > HUGE_M,
                    message: singular_pivot(&diagonal, k, hkk, scale),
                });
            }
        }
        // for i = λ(k) up the tree: a = H_ki / H_kk ; H_ij -= a H_kj for j = i, λ(i), ... ; H_ki = a
        let mut i = model.parent[k];
        while let Some(ii) = i {
            let a = h[k * n + ii] / hkk;
            let mut j = Some(ii);
            while let Some(jj) = j {
                let hkj = h[k * n + jj];
                h[ii * n + jj] -= a * hkj;
                j = model.parent[jj];
            }
            h[k * n + ii] = a;
            i = model.parent[ii];
        }
    }
    Ok(())
}

/// What a pivot `D_k` of `M` below `EPS_D` times its largest diagonal entry means: the joint's
/// subtree has no inertia about its axis (massless, no rotor inertia), or the inertias are so far
/// apart (more than `1 / EPS_D`) that `M` is singular in float64, or M is not positive definite.
/// Why pivot k failed, from M's diagonal.
fn singular_pivot(diagonal: &[f64], k: usize, hkk: f64, scale: f64) -> String {
    let mkk = diagonal[k];
    let largest = (0..diagonal.len()).fold(0, |b, i| if diagonal[i] > diagonal[b] { i } else { b });
    let head = format!("M is not positive definite to float64 precision at joint {k}: its pivot D = {hkk:e} in the L^T D L factorisation");
    if !hkk.is_finite() || !scale.is_finite() {
        format!("{head}; M has a non-finite entry (an inertia or a configuration too large for float64)")
    } else if scale > HUGE_M {
        format!(
            "{head}; M[{largest}, {largest}] = {scale:e}: an entry of M that large (a prismatic joint metres beyond any robot, \
             or a huge inertia) leaves the other joints below float64's resolution (a configuration or inertia too large for float64)"
        )
    } else if hkk < 0.0 && hkk.abs() > EPS_M * scale {
        format!(
            "{head}: a clearly negative pivot, so M is indefinite: some body that joint {k} moves has an inertia no rigid \
             body has (check the signs of the products of inertia)"
        )
    } else if mkk <= EPS_M * scale {
        format!(
            "{head}; M[{k}, {k}] = {mkk:e} ({:.1e} times the largest diagonal entry): the subtree of joint {k} has no inertia \
             about the joint's axis (massless, or its masses on the axis, and no rotor inertia)",
            if scale > 0.0 { mkk / scale } else { 0.0 }
        )
    } else {
        format!(
            "{head}, {:.1e} times M[{k}, {k}] = {mkk:e}: M is numerically singular here, the motion of joint {k} being (nearly) \
             the same as that of the joints it is coupled to; with M[{largest}, {largest}] = {scale:e} the largest diagonal entry, \
             check for inertias that differ by more than float64 can resolve (a wrong unit or a huge value) or for a \
             configuration where the subtree's inertia about the axis vanishes",
            hkk / mkk
        )
    }
}

/// Solve `L^T D L x = b` in place (`l`: the factors of [`ltdl`]; RBDA Table 6.4's back-substitutions).
#[inline(always)]
pub fn ltdl_solve<T: Real>(model: &Model, l: &[T], x: &mut [T]) {
    let n = model.n;
    // L^T z = b: for i = n-1..0, z_i = b_i; b_j -= L_ij z_i for the ancestors j of i
    for i in (0..n).rev() {
        let zi = x[i];
        let mut j = model.parent[i];
        while let Some(jj) = j {
            x[jj] -= l[i * n + jj] * zi;
            j = model.parent[jj];
        }
    }
    // w = D^-1 z
    for i in 0..n {
        x[i] = x[i] / l[i * n + i];
    }
    // L y = w: y_i = w_i - sum_{j ancestors of i} L_ij y_j
    for i in 0..n {
        let mut yi = x[i];
        let mut j = model.parent[i];
        while let Some(jj) = j {
            yi -= l[i * n + jj] * x[jj];
            j = model.parent[jj];
        }
        x[i] = yi;
    }
}

/// `M(q)^-1` written row-major to `data.m` (n x n); `data.m2` holds the factors of `M`.
#[inline(always)]
pub fn mass_matrix_inverse<'d, T: Real>(model: &Model, data: &'d mut Data<T>, q: &[T]) -> Result<&'d [T]> {
    crba(model, data, q);
    inverse_of_mass_matrix(model, data)
}

/// The inverse of the mass matrix in `data.m`, written over it (`data.m2`: its factors).
#[inline(always)]
pub fn inverse_of_mass_matrix<'d, T: Real>(model: &Model, data: &'d mut Data<T>) -> Result<&'d [T]> {
    let n = model.n;
    ltdl(model, data)?;
    let (l, x, out) = (&data.m2, &mut data.x, &mut data.m);
    for col in 0..n {
        // b = e_col
        x[..n].fill(T::zero());
        x[col] = T::one();
        ltdl_solve(model, l, x);
        // keep the lower triangle (rows >= col) of column col, mirrored into the upper one
        for r in col..n {
            out[r * n + col] = x[r];
            out[col * n + r] = x[r];
        }
    }
    Ok(&data.m)
}
