//! Criterion bench of forward kinematics and the tool Jacobian on a UR5-like arm and a random
//! 7-joint chain (never a CI gate): `cargo bench -p kinedyn-core --bench kinematics`.

use criterion::{criterion_group, criterion_main, Criterion};
use kinedyn_core::algorithms::{forward_kinematics, frame_jacobian, Reference};
use kinedyn_core::testing::{dh_model, random_model, Rng, UR5_DH};
use kinedyn_core::Data;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    for (name, model) in [("ur5", dh_model(&UR5_DH, 1)), ("chain7", random_model(2, 7, false))] {
        let mut data = Data::new(&model);
        let q = Rng::new(3).vector(model.n, -3.0, 3.0);
        let mut j = vec![0.0; 6 * model.n];
        let tool = 0;
        c.bench_function(&format!("{name}/forward_kinematics"), |b| {
            b.iter(|| forward_kinematics(&model, &mut data, black_box(&q)))
        });
        c.bench_function(&format!("{name}/tool_jacobian_world"), |b| {
            b.iter(|| frame_jacobian(&model, &mut data, black_box(&q), tool, Reference::World, None, &mut j))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
