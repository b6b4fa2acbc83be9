//! Geometric subproblems of inverse kinematics for revolute joints (Paden-Kahan).
//!
//! Source: Murray, Li & Sastry, *A Mathematical Introduction to Robotic Manipulation* (1994),
//! §3.2.2: subproblem 1 (rotation about one axis), 2 (about two intersecting axes), 3 (rotation to
//! a given distance). Subproblem 4 (a rotated vector with a given component along a direction,
//! `h . exp(w^ theta) p = d`) is the one named so by Elias & Wen, "IK-Geo: Unified robot inverse
//! kinematics using subproblem decomposition" (2022); the closed form below is derived here.
//!
//! | symbol      | here     | meaning                                                     |
//! |-------------|----------|-------------------------------------------------------------|
//! | `w`         | `axis.w` | unit direction of the rotation axis                         |
//! | `r`         | `axis.r` | a point on the axis                                         |
//! | `u`, `v`    | `u`, `v` | `p - r`, `q - r`                                            |
//! | `u'`, `v'`  | `up, vp` | their projections on the plane normal to `w` (MLS eq. 3.40) |
//!
//! Every function returns all solutions (0, 1 or 2) and whether the problem was degenerate
//! (a point on the axis: any angle solves it, 0 is returned and `singular` is set). Distances
//! within `tol` of tangency give a single solution (the limit of the two), flagged `tangent`
//! (sp2: a count of 1), where two branches of a chain's solution merge.

use crate::spatial::Vec3;

/// A rotation axis: unit direction `w` through the point `r`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    pub w: Vec3,
    pub r: Vec3,
}

/// Up to two angles, plus a flag for a degenerate (infinitely many solutions) problem.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Angles {
    pub count: usize,
    pub values: [f64; 2],
    pub singular: bool,
    /// The two roots met (a discriminant within tolerance of zero): one value is returned for
    /// both, and two branches of the solution merge there.
    pub tangent: bool,
}

impl Angles {
    fn none() -> Self {
        Self::default()
    }
    fn one(a: f64, singular: bool) -> Self {
        Self {
            count: 1,
            values: [a, 0.0],
            singular,
            tangent: false,
        }
    }
    /// The double root of a tangency.
    fn double(a: f64) -> Self {
        Self {
            tangent: true,
            ..Self::one(a, false)
        }
    }
    fn two(a: f64, b: f64) -> Self {
        Self {
            count: 2,
            values: [a, b],
            singular: false,
            tangent: false,
        }
    }
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.count]
    }
}

/// Relative tolerance for tangency and degeneracy tests (lengths are scaled by the problem size).
pub const TOL: f64 = 1e-9;

/// Projection of `x` on the plane normal to the unit vector `w`: `x - w w^T x`.
#[inline]
fn perp(w: &Vec3, x: &Vec3) -> Vec3 {
    x - w * w.dot(x)
}

/// Rodrigues: `exp(w^ theta) x` for a direction `x` (no translation).
#[inline]
pub fn rotate(w: &Vec3, theta: f64, x: &Vec3) -> Vec3 {
    let (s, c) = theta.sin_cos();
    x * c + w.cross(x) * s + w * (w.dot(x) * (1.0 - c))
}

/// `exp(xi^ theta) p` for the rotation about `axis`: `r + exp(w^ theta) (p - r)`.
#[inline]
pub fn rotate_point(axis: &Axis, theta: f64, p: &Vec3) -> Vec3 {
    axis.r + rotate(&axis.w, theta, &(p - axis.r))
}

/// Subproblem 1 (MLS §3.2.2): the angle with `exp(xi^ theta) p = q`, rotation about `axis`.
///
/// `theta = atan2(w . (u' x v'), u' . v')` (MLS eq. 3.41). Only the projections are used, so a
/// pair with mismatched heights or radii gets the best angle (callers verify by forward kinematics).
pub fn sp1(axis: &Axis, p: &Vec3, q: &Vec3) -> Angles {
    sp1_dir(&axis.w, &(p - axis.r), &(q - axis.r))
}

/// Subproblem 1 for free vectors: the rotation about direction `w` taking `u` towards `v`.
pub fn sp1_dir(w: &Vec3, u: &Vec3, v: &Vec3) -> Angles {
    let (up, vp) = (perp(w, u), perp(w, v));
    let scale = u.norm().max(v.norm()).max(1e-300);
    if up.norm() <= TOL * scale || vp.norm() <= TOL * scale {
        // p on the axis: every angle maps p to itself
        return Angles::one(0.0, true);
    }
    Angles::one(w.dot(&up.cross(&vp)).atan2(up.dot(&vp)), false)
}

