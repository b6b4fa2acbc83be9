//! A chain's closed-form solver as detected: the structures of [`super::analytic`] on the chain
//! as it is, or on the chain read backwards (tool to base), and the most real solutions each can
//! have (the completeness bound that every result states, `super::solutions`).
//!
//! **The reversed chain.** `g_d = e_1(theta_1) ... e_n(theta_n) g(0)` with `e_i = exp(xi_i^ .)`
//! inverts to `g_d^-1 = g(0)^-1 e_n(-theta_n) ... e_1(-theta_1)`; writing `H = g(0)^-1` and
//! `H e_i(x) H^-1 = exp((Ad_H xi_i)^ x)` (Murray, Li & Sastry 1994, §2.4, the adjoint moves a
//! screw rigidly),
//!
//! ```text
//! g_d^-1 = exp(xi'_1 theta'_1) ... exp(xi'_n theta'_n) H,   xi'_k = Ad_H xi_{n+1-k},  theta'_k = -theta_{n+1-k}
//! ```
//!
//! a chain of the same kind with home `H` and target `g_d^-1`. An arm whose first three axes meet
//! (a "spherical shoulder": the Panda with its last joint held, an SRS arm with a wrist joint held)
//! is then a spherical-wrist chain. Which end carries the structure is read from the geometry.
//!
//! | symbol    | here       | meaning                                          |
//! |-----------|------------|--------------------------------------------------|
//! | `H`       | `h`        | `g(0)^-1`, the reversed chain's home             |
//! | `theta'`  | row        | the reversed chain's coordinates                 |

use super::analytic::{AnalyticIk, Met, Screw, Solutions, Structure};
use super::subproblems::Axis;
use crate::spatial::Transform;

/// The most real solutions a structure's closed form has for one target (the product of the
/// subproblems' counts: subproblems 2, 3, 4 give at most two each, subproblem 1 one).
pub fn max_solutions(structure: Structure) -> usize {
    match structure {
        Structure::Planar2R | Structure::Planar3R => 2,
        Structure::ArmIntersecting | Structure::ArmParallel | Structure::ArmPrismaticBase => 4,
        Structure::ArmCartesian => 1,
        Structure::SphericalWrist | Structure::ThreeParallel => 8,
        // Raghavan & Roth: the degree-16 polynomial of the general 6R
        Structure::General6R => super::general6r::MAX_SOLUTIONS,
    }
}

/// A detected closed form, on the chain as it is or reversed.
#[derive(Clone, Debug)]
pub struct ChainIk {
    pub ik: AnalyticIk,
    /// The structure was found on the chain read from the tool to the base.
    pub reversed: bool,
}

/// The screw `Ad_h xi` (the axis moved rigidly by `h`).
fn moved(h: &Transform, s: &Screw) -> Screw {
    match s {
        Screw::Revolute(a) => Screw::Revolute(Axis {
            w: h.rot * a.w,
            r: h.act_point(&a.r),
        }),
        Screw::Prismatic(v) => Screw::Prismatic(h.rot * v),
    }
}

impl ChainIk {
    /// The structure of the chain, else of the reversed chain (6 joints: the arm/wrist split
    /// has a direction), else the general 6R elimination, else None.
    pub fn detect(screws: Vec<Screw>, home: Transform) -> Option<Self> {
        let n = screws.len();
        if let Some(ik) = AnalyticIk::detect(screws.clone(), home) {
            return Some(Self { ik, reversed: false });
        }
        if n != 6 {
            return None;
        }
        let h = home.inverse();
        let back: Vec<Screw> = screws.iter().rev().map(|s| moved(&h, s)).collect();
        if let Some(ik) = AnalyticIk::detect(back, h) {
            return Some(Self { ik, reversed: true });
        }
        AnalyticIk::detect_general(screws, home).map(|ik| Self { ik, reversed: false })
    }

    pub fn n(&self) -> usize {
        self.ik.n()
    }

    pub fn structure(&self) -> Structure {
        self.ik.structure
    }

