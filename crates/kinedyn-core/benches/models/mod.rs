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
    let joints = vec![
        Joint {
            kind: JointKind::Revolute,
            axis: Vec3::z()
        };
        n
    ];
    let parent = (0..n).map(|i| i.checked_sub(1)).collect();
    let z = vec![0.0; n];
    Model::new(
        parent,
        joints,
        z.clone(),
        placements,
        inertias,
        z.clone(),
        z.clone(),
        z,
        Vec3::new(0.0, 0.0, -9.81),
        vec![],
    )
    .unwrap()
}

/// UR5, standard DH `(d, a, alpha)`: body i = joint frame i; placement_i = Tx(a_{i-1}) Rx(alpha_{i-1}) Tz(d_i).
pub fn ur5() -> Model {
    let dh = [
        (0.089159, 0.0, FRAC_PI_2),
        (0.0, -0.425, 0.0),
        (0.0, -0.39225, 0.0),
        (0.10915, 0.0, FRAC_PI_2),
        (0.09465, 0.0, -FRAC_PI_2),
        (0.0823, 0.0, 0.0),
    ];
    let masses = [3.7, 8.393, 2.275, 1.219, 1.219, 0.1879];
    let coms = [
        [0.0, -0.02561, 0.00193],
        [0.2125, 0.0, 0.11336],
        [0.15, 0.0, 0.0265],
        [0.0, -0.0018, 0.01634],
        [0.0, 0.0018, 0.01634],
        [0.0, 0.0, -0.001159],
    ];
    let mut previous = Transform::identity();
    let mut placements = Vec::new();
    for &(d, a, alpha) in &dh {
        placements.push(previous * Transform::new(Mat3::identity(), Vec3::new(0.0, 0.0, d)));
        previous = Transform::new(axis_angle(&Vec3::x(), alpha), Vec3::new(a, 0.0, 0.0));
    }
    // centres of mass are given in the DH link frames: move them into the joint (body) frames
    let inertias = (0..6)
        .map(|i| dh_link_to_body(&dh[i], body(masses[i], coms[i], 0.1)))
        .collect();
    serial(placements, inertias)
}

fn dh_link_to_body(&(d, a, alpha): &(f64, f64, f64), link: Inertia) -> Inertia {
    let body_from_link = Transform::new(Mat3::identity(), Vec3::new(0.0, 0.0, d))
        * Transform::new(axis_angle(&Vec3::x(), alpha), Vec3::new(a, 0.0, 0.0));
    body_from_link.act_inertia(&link)
}

