//! Every real inverse-kinematics solution of a general 6R chain (up to 16), from its screw axes.
//!
//! **Method**: the elimination of Raghavan & Roth, "Inverse kinematics of the general 6R
//! manipulator and related linkages", ASME J. Mech. Des. 115(3), 1993, in the matrix-polynomial /
//! eigenvalue form of Manocha & Canny, "Efficient inverse kinematics for general 6R
//! manipulators", IEEE T-RA 10(5), 1994. Chosen over IK-Geo's search (Elias & Wen 2022), which
//! needs a 2-D search when no two axes meet or are parallel and can step over close roots: here
//! the solutions are the real eigenvalues of one 24 x 24 matrix, found all at once.
//!
//! **Loop** (product of exponentials, `E_j = exp(xi_j^ theta_j)`): `E_0 ... E_5 = G`,
//! `G = g_d g(0)^-1`. Cut the loop at joint `k`: with `S` the other five joints and `G^-1` in
//! loop order, `S = A B` and `B E_k = A^-1`. `E_k` fixes its own line, so for `x = r_k` (a point
//! on axis k) and `d = w_k`
//!
//! ```text
//! p = B x = A^-1 x,     l = R_B d = R_A^T d
//! ```
//!
//! One side (`V`) holds two joints, the other (`U`) three and the target. Both sides of the 14
//! equations of Raghavan & Roth, `l, p, p.p, p.l, p x l, (p.p) l - 2 (p.l) p`, are of degree one
//! in the cosine and sine of each joint angle (the quadratic terms of the last cancel:
//! `(c.Rq) Rm - (c.Rm) Rq = c x (Rm x Rq)` at every level), so each side is exactly its
//! three-point Fourier interpolation per joint: 27 samples of `U`, 9 of `V` (no symbolic algebra;
//! the test `equations_interpolate_exactly` checks the claim at random angles).
//!
//! ```text
//! F(th_u) - H_0 = Q_Y y(th_v),   y = the 8 products of {1, c, s} of the two V joints but 1
//! N F(th_u) = N H_0,             N: 6 x 14, the left null space of Q_Y (no target in V: once per chain)
//! ```
//!
//! Half-angle tangents (`x = tan((theta - phi)/2)`, a fixed shift `phi` per joint keeps the
//! roots off infinity) and one more row block times `x_a` give Manocha & Canny's 12 x 12 matrix
//! polynomial `M(x_t) m = 0`, `M = M2 x^2 + M1 x + M0`, `m = [x_a^i x_b^j]` (i < 4, j < 3); its
//! real roots are the real eigenvalues of the companion matrix `[0 I; -M2^-1 M0  -M2^-1 M1]`.
//! `x_a, x_b` come from the null vector of `M(x_t)`, the V joints from `y` (least squares), joint
//! `k` from subproblem 1. Each candidate is refined by Newton steps on the 6-D pose error and
//! kept only if it reproduces the target; repeats are merged. The cut, the V pair and the
//! eigen joint are chosen per chain, from those whose `Q_Y` has full rank, by solving targets of
//! known solutions (`General6R::new`).
//!
//! | symbol   | here        | meaning                                                        |
//! |----------|-------------|----------------------------------------------------------------|
//! | `k`      | `cut`       | joint whose axis closes the loop                               |
//! | `U`, `V` | `u`, `v`    | the three (with the target) and two joints of the two sides    |
//! | `F`      | `f`         | 14 x 27 coefficients of the U side in `{1, cos, sin}^3`        |
//! | `Q_Y`    | `qy`        | 14 x 8 coefficients of the V side (constant column `H_0` apart)|
//! | `t,a,b`  | `eig`, ...  | the U joint whose tangent is the eigenvalue, and the other two |

use super::subproblems::Axis;
use crate::joint::axis_angle;
use crate::spatial::{Transform, Vec3};
use nalgebra::SMatrix;
use std::f64::consts::PI;

type Eqs = [f64; 14];
/// Most rows of the matrix polynomial (6 equations times 4 monomial multipliers).
const ROWS: usize = 24;

/// Most real solutions a 6R chain can have (Raghavan & Roth 1993; Manseur & Doty 1989).
pub const MAX_SOLUTIONS: usize = 16;

