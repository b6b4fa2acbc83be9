//! Arms (joints 1-3, moving a point `p0` to `p`: the tool point of a 3-joint chain or the centre
//! of a spherical wrist) whose first joint is prismatic. A prismatic joint's exponential is the
//! translation `[I, v d]` (Murray, Li & Sastry 1994, eq. 2.41), and a joint before the others
//! moves them rigidly, so `p = v_1 d_1 + e_2 e_3 p0`:
//!
//! - **prismatic base, axes 2 and 3 meeting at c** (`ArmPrismaticBase`): joints 2 and 3 keep the
//!   distance to c, `|p - v d - c| = |p0 - c|`, a quadratic `d^2 - 2 d v.e + |e|^2 - |p0 - c|^2 = 0`
//!   with `e = p - c` (<= 2 roots), then `e_2 e_3 p0 = p - v d` by subproblem 2 (<= 2 pairs): <= 4;
//! - **three prismatic joints** (`ArmCartesian`, a gantry): `[v_1 v_2 v_3] d = p - p0`, one
//!   solution where the directions are independent.
//!
//! A prismatic joint elsewhere (after a revolute one, other than the third of an
//! intersecting-shoulder arm, `analytic.rs`) has no closed form here.

use super::analytic::{distance_to_line, intersection, AnalyticIk, Met, Screw, Solutions, Structure};
use super::subproblems::{sp2, Axis};
use crate::spatial::{Mat3, Vec3};

fn direction(s: &Screw) -> Option<Vec3> {
    match s {
        Screw::Prismatic(v) => Some(*v),
        Screw::Revolute(_) => None,
    }
}

/// The structure of joints 1-3 moving `p0` when joint 1 is prismatic (and the point where axes 2
/// and 3 meet), or None.
pub(super) fn detect_arm(screws: &[Screw], p0: &Vec3, tol: f64) -> Option<(Structure, Vec3)> {
    let v = direction(screws.first()?)?;
    match (screws.get(1)?, screws.get(2)?) {
        (Screw::Prismatic(v2), Screw::Prismatic(v3)) => {
            let independent = Mat3::from_columns(&[v, *v2, *v3]).determinant().abs() > 1e-9;
            independent.then_some((Structure::ArmCartesian, Vec3::zeros()))
        }
        (Screw::Revolute(a1), Screw::Revolute(a2)) => {
            let c = intersection(a1, a2, tol)?;
            // p0 off axis 3 and off c: else a joint is free
            (distance_to_line(a2, p0) > tol && (p0 - c).norm() > tol).then_some((Structure::ArmPrismaticBase, c))
        }
        _ => None,
    }
}

impl AnalyticIk {
    /// The arms of the module header: rows with `theta_1..3` set appended to `out`.
    pub(super) fn prismatic_arm(&self, structure: Structure, p0: &Vec3, p: &Vec3, out: &mut Solutions) -> Met {
        let mut met = Met::default();
        let v = |i: usize| direction(&self.screws[i]);
        match structure {
            Structure::ArmCartesian => {
                let (Some(v1), Some(v2), Some(v3)) = (v(0), v(1), v(2)) else {
                    return met;
                };
                if let Some(inverse) = Mat3::from_columns(&[v1, v2, v3]).try_inverse() {
                    let d = inverse * (p - p0);
                    out.push([d.x, d.y, d.z, 0.0, 0.0, 0.0]);
                }
            }
            Structure::ArmPrismaticBase => {
                let (Some(v1), Screw::Revolute(a1), Screw::Revolute(a2)) = (v(0), self.screws[1], self.screws[2])
                else {
                    return met;
                };
                let c = self.shoulder;
                let (a1, a2) = (Axis { r: c, ..a1 }, Axis { r: c, ..a2 });
                let e = p - c;
                let rho2 = (p0 - c).norm_squared();
                let b = v1.dot(&e);
                let disc = b * b - (e.norm_squared() - rho2);
                let scale = e.norm_squared().max(rho2).max(1e-300);
                let (roots, count) = if disc > 1e-12 * scale {
                    ([b + disc.sqrt(), b - disc.sqrt()], 2)
                } else if disc > -1e-9 * scale {
                    met.merged = true; // a double root: two branches meet
                    ([b, 0.0], 1)
                } else {
                    return met;
                };
                for &d in &roots[..count] {
                    let (pairs, m, s) = sp2(&a1, &a2, p0, &(p - v1 * d));
                    met.singular |= s;
                    met.merged |= m == 1;
                    for &(t2, t3) in &pairs[..m] {
                        out.push([d, t2, t3, 0.0, 0.0, 0.0]);
                    }
                }
            }
            _ => unreachable!("not a prismatic arm"),
        }
        met
    }
}

