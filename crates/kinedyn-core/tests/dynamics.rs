//! Identities between the dynamics algorithms on random chains, trees and forests (the seeded
//! generator of `kinedyn_core::testing`), finite-difference checks of the derivative quantities,
//! and a closed-form double pendulum.

use kinedyn_core::algorithms::{self as alg, Reference, RneaTerms};
use kinedyn_core::spatial::{Inertia, Mat3, Transform, Vec3};
use kinedyn_core::testing::{random_forest, random_model, Rng};
use kinedyn_core::{Data, Error, Joint, JointKind, Model};

/// Gravity off the coordinate axes, so that no identity leans on its direction.
const GRAVITY: [f64; 3] = [0.3, -0.5, -9.81];

fn tilted(mut model: Model) -> Model {
    model.gravity = Vec3::from(GRAVITY);
    model
}

/// Chains, trees (each body's parent any earlier body) and forests (some bodies on the base), all
/// with armature and viscous and Coulomb friction.
fn models() -> Vec<(String, Model)> {
    let mut out = Vec::new();
    for (seed, n) in [(1u64, 1usize), (2, 2), (3, 5), (4, 7), (5, 12)] {
        out.push((format!("chain n={n} seed={seed}"), tilted(random_model(seed, n, false))));
        out.push((
            format!("tree n={n} seed={seed}"),
            tilted(random_model(100 + seed, n, true)),
        ));
        out.push((
            format!("forest n={n} seed={seed}"),
            tilted(random_forest(200 + seed, n)),
        ));
    }
    out
}

fn vector(rng: &mut Rng, n: usize, scale: f64) -> Vec<f64> {
    rng.vector(n, -scale, scale)
}

fn matvec(m: &[f64], x: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..n).map(|i| (0..n).map(|j| m[i * n + j] * x[j]).sum()).collect()
}

fn assert_close(what: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: lengths differ");
    let scale = want.iter().fold(1.0f64, |s, v| s.max(v.abs()));
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= tol * scale,
            "{what}: index {k}: got {g}, want {w} (|diff| {:e}, scale {scale})",
            (g - w).abs()
        );
    }
}

fn friction(model: &Model, qd: &[f64]) -> Vec<f64> {
    (0..model.n)
        .map(|i| {
            model.viscous[i] * qd[i]
                + model.coulomb[i]
                    * if qd[i] > 0.0 {
                        1.0
                    } else if qd[i] < 0.0 {
                        -1.0
                    } else {
                        0.0
                    }
        })
        .collect()
}

/// A random state (q, qd, qdd) for each model.
fn states(model: &Model, seed: u64) -> Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let mut rng = Rng::new(seed);
    (0..3)
        .map(|_| {
            (
                vector(&mut rng, model.n, 3.0),
                vector(&mut rng, model.n, 2.0),
                vector(&mut rng, model.n, 2.0),
            )
        })
        .collect()
}

#[test]
fn rnea_equals_mass_matrix_times_qdd_plus_bias_plus_friction() {
    for (name, model) in models() {
        let mut data = Data::new(&model);
        for (q, qd, qdd) in states(&model, 7) {
            let tau = alg::rnea(&model, &mut data, &q, &qd, &qdd, None).to_vec();
            let m = alg::crba(&model, &mut data, &q).to_vec();
            let bias = alg::bias_torque(&model, &mut data, &q, &qd).to_vec();
            let fr = friction(&model, &qd);
            let want: Vec<f64> = matvec(&m, &qdd)
                .iter()
                .zip(&bias)
                .zip(&fr)
                .map(|((a, b), c)| a + b + c)
                .collect();
            assert_close(&format!("{name}: rnea vs M qdd + bias + friction"), &tau, &want, 1e-12);
        }
    }
}

