use super::Vec3;

/// A spatial force (wrench) about a frame's origin, in its axes: `lin` is the force, `ang` the
/// moment about the origin.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Force {
    pub lin: Vec3,
    pub ang: Vec3,
}

impl Force {
    #[inline]
    pub fn new(lin: Vec3, ang: Vec3) -> Self {
        Self { lin, ang }
    }
    #[inline]
    pub fn zero() -> Self {
        Self::default()
    }
    #[inline]
    pub fn to_array(&self) -> [f64; 6] {
        [self.lin.x, self.lin.y, self.lin.z, self.ang.x, self.ang.y, self.ang.z]
    }
    #[inline]
    pub fn from_slice(s: &[f64]) -> Self {
        Self::new(Vec3::new(s[0], s[1], s[2]), Vec3::new(s[3], s[4], s[5]))
    }
}

super::vector_ops!(Force);
