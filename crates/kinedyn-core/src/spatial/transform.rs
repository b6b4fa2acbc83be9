use super::{Force, Inertia, Mat3, Motion, Vec3};
use std::ops::Mul;

/// A rigid transform `a_from_b`: the pose of frame b in frame a, `p_a = rot * p_b + trans`.
///
/// Named by its frames at every use (`world_from_body`, `parent_from_joint`). Featherstone's
/// motion transform `^B X_A` (RBDA eq. 2.24) is `a_from_b.inverse()` acting on motions; the
/// `act_*` methods map a quantity given in b's coordinates into a's, the `inv_act_*` back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub rot: Mat3,
    pub trans: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::identity()
    }
}

impl Transform {
    #[inline]
    pub fn new(rot: Mat3, trans: Vec3) -> Self {
        Self { rot, trans }
    }
    #[inline]
    pub fn identity() -> Self {
        Self::new(Mat3::identity(), Vec3::zeros())
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
            r[(0, 0)], r[(0, 1)], r[(0, 2)], t.x,
            r[(1, 0)], r[(1, 1)], r[(1, 2)], t.y,
            r[(2, 0)], r[(2, 1)], r[(2, 2)], t.z,
            0.0, 0.0, 0.0, 1.0,
        ]
    }
    /// `b_from_a`.
    #[inline]
    pub fn inverse(&self) -> Self {
        let rt = self.rot.transpose();
        Self::new(rt, -(rt * self.trans))
    }
    /// A point given in b, in a.
    #[inline]
    pub fn act_point(&self, p: &Vec3) -> Vec3 {
        self.rot * p + self.trans
    }
    /// A motion given in b's frame, expressed in a's: `w_a = R w_b`, `v_a = R v_b + t x w_a`.
    #[inline]
    pub fn act_motion(&self, m: &Motion) -> Motion {
        let ang = self.rot * m.ang;
        Motion::new(self.rot * m.lin + self.trans.cross(&ang), ang)
    }
    /// A motion given in a's frame, expressed in b's (RBDA's `^B X_A m`).
    #[inline]
    pub fn inv_act_motion(&self, m: &Motion) -> Motion {
        let rt = self.rot.transpose();
        Motion::new(rt * (m.lin - self.trans.cross(&m.ang)), rt * m.ang)
    }
    /// A force given in b's frame, expressed in a's: `f_a = R f_b`, `n_a = R n_b + t x f_a`.
    #[inline]
    pub fn act_force(&self, f: &Force) -> Force {
        let lin = self.rot * f.lin;
        Force::new(lin, self.rot * f.ang + self.trans.cross(&lin))
    }
    /// A force given in a's frame, expressed in b's (RBDA's `^B X_A^* f`).
    #[inline]
    pub fn inv_act_force(&self, f: &Force) -> Force {
        let rt = self.rot.transpose();
        Force::new(rt * f.lin, rt * (f.ang - self.trans.cross(&f.lin)))
    }
    /// A rigid-body inertia given in b's frame, expressed in a's (RBDA eq. 2.66).
    #[inline]
    pub fn act_inertia(&self, i: &Inertia) -> Inertia {
        i.rotated(&self.rot).translated(&self.trans)
    }
    /// A rigid-body inertia given in a's frame, expressed in b's.
    #[inline]
    pub fn inv_act_inertia(&self, i: &Inertia) -> Inertia {
        self.inverse().act_inertia(i)
    }
}

impl Mul for Transform {
    type Output = Transform;
    /// `a_from_b * b_from_c = a_from_c`.
    #[inline]
    fn mul(self, o: Transform) -> Transform {
        Transform::new(self.rot * o.rot, self.rot * o.trans + self.trans)
    }
}

impl Mul<&Transform> for &Transform {
    type Output = Transform;
    #[inline]
    fn mul(self, o: &Transform) -> Transform {
        Transform::new(self.rot * o.rot, self.rot * o.trans + self.trans)
    }
}
