use super::{Force, Vec3};

/// A spatial motion vector (twist, acceleration or joint axis) at a frame's origin, in its axes:
/// `lin` is the velocity of the body point at the origin, `ang` the angular velocity.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    pub lin: Vec3,
    pub ang: Vec3,
}

impl Motion {
    #[inline]
    pub fn new(lin: Vec3, ang: Vec3) -> Self {
        Self { lin, ang }
    }
    #[inline]
    pub fn zero() -> Self {
        Self::default()
    }
    /// `[lin; ang]` as a 6-array.
    #[inline]
    pub fn to_array(&self) -> [f64; 6] {
        [self.lin.x, self.lin.y, self.lin.z, self.ang.x, self.ang.y, self.ang.z]
    }
    #[inline]
    pub fn from_slice(s: &[f64]) -> Self {
        Self::new(Vec3::new(s[0], s[1], s[2]), Vec3::new(s[3], s[4], s[5]))
    }
    /// `self x m` (RBDA eq. 2.31): `[w x m_lin + v x m_ang; w x m_ang]`.
    #[inline]
    pub fn cross_motion(&self, m: &Motion) -> Motion {
        Motion::new(self.ang.cross(&m.lin) + self.lin.cross(&m.ang), self.ang.cross(&m.ang))
    }
    /// `self x* f` (RBDA eq. 2.32): `[w x f_lin; w x f_ang + v x f_lin]`.
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force::new(self.ang.cross(&f.lin), self.ang.cross(&f.ang) + self.lin.cross(&f.lin))
    }
    /// Power `m . f` of a force on a motion.
    #[inline]
    pub fn dot(&self, f: &Force) -> f64 {
        self.lin.dot(&f.lin) + self.ang.dot(&f.ang)
    }
}

super::vector_ops!(Motion);
