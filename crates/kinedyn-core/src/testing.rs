//! Seeded random models for identity tests and benchmarks (RigidBodyDynamics.jl's approach:
//! algorithms checked against each other on random chains and trees).

use crate::joint::{axis_angle, Joint, JointKind};
use crate::model::{Frame, Model};
pub use crate::rng::Rng;
use crate::spatial::{Inertia, Mat3, Transform, Vec3};

/// A physically valid random inertia: positive mass, centre of mass and principal moments that
/// satisfy the triangle inequality, in random axes.
pub fn random_inertia(rng: &mut Rng) -> Inertia {
    let mass = rng.uniform(0.5, 3.0);
    let com = rng.vec3(-0.3, 0.3);
    // principal moments from a random box: always a real body
    let (a, b, c) = (rng.uniform(0.05, 0.5), rng.uniform(0.05, 0.5), rng.uniform(0.05, 0.5));
    let k = mass / 12.0;
    let principal = Mat3::from_diagonal(&Vec3::new(
        k * (b * b + c * c),
        k * (a * a + c * c),
        k * (a * a + b * b),
    ));
    let r = rng.rotation();
    let i_c = r * principal * r.transpose();
    // about the body origin: I_o = I_c - m [c]x [c]x
    let sc = crate::spatial::skew(&com);
    Inertia::new(mass, mass * com, i_c - mass * sc * sc)
}

/// A random model of `n` bodies: a serial chain (`branching = false`) or a tree where each body's
/// parent is any earlier body. Random axes, placements, inertias, offsets, armature, friction;
/// one extra frame per body at a random placement. Half the joint axes are signed coordinate axes
/// and half the placement rotations the identity or about a coordinate axis, so that the
/// algorithms' fast paths for those (`Joint::compose`, `inertia_to_parent`) are exercised too.
pub fn random_model(seed: u64, n: usize, branching: bool) -> Model {
    let mut rng = Rng::new(seed);
    let mut parent = Vec::with_capacity(n);
    let mut joints = Vec::with_capacity(n);
    let mut placements = Vec::with_capacity(n);
    let mut inertias = Vec::with_capacity(n);
    for i in 0..n {
        parent.push(match (i, branching) {
            (0, _) => None,
            (_, false) => Some(i - 1),
            (_, true) => Some((rng.next_u64() % i as u64) as usize),
        });
        let kind = if rng.uniform(0.0, 1.0) < 0.25 {
            JointKind::Prismatic
        } else {
            JointKind::Revolute
        };
        joints.push(Joint {
            kind,
            axis: random_axis(&mut rng),
        });
        let rotation = match rng.next_u64() % 4 {
            0 => Mat3::identity(),
            1 => axis_angle(&random_axis(&mut rng), rng.uniform(-3.0, 3.0)),
            _ => rng.rotation(),
        };
        placements.push(Transform::new(rotation, rng.vec3(-0.5, 0.5)));
        inertias.push(random_inertia(&mut rng));
    }
    let offset = rng.vector(n, -0.5, 0.5);
    let armature = rng.vector(n, 0.0, 0.2);
    let viscous = rng.vector(n, 0.0, 0.5);
    let coulomb = rng.vector(n, 0.0, 0.3);
    let frames = (0..n)
        .map(|b| Frame {
            body: Some(b),
            body_from_frame: Transform::new(rng.rotation(), rng.vec3(-0.3, 0.3)),
        })
        .chain(std::iter::once(Frame {
            body: None,
            body_from_frame: Transform::identity(),
        }))
        .collect();
    Model::new(
        parent,
        joints,
        offset,
        placements,
        inertias,
        armature,
        viscous,
        coulomb,
        Vec3::new(0.0, 0.0, -9.81),
        frames,
    )
    .expect("random models are valid by construction")
}

