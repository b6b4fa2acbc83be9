//! Joint kinds and the functions that decode them: a description's joint taken whole
//! ([`JointType`]: its name, its block of q and the columns of its motion subspace, one 1-DOF
//! [`Joint`] each) and `jcalc` of a column (RBDA §4.4, Table 4.1). Pinocchio keeps the same
//! knowledge in `multibody/joint/`; here it is written once, and the model builder
//! (`model/builder.rs`) expands a joint from it.

use crate::error::{Error, Result};
use crate::lie::Block;
use crate::spatial::{cross, mm, mv, splat3, Force, Inertia, Mat3, Motion, Real, Transform, Vec3};

/// The closed set of joint kinds of the compiled model (fixed joints are merged at build time).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about `axis` by the joint coordinate.
    Revolute,
    /// Translation along `axis` by the joint coordinate.
    Prismatic,
}

/// A joint taken whole, as a robot description names it (fixed joints are merged before the
/// model is built). A multi-DOF joint's q block and columns follow Pinocchio's conventions
/// (`model/mod.rs`, [`crate::model::Coordinates::Head`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointType {
    /// Rotation about the unit `axis` (a URDF "continuous" joint is one without limits).
    Revolute { axis: Vec3 },
    /// Translation along the unit `axis`.
    Prismatic { axis: Vec3 },
    /// Six degrees of freedom, SE(3) (a description's "floating" joint).
    FreeFlyer,
    /// Three rotational degrees of freedom about the joint frame's origin, SO(3).
    Spherical,
    /// Motion in the plane normal to the unit `normal`, SE(2).
    Planar { normal: Vec3 },
}

impl JointType {
    /// The joint a description names ("revolute", "continuous", "prismatic", "floating",
    /// "spherical", "planar") with its axis (the planar joint's normal; not read for "floating"
    /// and "spherical"): the one place the border's kind names are decoded.
    pub fn from_name(name: &str, axis: Option<Vec3>) -> Result<JointType> {
        let axis = || axis.ok_or_else(|| Error::InvalidModel(format!("a {name} joint needs an axis")));
        Ok(match name {
            "revolute" | "continuous" => JointType::Revolute { axis: axis()? },
            "prismatic" => JointType::Prismatic { axis: axis()? },
            "floating" => JointType::FreeFlyer,
            "spherical" => JointType::Spherical,
            "planar" => JointType::Planar { normal: axis()? },
            _ => {
                return Err(Error::InvalidModel(format!(
                    "unknown joint kind '{name}' (expected 'revolute', 'continuous', 'prismatic', 'floating', \
                     'spherical' or 'planar')"
                )))
            }
        })
    }

    /// The configuration block of a kind named as at the border, "" standing for any 1-DOF joint:
    /// what the Lie-group operations need when no model is built (a symbolic robot's joints). The
    /// block does not depend on the axis, so the decoding above runs with a placeholder one.
    pub fn block_of_kind(name: &str) -> Result<Block> {
        match name {
            "" => Ok(Block::Scalar),
            _ => JointType::from_name(name, Some(Vec3::z())).map(|j| j.block()),
        }
    }

    /// The description's name of the kind ("floating" for the free-flyer).
    pub fn name(&self) -> &'static str {
        match self {
            JointType::Revolute { .. } => "revolute",
            JointType::Prismatic { .. } => "prismatic",
            JointType::FreeFlyer | JointType::Spherical | JointType::Planar { .. } => self.block().kind_name(),
        }
    }

    /// The joint's block of q and v.
    pub fn block(&self) -> Block {
        match self {
            JointType::Revolute { .. } | JointType::Prismatic { .. } => Block::Scalar,
            JointType::FreeFlyer => Block::FreeFlyer,
            JointType::Spherical => Block::Spherical,
            JointType::Planar { .. } => Block::Planar,
        }
    }

    /// The unit axis the joint reads (`None` for the free-flyer and the spherical joint).
    pub fn axis(&self) -> Option<Vec3> {
        match *self {
            JointType::Revolute { axis } | JointType::Prismatic { axis } => Some(axis),
            JointType::Planar { normal } => Some(normal),
            JointType::FreeFlyer | JointType::Spherical => None,
        }
    }

    /// The columns of the joint's motion subspace `S`, one 1-DOF [`Joint`] per degree of freedom,
    /// in v's order: the joint itself for a 1-DOF joint, else [`block_columns`] (a planar joint's
    /// in-plane axes from [`planar_basis`] of its normal).
    pub fn columns(&self) -> Vec<Joint> {
        match *self {
            JointType::Revolute { axis } => vec![Joint {
                kind: JointKind::Revolute,
                axis,
            }],
            JointType::Prismatic { axis } => vec![Joint {
                kind: JointKind::Prismatic,
                axis,
            }],
            JointType::Planar { normal } => block_columns(Block::Planar, planar_basis(normal)),
            JointType::FreeFlyer | JointType::Spherical => block_columns(self.block(), (Vec3::x(), Vec3::y())),
        }
    }
}

