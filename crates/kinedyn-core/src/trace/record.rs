//! The algorithms recorded for one robot: each generic algorithm of `crate::algorithms` run once on
//! [`Traced`] (Griewank & Walther, *Evaluating Derivatives*, 2nd ed., §6.1: a program's operation
//! sequence recorded by operator overloading; the algorithms are RBDA's, Featherstone 2008).
//!
//! Every program takes one flat input vector and writes one flat output vector; matrices are
//! row-major (`[i * nv + j]`), `nq`/`nv` the model's configuration and velocity sizes. No external
//! forces; drives (armature, viscous and Coulomb friction) as the generic algorithms include them.
//! The model's constants are recorded with the rounding residue of right angles made exact
//! (`snap.rs`): the program equals the generic algorithm to rounding (1e-16 relative), and to the bit
//! on a model without such residue.
//!
//! The pivots: M^-1, forward dynamics and its derivatives divide by the pivots of `M` (the `L^T D L`
//! factors, the ABA's `D_i`). The generic algorithms test each pivot and refuse a singular `M` with
//! an error naming the joint; a recording cannot branch on a value ([`crate::Real::RECORDING`]), so
//! the program divides unconditionally. The test is then the caller's, on the program's output: a
//! non-finite output means a singular `M` (rerun the generic algorithm at that state for the error
//! naming the joint). For the built-in robots and any model whose subtrees all have inertia about
//! their joints' axes, `M` is positive definite at every configuration and the test never fires.

use super::program::Program;
use super::snap::snapped;
use super::traced::{record, Traced};
use crate::algorithms::{aba, aba_derivatives, crba, gravity_torque, mass_matrix_inverse, rnea, rnea_derivatives};
use crate::{Data, Model};

/// An algorithm that can be recorded for one robot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Algorithm {
    /// Inverse dynamics: in `[q, qd, qdd]`, out `tau (nv)`.
    Rnea,
    /// The mass matrix `M(q)` (armature on the diagonal): in `q`, out `M (nv x nv)`.
    Crba,
    /// `M(q)^-1`: in `q`, out `M^-1 (nv x nv)`.
    Minv,
    /// Forward dynamics: in `[q, qd, tau]`, out `qdd (nv)`.
    Aba,
    /// The gravity torque `g(q)` (no friction): in `q`, out `g (nv)`.
    Gravity,
    /// `dtau/dq` and `dtau/dqd` of [`Algorithm::Rnea`] (dq in the tangent space, as
    /// [`rnea_derivatives`]): in `[q, qd, qdd]`, out `[dtau/dq (nv x nv), dtau/dqd (nv x nv)]`.
    RneaDerivatives,
    /// `dqdd/dq`, `dqdd/dqd` and `dqdd/dtau = M^-1` of [`Algorithm::Aba`]: in `[q, qd, tau]`, out
    /// `[dqdd/dq, dqdd/dqd, dqdd/dtau]` (nv x nv each).
    AbaDerivatives,
}

impl Algorithm {
    /// Every algorithm, in the order of the enum.
    pub const ALL: [Algorithm; 7] = [
        Algorithm::Rnea,
        Algorithm::Crba,
        Algorithm::Minv,
        Algorithm::Aba,
        Algorithm::Gravity,
        Algorithm::RneaDerivatives,
        Algorithm::AbaDerivatives,
    ];