/// `random_model(seed, n, true)` cut into a forest: after the first body, each body hangs from
/// the base instead of its parent with probability 1/4 (seeded), so that several subtrees share
/// the fixed base (two arms on one table); joints, placements, inertias and drives unchanged.
pub fn random_forest(seed: u64, n: usize) -> Model {
    let tree = random_model(seed, n, true);
    let mut rng = Rng::new(seed ^ 0xf0_2e57);
    let parent = (0..n)
        .map(|i| {
            if i > 0 && rng.next_u64().is_multiple_of(4) {
                None
            } else {
                tree.parent[i]
            }
        })
        .collect();
    Model::new(
        parent,
        tree.joints,
        tree.offset,
        tree.parent_from_joint,
        tree.inertia,
        tree.armature,
        tree.viscous,
        tree.coulomb,
        tree.gravity,
        tree.frames,
    )
    .expect("a forest of a valid tree is valid")
}

/// A random unit vector, or (half of the time) a signed coordinate axis.
fn random_axis(rng: &mut Rng) -> Vec3 {
    let k = rng.next_u64() % 12;
    if k >= 6 {
        return rng.unit();
    }
    let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
    let mut axis = Vec3::zeros();
    axis[(k / 2) as usize] = sign;
    axis
}

/// A serial revolute arm from standard DH rows `(d, a, alpha)` (Spong/Corke convention), with
/// seeded random inertias: body i's frame is joint i's frame, `placement_i = Tx(a_{i-1})
/// Rx(alpha_{i-1}) Tz(d_i)`; the last link's DH frame is frame 0 of the model (the tool).
pub fn dh_model(rows: &[(f64, f64, f64)], seed: u64) -> Model {
    let mut rng = Rng::new(seed);
    let n = rows.len();
    let tx_rx = |a: f64, alpha: f64| Transform::new(axis_angle(&Vec3::x(), alpha), Vec3::new(a, 0.0, 0.0));
    let mut placements = Vec::with_capacity(n);
    let mut previous = Transform::identity();
    for &(d, a, alpha) in rows {
        placements.push(previous * Transform::new(Mat3::identity(), Vec3::new(0.0, 0.0, d)));
        previous = tx_rx(a, alpha);
    }
    let joints = vec![
        Joint {
            kind: JointKind::Revolute,
            axis: Vec3::z()
        };
        n
    ];
    let parent = (0..n).map(|i| i.checked_sub(1)).collect();
    let inertias = (0..n).map(|_| random_inertia(&mut rng)).collect();
    let tool = Frame {
        body: Some(n - 1),
        body_from_frame: previous,
    };
    Model::new(
        parent,
        joints,
        vec![0.0; n],
        placements,
        inertias,
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        Vec3::new(0.0, 0.0, -9.81),
        vec![tool],
    )
    .expect("a DH arm is a valid model")
}

/// Universal Robots' published UR5 DH rows `(d, a, alpha)`.
pub const UR5_DH: [(f64, f64, f64); 6] = [
    (0.089159, 0.0, std::f64::consts::FRAC_PI_2),
    (0.0, -0.425, 0.0),
    (0.0, -0.39225, 0.0),
    (0.10915, 0.0, std::f64::consts::FRAC_PI_2),
    (0.09465, 0.0, -std::f64::consts::FRAC_PI_2),
    (0.0823, 0.0, 0.0),
];

