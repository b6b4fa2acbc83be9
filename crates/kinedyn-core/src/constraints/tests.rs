//! Checks of the loop algorithms by independent routes: `J` against central differences of the
//! residual on the configuration manifold (`q ⊕ h e_k`), `gamma` against differences of `J qd`
//! along `q ⊕ t qd`, the constrained dynamics against the equations it solves (RNEA and `J`),
//! redundant rows against the same loop declared once, and the lanes against single calls.

use super::*;
use crate::algorithms::{forward_kinematics, rnea};
use crate::batch::{self, kernels::ConstrainedForwardDynamics, Input, Scratch, Simd};
use crate::model::Frame;
use crate::testing::{random_configuration, random_floating_model, random_model, Rng};
use crate::Data;

/// `model` with loops between the frames of two bodies, closed at `q0`: for each `(a, b, kind)`,
/// frame a as it is and a new frame on frame b's body placed where frame a is at `q0`.
fn closed(mut model: Model, q0: &[f64], pairs: &[(usize, usize, LoopKind)]) -> Model {
    let mut data = Data::new(&model);
    forward_kinematics(&model, &mut data, q0);
    let mut loops = Vec::new();
    for (k, &(a, b, kind)) in pairs.iter().enumerate() {
        let world_a = kinematics_pose(&model, &data, a);
        let body = model.frames[b].body;
        let world_body = body.map_or(crate::spatial::Transform::identity(), |b| data.world_from_body[b]);
        model.frames.push(Frame {
            body,
            body_from_frame: world_body.inverse() * world_a,
        });
        loops.push(Loop {
            name: format!("loop{k}"),
            frame_a: a,
            frame_b: model.frames.len() - 1,
            kind,
        });
    }
    model.with_loops(loops).unwrap()
}

fn kinematics_pose(model: &Model, data: &Data, frame: usize) -> crate::spatial::Transform {
    crate::algorithms::frame_pose(model, data, frame)
}

/// The first frame on `body` (`None`: the base), added at the body's origin if it has none.
fn frame_on(model: &mut Model, body: Option<usize>) -> usize {
    if let Some(k) = model.frames.iter().position(|f| f.body == body) {
        return k;
    }
    model.frames.push(Frame {
        body,
        body_from_frame: crate::spatial::Transform::identity(),
    });
    model.frames.len() - 1
}

/// The body with the most joints supporting it.
fn deepest(model: &Model) -> usize {
    (0..model.n).max_by_key(|&b| model.support[b].len()).unwrap()
}

/// Models with loops (J of full row rank), closed at the configuration returned with them: a
/// chain with a point and a weld loop between its links, a tree with a point loop pinning its
/// deepest link to the ground, a floating tree (a free-flyer and a spherical joint) with a point
/// and a weld loop to the ground.
fn cases() -> Vec<(&'static str, Model, Vec<f64>)> {
    let chain = random_model(11, 10, false);
    let tree = random_model(12, 10, true);
    let floating = random_floating_model(13, 6, true);
    let mut out = Vec::new();
    for (name, mut model, seed) in [
        ("chain", chain, 1u64),
        ("tree", tree, 2),
        ("floating tree", floating, 3),
    ] {
        let q0 = random_configuration(&model, &mut Rng::new(seed));
        let d = deepest(&model);
        let up = model.parent[d].unwrap_or(d);
        let pairs = match name {
            "chain" => vec![
                (
                    frame_on(&mut model, Some(9)),
                    frame_on(&mut model, Some(2)),
                    LoopKind::Point,
                ),
                (
                    frame_on(&mut model, Some(8)),
                    frame_on(&mut model, Some(1)),
                    LoopKind::Weld,
                ),
            ],
            "tree" => vec![(
                frame_on(&mut model, Some(d)),
                frame_on(&mut model, None),
                LoopKind::Point,
            )],
            _ => vec![
                (
                    frame_on(&mut model, Some(d)),
                    frame_on(&mut model, None),
                    LoopKind::Point,
                ),
                (
                    frame_on(&mut model, Some(up)),
                    frame_on(&mut model, None),
                    LoopKind::Weld,
                ),
            ],
        };
        out.push((name, closed(model, &q0, &pairs), q0));
    }
    out
}

fn stepped(model: &Model, q: &[f64], v: &[f64], h: f64) -> Vec<f64> {
    let mut out = vec![0.0; model.nq];
    model.integrate_configuration(q, v, h, &mut out);
    out
}

fn residual(model: &Model, data: &mut Data, q: &[f64]) -> Vec<f64> {
    let mut r = vec![0.0; model.loop_rows()];
    loop_residual(model, data, q, &mut r);
    r
}

