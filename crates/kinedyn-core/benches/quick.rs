//! A noise-robust A/B timer for optimising the core (never a CI gate): the minimum over rounds of
//! the mean time per call, which a busy shared machine disturbs far less than criterion's median.
//!   cargo bench -p kinedyn-core --bench quick [-- FILTER]
//! Prints `model/algorithm  ns`, one line each. Copy the binary from `target/release/deps` to
//! compare two builds back to back.
//!
//! `KINEDYN_BENCH_TREES=a.tree:b.tree` adds floating-base robots read from `benches/cpp/dump_tree.py`
//! files (issue 14; Pinocchio's C++ harness builds its models from the same files): rnea, crba and
//! aba on the file's state, with `<robot>/check_<algorithm>` lines of their results for
//! `benches/cpp/compare_core.sh` to compare across the two sides; also M^-1 and the derivatives, and
//! with the filter `flops` the operation counts (`benches/cpp/compare_codegen.sh`, issue 30).
//! `KINEDYN_BENCH_TREES_ONLY=1` leaves out the built-in DH models.

mod models;

use kinedyn_core::algorithms as alg;
use kinedyn_core::Data;
use std::hint::black_box;
use std::time::Instant;

/// Calls of `f` that take about 1 ms.
fn calls_per_ms(f: &mut dyn FnMut()) -> u64 {
    let start = Instant::now();
    let mut calls = 0u64;
    while start.elapsed().as_micros() < 300 {
        f();
        calls += 1;
    }
    calls
}

/// Mean ns per call of `f` over `calls` calls.
fn mean_ns(f: &mut dyn FnMut(), calls: u64) -> f64 {
    let t = Instant::now();
    for _ in 0..calls {
        f();
    }
    t.elapsed().as_nanos() as f64 / calls as f64
}

/// Minimum over 100 rounds of the mean ns per call of `f` over ~1 ms batches.
fn min_ns(mut f: impl FnMut()) -> f64 {
    let calls = calls_per_ms(&mut f);
    (0..100).map(|_| mean_ns(&mut f, calls)).fold(f64::INFINITY, f64::min)
}

/// A/B: the minimum ns per call of `a` and of `b`, their ~1 ms rounds interleaved so that both
/// see the same machine (whose speed drifts by tens of percent here between runs).
#[allow(dead_code)]
fn min_ns_ab(mut a: impl FnMut(), mut b: impl FnMut()) -> (f64, f64) {
    let calls = calls_per_ms(&mut a);
    let (mut ta, mut tb) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..400 {
        ta = ta.min(mean_ns(&mut a, calls));
        tb = tb.min(mean_ns(&mut b, calls));
    }
    (ta, tb)
}

fn main() {
    let filter = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with("--"))
        .unwrap_or_default();
    // KINEDYN_BENCH_TREES_ONLY=1: the tree files alone (compare_codegen.sh), not the DH models
    let built_in = std::env::var("KINEDYN_BENCH_TREES_ONLY").map_or(true, |v| v != "1");
    for (name, model) in models::all().into_iter().filter(|_| built_in) {
        let n = model.n;
        let mut data = Data::new(&model);
        let (q, qd, qdd) = models::state(n);
        let tau = alg::rnea(&model, &mut data, &q, &qd, &qdd, None).to_vec();
        let d = &mut data;
        let mut run = |alg: &str, f: &mut dyn FnMut(&mut Data)| {
            let key = format!("{name}/{alg}");
            if key.contains(&filter) {
                println!("{key:28} {:8.1}", min_ns(|| f(&mut *d)));
            }
        };
        run("rnea", &mut |d| {
            _ = black_box(alg::rnea(&model, d, black_box(&q), black_box(&qd), black_box(&qdd), None)[0])
        });
        run("crba", &mut |d| _ = black_box(alg::crba(&model, d, black_box(&q))[0]));
        run("aba", &mut |d| {
            _ = black_box(alg::aba(&model, d, black_box(&q), black_box(&qd), black_box(&tau), None).unwrap()[0])
        });
        run("coriolis_matrix", &mut |d| {
            _ = black_box(alg::coriolis_matrix(&model, d, black_box(&q), black_box(&qd))[0])
        });
        run("gravity_torque", &mut |d| {
            _ = black_box(alg::gravity_torque(&model, d, black_box(&q))[0])
        });
        run("mass_matrix_inverse", &mut |d| {
            _ = black_box(alg::mass_matrix_inverse(&model, d, black_box(&q)).unwrap()[0])
        });
        let (mut d1, mut d2, mut d3) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
        run("rnea_derivatives", &mut |d| {
            alg::rnea_derivatives(
                &model,
                d,
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                None,
                &mut d1,
                &mut d2,
                None,
            )
        });
        let fx: Vec<f64> = (0..6 * n).map(|k| 0.1 * k as f64 - 1.0).collect();
        run("rnea_derivatives_f_ext", &mut |d| {
            alg::rnea_derivatives(
                &model,
                d,
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                Some(&fx),
                &mut d1,
                &mut d2,
                None,
            )
        });
        run("aba_derivatives", &mut |d| {
            alg::aba_derivatives(
                &model,
                d,
                black_box(&q),
                black_box(&qd),
                black_box(&tau),
                None,
                &mut d1,
                &mut d2,
                &mut d3,
            )
            .unwrap()
        });
        run("forward_kinematics", &mut |d| {
            alg::forward_kinematics(&model, d, black_box(&q))
        });
        bench_batches(name, &model, &filter);
        bench_ik(name, &model, &filter);
        if filter == "flops" {
            print_flops(name, &model);
        }
    }
    let trees = std::env::var("KINEDYN_BENCH_TREES").unwrap_or_default();
    for path in trees.split(':').filter(|p| !p.is_empty()) {
        bench_tree(&models::read_tree(path), &filter);
    }
}

