use super::{Force, Inertia, Mat3, Motion, Transform, Vec3};
use crate::joint::{Joint, JointKind};

/// A symmetric 6x6 articulated-body inertia (RBDA §7.2), kept as three 3x3 blocks in our
/// `[linear; angular]` order: `f = IA m` is `f.lin = a m.lin + b m.ang`,
/// `f.ang = b^T m.lin + c m.ang` (`a`, `c` symmetric). A rigid body is the special case
/// `a = m 1`, `b = -[h]x`, `c = I_o`; an articulated inertia leaves that 10-parameter family once
/// a joint's `U D^-1 U^T` is removed, so it needs its own type.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ArticulatedInertia {
    pub a: Mat3,
    pub b: Mat3,
    pub c: Mat3,
}

impl From<&Inertia> for ArticulatedInertia {
    #[inline]
    fn from(i: &Inertia) -> Self {
        let h = &i.h;
        Self {
            a: Mat3::from_diagonal_element(i.mass),
            // b = -[h]x
            b: Mat3::new(0.0, h.z, -h.y, -h.z, 0.0, h.x, h.y, -h.x, 0.0),
            c: i.i_o,
        }
    }
}

impl ArticulatedInertia {
    /// `IA m`.
    #[inline]
    pub fn mul_motion(&self, m: &Motion) -> Force {
        Force::new(self.a * m.lin + self.b * m.ang, self.b.tr_mul(&m.lin) + self.c * m.ang)
    }
    /// `IA s` for a joint's subspace: revolute `s = [0; a]` gives `[b a; c a]`, prismatic
    /// `s = [a; 0]` gives `[a_blk a; b^T a]` (half the work of a general product).
    #[inline]
    pub fn times_s(&self, joint: &Joint) -> Force {
        let ax = &joint.axis;
        match joint.kind {
            JointKind::Revolute => Force::new(self.b * ax, self.c * ax),
            JointKind::Prismatic => Force::new(self.a * ax, self.b.tr_mul(ax)),
        }
    }
    /// `IA - u u^T / d` (RBDA Table 7.1's `I^a = I^A - U D^-1 U^T`), `u` the force `U = IA s`.
    #[inline]
    pub fn sub_rank_one(&self, u: &Force, d_inv: f64) -> Self {
        let ul = u.lin * d_inv;
        let ua = u.ang * d_inv;
        Self { a: self.a - ul * u.lin.transpose(), b: self.b - ul * u.ang.transpose(), c: self.c - ua * u.ang.transpose() }
    }
    /// Trace of the 6x6 matrix (a scale for singularity tests; >= 0 for a positive semidefinite IA).
    #[inline]
    pub fn trace(&self) -> f64 {
        self.a.trace() + self.c.trace()
    }
}

impl Transform {
    /// An articulated inertia given in b's frame, expressed in a's: `X^* IA X^-1` (RBDA eq. 2.66
    /// for a general symmetric 6x6). With rotated blocks `A = R a R^T`, `B = R b R^T`,
    /// `C = R c R^T` and `T = [t]x`: `a' = A`, `b' = B - A T`, `c' = C + T B - B^T T - T A T`.
    #[inline]
    pub fn act_articulated(&self, ia: &ArticulatedInertia) -> ArticulatedInertia {
        let r = &self.rot;
        let t = &self.trans;
        // A = R a R^T and C = R c R^T are symmetric (6 entries each); B = R b R^T is not
        let ra = rotate_symmetric(r, &ia.a);
        let rb = r * ia.b * r.transpose();
        let rc = rotate_symmetric(r, &ia.c);
        // products with T = [t]x as column-wise cross products (T M = [t x m_0, t x m_1, t x m_2]);
        // A T = -(T A)^T for a symmetric A
        let at = -cross_columns(t, &ra).transpose();
        let tb = cross_columns(t, &rb);
        let tat = cross_columns(t, &at);
        ArticulatedInertia { a: ra, b: rb - at, c: rc + tb + tb.transpose() - tat }
    }
}

/// `[t]x m` column by column.
#[inline]
fn cross_columns(t: &Vec3, m: &Mat3) -> Mat3 {
    Mat3::from_columns(&[t.cross(&m.column(0).into_owned()), t.cross(&m.column(1).into_owned()), t.cross(&m.column(2).into_owned())])
}

/// `R S R^T` for a symmetric `S`: `A = R S`, then the 6 distinct entries `A_i . R_j`.
#[inline]
fn rotate_symmetric(r: &Mat3, s: &Mat3) -> Mat3 {
    let a = r * s;
    let e = |i: usize, j: usize| a[(i, 0)] * r[(j, 0)] + a[(i, 1)] * r[(j, 1)] + a[(i, 2)] * r[(j, 2)];
    let (xx, xy, xz, yy, yz, zz) = (e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2));
    Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
}
