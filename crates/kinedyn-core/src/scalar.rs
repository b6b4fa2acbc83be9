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
    /// The same number in every lane.
    fn splat(x: f64) -> Self;
    /// `(sin x, cos x)` per lane ([`crate::trig::sin_cos`]'s numbers).
    fn sin_cos(self) -> (Self, Self);
    /// `x[i] <- sin x[i]`, `cos[i] <- cos x[i]` for every i ([`crate::trig::sin_cos_in_place`]).
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
        crate::trig::sin_cos(self)
    }
    #[inline(always)]
    fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]) {
        // out of line for one state (inlined into the CRBA, the loop cost it 10-15 %)
        crate::trig::sin_cos_in_place_outlined(x, cos);
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
        crate::trig::sin_cos_in_place(&mut s.0, &mut c.0);
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
        crate::trig::sin_cos_in_place(x, cos);
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

/// Lane types on x86-64's vector registers (AVX2: 4 lanes, AVX-512: 8), their arithmetic written
/// with the intrinsics: relying on LLVM to vectorise `[f64; 8]` loops split values across
/// register widths and spilled (measured: AVX-512 slower than AVX2). Used only inside functions
/// compiled with the matching target features (`crate::batch`), where the intrinsics inline.
#[cfg(target_arch = "x86_64")]
pub mod x86 {
    use super::Real;
    use std::arch::x86_64::*;
    use std::fmt::Debug;
    use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

    macro_rules! lane_type {
        ($name:ident, $reg:ty, $n:literal, $add:ident, $sub:ident, $mul:ident, $div:ident, $set1:ident, $xor:ident, $setzero:ident) => {
            /// Lanes of f64 in one vector register.
            #[derive(Clone, Copy)]
            #[repr(transparent)]
            pub struct $name(pub $reg);

            impl $name {
                #[inline(always)]
                pub fn to_array(self) -> [f64; $n] {
                    // SAFETY: same size, any bit pattern is valid for both
                    unsafe { std::mem::transmute::<$reg, [f64; $n]>(self.0) }
                }
                #[inline(always)]
                pub fn from_array(a: [f64; $n]) -> Self {
                    // SAFETY: as above
                    Self(unsafe { std::mem::transmute::<[f64; $n], $reg>(a) })
                }
            }
            impl Debug for $name {
                fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                    self.to_array().fmt(f)
                }
            }
            impl PartialEq for $name {
                #[inline(always)]
                fn eq(&self, o: &Self) -> bool {
                    self.to_array() == o.to_array()
                }
            }
            impl Default for $name {
                #[inline(always)]
                fn default() -> Self {
                    // SAFETY (every intrinsic below): the type is only used in functions compiled
                    // with the feature it needs (`crate::batch`), on CPUs that have it
                    Self(unsafe { $setzero() })
                }
            }
            impl Add for $name {
                type Output = Self;
                #[inline(always)]
                fn add(self, o: Self) -> Self {
                    Self(unsafe { $add(self.0, o.0) })
                }
            }
            impl Sub for $name {
                type Output = Self;
                #[inline(always)]
                fn sub(self, o: Self) -> Self {
                    Self(unsafe { $sub(self.0, o.0) })
                }
            }
            impl Mul for $name {
                type Output = Self;
                #[inline(always)]
                fn mul(self, o: Self) -> Self {
                    Self(unsafe { $mul(self.0, o.0) })
                }
            }
            impl Div for $name {
                type Output = Self;
                #[inline(always)]
                fn div(self, o: Self) -> Self {
                    Self(unsafe { $div(self.0, o.0) })
                }
            }
            impl Neg for $name {
                type Output = Self;
                #[inline(always)]
                fn neg(self) -> Self {
                    // flip the sign bit (as f64's unary minus does, zeros included)
                    Self(unsafe { $xor(self.0, $set1(-0.0)) })
                }
            }
            impl AddAssign for $name {
                #[inline(always)]
                fn add_assign(&mut self, o: Self) {
                    *self = *self + o;
                }
            }
            impl SubAssign for $name {
                #[inline(always)]
                fn sub_assign(&mut self, o: Self) {
                    *self = *self - o;
                }
            }
            impl MulAssign for $name {
                #[inline(always)]
                fn mul_assign(&mut self, o: Self) {
                    *self = *self * o;
                }
            }
            impl num_traits::Zero for $name {
                #[inline(always)]
                fn zero() -> Self {
                    Self::default()
                }
                #[inline(always)]
                fn is_zero(&self) -> bool {
                    self.to_array().iter().all(|x| *x == 0.0)
                }
            }
            impl num_traits::One for $name {
                #[inline(always)]
                fn one() -> Self {
                    Self::splat(1.0)
                }
            }
            // SAFETY: plain numbers
            unsafe impl Send for $name {}
            unsafe impl Sync for $name {}
            impl Real for $name {
                const LANES: usize = $n;
                #[inline(always)]
                fn splat(x: f64) -> Self {
                    Self(unsafe { $set1(x) })
                }
                #[inline(always)]
                fn sin_cos(self) -> (Self, Self) {
                    let (mut s, mut c) = (self.to_array(), [0.0; $n]);
                    crate::trig::sin_cos_in_place(&mut s, &mut c);
                    (Self::from_array(s), Self::from_array(c))
                }
                #[inline(always)]
                fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]) {
                    let len = x.len() * $n;
                    assert!(cos.len() * $n >= len);
                    // SAFETY: the register type is `[f64; N]` in memory
                    let (x, cos) = unsafe {
                        (
                            std::slice::from_raw_parts_mut(x.as_mut_ptr() as *mut f64, len),
                            std::slice::from_raw_parts_mut(cos.as_mut_ptr() as *mut f64, len),
                        )
                    };
                    crate::trig::sin_cos_in_place(x, cos);
                }
                #[inline(always)]
                fn signed_level(self, a: f64, b: f64) -> Self {
                    self.select_signed(a, b)
                }
                #[inline(always)]
                fn lane(self, k: usize) -> f64 {
                    self.to_array()[k]
                }
                #[inline(always)]
                fn set_lane(&mut self, k: usize, x: f64) {
                    let mut a = self.to_array();
                    a[k] = x;
                    *self = Self::from_array(a);
                }
            }
        };
    }

    impl F64x4 {
        /// `a` where > 0, `-b` where < 0, else 0 (NaN included), by compare masks and blends.
        #[inline(always)]
        fn select_signed(self, a: f64, b: f64) -> Self {
            // SAFETY: AVX, as for every operation of this type
            unsafe {
                let zero = _mm256_setzero_pd();
                let positive = _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, zero);
                let negative = _mm256_cmp_pd::<_CMP_LT_OQ>(self.0, zero);
                let r = _mm256_blendv_pd(zero, _mm256_set1_pd(a), positive);
                Self(_mm256_blendv_pd(r, _mm256_set1_pd(-b), negative))
            }
        }
    }

    impl F64x8 {
        /// `a` where > 0, `-b` where < 0, else 0 (NaN included), by compare masks and blends.
        #[inline(always)]
        fn select_signed(self, a: f64, b: f64) -> Self {
            // SAFETY: AVX-512F, as for every operation of this type
            unsafe {
                let zero = _mm512_setzero_pd();
                let positive = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, zero);
                let negative = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(self.0, zero);
                let r = _mm512_mask_blend_pd(positive, zero, _mm512_set1_pd(a));
                Self(_mm512_mask_blend_pd(negative, r, _mm512_set1_pd(-b)))
            }
        }
    }

    lane_type!(
        F64x4,
        __m256d,
        4,
        _mm256_add_pd,
        _mm256_sub_pd,
        _mm256_mul_pd,
        _mm256_div_pd,
        _mm256_set1_pd,
        _mm256_xor_pd,
        _mm256_setzero_pd
    );
    lane_type!(
        F64x8,
        __m512d,
        8,
        _mm512_add_pd,
        _mm512_sub_pd,
        _mm512_mul_pd,
        _mm512_div_pd,
        _mm512_set1_pd,
        _mm512_xor_pd,
        _mm512_setzero_pd
    );
}

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
