//! Lane types on x86-64's vector registers (AVX2: 4 lanes, AVX-512: 8), their arithmetic written
//! with the intrinsics: relying on LLVM to vectorise `[f64; 8]` loops split values across
//! register widths and spilled (measured: AVX-512 slower than AVX2). Used only inside functions
//! compiled with the matching target features (`crate::batch`), where the intrinsics inline.

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
                super::trig::sin_cos_in_place(&mut s, &mut c);
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
                super::trig::sin_cos_in_place(x, cos);
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
