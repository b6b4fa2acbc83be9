//! Seven-joint arms: every closed-form branch for a given value of a redundancy parameter.
//!
//! **A held joint.** With joint k held at `theta_k = v`, moving `e_k(v)` past the joints after it
//! (`e_k(v) e_j(x) = exp((Ad_{e_k(v)} xi_j)^ x) e_k(v)`, Murray, Li & Sastry 1994, §2.4) leaves a
//! six-joint chain
//!
//! ```text
//! g_d = e_1 ... e_{k-1} e'_{k+1} ... e'_7 (e_k(v) g(0)),     xi'_j = Ad_{e_k(v)} xi_j  (j > k)
//! ```
//!
//! which [`ChainIk`] solves when its axes have a structure (from either end). Which joint is held
//! is the caller's choice; the Panda's last joint leaves a spherical shoulder (solved reversed),
//! an SRS arm's third joint a spherical wrist.
//!
//! **The arm angle of an SRS arm** (axes 1-3 meet at the shoulder S, axes 5-7 at the wrist W,
//! axis 4 the elbow; the KUKA iiwa). Derived here in the spirit of Kreutz-Delgado, Long & Seraji,
//! "Kinematic analysis of 7-DOF manipulators", IJRR 11(5), 1992, and Shimizu et al., "Analytical
//! inverse kinematic computation for 7-DOF redundant manipulators with joint limits and its
//! application to redundancy resolution", IEEE T-RO 24(5), 2008 (their reference plane is the
//! elbow's at theta_3 = 0; here it is a fixed one, defined below, so that psi is defined for
//! every target):
//!
//! 1. Joints 5-7 fix W, so `W_d = G W_0` with `G = g_d g(0)^-1`; joints 1-3 keep distances to S,
//!    so `theta_4` solves `|e_4(theta_4) W_0 - S| = |W_d - S|` (subproblem 3, <= 2 roots).
//! 2. The elbow point E_0 (the point of axis 4 nearest S) moves with joints 1-3 only and keeps
//!    its distances to S and to the wrist: in the triangle S E W its foot on the S-W line is
//!    `c = (E_0 - S).(p_4 - S) / d` from S and its distance to that line `rho`, with
//!    `p_4 = e_4(theta_4) W_0`, `d = |W_d - S|`. The elbow circle is
//!    `E(psi) = S + c u + rho (cos psi n_1 + sin psi n_2)`, `u = (W_d - S) / d`,
//!    `n_1` the unit part of the first joint's axis `z_1` normal to `u` (psi = 0: the elbow on the
//!    side of `z_1`, "up" for a vertical first axis), `n_2 = u x n_1`. `psi` is the **arm angle**.
//! 3. The shoulder's rotation `R = R_1 R_2 R_3` about S takes the triad of `(p_4 - S, E_0 - S)`
//!    to that of `(W_d - S, E(psi) - S)`: `R = F_d F_0^T`, F the orthonormal frames built from
//!    each pair. `R` is split into three angles by subproblem 2 (axes 1, 2, a point on axis 3;
//!    <= 2 roots) and subproblem 1 (axis 3).
//! 4. The wrist: `e_5 e_6 e_7 = (e_1 ... e_4)^-1 G`, subproblems 2 and 1 (<= 2 roots).
//!
//! Up to 2 x 2 x 2 = 8 branches for each psi, numbered `4 elbow + 2 shoulder + wrist` by the
//! order of the subproblems' roots (`+` root first), so that a branch's number is kept as psi
//! moves (the roots are continuous in psi away from the points where two of them meet).
//!
//! | symbol  | here              | meaning                                     |
//! |---------|-------------------|---------------------------------------------|
//! | `S`,`W` | `shoulder`,`wrist`| centres of the spherical shoulder and wrist |
//! | `E_0`   | `elbow`           | the point of axis 4 nearest S, at theta = 0 |
//! | `psi`   | `psi`             | arm angle (rad)                             |

use super::analytic::{Met, Screw, Solutions};
use super::chain::ChainIk;
use super::subproblems::{sp1, sp2, sp3, Axis};
use crate::spatial::{Mat3, Transform, Vec3};

/// Relative tolerance of the geometric tests (as `analytic`'s).
const GEOMETRY_TOL: f64 = 1e-9;

/// The most real solutions of an SRS arm for one target and one arm angle.
pub const SRS_MAX_SOLUTIONS: usize = 8;

