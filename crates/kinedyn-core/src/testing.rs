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
    let principal = Mat3::from_diagonal(&Vec3::new(k * (b * b + c * c), k * (a * a + c * c), k * (a * a + b * b)));
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
        let kind = if rng.uniform(0.0, 1.0) < 0.25 { JointKind::Prismatic } else { JointKind::Revolute };
        joints.push(Joint { kind, axis: random_axis(&mut rng) });
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
        .map(|b| Frame { body: Some(b), body_from_frame: Transform::new(rng.rotation(), rng.vec3(-0.3, 0.3)) })
        .chain(std::iter::once(Frame { body: None, body_from_frame: Transform::identity() }))
        .collect();
    Model::new(parent, joints, offset, placements, inertias, armature, viscous, coulomb, Vec3::new(0.0, 0.0, -9.81), frames)
        .expect("random models are valid by construction")
}

/// A random unit vector, or (half of the time) a signed coordinate axis.
fn random_axis(rng: &mut Rng) -> Vec3 {
    let k = rng.next_u64() % 12;
    if k >= 6 {
        return rng.unit();
    }
    let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
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
    let joints = vec![Joint { kind: JointKind::Revolute, axis: Vec3::z() }; n];
    let parent = (0..n).map(|i| i.checked_sub(1)).collect();
    let inertias = (0..n).map(|_| random_inertia(&mut rng)).collect();
    let tool = Frame { body: Some(n - 1), body_from_frame: previous };
    Model::new(parent, joints, vec![0.0; n], placements, inertias, vec![0.0; n], vec![0.0; n], vec![0.0; n], Vec3::new(0.0, 0.0, -9.81), vec![tool])
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
