//! Closed-form inverse kinematics of serial chains whose *geometry* admits it.
//!
//! The chain is written as a product of exponentials (Murray, Li & Sastry 1994, §3.2, eq. 3.3):
//!
//! ```text
//! g(theta) = exp(xi_1^ theta_1) ... exp(xi_n^ theta_n) g(0),     theta_i = q_i + offset_i
//! ```
//!
//! where `xi_i` is joint i's axis at `theta = 0` (a `Screw`: unit direction `w` through the point `r`,
//! or a prismatic direction) and `g(0)` the tool pose there ("home"). The structure is detected
//! from these lines alone (parallel / intersecting axes), never from a robot's name, and each
//! structure but the last is reduced to the subproblems of [`super::subproblems`]; the last is
//! the eigenvalue elimination of [`super::general6r`] (tried only when no other structure fits):
//!
//! | structure          | condition on the axes                                   | solutions |
//! |--------------------|---------------------------------------------------------|-----------|
//! | `Planar2R`         | 2 revolute, parallel, distinct                          | <= 2      |
//! | `Planar3R`         | 3 revolute, parallel (pose target)                      | <= 2      |
//! | `ArmIntersecting`  | axes 1, 2 meet (joint 3 revolute or prismatic)          | <= 4      |
//! | `ArmParallel`      | axes 2 and 3 parallel, axis 1 not                       | <= 4      |
//! | `ArmPrismaticBase` | joint 1 prismatic, axes 2, 3 meet (`prismatic.rs`)      | <= 4      |
//! | `ArmCartesian`     | joints 1-3 prismatic, independent (`prismatic.rs`)      | 1         |
//! | `SphericalWrist`   | one of the arms above + axes 4, 5, 6 meet in one point  | <= 8      |
//! | `ThreeParallel`    | axes 2, 3, 4 parallel, axes 5 and 6 meet (UR family)    | <= 8      |
//! | `General6R`        | any other 6R chain with a finite solution set           | <= 16     |
//!
//! Arms (n = 3) and planar 2R chains solve position targets (the tool origin); the others full poses.
//! Every candidate is returned as joint coordinates `theta` (offsets included); the caller maps
//! them to `q`, checks them by forward kinematics and applies joint limits (`super::analytic_solutions`).

use super::general6r::General6R;
use super::subproblems::{rotate, rotate_point, sp1, sp1_dir, sp2, sp3, sp4, Angles, Axis};
use crate::joint::axis_angle;
use crate::spatial::{Mat3, Transform, Vec3};

/// What a closed form met besides its roots: a non-isolated solution set (`singular`: a free
/// joint was set from the reference), or two roots of a subproblem merged into one (`merged`: a
/// discriminant within tolerance of zero, where two branches of the chain meet).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Met {
    pub singular: bool,
    pub merged: bool,
}

impl Met {
    pub fn of(a: &Angles) -> Self {
        Self {
            singular: a.singular,
            merged: a.tangent,
        }
    }
}

impl std::ops::BitOrAssign for Met {
    fn bitor_assign(&mut self, other: Self) {
        self.singular |= other.singular;
        self.merged |= other.merged;
    }
}

/// A joint's motion at `theta = 0`, in base coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Screw {
    Revolute(Axis),
    /// Translation along the unit direction.
    Prismatic(Vec3),
}

/// A revolute screw along `w` (normalised) through the point `r`: the arms of the IK tests.
#[cfg(test)]
pub(crate) fn rev(w: [f64; 3], r: [f64; 3]) -> Screw {
    Screw::Revolute(Axis {
        w: Vec3::new(w[0], w[1], w[2]).normalize(),
        r: Vec3::new(r[0], r[1], r[2]),
    })
}

impl Screw {
    /// `exp(xi^ theta)` as a rigid transform: `[R, (I - R) r]` (revolute) or `[I, v theta]`.
    #[inline]
    pub fn exp(&self, theta: f64) -> Transform {
        match self {
            Screw::Revolute(a) => {
                let rot = axis_angle(&a.w, theta);
                Transform::new(rot, a.r - rot * a.r)
            }
            Screw::Prismatic(v) => Transform::new(Mat3::identity(), v * theta),
        }
    }
    fn axis(&self) -> Option<&Axis> {
        match self {
            Screw::Revolute(a) => Some(a),
            Screw::Prismatic(_) => None,
        }
    }
}

