use super::{Real, Vec3};

/// A spatial force (wrench) about a frame's origin, in its axes: `lin` is the force, `ang` the
/// moment about the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Force<T: Real = f64> {
    pub lin: Vec3<T>,
    pub ang: Vec3<T>,
}

impl<T: Real> Default for Force<T> {
    #[inline(always)]
    fn default() -> Self {
        Self::zero()
    }
}

impl Force {
    #[inline]
    pub fn to_array(&self) -> [f64; 6] {
        [self.lin.x, self.lin.y, self.lin.z, self.ang.x, self.ang.y, self.ang.z]
    }
    #[inline]
    pub fn from_slice(s: &[f64]) -> Self {
        Self::new(Vec3::new(s[0], s[1], s[2]), Vec3::new(s[3], s[4], s[5]))
    }
}

impl<T: Real> Force<T> {
    #[inline(always)]
    pub fn new(lin: Vec3<T>, ang: Vec3<T>) -> Self {
        Self { lin, ang }
    }
    #[inline(always)]
    pub fn zero() -> Self {
        Self::new(Vec3::zeros(), Vec3::zeros())
    }
}

super::vector_ops!(Force);