/// Closed-form IK of every branch per target (issue 28), over 64 targets from random joint
/// vectors: the candidates alone (`<model>/ik_candidates`, `ChainIk::solve`), and the whole call the
/// bindings make (`<model>/ik_all`: candidates mapped to q, verified by forward kinematics,
/// deduplicated, stated and sorted). Chains without a closed form print nothing.
fn bench_ik(name: &str, model: &kinedyn_core::Model, filter: &str) {
    use kinedyn_core::algorithms::jacobian::frame_pose_at;
    use kinedyn_core::ik;
    let mut model = model.clone();
    model.frames.push(kinedyn_core::model::Frame {
        body: Some(model.n - 1),
        body_from_frame: kinedyn_core::spatial::Transform::identity(),
    });
    let frame = model.frames.len() - 1;
    let mut data = Data::new(&model);
    let Some(solver) = ik::detect_analytic(&model, &mut data, frame) else {
        return;
    };
    let mut rng = kinedyn_core::testing::Rng::new(28);
    let targets: Vec<_> = (0..64)
        .map(|_| {
            let q = kinedyn_core::testing::random_configuration(&model, &mut rng);
            frame_pose_at(&model, &mut data, &q, frame)
        })
        .collect();
    let (n, reference) = (model.n, vec![0.0; model.n]);
    let (lower, upper) = (vec![-1e3; n], vec![1e3; n]);
    let per_target = |key: &str, f: &mut dyn FnMut(&kinedyn_core::spatial::Transform)| {
        let key = format!("{name}/{key}");
        if key.contains(filter) {
            println!(
                "{key:28} {:8.1}",
                min_ns(|| targets.iter().for_each(&mut *f)) / targets.len() as f64
            );
        }
    };
    let mut rows = Vec::with_capacity(16);
    per_target("ik_candidates", &mut |t| {
        _ = black_box(solver.solve(black_box(t), false, &reference, &mut rows));
    });
    let d = &mut data;
    per_target("ik_all", &mut |t| {
        let out = ik::analytic_solutions(
            &model,
            d,
            &solver,
            frame,
            black_box(t),
            false,
            &reference,
            &lower,
            &upper,
            false,
            1e-9,
        );
        _ = black_box(out.found);
    });
}

