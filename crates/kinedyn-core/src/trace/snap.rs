//! The model a recording runs on: the rounding residue of right angles and rotated vectors made
//! exact, so that it folds.
//!
//! A placement rotated by a right angle holds `cos(pi/2) = 6.1e-17` where it means 0 (the double
//! nearest pi/2 is not pi/2), and a vector or inertia rotated by it holds entries of that size
//! relative to its others. Computed on, each is a multiplication and an addition that change the
//! result below its last bit; recorded, each keeps a product that would otherwise vanish (on the
//! UR5 and the Panda about a fifth of the CRBA's and ABA's operations). The core's fast paths already
//! take such entries as exact (`AxisRotation::classify`, within `AxisRotation::TOL` = 4 ulp of 1);
//! the recording does the same for every entry of the model's constants, so the program differs
//! from the generic algorithm at the rounding level (about 1e-16 relative), never more.

use crate::spatial::{AxisRotation, Vec3};
use crate::Model;

const TOL: f64 = AxisRotation::TOL;

/// An entry of a rotation or unit axis: 0 or ±1 when within [`TOL`] of it.
fn unit_entry(x: f64) -> f64 {
    if x.abs() <= TOL {
        0.0
    } else if (x.abs() - 1.0).abs() <= TOL {
        x.signum()
    } else {
        x
    }
}

/// Entries of `v` below [`TOL`] times `scale` (the size of the quantity they belong to) set to 0.
fn small_entries<'a>(v: impl IntoIterator<Item = &'a mut f64>, scale: f64) {
    for x in v {
        if x.abs() <= TOL * scale {
            *x = 0.0;
        }
    }
}

fn largest(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// `model` with its placements' rotations, joint axes, placements' translations and inertias
/// snapped as the module says (the placement classes recomputed from the snapped rotations).
pub(super) fn snapped(model: &Model) -> Model {
    let mut m = model.clone();
    for x in &mut m.parent_from_joint {
        x.rot.iter_mut().for_each(|r| *r = unit_entry(*r));
        let scale = largest(x.trans.as_slice());
        small_entries(x.trans.iter_mut(), scale);
    }
    for j in &mut m.joints {
        j.axis = Vec3::from_iterator(j.axis.iter().map(|&a| unit_entry(a)));
    }
    for inertia in &mut m.inertia {
        let scale = largest(inertia.h.as_slice());
        small_entries(inertia.h.iter_mut(), scale);
        let scale = largest(inertia.i_o.as_slice());
        small_entries(inertia.i_o.iter_mut(), scale);
    }
    m.placement_rotation = m
        .parent_from_joint
        .iter()
        .map(|x| AxisRotation::classify(&x.rot))
        .collect();
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::crba;
    use crate::testing::{dh_model, UR5_DH};
    use crate::trace::{record, Traced};
    use crate::Data;

    /// On a DH arm (cos(pi/2) in its placements) snapping moves no entry by more than 4 ulp and
    /// saves operations: the mass matrix recorded on the snapped model is shorter.
    #[test]
    fn snapping_right_angles_saves_operations() {
        let model = dh_model(&UR5_DH, 2);
        let snapped = snapped(&model);
        let moved = |a: &[f64], b: &[f64]| a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        let mut changed = 0;
        for (x, y) in model.parent_from_joint.iter().zip(&snapped.parent_from_joint) {
            assert!(moved(x.rot.as_slice(), y.rot.as_slice()) <= TOL);
            changed += x.rot.iter().zip(y.rot.iter()).filter(|(a, b)| a != b).count();
        }
        assert!(changed >= 6, "the UR5's right angles are snapped ({changed} entries)");
        let crba_ops = |m: &Model| record(m.n, |q| crba(m, &mut Data::<Traced>::new(m), q).to_vec()).arithmetic_count();
        let (raw, exact) = (crba_ops(&model), crba_ops(&snapped));
        assert!(5 * exact < 4 * raw, "{exact} operations snapped, {raw} not");
    }
}
