//! The check every algorithm needs of a configuration q: each multi-DOF joint's rotation block is
//! unit (a quaternion, or the (cos, sin) pair of a planar joint), since the algorithms read it as a
//! rotation and any other numbers would give a silently wrong result.

use super::{Coordinates, Model};
use crate::lie::Block;

/// Largest distance from 1 of the norm of a quaternion or (cos, sin) pair that the algorithms and
/// the inverse-kinematics solver accept (float64 round-off of a normalised block is ~1e-16; a user's
/// rounded quaternion, printed to 7 digits, is within 1e-6).
pub const UNIT_TOLERANCE: f64 = 1e-6;

impl Block {
    /// The unit part of a q block, relative to its start, and what it is called in messages
    /// (`None`: a scalar block has none).
    pub fn unit_range(self) -> Option<(std::ops::Range<usize>, &'static str)> {
        match self {
            Block::FreeFlyer => Some((3..7, "quaternion (qx, qy, qz, qw)")),
            Block::Spherical => Some((0..4, "quaternion (qx, qy, qz, qw)")),
            Block::Planar => Some((2..4, "(cos, sin) pair")),
            Block::Scalar => None,
        }
    }

    /// The one unit check of a q block `qb` (the block's own numbers): `None` when its unit part
    /// has norm 1 to within [`UNIT_TOLERANCE`] (or it has none), else that part's range in `qb`, its
    /// name in messages and its norm. [`Model::check_configuration`] and the inverse-kinematics
    /// solver's start check both ask it.
    pub fn not_unit(self, qb: &[f64]) -> Option<(std::ops::Range<usize>, &'static str, f64)> {
        let (unit, what) = self.unit_range()?;
        let norm = qb[unit.clone()].iter().map(|x| x * x).sum::<f64>().sqrt();
        ((norm - 1.0).abs() > UNIT_TOLERANCE).then_some((unit, what, norm))
    }

    /// The description's name of a multi-DOF block's joint kind ("floating", "spherical",
    /// "planar"; "1-DOF" for the scalar block).
    pub fn kind_name(self) -> &'static str {
        match self {
            Block::FreeFlyer => "floating",
            Block::Spherical => "spherical",
            Block::Planar => "planar",
            Block::Scalar => "1-DOF",
        }
    }
}

impl Model {
    /// Whether the rotation blocks of the configuration `q` (nq numbers) are unit to within
    /// [`UNIT_TOLERANCE`]; the error names the entries, the joint's first body and, for a batch, the
    /// state (`state`).
    pub fn check_configuration(&self, q: &[f64], state: Option<usize>) -> Result<(), String> {
        if self.plain {
            return Ok(());
        }
        for (i, c) in self.coordinates.iter().enumerate() {
            let Coordinates::Head { block, at } = *c else { continue };
            let Some((unit, what, norm)) = block.not_unit(&q[at..at + block.nq()]) else {
                continue;
            };
            let of_state = state.map_or(String::new(), |k| format!(" of state {k}"));
            return Err(format!(
                "q[{}..{}]{of_state}, the {what} of the {block:?} joint at body {i}, has norm {norm}, not 1 \
                 (to {UNIT_TOLERANCE:e}): normalise it (robot.normalize(q))",
                at + unit.start,
                at + block.nq()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::{Joint, JointKind};
    use crate::spatial::{Inertia, Transform, Vec3};

    /// A spherical joint (three revolute members about x, y, z) on a fixed base.
    fn spherical() -> Model {
        let axes = [Vec3::x(), Vec3::y(), Vec3::z()];
        let joints = axes
            .iter()
            .map(|&axis| Joint {
                kind: JointKind::Revolute,
                axis,
            })
            .collect();
        let inertia = Inertia::from_parameters(&[1.0, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.1, 0.0, 0.1]);
        Model::new(
            vec![None, Some(0), Some(1)],
            joints,
            vec![0.0; 3],
            vec![Transform::identity(); 3],
            vec![
                Inertia::from_parameters(&[0.0; 10]),
                Inertia::from_parameters(&[0.0; 10]),
                inertia,
            ],
            vec![0.0; 3],
            vec![0.0; 3],
            vec![0.0; 3],
            Vec3::new(0.0, 0.0, -9.81),
            vec![],
        )
        .unwrap()
        .with_coordinates(vec![
            Coordinates::Head {
                block: Block::Spherical,
                at: 0,
            },
            Coordinates::Member,
            Coordinates::Member,
        ])
        .unwrap()
    }

    #[test]
    fn a_unit_quaternion_passes_and_a_scaled_one_is_named() {
        let model = spherical();
        assert_eq!(model.check_configuration(&[0.0, 0.0, 0.0, 1.0], None), Ok(()));
        assert_eq!(
            model.check_configuration(&[0.0, 0.0, 0.0, 1.0 + 0.5 * UNIT_TOLERANCE], None),
            Ok(())
        );
        let e = model.check_configuration(&[0.0, 0.0, 0.0, 1.1], Some(3)).unwrap_err();
        assert!(
            e.starts_with("q[0..4] of state 3, the quaternion (qx, qy, qz, qw) of the Spherical joint at body 0"),
            "{e}"
        );
    }

    #[test]
    fn names_at_the_border_decode_into_the_spherical_layout() {
        use crate::joint::JointType;
        use crate::model::{JointRecord, ModelBuilder};
        let mut builder = ModelBuilder::new(Vec3::new(0.0, 0.0, -9.81));
        let inertia = Inertia::from_parameters(&[1.0, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.1, 0.0, 0.1]);
        let ball = JointType::from_name("spherical", None).unwrap();
        let elbow = JointType::from_name("continuous", Some(Vec3::z())).unwrap();
        builder
            .joint(JointRecord::new("ball", ball, None, Transform::identity(), inertia))
            .unwrap();
        builder
            .joint(JointRecord::new(
                "elbow",
                elbow,
                Some(0),
                Transform::identity(),
                inertia,
            ))
            .unwrap();
        let model = builder.build().unwrap();
        assert_eq!(&model.coordinates[..3], &spherical().coordinates[..]);
        assert_eq!(model.coordinates[3], Coordinates::Scalar { at: 4 });
        assert_eq!(model.parent[3], Some(2));
        let e = JointType::from_name("helical", None).unwrap_err().to_string();
        assert!(e.contains("'helical'"), "{e}");
        let e = JointType::from_name("prismatic", None).unwrap_err().to_string();
        assert!(e.contains("needs an axis"), "{e}");
        let e = crate::algorithms::jacobian::Reference::from_name("base")
            .unwrap_err()
            .to_string();
        assert!(e.contains("'base'"), "{e}");
    }
}
