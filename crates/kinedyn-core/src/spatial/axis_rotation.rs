use super::{Inertia, Mat3, Real};

/// A fixed rotation recognised as the identity or a rotation about one coordinate axis (what DH
/// tables and most URDF `rpy` placements produce), so that moving an inertia through it costs
/// 17 products instead of 54 (`Inertia::rotated_about`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AxisRotation {
    Identity,
    /// About x, y or z by the angle with cosine `c` and sine `s`.
    X {
        c: f64,
        s: f64,
    },
    Y {
        c: f64,
        s: f64,
    },
    Z {
        c: f64,
        s: f64,
    },
    General,
}

impl AxisRotation {
    /// Entries that must be 0 or 1 may be off by this (the rounding of `c + (1 - c)` in
    /// Rodrigues' formula); treating them as exact changes the result at the rounding level.
    pub const TOL: f64 = 4.0 * f64::EPSILON;

    /// The class of `r`.
    pub fn classify(r: &Mat3) -> Self {
        let near = |a: f64, b: f64| (a - b).abs() <= Self::TOL;
        // about axis k with (i, j) its cyclic successors: column/row k is e_k, the (i, j) block [[c, -s], [s, c]]
        let about = |i: usize, j: usize, k: usize| {
            let (c, s) = (r[(i, i)], r[(j, i)]);
            let axis_fixed = near(r[(k, k)], 1.0)
                && [r[(i, k)], r[(j, k)], r[(k, i)], r[(k, j)]]
                    .iter()
                    .all(|&x| near(x, 0.0));
            (axis_fixed && near(r[(j, j)], c) && near(r[(i, j)], -s)).then_some((c, s))
        };
        if (r - Mat3::identity()).abs().max() <= Self::TOL {
            Self::Identity
        } else if let Some((c, s)) = about(0, 1, 2) {
            Self::Z { c, s }
        } else if let Some((c, s)) = about(1, 2, 0) {
            Self::X { c, s }
        } else if let Some((c, s)) = about(2, 0, 1) {
            Self::Y { c, s }
        } else {
            Self::General
        }
    }

    /// `R I R^T` (and `R h`) with `r` the matrix this was classified from.
    #[inline(always)]
    pub fn rotate_inertia<T: Real>(&self, r: &Mat3, i: &Inertia<T>) -> Inertia<T> {
        match *self {
            Self::Identity => *i,
            Self::Z { c, s } => i.rotated_about::<0, 1>(T::splat(c), T::splat(s)),
            Self::X { c, s } => i.rotated_about::<1, 2>(T::splat(c), T::splat(s)),
            Self::Y { c, s } => i.rotated_about::<2, 0>(T::splat(c), T::splat(s)),
            Self::General => i.rotated(&super::splat33(r)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::axis_angle;
    use crate::spatial::Vec3;

    fn inertia() -> Inertia {
        Inertia::new(
            2.5,
            Vec3::new(0.3, -0.2, 0.7),
            Mat3::new(3.0, 0.4, -0.5, 0.4, 2.0, 0.6, -0.5, 0.6, 1.5),
        )
    }

    /// Every class rotates an inertia as the full `R I R^T` does, and is recognised in the
    /// matrices Rodrigues' formula makes (including the ones with rounding in the 1 entry).
    #[test]
    fn classes_rotate_like_the_full_matrix() {
        // an axis and the class its rotations must have
        type Case = (Vec3, fn(&AxisRotation) -> bool);
        let cases: [Case; 7] = [
            (Vec3::x(), |k| matches!(k, AxisRotation::X { .. })),
            (Vec3::y(), |k| matches!(k, AxisRotation::Y { .. })),
            (Vec3::z(), |k| matches!(k, AxisRotation::Z { .. })),
            (-Vec3::x(), |k| matches!(k, AxisRotation::X { .. })),
            (-Vec3::y(), |k| matches!(k, AxisRotation::Y { .. })),
            (-Vec3::z(), |k| matches!(k, AxisRotation::Z { .. })),
            (Vec3::new(1.0, 2.0, 2.0) / 3.0, |k| matches!(k, AxisRotation::General)),
        ];
        for (axis, expected) in cases {
            for angle in [0.3, -1.1, std::f64::consts::FRAC_PI_2, 2.9, -std::f64::consts::PI] {
                let r = axis_angle(&axis, angle);
                let class = AxisRotation::classify(&r);
                assert!(expected(&class), "{axis:?} {angle}: {class:?}");
                let (got, full) = (class.rotate_inertia(&r, &inertia()), inertia().rotated(&r));
                assert!(
                    (got.i_o - full.i_o).abs().max() < 1e-14 && (got.h - full.h).abs().max() < 1e-15,
                    "{axis:?} {angle}"
                );
            }
        }
        assert_eq!(AxisRotation::classify(&Mat3::identity()), AxisRotation::Identity);
    }
}
