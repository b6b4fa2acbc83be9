//! The recording scalar: a constant, or a value the program computes.

use super::program::{Op, Program};
use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A number during a recording: known now (`Const`), or the value of instruction `Var(i)` of the
/// program being recorded. Arithmetic on `Traced` folds constants and records the rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Traced {
    Const(f64),
    Var(u32),
}

impl Default for Traced {
    fn default() -> Self {
        Traced::Const(0.0)
    }
}

/// Hash-consing key: an instruction with its constants as bit patterns.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Const(u64),
    Binary(u8, u32, u32),
    Unary(u8, u32),
    Level(u32, u64, u64),
}

#[derive(Default)]
struct Recorder {
    ops: Vec<Op>,
    seen: HashMap<Key, u32>,
}

thread_local! {
    static RECORDER: RefCell<Option<Recorder>> = const { RefCell::new(None) };
}

/// Adds `op` unless the same instruction is already recorded; its index.
fn emit(key: Key, op: Op) -> u32 {
    RECORDER.with(|r| {
        let mut r = r.borrow_mut();
        let r = r
            .as_mut()
            .expect("a Traced value is only computed inside trace::record");
        if let Some(&i) = r.seen.get(&key) {
            return i;
        }
        let i = r.ops.len() as u32;
        r.ops.push(op);
        r.seen.insert(key, i);
        i
    })
}

impl Traced {
    /// The instruction holding this value (a constant is recorded on first use).
    fn var(self) -> u32 {
        match self {
            Traced::Var(i) => i,
            Traced::Const(c) => emit(Key::Const(c.to_bits()), Op::Const(c)),
        }
    }
    fn constant(self) -> Option<f64> {
        match self {
            Traced::Const(c) => Some(c),
            Traced::Var(_) => None,
        }
    }
    fn binary(code: u8, a: Traced, b: Traced, op: fn(u32, u32) -> Op, commutes: bool) -> Traced {
        let (mut x, mut y) = (a.var(), b.var());
        if commutes && x > y {
            std::mem::swap(&mut x, &mut y);
        }
        Traced::Var(emit(Key::Binary(code, x, y), op(x, y)))
    }
    fn unary(code: u8, a: Traced, op: fn(u32) -> Op) -> Traced {
        let x = a.var();
        Traced::Var(emit(Key::Unary(code, x), op(x)))
    }
}

/// Records `f` as a program of `n_inputs` inputs: `f` receives the inputs as traced values and
/// returns the outputs. Recordings on one thread do not nest.
pub fn record(n_inputs: usize, f: impl FnOnce(&[Traced]) -> Vec<Traced>) -> Program {
    RECORDER.with(|r| {
        let mut r = r.borrow_mut();
        assert!(r.is_none(), "trace::record does not nest");
        *r = Some(Recorder::default());
    });
    let inputs: Vec<Traced> = (0..n_inputs as u32)
        .map(|k| Traced::Var(emit(Key::Unary(0, k), Op::Input(k))))
        .collect();
    // the recorder is taken back even if `f` panics, so that the thread can record again
    struct Finish;
    impl Drop for Finish {
        fn drop(&mut self) {
            RECORDER.with(|r| r.borrow_mut().take());
        }
    }
    let finish = Finish;
    let outputs: Vec<u32> = f(&inputs).into_iter().map(Traced::var).collect();
    let ops = RECORDER.with(|r| r.borrow_mut().as_mut().map(|r| std::mem::take(&mut r.ops)));
    drop(finish);
    Program {
        n_inputs,
        ops: ops.unwrap_or_default(),
        outputs,
    }
    .without_dead_code()
}

impl Add for Traced {
    type Output = Traced;
    fn add(self, o: Traced) -> Traced {
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Traced::Const(a + b),
            (Some(0.0), _) => o,
            (_, Some(0.0)) => self,
            _ => Traced::binary(1, self, o, Op::Add, true),
        }
    }
}