#[test]
fn mass_matrix_columns_are_rnea_of_unit_accelerations_and_exactly_symmetric() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        for (q, _, _) in states(&model, 8) {
            let m = alg::crba(&model, &mut data, &q).to_vec();
            for i in 0..n {
                for j in 0..n {
                    assert_eq!(
                        m[i * n + j].to_bits(),
                        m[j * n + i].to_bits(),
                        "{name}: M not bitwise symmetric at ({i},{j})"
                    );
                }
            }
            let zero = vec![0.0; n];
            for j in 0..n {
                let mut e = vec![0.0; n];
                e[j] = 1.0;
                let col = alg::rnea_with(
                    &model,
                    &mut data,
                    &q,
                    &zero,
                    &e,
                    None,
                    RneaTerms {
                        gravity: false,
                        drives: true,
                    },
                )
                .to_vec();
                let mcol: Vec<f64> = (0..n).map(|i| m[i * n + j]).collect();
                assert_close(&format!("{name}: M column {j}"), &mcol, &col, 1e-12);
            }
            // M is positive definite: a Cholesky factorisation succeeds
            let mm = nalgebra::DMatrix::from_row_slice(n, n, &m);
            assert!(mm.cholesky().is_some(), "{name}: M not positive definite");
        }
    }
}

#[test]
fn forward_dynamics_inverts_inverse_dynamics_with_external_forces() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        let mut rng = Rng::new(9);
        let origins = (0..n)
            .map(|_| Vec3::from_column_slice(&vector(&mut rng, 3, 0.7)))
            .collect();
        let moved = model.clone().with_link_origins(origins).unwrap();
        for (q, qd, qdd) in states(&model, 10) {
            for (model, with_f) in [(&model, false), (&model, true), (&moved, true)] {
                let f = vector(&mut rng, 6 * n, 5.0);
                let f_ext = if with_f { Some(&f[..]) } else { None };
                let tau = alg::rnea(model, &mut data, &q, &qd, &qdd, f_ext).to_vec();
                let back = alg::aba(model, &mut data, &q, &qd, &tau, f_ext).unwrap().to_vec();
                assert_close(&format!("{name}: aba(rnea(qdd)) (f_ext {with_f})"), &back, &qdd, 1e-10);
            }
        }
    }
}

#[test]
fn external_wrench_enters_as_minus_jacobian_transpose() {
    for (name, plain) in models() {
        let n = plain.n;
        let mut rng = Rng::new(11);
        // wrenches about link-frame origins off the body origins (as DH links)
        let origins: Vec<Vec3> = (0..n)
            .map(|_| Vec3::from_column_slice(&vector(&mut rng, 3, 0.7)))
            .collect();
        let model = plain.with_link_origins(origins.clone()).unwrap();
        let mut data = Data::new(&model);
        let (q, qd, qdd) = states(&model, 12).remove(0);
        let f = vector(&mut rng, 6 * n, 5.0);
        let with = alg::rnea(&model, &mut data, &q, &qd, &qdd, Some(&f)).to_vec();
        let without = alg::rnea(&model, &mut data, &q, &qd, &qdd, None).to_vec();
        // tau(f) - tau(0) = -sum_i J_i^T f_i, J_i the world-aligned Jacobian of body i's origin
        let mut want = vec![0.0; n];
        let mut jac = vec![0.0; 6 * n];
        for i in 0..n {
            // frame i sits on body i; its Jacobian at body i's link origin (a point fixed in the frame)
            let origin = model.frames[i].body_from_frame.inverse().act_point(&origins[i]);
            alg::frame_jacobian(&model, &mut data, &q, i, Reference::World, Some(&origin), &mut jac);
            for k in 0..n {
                want[k] -= (0..6).map(|r| jac[r * n + k] * f[6 * i + r]).sum::<f64>();
            }
        }
        let got: Vec<f64> = with.iter().zip(&without).map(|(a, b)| a - b).collect();
        assert_close(&format!("{name}: f_ext"), &got, &want, 1e-12);
    }
}

#[test]
fn gravity_is_rnea_at_rest_and_the_gradient_of_potential_energy() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        for (q, _, _) in states(&model, 13) {
            let zero = vec![0.0; n];
            let g = alg::gravity_torque(&model, &mut data, &q).to_vec();
            let want = alg::rnea_with(&model, &mut data, &q, &zero, &zero, None, RneaTerms::RIGID).to_vec();
            assert_close(&format!("{name}: g vs rnea(q,0,0)"), &g, &want, 1e-12);
            // g = dP/dq (central differences)
            let h = 1e-6;
            let fd: Vec<f64> = (0..n)
                .map(|i| {
                    let (mut qp, mut qm) = (q.clone(), q.clone());
                    qp[i] += h;
                    qm[i] -= h;
                    (alg::potential_energy(&model, &mut data, &qp) - alg::potential_energy(&model, &mut data, &qm))
                        / (2.0 * h)
                })
                .collect();
            assert_close(&format!("{name}: g vs dP/dq"), &g, &fd, 1e-7);
        }
    }
}

