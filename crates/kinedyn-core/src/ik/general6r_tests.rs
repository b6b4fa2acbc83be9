use super::back::wrap;
use super::*;
use crate::ik::pose_error;
use crate::rng::Rng;
use nalgebra::{Matrix6, Vector6};

/// A random 6R chain: random unit axes through random points, a random home pose.
fn random_chain(seed: u64) -> ([Axis; 6], Transform) {
    let mut rng = Rng::new(seed);
    let axes = std::array::from_fn(|_| Axis {
        w: rng.unit(),
        r: rng.vec3(-0.5, 0.5),
    });
    (axes, Transform::new(rng.rotation(), rng.vec3(-0.6, 0.6)))
}

fn random_angles(rng: &mut Rng) -> [f64; 6] {
    std::array::from_fn(|_| rng.uniform(-PI, PI))
}

fn residual(solver: &General6R, th: &[f64; 6], target: &Transform) -> f64 {
    let e = pose_error(&solver.forward(th), target);
    e.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// An independent dense search: Levenberg-Marquardt with a finite-difference Jacobian of the
/// forward kinematics from many random starts, converged solutions deduplicated.
fn dense_search(solver: &General6R, target: &Transform, starts: usize, seed: u64) -> Vec<[f64; 6]> {
    let mut rng = Rng::new(seed);
    let mut found: Vec<[f64; 6]> = Vec::new();
    for _ in 0..starts {
        let mut q = random_angles(&mut rng);
        let mut lambda = 1e-3;
        let mut e = pose_error(&solver.forward(&q), target);
        let mut cost: f64 = e.iter().map(|x| x * x).sum();
        for _ in 0..200 {
            if cost < 1e-26 {
                break;
            }
            let mut jac = Matrix6::zeros();
            for j in 0..6 {
                let mut qh = q;
                qh[j] += 1e-7;
                let eh = pose_error(&solver.forward(&qh), target);
                for r in 0..6 {
                    jac[(r, j)] = (e[r] - eh[r]) / 1e-7; // de/dq = -d(fk)/dq
                }
            }
            let ev = Vector6::from_column_slice(&e);
            let a = jac.transpose() * jac + Matrix6::identity() * lambda;
            let Some(step) = a.lu().solve(&(jac.transpose() * ev)) else {
                break;
            };
            let mut qn = q;
            for j in 0..6 {
                qn[j] += step[j];
            }
            let en = pose_error(&solver.forward(&qn), target);
            let cn: f64 = en.iter().map(|x| x * x).sum();
            if cn < cost {
                (q, e, cost, lambda) = (qn, en, cn, (lambda * 0.3).max(1e-12));
            } else {
                lambda *= 10.0;
                if lambda > 1e6 {
                    break;
                }
            }
        }
        if cost < 1e-22 {
            let q = wrap(q);
            if !found.iter().any(|s| same_angles(s, &q, 1e-5)) {
                found.push(q);
            }
        }
    }
    found
}

#[test]
fn equations_interpolate_exactly() {
    // each side of the 14 equations is of degree one in (cos, sin) of each joint: its 3^3-point
    // Fourier interpolant equals it everywhere
    for seed in 0..4 {
        let (axes, home) = random_chain(seed);
        let me = General6R::formulation(&axes, &home, 1.0, 5, false).expect("generic chain");
        let mut rng = Rng::new(seed + 100);
        let g = Transform::new(rng.rotation(), rng.vec3(-1.0, 1.0));
        let [j0, j1, j2] = me.uj;
        let mut samples = [[[[0.0; 3]; 3]; 3]; 14];
        let mut th = [0.0; 6];
        for m0 in 0..3 {
            for m1 in 0..3 {
                for m2 in 0..3 {
                    th[j0] = 2.0 * PI * m0 as f64 / 3.0;
                    th[j1] = 2.0 * PI * m1 as f64 / 3.0;
                    th[j2] = 2.0 * PI * m2 as f64 / 3.0;
                    let e = me.side(&me.u, &th, &g);
                    for q in 0..14 {
                        samples[q][m0][m1][m2] = e[q];
                    }
                }
            }
        }
        for _ in 0..20 {
            let x = random_angles(&mut rng);
            let direct = me.side(&me.u, &x, &g);
            let basis = |t: f64| [1.0, t.cos(), t.sin()];
            let (b0, b1, b2) = (basis(x[j0]), basis(x[j1]), basis(x[j2]));
            for q in 0..14 {
                // coefficients by the transform along each axis
                let s = &samples[q];
                let mut value = 0.0;
                for (a, ba) in b0.iter().enumerate() {
                    for (b, bb) in b1.iter().enumerate() {
                        for (c, bc) in b2.iter().enumerate() {
                            let mut coef = 0.0;
                            // separable: c_abc = sum_m w_a(m0) w_b(m1) w_c(m2) s[m0][m1][m2]
                            let w = |k: usize, m: usize| {
                                let ang = 2.0 * PI * m as f64 / 3.0;
                                match k {
                                    0 => 1.0 / 3.0,
                                    1 => 2.0 / 3.0 * ang.cos(),
                                    _ => 2.0 / 3.0 * ang.sin(),
                                }
                            };
                            for m0 in 0..3 {
                                for m1 in 0..3 {
                                    for m2 in 0..3 {
                                        coef += w(a, m0) * w(b, m1) * w(c, m2) * s[m0][m1][m2];
                                    }
                                }
                            }
                            value += coef * ba * bb * bc;
                        }
                    }
                }
                assert!(
                    (value - direct[q]).abs() < 1e-10 * (1.0 + direct[q].abs()),
                    "equation {q}: interpolant {value} vs {}",
                    direct[q]
                );
            }
        }
    }
}

#[test]
fn fourier_recovers_a_first_degree_trigonometric_polynomial() {
    let (c0, c1, c2) = (0.3, -1.7, 2.2);
    let f = |t: f64| c0 + c1 * t.cos() + c2 * t.sin();
    let c = fourier(f(0.0), f(2.0 * PI / 3.0), f(4.0 * PI / 3.0));
    assert!(
        (c[0] - c0).abs() < 1e-14 && (c[1] - c1).abs() < 1e-14 && (c[2] - c2).abs() < 1e-14,
        "{c:?}"
    );
}

#[test]
fn random_chains_find_the_known_solution_and_only_solutions() {
    // 12 chains x 5 targets (unoptimised in `cargo test`: a minute for 30 chains in .ci/run)
    let mut hits = 0;
    for seed in 0..12 {
        let (axes, home) = random_chain(1000 + seed);
        let solver = General6R::new(axes, home).expect("a generic chain has a formulation");
        let mut rng = Rng::new(seed);
        let mut out = Vec::new();
        for _ in 0..5 {
            let q = random_angles(&mut rng);
            let target = solver.forward(&q);
            let stats = solver.solve(&target, &mut out);
            assert!(
                out.len() <= MAX_SOLUTIONS && out.len() % 2 == 0,
                "seed {seed}: {} solutions",
                out.len()
            );
            assert!(
                out.iter().any(|s| same_angles(s, &q, 1e-7)),
                "seed {seed}: the generating q {q:?} is missing from {out:?}"
            );
            for s in &out {
                assert!(residual(&solver, s, &target) < 1e-9, "seed {seed}: residual");
            }
            assert!(stats.worst_residual < 1e-9);
            hits += out.len();
        }
    }
    assert!(hits > 60);
}

// 2 chains x 2 targets x 600 starts: the dense search is the slowest check of the crate, one test
// per chain so that the test threads share it
#[test]
fn solution_count_matches_a_dense_numeric_search_on_a_first_chain() {
    solution_count_matches_a_dense_numeric_search(0);
}

#[test]
fn solution_count_matches_a_dense_numeric_search_on_a_second_chain() {
    solution_count_matches_a_dense_numeric_search(1);
}

fn solution_count_matches_a_dense_numeric_search(seed: u64) {
    let (axes, home) = random_chain(2000 + seed);
    let solver = General6R::new(axes, home).expect("generic chain");
    let mut rng = Rng::new(seed + 7);
    for _ in 0..2 {
        let target = solver.forward(&random_angles(&mut rng));
        let mut out = Vec::new();
        solver.solve(&target, &mut out);
        let dense = dense_search(&solver, &target, 600, seed);
        for d in &dense {
            assert!(
                out.iter().any(|s| same_angles(s, d, 1e-5)),
                "seed {seed}: numeric solution {d:?} missed ({} vs {})",
                out.len(),
                dense.len()
            );
        }
        assert_eq!(out.len(), dense.len(), "seed {seed}: eigenvalue count vs dense search");
    }
}

#[test]
fn unreachable_targets_have_no_solution() {
    let (axes, home) = random_chain(3000);
    let solver = General6R::new(axes, home).unwrap();
    let far = Transform::new(Mat3Alias::identity(), Vec3::new(50.0, 0.0, 0.0));
    let mut out = Vec::new();
    solver.solve(&far, &mut out);
    assert!(out.is_empty());
}

type Mat3Alias = crate::spatial::Mat3;

#[test]
#[ignore = "a timing figure, not a check: cargo test --release -p kinedyn-core time_per_solve -- --ignored --nocapture"]
fn time_per_solve() {
    // a figure, not a gate (speed belongs to the benches; unoptimised in CI it only cost time):
    // the whole solve, then its stages alone (the reduced equations of the targets; the eigenvalues
    // of random 24 x 24 matrices, the companion's order)
    let (axes, home) = random_chain(4000);
    let solver = General6R::new(axes, home).unwrap();
    let mut rng = Rng::new(4);
    let targets: Vec<Transform> = (0..200).map(|_| solver.forward(&random_angles(&mut rng))).collect();
    let mut out = Vec::with_capacity(16);
    let mut total = 0;
    let start = std::time::Instant::now();
    for t in &targets {
        solver.solve(t, &mut out);
        total += out.len();
    }
    let us = start.elapsed().as_secs_f64() * 1e6 / targets.len() as f64;
    let start = std::time::Instant::now();
    let mut sink = 0.0;
    for t in &targets {
        sink += solver.reduced_equations(&(*t * solver.home.inverse()))[0][1][1][1];
    }
    let equations_us = start.elapsed().as_secs_f64() * 1e6 / targets.len() as f64;
    let matrices: Vec<Square> = (0..200)
        .map(|_| {
            let mut m = Square::zeros(24);
            for row in m.a.iter_mut().take(24) {
                for x in row.iter_mut().take(24) {
                    *x = rng.uniform(-1.0, 1.0);
                }
            }
            m
        })
        .collect();
    let mut roots = Vec::with_capacity(32);
    let start = std::time::Instant::now();
    for m in &matrices {
        let mut m = m.clone();
        m.eigenvalues(&mut roots).unwrap();
        sink += roots[0].0;
    }
    let eig_us = start.elapsed().as_secs_f64() * 1e6 / matrices.len() as f64;
    println!(
        "general 6R: {us:.1} us per target ({equations_us:.1} us reduced equations, {eig_us:.1} us eigenvalues \
         of a 24 x 24), {:.2} solutions on average ({sink:.1e})",
        total as f64 / 200.0
    );
    assert!(total >= targets.len());
}

fn chain_of(rows: &[([f64; 3], [f64; 3]); 6], home_trans: [f64; 3]) -> ([Axis; 6], Transform) {
    let axes = std::array::from_fn(|i| Axis {
        w: Vec3::new(rows[i].0[0], rows[i].0[1], rows[i].0[2]).normalize(),
        r: Vec3::new(rows[i].1[0], rows[i].1[1], rows[i].1[2]),
    });
    let [x, y, z] = home_trans;
    (axes, Transform::new(Mat3Alias::identity(), Vec3::new(x, y, z)))
}

/// Arms whose consecutive axes all meet or are parallel, the wrist not spherical: the 12 x 12
/// matrix polynomial is singular at every x_t for each choice of cut and joints, and the extended
/// formulation is used. Axes at q = 0 (m) as ssik 8.2's prebuilt kinova/jaco2 and fanuc/crx10ia
/// build them (world-aligned, w and a point r per joint).
#[test]
fn consecutive_axes_meeting_or_parallel_get_the_extended_formulation() {
    let s = 0.866_025_605_676_658;
    let jaco = [
        ([0.0, 0.0, -1.0], [0.0, 0.0, 0.0]),
        ([0.0, -1.0, 0.0], [0.0, 0.0, 0.2755]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, -0.1345]),
        ([0.0, 0.0, -1.0], [0.0, -0.0098, 0.0]),
        (
            [0.0, -s, -0.499_999_650_312_255_35],
            [0.0, -0.052_489_241_271_964_98, 0.090_914_117_511_228_83],
        ),
        ([0.0, 0.0, -1.0], [0.0, 0.064_261_895_297_037_98, 0.0]),
    ];
    let crx = [
        ([0.0, 0.0, 1.0], [0.0, 0.0, 0.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 0.245]),
        ([0.0, -1.0, 0.0], [0.0, 0.0, 0.785]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 0.785]),
        ([0.0, -1.0, 0.0], [0.54, 0.0, 0.785]),
        ([-1.0, 0.0, 0.0], [0.0, -0.15, 0.785]),
    ];
    for (name, rows, home) in [("jaco", jaco, [0.0, 0.064, 0.361]), ("crx", crx, [0.7, -0.15, 0.785])] {
        let (axes, home) = chain_of(&rows, home);
        let solver = General6R::new(axes, home).expect("a formulation");
        assert!(solver.extended, "{name}: {}", solver.formulation_name());
        let mut rng = Rng::new(5);
        let mut out = Vec::new();
        for _ in 0..3 {
            let q = random_angles(&mut rng);
            let target = solver.forward(&q);
            solver.solve(&target, &mut out);
            assert!(out.iter().any(|s| same_angles(s, &q, 1e-7)), "{name}: {q:?} missing");
            assert!(out.len() >= 2 && out.len() <= MAX_SOLUTIONS, "{name}: {}", out.len());
            for s in &out {
                assert!(residual(&solver, s, &target) < 1e-9, "{name}: residual");
            }
        }
    }
}
