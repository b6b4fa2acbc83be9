//! The arm-angle intervals of an SRS arm inside its joint limits, in closed form.
//!
//! Along the self-motion of an SRS arm ([`Redundant::solve_arm_angle`]) the shoulder's rotation
//! is `R(psi) = F_d(psi) F_0^T` with `F_d(psi)` linear in `(cos psi, sin psi)` (`ArmCircle`), and
//! the wrist's `H(psi) = R_4^T R(psi)^T G` likewise (`theta_4` does not depend on psi). So every
//! scalar `x . M(psi) y` is a sinusoid `a sin psi + b cos psi + c`, fitted exactly from its values
//! at psi = 0, pi/2, pi. As Shimizu et al. (IEEE T-RO 24(5), 2008, §IV) observe, a joint reaches a
//! limit where such a sinusoid takes a given value; for a triple of axes `w_1, w_2, w_3` with
//! `M = exp(w_1 t_1) exp(w_2 t_2) exp(w_3 t_3)` (derived here from `M w_3 = R_1 R_2 w_3` and
//! `M^T w_1 = R_3^T R_2^T w_1`, which the outer rotations leave on fixed cones):
//!
//! ```text
//! t_1 = L:   (exp(w_1 L) w_2) . (M w_3)    = w_2 . w_3
//! t_2 = L:   w_1 . (M w_3)                 = w_1 . exp(w_2 L) w_3
//! t_3 = L:   (exp(-w_3 L) w_2) . (M^T w_1) = w_1 . w_2
//! ```
//!
//! and the triple has a solution only while `w_1 . M w_3` lies within
//! `(w_1.w_2)(w_2.w_3) +- |w_1 x w_2| |w_2 x w_3|` (the cone of `R_2 w_3` met by the plane of
//! `w_1`), two more values. Each equation `a sin psi + b cos psi + c = K` has at most two roots,
//! `psi = atan2(a, b) +- acos((K - c) / hypot(a, b))`; the roots hold for some branch (the
//! equations are necessary, not branch-specific), so they cut the sweep into arcs on which no
//! branch crosses a limit or appears, and one evaluation at each arc's middle says which branches
//! are inside there. Adjacent inside arcs are joined.