/// Panda, modified DH `(a, d, alpha)`: placement_i = Rx(alpha_i) Tx(a_i) Tz(d_i), joint about z.
pub fn panda() -> Model {
    let dh = [
        (0.0, 0.333, 0.0),
        (0.0, 0.0, -FRAC_PI_2),
        (0.0, 0.316, FRAC_PI_2),
        (0.0825, 0.0, FRAC_PI_2),
        (-0.0825, 0.384, -FRAC_PI_2),
        (0.0, 0.0, FRAC_PI_2),
        (0.088, 0.0, FRAC_PI_2),
    ];
    let masses = [4.97, 0.646, 3.228, 3.587, 1.225, 1.666, 0.735];
    let coms = [
        [0.0035, 0.0029, -0.0762],
        [-0.0032, -0.0714, 0.0042],
        [0.0275, 0.0392, -0.0665],
        [-0.0532, 0.1047, 0.0274],
        [-0.0119, 0.0413, -0.0383],
        [0.0601, -0.0141, -0.0104],
        [0.0105, -0.0043, 0.0616],
    ];
    let placements = dh
        .iter()
        .map(|&(a, d, alpha)| {
            Transform::new(axis_angle(&Vec3::x(), alpha), Vec3::new(a, 0.0, 0.0))
                * Transform::new(Mat3::identity(), Vec3::new(0.0, 0.0, d))
        })
        .collect();
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

/// A floating-base robot read from a tree file of `benches/cpp/dump_tree.py` (the C++ harness builds
/// Pinocchio's model from the same file): its name, model and state `(q, v, a)`.
#[allow(dead_code)]
pub struct TreeFile {
    pub name: String,
    pub model: Model,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    /// kinedyn's Python `inverse_dynamics` at the state (a third side of the check).
    pub expect_rnea: Vec<f64>,
    /// `benches/cpp/dump_loops.py`'s closed states, `[q, qd, tau, qdd]` each (none in a plain tree file).
    pub states: Vec<Vec<f64>>,
}

#[allow(dead_code)]
fn parse_numbers(path: &str, line: &str, words: &mut std::str::SplitWhitespace, count: usize) -> Vec<f64> {
    let out: Vec<f64> = words
        .by_ref()
        .take(count)
        .map(|w| {
            w.parse()
                .unwrap_or_else(|e| panic!("{path}: '{w}' in '{line:.40}...': {e}"))
        })
        .collect();
    assert_eq!(out.len(), count, "{path}: too few numbers in '{line:.40}...'");
    out
}

/// Build the kinedyn-core model of a tree file: each body's joint taken whole by the core's
/// `ModelBuilder` (a free-flyer becomes six native bodies), as `python/kinedyn/native/compile.py`
/// compiles a description.
#[allow(dead_code)]
pub fn read_tree(path: &str) -> TreeFile {
    use kinedyn_core::joint::JointType;
    use kinedyn_core::model::{JointRecord, ModelBuilder};
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
    let mut lines = text.lines();
    let mut next = |key: &str| -> (String, Vec<String>) {
        let line = lines
            .next()
            .unwrap_or_else(|| panic!("{path}: ends before its '{key}' line"))
            .to_string();
        let mut words = line.split_whitespace();
        let got = words.next().unwrap_or("");
        assert_eq!(got, key, "{path}: expected a '{key}' line");
        let rest = words.map(str::to_string).collect();
        (line, rest)
    };
    let name = next("robot").1[0].clone();
    let sizes: Vec<usize> = next("sizes").1.iter().map(|w| w.parse().unwrap()).collect();
    let (nq, nv, nbodies) = (sizes[0], sizes[1], sizes[2]);
    let g: Vec<f64> = next("gravity").1.iter().map(|w| w.parse().unwrap()).collect();
    let mut builder = ModelBuilder::new(Vec3::new(g[0], g[1], g[2]));
    for b in 0..nbodies {
        let (line, words) = next("body");
        let joined = words.join(" ");
        let mut w = joined.split_whitespace();
        let p: i64 = w.next().unwrap().parse().unwrap();
        let kind = w.next().unwrap().to_string();
        let x = parse_numbers(path, &line, &mut w, 28);
        let axis = Vec3::new(x[0], x[1], x[2]);
        let rot = Mat3::new(x[3], x[4], x[5], x[6], x[7], x[8], x[9], x[10], x[11]);
        let placement = Transform::new(rot, Vec3::new(x[12], x[13], x[14]));
        let (mass, c) = (x[15], Vec3::new(x[16], x[17], x[18]));
        let i_c = Mat3::new(x[19], x[20], x[21], x[22], x[23], x[24], x[25], x[26], x[27]);
        let sc = kinedyn_core::spatial::skew(&c);
        let inertia = Inertia::new(mass, mass * c, i_c - mass * sc * sc); // about the body origin
        let joint = match kind.as_str() {
            "free" => JointType::FreeFlyer,
            other => JointType::from_name(other, Some(axis)).unwrap_or_else(|e| panic!("{path}: body {b}: {e}")),
        };
        let parent = usize::try_from(p).ok();
        builder
            .joint(JointRecord::new(
                &format!("body {b}"),
                joint,
                parent,
                placement,
                inertia,
            ))
            .unwrap_or_else(|e| panic!("{path}: {e}"));
    }
    let mut vector = |key: &str, len: usize| -> Vec<f64> {
        let (line, words) = next(key);
        let joined = words.join(" ");
        parse_numbers(path, &line, &mut joined.split_whitespace(), len)
    };
    let (q, v, a) = (vector("q", nq), vector("v", nv), vector("a", nv));
    let expect_rnea = vector("expect_rnea", nv);
    // dump_loops.py's lines: "loop KIND BODY_A R T BODY_B R T" ..., "states K", K "state" lines
    let mut loops = Vec::new();
    let mut states = Vec::new();
    for line in lines {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("loop") => {
                let kind = kinedyn_core::constraints::LoopKind::from_name(words.next().unwrap_or(""))
                    .unwrap_or_else(|e| panic!("{path}: {e}"));
                let mut frame = |words: &mut std::str::SplitWhitespace| {
                    let body: i64 = words.next().and_then(|w| w.parse().ok()).expect("a loop's body");
                    let x = parse_numbers(path, line, words, 12);
                    let rot = Mat3::new(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8]);
                    let placement = Transform::new(rot, Vec3::new(x[9], x[10], x[11]));
                    builder
                        .frame(usize::try_from(body).ok(), placement)
                        .unwrap_or_else(|e| panic!("{path}: {e}"))
                };
                let (frame_a, frame_b) = (frame(&mut words), frame(&mut words));
                loops.push(kinedyn_core::constraints::Loop {
                    name: format!("loop {}", loops.len()),
                    frame_a,
                    frame_b,
                    kind,
                });
            }
            Some("state") => states.push(parse_numbers(path, line, &mut words, nq + 3 * nv)),
            _ => {}
        }
    }
    let model = builder
        .build()
        .and_then(|m| m.with_loops(loops))
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    assert_eq!(
        (model.nq, model.n),
        (nq, nv),
        "{path}: built nq, nv = {}, {}, the file says {nq}, {nv}",
        model.nq,
        model.n
    );
    TreeFile {
        name,
        model,
        q,
        v,
        a,
        expect_rnea,
        states,
    }
}
