//! Kinematics identities on random chains and trees: Jacobians vs finite differences of FK,
//! twists vs J qd, and the acceleration drift vs the derivative of J qd.

use kinedyn_core::algorithms::{frame_jacobian, frame_pose_at, frame_velocity, jacobian_dot_qd, Reference};
use kinedyn_core::spatial::{Mat3, Vec3};
use kinedyn_core::testing::{random_model, Rng};
use kinedyn_core::{Data, Model};

const REFS: [Reference; 3] = [Reference::World, Reference::Local, Reference::Spatial];

fn models() -> Vec<Model> {
    vec![
        random_model(1, 7, false),
        random_model(2, 9, true),
        random_model(3, 1, false),
    ]
}

/// Angular velocity w (base axes) from dR/dt R^T, by central differences.
fn omega(rm: &Mat3, rp: &Mat3, h: f64) -> Vec3 {
    let w = (rp - rm) / (2.0 * h) * ((rp + rm) / 2.0).transpose();
    Vec3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]) / 2.0
}

#[test]
fn jacobians_match_finite_differences_of_forward_kinematics() {
    for model in models() {
        let mut data = Data::new(&model);
        let mut rng = Rng::new(7);
        let n = model.n;
        let q = rng.vector(n, -3.0, 3.0);
        let h = 1e-6;
        for frame in 0..model.frames.len() {
            let pose = frame_pose_at(&model, &mut data, &q, frame);
            let mut j = vec![0.0; 6 * n];
            for reference in REFS {
                frame_jacobian(&model, &mut data, &q, frame, reference, None, &mut j);
                for col in 0..n {
                    let (mut qp, mut qm) = (q.clone(), q.clone());
                    qp[col] += h;
                    qm[col] -= h;
                    let (tp, tm) = (
                        frame_pose_at(&model, &mut data, &qp, frame),
                        frame_pose_at(&model, &mut data, &qm, frame),
                    );
                    let v = (tp.trans - tm.trans) / (2.0 * h);
                    let w = omega(&tm.rot, &tp.rot, h);
                    let (lin, ang) = match reference {
                        Reference::World => (v, w),
                        Reference::Local => (pose.rot.transpose() * v, pose.rot.transpose() * w),
                        Reference::Spatial => (v - w.cross(&pose.trans), w),
                    };
                    let expected = [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z];
                    for row in 0..6 {
                        let got = j[row * n + col];
                        assert!(
                            (got - expected[row]).abs() < 1e-6,
                            "frame {frame} {reference:?} J[{row}][{col}] = {got}, fd {}",
                            expected[row]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn twist_is_j_qd_and_drift_is_its_derivative() {
    for model in models() {
        let mut data = Data::new(&model);
        let mut rng = Rng::new(11);
        let n = model.n;
        let q = rng.vector(n, -3.0, 3.0);
        let qd = rng.vector(n, -2.0, 2.0);
        let h = 1e-6;
        let point = Some(Vec3::new(0.1, -0.2, 0.05));
        for frame in 0..model.frames.len() {
            for reference in REFS {
                let jqd = |data: &mut Data, q: &[f64]| {
                    let mut j = vec![0.0; 6 * n];
                    frame_jacobian(&model, data, q, frame, reference, point.as_ref(), &mut j);
                    (0..6)
                        .map(|r| (0..n).map(|c| j[r * n + c] * qd[c]).sum::<f64>())
                        .collect::<Vec<f64>>()
                };
                let v = frame_velocity(&model, &mut data, &q, &qd, frame, reference, point.as_ref()).to_array();
                let expected = jqd(&mut data, &q);
                for r in 0..6 {
                    assert!((v[r] - expected[r]).abs() < 1e-12, "twist row {r}");
                }
                let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
                let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - h * b).collect();
                let (ep, em) = (jqd(&mut data, &qp), jqd(&mut data, &qm));
                let drift = jacobian_dot_qd(&model, &mut data, &q, &qd, frame, reference, point.as_ref()).to_array();
                for r in 0..6 {
                    let fd = (ep[r] - em[r]) / (2.0 * h);
                    assert!(
                        (drift[r] - fd).abs() < 1e-6 * fd.abs().max(1.0),
                        "frame {frame} {reference:?} drift row {r}: {} vs {fd}",
                        drift[r]
                    );
                }
            }
        }
    }
}

#[test]
fn hessian_matches_finite_differences_of_the_jacobian_and_gives_the_drift() {
    for model in models() {
        let mut data = Data::new(&model);
        let mut rng = Rng::new(23);
        let n = model.n;
        let q = rng.vector(n, -3.0, 3.0);
        let qd = rng.vector(n, -2.0, 2.0);
        let h = 1e-6;
        for point in [None, Some(Vec3::new(0.1, -0.2, 0.05))] {
            for frame in 0..model.frames.len() {
                for reference in REFS {
                    let mut hess = vec![0.0; 6 * n * n];
                    kinedyn_core::algorithms::frame_jacobian_hessian(
                        &model,
                        &mut data,
                        &q,
                        frame,
                        reference,
                        point.as_ref(),
                        &mut hess,
                    );
                    let (mut jp, mut jm) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
                    for i in 0..n {
                        let (mut qp, mut qm) = (q.clone(), q.clone());
                        qp[i] += h;
                        qm[i] -= h;
                        frame_jacobian(&model, &mut data, &qp, frame, reference, point.as_ref(), &mut jp);
                        frame_jacobian(&model, &mut data, &qm, frame, reference, point.as_ref(), &mut jm);
                        for k in 0..6 * n {
                            let fd = (jp[k] - jm[k]) / (2.0 * h);
                            let got = hess[i * 6 * n + k];
                            assert!(
                                (got - fd).abs() < 1e-6 * fd.abs().max(1.0),
                                "frame {frame} {reference:?} dJ[{}][{}]/dq{i} = {got}, fd {fd}",
                                k / n,
                                k % n
                            );
                        }
                    }
                    // sum_i H[i] qd_i qd = dJ/dt qd, the acceleration drift of the same reference
                    let drift =
                        jacobian_dot_qd(&model, &mut data, &q, &qd, frame, reference, point.as_ref()).to_array();
                    for r in 0..6 {
                        let hqq: f64 = (0..n)
                            .map(|i| (0..n).map(|j| hess[(i * 6 + r) * n + j] * qd[i] * qd[j]).sum::<f64>())
                            .sum();
                        assert!(
                            (hqq - drift[r]).abs() < 1e-9 * drift[r].abs().max(1.0),
                            "frame {frame} {reference:?} drift row {r}: H qd qd = {hqq}, {}",
                            drift[r]
                        );
                    }
                }
            }
        }
    }
}