/// Per state, batches of 1024 random states on one thread (issue 17): rnea, crba and aba with
/// each lane kind this CPU runs (`<model>/<alg>_batch_<kind>`; `off` is one state at a time).
fn bench_batches(name: &str, model: &kinedyn_core::Model, filter: &str) {
    use kinedyn_core::batch::{self, kernels, Input, Kernel, Scratch, Simd};
    const STATES: usize = 1024;
    let mut rng = kinedyn_core::testing::Rng::new(17);
    let q: Vec<f64> = (0..STATES)
        .flat_map(|_| kinedyn_core::testing::random_configuration(model, &mut rng))
        .collect();
    let (qd, qdd) = (
        rng.vector(STATES * model.n, -2.0, 2.0),
        rng.vector(STATES * model.n, -2.0, 2.0),
    );
    let mut scratch = Scratch::new(model);
    let mut tau = vec![0.0; STATES * model.n];
    let x3 = [
        Input {
            values: &q,
            width: model.nq,
        },
        Input {
            values: &qd,
            width: model.n,
        },
        Input {
            values: &qdd,
            width: model.n,
        },
    ];
    batch::run(model, &mut scratch, &kernels::InverseDynamics, &x3, &mut tau, Simd::Off).unwrap();
    let aba_in = [
        x3[0],
        x3[1],
        Input {
            values: &tau,
            width: model.n,
        },
    ];
    for simd in [Simd::Off, Simd::Portable, Simd::Avx2, Simd::Avx512]
        .into_iter()
        .filter(|s| s.is_supported())
    {
        let mut time = |alg: &str, kernel: &dyn Fn(&mut Scratch)| {
            let key = format!("{name}/{alg}_batch_{}", simd.name());
            if key.contains(filter) {
                println!("{key:28} {:8.1}", min_ns(|| kernel(&mut scratch)) / STATES as f64);
            }
        };
        fn go<K: Kernel>(model: &kinedyn_core::Model, s: &mut Scratch, k: &K, x: &[Input], simd: Simd) {
            let mut out = vec![0.0; STATES * k.output_len(model)];
            batch::run(model, s, k, x, black_box(&mut out), simd).unwrap();
        }
        time("rnea", &|s| go(model, s, &kernels::InverseDynamics, &x3, simd));
        time("crba", &|s| go(model, s, &kernels::MassMatrix, &x3[..1], simd));
        time("aba", &|s| go(model, s, &kernels::ForwardDynamics, &aba_in, simd));
    }
}

fn print_check(key: &str, x: &[f64]) {
    let values: Vec<String> = x.iter().map(|v| format!("{v:e}")).collect();
    println!("{key} {}", values.join(" "));
}

/// rnea, crba and aba of a floating-base robot from a tree file, after their results for the check.
fn bench_tree(tree: &models::TreeFile, filter: &str) {
    let (model, name) = (&tree.model, &tree.name);
    let (q, v, a) = (&tree.q, &tree.v, &tree.a);
    let n = model.n;
    let mut data = Data::new(model);
    let tau = alg::rnea(model, &mut data, q, v, a, None).to_vec();
    print_check(&format!("{name}/check_rnea"), &tau);
    let m = alg::crba(model, &mut data, q).to_vec();
    let upper: Vec<f64> = (0..n)
        .flat_map(|i| (i..n).map(move |j| (i, j)))
        .map(|(i, j)| m[i * n + j])
        .collect();
    print_check(&format!("{name}/check_crba"), &upper);
    print_check(
        &format!("{name}/check_aba"),
        alg::aba(model, &mut data, q, v, &tau, None).unwrap(),
    );
    // issue 30's comparison with Pinocchio's generated code (compare_codegen.sh): M^-1 (upper
    // triangle) and the derivatives (dtau/dq then dtau/dv; dqdd/dq then dqdd/dv, row-major)
    let minv = alg::mass_matrix_inverse(model, &mut data, q).unwrap().to_vec();
    let minv_upper: Vec<f64> = (0..n)
        .flat_map(|i| (i..n).map(move |j| (i, j)))
        .map(|(i, j)| minv[i * n + j])
        .collect();
    print_check(&format!("{name}/check_mass_matrix_inverse"), &minv_upper);
    let (mut d1, mut d2, mut d3) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
    alg::rnea_derivatives(model, &mut data, q, v, a, None, &mut d1, &mut d2, Some(&mut d3));
    print_check(&format!("{name}/check_rnea_derivatives"), &[&d1[..], &d2[..]].concat());
    alg::aba_derivatives(model, &mut data, q, v, &tau, None, &mut d1, &mut d2, &mut d3).unwrap();
    print_check(&format!("{name}/check_aba_derivatives"), &[&d1[..], &d2[..]].concat());
    let d = &mut data;
    let mut run = |alg: &str, f: &mut dyn FnMut(&mut Data)| {
        let key = format!("{name}/{alg}");
        if key.contains(filter) {
            println!("{key:28} {:8.1}", min_ns(|| f(&mut *d)));
        }
    };
    run("rnea", &mut |d| {
        _ = black_box(alg::rnea(model, d, black_box(q), black_box(v), black_box(a), None)[0])
    });
    run("crba", &mut |d| _ = black_box(alg::crba(model, d, black_box(q))[0]));
    run("aba", &mut |d| {
        _ = black_box(alg::aba(model, d, black_box(q), black_box(v), black_box(&tau), None).unwrap()[0])
    });
    run("mass_matrix_inverse", &mut |d| {
        _ = black_box(alg::mass_matrix_inverse(model, d, black_box(q)).unwrap()[0])
    });
    // dtau/dqdd = M as well: Pinocchio's computeRNEADerivatives (and its generated code) give all three
    run("rnea_derivatives", &mut |d| {
        alg::rnea_derivatives(
            model,
            d,
            black_box(q),
            black_box(v),
            black_box(a),
            None,
            &mut d1,
            &mut d2,
            Some(&mut d3),
        )
    });
    run("aba_derivatives", &mut |d| {
        alg::aba_derivatives(
            model,
            d,
            black_box(q),
            black_box(v),
            black_box(&tau),
            None,
            &mut d1,
            &mut d2,
            &mut d3,
        )
        .unwrap()
    });
    if filter == "flops" {
        print_flops(name, model);
    }
    free_flyer_crba_share(model, d, tree, filter);
}

