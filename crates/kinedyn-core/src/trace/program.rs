//! The straight-line program a recording produces, and its reference evaluator.

/// One instruction; operands are indices of earlier instructions (SSA: each instruction defines
/// one value, its own index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// The k-th input.
    Input(u32),
    Const(f64),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Neg(u32),
    /// `sin x`, computed as [`crate::scalar::trig::sin_cos`] does.
    Sin(u32),
    /// `cos x`, computed as [`crate::scalar::trig::sin_cos`] does.
    Cos(u32),
    /// [`crate::Real::signed_level`]: `a` where `x > 0`, `-b` where `x < 0`, 0 at 0 (Coulomb
    /// friction).
    SignedLevel {
        x: u32,
        a: f64,
        b: f64,
    },
}

impl Op {
    /// The values this instruction reads.
    pub fn operands(&self) -> impl Iterator<Item = u32> {
        let (a, b) = match *self {
            Op::Input(_) | Op::Const(_) => (None, None),
            Op::Add(x, y) | Op::Sub(x, y) | Op::Mul(x, y) | Op::Div(x, y) => (Some(x), Some(y)),
            Op::Neg(x) | Op::Sin(x) | Op::Cos(x) | Op::SignedLevel { x, .. } => (Some(x), None),
        };
        a.into_iter().chain(b)
    }
}

/// A straight-line program: `n_inputs` numbers in, `outputs.len()` numbers out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Program {
    pub n_inputs: usize,
    pub ops: Vec<Op>,
    /// The instruction whose value is each output.
    pub outputs: Vec<u32>,
}

impl Program {
    /// Runs the program one instruction at a time (the reference every backend is tested against).
    ///
    /// Panics if `inputs` or `outputs` do not have the program's lengths.
    pub fn eval(&self, inputs: &[f64], outputs: &mut [f64]) {
        assert_eq!(inputs.len(), self.n_inputs, "program inputs");
        assert_eq!(outputs.len(), self.outputs.len(), "program outputs");
        let mut v = vec![0.0; self.ops.len()];
        for (i, op) in self.ops.iter().enumerate() {
            let r = |k: u32| v[k as usize];
            v[i] = match *op {
                Op::Input(k) => inputs[k as usize],
                Op::Const(c) => c,
                Op::Add(a, b) => r(a) + r(b),
                Op::Sub(a, b) => r(a) - r(b),
                Op::Mul(a, b) => r(a) * r(b),
                Op::Div(a, b) => r(a) / r(b),
                Op::Neg(a) => -r(a),
                Op::Sin(a) => crate::scalar::trig::sin_cos(r(a)).0,
                Op::Cos(a) => crate::scalar::trig::sin_cos(r(a)).1,
                Op::SignedLevel { x, a, b } => crate::Real::signed_level(r(x), a, b),
            };
        }
        for (o, &k) in outputs.iter_mut().zip(&self.outputs) {
            *o = v[k as usize];
        }
    }

    /// The program without the instructions no output depends on, renumbered (inputs kept, so that
    /// the calling convention does not change).
    pub fn without_dead_code(&self) -> Program {
        let mut live = vec![false; self.ops.len()];
        for &o in &self.outputs {
            live[o as usize] = true;
        }
        for i in (0..self.ops.len()).rev() {
            if live[i] || matches!(self.ops[i], Op::Input(_)) {
                live[i] = true;
                for k in self.ops[i].operands() {
                    live[k as usize] = true;
                }
            }
        }
        let mut index = vec![u32::MAX; self.ops.len()];
        let mut ops = Vec::new();
        for (i, op) in self.ops.iter().enumerate().filter(|(i, _)| live[*i]) {
            let m = |k: u32| index[k as usize];
            let renumbered = match *op {
                Op::Add(a, b) => Op::Add(m(a), m(b)),
                Op::Sub(a, b) => Op::Sub(m(a), m(b)),
                Op::Mul(a, b) => Op::Mul(m(a), m(b)),
                Op::Div(a, b) => Op::Div(m(a), m(b)),
                Op::Neg(a) => Op::Neg(m(a)),
                Op::Sin(a) => Op::Sin(m(a)),
                Op::Cos(a) => Op::Cos(m(a)),
                Op::SignedLevel { x, a, b } => Op::SignedLevel { x: m(x), a, b },
                leaf => leaf,
            };
            index[i] = ops.len() as u32;
            ops.push(renumbered);
        }
        Program {
            n_inputs: self.n_inputs,
            ops,
            outputs: self.outputs.iter().map(|&o| index[o as usize]).collect(),
        }
    }

    /// Instructions that do arithmetic (neither inputs nor constants).
    pub fn arithmetic_count(&self) -> usize {
        self.ops
            .iter()
            .filter(|op| !matches!(op, Op::Input(_) | Op::Const(_)))
            .count()
    }
}
