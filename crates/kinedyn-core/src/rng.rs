//! A small seeded generator: SplitMix64 (Steele, Lea & Flood 2014), used by the IK solver's
//! random restarts and by the seeded test models, so neither needs an external RNG crate.

use crate::joint::axis_angle;
use crate::spatial::{Mat3, Vec3};

/// SplitMix64: deterministic for a seed, on every platform.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub fn vec3(&mut self, lo: f64, hi: f64) -> Vec3 {
        Vec3::new(self.uniform(lo, hi), self.uniform(lo, hi), self.uniform(lo, hi))
    }
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec3(-1.0, 1.0);
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
    pub fn rotation(&mut self) -> Mat3 {
        let axis = self.unit();
        axis_angle(&axis, self.uniform(-std::f64::consts::PI, std::f64::consts::PI))
    }
    pub fn vector(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(lo, hi)).collect()
    }
}
