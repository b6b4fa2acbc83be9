use super::{cross, mm, mmt, mtv, mv, outer, Force, Inertia, Mat3, Motion, Real, Transform, Vec3};
use crate::joint::{Joint, JointKind};

/// A symmetric 6x6 articulated-body inertia (RBDA §7.2), kept as three 3x3 blocks in our
/// `[linear; angular]` order: `f = IA m` is `f.lin = a m.lin + b m.ang`,
/// `f.ang = b^T m.lin + c m.ang` (`a`, `c` symmetric). A rigid body is the special case
/// `a = m 1`, `b = -[h]x`, `c = I_o`; an articulated inertia leaves that 10-parameter family once
/// a joint's `U D^-1 U^T` is removed, so it needs its own type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArticulatedInertia<T: Real = f64> {
    pub a: Mat3<T>,
    pub b: Mat3<T>,
    pub c: Mat3<T>,
}

impl<T: Real> Default for ArticulatedInertia<T> {
    #[inline(always)]
    fn default() -> Self {
        Self {
            a: Mat3::zeros(),
            b: Mat3::zeros(),
            c: Mat3::zeros(),
        }
    }
}

impl<T: Real> From<&Inertia<T>> for ArticulatedInertia<T> {
    #[inline(always)]
    fn from(i: &Inertia<T>) -> Self {
        let h = &i.h;
        let z = T::zero();
        Self {
            a: Mat3::from_diagonal_element(i.mass),
            // b = -[h]x
            b: Mat3::new(z, h.z, -h.y, -h.z, z, h.x, h.y, -h.x, z),
            c: i.i_o,
        }
    }
}

impl<T: Real> ArticulatedInertia<T> {
    /// `IA m`.
    #[inline(always)]
    pub fn mul_motion(&self, m: &Motion<T>) -> Force<T> {
        Force::new(
            mv(&self.a, &m.lin) + mv(&self.b, &m.ang),
            mtv(&self.b, &m.lin) + mv(&self.c, &m.ang),
        )
    }
    /// `IA s` for a joint's subspace: revolute `s = [0; a]` gives `[b a; c a]`, prismatic
    /// `s = [a; 0]` gives `[a_blk a; b^T a]` (half the work of a general product).
    #[inline(always)]
    pub fn times_s(&self, joint: &Joint) -> Force<T> {
        let ax = &super::splat3::<T>(&joint.axis);
        match joint.kind {
            JointKind::Revolute => Force::new(mv(&self.b, ax), mv(&self.c, ax)),
            JointKind::Prismatic => Force::new(mv(&self.a, ax), mtv(&self.b, ax)),
        }
    }
    /// `IA - u u^T / d` (RBDA Table 7.1's `I^a = I^A - U D^-1 U^T`), `u` the force `U = IA s`.
    #[inline(always)]
    pub fn sub_rank_one(&self, u: &Force<T>, d_inv: T) -> Self {
        let ul = u.lin * d_inv;
        let ua = u.ang * d_inv;
        Self {
            a: self.a - outer(&ul, &u.lin),
            b: self.b - outer(&ul, &u.ang),
            c: self.c - outer(&ua, &u.ang),
        }
    }
    /// Trace of the 6x6 matrix (a scale for singularity tests; >= 0 for a positive semidefinite IA).
    #[inline(always)]
    pub fn trace(&self) -> T {
        self.a.trace() + self.c.trace()
    }
}

impl<T: Real> Transform<T> {
    /// An articulated inertia given in b's frame, expressed in a's: `X^* IA X^-1` (RBDA eq. 2.66
    /// for a general symmetric 6x6). With rotated blocks `A = R a R^T`, `B = R b R^T`,
    /// `C = R c R^T` and `T = [t]x`: `a' = A`, `b' = B - A T`, `c' = C + T B - B^T T - T A T`.
    #[inline(always)]
    pub fn act_articulated(&self, ia: &ArticulatedInertia<T>) -> ArticulatedInertia<T> {
        let r = &self.rot;
        let t = &self.trans;
        // A = R a R^T and C = R c R^T are symmetric (6 entries each); B = R b R^T is not
        let ra = rotate_symmetric(r, &ia.a);
        let rb = mmt(&mm(r, &ia.b), r);
        let rc = rotate_symmetric(r, &ia.c);
        // products with T = [t]x as column-wise cross products (T M = [t x m_0, t x m_1, t x m_2]);
        // A T = -(T A)^T for a symmetric A
        let at = -cross_columns(t, &ra).transpose();
        let tb = cross_columns(t, &rb);
        let tat = cross_columns(t, &at);
        ArticulatedInertia {
            a: ra,
            b: rb - at,
            c: rc + tb + tb.transpose() - tat,
        }
    }
}

/// `[t]x m` column by column.
#[inline(always)]
fn cross_columns<T: Real>(t: &Vec3<T>, m: &Mat3<T>) -> Mat3<T> {
    let c0 = cross(t, &Vec3::new(m[(0, 0)], m[(1, 0)], m[(2, 0)]));
    let c1 = cross(t, &Vec3::new(m[(0, 1)], m[(1, 1)], m[(2, 1)]));
    let c2 = cross(t, &Vec3::new(m[(0, 2)], m[(1, 2)], m[(2, 2)]));
    Mat3::new(c0.x, c1.x, c2.x, c0.y, c1.y, c2.y, c0.z, c1.z, c2.z)
}

/// `R S R^T` for a symmetric `S`: `A = R S`, then the 6 distinct entries `A_i . R_j`.
#[inline(always)]
fn rotate_symmetric<T: Real>(r: &Mat3<T>, s: &Mat3<T>) -> Mat3<T> {
    let a = mm(r, s);
    let e = |i: usize, j: usize| a[(i, 0)] * r[(j, 0)] + a[(i, 1)] * r[(j, 1)] + a[(i, 2)] * r[(j, 2)];
    let (xx, xy, xz, yy, yz, zz) = (e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2));
    Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
}