#[test]
fn coriolis_times_qd_is_bias_minus_gravity() {
    for (name, model) in models() {
        let mut data = Data::new(&model);
        for (q, qd, _) in states(&model, 14) {
            let c = alg::coriolis_matrix(&model, &mut data, &q, &qd).to_vec();
            let g = alg::gravity_torque(&model, &mut data, &q).to_vec();
            let b = alg::bias_torque(&model, &mut data, &q, &qd).to_vec();
            let want: Vec<f64> = b.iter().zip(&g).map(|(b, g)| b - g).collect();
            assert_close(&format!("{name}: C qd"), &matvec(&c, &qd), &want, 1e-12);
        }
    }
}

/// dM/dt along qd by central differences of M(q + t qd).
fn mdot_fd(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let h = 1e-6;
    let qp: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a + h * b).collect();
    let qm: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a - h * b).collect();
    let mp = alg::crba(model, data, &qp).to_vec();
    let mm = alg::crba(model, data, &qm).to_vec();
    mp.iter().zip(&mm).map(|(a, b)| (a - b) / (2.0 * h)).collect()
}

#[test]
fn mdot_equals_c_plus_c_transpose_and_mdot_minus_2c_is_skew() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        for (q, qd, _) in states(&model, 15) {
            let c = alg::coriolis_matrix(&model, &mut data, &q, &qd).to_vec();
            let md = mdot_fd(&model, &mut data, &q, &qd);
            let ct: Vec<f64> = (0..n * n).map(|k| c[k] + c[(k % n) * n + k / n]).collect();
            assert_close(&format!("{name}: dM/dt vs C + C^T"), &ct, &md, 1e-7);
            let n2c: Vec<f64> = (0..n * n).map(|k| md[k] - 2.0 * c[k]).collect();
            let skew: Vec<f64> = (0..n * n).map(|k| -n2c[(k % n) * n + k / n]).collect();
            assert_close(&format!("{name}: dM/dt - 2C skew"), &n2c, &skew, 1e-7);
        }
    }
}

#[test]
fn christoffel_symbols_match_finite_differences_of_m_and_build_c() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        for (q, qd, _) in states(&model, 16).into_iter().take(2) {
            let mut c3 = vec![0.0; n * n * n];
            alg::christoffel(&model, &mut data, &q, &mut c3);
            // dM/dq_i by central differences
            let h = 1e-6;
            let dm: Vec<Vec<f64>> = (0..n)
                .map(|i| {
                    let (mut qp, mut qm) = (q.clone(), q.clone());
                    qp[i] += h;
                    qm[i] -= h;
                    let mp = alg::crba(&model, &mut data, &qp).to_vec();
                    let mm = alg::crba(&model, &mut data, &qm).to_vec();
                    mp.iter().zip(&mm).map(|(a, b)| (a - b) / (2.0 * h)).collect()
                })
                .collect();
            let mut want = vec![0.0; n * n * n];
            for i in 0..n {
                for j in 0..n {
                    for k in 0..n {
                        want[i * n * n + j * n + k] = 0.5 * (dm[i][k * n + j] + dm[j][k * n + i] - dm[k][i * n + j]);
                    }
                }
            }
            assert_close(&format!("{name}: christoffel vs FD"), &c3, &want, 1e-7);
            // C[k][j] = sum_i c_ijk qd_i
            let c = alg::coriolis_matrix(&model, &mut data, &q, &qd).to_vec();
            let from3: Vec<f64> = (0..n * n)
                .map(|kj| (0..n).map(|i| c3[i * n * n + (kj % n) * n + kj / n] * qd[i]).sum())
                .collect();
            assert_close(&format!("{name}: C from christoffel"), &c, &from3, 1e-12);
        }
    }
}

