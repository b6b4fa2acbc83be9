//! The scalar the algorithms compute with: `f64` for one state, [`Lanes<N>`] for N states at once.
//!
//! Every algorithm that a batch runs is written once, generic over [`Real`]. With `f64` it is the
//! single-call code (monomorphised, as fast as before the trait existed); with `Lanes<N>` each
//! number of the algorithm holds the same quantity for N states, one per SIMD lane
//! (structure-of-arrays across states), so one instruction advances N states. The model's constants
//! (axes, placements, inertias) stay `f64` and are broadcast where they meet state-dependent values
//! ([`Real::splat`]).
//!
//! Lane arithmetic is written as loops over `[f64; N]` that LLVM turns into vector instructions;
//! which ones depends on the features the calling function is compiled for: the batch drivers
//! (`crate::batch`) compile each kernel for AVX-512, AVX2 and the baseline and pick one at run time.
//! The operations are the same IEEE operations in the same order as the `f64` path (no fused
//! multiply-add, no reassociation), so a lane's result equals the single call's to the last bit
//! except where noted (tests: `batch.rs`).

use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

pub mod trig;

/// A real number type the algorithms run on: `f64` or [`Lanes<N>`] (one `f64` per state).
pub trait Real:
    Copy
    + Default
    + Debug
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + num_traits::Zero
    + num_traits::One
{
    /// States per value (1 for `f64`).
    const LANES: usize;
    /// Whether values are recorded rather than computed ([`crate::trace::Traced`]): a recording
    /// cannot branch on a value, so the algorithms skip their tests of values (the pivots of the
    /// mass matrix) and leave them to whoever runs the recorded program (`trace::record`).
    const RECORDING: bool = false;
    /// The same number in every lane.
    fn splat(x: f64) -> Self;
    /// `(sin x, cos x)` per lane ([`trig::sin_cos`]'s numbers).
    fn sin_cos(self) -> (Self, Self);
    /// `x[i] <- sin x[i]`, `cos[i] <- cos x[i]` for every i ([`trig::sin_cos_in_place`]).
    fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]);
    /// `a` where `self > 0`, `-b` where `self < 0`, 0 where `self == 0` (and NaN where NaN): a
    /// direction-dependent Coulomb friction torque, lane by lane.
    fn signed_level(self, a: f64, b: f64) -> Self;
    /// Lane `k` as an `f64`.
    fn lane(self, k: usize) -> f64;
    /// Lane `k` set to `x`.
    fn set_lane(&mut self, k: usize, x: f64);
}

impl Real for f64 {
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        trig::sin_cos(self)
    }
    #[inline(always)]
    fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]) {
        // out of line for one state (inlined into the CRBA, the loop cost it 10-15 %)
        trig::sin_cos_in_place_outlined(x, cos);
    }
    #[inline(always)]
    fn signed_level(self, a: f64, b: f64) -> Self {
        if self > 0.0 {
            a
        } else if self < 0.0 {
            -b
        } else {
            0.0
        }
    }
    #[inline(always)]
    fn lane(self, _k: usize) -> f64 {
        self
    }
    #[inline(always)]
    fn set_lane(&mut self, _k: usize, x: f64) {
        *self = x;
    }
}

/// N `f64`s, one per state, operated on lane by lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct Lanes<const N: usize>(pub [f64; N]);

impl<const N: usize> Default for Lanes<N> {
    #[inline(always)]
    fn default() -> Self {
        Self([0.0; N])
    }
}

impl<const N: usize> Lanes<N> {
    /// `f(self[k], other[k])` in every lane.
    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut r = self;
        for k in 0..N {
            r.0[k] = f(self.0[k], o.0[k]);
        }
        r
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $op:tt) => {
        impl<const N: usize> $trait for Lanes<N> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl<const N: usize> $assign_trait for Lanes<N> {
            #[inline(always)]
            fn $assign(&mut self, o: Self) {
                *self = self.zip(o, |a, b| a $op b);
            }
        }
    };
}
lane_op!(Add, add, AddAssign, add_assign, +);
lane_op!(Sub, sub, SubAssign, sub_assign, -);
lane_op!(Mul, mul, MulAssign, mul_assign, *);

impl<const N: usize> Div for Lanes<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        self.zip(o, |a, b| a / b)
    }
}

impl<const N: usize> Neg for Lanes<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        let mut r = self;
        for x in &mut r.0 {
            *x = -*x;
        }
        r
    }
}

impl<const N: usize> num_traits::Zero for Lanes<N> {
    #[inline(always)]
    fn zero() -> Self {
        Self([0.0; N])
    }
    #[inline(always)]
    fn is_zero(&self) -> bool {
        self.0.iter().all(|x| *x == 0.0)
    }
}

impl<const N: usize> num_traits::One for Lanes<N> {
    #[inline(always)]
    fn one() -> Self {
        Self([1.0; N])
    }
}

impl<const N: usize> Real for Lanes<N> {
    const LANES: usize = N;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self([x; N])
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (mut s, mut c) = (self, Self([0.0; N]));
        trig::sin_cos_in_place(&mut s.0, &mut c.0);
        (s, c)
    }
    #[inline(always)]
    fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]) {
        let len = x.len() * N;
        assert!(cos.len() * N >= len);
        // SAFETY: `Lanes<N>` is `repr(transparent)` over `[f64; N]`: a slice of k of them is k N f64s
        let (x, cos) = unsafe {
            (
                std::slice::from_raw_parts_mut(x.as_mut_ptr() as *mut f64, len),
                std::slice::from_raw_parts_mut(cos.as_mut_ptr() as *mut f64, len),
            )
        };
        trig::sin_cos_in_place(x, cos);
    }
    #[inline(always)]
    fn signed_level(self, a: f64, b: f64) -> Self {
        let mut r = self;
        for x in &mut r.0 {
            *x = x.signed_level(a, b);
        }
        r
    }
    #[inline(always)]
    fn lane(self, k: usize) -> f64 {
        self.0[k]
    }
    #[inline(always)]
    fn set_lane(&mut self, k: usize, x: f64) {
        self.0[k] = x;
    }
}

#[cfg(target_arch = "x86_64")]
pub mod x86;

/// The numbers of a slice of lane values, lane after lane of each value (`v[i]` lane k at `i N + k`).
#[inline(always)]
pub fn as_f64s<L: Real>(v: &[L]) -> &[f64] {
    assert_eq!(std::mem::size_of::<L>(), 8 * L::LANES, "a lane type is N f64s");
    // SAFETY: every lane type is `repr(transparent)` over N f64s (size checked above), f64 itself one
    unsafe { std::slice::from_raw_parts(v.as_ptr() as *const f64, v.len() * L::LANES) }
}

/// [`as_f64s`], writable.
#[inline(always)]
pub fn as_f64s_mut<L: Real>(v: &mut [L]) -> &mut [f64] {
    assert_eq!(std::mem::size_of::<L>(), 8 * L::LANES, "a lane type is N f64s");
    // SAFETY: as above
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr() as *mut f64, v.len() * L::LANES) }
}