/// The structures of the module table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Structure {
    Planar2R,
    Planar3R,
    ArmIntersecting,
    ArmParallel,
    ArmPrismaticBase,
    ArmCartesian,
    SphericalWrist,
    ThreeParallel,
    General6R,
}

impl Structure {
    pub fn name(&self) -> &'static str {
        match self {
            Structure::Planar2R => "planar_2r",
            Structure::Planar3R => "planar_3r",
            Structure::ArmIntersecting => "arm_intersecting_shoulder",
            Structure::ArmParallel => "arm_parallel_elbow",
            Structure::ArmPrismaticBase => "arm_prismatic_base",
            Structure::ArmCartesian => "arm_cartesian",
            Structure::SphericalWrist => "spherical_wrist",
            Structure::ThreeParallel => "three_parallel",
            Structure::General6R => "general_6r",
        }
    }
    /// Whether the structure solves a position-only target (else it needs a full pose).
    pub fn solves_position(&self) -> bool {
        matches!(
            self,
            Structure::Planar2R
                | Structure::ArmIntersecting
                | Structure::ArmParallel
                | Structure::ArmPrismaticBase
                | Structure::ArmCartesian
        )
    }
}

/// A detected closed-form solver for one chain.
#[derive(Clone, Debug)]
pub struct AnalyticIk {
    pub structure: Structure,
    /// The arm (joints 1-3) of a `SphericalWrist` chain.
    pub arm: Option<Structure>,
    pub screws: Vec<Screw>,
    /// `g(0)`: the tool pose at theta = 0.
    pub home: Transform,
    /// The eigenvalue solver of a `General6R` chain.
    pub general: Option<Box<General6R>>,
    /// Intersection of axes 1 and 2 (intersecting-shoulder arms).
    pub(super) shoulder: Vec3,
    /// Wrist centre (axes 4, 5, 6 meet) or the point where axes 5 and 6 meet (three parallel).
    wrist: Vec3,
}

/// Relative tolerance of the geometric tests (lengths scaled by the chain's size).
const GEOMETRY_TOL: f64 = 1e-9;

fn parallel(a: &Vec3, b: &Vec3) -> bool {
    a.cross(b).norm() <= GEOMETRY_TOL
}

/// Distance from point `p` to the line of `a`.
pub(super) fn distance_to_line(a: &Axis, p: &Vec3) -> f64 {
    let d = p - a.r;
    (d - a.w * a.w.dot(&d)).norm()
}

/// The point where two non-parallel lines meet, if they do (within `tol`).
pub(super) fn intersection(a: &Axis, b: &Axis, tol: f64) -> Option<Vec3> {
    let n = a.w.cross(&b.w);
    let nn = n.norm_squared();
    if nn <= GEOMETRY_TOL * GEOMETRY_TOL {
        return None;
    }
    let d = b.r - a.r;
    if (d.dot(&n)).abs() / nn.sqrt() > tol {
        return None;
    }
    // a.r + s a.w = b.r + t b.w  =>  s = ((b.r - a.r) x b.w) . n / |n|^2
    let s = d.cross(&b.w).dot(&n) / nn;
    Some(a.r + a.w * s)
}

/// A unit vector normal to `w`.
fn normal_to(w: &Vec3) -> Vec3 {
    let e = if w.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    (e - w * w.dot(&e)).normalize()
}

/// Appends to `out` (one row of `theta` per solution, 6 slots of which the chain uses n).
pub type Solutions = Vec<[f64; 6]>;

