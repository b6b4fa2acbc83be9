//! Joint kinds and the one function that decodes them, `jcalc` (RBDA §4.4, Table 4.1).

use crate::spatial::{Mat3, Motion, Transform, Vec3};

/// The closed set of joint kinds of the compiled model (fixed joints are merged at build time).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about `axis` by the joint coordinate.
    Revolute,
    /// Translation along `axis` by the joint coordinate.
    Prismatic,
}

/// A one-degree-of-freedom joint: its kind and unit axis in the joint frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    pub kind: JointKind,
    pub axis: Vec3,
}

/// Rotation matrix about the unit vector `a` by `angle` (Rodrigues' formula).
#[inline]
pub fn axis_angle(a: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let v = 1.0 - c;
    Mat3::new(
        c + a.x * a.x * v,
        a.x * a.y * v - a.z * s,
        a.x * a.z * v + a.y * s,
        a.y * a.x * v + a.z * s,
        c + a.y * a.y * v,
        a.y * a.z * v - a.x * s,
        a.z * a.x * v - a.y * s,
        a.z * a.y * v + a.x * s,
        c + a.z * a.z * v,
    )
}

impl Joint {
    /// `jcalc`: the joint transform `joint_from_body` at joint coordinate `x` (q + offset) and
    /// the motion subspace `s` in the body frame (RBDA Table 4.1: `S = [a; 0]` prismatic,
    /// `[0; a]` revolute in our `[linear; angular]` order; the axis is invariant under the motion).
    #[inline]
    pub fn jcalc(&self, x: f64) -> (Transform, Motion) {
        match self.kind {
            JointKind::Revolute => (
                Transform::new(axis_angle(&self.axis, x), Vec3::zeros()),
                Motion::new(Vec3::zeros(), self.axis),
            ),
            JointKind::Prismatic => (
                Transform::new(Mat3::identity(), self.axis * x),
                Motion::new(self.axis, Vec3::zeros()),
            ),
        }
    }

    /// The motion subspace `s` in the body frame (independent of q for these kinds).
    #[inline]
    pub fn subspace(&self) -> Motion {
        match self.kind {
            JointKind::Revolute => Motion::new(Vec3::zeros(), self.axis),
            JointKind::Prismatic => Motion::new(self.axis, Vec3::zeros()),
        }
    }
}