#[cfg(test)]
mod tests {
    use super::super::chain::ChainIk;
    use super::*;
    use crate::joint::axis_angle;
    use crate::spatial::Transform;
    use std::f64::consts::PI;

    use crate::ik::analytic::rev;

    fn prism(v: [f64; 3]) -> Screw {
        Screw::Prismatic(Vec3::new(v[0], v[1], v[2]).normalize())
    }

    fn fk(screws: &[Screw], home: &Transform, theta: &[f64]) -> Transform {
        let mut t = Transform::identity();
        for (s, &x) in screws.iter().zip(theta) {
            t = t * s.exp(x);
        }
        t * *home
    }

    /// Every candidate reproduces the target, the configuration it came from is among them, and
    /// their number is the bound at a generic target.
    fn check(screws: Vec<Screw>, home: Transform, name: &str, most: usize, theta: [f64; 6]) {
        let solver = ChainIk::detect(screws.clone(), home).expect("a structure");
        assert_eq!(solver.name(), name);
        assert_eq!(solver.max_solutions(), most);
        let target = fk(&screws, &home, &theta);
        let mut out = Vec::new();
        solver.solve(&target, false, &[0.0; 6], &mut out);
        assert_eq!(out.len(), most, "{name}: every branch at a generic target");
        let mut original = false;
        for row in &out {
            let t = fk(&screws, &home, row);
            assert!((t.trans - target.trans).norm() < 1e-9 && (t.rot - target.rot).abs().max() < 1e-9);
            original |= row.iter().zip(&theta).zip(&screws).all(|((a, b), s)| {
                let d = a - b;
                match s {
                    Screw::Prismatic(_) => d.abs() < 1e-9,
                    Screw::Revolute(_) => (d - 2.0 * PI * (d / (2.0 * PI)).round()).abs() < 1e-9,
                }
            });
        }
        assert!(original, "{name}: the original configuration is a candidate");
    }

    #[test]
    fn a_gantry_with_a_spherical_wrist() {
        let w = [0.1, -0.2, 0.3];
        let screws = vec![
            prism([1.0, 0.0, 0.0]),
            prism([0.2, 1.0, 0.0]),
            prism([0.0, 0.1, 1.0]),
            rev([0.0, 0.0, 1.0], w),
            rev([0.0, 1.0, 0.0], w),
            rev([1.0, 0.0, 0.3], w),
        ];
        let home = Transform::new(axis_angle(&Vec3::y(), 0.5), Vec3::new(0.1, -0.2, 0.45));
        check(
            screws,
            home,
            "spherical_wrist_cartesian_arm",
            2,
            [0.3, -0.2, 0.5, 0.7, 0.9, -1.1],
        );
    }

    #[test]
    fn a_prismatic_base_with_a_spherical_wrist() {
        // a vertical rail, a shoulder on it, an elbow of the RRP kind turned revolute: axes 2 and 3
        // meet at (0, 0, 0.4); the wrist centre is off axis 3
        let (c, w) = ([0.0, 0.0, 0.4], [0.35, 0.1, 0.6]);
        let screws = vec![
            prism([0.0, 0.0, 1.0]),
            rev([0.0, 0.0, 1.0], c),
            rev([0.0, 1.0, 0.0], c),
            rev([1.0, 0.0, 0.0], w),
            rev([0.0, 1.0, 0.0], w),
            rev([1.0, 0.0, 0.0], w),
        ];
        let home = Transform::new(axis_angle(&Vec3::z(), 0.3), Vec3::new(0.45, 0.1, 0.6));
        check(
            screws,
            home,
            "spherical_wrist_prismatic_base",
            8,
            [0.25, 0.4, -0.6, 0.3, 0.8, -0.5],
        );
    }

