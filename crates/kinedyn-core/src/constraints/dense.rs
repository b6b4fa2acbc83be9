//! Small dense symmetric solves on any scalar (one state or SIMD lanes): `L D L^T` without
//! pivoting, for the symmetric positive definite `J M^-1 J^T + mu 1` of the proximal solve
//! (Golub & Van Loan, Matrix Computations, 4th ed., Algorithm 4.1.2; no square roots, so it runs
//! on lanes).

use crate::scalar::Real;

/// Factor the row-major m x m symmetric `a` in place: `D` on the diagonal, the unit lower `L`
/// below it (the upper triangle is left as it was).
#[inline(always)]
pub fn ldlt<T: Real>(a: &mut [T], m: usize) {
    for j in 0..m {
        // d_j = a_jj - sum_k L_jk^2 d_k
        let mut d = a[j * m + j];
        for k in 0..j {
            let l = a[j * m + k];
            d -= l * l * a[k * m + k];
        }
        a[j * m + j] = d;
        // L_ij = (a_ij - sum_k L_ik L_jk d_k) / d_j
        for i in j + 1..m {
            let mut s = a[i * m + j];
            for k in 0..j {
                s -= a[i * m + k] * a[j * m + k] * a[k * m + k];
            }
            a[i * m + j] = s / d;
        }
    }
}

/// Solve `L D L^T x = b` in place with the factors of [`ldlt`].
#[inline(always)]
pub fn ldlt_solve<T: Real>(f: &[T], m: usize, x: &mut [T]) {
    for i in 0..m {
        for k in 0..i {
            let xk = x[k];
            x[i] -= f[i * m + k] * xk;
        }
    }
    for i in 0..m {
        x[i] = x[i] / f[i * m + i];
    }
    for i in (0..m).rev() {
        for k in i + 1..m {
            let xk = x[k];
            x[i] -= f[k * m + i] * xk;
        }
    }
}

/// `a . b`.
#[inline(always)]
pub fn dot<T: Real>(a: &[T], b: &[T]) -> T {
    a.iter().zip(b).fold(T::zero(), |s, (x, y)| s + *x * *y)
}

/// The largest `|x_i|` of each lane (one per state of a batch; lane 0 for `f64`).
#[inline(always)]
pub fn lane_max_abs<T: Real>(x: &[T]) -> [f64; 16] {
    let mut out = [0.0f64; 16];
    for v in x {
        for (l, o) in out[..T::LANES].iter_mut().enumerate() {
            *o = o.max(v.lane(l).abs());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ldlt_solves_a_symmetric_positive_definite_system() {
        let m = 4;
        let b: Vec<f64> = (0..m * m).map(|k| ((k * 7 + 3) % 11) as f64 - 5.0).collect();
        // a = B B^T + 1
        let mut a = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                a[i * m + j] =
                    (0..m).map(|k| b[i * m + k] * b[j * m + k]).sum::<f64>() + if i == j { 1.0 } else { 0.0 };
            }
        }
        let x: Vec<f64> = (0..m).map(|i| i as f64 - 1.5).collect();
        let mut rhs: Vec<f64> = (0..m).map(|i| dot(&a[i * m..(i + 1) * m], &x)).collect();
        let mut f = a.clone();
        ldlt(&mut f, m);
        ldlt_solve(&f, m, &mut rhs);
        for i in 0..m {
            assert!((rhs[i] - x[i]).abs() < 1e-12, "{rhs:?} vs {x:?}");
        }
    }
}
