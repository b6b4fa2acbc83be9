//! The two benchmark models shared by the core benches: the UR5 from Universal Robots' standard DH
//! table and dynamic parameters, and the Panda from Franka's modified DH table with its published
//! masses and centres of mass (inertia tensors: solid boxes, for the work they cause, not physics).

use kinedyn_core::joint::axis_angle;
use kinedyn_core::spatial::{Inertia, Mat3, Transform, Vec3};
use kinedyn_core::{Joint, JointKind, Model};
use std::f64::consts::FRAC_PI_2;

/// `(mass, centre of mass in the link frame, box size)` -> inertia about the link-frame origin.
fn body(mass: f64, c: [f64; 3], size: f64) -> Inertia {
    let c = Vec3::new(c[0], c[1], c[2]);
    let k = mass * size * size / 6.0;
    let sc = kinedyn_core::spatial::skew(&c);
    Inertia::new(mass, mass * c, Mat3::from_diagonal_element(k) - mass * sc * sc)
}

fn serial(placements: Vec<Transform>, inertias: Vec<Inertia>) -> Model {
    let n = placements.len();
    let joints = vec![Joint { kind: JointKind::Revolute, axis: Vec3::z() }; n];
    let parent = (0..n).map(|i| i.checked_sub(1)).collect();
    let z = vec![0.0; n];
    Model::new(parent, joints, z.clone(), placements, inertias, z.clone(), z.clone(), z, Vec3::new(0.0, 0.0, -9.81), vec![]).unwrap()
}

/// UR5, standard DH `(d, a, alpha)`: body i = joint frame i; placement_i = Tx(a_{i-1}) Rx(alpha_{i-1}) Tz(d_i).
pub fn ur5() -> Model {
    let dh = [(0.089159, 0.0, FRAC_PI_2), (0.0, -0.425, 0.0), (0.0, -0.39225, 0.0), (0.10915, 0.0, FRAC_PI_2), (0.09465, 0.0, -FRAC_PI_2), (0.0823, 0.0, 0.0)];
    let masses = [3.7, 8.393, 2.275, 1.219, 1.219, 0.1879];
    let coms = [[0.0, -0.02561, 0.00193], [0.2125, 0.0, 0.11336], [0.15, 0.0, 0.0265], [0.0, -0.0018, 0.01634], [0.0, 0.0018, 0.01634], [0.0, 0.0, -0.001159]];
    let mut previous = Transform::identity();
    let mut placements = Vec::new();
    for &(d, a, alpha) in &dh {
        placements.push(previous * Transform::new(Mat3::identity(), Vec3::new(0.0, 0.0, d)));
        previous = Transform::new(axis_angle(&Vec3::x(), alpha), Vec3::new(a, 0.0, 0.0));
    }
    // centres of mass are given in the DH link frames: move them into the joint (body) frames
    let inertias = (0..6).map(|i| dh_link_to_body(&dh[i], body(masses[i], coms[i], 0.1))).collect();
    serial(placements, inertias)
}

fn dh_link_to_body(&(d, a, alpha): &(f64, f64, f64), link: Inertia) -> Inertia {
    let body_from_link = Transform::new(Mat3::identity(), Vec3::new(0.0, 0.0, d)) * Transform::new(axis_angle(&Vec3::x(), alpha), Vec3::new(a, 0.0, 0.0));
    body_from_link.act_inertia(&link)
}

/// Panda, modified DH `(a, d, alpha)`: placement_i = Rx(alpha_i) Tx(a_i) Tz(d_i), joint about z.
pub fn panda() -> Model {
    let dh = [(0.0, 0.333, 0.0), (0.0, 0.0, -FRAC_PI_2), (0.0, 0.316, FRAC_PI_2), (0.0825, 0.0, FRAC_PI_2), (-0.0825, 0.384, -FRAC_PI_2), (0.0, 0.0, FRAC_PI_2), (0.088, 0.0, FRAC_PI_2)];
    let masses = [4.97, 0.646, 3.228, 3.587, 1.225, 1.666, 0.735];
    let coms = [[0.0035, 0.0029, -0.0762], [-0.0032, -0.0714, 0.0042], [0.0275, 0.0392, -0.0665], [-0.0532, 0.1047, 0.0274], [-0.0119, 0.0413, -0.0383], [0.0601, -0.0141, -0.0104], [0.0105, -0.0043, 0.0616]];
    let placements = dh.iter().map(|&(a, d, alpha)| Transform::new(axis_angle(&Vec3::x(), alpha), Vec3::new(a, 0.0, 0.0)) * Transform::new(Mat3::identity(), Vec3::new(0.0, 0.0, d))).collect();
    let inertias = (0..7).map(|i| body(masses[i], coms[i], 0.12)).collect();
    serial(placements, inertias)
}

/// Both models with their names.
pub fn all() -> [(&'static str, Model); 2] {
    [("ur5", ur5()), ("panda", panda())]
}

/// The benchmark state `(q, qd, qdd)` of an n-joint model (the C++ harness uses the same numbers).
pub fn state(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.3 + 0.7 * i as f64).collect();
    let qd = (0..n).map(|i| 1.1 - 0.4 * i as f64).collect();
    let qdd = (0..n).map(|i| -0.5 + 0.3 * i as f64).collect();
    (q, qd, qdd)
}