/// The columns of a multi-DOF block's motion subspace in the child frame, each a unit linear
/// (prismatic) or angular (revolute) axis, constant in that frame (RBDA Table 4.1's free-flyer
/// `S = 1` in `[linear; angular]` order): free-flyer linear x, y, z then angular x, y, z;
/// spherical angular x, y, z; planar linear `e1`, `e2` and angular `e1 x e2` from the in-plane axes
/// `in_plane` (read only for the planar block). Empty for [`Block::Scalar`].
pub fn block_columns(block: Block, in_plane: (Vec3, Vec3)) -> Vec<Joint> {
    let column = |kind, axis| Joint { kind, axis };
    let (lin, ang) = (JointKind::Prismatic, JointKind::Revolute);
    let unit = |k: usize| Vec3::ith(k, 1.0);
    match block {
        Block::FreeFlyer => (0..6)
            .map(|k| column(if k < 3 { lin } else { ang }, unit(k % 3)))
            .collect(),
        Block::Spherical => (0..3).map(|k| column(ang, unit(k))).collect(),
        Block::Planar => {
            let (e1, e2) = in_plane;
            vec![column(lin, e1), column(lin, e2), column(ang, e1.cross(&e2))]
        }
        Block::Scalar => vec![],
    }
}

/// The joint transform `joint_from_body` of a multi-DOF block at its q block `qb` (Pinocchio's
/// conventions: quaternion (x, y, z, w), assumed unit; planar (x, y, cos θ, sin θ) with in-plane
/// axes `in_plane` = (e1, e2), read only for the planar block): a free-flyer's (R(quat), p), a
/// spherical joint's (R(quat), 0), a planar joint's rotation by θ about n = e1 x e2,
/// `R = c 1 + s [n]x + (1 - c) n n^T` (Rodrigues), and translation x e1 + y e2.
#[inline(always)]
pub fn block_transform<T: Real>(block: Block, in_plane: (Vec3, Vec3), qb: &[T]) -> Transform<T> {
    use crate::lie::quaternion_matrix;
    match block {
        Block::FreeFlyer => Transform::new(quaternion_matrix(&qb[3..7]), Vec3::new(qb[0], qb[1], qb[2])),
        Block::Spherical => Transform::new(quaternion_matrix(&qb[0..4]), Vec3::zeros()),
        Block::Planar => {
            let (e1, e2) = in_plane;
            let n = e1.cross(&e2);
            let (c, s) = (qb[2], qb[3]);
            let (skew_n, nn) = (
                crate::spatial::splat33::<T>(&crate::spatial::skew(&n)),
                crate::spatial::splat33::<T>(&(n * n.transpose())),
            );
            let rot = Mat3::identity() * c + skew_n * s + nn * (T::one() - c);
            Transform::new(rot, splat3::<T>(&e1) * qb[0] + splat3::<T>(&e2) * qb[1])
        }
        Block::Scalar => unreachable!("a 1-DOF joint's transform is its column's jcalc"),
    }
}

