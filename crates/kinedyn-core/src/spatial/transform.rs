use super::{cross, mm, mtv, mv, Force, Inertia, Mat3, Motion, Real, Vec3};
use std::ops::Mul;

/// A rigid transform `a_from_b`: the pose of frame b in frame a, `p_a = rot * p_b + trans`.
///
/// Named by its frames at every use (`world_from_body`, `parent_from_joint`). Featherstone's
/// motion transform `^B X_A` (RBDA eq. 2.24) is `a_from_b.inverse()` acting on motions; the
/// `act_*` methods map a quantity given in b's coordinates into a's, the `inv_act_*` back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform<T: Real = f64> {
    pub rot: Mat3<T>,
    pub trans: Vec3<T>,
}

impl<T: Real> Default for Transform<T> {
    fn default() -> Self {
        Self::identity()
    }
}

impl Transform {
    /// This constant transform broadcast to every lane of `T`.
    #[inline(always)]
    pub fn splat<T: Real>(&self) -> Transform<T> {
        Transform::new(super::splat33(&self.rot), super::splat3(&self.trans))
    }
    /// From a row-major 4x4 homogeneous matrix (the bottom row is not read).
    pub fn from_homogeneous(m: &[f64]) -> Self {
        Self::new(
            Mat3::new(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]),
            Vec3::new(m[3], m[7], m[11]),
        )
    }
    /// Row-major 4x4 homogeneous matrix.
    pub fn to_homogeneous(&self) -> [f64; 16] {
        let (r, t) = (&self.rot, &self.trans);
        [
            r[(0, 0)],
            r[(0, 1)],
            r[(0, 2)],
            t.x,
            r[(1, 0)],
            r[(1, 1)],
            r[(1, 2)],
            t.y,
            r[(2, 0)],
            r[(2, 1)],
            r[(2, 2)],
            t.z,
            0.0,
            0.0,
            0.0,
            1.0,
        ]
    }
}

impl<T: Real> Transform<T> {
    #[inline(always)]
    pub fn new(rot: Mat3<T>, trans: Vec3<T>) -> Self {
        Self { rot, trans }
    }
    #[inline(always)]
    pub fn identity() -> Self {
        Self::new(Mat3::identity(), Vec3::zeros())
    }
    /// `b_from_a`.
    #[inline(always)]
    pub fn inverse(&self) -> Self {
        Self::new(self.rot.transpose(), -mtv(&self.rot, &self.trans))
    }
    /// A point given in b, in a.
    #[inline(always)]
    pub fn act_point(&self, p: &Vec3<T>) -> Vec3<T> {
        mv(&self.rot, p) + self.trans
    }
    /// A motion given in b's frame, expressed in a's: `w_a = R w_b`, `v_a = R v_b + t x w_a`.
    #[inline(always)]
    pub fn act_motion(&self, m: &Motion<T>) -> Motion<T> {
        let ang = mv(&self.rot, &m.ang);
        Motion::new(mv(&self.rot, &m.lin) + cross(&self.trans, &ang), ang)
    }
    /// A motion given in a's frame, expressed in b's (RBDA's `^B X_A m`).
    #[inline(always)]
    pub fn inv_act_motion(&self, m: &Motion<T>) -> Motion<T> {
        Motion::new(
            mtv(&self.rot, &(m.lin - cross(&self.trans, &m.ang))),
            mtv(&self.rot, &m.ang),
        )
    }
    /// A force given in b's frame, expressed in a's: `f_a = R f_b`, `n_a = R n_b + t x f_a`.
    #[inline(always)]
    pub fn act_force(&self, f: &Force<T>) -> Force<T> {
        let lin = mv(&self.rot, &f.lin);
        Force::new(lin, mv(&self.rot, &f.ang) + cross(&self.trans, &lin))
    }
    /// A force given in a's frame, expressed in b's (RBDA's `^B X_A^* f`).
    #[inline(always)]
    pub fn inv_act_force(&self, f: &Force<T>) -> Force<T> {
        Force::new(
            mtv(&self.rot, &f.lin),
            mtv(&self.rot, &(f.ang - cross(&self.trans, &f.lin))),
        )
    }
    /// A rigid-body inertia given in b's frame, expressed in a's (RBDA eq. 2.66).
    #[inline(always)]
    pub fn act_inertia(&self, i: &Inertia<T>) -> Inertia<T> {
        i.rotated(&self.rot).translated(&self.trans)
    }
    /// A rigid-body inertia given in a's frame, expressed in b's.
    #[inline(always)]
    pub fn inv_act_inertia(&self, i: &Inertia<T>) -> Inertia<T> {
        self.inverse().act_inertia(i)
    }
}

impl<T: Real> Mul for Transform<T> {
    type Output = Transform<T>;
    /// `a_from_b * b_from_c = a_from_c`.
    // composition: (R_ab, p_ab) (R_bc, p_bc) = (R_ab R_bc, R_ab p_bc + p_ab), a sum inside a product
    #[allow(clippy::suspicious_arithmetic_impl)]
    #[inline(always)]
    fn mul(self, o: Transform<T>) -> Transform<T> {
        Transform::new(mm(&self.rot, &o.rot), mv(&self.rot, &o.trans) + self.trans)
    }
}

impl<T: Real> Mul<&Transform<T>> for &Transform<T> {
    type Output = Transform<T>;
    // composition, as for values
    #[allow(clippy::suspicious_arithmetic_impl)]
    #[inline(always)]
    fn mul(self, o: &Transform<T>) -> Transform<T> {
        Transform::new(mm(&self.rot, &o.rot), mv(&self.rot, &o.trans) + self.trans)
    }
}