/// The spherical shoulder and wrist of an SRS arm, at theta = 0.
#[derive(Clone, Copy, Debug)]
pub struct Srs {
    pub shoulder: Vec3,
    pub wrist: Vec3,
    pub elbow: Vec3,
}

/// A seven-joint chain (screws at theta = 0 and the tool's home pose).
#[derive(Clone, Debug)]
pub struct Redundant {
    pub screws: Vec<Screw>,
    pub home: Transform,
    /// Present when axes 1-3 and 5-7 meet in two points (the arm angle applies).
    pub srs: Option<Srs>,
}

/// A target's elbow circle (steps 1-2 of the module header): the shoulder's rotation
/// `R(psi) = F_d(psi) F_0^T` for each elbow root, with `F_d(psi)` the triad of `(u, cos psi n_1 +
/// sin psi n_2)`, so that every entry of `R(psi)` is `a sin psi + b cos psi + c`.
#[derive(Clone, Copy, Debug)]
pub(super) struct ArmCircle {
    /// `g_d g(0)^-1`
    pub g: Transform,
    pub u: Vec3,
    pub n1: Vec3,
    pub n2: Vec3,
    /// Per elbow root: (theta_4, F_0).
    pub elbows: [Option<(f64, Mat3)>; 2],
    /// psi undefined (see `solve_arm_angle`), or the two elbow roots merged.
    pub met: Met,
}

impl ArmCircle {
    /// The shoulder rotation `R_1 R_2 R_3` of elbow root `ie` at arm angle `psi`.
    pub fn rotation(&self, ie: usize, psi: f64) -> Option<Mat3> {
        let (_, f0) = self.elbows[ie]?;
        let (sp, cp) = psi.sin_cos();
        // the unit part of E(psi) - S normal to u is cos psi n_1 + sin psi n_2 exactly
        let y = self.n1 * cp + self.n2 * sp;
        Some(Mat3::from_columns(&[self.u, y, self.u.cross(&y)]) * f0.transpose())
    }
}

fn axis_of(s: &Screw) -> Option<Axis> {
    match s {
        Screw::Revolute(a) => Some(*a),
        Screw::Prismatic(_) => None,
    }
}

/// The point where three axes meet, if they do (within `tol`), the first two not parallel.
fn common_point(a: &Axis, b: &Axis, c: &Axis, tol: f64) -> Option<Vec3> {
    let n = a.w.cross(&b.w);
    let nn = n.norm_squared();
    if nn <= GEOMETRY_TOL * GEOMETRY_TOL || b.w.cross(&c.w).norm() <= GEOMETRY_TOL {
        return None;
    }
    let d = b.r - a.r;
    if d.dot(&n).abs() / nn.sqrt() > tol {
        return None;
    }
    let p = a.r + a.w * (d.cross(&b.w).dot(&n) / nn);
    let off = p - c.r;
    ((off - c.w * c.w.dot(&off)).norm() <= tol).then_some(p)
}

/// The point of axis `a` nearest `p`.
fn foot(a: &Axis, p: &Vec3) -> Vec3 {
    a.r + a.w * a.w.dot(&(p - a.r))
}

/// A unit vector normal to `w`.
fn normal_to(w: &Vec3) -> Vec3 {
    let e = if w.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    (e - w * w.dot(&e)).normalize()
}

/// The rotation whose columns are `x`, the unit part of `y` normal to `x`, and their cross
/// product; None when `y` is (nearly) along `x`.
fn triad(x: &Vec3, y: &Vec3) -> Option<Mat3> {
    let x = x.normalize();
    let yp = y - x * x.dot(y);
    if yp.norm() <= 1e-9 * y.norm().max(1e-300) {
        return None;
    }
    let y = yp.normalize();
    Some(Mat3::from_columns(&[x, y, x.cross(&y)]))
}

impl Redundant {
    /// A seven-joint chain; `srs` is detected from its axes.
    pub fn new(screws: Vec<Screw>, home: Transform) -> Option<Self> {
        if screws.len() != 7 {
            return None;
        }
        let size = screws
            .iter()
            .filter_map(|s| axis_of(s).map(|a| a.r.norm()))
            .fold(home.trans.norm(), f64::max)
            .max(1.0);
        let tol = GEOMETRY_TOL * size;
        let ax: Option<Vec<Axis>> = screws.iter().map(axis_of).collect();
        let srs = ax.and_then(|ax| {
            let s = common_point(&ax[0], &ax[1], &ax[2], tol)?;
            let w = common_point(&ax[4], &ax[5], &ax[6], tol)?;
            let e = foot(&ax[3], &s);
            // the elbow must bend: axis 4 off both centres
            let off = |p: &Vec3| (p - foot(&ax[3], p)).norm() > tol;
            (off(&s) && off(&w) && (w - e).norm() > tol && (e - s).norm() > tol).then_some(Srs {
                shoulder: s,
                wrist: w,
                elbow: e,
            })
        });
        Some(Self { screws, home, srs })
    }