    /// The count against a dense numeric search: Levenberg-Marquardt from 64 random starts on a
    /// model built from the same screws finds no solution the closed form lacks, and every
    /// closed-form solution is found.
    #[test]
    fn the_prismatic_base_count_matches_a_numeric_search() {
        use crate::ik::{numeric_ik, Settings};
        use crate::spatial::Inertia;
        use crate::{Data, Frame, Joint, JointKind, Model};
        let (c, w) = ([0.0, 0.0, 0.4], [0.35, 0.1, 0.6]);
        let screws = vec![
            prism([0.0, 0.0, 1.0]),
            rev([0.0, 0.0, 1.0], c),
            rev([0.0, 1.0, 0.0], c),
            rev([1.0, 0.0, 0.0], w),
            rev([0.0, 1.0, 0.0], w),
            rev([1.0, 0.0, 0.0], w),
        ];
        let home = Transform::new(axis_angle(&Vec3::z(), 0.3), Vec3::new(0.45, 0.1, 0.6));
        // body frames parallel to the base at theta = 0, each at a point of its axis
        let (mut joints, mut placements, mut previous) = (Vec::new(), Vec::new(), Vec3::zeros());
        for s in &screws {
            let (kind, axis, at) = match s {
                Screw::Prismatic(v) => (JointKind::Prismatic, *v, previous),
                Screw::Revolute(a) => (JointKind::Revolute, a.w, a.r),
            };
            joints.push(Joint { kind, axis });
            placements.push(Transform::new(Mat3::identity(), at - previous));
            previous = at;
        }
        let tool = Transform::new(home.rot, home.trans - previous);
        let body = Inertia::new(1.0, Vec3::zeros(), Mat3::identity() * 0.01);
        let z = vec![0.0; 6];
        let frames = vec![Frame {
            body: Some(5),
            body_from_frame: tool,
        }];
        let parent = (0..6).map(|i: usize| i.checked_sub(1)).collect();
        let model = Model::new(
            parent,
            joints,
            z.clone(),
            placements,
            vec![body; 6],
            z.clone(),
            z.clone(),
            z,
            Vec3::zeros(),
            frames,
        )
        .unwrap();
        let mut data = Data::new(&model);
        let theta = [0.25, 0.4, -0.6, 0.3, 0.8, -0.5];
        let target = fk(&screws, &home, &theta);
        let solver = ChainIk::detect(screws.clone(), home).unwrap();
        let mut closed = Vec::new();
        solver.solve(&target, false, &[0.0; 6], &mut closed);
        let same = |a: &[f64], b: &[f64]| {
            (a[0] - b[0]).abs() < 1e-6
                && (1..6).all(|i| {
                    let d = a[i] - b[i];
                    (d - 2.0 * PI * (d / (2.0 * PI)).round()).abs() < 1e-6
                })
        };
        let (lower, upper) = ([-2.0, -PI, -PI, -PI, -PI, -PI], [2.0, PI, PI, PI, PI, PI]);
        let settings = Settings {
            restarts: 4,
            position_tolerance: 1e-12,
            orientation_tolerance: 1e-12,
            ..Default::default()
        };
        let mut rng = crate::testing::Rng::new(3);
        let mut found: Vec<Vec<f64>> = Vec::new();
        for seed in 0..64 {
            let start: Vec<f64> = (0..6).map(|i| rng.uniform(lower[i], upper[i])).collect();
            let r = numeric_ik(&model, &mut data, 0, &target, &start, &lower, &upper, &settings, seed);
            if r.success && !found.iter().any(|f| same(f, &r.q)) {
                found.push(r.q);
            }
        }
        for f in &found {
            assert!(
                closed.iter().any(|row| same(row, f)),
                "numeric {f:?} missing from the closed form"
            );
        }
        assert_eq!(found.len(), closed.len(), "the numeric search found every branch");
    }
}