/// Profile (kinedyn-core only, no Pinocchio peer): the part of `crba` (the `crba_blocks` pass of
/// src/algorithms/crba.rs) spent on a root free-flyer's member bodies 2..=5, whose parent is not a
/// root: each forms its transform (the identity, as a member's placement and joint are), carries its
/// composite inertia to the parent, and transforms the force columns of its whole subtree (about nv
/// of them) by it. Pinocchio's free-flyer is one joint: it does this once for 6 columns together.
/// The same calls as crba_blocks, on the model's own data, without the rest of the algorithm.
fn free_flyer_crba_share(model: &kinedyn_core::Model, data: &mut Data, tree: &models::TreeFile, filter: &str) {
    use kinedyn_core::algorithms::kinematics::{inertia_to_parent, joint_trig, parent_from_body_trig};
    use kinedyn_core::lie::Block;
    use kinedyn_core::model::Coordinates;
    use kinedyn_core::spatial::{Force, Inertia, Vec3};
    if !matches!(
        model.coordinates.first(),
        Some(Coordinates::Head {
            block: Block::FreeFlyer,
            ..
        })
    ) || model.parent[0].is_some()
    {
        return;
    }
    let key = format!("{}/crba_free_flyer_members", tree.name);
    if !key.contains(filter) {
        return;
    }
    let (n, q) = (model.n, &tree.q);
    joint_trig(model, data, q);
    let (sin, cos) = (data.sin.clone(), data.cos.clone());
    let ic: Vec<Inertia> = model.inertia.clone();
    let mut to_parent = vec![Inertia::zero(); n];
    let mut f: Vec<Force> = (0..n)
        .map(|k| Force::new(Vec3::new(k as f64, 1.0, -2.0), Vec3::new(0.5, k as f64, 3.0)))
        .collect();
    let ns = min_ns(|| {
        for i in (2..=5).rev() {
            let x = parent_from_body_trig(model, black_box(q), &sin, &cos, i);
            to_parent[i - 1] = inertia_to_parent(model, i, &x, sin[i], cos[i], &ic[i]);
            for fk in &mut f[i..n] {
                *fk = x.act_force(fk);
            }
        }
        black_box((&to_parent, &f));
    });
    println!("{key:28} {ns:8.1}");
    // the free-flyer's six rows of M: members 1..=5 project their subtree's columns (s_i^T F_k, both
    // triangles written, the column strided), the root's row comes from body 1 (w^T F_k)
    let m = &mut data.m;
    let w = kinedyn_core::spatial::Motion::new(Vec3::new(0.3, -0.2, 0.1), Vec3::new(0.5, 0.7, -0.4));
    let rows = min_ns(|| {
        for i in 1..=5 {
            let joint = &model.joints[i];
            for k in i..n {
                let h = joint.project(black_box(&f[k]));
                m[i * n + k] = h;
                m[k * n + i] = h;
            }
        }
        for k in 1..n {
            let h = w.dot(black_box(&f[k]));
            m[k] = h;
            m[k * n] = h;
        }
        black_box(&m);
    });
    println!("{:28} {rows:8.1}", format!("{}/crba_free_flyer_rows", tree.name));
}

/// The floating-point operations of one call (issue 17's "fraction of the arithmetic floor"): the
/// algorithms run on `Counted`, an f64 that counts its + - * / (a negation is a sign flip, not
/// counted; sin/cos pairs counted apart, as one call each).
mod flops {
    use kinedyn_core::Real;
    use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
    use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

    pub static OPS: AtomicU64 = AtomicU64::new(0);
    pub static SIN_COS: AtomicU64 = AtomicU64::new(0);

    #[derive(Clone, Copy, Debug, Default, PartialEq)]
    pub struct Counted(pub f64);

