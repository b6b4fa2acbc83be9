use super::Vec3;
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

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

impl Add for Force {
    type Output = Force;
    #[inline]
    fn add(self, o: Force) -> Force {
        Force::new(self.lin + o.lin, self.ang + o.ang)
    }
}
impl AddAssign for Force {
    #[inline]
    fn add_assign(&mut self, o: Force) {
        self.lin += o.lin;
        self.ang += o.ang;
    }
}
impl Sub for Force {
    type Output = Force;
    #[inline]
    fn sub(self, o: Force) -> Force {
        Force::new(self.lin - o.lin, self.ang - o.ang)
    }
}
impl SubAssign for Force {
    #[inline]
    fn sub_assign(&mut self, o: Force) {
        self.lin -= o.lin;
        self.ang -= o.ang;
    }
}
impl Neg for Force {
    type Output = Force;
    #[inline]
    fn neg(self) -> Force {
        Force::new(-self.lin, -self.ang)
    }
}
impl Mul<f64> for Force {
    type Output = Force;
    #[inline]
    fn mul(self, s: f64) -> Force {
        Force::new(self.lin * s, self.ang * s)
    }
}
