//! `sin_cos(x)` for joint angles: one argument reduction and two short polynomials, without the
//! rounding-mode save/restore of the C library's `sincos` (about 130 instructions there, a sixth of
//! an RNEA call). Within 2 ulp of `f64::sin_cos` (tested below); `|x| >= 1e5` or non-finite `x`
//! fall back to the standard library.
//!
//! Method (Cody & Waite, *Software Manual for the Elementary Functions*, 1980; the polynomial
//! kernels of Sun's fdlibm `__kernel_sin`/`__kernel_cos`): `x = k pi/2 + r` with `|r| <= pi/4`,
//! `pi/2` split in three parts so that `k * part` is exact; then `sin r`, `cos r` by minimax
//! polynomials in `z = r^2`, and the quadrant `k mod 4` swaps and negates them.

// The constants keep the digits fdlibm prints for them (e_rem_pio2.c, k_sin.c, k_cos.c), so that
// they can be checked against the source; each literal is the double fdlibm's hex words give.
#![allow(clippy::excessive_precision)]

// pi/2 = PIO2_1 + PIO2_2 + PIO2_3, the first two with 33 significant bits (k PIO2_i exact for |k| < 2^20)
pub(crate) const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
pub(crate) const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
pub(crate) const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;
pub(crate) const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI; // fdlibm's invpio2 6.36619772367581382433e-01, the same double
                                                                 // sin r = r + r z (S1 + z (S2 + ... + z S6))
pub(crate) const S1: f64 = -1.666_666_666_666_663_243_48e-01;
pub(crate) const S2: f64 = 8.333_333_333_322_489_461_24e-03;
pub(crate) const S3: f64 = -1.984_126_982_985_794_931_34e-04;
pub(crate) const S4: f64 = 2.755_731_370_707_006_767_89e-06;
pub(crate) const S5: f64 = -2.505_076_025_340_686_341_95e-08;
pub(crate) const S6: f64 = 1.589_690_995_211_550_102_21e-10;
// cos r = 1 - z/2 + z^2 (C1 + z (C2 + ... + z C6))
pub(crate) const C1: f64 = 4.166_666_666_666_660_190_37e-02;
pub(crate) const C2: f64 = -1.388_888_888_887_410_957_49e-03;
pub(crate) const C3: f64 = 2.480_158_728_947_672_941_78e-05;
pub(crate) const C4: f64 = -2.755_731_435_139_066_330_35e-07;
pub(crate) const C5: f64 = 2.087_572_321_298_174_827_90e-09;
pub(crate) const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `(sin x, cos x)`.
// `!(|x| < LIMIT)` also sends NaN to the standard library, in one comparison
#[allow(clippy::neg_cmp_op_on_partial_ord)]
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if !(x.abs() < LIMIT) {
        return x.sin_cos();
    }
    reduced_sin_cos(x)
}

/// `x[i] <- sin x[i]`, `cos[i] <- cos x[i]` for every i: the same numbers as [`sin_cos`], in a
/// branch-free loop the compiler vectorises when every `|x| < 1e5` (joint angles always are).
#[inline(always)]
pub fn sin_cos_in_place(x: &mut [f64], cos: &mut [f64]) {
    let cos = &mut cos[..x.len()];
    if x.iter().all(|v| v.abs() < LIMIT) {
        for (v, c) in x.iter_mut().zip(cos.iter_mut()) {
            (*v, *c) = reduced_sin_cos(*v);
        }
    } else {
        for (v, c) in x.iter_mut().zip(cos.iter_mut()) {
            (*v, *c) = sin_cos(*v);
        }
    }
}

/// [`sin_cos_in_place`] as a function of its own (the single-state algorithms call it so).
#[inline(never)]
pub fn sin_cos_in_place_outlined(x: &mut [f64], cos: &mut [f64]) {
    sin_cos_in_place(x, cos);
}

/// Inputs at least this large (or non-finite) go to the standard library.
const LIMIT: f64 = 1e5;

