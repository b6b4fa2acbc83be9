//! The eigenvalues (only) of the general-6R companion matrix, on the stack: balancing, reduction to
//! upper Hessenberg form, the Francis double-shift QR iteration.
//!
//! The solver needs the real eigenvalues of one matrix of size at most 24 per target; the
//! eigenvectors it does not need (the other joints come from the null vector of the 12 x 12 matrix
//! polynomial at each root, `general6r_back::null_vector`), so nothing is accumulated, and every
//! transformation acts only on the active window of the iteration:
//!
//! - balancing by powers of two (Parlett & Reinsch, "Balancing a matrix for calculation of
//!   eigenvalues and eigenvectors", Numer. Math. 13, 1969): row and column norms made alike, which
//!   keeps the companion's tiny and huge entries from costing accuracy;
//! - Hessenberg form by Gaussian elimination with row pivoting, each step a similarity (Wilkinson,
//!   The Algebraic Eigenvalue Problem, 1965, §6.49; half the work of Householder reflections);
//! - the implicit double-shift QR step of Francis on the unreduced window, deflating where a
//!   subdiagonal entry falls below machine precision relative to its neighbours (Golub & Van Loan,
//!   Matrix Computations, 4th ed., Algorithms 7.5.1-7.5.2), with Wilkinson's exceptional shifts
//!   after 10 and 20 iterations without deflation.

/// Largest order handled (the companion matrix of a 16 x 16 quadratic matrix polynomial).
pub(super) const MAX: usize = 32;

/// A square matrix of order `n <= MAX`, row-major in a fixed array.
#[derive(Clone)]
pub(super) struct Square {
    pub n: usize,
    pub a: [[f64; MAX]; MAX],
}

impl Square {
    pub fn zeros(n: usize) -> Self {
        debug_assert!(n <= MAX);
        Self {
            n,
            a: [[0.0; MAX]; MAX],
        }
    }

    /// Parlett-Reinsch balancing: `D^-1 A D` with `D` diagonal powers of two (exact in floating
    /// point), row i and column i scaled until their off-diagonal 1-norms agree within a factor 2.
    fn balance(&mut self) {
        let n = self.n;
        let radix = 2.0f64;
        let sq = radix * radix;
        let mut done = false;
        let mut sweeps = 0;
        while !done && sweeps < 40 {
            done = true;
            sweeps += 1;
            for i in 0..n {
                let (mut c, mut r) = (0.0, 0.0);
                for j in 0..n {
                    if j != i {
                        c += self.a[j][i].abs();
                        r += self.a[i][j].abs();
                    }
                }
                if c == 0.0 || r == 0.0 {
                    continue;
                }
                let s = c + r;
                let (mut f, mut g) = (1.0, r / radix);
                while c < g {
                    f *= radix;
                    c *= sq;
                }
                g = r * radix;
                while c > g {
                    f /= radix;
                    c /= sq;
                }
                if (c + r) / f < 0.95 * s {
                    done = false;
                    for j in 0..n {
                        self.a[i][j] /= f;
                    }
                    for j in 0..n {
                        self.a[j][i] *= f;
                    }
                }
            }
        }
    }

    /// Upper Hessenberg form by stabilised elementary similarities: for each column k, the largest
    /// entry below the subdiagonal is swapped up (rows and columns, a permutation similarity), the
    /// entries below it are eliminated by `L^-1 A L`.
    fn hessenberg(&mut self) {
        let n = self.n;
        for k in 1..n.saturating_sub(1) {
            let (mut p, mut big) = (k, 0.0);
            for i in k..n {
                if self.a[i][k - 1].abs() > big {
                    (p, big) = (i, self.a[i][k - 1].abs());
                }
            }
            if p != k {
                self.a.swap(p, k);
                for row in self.a[..n].iter_mut() {
                    row.swap(p, k);
                }
            }
            let pivot = self.a[k][k - 1];
            if pivot == 0.0 {
                continue;
            }
            for i in k + 1..n {
                let m = self.a[i][k - 1] / pivot;
                if m == 0.0 {
                    continue;
                }
                self.a[i][k - 1] = 0.0;
                // row i -= m row k (left), then column k += m column i (right)
                let (top, bottom) = self.a.split_at_mut(i);
                for (x, y) in bottom[0][k..n].iter_mut().zip(&top[k][k..n]) {
                    *x -= m * y;
                }
                for row in self.a[..n].iter_mut() {
                    row[k] += m * row[i];
                }
            }
        }
    }

