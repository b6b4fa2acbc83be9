use super::{cross, mm, mv, Force, Mat3, Motion, Real, Vec3};
use std::ops::{Add, AddAssign};

/// Rigid-body spatial inertia about a frame's origin (RBDA eq. 2.63), stored by its
/// 10 parameters: mass `m`, first moment `h = m c` and the rotational inertia `i_o` about the
/// origin (not about the centre of mass), all in the frame's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia<T: Real = f64> {
    pub mass: T,
    pub h: Vec3<T>,
    pub i_o: Mat3<T>,
}

impl<T: Real> Default for Inertia<T> {
    #[inline(always)]
    fn default() -> Self {
        Self::zero()
    }
}

impl Inertia {
    /// From `[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` about the origin (Pinocchio's order).
    pub fn from_parameters(p: &[f64]) -> Self {
        Self::new(
            p[0],
            Vec3::new(p[1], p[2], p[3]),
            Mat3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]),
        )
    }
    pub fn to_parameters(&self) -> [f64; 10] {
        let i = &self.i_o;
        [
            self.mass,
            self.h.x,
            self.h.y,
            self.h.z,
            i[(0, 0)],
            i[(0, 1)],
            i[(1, 1)],
            i[(0, 2)],
            i[(1, 2)],
            i[(2, 2)],
        ]
    }
    /// This constant inertia broadcast to every lane of `T`.
    #[inline(always)]
    pub fn splat<T: Real>(&self) -> Inertia<T> {
        Inertia::new(T::splat(self.mass), super::splat3(&self.h), super::splat33(&self.i_o))
    }
}

impl<T: Real> Inertia<T> {
    #[inline(always)]
    pub fn new(mass: T, h: Vec3<T>, i_o: Mat3<T>) -> Self {
        Self { mass, h, i_o }
    }
    #[inline(always)]
    pub fn zero() -> Self {
        Self::new(T::zero(), Vec3::zeros(), Mat3::zeros())
    }
    /// Momentum `I v` of a body moving with twist `v`: `[m v_o - h x w; I_o w + h x v_o]`.
    #[inline(always)]
    pub fn mul_motion(&self, v: &Motion<T>) -> Force<T> {
        Force::new(
            v.lin * self.mass - cross(&self.h, &v.ang),
            mv(&self.i_o, &v.ang) + cross(&self.h, &v.lin),
        )
    }
    /// Kinetic energy `1/2 v . I v`.
    #[inline(always)]
    pub fn kinetic_energy(&self, v: &Motion<T>) -> T {
        T::splat(0.5) * v.dot(&self.mul_motion(v))
    }
    /// Same body, axes rotated by `r` (origin unchanged): `h' = R h`, `I' = R I R^T`.
    #[inline(always)]
    pub fn rotated(&self, r: &Mat3<T>) -> Self {
        // R I R^T is symmetric: A = R I, then the 6 distinct entries A_i . R_j
        let a = mm(r, &self.i_o);
        let e = |i: usize, j: usize| a[(i, 0)] * r[(j, 0)] + a[(i, 1)] * r[(j, 1)] + a[(i, 2)] * r[(j, 2)];
        let (xx, xy, xz, yy, yz, zz) = (e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2));
        Self::new(self.mass, mv(r, &self.h), Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz))
    }
    /// Same body, axes rotated about the coordinate axis k by the angle with cosine `c` and sine
    /// `s`, where `(I, J)` is `(0, 1)` for k = z, `(1, 2)` for x and `(2, 0)` for y (so that
    /// `R e_I = c e_I + s e_J`): `rotated` with 17 products instead of 54, the I-J block by the
    /// double angle: `I'_II = a + b C - I_IJ S`, `I'_JJ = a - b C + I_IJ S`, `I'_IJ = b S + I_IJ C`
    /// with `a, b = (I_II +- I_JJ) / 2`, `C = c^2 - s^2`, `S = 2 c s`.
    #[inline(always)]
    pub fn rotated_about<const I: usize, const J: usize>(&self, c: T, s: T) -> Self {
        const { assert!(I < 3 && J < 3 && I != J) };
        let k = 3 - I - J;
        let i = &self.i_o;
        let half = T::splat(0.5);
        let (double_c, double_s) = (c * c - s * s, T::splat(2.0) * c * s);
        let (a, b) = (half * (i[(I, I)] + i[(J, J)]), half * (i[(I, I)] - i[(J, J)]));
        let (bc, bs, xc, xs) = (b * double_c, b * double_s, i[(I, J)] * double_c, i[(I, J)] * double_s);
        let mut i_o = *i;
        i_o[(I, I)] = a + bc - xs;
        i_o[(J, J)] = a - bc + xs;
        let ij = bs + xc;
        (i_o[(I, J)], i_o[(J, I)]) = (ij, ij);
        let (ik, jk) = (c * i[(I, k)] - s * i[(J, k)], s * i[(I, k)] + c * i[(J, k)]);
        (i_o[(I, k)], i_o[(k, I)]) = (ik, ik);
        (i_o[(J, k)], i_o[(k, J)]) = (jk, jk);
        let h = &self.h;
        let mut h_r = *h;
        h_r[I] = c * h[I] - s * h[J];
        h_r[J] = s * h[I] + c * h[J];
        Self::new(self.mass, h_r, i_o)
    }

    /// Same body, origin moved to `-t` (i.e. expressed in a frame whose origin is at `-t` from
    /// this one, same axes): the parallel-axis theorem written on `h` so that `m = 0` is fine:
    /// `h' = h + m t`, `I' = I - [t]x[h]x - [h]x[t]x - m [t]x[t]x` (derivation: docs/notation.md).
    #[inline(always)]
    pub fn translated(&self, t: &Vec3<T>) -> Self {
        // with [a]x[b]x = b a^T - (a . b) 1 the three products are outer products:
        // I' = I - (h t^T + t h^T) - m t t^T + (2 t . h + m t . t) 1, and with u = h + m t / 2
        // I' = I - (u t^T + t u^T) + 2 (t . u) 1   (symmetric: 6 entries, 2 products each)
        let (m, h) = (self.mass, &self.h);
        let mt = t * m;
        let u = h + mt * T::splat(0.5);
        let d = T::splat(2.0) * t.dot(&u);
        let e = |r: usize, c: usize| -(u[r] * t[c] + t[r] * u[c]);
        let (xx, yy, zz) = (e(0, 0) + d, e(1, 1) + d, e(2, 2) + d);
        let (xy, xz, yz) = (e(0, 1), e(0, 2), e(1, 2));
        let i = &self.i_o;
        #[rustfmt::skip]
        let i_o = Mat3::new(
            i[(0, 0)] + xx, i[(0, 1)] + xy, i[(0, 2)] + xz,
            i[(1, 0)] + xy, i[(1, 1)] + yy, i[(1, 2)] + yz,
            i[(2, 0)] + xz, i[(2, 1)] + yz, i[(2, 2)] + zz,
        );
        Self::new(m, h + mt, i_o)
    }
}

impl<T: Real> Add for Inertia<T> {
    type Output = Inertia<T>;
    #[inline(always)]
    fn add(self, o: Inertia<T>) -> Inertia<T> {
        Inertia::new(self.mass + o.mass, self.h + o.h, self.i_o + o.i_o)
    }
}
impl<T: Real> AddAssign for Inertia<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Inertia<T>) {
        self.mass += o.mass;
        self.h += o.h;
        self.i_o += o.i_o;
    }
}
