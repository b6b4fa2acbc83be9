//! The last steps of the general-6R solve (`super`): the remaining joints from an eigenvalue
//! (least squares or subproblems), Newton refinement on the pose error, and the null vector of
//! the matrix polynomial.

use super::{joint_exp, General6R, Item, M12};
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

/// A unit null vector of a (numerically) singular 12 x 12 matrix: Gaussian elimination with full
/// pivoting, the last pivot taken as zero.
pub(super) fn null_vector(m: &M12) -> [f64; 12] {
    let mut a = *m;
    let mut col: [usize; 12] = std::array::from_fn(|i| i);
    for k in 0..11 {
        let (mut pr, mut pc, mut best) = (k, k, -1.0);
        for i in k..12 {
            for j in k..12 {
                if a[(i, j)].abs() > best {
                    (pr, pc, best) = (i, j, a[(i, j)].abs());
                }
            }
        }
        a.swap_rows(k, pr);
        a.swap_columns(k, pc);
        col.swap(k, pc);
        if best == 0.0 {
            continue;
        }
        for i in k + 1..12 {
            let f = a[(i, k)] / a[(k, k)];
            for j in k..12 {
                a[(i, j)] -= f * a[(k, j)];
            }
        }
    }
    // upper triangular: z_11 = 1, back substitution for z_0..z_10
    let mut z = [0.0; 12];
    z[11] = 1.0;
    for i in (0..11).rev() {
        let s: f64 = (i + 1..12).map(|j| a[(i, j)] * z[j]).sum();
        z[i] = if a[(i, i)] != 0.0 { -s / a[(i, i)] } else { 0.0 };
    }
    let norm = z.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut u = [0.0; 12];
    for i in 0..12 {
        u[col[i]] = z[i] / norm;
    }
    u
}
