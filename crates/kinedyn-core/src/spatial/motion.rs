use super::{cross, Force, Real, Vec3};

/// A spatial motion vector (twist, acceleration or joint axis) at a frame's origin, in its axes:
/// `lin` is the velocity of the body point at the origin, `ang` the angular velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion<T: Real = f64> {
    pub lin: Vec3<T>,
    pub ang: Vec3<T>,
}

impl<T: Real> Default for Motion<T> {
    #[inline(always)]
    fn default() -> Self {
        Self::zero()
    }
}

impl Motion {
    /// `[lin; ang]` as a 6-array.
    #[inline]
    pub fn to_array(&self) -> [f64; 6] {
        [self.lin.x, self.lin.y, self.lin.z, self.ang.x, self.ang.y, self.ang.z]
    }
    #[inline]
    pub fn from_slice(s: &[f64]) -> Self {
        Self::new(Vec3::new(s[0], s[1], s[2]), Vec3::new(s[3], s[4], s[5]))
    }
    /// This constant motion broadcast to every lane of `T`.
    #[inline(always)]
    pub fn splat<T: Real>(&self) -> Motion<T> {
        Motion::new(super::splat3(&self.lin), super::splat3(&self.ang))
    }
}

impl<T: Real> Motion<T> {
    #[inline(always)]
    pub fn new(lin: Vec3<T>, ang: Vec3<T>) -> Self {
        Self { lin, ang }
    }
    #[inline(always)]
    pub fn zero() -> Self {
        Self::new(Vec3::zeros(), Vec3::zeros())
    }
    /// `self x m` (RBDA eq. 2.31): `[w x m_lin + v x m_ang; w x m_ang]`.
    #[inline(always)]
    pub fn cross_motion(&self, m: &Motion<T>) -> Motion<T> {
        Motion::new(
            cross(&self.ang, &m.lin) + cross(&self.lin, &m.ang),
            cross(&self.ang, &m.ang),
        )
    }
    /// `self x* f` (RBDA eq. 2.32): `[w x f_lin; w x f_ang + v x f_lin]`.
    #[inline(always)]
    pub fn cross_force(&self, f: &Force<T>) -> Force<T> {
        Force::new(
            cross(&self.ang, &f.lin),
            cross(&self.ang, &f.ang) + cross(&self.lin, &f.lin),
        )
    }
    /// Power `m . f` of a force on a motion.
    #[inline(always)]
    pub fn dot(&self, f: &Force<T>) -> T {
        self.lin.dot(&f.lin) + self.ang.dot(&f.ang)
    }
}

super::vector_ops!(Motion);