impl AnalyticIk {
    /// Detect a closed-form structure from the axes at theta = 0 and the home pose.
    pub fn detect(screws: Vec<Screw>, home: Transform) -> Option<Self> {
        let n = screws.len();
        let size = screws
            .iter()
            .filter_map(|s| s.axis().map(|a| a.r.norm()))
            .fold(home.trans.norm(), f64::max)
            .max(1.0);
        let tol = GEOMETRY_TOL * size;
        let rev = |i: usize| screws.get(i).and_then(|s| s.axis()).copied();
        let mut me = Self {
            structure: Structure::Planar2R,
            arm: None,
            screws: screws.clone(),
            home,
            general: None,
            shoulder: Vec3::zeros(),
            wrist: Vec3::zeros(),
        };
        // an arm on joints 0..3 moving the point p0
        let arm = |p0: &Vec3| -> Option<(Structure, Vec3)> {
            if let Some(found) = super::prismatic::detect_arm(&screws, p0, tol) {
                return Some(found);
            }
            let (a0, a1) = (rev(0)?, rev(1)?);
            if let Some(c) = intersection(&a0, &a1, tol) {
                let ok = match screws[2] {
                    Screw::Revolute(a2) => distance_to_line(&a2, p0) > tol && distance_to_line(&a2, &c) > tol,
                    Screw::Prismatic(_) => true, // |p0 + t v - c| always varies with t
                };
                if ok {
                    return Some((Structure::ArmIntersecting, c));
                }
            }
            let a2 = rev(2)?;
            if parallel(&a1.w, &a2.w)
                && !parallel(&a0.w, &a1.w)
                && distance_to_line(&a1, &a2.r) > tol
                && distance_to_line(&a2, p0) > tol
            {
                return Some((Structure::ArmParallel, Vec3::zeros()));
            }
            None
        };
        match n {
            2 => {
                let (a0, a1) = (rev(0)?, rev(1)?);
                if parallel(&a0.w, &a1.w)
                    && distance_to_line(&a0, &a1.r) > tol
                    && distance_to_line(&a1, &home.trans) > tol
                {
                    me.structure = Structure::Planar2R;
                    return Some(me);
                }
                None
            }
            3 => {
                let (a0, a1, a2) = (rev(0), rev(1), rev(2));
                if let (Some(a0), Some(a1), Some(a2)) = (a0, a1, a2) {
                    if parallel(&a0.w, &a1.w) && parallel(&a1.w, &a2.w) {
                        if distance_to_line(&a0, &a1.r) > tol && distance_to_line(&a1, &a2.r) > tol {
                            me.structure = Structure::Planar3R;
                            return Some(me);
                        }
                        return None;
                    }
                }
                let (s, c) = arm(&home.trans)?;
                me.structure = s;
                me.shoulder = c;
                Some(me)
            }
            6 => {
                let (a3, a4, a5) = (rev(3)?, rev(4)?, rev(5)?);
                // spherical wrist: axes 4, 5, 6 through one point
                if let Some(w) = intersection(&a3, &a4, tol) {
                    if distance_to_line(&a5, &w) <= tol && !parallel(&a4.w, &a5.w) {
                        if let Some((s, c)) = arm(&w) {
                            me.structure = Structure::SphericalWrist;
                            me.arm = Some(s);
                            me.shoulder = c;
                            me.wrist = w;
                            return Some(me);
                        }
                    }
                }
                // three parallel axes 2, 3, 4; axes 5 and 6 meet
                let (a0, a1, a2) = (rev(0)?, rev(1)?, rev(2)?);
                if parallel(&a1.w, &a2.w)
                    && parallel(&a2.w, &a3.w)
                    && !parallel(&a0.w, &a1.w)
                    && !parallel(&a4.w, &a1.w)
                {
                    if let Some(w) = intersection(&a4, &a5, tol) {
                        if distance_to_line(&a2, &a1.r) > tol && distance_to_line(&a2, &a3.r) > tol {
                            me.structure = Structure::ThreeParallel;
                            me.wrist = w;
                            return Some(me);
                        }
                    }
                }
                // no special structure here: `ChainIk` reads the chain backwards, then falls back to
                // `detect_general`
                None
            }
            _ => None,
        }
    }

    /// The general 6R elimination of a chain of six revolute joints (`None` where it is degenerate
    /// or a joint is prismatic): what a chain with no special structure from either end is solved by.
    pub fn detect_general(screws: Vec<Screw>, home: Transform) -> Option<Self> {
        let axes: Vec<Axis> = screws.iter().filter_map(|s| s.axis().copied()).collect();
        let axes: [Axis; 6] = axes.try_into().ok()?;
        let general = General6R::new(axes, home)?;
        Some(Self {
            structure: Structure::General6R,
            arm: None,
            screws,
            home,
            general: Some(Box::new(general)),
            shoulder: Vec3::zeros(),
            wrist: Vec3::zeros(),
        })
    }