/// One factor of a side's product: a joint's exponential (angle times `sign`) or the target.
#[derive(Clone, Copy, Debug)]
enum Item {
    Joint(usize, f64),
    /// `G` (false) or `G^-1` (true).
    Target(bool),
}

/// Shifts of the half-angle variables (any fixed angles far from 0 and pi would do).
const SHIFT: [f64; 6] = [0.4133, -0.8721, 1.2517, -0.3361, 0.7093, -1.1657];

/// A chain's general-6R solver: the cut and sides chosen, the V side's equations factored.
#[derive(Clone, Debug)]
pub struct General6R {
    axes: [Axis; 6],
    home: Transform,
    /// Lengths divided by this (equations of one size).
    scale: f64,
    cut: usize,
    u: Vec<Item>,
    /// U's joints in product order, then V's.
    uj: [usize; 3],
    vj: [usize; 2],
    v: Vec<Item>,
    /// Position in `uj` of the eigen joint.
    eig: usize,
    /// Whether Q_Y has full rank (8).
    full_rank: bool,
    /// The extended formulation: rows `x_b d` and `x_a x_b d` too (24 x 16, squared by `mix`),
    /// for chains whose 12 x 12 matrix polynomial is singular at every `x_t`.
    extended: bool,
    /// Fixed generic row combinations that square a non-square system.
    mix: [[f64; ROWS]; SIDE],
    /// Each joint's motion at the U side's three sample angles (sign included).
    grid: [[Transform; 3]; 6],
    /// Left null space of Q_Y (6 x 14), its pseudo-inverse (8 x 14), the constant column H_0.
    null: SMatrix<f64, 6, 14>,
    qy_pinv: SMatrix<f64, 8, 14>,
    h0: Eqs,
}

/// What one solve found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct General6RStats {
    /// Real (or near-real) eigenvalues tried.
    pub candidates: usize,
    /// Largest pose residual of the solutions returned (`|dp| + |dR|`, m and rad).
    pub worst_residual: f64,
    /// Two accepted roots came close (branches meeting: a near-singular target).
    pub near_double: bool,
}

/// The 14 equations of Raghavan & Roth from a point and a direction.
#[inline]
fn equations(p: &Vec3, l: &Vec3) -> Eqs {
    let pp = p.dot(p);
    let pl = p.dot(l);
    let c = p.cross(l);
    let r = l * pp - p * (2.0 * pl);
    [l.x, l.y, l.z, p.x, p.y, p.z, pp, pl, c.x, c.y, c.z, r.x, r.y, r.z]
}

/// Coefficients `[c0, c1, c2]` of `c0 + c1 cos(psi) + c2 sin(psi)` from its values at
/// `psi = 0, 2 pi/3, 4 pi/3` (the three-point discrete Fourier transform).
#[inline]
fn fourier(f0: f64, f1: f64, f2: f64) -> [f64; 3] {
    [
        (f0 + f1 + f2) / 3.0,
        (2.0 * f0 - f1 - f2) / 3.0,
        (f1 - f2) / 3f64.sqrt(),
    ]
}

/// `{1, cos, sin}` coefficients to half-angle powers `[x^0, x^1, x^2]` after multiplying by `1 + x^2`.
#[inline]
fn powers(c: [f64; 3]) -> [f64; 3] {
    [c[0] + c[1], 2.0 * c[2], c[0] - c[1]]
}

fn joint_exp(axis: &Axis, theta: f64) -> Transform {
    let rot = axis_angle(&axis.w, theta);
    Transform::new(rot, axis.r - rot * axis.r)
}

impl General6R {
    /// The solver of the chain `exp(xi_0 theta_0) ... exp(xi_5 theta_5) g(0)`, or None when no
    /// cut of the loop gives a well-posed elimination (the chain's geometry is then special
    /// enough for one of the closed forms of `analytic`, or its solution set is not finite).
    pub fn new(axes: [Axis; 6], home: Transform) -> Option<Self> {
        let scale = axes
            .iter()
            .map(|a| a.r.norm())
            .fold(home.trans.norm(), f64::max)
            .max(1e-3);
        let mut best: Option<(f64, Self)> = None;
        // the 12 x 12 formulations first; where every one is singular at every x_t (consecutive
        // axes that all meet or are parallel: JACO 2, Gen3 lite, CRX), the extended ones
        for extended in [false, true] {
            for cut in 0..6 {
                for v_first in [true, false] {
                    let Some(mut me) = Self::formulation(&axes, &home, scale, cut, v_first) else {
                        continue;
                    };
                    me.extended = extended;
                    for eig in 0..3 {
                        me.eig = eig;
                        let score = me.trial();
                        if score > 0.0 && best.as_ref().is_none_or(|b| score > b.0) {
                            best = Some((score, me.clone()));
                        }
                    }
                }
            }
            if best.is_some() {
                break;
            }
        }
        best.map(|b| b.1)
    }

