//! `ModelBuilder`: a robot's joints taken whole (multi-DOF ones included) and expanded into the
//! model's bodies, one per degree of freedom (the layout of `model/mod.rs`): a multi-DOF joint
//! becomes its head body, at the joint's placement, and members at the identity on the body
//! before, each adding one column of the joint's motion subspace ([`JointType::columns`]); the
//! link's inertia sits on the last. Every record is checked here and a bad one is named
//! ([`Error::InvalidJoint`]), so that what crosses from a description is the joint as written.

use super::{Coordinates, Frame, Model};
use crate::error::{Error, Result};
use crate::joint::JointType;
use crate::lie::Block;
use crate::spatial::{Inertia, Transform, Vec3};

/// One joint of a robot and the link it moves.
#[derive(Clone, Debug, PartialEq)]
pub struct JointRecord {
    /// The joint's name (errors name it).
    pub name: String,
    pub joint: JointType,
    /// The joint whose link carries this joint (an earlier record; `None`: the base).
    pub parent: Option<usize>,
    /// The joint frame in the parent link's frame at q = 0.
    pub placement: Transform,
    /// Added to the joint coordinate before `jcalc` (DH theta / d offsets); 1-DOF joints only.
    pub offset: f64,
    /// The moved link's inertia about its frame origin (the joint frame after the motion).
    pub inertia: Inertia,
    /// The origin of the link's own frame in the joint frame after the motion (a standard-DH link
    /// frame sits at `Tx(a)`; a URDF link frame at the joint frame: zero): the point about which the
    /// moment of an external wrench on the link is given ([`Model::link_origin`] of the body that
    /// carries the link).
    pub link_origin: Vec3,
    /// Reflected rotor inertia `r^2 J_m`, viscous and Coulomb friction: 1-DOF joints only.
    pub armature: f64,
    pub viscous: f64,
    pub coulomb: f64,
    /// Coulomb level for `qd < 0` when it differs from `coulomb` (`None`: symmetric).
    pub coulomb_negative: Option<f64>,
}

impl JointRecord {
    /// A joint without offset, drive or friction data.
    pub fn new(name: &str, joint: JointType, parent: Option<usize>, placement: Transform, inertia: Inertia) -> Self {
        Self {
            name: name.to_string(),
            joint,
            parent,
            placement,
            offset: 0.0,
            inertia,
            link_origin: Vec3::zeros(),
            armature: 0.0,
            viscous: 0.0,
            coulomb: 0.0,
            coulomb_negative: None,
        }
    }

    /// What is wrong with this record as joint `index` of a builder (`None`: nothing).
    fn problem(&self, index: usize) -> Option<String> {
        if let Some(p) = self.parent {
            if p >= index {
                return Some(format!(
                    "its parent joint {p} is not an earlier joint (parents come before children)"
                ));
            }
        }
        if let Some(axis) = self.joint.axis() {
            let norm = axis.norm();
            if !norm.is_finite() || (norm - 1.0).abs() > 1e-9 {
                return Some(format!("axis {:?} is not a unit vector", axis.as_slice()));
            }
        }
        if self.placement.to_homogeneous().iter().any(|x| !x.is_finite()) {
            return Some("its placement has a non-finite value".into());
        }
        if self.inertia.to_parameters().iter().any(|x| !x.is_finite()) {
            return Some("its link's inertia has a non-finite value".into());
        }
        if self.link_origin.iter().any(|x| !x.is_finite()) {
            return Some("its link origin has a non-finite value".into());
        }
        if self.inertia.mass < 0.0 {
            return Some(format!("its link has negative mass {}", self.inertia.mass));
        }
        let drive = [
            ("offset", self.offset),
            ("armature", self.armature),
            ("viscous", self.viscous),
            ("coulomb", self.coulomb),
        ];
        if let Some((what, x)) = drive.iter().find(|(_, x)| !x.is_finite()) {
            return Some(format!("{what} is {x}, not a finite number"));
        }
        if let Some(level) = self.coulomb_negative {
            if !(level.is_finite() && level >= 0.0) {
                return Some(format!("coulomb_negative is {level}, a level must be >= 0"));
            }
        }
        if self.joint.block() != Block::Scalar {
            // one scalar per degree of freedom is no data of a multi-DOF joint (its coordinates are
            // not angles or displacements along one axis)
            if let Some((what, x)) = drive.iter().find(|(_, x)| *x != 0.0) {
                return Some(format!("a {} joint takes no {what} (got {x})", self.joint.name()));
            }
            if self.coulomb_negative.is_some() {
                return Some(format!("a {} joint takes no coulomb_negative", self.joint.name()));
            }
        }
        None
    }
}