    macro_rules! counted {
        ($t:ident, $m:ident, $at:ident, $am:ident, $op:tt) => {
            impl $t for Counted {
                type Output = Counted;
                fn $m(self, o: Counted) -> Counted {
                    OPS.fetch_add(1, Relaxed);
                    Counted(self.0 $op o.0)
                }
            }
            impl $at for Counted {
                fn $am(&mut self, o: Counted) {
                    *self = *self $op o;
                }
            }
        };
    }
    counted!(Add, add, AddAssign, add_assign, +);
    counted!(Sub, sub, SubAssign, sub_assign, -);
    counted!(Mul, mul, MulAssign, mul_assign, *);
    impl Div for Counted {
        type Output = Counted;
        fn div(self, o: Counted) -> Counted {
            OPS.fetch_add(1, Relaxed);
            Counted(self.0 / o.0)
        }
    }
    impl Neg for Counted {
        type Output = Counted;
        fn neg(self) -> Counted {
            Counted(-self.0)
        }
    }
    impl num_traits::Zero for Counted {
        fn zero() -> Self {
            Counted(0.0)
        }
        fn is_zero(&self) -> bool {
            self.0 == 0.0
        }
    }
    impl num_traits::One for Counted {
        fn one() -> Self {
            Counted(1.0)
        }
    }
    impl Real for Counted {
        const LANES: usize = 1;
        fn splat(x: f64) -> Self {
            Counted(x)
        }
        fn sin_cos(self) -> (Self, Self) {
            SIN_COS.fetch_add(1, Relaxed);
            let (s, c) = self.0.sin_cos();
            (Counted(s), Counted(c))
        }
        fn sin_cos_in_place(x: &mut [Self], cos: &mut [Self]) {
            for (s, c) in x.iter_mut().zip(cos.iter_mut()) {
                (*s, *c) = s.sin_cos();
            }
        }
        fn signed_level(self, a: f64, b: f64) -> Self {
            Counted(self.0.signed_level(a, b))
        }
        fn lane(self, _k: usize) -> f64 {
            self.0
        }
        fn set_lane(&mut self, _k: usize, x: f64) {
            self.0 = x;
        }
    }

    /// `(operations, sin/cos pairs)` of `f`.
    pub fn count(f: impl FnOnce()) -> (u64, u64) {
        OPS.store(0, Relaxed);
        SIN_COS.store(0, Relaxed);
        f();
        (OPS.load(Relaxed), SIN_COS.load(Relaxed))
    }
}

/// `<model>/<alg>_flops`: operations per call of rnea, crba and aba, and sin/cos pairs.
fn print_flops(name: &str, model: &kinedyn_core::Model) {
    use flops::{count, Counted};
    let mut rng = kinedyn_core::testing::Rng::new(3);
    let lift = |v: Vec<f64>| v.into_iter().map(Counted).collect::<Vec<_>>();
    let q = lift(kinedyn_core::testing::random_configuration(model, &mut rng));
    let (qd, qdd) = (
        lift(rng.vector(model.n, -1.0, 1.0)),
        lift(rng.vector(model.n, -1.0, 1.0)),
    );
    let mut data = Data::<Counted>::new(model);
    let d = &mut data;
    let n = model.n;
    let m = || vec![Counted(0.0); n * n];
    let (mut d1, mut d2, mut d3) = (m(), m(), m());
    for (alg, (ops, trig)) in [
        ("rnea", count(|| _ = alg::rnea(model, d, &q, &qd, &qdd, None))),
        ("crba", count(|| _ = alg::crba(model, d, &q))),
        ("aba", count(|| _ = alg::aba(model, d, &q, &qd, &qdd, None).unwrap())),
        (
            "mass_matrix_inverse",
            count(|| _ = alg::mass_matrix_inverse(model, d, &q).unwrap()),
        ),
        (
            "rnea_derivatives",
            count(|| alg::rnea_derivatives(model, d, &q, &qd, &qdd, None, &mut d1, &mut d2, Some(&mut d3))),
        ),
        (
            "aba_derivatives",
            count(|| alg::aba_derivatives(model, d, &q, &qd, &qdd, None, &mut d1, &mut d2, &mut d3).unwrap()),
        ),
    ] {
        println!("{name}/{alg}_flops {ops} {trig}");
    }
    // the same algorithm recorded for this one robot (kinedyn_core::trace: constants folded,
    // repeated operations merged, dead values dropped): the arithmetic a specialised kernel runs
    let recorded = kinedyn_core::trace::record_rnea(model).without_dead_code();
    println!("{name}/rnea_recorded_ops {}", recorded.arithmetic_count());
}
