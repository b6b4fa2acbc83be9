//! Constrained forward dynamics of closed mechanisms (issue 27), for `benches/cpp/compare_loops.sh`
//! beside Pinocchio's C++ `constraintDynamics` (never a CI gate).
//!   KINEDYN_BENCH_LOOPS=a.loops:b.loops cargo bench -p kinedyn-core --bench loops
//! The files are `benches/cpp/dump_loops.py`'s: a tree, its loops and closed states. Prints, per
//! mechanism R:
//!   R/check_qdd x...     qdd of every state (one after the other), for the comparison
//!   R/cfd NS             one call (`constraints::constrained_forward_dynamics`, the default
//!                        proximal settings), the states taken in turn
//!   R/cfd_batch_KIND NS  per state of a 1024-state batch on one thread (the states repeated), each
//!                        lane kind this CPU runs (`off`: one state at a time)
//! Timing as quick.rs: the minimum over rounds of the mean over ~0.3 ms.

#[allow(dead_code)] // the DH models of the other benches
mod models;

use kinedyn_core::batch::{self, kernels, Input, Scratch, Simd};
use kinedyn_core::constraints::{constrained_forward_dynamics, PROXIMAL};
use kinedyn_core::Data;
use std::hint::black_box;
use std::time::Instant;

/// One closed state: `(q, qd, tau)`.
type State = (Vec<f64>, Vec<f64>, Vec<f64>);

fn min_ns(mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    let mut calls = 0u64;
    while start.elapsed().as_micros() < 300 {
        f();
        calls += 1;
    }
    (0..100)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..calls {
                f();
            }
            t.elapsed().as_nanos() as f64 / calls as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let files = std::env::var("KINEDYN_BENCH_LOOPS").unwrap_or_default();
    for path in files.split(':').filter(|p| !p.is_empty()) {
        let tree = models::read_tree(path);
        let (model, name) = (&tree.model, &tree.name);
        let (n, nq, m) = (model.n, model.nq, model.loop_rows());
        assert!(
            !tree.states.is_empty(),
            "{path}: no closed states (a dump_loops.py file?)"
        );
        let split = |s: &Vec<f64>| (s[..nq].to_vec(), s[nq..nq + n].to_vec(), s[nq + n..nq + 2 * n].to_vec());
        let states: Vec<_> = tree.states.iter().map(split).collect();
        let mut data = Data::new(model);
        let mut out = vec![0.0; n + m];
        let mut qdd = Vec::new();
        for (q, qd, tau) in &states {
            constrained_forward_dynamics(model, &mut data, q, qd, tau, None, &PROXIMAL, &mut out)
                .unwrap_or_else(|e| panic!("{path}: {e}"));
            qdd.extend_from_slice(&out[..n]);
        }
        let values: Vec<String> = qdd.iter().map(|v| format!("{v:e}")).collect();
        println!("{name}/check_qdd {}", values.join(" "));
        let mut k = 0;
        let ns = min_ns(|| {
            let (q, qd, tau) = &states[k];
            k = (k + 1) % states.len();
            constrained_forward_dynamics(
                model,
                &mut data,
                black_box(q),
                black_box(qd),
                black_box(tau),
                None,
                &PROXIMAL,
                &mut out,
            )
            .unwrap();
            black_box(&out);
        });
        println!("{:28} {ns:8.1}", format!("{name}/cfd"));
        // a batch: the states repeated to 1024, in the layout of the Python batch call
        const STATES: usize = 1024;
        let pick = |f: &dyn Fn(&State) -> &Vec<f64>| -> Vec<f64> {
            (0..STATES).flat_map(|s| f(&states[s % states.len()]).clone()).collect()
        };
        let (bq, bqd, btau) = (pick(&|s| &s.0), pick(&|s| &s.1), pick(&|s| &s.2));
        let x = [
            Input { values: &bq, width: nq },
            Input { values: &bqd, width: n },
            Input {
                values: &btau,
                width: n,
            },
        ];
        let mut scratch = Scratch::new(model);
        let mut batch_out = vec![0.0; STATES * (n + m)];
        for simd in [Simd::Off, Simd::Portable, Simd::Avx2, Simd::Avx512]
            .into_iter()
            .filter(|s| s.is_supported())
        {
            let kernel = &kernels::ConstrainedForwardDynamics;
            batch::run(model, &mut scratch, kernel, &x, &mut batch_out, simd)
                .unwrap_or_else(|e| panic!("{path}: {e:?}"));
            // the batch computes what the single calls compute
            for s in 0..states.len() {
                for i in 0..n {
                    let (got, want) = (batch_out[s * (n + m) + i], qdd[s * n + i]);
                    assert!(
                        (got - want).abs() <= 1e-9 * want.abs().max(1.0),
                        "{name}: batch {} state {s}: {got} vs {want}",
                        simd.name()
                    );
                }
            }
            let ns = min_ns(|| {
                batch::run(model, &mut scratch, kernel, &x, black_box(&mut batch_out), simd).unwrap();
            }) / STATES as f64;
            println!("{:28} {ns:8.1}", format!("{name}/cfd_batch_{}", simd.name()));
        }
    }
}