impl JointType {
    /// The joint's motion `joint_from_body` at its block of q (`block().nq()` numbers): `jcalc`
    /// of a 1-DOF joint's column, [`block_transform`] of a multi-DOF joint (the planar joint's
    /// in-plane axes from [`planar_basis`] of its normal, as the model builder lays them out).
    /// What locking a joint at a configuration folds into the next placement. `Err` when `q` has
    /// another length or is not finite, or its quaternion / (cos, sin) pair is not unit
    /// ([`Block::not_unit`]).
    pub fn transform(&self, q: &[f64]) -> Result<Transform> {
        let block = self.block();
        if q.len() != block.nq() || q.iter().any(|x| !x.is_finite()) {
            return Err(Error::InvalidModel(format!(
                "a {} joint's configuration is {} finite numbers, got {q:?}",
                self.name(),
                block.nq()
            )));
        }
        if let Some((range, what, norm)) = block.not_unit(q) {
            return Err(Error::InvalidModel(format!(
                "{what} {:?} is not unit (norm {norm})",
                &q[range]
            )));
        }
        Ok(match *self {
            JointType::Revolute { .. } | JointType::Prismatic { .. } => self.columns()[0].jcalc(q[0]).0,
            JointType::Planar { normal } => block_transform(block, planar_basis(normal), q),
            JointType::FreeFlyer | JointType::Spherical => block_transform(block, (Vec3::x(), Vec3::y()), q),
        })
    }
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
    let (s, c) = crate::scalar::trig::sin_cos(angle);
    axis_angle_trig(a, s, c)
}