/// The kernel, for `|x| < 1e5`: no branches, no float-to-integer conversion.
#[inline(always)]
fn reduced_sin_cos(x: f64) -> (f64, f64) {
    // x = k pi/2 + r, k the nearest integer: adding 1.5 2^52 rounds to an integer (without a call
    // to `round`, which baseline x86-64 lacks as an instruction), and leaves k mod 4 in the two
    // lowest bits of the sum (its unit in the last place is 1, its mantissa 2^51 + k)
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let shifted = x * TWO_OVER_PI + ROUND;
    let k_bits = shifted.to_bits();
    let k = shifted - ROUND;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let z = r * r;
    // sin r, cos r on |r| <= pi/4 (fdlibm's kernels with a zero tail)
    let sin_r = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let poly_c = z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let cos_r = w + (((1.0 - w) - hz) + poly_c);
    // quadrant k mod 4: (sin, cos) of x is (s, c), (c, -s), (-s, -c), (-c, s) for k = 0..3,
    // chosen with bit masks (joint angles of a batch make the quadrant unpredictable to a branch)
    let swap = (k_bits & 1).wrapping_neg();
    let (sb, cb) = (sin_r.to_bits(), cos_r.to_bits());
    let sin_bits = ((cb & swap) | (sb & !swap)) ^ ((k_bits & 2) << 62);
    let cos_bits = ((sb & swap) | (cb & !swap)) ^ ((k_bits.wrapping_add(1) & 2) << 62);
    (f64::from_bits(sin_bits), f64::from_bits(cos_bits))
}

#[cfg(test)]
mod tests {
    use super::{sin_cos, sin_cos_in_place};

    fn ulps(a: f64, b: f64) -> f64 {
        // distance in units of the last place of b (at least the smallest normal's ulp)
        let ulp = (b.abs().max(f64::MIN_POSITIVE) * f64::EPSILON).max(f64::EPSILON * 1e-300);
        (a - b).abs() / ulp
    }

    #[test]
    fn within_two_ulps_of_the_standard_library() {
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst: f64 = 0.0;
        let mut xs: Vec<f64> = (0..400_000).map(|_| (next() - 0.5) * 40.0).collect();
        xs.extend((0..50_000).map(|_| (next() - 0.5) * 2e5));
        xs.extend((-64..=64).map(|k| k as f64 * std::f64::consts::FRAC_PI_2));
        xs.extend([0.0, -0.0, 1e-300, -1e-300, 1e-8, 3.0, 1e5, -1e5, 1e7, f64::MAX]);
        for x in xs {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            // near a zero of sin or cos compare absolutely (the reduction is accurate to ~1e-30)
            let es = if s0.abs() < 1e-12 {
                (s - s0).abs() / f64::EPSILON
            } else {
                ulps(s, s0)
            };
            let ec = if c0.abs() < 1e-12 {
                (c - c0).abs() / f64::EPSILON
            } else {
                ulps(c, c0)
            };
            worst = worst.max(es).max(ec);
            assert!(
                es <= 2.0 && ec <= 2.0,
                "x = {x:e}: sin {s:e} vs {s0:e} ({es} ulp), cos {c:e} vs {c0:e} ({ec} ulp)"
            );
        }
        assert!(worst > 0.0, "the test should see some rounding differences");
    }

    /// The slice form gives the scalar form's numbers, in range and with a fallback element.
    #[test]
    fn in_place_equals_scalar() {
        for xs in [
            vec![0.3f64, -2.0, 7.5, 1e4, -3.1, 0.0, 2.2],
            vec![0.3, 2e5, -1.0, f64::NAN],
        ] {
            let (mut s, mut c) = (xs.clone(), vec![0.0; xs.len()]);
            sin_cos_in_place(&mut s, &mut c);
            for (k, &x) in xs.iter().enumerate() {
                let (s0, c0) = sin_cos(x);
                assert!(
                    s[k].to_bits() == s0.to_bits() && c[k].to_bits() == c0.to_bits() || x.is_nan() && s[k].is_nan(),
                    "{x}"
                );
            }
        }
    }

    #[test]
    fn non_finite_inputs_follow_the_standard_library() {
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::INFINITY).1.is_nan());
    }
}