    /// The short name (`rnea`, `crba`, `minv`, `aba`, `gravity`, `rnea_derivatives`,
    /// `aba_derivatives`): the CLI's `--algorithms` and the emitted function names.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Rnea => "rnea",
            Algorithm::Crba => "crba",
            Algorithm::Minv => "minv",
            Algorithm::Aba => "aba",
            Algorithm::Gravity => "gravity",
            Algorithm::RneaDerivatives => "rnea_derivatives",
            Algorithm::AbaDerivatives => "aba_derivatives",
        }
    }

    /// The algorithm of a short name ([`Algorithm::name`]).
    pub fn from_name(name: &str) -> Option<Algorithm> {
        Algorithm::ALL.into_iter().find(|a| a.name() == name)
    }

    /// The input sizes in order, each with its name: `q (nq)` first, then `qd`, `qdd` / `tau`.
    pub fn inputs(self, model: &Model) -> Vec<(&'static str, usize)> {
        let (nq, nv) = (model.nq, model.n);
        match self {
            Algorithm::Crba | Algorithm::Minv | Algorithm::Gravity => vec![("q", nq)],
            Algorithm::Rnea | Algorithm::RneaDerivatives => vec![("q", nq), ("qd", nv), ("qdd", nv)],
            Algorithm::Aba | Algorithm::AbaDerivatives => vec![("q", nq), ("qd", nv), ("tau", nv)],
        }
    }

    /// The output blocks in order, each with its name and size (matrices row-major).
    pub fn outputs(self, model: &Model) -> Vec<(&'static str, usize)> {
        let nv = model.n;
        match self {
            Algorithm::Rnea => vec![("tau", nv)],
            Algorithm::Crba => vec![("M", nv * nv)],
            Algorithm::Minv => vec![("Minv", nv * nv)],
            Algorithm::Aba => vec![("qdd", nv)],
            Algorithm::Gravity => vec![("g", nv)],
            Algorithm::RneaDerivatives => vec![("dtau_dq", nv * nv), ("dtau_dqd", nv * nv)],
            Algorithm::AbaDerivatives => vec![("dqdd_dq", nv * nv), ("dqdd_dqd", nv * nv), ("dqdd_dtau", nv * nv)],
        }
    }
}

/// `algorithm` recorded for `model`: a straight-line program with the inputs and outputs documented
/// at [`Algorithm`] (the pivots of `M` are the caller's to test: see the module's documentation).
pub fn record_algorithm(model: &Model, algorithm: Algorithm) -> Program {
    // the rounding residue of right angles taken as exact, so that it folds (`snap.rs`)
    let model = &snapped(model);
    let (nq, nv) = (model.nq, model.n);
    let n_inputs = algorithm.inputs(model).iter().map(|(_, k)| k).sum();
    record(n_inputs, |x| {
        let mut data = Data::<Traced>::new(model);
        let q = &x[..nq];
        let (qd, third) = (x.get(nq..nq + nv).unwrap_or(&[]), x.get(nq + nv..).unwrap_or(&[]));
        let matrix = || vec![Traced::default(); nv * nv];
        // Result::Err only comes from a pivot test, which a recording skips
        let unchecked = "a recording does not test pivots";
        match algorithm {
            Algorithm::Rnea => rnea(model, &mut data, q, qd, third, None).to_vec(),
            Algorithm::Crba => crba(model, &mut data, q).to_vec(),
            Algorithm::Minv => mass_matrix_inverse(model, &mut data, q).expect(unchecked).to_vec(),
            Algorithm::Aba => aba(model, &mut data, q, qd, third, None).expect(unchecked).to_vec(),
            Algorithm::Gravity => gravity_torque(model, &mut data, q).to_vec(),
            Algorithm::RneaDerivatives => {
                let (mut dq, mut dqd) = (matrix(), matrix());
                rnea_derivatives(model, &mut data, q, qd, third, None, &mut dq, &mut dqd, None);
                [dq, dqd].concat()
            }
            Algorithm::AbaDerivatives => {
                let (mut dq, mut dqd, mut dtau) = (matrix(), matrix(), matrix());
                aba_derivatives(model, &mut data, q, qd, third, None, &mut dq, &mut dqd, &mut dtau).expect(unchecked);
                [dq, dqd, dtau].concat()
            }
        }
    })
}