/// Joints and frames gathered in order, then [`ModelBuilder::build`] expands them into a [`Model`].
#[derive(Clone, Debug)]
pub struct ModelBuilder {
    records: Vec<JointRecord>,
    /// Each frame's joint (whose link it is fixed to; `None`: the base) and placement in that link.
    frames: Vec<(Option<usize>, Transform)>,
    gravity: Vec3,
}

impl ModelBuilder {
    /// An empty robot under `gravity` (base coordinates).
    pub fn new(gravity: Vec3) -> Self {
        Self {
            records: Vec::new(),
            frames: Vec::new(),
            gravity,
        }
    }

    /// Add a joint (after its parent); its index, or the error naming it.
    pub fn joint(&mut self, record: JointRecord) -> Result<usize> {
        let index = self.records.len();
        if let Some(message) = record.problem(index) {
            return Err(Error::InvalidJoint {
                joint: index,
                name: record.name,
                message,
            });
        }
        self.records.push(record);
        Ok(index)
    }

    /// Add a frame fixed to the link of `joint` (`None`: the base) at `placement` in it.
    pub fn frame(&mut self, joint: Option<usize>, placement: Transform) -> Result<usize> {
        let k = self.frames.len();
        if let Some(j) = joint {
            if j >= self.records.len() {
                return Err(Error::InvalidModel(format!(
                    "frame {k} is fixed to joint {j}, but there are {} joints",
                    self.records.len()
                )));
            }
        }
        self.frames.push((joint, placement));
        Ok(k)
    }