    pub fn n(&self) -> usize {
        self.screws.len()
    }

    fn axis(&self, i: usize) -> Axis {
        *self.screws[i].axis().expect("revolute joint by detection")
    }

    /// All candidate `theta` for the target `world_from_tool` (`position_only`: only its origin
    /// counts). `reference` (theta of the caller's q0) fixes free joints at singular targets.
    /// Returns what was met: a singular (non-isolated) solution set, a merge of two roots.
    pub fn solve(&self, target: &Transform, position_only: bool, reference: &[f64], out: &mut Solutions) -> Met {
        out.clear();
        if position_only && !self.structure.solves_position() {
            return Met::default();
        }
        // G = g_d g(0)^-1, so that exp(xi_1 theta_1) ... exp(xi_n theta_n) = G
        let g = target * &self.home.inverse();
        match self.structure {
            Structure::Planar2R => self.planar_2r(0, &self.home.trans, &target.trans, [0.0; 6], reference, out),
            Structure::Planar3R => self.planar_3r(&g, reference, out),
            Structure::ArmIntersecting
            | Structure::ArmParallel
            | Structure::ArmPrismaticBase
            | Structure::ArmCartesian => self.arm(self.structure, &self.home.trans, &target.trans, reference, out),
            Structure::SphericalWrist => self.spherical_wrist(&g, reference, out),
            Structure::ThreeParallel => self.three_parallel(&g, reference, out),
            Structure::General6R => {
                if let Some(general) = &self.general {
                    general.solve(target, out);
                }
                Met::default()
            }
        }
    }

    /// Joints i, i+1 (parallel axes) moving p0 to p: theta_{i+1} by subproblem 3 (distance from
    /// axis i is kept by joint i), then theta_i by subproblem 1 (free on axis i: the reference).
    fn planar_2r(
        &self,
        i: usize,
        p0: &Vec3,
        p: &Vec3,
        prefix: [f64; 6],
        reference: &[f64],
        out: &mut Solutions,
    ) -> Met {
        let (a0, a1) = (self.axis(i), self.axis(i + 1));
        // |exp(xi_{i+1} theta) p0 - r_i| = |p - r_i|
        let t1 = sp3(&a1, p0, &a0.r, (p - a0.r).norm());
        let mut met = Met::of(&t1);
        for &theta1 in t1.as_slice() {
            let p1 = rotate_point(&a1, theta1, p0);
            let t0 = sp1(&a0, &p1, p);
            met |= Met::of(&t0);
            let mut row = prefix;
            row[i] = if t0.singular {
                reference.get(i).copied().unwrap_or(0.0)
            } else {
                t0.values[0]
            };
            row[i + 1] = theta1;
            out.push(row);
        }
        met
    }

    /// Planar 3R: theta_1 + theta_2 + theta_3 is the rotation of G about the common direction;
    /// a point on axis 3 fixes theta_1, theta_2 (planar 2R).
    fn planar_3r(&self, g: &Transform, reference: &[f64], out: &mut Solutions) -> Met {
        let (a0, a2) = (self.axis(0), self.axis(2));
        let x = normal_to(&a0.w);
        let phi = sp1_dir(&a0.w, &x, &(g.rot * x)).values[0];
        let met = self.planar_2r(0, &a2.r, &g.act_point(&a2.r), [0.0; 6], reference, out);
        for row in out.iter_mut() {
            row[2] = phi - row[0] - row[1];
        }
        met
    }