/// `axis_angle` from the sine and cosine of the angle.
#[inline(always)]
fn axis_angle_trig<T: Real>(a: &Vec3, s: T, c: T) -> Mat3<T> {
    let v = T::one() - c;
    let a = &splat3::<T>(a);
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

/// `R` with columns i and j replaced by `c r_i + s r_j` and `c r_j - s r_i` (`R Rz(x)` for
/// `(i, j) = (0, 1)`, `R Rx(x)` for `(1, 2)`, `R Ry(x)` for `(2, 0)`).
#[inline(always)]
fn rotate_columns<const I: usize, const J: usize, T: Real>(r: &Mat3<T>, c: T, s: T) -> Mat3<T> {
    let mut rot = *r;
    for k in 0..3 {
        let (ri, rj) = (r[(k, I)], r[(k, J)]);
        rot[(k, I)] = c * ri + s * rj;
        rot[(k, J)] = c * rj - s * ri;
    }
    rot
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

    /// `parent_from_joint * joint_from_body(x)` without forming the joint rotation when the axis
    /// is a coordinate axis (DH joints and most URDF joints): rotating about e_k only mixes two
    /// columns of the placement's rotation, `R Rz(x) = [c r0 + s r1, c r1 - s r0, r2]`.
    #[inline]
    pub fn compose(&self, parent_from_joint: &Transform, x: f64) -> Transform {
        let (s, c) = crate::scalar::trig::sin_cos(x);
        self.compose_trig(parent_from_joint, x, s, c)
    }

    /// `compose` with `(s, c) = (sin x, cos x)` given (computed for all joints at once by
    /// `kinematics::joint_trig`, so that their polynomial evaluations overlap).
    #[inline(always)]
    pub fn compose_trig<T: Real>(&self, parent_from_joint: &Transform, x: T, s: T, c: T) -> Transform<T> {
        let placement = parent_from_joint.splat::<T>();
        let r = &placement.rot;
        match self.kind {
            JointKind::Prismatic => Transform::new(*r, placement.trans + mv(r, &(splat3::<T>(&self.axis) * x))),
            JointKind::Revolute => {
                let a = &self.axis;
                // columns (i, j) rotated into each other; constant indices let the compiler
                // emit 12 multiplications and no index arithmetic
                let rot = if a.x == 0.0 && a.y == 0.0 {
                    Some(rotate_columns::<0, 1, T>(r, c, s * T::splat(a.z)))
                } else if a.y == 0.0 && a.z == 0.0 {
                    Some(rotate_columns::<1, 2, T>(r, c, s * T::splat(a.x)))
                } else if a.x == 0.0 && a.z == 0.0 {
                    Some(rotate_columns::<2, 0, T>(r, c, s * T::splat(a.y)))
                } else {
                    None
                };
                match rot {
                    Some(rot) => Transform::new(rot, placement.trans),
                    None => Transform::new(mm(r, &axis_angle_trig(a, s, c)), placement.trans),
                }
            }
        }
    }

    /// `s x`: the joint's twist at rate `x` (`[0; a x]` revolute, `[a x; 0]` prismatic).
    #[inline(always)]
    pub fn motion<T: Real>(&self, x: T) -> Motion<T> {
        let ax = splat3::<T>(&self.axis) * x;
        match self.kind {
            JointKind::Revolute => Motion::new(Vec3::zeros(), ax),
            JointKind::Prismatic => Motion::new(ax, Vec3::zeros()),
        }
    }

    /// `Some(k)` when the axis is `+-e_k` (DH joints, most URDF joints): a product with it is one
    /// entry of the other factor, times `axis[k]` (+-1, so the result equals the general product).
    #[inline(always)]
    pub fn coordinate_axis(&self) -> Option<usize> {
        let a = &self.axis;
        if a.x == 0.0 && a.y == 0.0 {
            Some(2)
        } else if a.y == 0.0 && a.z == 0.0 {
            Some(0)
        } else if a.x == 0.0 && a.z == 0.0 {
            Some(1)
        } else {
            None
        }
    }

    /// `s^T f`: the component of a force along the joint (3 products instead of 6; one for a
    /// coordinate axis).
    #[inline(always)]
    pub fn project<T: Real>(&self, f: &Force<T>) -> T {
        let v = match self.kind {
            JointKind::Revolute => &f.ang,
            JointKind::Prismatic => &f.lin,
        };
        match self.coordinate_axis() {
            Some(k) => v[k] * T::splat(self.axis[k]),
            None => splat3::<T>(&self.axis).dot(v),
        }
    }

    /// `v x (s x)` (RBDA's velocity-product term), using the zero half of `s`:
    /// revolute `[v_lin x w; v_ang x w]` with `w = a x`, prismatic `[v_ang x l; 0]` with `l = a x`.
    #[inline(always)]
    pub fn cross<T: Real>(&self, v: &Motion<T>, x: T) -> Motion<T> {
        let ax = splat3::<T>(&self.axis) * x;
        match self.kind {
            JointKind::Revolute => Motion::new(cross(&v.lin, &ax), cross(&v.ang, &ax)),
            JointKind::Prismatic => Motion::new(cross(&v.ang, &ax), Vec3::zeros()),
        }
    }

    /// `I s` for a rigid-body inertia: revolute `[a x h; I_o a]`, prismatic `[m a; h x a]`.
    #[inline(always)]
    pub fn inertia_times_s<T: Real>(&self, i: &Inertia<T>) -> Force<T> {
        if let Some(k) = self.coordinate_axis() {
            // a = sign e_k: a x h = sign (e_k x h), I_o a = sign (column k of I_o), m a = sign m e_k
            let sign = T::splat(self.axis[k]);
            let ek_cross_h = match k {
                0 => Vec3::new(T::zero(), -i.h.z, i.h.y),
                1 => Vec3::new(i.h.z, T::zero(), -i.h.x),
                _ => Vec3::new(-i.h.y, i.h.x, T::zero()),
            };
            return match self.kind {
                JointKind::Revolute => Force::new(
                    ek_cross_h * sign,
                    Vec3::new(i.i_o[(0, k)], i.i_o[(1, k)], i.i_o[(2, k)]) * sign,
                ),
                JointKind::Prismatic => {
                    let mut lin = Vec3::zeros();
                    lin[k] = i.mass * sign;
                    Force::new(lin, -(ek_cross_h * sign))
                }
            };
        }
        let a = &splat3::<T>(&self.axis);
        match self.kind {
            JointKind::Revolute => Force::new(cross(a, &i.h), mv(&i.i_o, a)),
            JointKind::Prismatic => Force::new(a * i.mass, cross(&i.h, a)),
        }
    }

    /// The motion subspace `s` in the body frame (independent of q for these kinds).
    #[inline(always)]
    pub fn subspace<T: Real>(&self) -> Motion<T> {
        let a = splat3::<T>(&self.axis);
        match self.kind {
            JointKind::Revolute => Motion::new(Vec3::zeros(), a),
            JointKind::Prismatic => Motion::new(a, Vec3::zeros()),
        }
    }
}

/// The in-plane unit axes `(e1, e2)` of a planar joint with unit normal `n`, `e1 x e2 = n`: x and y
/// when `n` is z (Pinocchio's JointModelPlanar; "is z" as NumPy's `allclose(n, z, atol=1e-15)`),
/// else `e1` the coordinate axis most orthogonal to `n` (the first of equals) with its component
/// along `n` removed, normalised. The compiled model's planar members take their columns from it.
pub fn planar_basis(n: Vec3) -> (Vec3, Vec3) {
    let z: Vec3 = Vec3::z();
    if (0..3).all(|k: usize| (n[k] - z[k]).abs() <= 1e-15 + 1e-5 * z[k].abs()) {
        return (Vec3::x(), Vec3::y());
    }
    let k = (0..3).fold(0, |b, k| if n[k].abs() < n[b].abs() { k } else { b });
    let mut e: Vec3 = Vec3::zeros();
    e[k] = 1.0;
    let e1 = e - n * n.dot(&e);
    let e1 = e1 / e1.norm();
    (e1, n.cross(&e1))
}

#[cfg(test)]
mod planar_basis_tests {
    use super::*;

    #[test]
    fn the_basis_is_right_handed_about_the_normal() {
        assert_eq!(planar_basis(Vec3::z()), (Vec3::x(), Vec3::y()));
        for n in [
            Vec3::x(),
            Vec3::new(1.0, 2.0, -0.5).normalize(),
            Vec3::new(0.0, 0.0, -1.0),
        ] {
            let (e1, e2) = planar_basis(n);
            assert!((e1.norm() - 1.0).abs() < 1e-15 && e1.dot(&n).abs() < 1e-15, "{n}");
            assert!((e1.cross(&e2) - n).norm() < 1e-15, "{n}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coordinate-axis products equal the general ones (`s . f`, `I s` by the spatial algebra).
    #[test]
    fn coordinate_axis_products_equal_the_general_ones() {
        let inertia = crate::testing::random_inertia(&mut crate::rng::Rng::new(4));
        let f = Force::new(Vec3::new(0.3, -1.2, 2.5), Vec3::new(-0.7, 0.4, 1.9));
        for axis in [Vec3::x(), Vec3::y(), Vec3::z(), -Vec3::x(), -Vec3::y(), -Vec3::z()] {
            for kind in [JointKind::Revolute, JointKind::Prismatic] {
                let joint = Joint { kind, axis };
                assert!(joint.coordinate_axis().is_some());
                let s = joint.subspace::<f64>();
                assert_eq!(joint.project(&f), s.dot(&f), "{kind:?} {axis:?}");
                let (fast, general) = (joint.inertia_times_s(&inertia), inertia.mul_motion(&s));
                assert!(
                    (fast.lin - general.lin).norm() + (fast.ang - general.ang).norm() < 1e-15,
                    "{kind:?} {axis:?}"
                );
            }
        }
        assert!(Joint {
            kind: JointKind::Revolute,
            axis: Vec3::new(0.6, 0.8, 0.0)
        }
        .coordinate_axis()
        .is_none());
    }

    /// The specialised composition equals the general `placement * jcalc(x)` for every axis case.
    #[test]
    fn compose_equals_placement_times_jcalc() {
        let placement = Transform::new(
            axis_angle(&Vec3::new(0.3, -0.5, 0.8).normalize(), 0.9),
            Vec3::new(0.1, -0.2, 0.3),
        );
        let axes = [
            Vec3::x(),
            Vec3::y(),
            Vec3::z(),
            -Vec3::x(),
            -Vec3::y(),
            -Vec3::z(),
            Vec3::new(1.0, 2.0, -2.0) / 3.0,
        ];
        for axis in axes {
            for kind in [JointKind::Revolute, JointKind::Prismatic] {
                let joint = Joint { kind, axis };
                for x in [-2.5, 0.0, 0.7, 3.1] {
                    let expected = placement * joint.jcalc(x).0;
                    let got = joint.compose(&placement, x);
                    assert!(
                        (got.rot - expected.rot).abs().max() < 1e-15
                            && (got.trans - expected.trans).abs().max() < 1e-15,
                        "{kind:?} {axis:?} {x}"
                    );
                }
            }
        }
    }
}