    /// Axis `i` of an SRS arm (revolute by construction of `srs`).
    pub(super) fn axis(&self, i: usize) -> Axis {
        axis_of(&self.screws[i]).expect("SRS axes are revolute")
    }

    /// The six-joint chain left with joint `k` held at `theta_k` (see the module header), and
    /// its solver if its axes have a structure.
    pub fn held(&self, k: usize, theta_k: f64) -> Option<ChainIk> {
        let e = self.screws[k].exp(theta_k);
        let moved = |s: &Screw| match s {
            Screw::Revolute(a) => Screw::Revolute(Axis {
                w: e.rot * a.w,
                r: e.act_point(&a.r),
            }),
            Screw::Prismatic(v) => Screw::Prismatic(e.rot * v),
        };
        let screws: Vec<Screw> = (0..7)
            .filter(|&j| j != k)
            .map(|j| if j > k { moved(&self.screws[j]) } else { self.screws[j] })
            .collect();
        ChainIk::detect(screws, e * self.home)
    }

    /// Candidates (rows of 7 `theta`) with joint `k` held at `theta_k`: one row per branch of the
    /// six-joint solver, `theta_k` in slot k. Returns (what was met, the most solutions) or None
    /// when the held chain has no structure.
    pub fn solve_held(
        &self,
        target: &Transform,
        k: usize,
        theta_k: f64,
        reference: &[f64],
        out: &mut Vec<[f64; 7]>,
    ) -> Option<(Met, usize)> {
        out.clear();
        let chain = self.held(k, theta_k)?;
        let reduced: Vec<f64> = (0..7).filter(|&j| j != k).map(|j| reference[j]).collect();
        let mut rows: Solutions = Vec::with_capacity(8);
        let met = chain.solve(target, false, &reduced, &mut rows);
        for r in &rows {
            let mut row = [0.0; 7];
            let mut at = 0;
            for (j, slot) in row.iter_mut().enumerate() {
                if j == k {
                    *slot = theta_k;
                } else {
                    *slot = r[at];
                    at += 1;
                }
            }
            out.push(row);
        }
        Some((met, chain.max_solutions()))
    }

    /// Steps 1-2 of the module header for `target`: the elbow angles and, for each, the frames
    /// that give the shoulder rotation at any arm angle (`ArmCircle::rotation`); None when the
    /// chain is not SRS.
    pub(super) fn arm_circle(&self, target: &Transform) -> Option<ArmCircle> {
        let srs = self.srs?;
        let ax = |i: usize| axis_of(&self.screws[i]).expect("SRS axes are revolute");
        let g = target * &self.home.inverse();
        let s = srs.shoulder;
        let wd = g.act_point(&srs.wrist);
        let d = (wd - s).norm();
        let mut met = Met::default();
        // 1. the elbow angle keeps |W - S|
        let t4 = sp3(&ax(3), &srs.wrist, &s, d);
        met |= Met::of(&t4);
        let u = (wd - s) / d.max(1e-300);
        let z1 = ax(0).w;
        let mut n1 = z1 - u * u.dot(&z1);
        if n1.norm() <= 1e-9 {
            // the wrist on the first axis: psi is measured from the second axis instead
            met.singular = true;
            let z2 = ax(1).w;
            n1 = z2 - u * u.dot(&z2);
        }
        let n1 = n1.normalize();
        let n2 = u.cross(&n1);
        let mut elbows = [None; 2];
        for (ie, &theta4) in t4.as_slice().iter().enumerate() {
            let p4 = self.screws[3].exp(theta4).act_point(&srs.wrist);
            let (v, e0) = (p4 - s, srs.elbow - s);
            // 2. the elbow on its circle about the S-W line: foot c, radius rho (> 0 for psi to act)
            let c = e0.dot(&v) / d.max(1e-300);
            let rho2 = e0.norm_squared() - c * c;
            if rho2 <= 1e-12 * e0.norm_squared().max(1e-300) {
                met.singular = true; // elbow on the S-W line: every psi is the same posture
            }
            match triad(&v, &e0) {
                Some(f0) => elbows[ie] = Some((theta4, f0)),
                None => met.singular = true,
            }
        }
        Some(ArmCircle {
            g,
            u,
            n1,
            n2,
            elbows,
            met,
        })
    }

