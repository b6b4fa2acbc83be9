//! Robot-specialised programs: an algorithm run once on a recording scalar becomes a straight-line
//! program for one robot.
//!
//! The algorithms are generic over [`crate::Real`]; run on [`Traced`] they do not compute numbers but
//! write each arithmetic operation into a [`Program`]. The model's constants (axes, placements,
//! inertias) reach the algorithm through [`crate::Real::splat`], so they enter the recording as
//! constants, and every operation on constants alone is computed at once (constant folding);
//! `x * 0`, `x * 1`, `x + 0` vanish, and an operation already recorded on the same operands is not
//! recorded again (common subexpressions merged by hash-consing). What remains is what the robot's
//! structure needs: the zeros and ones of its joint axes and placements cost nothing. This is the
//! idea of code generation by operator overloading (CppADCodeGen; Griewank & Walther, *Evaluating
//! Derivatives*, 2nd ed., ch. 6), done on the algorithms' own source.
//!
//! A program has no loops and no branches; [`Program::eval`] runs it (the reference for every
//! backend), [`Program::optimized`] applies the exact rewrites of `passes.rs` (negations absorbed),
//! [`Program::counts`] measures it, [`emit::source`] writes it as C or Rust, and backends compile it.
//! [`record_algorithm`] records each algorithm of [`Algorithm`] with its input and output layout.

pub mod emit;
mod passes;
mod program;
mod record;
mod snap;
mod traced;

pub use passes::{absorb_negations, Counts};
pub use program::{Op, Program};
pub use record::{record_algorithm, record_rnea, Algorithm};
pub use traced::{record, Traced};