    /// The structure's name, `reversed_` before it when it was found from the tool end.
    pub fn name(&self) -> &'static str {
        if !self.reversed {
            // a spherical wrist on an arm with a prismatic first joint (`prismatic.rs`) says so
            return match (self.ik.structure, self.ik.arm) {
                (Structure::SphericalWrist, Some(Structure::ArmCartesian)) => "spherical_wrist_cartesian_arm",
                (Structure::SphericalWrist, Some(Structure::ArmPrismaticBase)) => "spherical_wrist_prismatic_base",
                (s, _) => s.name(),
            };
        }
        match self.ik.structure {
            Structure::SphericalWrist => "reversed_spherical_wrist",
            Structure::ThreeParallel => "reversed_three_parallel",
            // only 6-joint structures are looked for backwards
            s => s.name(),
        }
    }

    pub fn max_solutions(&self) -> usize {
        match (self.ik.structure, self.ik.arm) {
            // the arm's roots times the wrist's two
            (Structure::SphericalWrist, Some(arm)) => 2 * max_solutions(arm),
            (s, _) => max_solutions(s),
        }
    }

    /// Whether a position target has a closed form (never for a reversed chain: its "position"
    /// would be the base's in the tool frame).
    pub fn solves_position(&self) -> bool {
        !self.reversed && self.ik.structure.solves_position()
    }

    /// All candidate `theta` rows (see [`AnalyticIk::solve`]); returns what was met.
    pub fn solve(&self, target: &Transform, position_only: bool, reference: &[f64], out: &mut Solutions) -> Met {
        if !self.reversed {
            return self.ik.solve(target, position_only, reference, out);
        }
        if position_only {
            out.clear();
            return Met::default();
        }
        let n = self.n();
        let mut back_ref = [0.0; 6];
        for k in 0..n.min(reference.len()) {
            back_ref[k] = -reference[n - 1 - k];
        }
        let met = self.ik.solve(&target.inverse(), false, &back_ref[..n], out);
        for row in out.iter_mut() {
            let back = *row;
            for k in 0..n {
                row[k] = -back[n - 1 - k];
            }
        }
        met
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::axis_angle;
    use crate::spatial::Vec3;

    use crate::ik::analytic::rev;

    fn fk(screws: &[Screw], home: &Transform, theta: &[f64]) -> Transform {
        let mut t = Transform::identity();
        for (s, &x) in screws.iter().zip(theta) {
            t = t * s.exp(x);
        }
        t * *home
    }

    /// A 6R whose first three axes meet (a spherical shoulder) and whose last three do not: only
    /// the reversed chain has a structure, and every candidate reproduces the target.
    #[test]
    fn a_spherical_shoulder_is_solved_backwards() {
        let screws = vec![
            rev([0.0, 0.0, 1.0], [0.0, 0.0, 0.3]),
            rev([0.0, 1.0, 0.0], [0.0, 0.0, 0.3]),
            rev([1.0, 0.0, 0.2], [0.0, 0.0, 0.3]),
            rev([0.0, -1.0, 0.0], [0.08, 0.0, 0.6]),
            rev([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]),
            rev([0.0, -1.0, 0.0], [0.0, 0.0, 1.0]),
        ];
        let home = Transform::new(axis_angle(&Vec3::x(), 3.0), Vec3::new(0.09, 0.0, 0.9));
        assert!(AnalyticIk::detect(screws.clone(), home).is_none());
        let solver = ChainIk::detect(screws.clone(), home).expect("reversed structure");
        assert!(solver.reversed);
        assert_eq!(solver.name(), "reversed_spherical_wrist");
        let theta = [0.3, -0.7, 1.1, -1.4, 0.5, 0.9];
        let target = fk(&screws, &home, &theta);
        let mut out = Vec::new();
        solver.solve(&target, false, &[0.0; 6], &mut out);
        assert!(out.len() >= 2 && out.len() <= solver.max_solutions());
        let mut original = false;
        for row in &out {
            let t = fk(&screws, &home, row);
            assert!((t.trans - target.trans).norm() < 1e-9);
            assert!((t.rot - target.rot).abs().max() < 1e-9);
            original |= row.iter().zip(&theta).all(|(a, b)| {
                let d = a - b;
                (d - 2.0 * std::f64::consts::PI * (d / (2.0 * std::f64::consts::PI)).round()).abs() < 1e-7
            });
        }
        assert!(
            original,
            "the configuration the target came from is among the candidates"
        );
    }

    /// A spherical wrist at q5 = 0 (axes 4 and 6 in line) and near it: the wrist's subproblem 2
    /// meets a double root and says so; away from it, all eight roots are simple.
    #[test]
    fn a_wrist_singularity_is_met_as_merged_roots() {
        let screws = vec![
            rev([0.0, 0.0, 1.0], [0.0, 0.0, 0.0]),
            rev([0.0, 1.0, 0.0], [0.0, 0.0, 0.0]),
            rev([0.0, 1.0, 0.0], [0.43, 0.15, 0.0]),
            rev([0.0, 0.0, 1.0], [0.45, 0.15, 0.43]),
            rev([0.0, 1.0, 0.0], [0.45, 0.15, 0.43]),
            rev([0.0, 0.0, 1.0], [0.45, 0.15, 0.43]),
        ];
        let home = Transform::new(axis_angle(&Vec3::y(), 0.3), Vec3::new(0.45, 0.15, 0.5));
        let solver = ChainIk::detect(screws.clone(), home).expect("structure");
        assert_eq!(solver.name(), "spherical_wrist");
        let mut out = Vec::new();
        for (q5, merged) in [(0.0, true), (1e-6, true), (1e-5, true), (0.4, false)] {
            let theta = [0.3, -0.4, 0.5, 0.7, q5, -0.2];
            let met = solver.solve(&fk(&screws, &home, &theta), false, &[0.0; 6], &mut out);
            assert_eq!(met.merged, merged, "q5 = {q5}");
            assert_eq!(
                out.len() < solver.max_solutions(),
                merged,
                "q5 = {q5}: {} roots",
                out.len()
            );
        }
    }
}