fn jacobian(model: &Model, data: &mut Data, q: &[f64]) -> Vec<f64> {
    let mut j = vec![0.0; model.loop_rows() * model.n];
    loop_jacobian(model, data, q, &mut j);
    j
}

#[test]
fn residual_vanishes_where_closed_and_jacobian_is_its_derivative() {
    for (name, model, q0) in cases() {
        let (n, m) = (model.n, model.loop_rows());
        let mut data = Data::new(&model);
        let r0 = residual(&model, &mut data, &q0);
        assert!(r0.iter().all(|x| x.abs() < 1e-12), "{name}: closed at q0, r = {r0:?}");
        let j = jacobian(&model, &mut data, &q0);
        let h = 1e-6;
        for k in 0..n {
            let e: Vec<f64> = (0..n).map(|i| if i == k { 1.0 } else { 0.0 }).collect();
            let plus = residual(&model, &mut data, &stepped(&model, &q0, &e, h));
            let minus = residual(&model, &mut data, &stepped(&model, &q0, &e, -h));
            for row in 0..m {
                let fd = (plus[row] - minus[row]) / (2.0 * h);
                assert!(
                    (fd - j[row * n + k]).abs() < 1e-7,
                    "{name}: J[{row}][{k}] = {} vs {fd}",
                    j[row * n + k]
                );
            }
        }
    }
}

#[test]
fn point_jacobian_is_the_derivative_of_the_residual_anywhere() {
    // off the closure too: the point rows are p_a - p_b, whose derivative J is everywhere
    let model = random_model(21, 6, true);
    let last = model.frames.len() - 1;
    let model = model
        .with_loops(vec![Loop {
            name: "p".into(),
            frame_a: last,
            frame_b: 2,
            kind: LoopKind::Point,
        }])
        .unwrap();
    let mut data = Data::new(&model);
    let q = random_configuration(&model, &mut Rng::new(5));
    let j = jacobian(&model, &mut data, &q);
    let h = 1e-6;
    for k in 0..model.n {
        let mut qp = q.clone();
        let mut qm = q.clone();
        qp[k] += h;
        qm[k] -= h;
        let (p, m) = (residual(&model, &mut data, &qp), residual(&model, &mut data, &qm));
        for row in 0..3 {
            let fd = (p[row] - m[row]) / (2.0 * h);
            assert!((fd - j[row * model.n + k]).abs() < 1e-7);
        }
    }
}

#[test]
fn gamma_is_the_time_derivative_of_j_qd() {
    for (name, model, q0) in cases() {
        let (n, m) = (model.n, model.loop_rows());
        let mut data = Data::new(&model);
        let qd = Rng::new(9).vector(n, -1.5, 1.5);
        let mut gamma = vec![0.0; m];
        loop_gamma(&model, &mut data, &q0, &qd, &mut gamma);
        // d/dt (J(q(t)) qd) along q(t) = q0 ⊕ t qd, on which qdd = 0
        let h = 1e-6;
        let jqd = |data: &mut Data, t: f64| {
            let j = jacobian(&model, data, &stepped(&model, &q0, &qd, t));
            (0..m)
                .map(|r| (0..n).map(|c| j[r * n + c] * qd[c]).sum::<f64>())
                .collect::<Vec<_>>()
        };
        let (p, mm) = (jqd(&mut data, h), jqd(&mut data, -h));
        for row in 0..m {
            let fd = (p[row] - mm[row]) / (2.0 * h);
            assert!(
                (fd - gamma[row]).abs() < 1e-6 * (1.0 + fd.abs()),
                "{name}: gamma[{row}] = {} vs {fd}",
                gamma[row]
            );
        }
    }
}

/// `[qdd; lambda]` at a random state.
fn solve_state(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    seed: u64,
    f_ext: Option<&[f64]>,
) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = Rng::new(seed);
    let (open, tau) = (rng.vector(model.n, -1.0, 1.0), rng.vector(model.n, -3.0, 3.0));
    // a velocity that keeps the loops closed
    let mut qd = vec![0.0; model.n];
    project_velocity(model, data, q, &open, &mut qd);
    let mut out = vec![0.0; model.n + model.loop_rows()];
    constrained_forward_dynamics(model, data, q, &qd, &tau, f_ext, &PROXIMAL, &mut out).unwrap();
    let lambda = out.split_off(model.n);
    (qd, tau, out, lambda)
}

