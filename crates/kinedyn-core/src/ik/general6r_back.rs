//! The steps of the general-6R solve (`super`) around its eigenvalue problem: the reduced
//! equations of a target, the remaining joints from an eigenvalue (least squares or subproblems),
//! Newton refinement on the pose error, the null vector and block solve of the matrix polynomial.

use super::{equations, fourier, joint_exp, powers, General6R, Item};
use crate::ik::pose_error;
use crate::ik::subproblems::{sp1_dir, sp4};
use crate::spatial::{Transform, Vec3};
use nalgebra::{Matrix6, SMatrix, Vector6};
use std::f64::consts::PI;

impl General6R {
    /// The V joints from `y = Q_Y^+ (F(th_u) - H_0)` (or by subproblems), then the cut joint by
    /// subproblem 1.
    pub(super) fn back_substitute(&self, th: &mut [f64; 6], g: &Transform) {
        if self.full_rank {
            let fu = self.side(&self.u, th, g);
            let rhs = SMatrix::<f64, 14, 1>::from_fn(|q, _| fu[q] - self.h0[q]);
            let y = self.qy_pinv * rhs;
            // y[idx - 1] multiplies row a = idx / 3 (first V joint), column b = idx % 3 (second)
            th[self.vj[0]] = y[5].atan2(y[2]);
            th[self.vj[1]] = y[1].atan2(y[0]);
        } else {
            self.v_by_subproblems(th, g);
        }
        // E_k = (E_0 .. E_{k-1})^-1 G (E_{k+1} .. E_5)^-1
        let k = self.cut;
        let mut before = Transform::identity();
        for j in 0..k {
            before = before * joint_exp(&self.axes[j], th[j]);
        }
        let mut after = Transform::identity();
        for j in k + 1..6 {
            after = after * joint_exp(&self.axes[j], th[j]);
        }
        let ek = before.inverse() * *g * after.inverse();
        let w = self.axes[k].w;
        let n = if w.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
        th[k] = sp1_dir(&w, &n, &(ek.rot * n)).values[0];
    }

    /// The V joints `a, b` from `E_a E_b r_k = p`, `R_a R_b w_k = l` (p, l: the U side): rotations
    /// about `w_a` keep components along `w_a`, so `theta_b` solves subproblem 4 for the
    /// direction and for the point; `theta_a` then subproblem 1. The best fitting pair is kept.
    fn v_by_subproblems(&self, th: &mut [f64; 6], g: &Transform) {
        let cut = &self.axes[self.cut];
        let (mut p, mut l) = (cut.r, cut.w);
        for item in self.u.iter().rev() {
            let t = match *item {
                Item::Joint(j, sign) => joint_exp(&self.axes[j], sign * th[j]),
                Item::Target(false) => *g,
                Item::Target(true) => g.inverse(),
            };
            p = t.act_point(&p);
            l = t.rot * l;
        }
        let ((ja, sa), (jb, sb)) = match (self.v[0], self.v[1]) {
            (Item::Joint(ja, sa), Item::Joint(jb, sb)) => ((ja, sa), (jb, sb)),
            _ => return,
        };
        let (a, b) = (self.axes[ja], self.axes[jb]);
        let from_direction = sp4(&a.w, &b.w, &cut.w, a.w.dot(&l));
        let from_point = sp4(&a.w, &b.w, &(cut.r - b.r), a.w.dot(&(p - a.r)) - a.w.dot(&(b.r - a.r)));
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for (angles, ok) in [
            (from_direction, !from_direction.singular),
            (from_point, !from_point.singular),
        ] {
            for &phi_b in angles.as_slice().iter().filter(|_| ok) {
                let eb = joint_exp(&b, phi_b);
                let (x, d) = (eb.act_point(&cut.r), eb.rot * cut.w);
                for phi_a in [sp1_dir(&a.w, &d, &l), sp1_dir(&a.w, &(x - a.r), &(p - a.r))] {
                    if phi_a.singular {
                        continue;
                    }
                    let ea = joint_exp(&a, phi_a.values[0]);
                    let err = (ea.act_point(&x) - p).norm() / self.scale + (ea.rot * d - l).norm();
                    if err < best.0 {
                        best = (err, phi_a.values[0], phi_b);
                    }
                }
            }
        }
        th[ja] = sa * best.1;
        th[jb] = sb * best.2;
    }