    /// Every eigenvalue `(re, im)` into `out` (complex ones in conjugate pairs); the matrix is
    /// overwritten. None if the iteration does not converge (30 sweeps per eigenvalue).
    /// (Not inlined: one call per solve, and a profile then shows its share.)
    #[inline(never)]
    pub fn eigenvalues(&mut self, out: &mut Vec<(f64, f64)>) -> Option<()> {
        out.clear();
        let n = self.n;
        if n == 0 {
            return Some(());
        }
        self.balance();
        self.hessenberg();
        let h = &mut self.a;
        let norm: f64 = (0..n)
            .map(|i| h[i][i.saturating_sub(1)..n].iter().map(|x| x.abs()).sum::<f64>())
            .sum();
        if !norm.is_finite() {
            return None;
        }
        let eps = f64::EPSILON;
        let mut hi = n;
        let (mut its, mut total) = (0, 0);
        while hi > 0 {
            let e = hi - 1;
            // l: start of the unreduced window ending at e
            let mut l = e;
            while l > 0 {
                let mut s = h[l - 1][l - 1].abs() + h[l][l].abs();
                if s == 0.0 {
                    s = norm;
                }
                if h[l][l - 1].abs() <= eps * s {
                    h[l][l - 1] = 0.0;
                    break;
                }
                l -= 1;
            }
            if l == e {
                out.push((h[e][e], 0.0));
                hi -= 1;
                its = 0;
                continue;
            }
            if l + 1 == e {
                let (a, b, c, d) = (h[e - 1][e - 1], h[e - 1][e], h[e][e - 1], h[e][e]);
                let p = 0.5 * (a - d);
                let q = p * p + b * c;
                if q >= 0.0 {
                    let z = p + q.sqrt().copysign(p);
                    let first = d + z;
                    let second = if z != 0.0 { d - b * c / z } else { first };
                    out.push((first, 0.0));
                    out.push((second, 0.0));
                } else {
                    let im = (-q).sqrt();
                    out.push((d + p, im));
                    out.push((d + p, -im));
                }
                hi -= 2;
                its = 0;
                continue;
            }
            if total >= 30 * n {
                return None;
            }
            its += 1;
            total += 1;
            // the two shifts as the sum s and product t of the trailing 2 x 2 block's eigenvalues
            let (s, t) = if its % 10 == 0 {
                let w = h[e][e - 1].abs() + h[e - 1][e - 2].abs();
                (1.5 * w, w * w)
            } else {
                (
                    h[e - 1][e - 1] + h[e][e],
                    h[e - 1][e - 1] * h[e][e] - h[e - 1][e] * h[e][e - 1],
                )
            };
            // first column of (H - s1 I)(H - s2 I) = H^2 - s H + t I on the window
            let mut x = h[l][l] * h[l][l] + h[l][l + 1] * h[l + 1][l] - s * h[l][l] + t;
            let mut y = h[l + 1][l] * (h[l][l] + h[l + 1][l + 1] - s);
            let mut z = h[l + 1][l] * h[l + 2][l + 1];
            // chase the bulge down the window with 3-element reflectors, then a 2-element one
            for k in l..e {
                let three = k + 2 <= e;
                let alpha = (x * x + y * y + if three { z * z } else { 0.0 }).sqrt();
                if alpha != 0.0 {
                    // v = x + sign(x) |x| e1; P = I - 2 v v^T / v^T v
                    let v0 = x + alpha.copysign(x);
                    let (v1, v2) = (y, if three { z } else { 0.0 });
                    let beta = 2.0 / (v0 * v0 + v1 * v1 + v2 * v2);
                    let first = if k > l { k - 1 } else { l };
                    // rows k, k + 1 (and k + 2) as slices: the loop runs without bounds checks
                    let (top, rest) = h.split_at_mut(k + 1);
                    let (r1, rest) = rest.split_at_mut(1);
                    let (r0, r1) = (&mut top[k][first..=e], &mut r1[0][first..=e]);
                    if three {
                        let r2 = &mut rest[0][first..=e];
                        for ((a, b), c) in r0.iter_mut().zip(r1.iter_mut()).zip(r2.iter_mut()) {
                            let f = beta * (v0 * *a + v1 * *b + v2 * *c);
                            *a -= f * v0;
                            *b -= f * v1;
                            *c -= f * v2;
                        }
                    } else {
                        for (a, b) in r0.iter_mut().zip(r1.iter_mut()) {
                            let f = beta * (v0 * *a + v1 * *b);
                            *a -= f * v0;
                            *b -= f * v1;
                        }
                    }
                    let last = (k + 3).min(e);
                    for row in h[l..=last].iter_mut() {
                        let dot = row[k] * v0 + row[k + 1] * v1 + if three { row[k + 2] * v2 } else { 0.0 };
                        let f = beta * dot;
                        row[k] -= f * v0;
                        row[k + 1] -= f * v1;
                        if three {
                            row[k + 2] -= f * v2;
                        }
                    }
                    if k > l {
                        // the reflector zeroed these (round-off aside)
                        h[k + 1][k - 1] = 0.0;
                        if three {
                            h[k + 2][k - 1] = 0.0;
                        }
                    }
                }
                if k + 1 < e {
                    x = h[k + 1][k];
                    y = h[k + 2][k];
                    z = if k + 3 <= e { h[k + 3][k] } else { 0.0 };
                }
            }
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The eigenvalues of a random matrix with known spectrum `S diag-blocks S^-1` (real roots and
    /// complex pairs as 2 x 2 rotation-scaling blocks), against the spectrum it was built from.
    #[test]
    fn recovers_a_known_spectrum() {
        let mut rng = Rng::new(11);
        for n in [3usize, 8, 24] {
            let pairs = n / 3;
            let mut block = nalgebra::DMatrix::<f64>::zeros(n, n);
            let mut want = Vec::new();
            let mut i = 0;
            for _ in 0..pairs {
                let (re, im) = (rng.uniform(-3.0, 3.0), rng.uniform(0.1, 2.0));
                block[(i, i)] = re;
                block[(i + 1, i + 1)] = re;
                block[(i, i + 1)] = im;
                block[(i + 1, i)] = -im;
                want.push((re, im));
                want.push((re, -im));
                i += 2;
            }
            while i < n {
                let re = rng.uniform(-5.0, 5.0);
                block[(i, i)] = re;
                want.push((re, 0.0));
                i += 1;
            }
            let s = nalgebra::DMatrix::from_fn(n, n, |_, _| rng.uniform(-1.0, 1.0));
            let a = &s * block * s.clone().try_inverse().unwrap();
            let mut m = Square::zeros(n);
            for r in 0..n {
                for c in 0..n {
                    m.a[r][c] = a[(r, c)];
                }
            }
            let mut got = Vec::new();
            m.eigenvalues(&mut got).expect("converges");
            assert_eq!(got.len(), n);
            for w in &want {
                let near = got
                    .iter()
                    .map(|g| (g.0 - w.0).hypot(g.1 - w.1))
                    .fold(f64::INFINITY, f64::min);
                assert!(near < 1e-8, "n {n}: eigenvalue {w:?} missing from {got:?}");
            }
        }
    }
}