    /// The sides of cut `k` with V = the two joints after it (`v_first`) or before it.
    fn formulation(axes: &[Axis; 6], home: &Transform, scale: f64, k: usize, v_first: bool) -> Option<Self> {
        // S = E_{k+1} .. E_5 G^-1 E_0 .. E_{k-1}; S = A B, B E_k = A^-1
        let (u, v) = if v_first {
            if k > 3 {
                return None;
            }
            // V = A^-1 = E_{k+2}^-1 E_{k+1}^-1, U = B = E_{k+3} .. E_5 G^-1 E_0 .. E_{k-1}
            let v = vec![Item::Joint(k + 2, -1.0), Item::Joint(k + 1, -1.0)];
            let mut u: Vec<Item> = (k + 3..6).map(|j| Item::Joint(j, 1.0)).collect();
            u.push(Item::Target(true));
            u.extend((0..k).map(|j| Item::Joint(j, 1.0)));
            (u, v)
        } else {
            if k < 2 {
                return None;
            }
            // V = B = E_{k-2} E_{k-1}, U = A^-1 = E_{k-3}^-1 .. E_0^-1 G E_5^-1 .. E_{k+1}^-1
            let v = vec![Item::Joint(k - 2, 1.0), Item::Joint(k - 1, 1.0)];
            let mut u: Vec<Item> = (0..k - 2).rev().map(|j| Item::Joint(j, -1.0)).collect();
            u.push(Item::Target(false));
            u.extend((k + 1..6).rev().map(|j| Item::Joint(j, -1.0)));
            (u, v)
        };
        let joints = |side: &[Item]| -> Vec<usize> {
            side.iter()
                .filter_map(|i| match i {
                    Item::Joint(j, _) => Some(*j),
                    Item::Target(_) => None,
                })
                .collect()
        };
        let (uj, vj) = (joints(&u), joints(&v));
        let mut me = Self {
            axes: *axes,
            home: *home,
            scale,
            cut: k,
            u,
            uj: [uj[0], uj[1], uj[2]],
            vj: [vj[0], vj[1]],
            v,
            eig: 0,
            full_rank: true,
            extended: false,
            mix: [[0.0; ROWS]; SIDE],
            grid: [[Transform::identity(); 3]; 6],
            null: SMatrix::zeros(),
            qy_pinv: SMatrix::zeros(),
            h0: [0.0; 14],
        };
        // the V side's coefficients H (14 x 9) from its 3 x 3 samples
        let mut samples = [[[0.0; 3]; 3]; 14];
        for m0 in 0..3 {
            for m1 in 0..3 {
                let mut th = [0.0; 6];
                th[me.vj[0]] = 2.0 * PI * m0 as f64 / 3.0;
                th[me.vj[1]] = 2.0 * PI * m1 as f64 / 3.0;
                let e = me.side(&me.v, &th, &Transform::identity());
                for q in 0..14 {
                    samples[q][m0][m1] = e[q];
                }
            }
        }
        let mut qy = SMatrix::<f64, 14, 8>::zeros();
        for q in 0..14 {
            let mut c = [[0.0; 3]; 3];
            for m0 in 0..3 {
                let f = fourier(samples[q][m0][0], samples[q][m0][1], samples[q][m0][2]);
                for b in 0..3 {
                    c[m0][b] = f[b];
                }
            }
            let mut h = [[0.0; 3]; 3];
            for b in 0..3 {
                let f = fourier(c[0][b], c[1][b], c[2][b]);
                for a in 0..3 {
                    h[a][b] = f[a];
                }
            }
            me.h0[q] = h[0][0];
            for idx in 1..9 {
                qy[(q, idx - 1)] = h[idx / 3][idx % 3];
            }
        }
        let svd = qy.svd(true, true);
        let smax = svd.singular_values.max();
        if smax.is_nan() || smax <= 0.0 {
            return None;
        }
        // Q_Y of full rank (axes of the V pair skew): y, hence the V joints, by least squares;
        // else (they meet or are parallel) more than 6 equations are free of V: 6 fixed generic
        // combinations of them, and the V joints by subproblems
        me.full_rank = svd.singular_values.min() > 1e-7 * smax;
        me.qy_pinv = svd.pseudo_inverse(1e-7 * smax).ok()?;
        // left null space: eigenvectors of I - Q_Y Q_Y^+ with eigenvalue 1
        let proj = SMatrix::<f64, 14, 14>::identity() - qy * me.qy_pinv;
        let eig = proj.symmetric_eigen();
        let mut order: Vec<usize> = (0..14).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let dim = order.iter().filter(|&&c| eig.eigenvalues[c] > 0.5).count();
        let mut rng = crate::rng::Rng::new(0xbb67_ae85_84ca_a73b);
        for row in 0..6 {
            for (i, &c) in order[..dim].iter().enumerate() {
                let weight = if dim == 6 {
                    f64::from(u8::from(i == row))
                } else {
                    rng.uniform(-1.0, 1.0)
                };
                for q in 0..14 {
                    me.null[(row, q)] += weight * eig.eigenvectors[(q, c)];
                }
            }
        }
        for item in &me.u {
            if let Item::Joint(j, sign) = *item {
                for m in 0..3 {
                    let th = SHIFT[j] + 2.0 * PI * m as f64 / 3.0;
                    me.grid[j][m] = joint_exp(&axes[j], sign * th);
                }
            }
        }
        let mut rng = crate::rng::Rng::new(0x3c6e_f372_fe94_f82b);
        for row in me.mix.iter_mut() {
            for x in row.iter_mut() {
                *x = rng.uniform(-1.0, 1.0);
            }
        }
        Some(me)
    }