    /// The six equations free of the V joints, `N (F(th_u) - H_0)`, as coefficients
    /// `d[i][p0][p1][p2]` of the half-angle powers of the U joints (each shifted by `SHIFT`).
    #[inline(never)]
    pub(super) fn reduced_equations(&self, g: &Transform) -> [[[[f64; 3]; 3]; 3]; 6] {
        // U side: 27 samples on the shifted grid, then its Fourier coefficients f[q][a][b][c].
        // The cut axis is carried through the factors from the right, each joint's three sampled
        // motions precomputed (`grid`): 3 + 9 + 27 rigid motions instead of 27 products
        let mut f = [[[[0.0; 3]; 3]; 3]; 14];
        let cut = &self.axes[self.cut];
        let mut states = [(Vec3::zeros(), Vec3::zeros()); 27];
        states[0] = (cut.r, cut.w);
        let mut count = 1;
        let g_inv = g.inverse();
        for item in self.u.iter().rev() {
            match *item {
                Item::Joint(j, _) => {
                    for s in (0..count).rev() {
                        let (p, l) = states[s];
                        for (m, e) in self.grid[j].iter().enumerate() {
                            states[3 * s + m] = (e.act_point(&p), e.rot * l);
                        }
                    }
                    count *= 3;
                }
                Item::Target(inverse) => {
                    let t = if inverse { &g_inv } else { g };
                    for st in states[..count].iter_mut() {
                        *st = (t.act_point(&st.0), t.rot * st.1);
                    }
                }
            }
        }
        // state index: the first joint met from the right (uj[2]) varies slowest
        for (s, (p, l)) in states.iter().enumerate() {
            let e = equations(&((p - cut.r) / self.scale), l);
            let (m2, m1, m0) = (s / 9, (s / 3) % 3, s % 3);
            for q in 0..14 {
                f[q][m0][m1][m2] = e[q];
            }
        }
        // reduced equations N (F - H_0) in half-angle powers d[i][p0][p1][p2]
        let mut d = [[[[0.0; 3]; 3]; 3]; 6];
        for q in 0..14 {
            let fq = &mut f[q];
            for m0 in 0..3 {
                for m1 in 0..3 {
                    fq[m0][m1] = powers(fourier(fq[m0][m1][0], fq[m0][m1][1], fq[m0][m1][2]));
                }
                for p2 in 0..3 {
                    let c = powers(fourier(fq[m0][0][p2], fq[m0][1][p2], fq[m0][2][p2]));
                    for p1 in 0..3 {
                        fq[m0][p1][p2] = c[p1];
                    }
                }
            }
            for p1 in 0..3 {
                for p2 in 0..3 {
                    let c = powers(fourier(fq[0][p1][p2], fq[1][p1][p2], fq[2][p1][p2]));
                    for p0 in 0..3 {
                        fq[p0][p1][p2] = c[p0];
                    }
                }
            }
            // the constant H_0 (moved to this side) is 1 = (1 + x^2)/(1 + x^2) in every variable
            let h = self.h0[q];
            for p0 in [0, 2] {
                for p1 in [0, 2] {
                    for p2 in [0, 2] {
                        fq[p0][p1][p2] -= h;
                    }
                }
            }
            for i in 0..6 {
                let n = self.null[(i, q)];
                for p0 in 0..3 {
                    for p1 in 0..3 {
                        for p2 in 0..3 {
                            d[i][p0][p1][p2] += n * fq[p0][p1][p2];
                        }
                    }
                }
            }
        }
        d
    }

    /// Newton steps on the pose error (world-aligned Jacobian of the screws): the solution and
    /// its residual, or None if it does not reproduce the target.
    pub(super) fn refine(&self, mut th: [f64; 6], target: &Transform) -> Option<([f64; 6], f64)> {
        let tol = 1e-9 * self.scale.max(1.0);
        let mut last = f64::INFINITY;
        for _ in 0..12 {
            let (e, jac) = self.error_and_jacobian(&th, target);
            let r = Vector6::from_column_slice(&e);
            let size = r.fixed_rows::<3>(0).norm() + r.fixed_rows::<3>(3).norm();
            if size <= 1e-14 * self.scale.max(1.0) || (size >= 0.5 * last && size <= tol) {
                return Some((wrap(th), size));
            }
            if size > 0.5 * self.scale.max(1.0) || !size.is_finite() {
                return None; // far from any solution: a spurious root
            }
            last = size;
            let step = jac.lu().solve(&r)?;
            for j in 0..6 {
                th[j] += step[j];
            }
        }
        let (e, _) = self.error_and_jacobian(&th, target);
        let size = Vec3::new(e[0], e[1], e[2]).norm() + Vec3::new(e[3], e[4], e[5]).norm();
        (size <= tol).then_some((wrap(th), size))
    }

    fn error_and_jacobian(&self, th: &[f64; 6], target: &Transform) -> ([f64; 6], Matrix6<f64>) {
        let mut t = Transform::identity();
        let mut cols = [(Vec3::zeros(), Vec3::zeros()); 6];
        for j in 0..6 {
            // axis j at th: direction R w_j through T r_j
            cols[j] = (t.rot * self.axes[j].w, t.act_point(&self.axes[j].r));
            t = t * joint_exp(&self.axes[j], th[j]);
        }
        let tool = t * self.home;
        let e = pose_error(&tool, target);
        let mut jac = Matrix6::zeros();
        for (j, (w, r)) in cols.iter().enumerate() {
            let v = w.cross(&(tool.trans - r));
            for q in 0..3 {
                jac[(q, j)] = v[q];
                jac[(3 + q, j)] = w[q];
            }
        }
        (e, jac)
    }
}