    /// The SRS branches at arm angle `psi`: `out[b]` is branch b (`4 elbow + 2 shoulder + wrist`)
    /// or None where that root does not exist. Returns what was met (singular: psi undefined, the
    /// arm stretched or folded so that the elbow is on the shoulder-wrist line, or a free joint;
    /// merged: a double root), or None when the chain is not SRS.
    pub fn solve_arm_angle(
        &self,
        target: &Transform,
        psi: f64,
        reference: &[f64],
        out: &mut [Option<[f64; 7]>; SRS_MAX_SOLUTIONS],
    ) -> Option<Met> {
        let circle = self.arm_circle(target)?;
        let _ = reference; // branches are numbered, not ordered by the reference
        Some(self.branches_at(&circle, psi, out))
    }

    /// Steps 3-4 of the module header at arm angle `psi` (see `solve_arm_angle`): what was met.
    pub(super) fn branches_at(
        &self,
        circle: &ArmCircle,
        psi: f64,
        out: &mut [Option<[f64; 7]>; SRS_MAX_SOLUTIONS],
    ) -> Met {
        out.fill(None);
        let Some(srs) = self.srs else {
            return Met {
                singular: true,
                merged: false,
            };
        };
        let ax = |i: usize| axis_of(&self.screws[i]).expect("SRS axes are revolute");
        let s = srs.shoulder;
        let mut met = circle.met;
        let (a0, a1, a2) = (Axis { r: s, ..ax(0) }, Axis { r: s, ..ax(1) }, Axis { r: s, ..ax(2) });
        let w = srs.wrist;
        let (a4, a5, a6) = (Axis { r: w, ..ax(4) }, Axis { r: w, ..ax(5) }, Axis { r: w, ..ax(6) });
        for (ie, elbow) in circle.elbows.iter().enumerate() {
            let (Some(&(theta4, ..)), Some(r)) = (elbow.as_ref(), circle.rotation(ie, psi)) else {
                continue;
            };
            // 3. the shoulder rotation, split into three angles
            let p = s + a2.w;
            let q = s + r * a2.w;
            let (pairs, m, sing) = sp2(&a0, &a1, &p, &q);
            met.singular |= sing;
            met.merged |= m == 1;
            let x = normal_to(&a2.w);
            for (is, &(t1, t2)) in pairs[..m].iter().enumerate() {
                let e12 = self.screws[0].exp(t1) * self.screws[1].exp(t2);
                let t3 = sp1(&a2, &(s + x), &(s + e12.rot.transpose() * (r * x)));
                met.singular |= t3.singular;
                let t3 = t3.values[0];
                // 4. the wrist
                let front = e12 * self.screws[2].exp(t3) * self.screws[3].exp(theta4);
                let h = front.inverse() * circle.g;
                let pw = w + a6.w;
                let (wp, wm, ws) = sp2(&a4, &a5, &pw, &h.act_point(&pw));
                met.singular |= ws;
                met.merged |= wm == 1;
                let xw = w + normal_to(&a6.w);
                for (iw, &(t5, t6)) in wp[..wm].iter().enumerate() {
                    let e56 = self.screws[4].exp(t5) * self.screws[5].exp(t6);
                    let t7 = sp1(&a6, &xw, &e56.inverse().act_point(&h.act_point(&xw)));
                    met.singular |= t7.singular;
                    out[4 * ie + 2 * is + iw] = Some([t1, t2, t3, theta4, t5, t6, t7.values[0]]);
                }
            }
        }
        met
    }