/// `random_model(seed, n, branching)` on a free-flyer base (six bodies: linear x, y, z then
/// angular x, y, z, the last carrying a random inertia), with a spherical joint in place of its
/// second body when `n >= 2`: the multi-DOF layout of `Model::with_coordinates`.
pub fn random_floating_model(seed: u64, n: usize, branching: bool) -> Model {
    use crate::lie::Block;
    use crate::model::Coordinates;
    let tail = random_model(seed, n, branching);
    let mut rng = Rng::new(seed ^ 0x5eed);
    let unit = |k: usize| Vec3::ith(k % 3, 1.0);
    // (parent, joint, placement, inertia, coordinates) per body
    let mut bodies: Vec<(Option<usize>, Joint, Transform, Inertia, Coordinates)> = Vec::new();
    for k in 0..6usize {
        let kind = if k < 3 {
            JointKind::Prismatic
        } else {
            JointKind::Revolute
        };
        let inertia = if k == 5 {
            random_inertia(&mut rng)
        } else {
            Inertia::zero()
        };
        let c = if k == 0 {
            Coordinates::Head {
                block: Block::FreeFlyer,
                at: 0,
            }
        } else {
            Coordinates::Member
        };
        bodies.push((
            k.checked_sub(1),
            Joint { kind, axis: unit(k) },
            Transform::identity(),
            inertia,
            c,
        ));
    }
    // tail body i -> its (last) body here; tail body 1 (if any) becomes a spherical joint
    let mut index = vec![0usize; n];
    let mut at = 7;
    for i in 0..n {
        let p = tail.parent[i].map_or(5, |p| index[p]);
        if i == 1 {
            for k in 0..3 {
                let inertia = if k == 2 { tail.inertia[i] } else { Inertia::zero() };
                let (parent, x, c) = match k {
                    0 => (
                        p,
                        tail.parent_from_joint[i],
                        Coordinates::Head {
                            block: Block::Spherical,
                            at,
                        },
                    ),
                    _ => (bodies.len() - 1, Transform::identity(), Coordinates::Member),
                };
                bodies.push((
                    Some(parent),
                    Joint {
                        kind: JointKind::Revolute,
                        axis: unit(k),
                    },
                    x,
                    inertia,
                    c,
                ));
            }
            at += 4;
        } else {
            bodies.push((
                Some(p),
                tail.joints[i],
                tail.parent_from_joint[i],
                tail.inertia[i],
                Coordinates::Scalar { at },
            ));
            at += 1;
        }
        index[i] = bodies.len() - 1;
    }
    let count = bodies.len();
    // drive data of the 1-DOF joints only (a multi-DOF joint has none)
    let scalar_only = |v: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; count];
        for (i, x) in v.iter().enumerate().filter(|(i, _)| *i != 1) {
            out[index[i]] = *x;
        }
        out
    };
    let frames = (0..n)
        .map(|b| Frame {
            body: Some(index[b]),
            body_from_frame: tail.frames[b].body_from_frame,
        })
        .collect();
    Model::new(
        bodies.iter().map(|b| b.0).collect(),
        bodies.iter().map(|b| b.1).collect(),
        scalar_only(&tail.offset),
        bodies.iter().map(|b| b.2).collect(),
        bodies.iter().map(|b| b.3).collect(),
        scalar_only(&tail.armature),
        scalar_only(&tail.viscous),
        scalar_only(&tail.coulomb),
        tail.gravity,
        frames,
    )
    .and_then(|m| m.with_coordinates(bodies.iter().map(|b| b.4).collect()))
    .expect("random floating models are valid by construction")
}

/// A random configuration of `model` (nq numbers): joint coordinates in `[-3, 3]`, unit quaternions
/// for free-flyer and spherical joints, `(cos, sin)` of a random angle for planar ones.
pub fn random_configuration(model: &Model, rng: &mut Rng) -> Vec<f64> {
    use crate::lie::Block;
    use crate::model::Coordinates;
    let mut q = vec![0.0; model.nq];
    for c in &model.coordinates {
        match *c {
            Coordinates::Scalar { at } => q[at] = rng.uniform(-3.0, 3.0),
            Coordinates::Head { block, at } => {
                let (start, quaternion) = match block {
                    Block::FreeFlyer => (at + 3, true),
                    Block::Spherical => (at, true),
                    Block::Planar => (at + 2, false),
                    Block::Scalar => unreachable!("a multi-DOF head is never a scalar block"),
                };
                for x in &mut q[at..start] {
                    *x = rng.uniform(-1.0, 1.0);
                }
                if quaternion {
                    let v: Vec<f64> = (0..4).map(|_| rng.uniform(-1.0, 1.0)).collect();
                    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                    for k in 0..4 {
                        q[start + k] = v[k] / norm;
                    }
                } else {
                    let th = rng.uniform(-3.0, 3.0);
                    (q[start], q[start + 1]) = (th.cos(), th.sin());
                }
            }
            Coordinates::Member => {}
        }
    }
    q
}