/// Subproblem 2 (MLS §3.2.2): `exp(xi1^ theta1) exp(xi2^ theta2) p = q` for two axes meeting at
/// `r` (`axis1.r` must be the intersection point). Returns pairs `(theta1, theta2)`, their
/// count (1 only at a tangency: the two pairs merged) and the singular flag.
///
/// The intermediate point `c = exp(xi2^ theta2) p = exp(-xi1^ theta1) q` is `r + z` with
/// `z = alpha w1 + beta w2 + gamma (w1 x w2)` (MLS eqs. 3.43-3.46).
pub fn sp2(axis1: &Axis, axis2: &Axis, p: &Vec3, q: &Vec3) -> ([(f64, f64); 2], usize, bool) {
    let r = axis1.r;
    let (w1, w2) = (axis1.w, axis2.w);
    let (u, v) = (p - r, q - r);
    let c12 = w1.dot(&w2);
    let cross = w1.cross(&w2);
    let den = c12 * c12 - 1.0;
    // alpha = ((w1.w2) w2.u - w1.v) / ((w1.w2)^2 - 1), beta = ((w1.w2) w1.v - w2.u) / ((w1.w2)^2 - 1)
    let alpha = (c12 * w2.dot(&u) - w1.dot(&v)) / den;
    let beta = (c12 * w1.dot(&v) - w2.dot(&u)) / den;
    // gamma^2 = (|u|^2 - alpha^2 - beta^2 - 2 alpha beta w1.w2) / |w1 x w2|^2
    let g2 = (u.norm_squared() - alpha * alpha - beta * beta - 2.0 * alpha * beta * c12) / cross.norm_squared();
    let scale = u.norm_squared().max(v.norm_squared()).max(1e-300);
    let (gammas, count) = if g2 > TOL * scale {
        ([g2.sqrt(), -g2.sqrt()], 2)
    } else if g2 > -1e-7 * scale {
        ([0.0, 0.0], 1)
    } else {
        return ([(0.0, 0.0); 2], 0, false);
    };
    let mut out = [(0.0, 0.0); 2];
    let mut singular = false;
    for (k, gamma) in gammas[..count].iter().enumerate() {
        let c = r + w1 * alpha + w2 * beta + cross * *gamma;
        let t2 = sp1(axis2, p, &c);
        let t1 = sp1(axis1, &c, q);
        singular |= t1.singular || t2.singular;
        out[k] = (t1.values[0], t2.values[0]);
    }
    (out, count, singular)
}

/// Subproblem 3 (MLS §3.2.2): the angles with `|exp(xi^ theta) p - q| = delta`.
///
/// `theta = theta0 +- acos((|u'|^2 + |v'|^2 - delta'^2) / (2 |u'| |v'|))`, `theta0` the angle
/// from `u'` to `v'` and `delta'^2 = delta^2 - |w . (p - q)|^2` (MLS eqs. 3.47-3.49).
pub fn sp3(axis: &Axis, p: &Vec3, q: &Vec3, delta: f64) -> Angles {
    let w = &axis.w;
    let (u, v) = (p - axis.r, q - axis.r);
    let (up, vp) = (perp(w, &u), perp(w, &v));
    let h = w.dot(&(p - q));
    let dp2 = delta * delta - h * h;
    let (nu, nv) = (up.norm(), vp.norm());
    let scale = (nu + nv + delta).max(1e-300);
    if nu <= TOL * scale || nv <= TOL * scale {
        // p (or q) on the axis: the distance does not depend on theta
        let d0 = (up - vp).norm_squared();
        return if (d0 - dp2).abs() <= 1e-9 * scale * scale {
            Angles::one(0.0, true)
        } else {
            Angles::none()
        };
    }
    let theta0 = w.dot(&up.cross(&vp)).atan2(up.dot(&vp));
    let cosine = (nu * nu + nv * nv - dp2) / (2.0 * nu * nv);
    if cosine.abs() <= 1.0 - 1e-15 {
        let phi = cosine.acos();
        Angles::two(theta0 + phi, theta0 - phi)
    } else if (cosine.abs() - 1.0) <= 1e-7 {
        Angles::double(theta0 + if cosine > 0.0 { 0.0 } else { std::f64::consts::PI })
    } else {
        Angles::none()
    }
}