    /// A side's product applied to the cut axis (point and direction), as the 14 equations
    /// (lengths from the cut point, divided by `scale`).
    fn side(&self, items: &[Item], theta: &[f64; 6], g: &Transform) -> Eqs {
        let a = &self.axes[self.cut];
        let (mut p, mut l) = (a.r, a.w);
        for item in items.iter().rev() {
            let t = match *item {
                Item::Joint(j, sign) => joint_exp(&self.axes[j], sign * theta[j]),
                Item::Target(false) => *g,
                Item::Target(true) => g.inverse(),
            };
            p = t.act_point(&p);
            l = t.rot * l;
        }
        equations(&((p - a.r) / self.scale), &l)
    }

    /// Score of this formulation on targets of known solutions: 0 if one is missed or two roots
    /// meet, else the smallest relative gap to singularity of the leading matrix met.
    fn trial(&self) -> f64 {
        let mut rng = crate::rng::Rng::new(0x6a09_e667_f3bc_c908 ^ (self.cut * 7 + self.eig) as u64);
        let mut out = Vec::with_capacity(16);
        let mut worst = f64::INFINITY;
        for _ in 0..3 {
            let mut q = [0.0; 6];
            for x in q.iter_mut() {
                *x = rng.uniform(-PI, PI);
            }
            let target = self.forward(&q);
            let (stats, lead) = self.solve_with(&target, &mut out);
            // two roots together at a random target: the eigen joint's angle is shared by pairs
            // of solutions (a wrist's flip), its null space is two-dimensional there and the
            // other joints cannot be read from it
            if stats.candidates == 0 || stats.near_double || !out.iter().any(|s| same_angles(s, &q, 1e-6)) {
                return 0.0;
            }
            worst = worst.min(lead);
        }
        worst
    }

    /// `exp(xi_0 theta_0) ... exp(xi_5 theta_5) g(0)`.
    pub fn forward(&self, theta: &[f64; 6]) -> Transform {
        let mut t = Transform::identity();
        for (a, &x) in self.axes.iter().zip(theta) {
            t = t * joint_exp(a, x);
        }
        t * self.home
    }

