//! Spatial (6-D) vector algebra, ordered `[linear; angular]` as in docs/architecture.md (Pinocchio's order).
//!
//! Featherstone, *Rigid Body Dynamics Algorithms* (RBDA), ch. 2, writes motion vectors `[w; v]`;
//! here the same quantities are stored as named 3-vectors, so the ordering is only a convention of
//! the public arrays. Types never mix: a `Motion` is not a `Force`, a `Transform` names its frames.
//!
//! | RBDA symbol | here                         | meaning                                   |
//! |-------------|------------------------------|-------------------------------------------|
//! | `v`, `a`    | `Motion { lin, ang }`        | twist / acceleration at the frame origin  |
//! | `f`         | `Force { lin, ang }`         | wrench: force, moment about the origin    |
//! | `^B X_A`    | `Transform` `a_from_b` (inverse) | rigid transform between frames        |
//! | `I`         | `Inertia`                    | rigid-body inertia about the frame origin |
//! | `v x`, `v x*` | `Motion::cross_motion`, `cross_force` | spatial cross products          |
//! | `I^A`       | `ArticulatedInertia`         | articulated-body inertia (3x3 blocks)     |

/// The vector-space operations shared by `Motion` and `Force` (two `Vec3` halves, `lin` and `ang`):
/// `+`, `+=`, `-`, `-=`, unary `-` and `* T` (a scalar), component by component.
macro_rules! vector_ops {
    ($t:ident) => {
        impl<T: Real> std::ops::Add for $t<T> {
            type Output = $t<T>;
            #[inline(always)]
            fn add(self, o: $t<T>) -> $t<T> {
                $t::new(self.lin + o.lin, self.ang + o.ang)
            }
        }
        impl<T: Real> std::ops::AddAssign for $t<T> {
            #[inline(always)]
            fn add_assign(&mut self, o: $t<T>) {
                self.lin += o.lin;
                self.ang += o.ang;
            }
        }
        impl<T: Real> std::ops::Sub for $t<T> {
            type Output = $t<T>;
            #[inline(always)]
            fn sub(self, o: $t<T>) -> $t<T> {
                $t::new(self.lin - o.lin, self.ang - o.ang)
            }
        }
        impl<T: Real> std::ops::SubAssign for $t<T> {
            #[inline(always)]
            fn sub_assign(&mut self, o: $t<T>) {
                self.lin -= o.lin;
                self.ang -= o.ang;
            }
        }
        impl<T: Real> std::ops::Neg for $t<T> {
            type Output = $t<T>;
            #[inline(always)]
            fn neg(self) -> $t<T> {
                $t::new(-self.lin, -self.ang)
            }
        }
        impl<T: Real> std::ops::Mul<T> for $t<T> {
            type Output = $t<T>;
            #[inline(always)]
            fn mul(self, s: T) -> $t<T> {
                $t::new(self.lin * s, self.ang * s)
            }
        }
    };
}
use vector_ops;

mod articulated;
mod axis_rotation;
mod force;
mod inertia;
mod motion;
mod transform;

pub use articulated::ArticulatedInertia;
pub use axis_rotation::AxisRotation;
pub use force::Force;
pub use inertia::Inertia;
pub use motion::Motion;
pub use transform::Transform;

pub use crate::scalar::Real;

/// 3-vector (of f64 unless said otherwise).
pub type Vec3<T = f64> = nalgebra::Vector3<T>;
/// 3x3 matrix (of f64 unless said otherwise).
pub type Mat3<T = f64> = nalgebra::Matrix3<T>;

/// `[v]x`, the cross-product matrix: `skew(v) * w == v.cross(&w)`.
#[inline(always)]
pub fn skew<T: Real>(v: &Vec3<T>) -> Mat3<T> {
    let z = T::zero();
    Mat3::new(z, -v.z, v.y, v.z, z, -v.x, -v.y, v.x, z)
}

// The 3-vector and 3x3 products of the generic algorithms, written out: nalgebra's generic
// `Matrix * Matrix`, `cross` and `tr_mul` are not always inlined, and an out-of-line copy is
// compiled for the baseline instruction set, which cost a batch in SIMD lanes a factor 10.

/// `a x b`.
#[inline(always)]
pub fn cross<T: Real>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    Vec3::new(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x)
}

/// `m v`.
#[inline(always)]
pub fn mv<T: Real>(m: &Mat3<T>, v: &Vec3<T>) -> Vec3<T> {
    let row = |i: usize| m[(i, 0)] * v.x + m[(i, 1)] * v.y + m[(i, 2)] * v.z;
    Vec3::new(row(0), row(1), row(2))
}

/// `m^T v`.
#[inline(always)]
pub fn mtv<T: Real>(m: &Mat3<T>, v: &Vec3<T>) -> Vec3<T> {
    let col = |j: usize| m[(0, j)] * v.x + m[(1, j)] * v.y + m[(2, j)] * v.z;
    Vec3::new(col(0), col(1), col(2))
}

/// `a b`.
#[inline(always)]
pub fn mm<T: Real>(a: &Mat3<T>, b: &Mat3<T>) -> Mat3<T> {
    let e = |i: usize, j: usize| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)] + a[(i, 2)] * b[(2, j)];
    Mat3::new(
        e(0, 0),
        e(0, 1),
        e(0, 2),
        e(1, 0),
        e(1, 1),
        e(1, 2),
        e(2, 0),
        e(2, 1),
        e(2, 2),
    )
}

/// `a b^T`.
#[inline(always)]
pub fn mmt<T: Real>(a: &Mat3<T>, b: &Mat3<T>) -> Mat3<T> {
    let e = |i: usize, j: usize| a[(i, 0)] * b[(j, 0)] + a[(i, 1)] * b[(j, 1)] + a[(i, 2)] * b[(j, 2)];
    Mat3::new(
        e(0, 0),
        e(0, 1),
        e(0, 2),
        e(1, 0),
        e(1, 1),
        e(1, 2),
        e(2, 0),
        e(2, 1),
        e(2, 2),
    )
}

/// `u v^T`.
#[inline(always)]
pub fn outer<T: Real>(u: &Vec3<T>, v: &Vec3<T>) -> Mat3<T> {
    Mat3::new(
        u.x * v.x,
        u.x * v.y,
        u.x * v.z,
        u.y * v.x,
        u.y * v.y,
        u.y * v.z,
        u.z * v.x,
        u.z * v.y,
        u.z * v.z,
    )
}

/// A model constant (f64) broadcast to every lane of `T`.
#[inline(always)]
pub fn splat3<T: Real>(v: &Vec3) -> Vec3<T> {
    Vec3::new(T::splat(v.x), T::splat(v.y), T::splat(v.z))
}

/// A constant 3x3 matrix broadcast to every lane of `T`.
#[inline(always)]
pub fn splat33<T: Real>(m: &Mat3) -> Mat3<T> {
    // written out, not `m.map(T::splat)`: for f64 a plain copy the optimiser can drop
    let e = |i: usize, j: usize| T::splat(m[(i, j)]);
    Mat3::new(
        e(0, 0),
        e(0, 1),
        e(0, 2),
        e(1, 0),
        e(1, 1),
        e(1, 2),
        e(2, 0),
        e(2, 1),
        e(2, 2),
    )
}