#[test]
fn kinetic_energy_is_half_qd_m_qd_and_momentum_matches_com_velocity() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        for (q, qd, _) in states(&model, 17) {
            let k = alg::kinetic_energy(&model, &mut data, &q, &qd);
            let m = alg::crba(&model, &mut data, &q).to_vec();
            let want = 0.5 * qd.iter().zip(matvec(&m, &qd)).map(|(a, b)| a * b).sum::<f64>();
            assert_close(&format!("{name}: K"), &[k], &[want], 1e-12);
            // linear momentum = total mass * dc/dt
            let total: f64 = model.inertia.iter().map(|i| i.mass).sum();
            let h = 1e-6;
            let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
            let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - h * b).collect();
            let cd = (alg::center_of_mass(&model, &mut data, &qp).unwrap()
                - alg::center_of_mass(&model, &mut data, &qm).unwrap())
                / (2.0 * h);
            let p = alg::spatial_momentum(&model, &mut data, &q, &qd);
            assert_close(
                &format!("{name}: momentum"),
                p.lin.as_slice(),
                (cd * total).as_slice(),
                1e-7,
            );
            let _ = n;
        }
    }
}

#[test]
fn spatial_momentum_projected_on_the_first_joint_is_its_generalised_momentum() {
    // Joint 0 of a chain moves every body, so s_0 (world) . h = dK/dqd_0 = (M qd)_0 without
    // the rotor term: this checks the angular part of h (the linear part is checked above).
    for (name, model) in models() {
        if model.joints[0].kind != JointKind::Revolute || model.parent.iter().skip(1).any(|p| p.is_none()) {
            continue;
        }
        let mut data = Data::new(&model);
        for (q, qd, _) in states(&model, 18) {
            let h = alg::spatial_momentum(&model, &mut data, &q, &qd);
            alg::forward_kinematics(&model, &mut data, &q);
            let s0 = data.world_from_body[0].act_motion(&data.s[0]);
            let m = alg::crba(&model, &mut data, &q).to_vec();
            let p0: f64 = (0..model.n).map(|j| m[j] * qd[j]).sum::<f64>() - model.armature[0] * qd[0];
            assert_close(&format!("{name}: s_0 . h"), &[s0.dot(&h)], &[p0], 1e-12);
        }
    }
}

#[test]
fn regressor_times_parameters_is_rigid_body_torque() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        let pi: Vec<f64> = model.inertia.iter().flat_map(|i| i.to_parameters()).collect();
        for (q, qd, qdd) in states(&model, 19) {
            let mut y = vec![0.0; n * 10 * n];
            alg::regressor(&model, &mut data, &q, &qd, &qdd, &mut y);
            let got: Vec<f64> = (0..n)
                .map(|i| (0..10 * n).map(|c| y[i * 10 * n + c] * pi[c]).sum())
                .collect();
            let want = alg::rnea_with(&model, &mut data, &q, &qd, &qdd, None, RneaTerms::RIGID).to_vec();
            assert_close(&format!("{name}: Y pi"), &got, &want, 1e-12);
        }
    }
}

#[test]
fn mass_matrix_inverse_times_mass_matrix_is_identity() {
    for (name, model) in models() {
        let n = model.n;
        let mut data = Data::new(&model);
        for (q, qd, _) in states(&model, 20) {
            let minv = alg::mass_matrix_inverse(&model, &mut data, &q).unwrap().to_vec();
            for i in 0..n {
                for j in 0..n {
                    assert_eq!(
                        minv[i * n + j].to_bits(),
                        minv[j * n + i].to_bits(),
                        "{name}: Minv not symmetric"
                    );
                }
            }
            let m = alg::crba(&model, &mut data, &q).to_vec();
            let mut prod = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    prod[i * n + j] = (0..n).map(|k| minv[i * n + k] * m[k * n + j]).sum();
                }
            }
            let eye: Vec<f64> = (0..n * n).map(|k| if k / n == k % n { 1.0 } else { 0.0 }).collect();
            assert_close(&format!("{name}: Minv M"), &prod, &eye, 1e-10);
            // and the ABA agrees with Minv (tau - bias - friction)
            let tau: Vec<f64> = qd.iter().map(|x| 3.0 * x).collect();
            let qdd = alg::aba(&model, &mut data, &q, &qd, &tau, None).unwrap().to_vec();
            let b = alg::bias_torque(&model, &mut data, &q, &qd).to_vec();
            let fr = friction(&model, &qd);
            let rhs: Vec<f64> = (0..n).map(|i| tau[i] - b[i] - fr[i]).collect();
            assert_close(&format!("{name}: aba vs Minv"), &qdd, &matvec(&minv, &rhs), 1e-10);
        }
    }
}