/// A forward-mode dual number `re + eps ε` (ε² = 0): the algorithms run on it (they are generic
/// over [`crate::Real`]) give a value and its exact directional derivative, the second,
/// independent route the analytical derivatives are tested against (no step size, no truncation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dual {
    pub re: f64,
    pub eps: f64,
}

impl Dual {
    pub fn new(re: f64, eps: f64) -> Self {
        Self { re, eps }
    }
    /// `x` with `eps = 1` at index `k` and 0 elsewhere (the direction e_k).
    pub fn seeded(x: &[f64], k: Option<usize>) -> Vec<Dual> {
        x.iter()
            .enumerate()
            .map(|(i, &v)| Dual::new(v, if Some(i) == k { 1.0 } else { 0.0 }))
            .collect()
    }
}

mod dual_ops {
    use super::Dual;
    use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
    impl Add for Dual {
        type Output = Dual;
        fn add(self, o: Dual) -> Dual {
            Dual::new(self.re + o.re, self.eps + o.eps)
        }
    }
    impl Sub for Dual {
        type Output = Dual;
        fn sub(self, o: Dual) -> Dual {
            Dual::new(self.re - o.re, self.eps - o.eps)
        }
    }
    impl Mul for Dual {
        type Output = Dual;
        fn mul(self, o: Dual) -> Dual {
            Dual::new(self.re * o.re, self.re * o.eps + self.eps * o.re)
        }
    }
    impl Div for Dual {
        type Output = Dual;
        fn div(self, o: Dual) -> Dual {
            Dual::new(self.re / o.re, (self.eps * o.re - self.re * o.eps) / (o.re * o.re))
        }
    }
    impl Neg for Dual {
        type Output = Dual;
        fn neg(self) -> Dual {
            Dual::new(-self.re, -self.eps)
        }
    }
    impl AddAssign for Dual {
        fn add_assign(&mut self, o: Dual) {
            *self = *self + o;
        }
    }
    impl SubAssign for Dual {
        fn sub_assign(&mut self, o: Dual) {
            *self = *self - o;
        }
    }
    impl MulAssign for Dual {
        fn mul_assign(&mut self, o: Dual) {
            *self = *self * o;
        }
    }
    impl num_traits::Zero for Dual {
        fn zero() -> Dual {
            Dual::new(0.0, 0.0)
        }
        fn is_zero(&self) -> bool {
            self.re == 0.0 && self.eps == 0.0
        }
    }
    impl num_traits::One for Dual {
        fn one() -> Dual {
            Dual::new(1.0, 0.0)
        }
    }
}

impl crate::Real for Dual {
    const LANES: usize = 1;
    fn splat(x: f64) -> Self {
        Dual::new(x, 0.0)
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = crate::scalar::trig::sin_cos(self.re);
        (Dual::new(s, c * self.eps), Dual::new(c, -s * self.eps))
    }
    fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]) {
        for (s, c) in x.iter_mut().zip(cos.iter_mut()) {
            (*s, *c) = s.sin_cos();
        }
    }
    fn signed_level(self, a: f64, b: f64) -> Self {
        // piecewise constant in the rate: no derivative
        Dual::new(self.re.signed_level(a, b), 0.0)
    }
    fn lane(self, _k: usize) -> f64 {
        self.re
    }
    fn set_lane(&mut self, _k: usize, x: f64) {
        self.re = x;
    }
}