/// Angles into (-pi, pi].
pub(super) fn wrap(mut th: [f64; 6]) -> [f64; 6] {
    for x in th.iter_mut() {
        *x -= 2.0 * PI * ((*x + PI) / (2.0 * PI)).floor();
        if *x <= -PI {
            *x += 2.0 * PI;
        }
    }
    th
}

/// Equal modulo 2 pi, entry by entry.
pub fn same_angles(a: &[f64; 6], b: &[f64; 6], tol: f64) -> bool {
    (0..6).all(|j| {
        let d = a[j] - b[j];
        (d - 2.0 * PI * (d / (2.0 * PI)).round()).abs() < tol
    })
}

/// Largest side of the square matrix polynomial (16 monomials of the extended formulation).
pub(super) const SIDE: usize = 16;
pub(super) type Sq = [[f64; SIDE]; SIDE];

/// A unit null vector of a (numerically) singular `n x n` matrix (its leading block of `a`):
/// Gaussian elimination with full pivoting, the last pivot taken as zero.
#[inline(never)]
pub(super) fn null_vector(m: &Sq, n: usize) -> [f64; SIDE] {
    let mut a = *m;
    let mut col: [usize; SIDE] = std::array::from_fn(|i| i);
    for k in 0..n.saturating_sub(1) {
        let (mut pr, mut pc, mut best) = (k, k, -1.0);
        for (i, row) in a.iter().enumerate().take(n).skip(k) {
            for (j, x) in row.iter().enumerate().take(n).skip(k) {
                if x.abs() > best {
                    (pr, pc, best) = (i, j, x.abs());
                }
            }
        }
        a.swap(k, pr);
        for row in a.iter_mut().take(n) {
            row.swap(k, pc);
        }
        col.swap(k, pc);
        if best == 0.0 {
            continue;
        }
        let (top, bottom) = a.split_at_mut(k + 1);
        let pivot_row = &top[k];
        for row in bottom.iter_mut().take(n - k - 1) {
            let f = row[k] / pivot_row[k];
            for j in k..n {
                row[j] -= f * pivot_row[j];
            }
        }
    }
    // upper triangular: z_{n-1} = 1, back substitution for the others
    let mut z = [0.0; SIDE];
    if n == 0 {
        return z;
    }
    z[n - 1] = 1.0;
    for i in (0..n - 1).rev() {
        let s: f64 = (i + 1..n).map(|j| a[i][j] * z[j]).sum();
        z[i] = if a[i][i] != 0.0 { -s / a[i][i] } else { 0.0 };
    }
    let norm = z[..n].iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut u = [0.0; SIDE];
    for i in 0..n {
        u[col[i]] = z[i] / norm;
    }
    u
}

/// `A^-1 [B C]` for `n x n` blocks by Gaussian elimination with full pivoting, into `out` (row i:
/// the `2n` entries of row i of the result); returns the smallest pivot relative to the largest
/// (how far `A` is from singular), or None if `A` is singular.
pub(super) fn solve_blocks(a: &Sq, b: &Sq, c: &Sq, n: usize, out: &mut [[f64; 2 * SIDE]; SIDE]) -> Option<f64> {
    let mut m = *a;
    for i in 0..n {
        out[i][..n].copy_from_slice(&b[i][..n]);
        out[i][n..2 * n].copy_from_slice(&c[i][..n]);
    }
    let mut col: [usize; SIDE] = std::array::from_fn(|i| i);
    let (mut small, mut large) = (f64::INFINITY, 0.0f64);
    for k in 0..n {
        let (mut pr, mut pc, mut best) = (k, k, -1.0);
        for (i, row) in m.iter().enumerate().take(n).skip(k) {
            for (j, x) in row.iter().enumerate().take(n).skip(k) {
                if x.abs() > best {
                    (pr, pc, best) = (i, j, x.abs());
                }
            }
        }
        if best <= 0.0 || !best.is_finite() {
            return None;
        }
        (small, large) = (small.min(best), large.max(best));
        m.swap(k, pr);
        out.swap(k, pr);
        for row in m.iter_mut().take(n) {
            row.swap(k, pc);
        }
        col.swap(k, pc);
        let (top, bottom) = m.split_at_mut(k + 1);
        let (otop, obottom) = out.split_at_mut(k + 1);
        for (row, orow) in bottom.iter_mut().zip(obottom.iter_mut()).take(n - k - 1) {
            let f = row[k] / top[k][k];
            if f == 0.0 {
                continue;
            }
            for j in k..n {
                row[j] -= f * top[k][j];
            }
            for j in 0..2 * n {
                orow[j] -= f * otop[k][j];
            }
        }
    }
    // back substitution, rows of the permuted unknowns, then undo the column permutation
    for i in (0..n).rev() {
        for j in i + 1..n {
            let f = m[i][j];
            if f != 0.0 {
                let (top, bottom) = out.split_at_mut(j);
                for t in 0..2 * n {
                    top[i][t] -= f * bottom[0][t];
                }
            }
        }
        let d = m[i][i];
        for t in 0..2 * n {
            out[i][t] /= d;
        }
    }
    let permuted = *out;
    for i in 0..n {
        out[col[i]] = permuted[i];
    }
    Some(small / large)
}
