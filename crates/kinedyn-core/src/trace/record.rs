//! The algorithms recorded for one robot.

use super::program::Program;
use super::traced::{record, Traced};
use crate::algorithms::rnea::rnea;
use crate::{Data, Model};

/// Inverse dynamics `tau = rnea(q, qd, qdd)` (no external forces) for `model`: inputs
/// `[q (nq), qd (nv), qdd (nv)]`, outputs `tau (nv)`.
pub fn record_rnea(model: &Model) -> Program {
    let (nq, nv) = (model.nq, model.n);
    record(nq + 2 * nv, |x| {
        let mut data = Data::<Traced>::new(model);
        let (q, rest) = x.split_at(nq);
        let (qd, qdd) = rest.split_at(nv);
        rnea(model, &mut data, q, qd, qdd, None).to_vec()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::testing::{random_configuration, random_floating_model, random_model};

    /// The recorded program computes what the generic algorithm computes, on fixed and floating
    /// trees, and folds the constants (fewer operations than an unfolded run would record).
    #[test]
    fn recorded_rnea_equals_the_generic_algorithm() {
        for (seed, model) in [
            (1, random_model(1, 6, false)),
            (2, random_model(2, 9, true)),
            (3, random_floating_model(3, 7, true)),
        ] {
            let program = record_rnea(&model);
            let mut rng = Rng::new(seed);
            for _ in 0..5 {
                let q = random_configuration(&model, &mut rng);
                let qd: Vec<f64> = (0..model.n).map(|_| rng.uniform(-2.0, 2.0)).collect();
                let qdd: Vec<f64> = (0..model.n).map(|_| rng.uniform(-2.0, 2.0)).collect();
                let mut data = Data::new(&model);
                let expected = rnea(&model, &mut data, &q, &qd, &qdd, None).to_vec();
                let inputs = [q, qd, qdd].concat();
                let mut got = vec![0.0; model.n];
                program.eval(&inputs, &mut got);
                for (g, e) in got.iter().zip(&expected) {
                    assert!((g - e).abs() <= 1e-12 * (1.0 + e.abs()), "{g} vs {e} (seed {seed})");
                }
            }
        }
    }
}