#[test]
fn singular_mass_matrix_is_an_error_naming_the_joint() {
    // a massless chain without rotor inertia: the last joint moves nothing
    let mut model = random_model(3, 4, false);
    model.inertia = vec![Inertia::zero(); 4];
    model.armature = vec![0.0; 4];
    let mut data = Data::new(&model);
    let z = vec![0.0; 4];
    match alg::aba(&model, &mut data, &z, &z, &z, None) {
        Err(Error::SingularMassMatrix { joint, message, .. }) => {
            assert_eq!(joint, 3);
            assert!(message.contains("joint 3"), "{message}")
        }
        other => panic!("expected a singular mass matrix error, got {other:?}"),
    }
    assert!(matches!(
        alg::mass_matrix_inverse(&model, &mut data, &z),
        Err(Error::SingularMassMatrix { .. })
    ));
    // a point mass on a revolute axis through it: zero inertia about the axis
    let joints = vec![Joint {
        kind: JointKind::Revolute,
        axis: Vec3::z(),
    }];
    let model = Model::new(
        vec![None],
        joints,
        vec![0.0],
        vec![Transform::identity()],
        vec![Inertia::new(2.0, Vec3::zeros(), Mat3::zeros())],
        vec![0.0],
        vec![0.0],
        vec![0.0],
        Vec3::new(0.0, 0.0, -9.81),
        vec![],
    )
    .unwrap();
    let mut data = Data::new(&model);
    assert!(matches!(
        alg::aba(&model, &mut data, &[0.3], &[0.0], &[1.0], None),
        Err(Error::SingularMassMatrix { .. })
    ));
    // with a rotor inertia the same joint is fine: qdd = tau / armature
    let mut m2 = model.clone();
    m2.armature = vec![0.5];
    let mut data = Data::new(&m2);
    let qdd = alg::aba(&m2, &mut data, &[0.3], &[0.0], &[1.0], None).unwrap();
    assert!((qdd[0] - 2.0).abs() < 1e-15);
}

#[test]
fn forests_have_several_roots_and_trees_branch() {
    // else the forests and trees of `models` would test nothing that the chains do not
    let (mut forests, mut trees) = (0, 0);
    for (name, model) in models() {
        let roots = model.parent.iter().filter(|p| p.is_none()).count();
        let branching = (1..model.n).any(|i| model.parent[i] != Some(i - 1));
        forests += (name.starts_with("forest") && roots > 1) as usize;
        trees += (name.starts_with("tree") && roots == 1 && branching) as usize;
    }
    assert!(forests >= 2 && trees >= 2, "{forests} forests, {trees} trees");
}

#[test]
fn branches_do_not_couple() {
    for (name, model) in models().into_iter().filter(|(n, _)| !n.starts_with("chain")) {
        let n = model.n;
        let mut data = Data::new(&model);
        let (q, qd, _) = states(&model, 21).remove(0);
        let m = alg::crba(&model, &mut data, &q).to_vec();
        let c = alg::coriolis_matrix(&model, &mut data, &q, &qd).to_vec();
        for i in 0..n {
            for j in 0..i {
                if !model.support[i].contains(&j) {
                    assert_eq!(m[i * n + j], 0.0, "{name}: M[{i}][{j}]");
                    assert_eq!(c[i * n + j], 0.0, "{name}: C[{i}][{j}]");
                    assert_eq!(c[j * n + i], 0.0, "{name}: C[{j}][{i}]");
                }
            }
        }
    }
}