    /// Name of the chosen formulation (cut joint, V pair, eigen joint; 0-based), for reports.
    pub fn formulation_name(&self) -> String {
        format!(
            "cut {} | V {:?} | U {:?} | eigen joint {}",
            self.cut, self.vj, self.uj, self.uj[self.eig]
        )
    }

    /// Every real solution `theta` for the pose `target` of the tool, appended to `out` (cleared
    /// first), each refined and checked by forward kinematics to `1e-9 * scale`.
    pub fn solve(&self, target: &Transform, out: &mut Vec<[f64; 6]>) -> General6RStats {
        self.solve_with(target, out).0
    }

    fn solve_with(&self, target: &Transform, out: &mut Vec<[f64; 6]>) -> (General6RStats, f64) {
        out.clear();
        let mut stats = General6RStats::default();
        let g = *target * self.home.inverse();
        let d = self.reduced_equations(&g);
        // M(x_t) = sum_p M_p x_t^p on monomials x_a^i x_b^j (column nb i + j): rows d and x_a d
        // (Manocha & Canny), and in the extended formulation also x_b d and x_a x_b d
        let (t, a, b) = match self.eig {
            0 => (0, 1, 2),
            1 => (1, 0, 2),
            _ => (2, 0, 1),
        };
        let (nb, shifts): (usize, &[(usize, usize)]) = if self.extended {
            (4, &[(0, 0), (1, 0), (0, 1), (1, 1)])
        } else {
            (3, &[(0, 0), (1, 0)])
        };
        let rows = 6 * shifts.len();
        let mut m = [[[0.0; SIDE]; ROWS]; 3];
        for i in 0..6 {
            for pw in 0..27 {
                let (pt, pa, pb) = (pw / 9, (pw / 3) % 3, pw % 3);
                let mut idx = [0usize; 3];
                idx[t] = pt;
                idx[a] = pa;
                idx[b] = pb;
                let c = d[i][idx[0]][idx[1]][idx[2]];
                for (s, &(sa, sb)) in shifts.iter().enumerate() {
                    m[pt][6 * s + i][nb * (pa + sa) + pb + sb] = c;
                }
            }
        }
        // monomials absent from every equation (axes that meet or are parallel) are dropped; a
        // system that is then not square is squared by fixed generic combinations of its rows
        // (a random projection: it keeps every root, adds spurious ones that the residual of the
        // full system rejects; Hochstenbach, Mehl & Plestenjak, "Solving singular generalized
        // eigenvalue problems. Part II: projection and augmentation", SIMAX 44(4), 2023)
        let cols = 4 * nb;
        let big = m
            .iter()
            .flatten()
            .flat_map(|r| r[..cols].iter())
            .fold(0.0f64, |s, x| s.max(x.abs()));
        let mut present = [0usize; SIDE];
        let mut n = 0;
        for c in 0..cols {
            if m.iter().any(|mp| mp[..rows].iter().any(|r| r[c].abs() > 1e-12 * big)) {
                present[n] = c;
                n += 1;
            }
        }
        let mixed = n != rows;
        let mut sq = [[[0.0; SIDE]; SIDE]; 3];
        for p in 0..3 {
            for i in 0..n {
                for (j, &c) in present[..n].iter().enumerate() {
                    sq[p][i][j] = if mixed {
                        (0..rows).map(|r| self.mix[i][r] * m[p][r][c]).sum()
                    } else {
                        m[p][i][c]
                    };
                }
            }
        }
        // x = eigenvalue of [0 I; -S2^-1 S0, -S2^-1 S1]; if S2 is nearly singular (roots near
        // x = inf), 1/x = eigenvalue of [0 I; -S0^-1 S2, -S0^-1 S1] (the infinite roots become 0)
        let mut blocks = [[0.0; 2 * SIDE]; SIDE];
        let mut other = [[0.0; 2 * SIDE]; SIDE];
        let lead2 = solve_blocks(&sq[2], &sq[0], &sq[1], n, &mut blocks).unwrap_or(0.0);
        // (the reversed form only where S2 is far from regular: one elimination less per call)
        let lead0 = if lead2 < 1e-3 {
            solve_blocks(&sq[0], &sq[2], &sq[1], n, &mut other).unwrap_or(0.0)
        } else {
            0.0
        };
        let reversed = lead0 > 100.0 * lead2;
        let lead = if reversed { lead0 } else { lead2 };
        if reversed {
            blocks = other;
        }
        if n == 0 || lead <= 1e-13 {
            return (stats, 0.0);
        }
        let mut c = Square::zeros(2 * n);
        for i in 0..n {
            c.a[i][n + i] = 1.0;
            for j in 0..2 * n {
                c.a[n + i][j] = -blocks[i][j];
            }
        }
        let mut roots = Vec::with_capacity(2 * SIDE);
        if c.eigenvalues(&mut roots).is_none() {
            return (stats, 0.0);
        }
        let mut xs: Vec<f64> = roots
            .iter()
            .filter(|z| z.1.abs() <= 1e-4 * (1.0 + z.0.abs()))
            .map(|z| z.0)
            .filter_map(|x| match reversed {
                false => Some(x),
                true => (x.abs() > 1e-12).then(|| 1.0 / x),
            })
            .collect();
        xs.sort_by(f64::total_cmp);
        for w in xs.windows(2) {
            if (w[1] - w[0]).abs() < 1e-6 * (1.0 + w[0].abs()) {
                stats.near_double = true;
            }
        }
        stats.candidates = xs.len();
        let has = |c: usize| present[..n].contains(&c);
        for &x in &xs {
            let mut mx = [[0.0; SIDE]; SIDE];
            for i in 0..n {
                for j in 0..n {
                    mx[i][j] = (sq[2][i][j] * x + sq[1][i][j]) * x + sq[0][i][j];
                }
            }
            let z = null_vector(&mx, n);
            let mut u = [0.0; SIDE];
            for (j, &c) in present[..n].iter().enumerate() {
                u[c] = z[j];
            }
            if mixed {
                // a root of the projection only: the full system is not singular there
                let (mut res, mut size) = (0.0f64, 0.0f64);
                for r in 0..rows {
                    let (mut dot, mut row) = (0.0, 0.0);
                    for &c in &present[..n] {
                        let e = (m[2][r][c] * x + m[1][r][c]) * x + m[0][r][c];
                        dot += e * u[c];
                        row += e * e;
                    }
                    res = res.max(dot.abs());
                    size = size.max(row.sqrt());
                }
                if res > 1e-6 * size {
                    continue;
                }
            }
            let mut th = [0.0; 6];
            th[self.uj[t]] = SHIFT[self.uj[t]] + 2.0 * x.atan();
            // x_a from consecutive powers of x_a (i, i + 1), x_b from (j, j + 1)
            let (mut lo_a, mut hi_a, mut cr_a, mut lo_b, mut hi_b, mut cr_b) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for i in 0..4 {
                for j in 0..nb {
                    let e = u[nb * i + j];
                    if i < 3 && has(nb * i + j) && has(nb * (i + 1) + j) {
                        let h = u[nb * (i + 1) + j];
                        (lo_a, hi_a, cr_a) = (lo_a + e * e, hi_a + h * h, cr_a + e * h);
                    }
                    if j + 1 < nb && has(nb * i + j) && has(nb * i + j + 1) {
                        let h = u[nb * i + j + 1];
                        (lo_b, hi_b, cr_b) = (lo_b + e * e, hi_b + h * h, cr_b + e * h);
                    }
                }
            }
            let half = |lo: f64, hi: f64, cr: f64| if lo >= hi { cr.atan2(lo) } else { hi.atan2(cr) };
            th[self.uj[a]] = SHIFT[self.uj[a]] + 2.0 * half(lo_a, hi_a, cr_a);
            th[self.uj[b]] = SHIFT[self.uj[b]] + 2.0 * half(lo_b, hi_b, cr_b);
            self.back_substitute(&mut th, &g);
            if let Some((theta, residual)) = self.refine(th, target) {
                if !out.iter().any(|s| same_angles(s, &theta, 1e-7)) {
                    stats.worst_residual = stats.worst_residual.max(residual);
                    out.push(theta);
                }
            }
        }
        (stats, lead)
    }
}

#[path = "general6r_back.rs"]
mod back;
pub use back::same_angles;
use back::{null_vector, solve_blocks, SIDE};
#[path = "general6r_eig.rs"]
mod eig;
use eig::Square;

#[cfg(test)]
#[path = "general6r_tests.rs"]
mod tests;
