//! Spatial (6-D) vector algebra, ordered `[linear; angular]` as in DESIGN.md (Pinocchio's order).
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
/// `+`, `+=`, `-`, `-=`, unary `-` and `* f64`, component by component.
macro_rules! vector_ops {
    ($t:ident) => {
        impl std::ops::Add for $t {
            type Output = $t;
            #[inline]
            fn add(self, o: $t) -> $t {
                $t::new(self.lin + o.lin, self.ang + o.ang)
            }
        }
        impl std::ops::AddAssign for $t {
            #[inline]
            fn add_assign(&mut self, o: $t) {
                self.lin += o.lin;
                self.ang += o.ang;
            }
        }
        impl std::ops::Sub for $t {
            type Output = $t;
            #[inline]
            fn sub(self, o: $t) -> $t {
                $t::new(self.lin - o.lin, self.ang - o.ang)
            }
        }
        impl std::ops::SubAssign for $t {
            #[inline]
            fn sub_assign(&mut self, o: $t) {
                self.lin -= o.lin;
                self.ang -= o.ang;
            }
        }
        impl std::ops::Neg for $t {
            type Output = $t;
            #[inline]
            fn neg(self) -> $t {
                $t::new(-self.lin, -self.ang)
            }
        }
        impl std::ops::Mul<f64> for $t {
            type Output = $t;
            #[inline]
            fn mul(self, s: f64) -> $t {
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

/// 3-vector of f64.
pub type Vec3 = nalgebra::Vector3<f64>;
/// 3x3 matrix of f64.
pub type Mat3 = nalgebra::Matrix3<f64>;

/// `[v]x`, the cross-product matrix: `skew(v) * w == v.cross(&w)`.
#[inline]
pub fn skew(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}