#[test]
fn constrained_dynamics_solves_its_equations() {
    for (name, model, q0) in cases() {
        let (n, m) = (model.n, model.loop_rows());
        let mut data = Data::new(&model);
        let f_ext = Rng::new(4).vector(6 * n, -2.0, 2.0);
        for fx in [None, Some(&f_ext[..])] {
            let (qd, tau, qdd, lambda) = solve_state(&model, &mut data, &q0, 17, fx);
            let j = jacobian(&model, &mut data, &q0);
            let mut gamma = vec![0.0; m];
            loop_gamma(&model, &mut data, &q0, &qd, &mut gamma);
            for row in 0..m {
                let c: f64 = (0..n).map(|k| j[row * n + k] * qdd[k]).sum::<f64>() + gamma[row];
                assert!(c.abs() < 1e-9, "{name}: (J qdd + gamma)[{row}] = {c:e}");
            }
            // M qdd + h - tau = rnea(q, qd, qdd, f_ext) - tau = J^T lambda
            let id = rnea(&model, &mut data, &q0, &qd, &qdd, fx).to_vec();
            for k in 0..n {
                let jtl: f64 = (0..m).map(|row| j[row * n + k] * lambda[row]).sum();
                assert!(
                    (id[k] - tau[k] - jtl).abs() < 1e-8 * (1.0 + jtl.abs()),
                    "{name}: joint {k}: {} vs {jtl}",
                    id[k] - tau[k]
                );
            }
        }
    }
}

#[test]
fn a_loop_declared_twice_gives_the_same_motion_and_shares_its_force() {
    // two identical loops: A = J M^-1 J^T is singular (rank 3 of 6); the proximal iteration must give
    // the single loop's qdd and the least-norm split of its force, half on each
    let base = random_model(31, 6, false);
    let q0 = random_configuration(&base, &mut Rng::new(8));
    let mut base = base;
    let pair = (
        frame_on(&mut base, Some(5)),
        frame_on(&mut base, Some(1)),
        LoopKind::Point,
    );
    let once = closed(base, &q0, &[pair]);
    let mut twice_loops = once.loops.clone();
    twice_loops.push(Loop {
        name: "again".into(),
        ..once.loops[0].clone()
    });
    let twice = once.clone().with_loops(twice_loops).unwrap();
    let (mut d1, mut d2) = (Data::new(&once), Data::new(&twice));
    let (_, _, qdd1, l1) = solve_state(&once, &mut d1, &q0, 3, None);
    let (_, _, qdd2, l2) = solve_state(&twice, &mut d2, &q0, 3, None);
    for k in 0..once.n {
        assert!(
            (qdd1[k] - qdd2[k]).abs() < 1e-9 * (1.0 + qdd1[k].abs()),
            "qdd[{k}] {} vs {}",
            qdd1[k],
            qdd2[k]
        );
    }
    for r in 0..3 {
        // the split is exact up to the rounding that the null direction keeps (cond(A + mu) eps)
        assert!(
            (l2[r] - 0.5 * l1[r]).abs() < 1e-5 * (1.0 + l1[r].abs()),
            "{l1:?} {l2:?}"
        );
        assert!(
            (l2[3 + r] - 0.5 * l1[r]).abs() < 1e-5 * (1.0 + l1[r].abs()),
            "{l1:?} {l2:?}"
        );
    }
}

#[test]
fn a_batch_in_lanes_gives_the_single_calls() {
    // unoptimised lane code keeps every temporary on the stack: a thread with room for it
    std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(lanes_equal_single_calls)
        .unwrap()
        .join()
        .unwrap();
}

fn lanes_equal_single_calls() {
    for (name, model, q0) in cases() {
        let (n, m, nq) = (model.n, model.loop_rows(), model.nq);
        let states = 11;
        let mut rng = Rng::new(44);
        let q: Vec<f64> = (0..states).flat_map(|_| q0.clone()).collect();
        let (open, tau) = (rng.vector(states * n, -1.0, 1.0), rng.vector(states * n, -2.0, 2.0));
        let mut data = Data::new(&model);
        let mut qd = vec![0.0; states * n];
        for (v, o) in qd.chunks_mut(n).zip(open.chunks(n)) {
            project_velocity(&model, &mut data, &q0, o, v);
        }
        let inputs = [
            Input { values: &q, width: nq },
            Input { values: &qd, width: n },
            Input { values: &tau, width: n },
        ];
        let mut scratch = Scratch::new(&model);
        let mut single = vec![0.0; states * (n + m)];
        batch::run(
            &model,
            &mut scratch,
            &ConstrainedForwardDynamics,
            &inputs,
            &mut single,
            Simd::Off,
        )
        .unwrap();
        for simd in [Simd::Portable, Simd::Avx2, Simd::Avx512]
            .into_iter()
            .filter(|s| s.is_supported())
        {
            let mut lanes = vec![0.0; states * (n + m)];
            batch::run(
                &model,
                &mut scratch,
                &ConstrainedForwardDynamics,
                &inputs,
                &mut lanes,
                simd,
            )
            .unwrap();
            for (k, (a, b)) in single.iter().zip(&lanes).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-9 * (1.0 + a.abs()),
                    "{name} {simd:?}: [{k}] {a} vs {b}"
                );
            }
        }
    }
}