use super::redundant::{ArmCircle, Redundant, SRS_MAX_SOLUTIONS};
use super::subproblems::rotate;
use crate::spatial::{Mat3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// `a sin psi + b cos psi + c`.
#[derive(Clone, Copy, Debug)]
struct Sinusoid {
    a: f64,
    b: f64,
    c: f64,
}

impl Sinusoid {
    /// The sinusoid through `f(0)`, `f(pi/2)`, `f(pi)` (exact for a function of that form).
    fn fit(f: impl Fn(f64) -> f64) -> Self {
        let (f0, fh, fp) = (f(0.0), f(FRAC_PI_2), f(PI));
        let c = 0.5 * (f0 + fp);
        Self {
            a: fh - c,
            b: 0.5 * (f0 - fp),
            c,
        }
    }

    /// The psi where it equals `k` (0, 1 or 2 roots; a tangency within rounding counts once).
    fn roots(&self, k: f64, out: &mut Vec<f64>) {
        let r = self.a.hypot(self.b);
        if r <= 1e-13 {
            return; // constant in psi: crosses k nowhere (or everywhere, which changes nothing)
        }
        let x = (k - self.c) / r;
        if x.abs() > 1.0 + 1e-12 {
            return;
        }
        let phi = self.a.atan2(self.b);
        let d = x.clamp(-1.0, 1.0).acos();
        out.push(phi + d);
        if d > 0.0 {
            out.push(phi - d);
        }
    }
}

/// Whether `[lo, hi]` spans less than a turn (NaN-free limits: infinite ones span more).
fn bounded(lo: f64, hi: f64) -> bool {
    hi - lo < 2.0 * PI
}

/// Whether some `theta + 2 pi k` lies in `[lo, hi]` (the limits in theta), as the joint vectors
/// are mapped (`solutions::wrap_angle`) and tested (1e-12 slack).
fn inside(theta: f64, lo: f64, hi: f64) -> bool {
    if !bounded(lo, hi) {
        return true; // a full turn (or an unbounded side) holds every angle
    }
    let v = theta + 2.0 * PI * ((lo - 1e-12 - theta) / (2.0 * PI)).ceil();
    v <= hi + 1e-12
}

/// Joint-limit and existence values of one triple of axes `w` with rotation `m(psi)` (see the
/// module header), their roots appended to `out`.
fn triple_roots(w: [Vec3; 3], m: impl Fn(f64) -> Mat3, lo: &[f64], hi: &[f64], out: &mut Vec<f64>) {
    let [w1, w2, w3] = w;
    let along = Sinusoid::fit(|p| w1.dot(&(m(p) * w3)));
    let (c12, c23) = (w1.dot(&w2), w2.dot(&w3));
    let s = w1.cross(&w2).norm() * w2.cross(&w3).norm();
    along.roots(c12 * c23 + s, out);
    along.roots(c12 * c23 - s, out);
    for (j, (&l, &h)) in lo.iter().zip(hi).enumerate() {
        if !bounded(l, h) {
            continue;
        }
        for limit in [l, h] {
            match j {
                0 => {
                    let x = rotate(&w1, limit, &w2);
                    Sinusoid::fit(|p| x.dot(&(m(p) * w3))).roots(c23, out)
                }
                1 => along.roots(w1.dot(&rotate(&w2, limit, &w3)), out),
                _ => {
                    let x = rotate(&w3, -limit, &w2);
                    Sinusoid::fit(|p| x.dot(&(m(p).transpose() * w1))).roots(c12, out)
                }
            }
        }
    }
}

impl Redundant {
    /// The arm-angle intervals within `span` (lo <= hi) where each SRS branch exists with every
    /// joint inside `[lower, upper]` (limits on theta = q + offset): `out[b]` for branch b of
    /// [`Redundant::solve_arm_angle`], intervals sorted, their inner ends on a joint limit (or
    /// where the branch ends). None when the arm is not SRS or the target leaves psi undefined.
    pub fn arm_angle_intervals(
        &self,
        target: &crate::spatial::Transform,
        lower: &[f64],
        upper: &[f64],
        span: (f64, f64),
    ) -> Option<[Vec<(f64, f64)>; SRS_MAX_SOLUTIONS]> {
        let circle: ArmCircle = self.arm_circle(target)?;
        if circle.met.singular {
            return None;
        }
        let w = |i: usize| self.axis(i).w;
        let mut roots = Vec::with_capacity(64);
        for (ie, elbow) in circle.elbows.iter().enumerate() {
            let Some((theta4, _)) = *elbow else { continue };
            let shoulder = |p: f64| circle.rotation(ie, p).unwrap_or_else(Mat3::identity);
            triple_roots([w(0), w(1), w(2)], shoulder, &lower[..3], &upper[..3], &mut roots);
            let r4 = self.screws[3].exp(theta4).rot.transpose();
            let g = circle.g.rot;
            let wrist = |p: f64| r4 * shoulder(p).transpose() * g;
            triple_roots([w(4), w(5), w(6)], wrist, &lower[4..], &upper[4..], &mut roots);
        }
        // every representative inside the span, and the span's ends
        let (lo, hi) = span;
        let mut cuts = vec![lo, hi];
        for r in roots {
            let mut x = r + 2.0 * PI * ((lo - r) / (2.0 * PI)).ceil();
            while x < hi {
                cuts.push(x);
                x += 2.0 * PI;
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let mut out: [Vec<(f64, f64)>; SRS_MAX_SOLUTIONS] = Default::default();
        let mut rows = [None; SRS_MAX_SOLUTIONS];
        for arc in cuts.windows(2) {
            let (a, z) = (arc[0], arc[1]);
            if z <= a {
                continue;
            }
            self.branches_at(&circle, 0.5 * (a + z), &mut rows);
            for (b, row) in rows.iter().enumerate() {
                let ok = row.is_some_and(|t| (0..7).all(|j| inside(t[j], lower[j], upper[j])));
                if !ok {
                    continue;
                }
                match out[b].last_mut() {
                    Some(last) if last.1 == a => last.1 = z,
                    _ => out[b].push((a, z)),
                }
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint::axis_angle;
    use crate::spatial::Transform;

    use crate::ik::analytic::rev;

    /// An SRS arm with skewed shoulder and wrist axes (not the iiwa's right angles, so that the
    /// existence bounds of the module header cut too), and iiwa-like limits.
    fn arm() -> (Redundant, [f64; 7], [f64; 7]) {
        let (s, w) = ([0.0, 0.0, 0.36], [0.05, 0.0, 1.18]);
        let screws = vec![
            rev([0.0, 0.0, 1.0], s),
            rev([0.0, 1.0, 0.3], s),
            rev([0.2, 0.0, 1.0], s),
            rev([0.0, -1.0, 0.0], [0.0, 0.0, 0.78]),
            rev([0.0, 0.1, 1.0], w),
            rev([0.0, 1.0, 0.0], w),
            rev([0.3, 0.0, 1.0], w),
        ];
        let home = Transform::new(axis_angle(&Vec3::x(), 0.4), Vec3::new(0.05, 0.0, 1.306));
        let d = |x: f64| x.to_radians();
        let lower = [
            d(-170.0),
            d(-120.0),
            d(-170.0),
            d(-120.0),
            d(-170.0),
            d(-120.0),
            d(-175.0),
        ];
        // not symmetric, so that a sign error in a limit equation shows
        let upper = [d(150.0), d(100.0), d(160.0), d(110.0), d(165.0), d(115.0), d(170.0)];
        (Redundant::new(screws, home).expect("7 joints"), lower, upper)
    }

    fn inside_at(arm: &Redundant, circle: &ArmCircle, psi: f64, b: usize, lo: &[f64; 7], hi: &[f64; 7]) -> bool {
        let mut rows = [None; SRS_MAX_SOLUTIONS];
        arm.branches_at(circle, psi, &mut rows);
        rows[b].is_some_and(|t| (0..7).all(|j| inside(t[j], lo[j], hi[j])))
    }

    #[test]
    fn intervals_match_a_dense_sampling_and_end_on_a_limit() {
        let (arm, lo, hi) = arm();
        assert!(arm.srs.is_some());
        let mut t = Transform::identity();
        for (s, x) in arm.screws.iter().zip([0.4, 0.9, -0.5, 1.2, 0.3, -0.8, 0.6]) {
            t = t * s.exp(x);
        }
        let target = t * arm.home;
        let circle = arm.arm_circle(&target).unwrap();
        let found = arm.arm_angle_intervals(&target, &lo, &hi, (-PI, PI)).unwrap();
        let (samples, step) = (1001, 2.0 * PI / 1000.0);
        let sampled: Vec<_> = (0..samples)
            .map(|m| {
                let mut rows = [None; SRS_MAX_SOLUTIONS];
                arm.branches_at(&circle, -PI + step * m as f64, &mut rows);
                rows
            })
            .collect();
        let (mut ends, mut checked) = (0, 0);
        for (b, intervals) in found.iter().enumerate() {
            let member = |x: f64| intervals.iter().any(|&(a, z)| a <= x && x <= z);
            let near_end = |x: f64| {
                intervals
                    .iter()
                    .any(|&(a, z)| (x - a).abs() < step || (x - z).abs() < step)
            };
            for (m, rows) in sampled.iter().enumerate() {
                let x = -PI + step * m as f64;
                if !near_end(x) {
                    let ok = rows[b].is_some_and(|t| (0..7).all(|j| inside(t[j], lo[j], hi[j])));
                    assert_eq!(member(x), ok, "branch {b} at {x}");
                    checked += 1;
                }
            }
            for &(a, z) in intervals {
                for (end, out) in [(a, -1e-7), (z, 1e-7)] {
                    if end == -PI || end == PI {
                        continue;
                    }
                    // on the end a joint touches its limit (or the branch ends); just past it, outside
                    let mut rows = [None; SRS_MAX_SOLUTIONS];
                    arm.branches_at(&circle, end, &mut rows);
                    let touch = rows[b].is_none_or(|t| {
                        (0..7).any(|j| {
                            [lo[j], hi[j]].iter().any(|l| {
                                let d = t[j] - l;
                                (d - 2.0 * PI * (d / (2.0 * PI)).round()).abs() < 1e-9
                            })
                        })
                    });
                    assert!(touch, "branch {b} end {end}: no joint on a limit");
                    assert!(
                        inside_at(&arm, &circle, end - 0.1 * out, b, &lo, &hi),
                        "branch {b} end {end}"
                    );
                    assert!(
                        !inside_at(&arm, &circle, end + out, b, &lo, &hi),
                        "branch {b} end {end}"
                    );
                    ends += 1;
                }
            }
        }
        assert!(ends >= 4 && checked > 7000, "{ends} ends, {checked} samples");
    }
}