    /// The first three joints moving p0 to p (appends rows with theta_1..3 set).
    fn arm(&self, structure: Structure, p0: &Vec3, p: &Vec3, reference: &[f64], out: &mut Solutions) -> Met {
        let mut met = Met::default();
        match structure {
            Structure::ArmIntersecting => {
                let c = self.shoulder;
                let (a0, a1) = (Axis { r: c, ..self.axis(0) }, Axis { r: c, ..self.axis(1) });
                // joints 1, 2 keep the distance to c: |exp(xi_3 theta_3) p0 - c| = |p - c|
                let delta = (p - c).norm();
                let mut third = [0.0; 2];
                let mut count = 0;
                match self.screws[2] {
                    Screw::Revolute(a2) => {
                        let t = sp3(&a2, p0, &c, delta);
                        met |= Met::of(&t);
                        count = t.count;
                        third = t.values;
                    }
                    Screw::Prismatic(v) => {
                        // |p0 + t v - c|^2 = delta^2: t^2 + 2 t v.(p0 - c) + |p0 - c|^2 - delta^2 = 0
                        let b = v.dot(&(p0 - c));
                        let disc = b * b - ((p0 - c).norm_squared() - delta * delta);
                        let scale = (p0 - c).norm_squared().max(delta * delta).max(1e-300);
                        if disc > 1e-12 * scale {
                            third = [-b + disc.sqrt(), -b - disc.sqrt()];
                            count = 2;
                        } else if disc > -1e-9 * scale {
                            third = [-b, 0.0];
                            count = 1;
                            met.merged = true; // a double root
                        }
                    }
                }
                for &t3 in &third[..count] {
                    let p3 = self.screws[2].exp(t3).act_point(p0);
                    let (pairs, m, s) = sp2(&a0, &a1, &p3, p);
                    met.singular |= s;
                    met.merged |= m == 1;
                    if s && m > 0 {
                        // p on axis 1: theta_1 is free; keep the reference, solve theta_2 by subproblem 1
                        let t1 = reference.first().copied().unwrap_or(0.0);
                        let t2 = sp1(&a1, &p3, &rotate_point(&a0, -t1, p)).values[0];
                        out.push([t1, t2, t3, 0.0, 0.0, 0.0]);
                        continue;
                    }
                    for &(t1, t2) in &pairs[..m] {
                        out.push([t1, t2, t3, 0.0, 0.0, 0.0]);
                    }
                }
            }
            Structure::ArmParallel => {
                let (a0, a1) = (self.axis(0), self.axis(1));
                // joints 2, 3 keep the component along w2: w2 . exp(-w1 theta_1)(p - r1) = w2 . (p0 - r1)
                let t0 = sp4(&a1.w, &a0.w, &(p - a0.r), a1.w.dot(&(p0 - a0.r)));
                met |= Met::of(&t0);
                for &phi in t0.as_slice() {
                    // on axis 1 theta_1 is free: keep the reference
                    let phi = if t0.singular {
                        -reference.first().copied().unwrap_or(0.0)
                    } else {
                        phi
                    };
                    let theta0 = -phi;
                    let p1 = rotate_point(&a0, phi, p);
                    let prefix = [theta0, 0.0, 0.0, 0.0, 0.0, 0.0];
                    met |= self.planar_2r(1, p0, &p1, prefix, reference, out);
                }
            }
            Structure::ArmPrismaticBase | Structure::ArmCartesian => met |= self.prismatic_arm(structure, p0, p, out),
            _ => unreachable!("not an arm"),
        }
        met
    }

    /// `exp(xi_1 theta_1) ... exp(xi_k theta_k)`.
    fn product(&self, theta: &[f64]) -> Transform {
        let mut t = Transform::identity();
        for (s, &x) in self.screws.iter().zip(theta) {
            t = t * s.exp(x);
        }
        t
    }