    /// The model: one body per degree of freedom, q blocks in joint order (RBDA §4.4's `jcalc`
    /// per column; the layout of a multi-DOF joint is that of `model/mod.rs`).
    pub fn build(self) -> Result<Model> {
        let nv: usize = self.records.iter().map(|r| r.joint.block().nv()).sum();
        let mut parent = Vec::with_capacity(nv);
        let mut joints = Vec::with_capacity(nv);
        let mut offset = Vec::with_capacity(nv);
        let mut placement = Vec::with_capacity(nv);
        let mut inertia = Vec::with_capacity(nv);
        let (mut armature, mut viscous, mut coulomb) =
            (Vec::with_capacity(nv), Vec::with_capacity(nv), Vec::with_capacity(nv));
        let mut negative = Vec::with_capacity(nv);
        let mut coordinates = Vec::with_capacity(nv);
        let mut link_origin = Vec::with_capacity(nv);
        // the body that carries each joint's link: its last column
        let mut last_body: Vec<usize> = Vec::with_capacity(self.records.len());
        let mut at = 0;
        for r in &self.records {
            let (block, columns, first) = (r.joint.block(), r.joint.columns(), parent.len());
            for (m, column) in columns.iter().enumerate() {
                let head = m == 0;
                parent.push(if head {
                    r.parent.map(|p| last_body[p])
                } else {
                    Some(first + m - 1)
                });
                joints.push(*column);
                placement.push(if head { r.placement } else { Transform::identity() });
                // the link (its inertia and frame) is on the last column's body
                let last = m + 1 == columns.len();
                inertia.push(if last { r.inertia } else { Inertia::zero() });
                link_origin.push(if last { r.link_origin } else { Vec3::zeros() });
                // drive and friction data exist for 1-DOF joints only (checked in `joint`)
                offset.push(if head { r.offset } else { 0.0 });
                armature.push(if head { r.armature } else { 0.0 });
                viscous.push(if head { r.viscous } else { 0.0 });
                coulomb.push(if head { r.coulomb } else { 0.0 });
                negative.push(if head {
                    r.coulomb_negative.unwrap_or(r.coulomb)
                } else {
                    0.0
                });
                coordinates.push(match (block, head) {
                    (Block::Scalar, _) => Coordinates::Scalar { at },
                    (block, true) => Coordinates::Head { block, at },
                    (_, false) => Coordinates::Member,
                });
            }
            at += block.nq();
            last_body.push(parent.len() - 1);
        }
        let frames = self
            .frames
            .iter()
            .map(|&(joint, body_from_frame)| Frame {
                body: joint.map(|j| last_body[j]),
                body_from_frame,
            })
            .collect();
        let asymmetric = negative != coulomb;
        let mut model = Model::new(
            parent,
            joints,
            offset,
            placement,
            inertia,
            armature,
            viscous,
            coulomb,
            self.gravity,
            frames,
        )?;
        if asymmetric {
            model = model.with_coulomb_negative(negative)?;
        }
        if link_origin.iter().any(|u| *u != Vec3::zeros()) {
            model = model.with_link_origins(link_origin)?;
        }
        if coordinates.iter().all(|c| matches!(c, Coordinates::Scalar { .. })) {
            return Ok(model);
        }
        model.with_coordinates(coordinates)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::{crba, rnea};
    use crate::joint::{Joint, JointKind};
    use crate::rng::Rng;
    use crate::testing::{random_configuration, random_inertia};
    use crate::Data;

    fn random_placement(rng: &mut Rng) -> Transform {
        Transform::new(rng.rotation(), rng.vec3(-0.5, 0.5))
    }

    /// Floating base -> spherical -> planar (normal z) -> revolute -> prismatic, with a frame on
    /// the planar joint's link and one on the base: as records, and the same bodies written out.
    fn chain() -> (ModelBuilder, Model) {
        let mut rng = Rng::new(11);
        let p: Vec<Transform> = (0..5).map(|_| random_placement(&mut rng)).collect();
        let m: Vec<Inertia> = (0..5).map(|_| random_inertia(&mut rng)).collect();
        let (frame_placement, elbow_axis) = (random_placement(&mut rng), Vec3::new(0.6, 0.8, 0.0));
        let gravity = Vec3::new(0.1, -0.2, -9.81);

        let mut builder = ModelBuilder::new(gravity);
        builder
            .joint(JointRecord::new("base", JointType::FreeFlyer, None, p[0], m[0]))
            .unwrap();
        builder
            .joint(JointRecord::new("ball", JointType::Spherical, Some(0), p[1], m[1]))
            .unwrap();
        let slide = JointType::Planar { normal: Vec3::z() };
        builder
            .joint(JointRecord::new("slide", slide, Some(1), p[2], m[2]))
            .unwrap();
        let elbow = JointRecord {
            offset: 0.3,
            armature: 0.02,
            viscous: 0.5,
            coulomb: 0.7,
            coulomb_negative: Some(0.4),
            ..JointRecord::new("elbow", JointType::Revolute { axis: elbow_axis }, Some(2), p[3], m[3])
        };
        builder.joint(elbow).unwrap();
        let tip = JointType::Prismatic { axis: Vec3::x() };
        builder
            .joint(JointRecord::new("tip", tip, Some(3), p[4], m[4]))
            .unwrap();
        builder.frame(Some(2), frame_placement).unwrap();
        builder.frame(None, frame_placement).unwrap();

        // by hand: (parent, kind, axis, placement, inertia) per body
        use JointKind::{Prismatic as P, Revolute as R};
        let (x, y, z, zero, one) = (Vec3::x(), Vec3::y(), Vec3::z(), Inertia::zero(), Transform::identity());
        #[rustfmt::skip]
        let bodies = [
            (None, P, x, p[0], zero), (Some(0), P, y, one, zero), (Some(1), P, z, one, zero),
            (Some(2), R, x, one, zero), (Some(3), R, y, one, zero), (Some(4), R, z, one, m[0]),
            (Some(5), R, x, p[1], zero), (Some(6), R, y, one, zero), (Some(7), R, z, one, m[1]),
            (Some(8), P, x, p[2], zero), (Some(9), P, y, one, zero), (Some(10), R, z, one, m[2]),
            (Some(11), R, elbow_axis, p[3], m[3]),
            (Some(12), P, x, p[4], m[4]),
        ];
        let at_elbow = |v: f64| (0..14).map(|i| if i == 12 { v } else { 0.0 }).collect::<Vec<_>>();
        use Coordinates::{Head, Member, Scalar};
        #[rustfmt::skip]
        let coordinates = vec![
            Head { block: Block::FreeFlyer, at: 0 }, Member, Member, Member, Member, Member,
            Head { block: Block::Spherical, at: 7 }, Member, Member,
            Head { block: Block::Planar, at: 11 }, Member, Member,
            Scalar { at: 15 }, Scalar { at: 16 },
        ];
        let frames = vec![
            Frame {
                body: Some(11),
                body_from_frame: frame_placement,
            },
            Frame {
                body: None,
                body_from_frame: frame_placement,
            },
        ];
        let by_hand = Model::new(
            bodies.iter().map(|b| b.0).collect(),
            bodies.iter().map(|b| Joint { kind: b.1, axis: b.2 }).collect(),
            at_elbow(0.3),
            bodies.iter().map(|b| b.3).collect(),
            bodies.iter().map(|b| b.4).collect(),
            at_elbow(0.02),
            at_elbow(0.5),
            at_elbow(0.7),
            gravity,
            frames,
        )
        .and_then(|m| m.with_coulomb_negative(at_elbow(0.4)))
        .and_then(|m| m.with_coordinates(coordinates))
        .unwrap();
        (builder, by_hand)
    }

    #[test]
    fn a_floating_spherical_planar_chain_built_whole_equals_the_chain_laid_out_by_hand() {
        let (builder, by_hand) = chain();
        let built = builder.build().unwrap();
        assert_eq!((built.n, built.nq, built.plain), (by_hand.n, by_hand.nq, by_hand.plain));
        assert_eq!(built.parent, by_hand.parent);
        assert_eq!(built.joints, by_hand.joints);
        assert_eq!(built.coordinates, by_hand.coordinates);
        assert_eq!(
            (&built.group_first, &built.group_last),
            (&by_hand.group_first, &by_hand.group_last)
        );
        assert_eq!(built.parent_from_joint, by_hand.parent_from_joint);
        let params = |m: &Model| m.inertia.iter().map(|i| i.to_parameters()).collect::<Vec<_>>();
        assert_eq!(params(&built), params(&by_hand));
        assert_eq!(built.offset, by_hand.offset);
        assert_eq!((&built.armature, &built.viscous), (&by_hand.armature, &by_hand.viscous));
        assert_eq!(
            (&built.coulomb, &built.coulomb_negative),
            (&by_hand.coulomb, &by_hand.coulomb_negative)
        );
        assert_eq!(built.frames, by_hand.frames);
        assert_eq!(built.gravity, by_hand.gravity);
        // and so every algorithm gives the same numbers, to the bit
        let mut rng = Rng::new(5);
        let q = random_configuration(&built, &mut rng);
        let (qd, qdd) = (rng.vector(built.n, -1.0, 1.0), rng.vector(built.n, -1.0, 1.0));
        let (mut a, mut b) = (Data::new(&built), Data::new(&by_hand));
        assert_eq!(
            rnea(&built, &mut a, &q, &qd, &qdd, None).to_vec(),
            rnea(&by_hand, &mut b, &q, &qd, &qdd, None).to_vec()
        );
        assert_eq!(crba(&built, &mut a, &q).to_vec(), crba(&by_hand, &mut b, &q).to_vec());
    }

    #[test]
    fn a_planar_joint_takes_its_in_plane_axes_from_its_normal() {
        let normal = Vec3::new(1.0, 2.0, -0.5).normalize();
        let mut builder = ModelBuilder::new(Vec3::zeros());
        let inertia = random_inertia(&mut Rng::new(2));
        let planar = JointType::Planar { normal };
        builder
            .joint(JointRecord::new("slide", planar, None, Transform::identity(), inertia))
            .unwrap();
        let model = builder.build().unwrap();
        let (e1, e2) = crate::joint::planar_basis(normal);
        let axes: Vec<Vec3> = model.joints.iter().map(|j| j.axis).collect();
        assert_eq!(axes, vec![e1, e2, e1.cross(&e2)]);
        assert!((e1.cross(&e2) - normal).norm() < 1e-15);
    }

    #[test]
    fn a_bad_joint_record_is_refused_naming_the_joint() {
        let inertia = random_inertia(&mut Rng::new(3));
        let good = |name: &str, joint| JointRecord::new(name, joint, Some(0), Transform::identity(), inertia);
        let revolute = JointType::Revolute { axis: Vec3::z() };
        let cases: Vec<(JointRecord, &str)> = vec![
            (
                good(
                    "long",
                    JointType::Revolute {
                        axis: Vec3::new(0.0, 0.0, 2.0),
                    },
                ),
                "not a unit vector",
            ),
            (
                good(
                    "tilted",
                    JointType::Planar {
                        normal: Vec3::new(1.0, 1.0, 0.0),
                    },
                ),
                "not a unit vector",
            ),
            (
                JointRecord {
                    parent: Some(1),
                    ..good("ahead", revolute)
                },
                "parent joint 1 is not an earlier",
            ),
            (
                JointRecord {
                    armature: 0.1,
                    ..good("ball", JointType::Spherical)
                },
                "spherical joint takes no armature",
            ),
            (
                JointRecord {
                    offset: 0.2,
                    ..good("free", JointType::FreeFlyer)
                },
                "floating joint takes no offset",
            ),
            (
                JointRecord {
                    coulomb_negative: Some(-1.0),
                    ..good("rub", revolute)
                },
                "coulomb_negative is -1",
            ),
            (
                JointRecord {
                    viscous: f64::NAN,
                    ..good("wet", revolute)
                },
                "viscous is NaN",
            ),
            (
                JointRecord {
                    inertia: Inertia { mass: -1.0, ..inertia },
                    ..good("light", revolute)
                },
                "negative mass",
            ),
        ];
        for (record, expected) in cases {
            let mut builder = ModelBuilder::new(Vec3::zeros());
            let base = JointRecord::new("base", JointType::FreeFlyer, None, Transform::identity(), inertia);
            builder.joint(base).unwrap();
            let name = record.name.clone();
            match builder.joint(record) {
                Err(Error::InvalidJoint {
                    joint,
                    name: got,
                    message,
                }) => {
                    assert_eq!((joint, got.as_str()), (1, name.as_str()));
                    assert!(message.contains(expected), "{name}: {message}");
                }
                other => panic!("{name}: expected an error naming it, got {other:?}"),
            }
        }
        let mut builder = ModelBuilder::new(Vec3::zeros());
        let e = builder.frame(Some(0), Transform::identity()).unwrap_err().to_string();
        assert!(e.contains("frame 0 is fixed to joint 0, but there are 0 joints"), "{e}");
    }

    /// A link origin given in a record lands on the body that carries the link (a multi-DOF
    /// joint's last), per-link wrenches are laid out on those bodies, and RNEA then equals the
    /// chain laid out by hand with the same origins and per-body wrenches.
    #[test]
    fn link_origins_and_wrenches_go_to_the_body_that_carries_the_link() {
        let mut rng = Rng::new(12);
        let origins: Vec<Vec3> = (0..5).map(|_| rng.vec3(-0.4, 0.4)).collect();
        let (builder, by_hand) = chain();
        let mut with_origins = ModelBuilder::new(builder.gravity);
        for (r, u) in builder.records.iter().zip(&origins) {
            with_origins
                .joint(JointRecord {
                    link_origin: *u,
                    ..r.clone()
                })
                .unwrap();
        }
        with_origins.frames = builder.frames.clone();
        let built = with_origins.build().unwrap();
        let carriers = [5, 8, 11, 12, 13];
        assert_eq!(built.link_bodies(), carriers.to_vec());
        assert_eq!(by_hand.link_bodies(), carriers.to_vec());
        let mut per_body = vec![Vec3::zeros(); 14];
        for (b, u) in carriers.iter().zip(&origins) {
            per_body[*b] = *u;
        }
        assert_eq!(built.link_origin, per_body);
        let by_hand = by_hand.with_link_origins(per_body).unwrap();

        let per_link = rng.vector(6 * 5, -2.0, 2.0);
        let mut bodies = vec![f64::NAN; 6 * 14];
        built.link_wrenches(&per_link, &mut bodies).unwrap();
        for b in 0..14 {
            let want = match carriers.iter().position(|c| *c == b) {
                Some(l) => per_link[6 * l..6 * l + 6].to_vec(),
                None => vec![0.0; 6],
            };
            assert_eq!(bodies[6 * b..6 * b + 6], want[..], "body {b}");
        }
        let e = built
            .link_wrenches(&per_link[..6], &mut bodies)
            .unwrap_err()
            .to_string();
        assert!(e.contains("6 numbers for 5 links"), "{e}");

        let q = random_configuration(&built, &mut rng);
        let (qd, qdd) = (rng.vector(14, -1.0, 1.0), rng.vector(14, -1.0, 1.0));
        let (mut a, mut b) = (Data::new(&built), Data::new(&by_hand));
        assert_eq!(
            rnea(&built, &mut a, &q, &qd, &qdd, Some(&bodies)).to_vec(),
            rnea(&by_hand, &mut b, &q, &qd, &qdd, Some(&bodies)).to_vec()
        );
        let bad = JointRecord {
            link_origin: Vec3::new(0.0, f64::INFINITY, 0.0),
            ..builder.records[0].clone()
        };
        let e = ModelBuilder::new(Vec3::zeros()).joint(bad).unwrap_err().to_string();
        assert!(e.contains("link origin has a non-finite value"), "{e}");
    }

    /// `JointType::transform` (what locking a joint folds into a placement) is the motion the
    /// model's kinematics give a lone joint of each kind at the same q; bad blocks are refused.
    #[test]
    fn a_joints_transform_is_its_motion_in_the_model() {
        let mut rng = Rng::new(13);
        let kinds = [
            JointType::Revolute {
                axis: Vec3::new(0.6, 0.0, 0.8),
            },
            JointType::Prismatic { axis: Vec3::y() },
            JointType::FreeFlyer,
            JointType::Spherical,
            JointType::Planar {
                normal: Vec3::new(1.0, 2.0, -0.5).normalize(),
            },
        ];
        for joint in kinds {
            let mut builder = ModelBuilder::new(Vec3::zeros());
            let inertia = random_inertia(&mut rng);
            builder
                .joint(JointRecord::new("j", joint, None, Transform::identity(), inertia))
                .unwrap();
            let model = builder.build().unwrap();
            let q = random_configuration(&model, &mut rng);
            let mut data = Data::new(&model);
            crate::algorithms::forward_kinematics(&model, &mut data, &q);
            let want = data.world_from_body[model.n - 1].to_homogeneous();
            let got = joint.transform(&q).unwrap().to_homogeneous();
            let err = got.iter().zip(&want).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(err < 1e-15, "{}: {err:e}", joint.name());
            if joint.block() != Block::Scalar {
                let mut bad = q.clone();
                bad[model.nq - 1] += 0.1;
                let e = joint.transform(&bad).unwrap_err().to_string();
                assert!(e.contains("not unit"), "{e}");
            }
            let e = joint.transform(&q[..model.nq - 1]).unwrap_err().to_string();
            assert!(e.contains("finite numbers"), "{e}");
        }
    }
}