#[test]
fn inverse_then_forward_gives_the_motion_back() {
    for (name, model, q0) in cases() {
        let n = model.n;
        let mut data = Data::new(&model);
        let (qd, _, qdd, _) = solve_state(&model, &mut data, &q0, 5, None);
        // passive: columns of J that together have the loops' rank (chosen greedily from the last);
        // actuated: the others
        let j = nalgebra::DMatrix::from_row_slice(model.loop_rows(), n, &jacobian(&model, &mut data, &q0));
        let rank = |cols: &[usize]| {
            let sub = nalgebra::DMatrix::from_fn(j.nrows(), cols.len(), |r, c| j[(r, cols[c])]);
            sub.svd(false, false).rank(1e-9)
        };
        let mut passive: Vec<usize> = Vec::new();
        for k in (0..n).rev() {
            let mut with = passive.clone();
            with.push(k);
            if rank(&with) > passive.len() {
                passive = with;
            }
        }
        let actuated: Vec<usize> = (0..n).filter(|k| !passive.contains(k)).collect();
        let mut tau = vec![0.0; n];
        constrained_inverse_dynamics(&model, &mut data, &q0, &qd, &qdd, None, &actuated, &mut tau)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(passive.iter().all(|&k| tau[k] == 0.0));
        let mut out = vec![0.0; n + model.loop_rows()];
        constrained_forward_dynamics(&model, &mut data, &q0, &qd, &tau, None, &PROXIMAL, &mut out).unwrap();
        for k in 0..n {
            assert!(
                (out[k] - qdd[k]).abs() < 1e-7 * (1.0 + qdd[k].abs()),
                "{name}: qdd[{k}] {} vs {}",
                out[k],
                qdd[k]
            );
        }
    }
}

#[test]
fn inverse_dynamics_refuses_an_open_motion() {
    let (_, model, q0) = cases().remove(0);
    let mut data = Data::new(&model);
    let n = model.n;
    let mut tau = vec![0.0; n];
    let err = constrained_inverse_dynamics(
        &model,
        &mut data,
        &q0,
        &vec![0.0; n],
        &vec![1.0; n],
        None,
        &[0],
        &mut tau,
    )
    .unwrap_err();
    assert!(err.to_string().contains("does not keep loop"), "{err}");
}

#[test]
fn projections_close_the_loops() {
    for (name, model, q0) in cases() {
        let (n, nq) = (model.n, model.nq);
        let mut data = Data::new(&model);
        let push = Rng::new(6).vector(n, -0.05, 0.05);
        let start = stepped(&model, &q0, &push, 1.0);
        // hold the first joint (a floating base whole: its block of q must not move)
        let (hold, held_q): (Vec<usize>, usize) = if model.plain {
            (vec![0], 1)
        } else {
            ((0..6).collect(), 7)
        };
        let mut q = vec![0.0; nq];
        project_configuration(&model, &mut data, &start, &hold, 1e-12, 50, &mut q).unwrap();
        let r = residual(&model, &mut data, &q);
        assert!(r.iter().all(|x| x.abs() <= 1e-12), "{name}: {r:?}");
        assert_eq!(q[..held_q], start[..held_q], "{name}: a held joint moved");
        let qd = Rng::new(7).vector(n, -1.0, 1.0);
        let mut v = vec![0.0; n];
        project_velocity(&model, &mut data, &q, &qd, &mut v);
        let j = jacobian(&model, &mut data, &q);
        for row in 0..model.loop_rows() {
            let c: f64 = (0..n).map(|k| j[row * n + k] * v[k]).sum();
            assert!(c.abs() < 1e-10, "{name}: (J qd)[{row}] = {c:e}");
        }
    }
}

#[test]
fn a_loop_must_name_two_frames_of_the_model() {
    let model = random_model(1, 3, false);
    let frames = model.frames.len();
    let bad = |a, b| {
        model
            .clone()
            .with_loops(vec![Loop {
                name: "l".into(),
                frame_a: a,
                frame_b: b,
                kind: LoopKind::Point,
            }])
            .unwrap_err()
            .to_string()
    };
    assert!(bad(0, frames).contains("loop 0 'l': frame"));
    assert!(bad(1, 1).contains("on itself"));
    assert!(LoopKind::from_name("hinge").unwrap_err().to_string().contains("point"));
}