/// Inverse dynamics recorded for `model` ([`Algorithm::Rnea`]).
pub fn record_rnea(model: &Model) -> Program {
    record_algorithm(model, Algorithm::Rnea)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::testing::{dh_model, random_configuration, random_floating_model, random_model, UR5_DH};

    /// The generic algorithm on f64 with the program's input layout.
    fn generic(model: &Model, algorithm: Algorithm, x: &[f64]) -> Vec<f64> {
        let (nq, nv) = (model.nq, model.n);
        let mut data = Data::new(model);
        let q = &x[..nq];
        let (qd, third) = (x.get(nq..nq + nv).unwrap_or(&[]), x.get(nq + nv..).unwrap_or(&[]));
        let m = || vec![0.0; nv * nv];
        match algorithm {
            Algorithm::Rnea => rnea(model, &mut data, q, qd, third, None).to_vec(),
            Algorithm::Crba => crba(model, &mut data, q).to_vec(),
            Algorithm::Minv => mass_matrix_inverse(model, &mut data, q).unwrap().to_vec(),
            Algorithm::Aba => aba(model, &mut data, q, qd, third, None).unwrap().to_vec(),
            Algorithm::Gravity => gravity_torque(model, &mut data, q).to_vec(),
            Algorithm::RneaDerivatives => {
                let (mut a, mut b) = (m(), m());
                rnea_derivatives(model, &mut data, q, qd, third, None, &mut a, &mut b, None);
                [a, b].concat()
            }
            Algorithm::AbaDerivatives => {
                let (mut a, mut b, mut c) = (m(), m(), m());
                aba_derivatives(model, &mut data, q, qd, third, None, &mut a, &mut b, &mut c).unwrap();
                [a, b, c].concat()
            }
        }
    }

    /// Every recorded program computes what the generic algorithm computes (to 1e-12 relative to
    /// the output's scale), on a chain, a branching tree, a floating base with a spherical joint and
    /// a DH arm.
    #[test]
    fn every_recorded_algorithm_equals_the_generic_one() {
        for (seed, model) in [
            (1, random_model(1, 5, false)),
            (2, random_model(2, 6, true)),
            (3, random_floating_model(3, 4, true)),
            // placements rotated by pi/2: cos(pi/2) = 6.1e-17 entries, snapped in the recording
            (4, dh_model(&UR5_DH, 4)),
        ] {
            let mut rng = Rng::new(seed);
            let states: Vec<Vec<f64>> = (0..3)
                .map(|_| {
                    let q = random_configuration(&model, &mut rng);
                    [q, rng.vector(2 * model.n, -2.0, 2.0)].concat()
                })
                .collect();
            for algorithm in Algorithm::ALL {
                let program = record_algorithm(&model, algorithm);
                let n_in: usize = algorithm.inputs(&model).iter().map(|(_, k)| k).sum();
                let n_out: usize = algorithm.outputs(&model).iter().map(|(_, k)| k).sum();
                assert_eq!(
                    (program.n_inputs, program.outputs.len()),
                    (n_in, n_out),
                    "{algorithm:?}"
                );
                for state in &states {
                    let x = &state[..n_in];
                    let expected = generic(&model, algorithm, x);
                    let mut got = vec![0.0; n_out];
                    program.eval(x, &mut got);
                    let scale = expected.iter().fold(1.0f64, |s, e| s.max(e.abs()));
                    for (k, (g, e)) in got.iter().zip(&expected).enumerate() {
                        assert!(
                            (g - e).abs() <= 1e-12 * scale,
                            "{algorithm:?} output {k}: {g} vs {e} (seed {seed})"
                        );
                    }
                }
            }
        }
    }

    /// Folding works: a DH arm (z axes, placements rotated about x by multiples of pi/2) records
    /// far fewer operations than a random chain of the same size, whose axes and placements are
    /// mostly general.
    #[test]
    fn axis_aligned_robots_record_fewer_operations() {
        let (aligned, random) = (dh_model(&UR5_DH, 1), random_model(5, 6, false));
        for algorithm in [Algorithm::Rnea, Algorithm::Crba, Algorithm::Aba] {
            let a = record_algorithm(&aligned, algorithm).arithmetic_count();
            let r = record_algorithm(&random, algorithm).arithmetic_count();
            assert!(5 * a < 3 * r, "{algorithm:?}: {a} operations aligned, {r} random");
        }
    }
}
