//! Passes over a recorded [`Program`] that keep its numbers, and the operation counts that measure
//! them.
//!
//! Only rewrites exact in IEEE arithmetic are allowed (the specialised program must equal the
//! generic core to rounding, so no reassociation and no fused multiply-add): negation commutes
//! exactly with every rounded operation (round-to-nearest is symmetric), so `a + (-b) = a - b`,
//! `(-a) b = -(a b)`, `-(a - b) = b - a` hold to the bit (up to the sign of a zero result).
//! [`absorb_negations`] uses them to carry each sign to where an addition, subtraction,
//! multiplication or division takes it for free, which also exposes repeated operations that
//! differed only by a sign (`x c` and `x (-c)`; `a - b` and `b - a`) to the merging of the
//! recorder. `sin` and `cos` of one argument are counted once: the backends compute them together
//! (`sin_cos`).

use super::program::{Op, Program};
use super::traced::{record, Traced};
use crate::Real;

/// What a program computes, by kind of operation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Additions and subtractions.
    pub add: usize,
    pub mul: usize,
    pub div: usize,
    /// Negations (a sign flip, no rounding).
    pub neg: usize,
    /// `sin_cos` evaluations: the distinct arguments of `sin` and `cos`.
    pub sincos: usize,
    /// Coulomb friction levels (a comparison and a select each).
    pub select: usize,
}

impl Counts {
    /// The arithmetic floor's main term: additions and multiplications (divisions and `sin_cos`
    /// counted apart, as they cost several of either).
    pub fn add_mul(&self) -> usize {
        self.add + self.mul
    }
}

impl Program {
    /// The operations of the program by kind ([`Counts`]).
    pub fn counts(&self) -> Counts {
        let mut c = Counts::default();
        let mut trig = vec![false; self.ops.len()];
        for op in &self.ops {
            match *op {
                Op::Add(..) | Op::Sub(..) => c.add += 1,
                Op::Mul(..) => c.mul += 1,
                Op::Div(..) => c.div += 1,
                Op::Neg(_) => c.neg += 1,
                Op::Sin(x) | Op::Cos(x) => {
                    if !trig[x as usize] {
                        trig[x as usize] = true;
                        c.sincos += 1;
                    }
                }
                Op::SignedLevel { .. } => c.select += 1,
                Op::Input(_) | Op::Const(_) => {}
            }
        }
        c
    }

    /// The program after every pass of this module ([`absorb_negations`]); the same numbers.
    pub fn optimized(&self) -> Program {
        absorb_negations(self)
    }
}

/// A value of the rewritten program with a pending sign: `-v` when `neg`.
#[derive(Clone, Copy)]
struct Signed {
    v: Traced,
    neg: bool,
}

impl Signed {
    fn plus(v: Traced) -> Signed {
        Signed { v, neg: false }
    }
    /// The value with its sign applied (a negation recorded if one is pending).
    fn value(self) -> Traced {
        if self.neg {
            -self.v
        } else {
            self.v
        }
    }
    fn index(self) -> Option<u32> {
        match self.v {
            Traced::Var(i) => Some(i),
            Traced::Const(_) => None,
        }
    }
}