#[test]
fn double_pendulum_matches_its_closed_form() {
    // planar 2R in the x-y plane, joints about z, gravity -y; link i: length l_i, centre of mass
    // at lc_i on its x axis, inertia izz_i about the centre of mass (Spong et al. 2006, §7.4).
    let (m1, m2, l1, lc1, lc2, i1, i2, g0) = (1.3, 0.7, 0.9, 0.4, 0.35, 0.05, 0.02, 9.81);
    let body = |m: f64, lc: f64, izz: f64| {
        Inertia::new(
            m,
            Vec3::new(m * lc, 0.0, 0.0),
            Mat3::from_diagonal(&Vec3::new(0.01, 0.01 + m * lc * lc, izz + m * lc * lc)),
        )
    };
    let rz = Joint {
        kind: JointKind::Revolute,
        axis: Vec3::z(),
    };
    let model = Model::new(
        vec![None, Some(0)],
        vec![rz, rz],
        vec![0.0, 0.0],
        vec![
            Transform::identity(),
            Transform::new(Mat3::identity(), Vec3::new(l1, 0.0, 0.0)),
        ],
        vec![body(m1, lc1, i1), body(m2, lc2, i2)],
        vec![0.0; 2],
        vec![0.0; 2],
        vec![0.0; 2],
        Vec3::new(0.0, -g0, 0.0),
        vec![],
    )
    .unwrap();
    let mut data = Data::new(&model);
    let (q, qd): ([f64; 2], [f64; 2]) = ([0.4, -1.1], [0.7, 1.9]);
    let (c2, s2) = (q[1].cos(), q[1].sin());
    let d11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * c2) + i1 + i2;
    let d12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + i2;
    let d22 = m2 * lc2 * lc2 + i2;
    assert_close("M", alg::crba(&model, &mut data, &q), &[d11, d12, d12, d22], 1e-14);
    let hh = -m2 * l1 * lc2 * s2;
    let c = [hh * qd[1], hh * (qd[0] + qd[1]), -hh * qd[0], 0.0];
    assert_close("C", alg::coriolis_matrix(&model, &mut data, &q, &qd), &c, 1e-14);
    let g1 = (m1 * lc1 + m2 * l1) * g0 * q[0].cos() + m2 * lc2 * g0 * (q[0] + q[1]).cos();
    let g2 = m2 * lc2 * g0 * (q[0] + q[1]).cos();
    assert_close("g", alg::gravity_torque(&model, &mut data, &q), &[g1, g2], 1e-14);
}

/// Direction-dependent Coulomb friction (Corke's PUMA 560 motors, `Tc = [Tc+, Tc-]`): RNEA adds
/// `coulomb` for qd > 0 and `-coulomb_negative` for qd < 0, nothing at rest, and the ABA inverts it.
#[test]
fn asymmetric_coulomb_friction_gives_each_direction_its_level() {
    for (name, model) in models() {
        let n = model.n;
        let negative: Vec<f64> = (0..n).map(|i| 0.1 + 2.0 * model.coulomb[i] + 0.05 * i as f64).collect();
        let asym = model.clone().with_coulomb_negative(negative.clone()).unwrap();
        let (mut data, mut data_a) = (Data::new(&model), Data::new(&asym));
        for (q, qd, qdd) in states(&model, 21) {
            let base = alg::rnea(&model, &mut data, &q, &qd, &qdd, None).to_vec();
            let tau = alg::rnea(&asym, &mut data_a, &q, &qd, &qdd, None).to_vec();
            for i in 0..n {
                // the symmetric model carries coulomb sign(qd); the asymmetric one differs only for qd < 0
                let want = if qd[i] < 0.0 {
                    base[i] + model.coulomb[i] - negative[i]
                } else {
                    base[i]
                };
                assert!(
                    (tau[i] - want).abs() < 1e-12 * want.abs().max(1.0),
                    "{name}: joint {i} qd {}: tau {} want {want}",
                    qd[i],
                    tau[i]
                );
            }
            let back = alg::aba(&asym, &mut data_a, &q, &qd, &tau, None).unwrap().to_vec();
            assert_close(
                &format!("{name}: aba(rnea(qdd)) with asymmetric Coulomb"),
                &back,
                &qdd,
                1e-10,
            );
            for (i, &level) in negative.iter().enumerate() {
                assert_eq!(asym.coulomb_torque(i, 0.0), 0.0);
                assert_eq!(asym.coulomb_torque(i, 1e-300), asym.coulomb[i]);
                assert_eq!(asym.coulomb_torque(i, -1e-300), -level);
            }
        }
    }
    let model = random_model(1, 2, false);
    let short = model.clone().with_coulomb_negative(vec![0.1]).unwrap_err();
    assert!(
        format!("{short:?}").contains("coulomb_negative has 1 entries for 2 bodies"),
        "{short:?}"
    );
    let negative = model.clone().with_coulomb_negative(vec![0.1, -0.2]).unwrap_err();
    assert!(
        format!("{negative:?}").contains("coulomb_negative of joint 1 is -0.2"),
        "{negative:?}"
    );
    let nan = model.with_coulomb_negative(vec![f64::NAN, 0.1]).unwrap_err();
    assert!(
        format!("{nan:?}").contains("coulomb_negative has a non-finite value at index 0"),
        "{nan:?}"
    );
}