/// Subproblem 4 (Elias & Wen's numbering): the angles with `h . exp(w^ theta) p = d`, for
/// directions `h`, `w` and a vector `p` (no translation).
///
/// `exp(w^ theta) p = w (w.p) + cos(theta) (p - w (w.p)) + sin(theta) (w x p)`, so
/// `a cos(theta) + b sin(theta) = c` with `a = h.(p - w (w.p))`, `b = h.(w x p)`,
/// `c = d - (h.w)(w.p)`: `theta = atan2(b, a) +- acos(c / sqrt(a^2 + b^2))`.
pub fn sp4(h: &Vec3, w: &Vec3, p: &Vec3, d: f64) -> Angles {
    let pw = w.dot(p);
    let a = h.dot(&(p - w * pw));
    let b = h.dot(&w.cross(p));
    let c = d - h.dot(w) * pw;
    let rho = a.hypot(b);
    let scale = (p.norm() * h.norm()).max(d.abs()).max(1e-300);
    if rho <= TOL * scale {
        return if c.abs() <= 1e-9 * scale {
            Angles::one(0.0, true)
        } else {
            Angles::none()
        };
    }
    let base = b.atan2(a);
    let cosine = c / rho;
    if cosine.abs() <= 1.0 - 1e-15 {
        let phi = cosine.acos();
        Angles::two(base + phi, base - phi)
    } else if cosine.abs() - 1.0 <= 1e-7 {
        Angles::double(base + if cosine > 0.0 { 0.0 } else { std::f64::consts::PI })
    } else {
        Angles::none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z).normalize()
    }

    #[test]
    fn subproblem1_recovers_the_angle() {
        let axis = Axis {
            w: unit(0.3, -0.2, 0.9),
            r: Vec3::new(0.1, 0.4, -0.3),
        };
        let p = Vec3::new(1.0, 0.5, 0.2);
        for &theta in &[0.3, -2.0, 3.0] {
            let q = rotate_point(&axis, theta, &p);
            let s = sp1(&axis, &p, &q);
            assert_eq!(s.count, 1);
            assert!((rotate_point(&axis, s.values[0], &p) - q).norm() < 1e-12);
        }
    }

    #[test]
    fn subproblem2_finds_both_pairs() {
        let r = Vec3::new(0.2, -0.1, 0.5);
        let a1 = Axis {
            w: unit(0.0, 0.1, 1.0),
            r,
        };
        let a2 = Axis {
            w: unit(1.0, 0.2, 0.1),
            r,
        };
        let p = Vec3::new(1.0, 0.7, -0.4);
        let q = rotate_point(&a1, 0.7, &rotate_point(&a2, -1.1, &p));
        let (pairs, count, _) = sp2(&a1, &a2, &p, &q);
        assert_eq!(count, 2);
        let mut found = false;
        for (t1, t2) in &pairs[..count] {
            let x = rotate_point(&a1, *t1, &rotate_point(&a2, *t2, &p));
            assert!((x - q).norm() < 1e-12);
            found |= ((t1 - 0.7).abs() < 1e-9) && ((t2 + 1.1).abs() < 1e-9);
        }
        assert!(found);
    }

    #[test]
    fn subproblem3_gives_the_distance() {
        let axis = Axis {
            w: unit(0.1, 0.0, 1.0),
            r: Vec3::new(0.0, 0.3, 0.0),
        };
        let (p, q) = (Vec3::new(1.0, 0.0, 0.2), Vec3::new(-0.5, 0.8, 0.6));
        let delta = (rotate_point(&axis, 1.2, &p) - q).norm();
        let s = sp3(&axis, &p, &q, delta);
        assert_eq!(s.count, 2);
        for t in s.as_slice() {
            assert!(((rotate_point(&axis, *t, &p) - q).norm() - delta).abs() < 1e-12);
        }
        assert_eq!(sp3(&axis, &p, &q, 100.0).count, 0);
    }

    #[test]
    fn subproblem4_gives_the_component() {
        let (h, w, p) = (unit(0.2, 1.0, 0.3), unit(1.0, 0.0, 0.4), Vec3::new(0.3, -0.7, 0.5));
        let d = h.dot(&rotate(&w, 0.9, &p));
        let s = sp4(&h, &w, &p, d);
        assert_eq!(s.count, 2);
        for t in s.as_slice() {
            assert!((h.dot(&rotate(&w, *t, &p)) - d).abs() < 1e-12);
        }
    }
}