/// `program` replayed with each negation carried to the operation that can absorb it:
/// `a + (-b) = a - b`, `(-a) + (-b) = -(a + b)`, `a - (-b) = a + b`, `(-a) - b = -(a + b)`,
/// `(-a) - (-b) = b - a`, `(±a)(±b) = ±(a b)` (and for `/`), `-(-a) = a`, negative constants as
/// negated positive ones, and `b - a` recorded as `-(a - b)` when `a` was computed first (so that
/// both orders merge). A sign reaches a `sin`, `cos`, Coulomb level or output as one negation. The
/// replay records through [`Traced`], so its folding and merging apply again, and the dead code is
/// dropped. Exact: every rewrite holds in IEEE arithmetic (Griewank & Walther, *Evaluating
/// Derivatives*, 2nd ed., §6.1: an operation sequence may be rewritten by value-preserving rules).
pub fn absorb_negations(program: &Program) -> Program {
    record(program.n_inputs, |x| {
        let mut v: Vec<Signed> = Vec::with_capacity(program.ops.len());
        for op in &program.ops {
            let r = |k: u32| v[k as usize];
            let s = match *op {
                Op::Input(k) => Signed::plus(x[k as usize]),
                Op::Const(c) if c < 0.0 => Signed {
                    v: Traced::Const(-c),
                    neg: true,
                },
                Op::Const(c) => Signed::plus(Traced::Const(c)),
                Op::Add(a, b) => add(r(a), r(b)),
                Op::Sub(a, b) => {
                    let b = r(b);
                    add(r(a), Signed { v: b.v, neg: !b.neg })
                }
                Op::Mul(a, b) => Signed {
                    v: r(a).v * r(b).v,
                    neg: r(a).neg != r(b).neg,
                },
                Op::Div(a, b) => Signed {
                    v: r(a).v / r(b).v,
                    neg: r(a).neg != r(b).neg,
                },
                Op::Neg(a) => Signed {
                    v: r(a).v,
                    neg: !r(a).neg,
                },
                Op::Sin(a) => Signed::plus(r(a).value().sin_cos().0),
                Op::Cos(a) => Signed::plus(r(a).value().sin_cos().1),
                Op::SignedLevel { x, a, b } => Signed::plus(r(x).value().signed_level(a, b)),
            };
            v.push(s);
        }
        program.outputs.iter().map(|&o| v[o as usize].value()).collect()
    })
}

/// `a + b` of two signed values, the result's sign pending.
fn add(a: Signed, b: Signed) -> Signed {
    match (a.neg, b.neg) {
        (false, false) => Signed::plus(a.v + b.v),
        (true, true) => Signed {
            v: a.v + b.v,
            neg: true,
        },
        // x - y with x = the positive one: recorded in the order of computation, so that x - y and
        // y - x are one operation and a negation
        (false, true) => difference(a.v, b.v),
        (true, false) => difference(b.v, a.v),
    }
}

/// `x - y`, as `-(y - x)` when `y` was computed before `x`.
fn difference(x: Traced, y: Traced) -> Signed {
    match (Signed::plus(x).index(), Signed::plus(y).index()) {
        (Some(i), Some(j)) if j < i => Signed { v: y - x, neg: true },
        _ => Signed::plus(x - y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::testing::{random_configuration, random_model};
    use crate::trace::{record_algorithm, Algorithm};

    /// The pass keeps the numbers to the bit (its rewrites are exact, but for the sign of a zero)
    /// and removes operations; the counts add up to the arithmetic instructions.
    #[test]
    fn absorbing_negations_keeps_the_numbers_and_saves_operations() {
        let model = random_model(9, 5, true);
        let mut rng = Rng::new(9);
        let state = [
            random_configuration(&model, &mut rng),
            rng.vector(2 * model.n, -2.0, 2.0),
        ]
        .concat();
        for algorithm in [Algorithm::Rnea, Algorithm::Aba, Algorithm::RneaDerivatives] {
            let program = record_algorithm(&model, algorithm);
            let better = program.optimized();
            let (c0, c1) = (program.counts(), better.counts());
            assert!(
                c1.add + c1.mul + c1.neg < c0.add + c0.mul + c0.neg,
                "{algorithm:?}: {c0:?} -> {c1:?}"
            );
            assert!(c1.neg < c0.neg, "{algorithm:?}: {c0:?} -> {c1:?}");
            let ops = better.arithmetic_count();
            let trig = better
                .ops
                .iter()
                .filter(|op| matches!(op, Op::Sin(_) | Op::Cos(_)))
                .count();
            assert_eq!(c1.add + c1.mul + c1.div + c1.neg + c1.select + trig, ops);
            let x = &state[..program.n_inputs];
            let (mut a, mut b) = (vec![0.0; program.outputs.len()], vec![0.0; program.outputs.len()]);
            program.eval(x, &mut a);
            better.eval(x, &mut b);
            for (p, q) in a.iter().zip(&b) {
                assert!(p == q, "{algorithm:?}: {p} vs {q} (the rewrites are exact)");
            }
        }
    }
}