impl Sub for Traced {
    type Output = Traced;
    fn sub(self, o: Traced) -> Traced {
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Traced::Const(a - b),
            (Some(0.0), _) => -o,
            (_, Some(0.0)) => self,
            _ if self == o => Traced::Const(0.0),
            _ => Traced::binary(2, self, o, Op::Sub, false),
        }
    }
}

impl Mul for Traced {
    type Output = Traced;
    fn mul(self, o: Traced) -> Traced {
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Traced::Const(a * b),
            (Some(0.0), _) | (_, Some(0.0)) => Traced::Const(0.0),
            (Some(1.0), _) => o,
            (_, Some(1.0)) => self,
            (Some(-1.0), _) => -o,
            (_, Some(-1.0)) => -self,
            _ => Traced::binary(3, self, o, Op::Mul, true),
        }
    }
}

impl Div for Traced {
    type Output = Traced;
    fn div(self, o: Traced) -> Traced {
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Traced::Const(a / b),
            (Some(0.0), _) => Traced::Const(0.0),
            (_, Some(1.0)) => self,
            _ => Traced::binary(4, self, o, Op::Div, false),
        }
    }
}

impl Neg for Traced {
    type Output = Traced;
    fn neg(self) -> Traced {
        match self {
            Traced::Const(c) => Traced::Const(-c),
            Traced::Var(i) => {
                // -(-x) = x
                let inner = RECORDER.with(|r| match r.borrow().as_ref().map(|r| r.ops[i as usize]) {
                    Some(Op::Neg(x)) => Some(x),
                    _ => None,
                });
                match inner {
                    Some(x) => Traced::Var(x),
                    None => Traced::unary(5, self, Op::Neg),
                }
            }
        }
    }
}

impl AddAssign for Traced {
    fn add_assign(&mut self, o: Traced) {
        *self = *self + o;
    }
}
impl SubAssign for Traced {
    fn sub_assign(&mut self, o: Traced) {
        *self = *self - o;
    }
}
impl MulAssign for Traced {
    fn mul_assign(&mut self, o: Traced) {
        *self = *self * o;
    }
}

impl num_traits::Zero for Traced {
    fn zero() -> Traced {
        Traced::Const(0.0)
    }
    fn is_zero(&self) -> bool {
        *self == Traced::Const(0.0)
    }
}
impl num_traits::One for Traced {
    fn one() -> Traced {
        Traced::Const(1.0)
    }
}

impl crate::Real for Traced {
    const LANES: usize = 1;
    const RECORDING: bool = true;
    fn splat(x: f64) -> Self {
        Traced::Const(x)
    }
    fn sin_cos(self) -> (Self, Self) {
        match self {
            Traced::Const(c) => {
                let (s, k) = crate::scalar::trig::sin_cos(c);
                (Traced::Const(s), Traced::Const(k))
            }
            Traced::Var(_) => (Traced::unary(6, self, Op::Sin), Traced::unary(7, self, Op::Cos)),
        }
    }
    fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]) {
        for (s, c) in x.iter_mut().zip(cos.iter_mut()) {
            (*s, *c) = s.sin_cos();
        }
    }
    fn signed_level(self, a: f64, b: f64) -> Self {
        match self {
            Traced::Const(c) => Traced::Const(c.signed_level(a, b)),
            _ if a == 0.0 && b == 0.0 => Traced::Const(0.0),
            Traced::Var(x) => Traced::Var(emit(
                Key::Level(x, a.to_bits(), b.to_bits()),
                Op::SignedLevel { x, a, b },
            )),
        }
    }
    /// A recording has no lanes: the batch drivers never run on `Traced`.
    fn lane(self, _k: usize) -> f64 {
        self.constant().unwrap_or(f64::NAN)
    }
    fn set_lane(&mut self, _k: usize, x: f64) {
        *self = Traced::Const(x);
    }
}