    /// Arm to the wrist centre, then the wrist: subproblem 2 on axes 4, 5 with a point on axis 6,
    /// subproblem 1 for axis 6.
    fn spherical_wrist(&self, g: &Transform, reference: &[f64], out: &mut Solutions) -> Met {
        let w = self.wrist;
        // joints 4-6 fix w: exp(xi_1 theta_1) exp(xi_2 theta_2) exp(xi_3 theta_3) w = G w
        let mut arms = Vec::with_capacity(4);
        let mut met = self.arm(
            self.arm.expect("arm of a wrist"),
            &w,
            &g.act_point(&w),
            reference,
            &mut arms,
        );
        let (a3, a4, a5) = (
            Axis { r: w, ..self.axis(3) },
            Axis { r: w, ..self.axis(4) },
            Axis { r: w, ..self.axis(5) },
        );
        let p = w + a5.w; // on axis 6, not w
        let x = w + normal_to(&a5.w); // off axis 6
        for arm in &arms {
            // H = (e1 e2 e3)^-1 G = e4 e5 e6
            let h = self.product(&arm[..3]).inverse() * *g;
            let hp = h.act_point(&p);
            let (pairs, m, s) = sp2(&a3, &a4, &p, &hp);
            let mut rows: [(f64, f64); 2] = pairs;
            let mut count = m;
            met.merged |= m == 1;
            if s && m > 0 {
                // axis 6 lines up with axis 4: theta_4 + theta_6 is fixed; keep theta_4 at the reference
                met.singular = true;
                let t3 = reference.get(3).copied().unwrap_or(0.0);
                let t4 = sp1(&a4, &p, &rotate_point(&a3, -t3, &hp)).values[0];
                rows = [(t3, t4), (0.0, 0.0)];
                count = 1;
            }
            for &(t3, t4) in &rows[..count] {
                let e45 = self.screws[3].exp(t3) * self.screws[4].exp(t4);
                let t5 = sp1(&a5, &x, &e45.inverse().act_point(&h.act_point(&x)));
                out.push([arm[0], arm[1], arm[2], t3, t4, t5.values[0]]);
            }
        }
        met
    }

    /// UR-type chains: theta_1 and theta_5 by subproblem 4 (rotations about the parallel axes
    /// keep components along their direction w2), theta_6 by subproblem 1, theta_2..4 planar.
    fn three_parallel(&self, g: &Transform, reference: &[f64], out: &mut Solutions) -> Met {
        let (a0, a1, a3, a4, a5) = (self.axis(0), self.axis(1), self.axis(3), self.axis(4), self.axis(5));
        let w2 = a1.w;
        let mut met = Met::default();
        // w2 . exp(-xi_1 theta_1) G w = w2 . w   (joints 2-4 keep it, joints 5, 6 fix w)
        let pw = g.act_point(&self.wrist);
        let t0 = sp4(&w2, &a0.w, &(pw - a0.r), w2.dot(&(self.wrist - a0.r)));
        met |= Met::of(&t0);
        let x = normal_to(&w2);
        for &phi in t0.as_slice() {
            let theta0 = if t0.singular {
                reference.first().copied().unwrap_or(0.0)
            } else {
                -phi
            };
            let r0 = axis_angle(&a0.w, theta0);
            // w2 . R5(theta_5) w6 = w2 . R1^T R_G w6
            let t4 = sp4(&w2, &a4.w, &a5.w, w2.dot(&(r0.transpose() * (g.rot * a5.w))));
            met |= Met::of(&t4);
            for &theta4 in t4.as_slice() {
                let theta4 = if t4.singular {
                    reference.get(4).copied().unwrap_or(0.0)
                } else {
                    theta4
                };
                // R6 (R_G^T R1 w2) = R5^T w2
                let v = g.rot.transpose() * (r0 * w2);
                let u = rotate(&a4.w, -theta4, &w2);
                let t5 = sp1_dir(&a5.w, &v, &u);
                let theta5 = if t5.singular {
                    met.singular = true;
                    reference.get(5).copied().unwrap_or(0.0)
                } else {
                    t5.values[0]
                };
                // H = e1^-1 G e6^-1 e5^-1 = e2 e3 e4
                let h = self.screws[0].exp(-theta0) * *g * self.screws[5].exp(-theta5) * self.screws[4].exp(-theta4);
                let phi234 = sp1_dir(&w2, &x, &(h.rot * x)).values[0];
                let mut planar = Vec::with_capacity(2);
                // e2 e3 r4 = H r4 (joint 4 fixes a point on its axis)
                met |= self.planar_2r(
                    1,
                    &a3.r,
                    &h.act_point(&a3.r),
                    [theta0, 0.0, 0.0, 0.0, theta4, theta5],
                    reference,
                    &mut planar,
                );
                for mut row in planar {
                    row[3] = phi234 - row[1] - row[2];
                    out.push(row);
                }
            }
        }
        met
    }
}