    /// The arm angle of the joint vector `theta` (SRS arms): the angle about the shoulder-wrist
    /// line from the reference plane to the elbow, as in `solve_arm_angle`; None for a stretched
    /// arm or a chain that is not SRS.
    pub fn arm_angle(&self, theta: &[f64]) -> Option<f64> {
        let srs = self.srs?;
        let mut t = Transform::identity();
        let mut points = [Vec3::zeros(); 2];
        for (i, s) in self.screws.iter().enumerate().take(4) {
            if i == 3 {
                points[0] = t.act_point(&srs.elbow);
            }
            t = t * s.exp(theta[i]);
        }
        points[1] = t.act_point(&srs.wrist);
        let s = srs.shoulder;
        let u = (points[1] - s).normalize();
        let z1 = axis_of(&self.screws[0])?.w;
        let mut n1 = z1 - u * u.dot(&z1);
        if n1.norm() <= 1e-9 {
            let z2 = axis_of(&self.screws[1])?.w;
            n1 = z2 - u * u.dot(&z2);
        }
        let n1 = n1.normalize();
        let n2 = u.cross(&n1);
        let e = points[0] - s;
        let ep = e - u * u.dot(&e);
        if ep.norm() <= 1e-12 {
            return None;
        }
        Some(ep.dot(&n2).atan2(ep.dot(&n1)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::axis_angle;

    use crate::ik::analytic::rev;

    fn fk(screws: &[Screw], home: &Transform, theta: &[f64]) -> Transform {
        let mut t = Transform::identity();
        for (s, &x) in screws.iter().zip(theta) {
            t = t * s.exp(x);
        }
        t * *home
    }

    /// An iiwa-like SRS arm (shoulder at 0.36 m, elbow 0.42 m above, wrist 0.4 m above that).
    fn srs_arm() -> Redundant {
        let screws = vec![
            rev([0.0, 0.0, 1.0], [0.0, 0.0, 0.36]),
            rev([0.0, 1.0, 0.0], [0.0, 0.0, 0.36]),
            rev([0.0, 0.0, 1.0], [0.0, 0.0, 0.36]),
            rev([0.0, -1.0, 0.0], [0.0, 0.0, 0.78]),
            rev([0.0, 0.0, 1.0], [0.0, 0.0, 1.18]),
            rev([0.0, 1.0, 0.0], [0.0, 0.0, 1.18]),
            rev([0.0, 0.0, 1.0], [0.0, 0.0, 1.18]),
        ];
        let home = Transform::new(axis_angle(&Vec3::x(), 0.4), Vec3::new(0.0, 0.0, 1.306));
        Redundant::new(screws, home).expect("7 joints")
    }

    fn same_pose(a: &Transform, b: &Transform) -> bool {
        (a.trans - b.trans).norm() < 1e-9 && (a.rot - b.rot).abs().max() < 1e-9
    }

    #[test]
    fn every_arm_angle_branch_reaches_the_target_at_its_arm_angle() {
        let arm = srs_arm();
        assert!(arm.srs.is_some());
        let theta = [0.4, 0.7, -0.5, 1.2, 0.3, -0.8, 0.6];
        let target = fk(&arm.screws, &arm.home, &theta);
        let psi0 = arm.arm_angle(&theta).expect("bent elbow");
        let mut out = [None; SRS_MAX_SOLUTIONS];
        for psi in [psi0, psi0 + 0.5, -2.0] {
            arm.solve_arm_angle(&target, psi, &[0.0; 7], &mut out).unwrap();
            let rows: Vec<_> = out.iter().flatten().collect();
            assert_eq!(rows.len(), 8, "eight branches at a generic target");
            for row in rows {
                assert!(same_pose(&fk(&arm.screws, &arm.home, row), &target));
                let back = arm.arm_angle(row).unwrap();
                let d = back - psi;
                assert!((d - 2.0 * std::f64::consts::PI * (d / (2.0 * std::f64::consts::PI)).round()).abs() < 1e-9);
            }
        }
        // the configuration the target came from is a branch at its own arm angle
        arm.solve_arm_angle(&target, psi0, &[0.0; 7], &mut out).unwrap();
        assert!(out
            .iter()
            .flatten()
            .any(|row| row.iter().zip(&theta).all(|(a, b)| (a - b).abs() < 1e-9)));
    }

    #[test]
    fn a_held_joint_keeps_its_value_and_reaches_the_target() {
        let arm = srs_arm();
        let theta = [0.4, 0.7, -0.5, 1.2, 0.3, -0.8, 0.6];
        let target = fk(&arm.screws, &arm.home, &theta);
        let mut out = Vec::new();
        for k in [0, 2, 6] {
            let (_, most) = arm
                .solve_held(&target, k, theta[k], &[0.0; 7], &mut out)
                .expect("structure");
            assert!(!out.is_empty() && out.len() <= most);
            for row in &out {
                assert_eq!(row[k], theta[k]);
                assert!(same_pose(&fk(&arm.screws, &arm.home, row), &target));
            }
        }
    }
}
