//! Criterion bench of the dynamics algorithms of the core (never a CI gate):
//! `cargo bench -p kinedyn-core --bench core` (add `RUSTFLAGS="-C target-cpu=native"` to compare
//! with a `-march=native` C++ build). Models: `models/mod.rs` (UR5 and Panda from their DH tables).

mod models;

use criterion::{criterion_group, criterion_main, Criterion};
use kinedyn_core::algorithms as alg;
use kinedyn_core::Data;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    for (name, model) in models::all() {
        let n = model.n;
        let mut data = Data::new(&model);
        let (q, qd, qdd) = models::state(n);
        let tau = alg::rnea(&model, &mut data, &q, &qd, &qdd, None).to_vec();
        let mut out = vec![0.0; 10 * n * n];
        let mut g = c.benchmark_group(name);
        g.bench_function("rnea", |b| {
            b.iter(|| alg::rnea(&model, &mut data, black_box(&q), black_box(&qd), black_box(&qdd), None)[0])
        });
        g.bench_function("crba", |b| b.iter(|| alg::crba(&model, &mut data, black_box(&q))[0]));
        g.bench_function("aba", |b| {
            b.iter(|| alg::aba(&model, &mut data, black_box(&q), black_box(&qd), black_box(&tau), None).unwrap()[0])
        });
        g.bench_function("coriolis_matrix", |b| {
            b.iter(|| alg::coriolis_matrix(&model, &mut data, black_box(&q), black_box(&qd))[0])
        });
        g.bench_function("gravity_torque", |b| {
            b.iter(|| alg::gravity_torque(&model, &mut data, black_box(&q))[0])
        });
        g.bench_function("mass_matrix_inverse", |b| {
            b.iter(|| alg::mass_matrix_inverse(&model, &mut data, black_box(&q)).unwrap()[0])
        });
        g.bench_function("christoffel", |b| {
            b.iter(|| alg::christoffel(&model, &mut data, black_box(&q), &mut out[..n * n * n]))
        });
        g.bench_function("regressor", |b| {
            b.iter(|| {
                alg::regressor(
                    &model,
                    &mut data,
                    black_box(&q),
                    black_box(&qd),
                    black_box(&qdd),
                    &mut out,
                )
            })
        });
        let (mut d1, mut d2, mut d3) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
        g.bench_function("rnea_derivatives", |b| {
            b.iter(|| {
                alg::rnea_derivatives(
                    &model,
                    &mut data,
                    black_box(&q),
                    black_box(&qd),
                    black_box(&qdd),
                    None,
                    &mut d1,
                    &mut d2,
                    None,
                )
            })
        });
        g.bench_function("aba_derivatives", |b| {
            b.iter(|| {
                alg::aba_derivatives(
                    &model,
                    &mut data,
                    black_box(&q),
                    black_box(&qd),
                    black_box(&tau),
                    None,
                    &mut d1,
                    &mut d2,
                    &mut d3,
                )
                .unwrap()
            })
        });
        g.bench_function("kinetic_energy", |b| {
            b.iter(|| alg::kinetic_energy(&model, &mut data, black_box(&q), black_box(&qd)))
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(std::time::Duration::from_millis(300)).measurement_time(std::time::Duration::from_secs(1)).sample_size(30);
    targets = bench
}
criterion_main!(benches);
