//! Many states at once: the algorithms run on [`Lanes<N>`], one state per SIMD lane.
//!
//! A batch of states (row-major, one state after the other, as NumPy holds `(N, n)` arrays) is cut
//! into blocks of `N` states; each block is transposed into structure-of-arrays form (`q[j]` holds
//! coordinate j of the N states), the generic algorithm runs once on it, and its result is
//! transposed back. The lane count and instruction set are chosen at run time from the CPU
//! ([`Simd::detected`]): AVX-512 (8 lanes), AVX2 (4 lanes), or a portable 4-lane build for the
//! baseline instruction set; each is the same generic code compiled with other target features.
//! A block that is not full is padded with copies of its last state, whose results are dropped.
//!
//! A state that makes an algorithm fail (a singular mass matrix in the ABA) fails its block; the
//! block is then run again one state at a time, so the error is the single call's, for the first
//! failing state.

use crate::data::Data;
use crate::error::Error;
use crate::model::Model;
#[cfg(target_arch = "x86_64")]
use crate::scalar::x86::{F64x4, F64x8};
use crate::scalar::{as_f64s, as_f64s_mut, Lanes, Real};
use std::sync::OnceLock;

/// An algorithm as a batch runs it: `run` reads one state's inputs (`x[k]`, one slice per input)
/// and writes every number of its output `out`; it is generic over the scalar, so that one source
/// serves a single state (`f64`) and a block of states (`Lanes<N>`).
pub trait Kernel: Sync {
    /// Numbers per state of the output.
    fn output_len(&self, model: &Model) -> usize;
    fn run<T: Real>(&self, model: &Model, data: &mut Data<T>, x: &[&[T]], out: &mut [T]) -> crate::Result<()>;
}

/// How a batch is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simd {
    /// 8 lanes of AVX-512 (x86-64 with avx512f and avx512dq).
    Avx512,
    /// 4 lanes of AVX2 (x86-64 with avx2 and fma).
    Avx2,
    /// 4 lanes on the baseline instruction set (SSE2 on x86-64, NEON on aarch64).
    Portable,
    /// One state at a time, the single-call code (for comparisons).
    Off,
}

impl Simd {
    /// The widest kind this CPU runs, or the one named by the environment variable
    /// `KINEDYN_SIMD` (`avx512`, `avx2`, `portable`, `off`) when the CPU supports it.
    pub fn detected() -> Simd {
        static DETECTED: OnceLock<Simd> = OnceLock::new();
        *DETECTED.get_or_init(|| {
            let best = Simd::best_supported();
            match std::env::var("KINEDYN_SIMD").ok().and_then(|v| Simd::parse(&v)) {
                Some(asked) if asked.is_supported() => asked,
                _ => best,
            }
        })
    }

    /// `avx512`, `avx2`, `portable` or `off`.
    pub fn parse(name: &str) -> Option<Simd> {
        match name.trim().to_ascii_lowercase().as_str() {
            "avx512" => Some(Simd::Avx512),
            "avx2" => Some(Simd::Avx2),
            "portable" => Some(Simd::Portable),
            "off" => Some(Simd::Off),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Simd::Avx512 => "avx512",
            Simd::Avx2 => "avx2",
            Simd::Portable => "portable",
            Simd::Off => "off",
        }
    }

    /// States computed together.
    pub fn lanes(self) -> usize {
        match self {
            Simd::Avx512 => 8,
            Simd::Avx2 | Simd::Portable => 4,
            Simd::Off => 1,
        }
    }

    /// Whether this CPU can run this kind.
    pub fn is_supported(self) -> bool {
        match self {
            #[cfg(target_arch = "x86_64")]
            Simd::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("avx512dq")
            }
            #[cfg(target_arch = "x86_64")]
            Simd::Avx2 => std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma"),
            #[cfg(not(target_arch = "x86_64"))]
            Simd::Avx512 | Simd::Avx2 => false,
            Simd::Portable | Simd::Off => true,
        }
    }

    fn best_supported() -> Simd {
        [Simd::Avx512, Simd::Avx2]
            .into_iter()
            .find(|s| s.is_supported())
            .unwrap_or(Simd::Portable)
    }
}

/// Per-thread scratch of a batch: one `Data` per scalar type (made on first use) and the
/// transposed inputs and output of one block.
pub struct Scratch {
    pub data: Data,
    /// Free for the caller (the Python binding gathers several outputs of a state here).
    pub buffer: Vec<f64>,
    portable: Option<Block<Lanes<4>>>,
    #[cfg(target_arch = "x86_64")]
    avx2: Option<Block<F64x4>>,
    #[cfg(target_arch = "x86_64")]
    avx512: Option<Block<F64x8>>,
}

/// A block's `Data` and its transposed inputs and output.
struct Block<L: Real> {
    data: Data<L>,
    inputs: Vec<Vec<L>>,
    out: Vec<L>,
}

impl Scratch {
    pub fn new(model: &Model) -> Self {
        Self {
            data: Data::new(model),
            buffer: Vec::new(),
            portable: None,
            #[cfg(target_arch = "x86_64")]
            avx2: None,
            #[cfg(target_arch = "x86_64")]
            avx512: None,
        }
    }
}

/// One input of a batch: `values` holds the states' numbers, `width` per state.
#[derive(Clone, Copy)]
pub struct Input<'a> {
    pub values: &'a [f64],
    pub width: usize,
}

/// A failed state of a batch: its index in the states passed and the single call's error.
#[derive(Debug)]
pub struct StateError {
    pub state: usize,
    pub error: Error,
}

/// `kernel` on every state of `inputs` (each holding the same number of states), results to `out`
/// (`kernel.output_len(model)` numbers per state), computed the `simd` way.
pub fn run<K: Kernel>(
    model: &Model,
    scratch: &mut Scratch,
    kernel: &K,
    inputs: &[Input],
    out: &mut [f64],
    simd: Simd,
) -> Result<(), StateError> {
    let width = kernel.output_len(model);
    let states = out
        .len()
        .checked_div(width)
        .unwrap_or_else(|| inputs.first().map_or(0, |x| x.values.len() / x.width.max(1)));
    assert!(
        inputs.iter().all(|x| x.values.len() == states * x.width) && out.len() == states * width,
        "batch::run: inputs and output disagree on the number of states"
    );
    match simd {
        Simd::Off => one_by_one(model, &mut scratch.data, kernel, inputs, out, 0, states),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has the features this instance is compiled for (checked by `is_supported`)
        Simd::Avx512 if simd.is_supported() => unsafe { blocks_avx512(model, scratch, kernel, inputs, out, states) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above
        Simd::Avx2 if simd.is_supported() => unsafe { blocks_avx2(model, scratch, kernel, inputs, out, states) },
        _ => blocks(
            model,
            split(model, &mut scratch.portable),
            &mut scratch.data,
            kernel,
            inputs,
            out,
            states,
        ),
    }
}

/// The scratch's block of lane type L (made on first use).
fn split<'s, L: Real>(model: &Model, slot: &'s mut Option<Block<L>>) -> &'s mut Block<L> {
    slot.get_or_insert_with(|| Block {
        data: Data::new(model),
        inputs: Vec::new(),
        out: Vec::new(),
    })
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx2,fma")]
fn blocks_avx512<K: Kernel>(
    model: &Model,
    scratch: &mut Scratch,
    kernel: &K,
    inputs: &[Input],
    out: &mut [f64],
    states: usize,
) -> Result<(), StateError> {
    let block = split(model, &mut scratch.avx512);
    blocks(model, block, &mut scratch.data, kernel, inputs, out, states)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn blocks_avx2<K: Kernel>(
    model: &Model,
    scratch: &mut Scratch,
    kernel: &K,
    inputs: &[Input],
    out: &mut [f64],
    states: usize,
) -> Result<(), StateError> {
    let block = split(model, &mut scratch.avx2);
    blocks(model, block, &mut scratch.data, kernel, inputs, out, states)
}

/// The states in blocks of N: transpose in, run, transpose out. Inlined into each instance above,
/// so that the whole algorithm is compiled for that instance's instruction set.
#[inline(always)]
fn blocks<K: Kernel, L: Real>(
    model: &Model,
    block: &mut Block<L>,
    data: &mut Data,
    kernel: &K,
    inputs: &[Input],
    out: &mut [f64],
    states: usize,
) -> Result<(), StateError> {
    let (width, lanes) = (kernel.output_len(model), L::LANES);
    block.inputs.resize_with(inputs.len(), Vec::new);
    for (buf, x) in block.inputs.iter_mut().zip(inputs) {
        buf.resize(x.width, L::zero());
    }
    block.out.resize(width, L::zero());
    let mut first = 0;
    while first < states {
        let count = (states - first).min(lanes);
        for (buf, x) in block.inputs.iter_mut().zip(inputs) {
            let (w, soa) = (x.width, as_f64s_mut(buf));
            for k in 0..lanes {
                // a short block repeats its last state in the remaining lanes
                let state = first + k.min(count - 1);
                for (j, v) in x.values[state * w..(state + 1) * w].iter().enumerate() {
                    soa[j * lanes + k] = *v;
                }
            }
        }
        let x: [&[L]; 4] = std::array::from_fn(|k| block.inputs.get(k).map_or(&[][..], |b| &b[..]));
        if kernel
            .run(model, &mut block.data, &x[..inputs.len()], &mut block.out)
            .is_err()
        {
            return one_by_one(model, data, kernel, inputs, out, first, first + count);
        }
        let soa = as_f64s(&block.out);
        for k in 0..count {
            for (j, v) in out[(first + k) * width..(first + k + 1) * width].iter_mut().enumerate() {
                *v = soa[j * lanes + k];
            }
        }
        first += count;
    }
    Ok(())
}

/// States `a..b` one at a time with the single-call code (stops at the first error).
fn one_by_one<K: Kernel>(
    model: &Model,
    data: &mut Data,
    kernel: &K,
    inputs: &[Input],
    out: &mut [f64],
    a: usize,
    b: usize,
) -> Result<(), StateError> {
    let width = kernel.output_len(model);
    for state in a..b {
        let x: [&[f64]; 4] = std::array::from_fn(|k| {
            inputs
                .get(k)
                .map_or(&[][..], |x| &x.values[state * x.width..(state + 1) * x.width])
        });
        kernel
            .run(
                model,
                data,
                &x[..inputs.len()],
                &mut out[state * width..(state + 1) * width],
            )
            .map_err(|error| StateError { state, error })?;
    }
    Ok(())
}

/// The batched algorithms, as [`Kernel`]s.
pub mod kernels {
    use super::Kernel;
    use crate::algorithms as alg;
    use crate::data::Data;
    use crate::model::Model;
    use crate::scalar::Real;

    /// A kernel without parameters: `kernel!(/// doc, Name, |model| output length, |model, data, x, out| body)`
    /// (the body returns `crate::Result<()>`, generic over the scalar `T`).
    macro_rules! kernel {
        ($(#[$doc:meta])* $name:ident, |$m:ident| $len:expr, |$model:ident, $data:ident, $x:ident, $out:ident| $body:block) => {
            $(#[$doc])*
            pub struct $name;
            impl Kernel for $name {
                fn output_len(&self, $m: &Model) -> usize {
                    $len
                }
                #[inline(always)]
                fn run<T: Real>(&self, $model: &Model, $data: &mut Data<T>, $x: &[&[T]], $out: &mut [T]) -> crate::Result<()> $body
            }
        };
    }

    /// The optional input `k` (`f_ext`), when given.
    #[inline(always)]
    fn optional<'a, T>(x: &[&'a [T]], k: usize) -> Option<&'a [T]> {
        x.get(k).copied().filter(|v| !v.is_empty())
    }
    kernel!(
        /// `tau = rnea(q, qd, qdd[, f_ext])`, friction and armature included.
        InverseDynamics, |model| model.n, |model, data, x, out| {
            out.copy_from_slice(alg::rnea(model, data, x[0], x[1], x[2], optional(x, 3)));
            Ok(())
        }
    );
    kernel!(
        /// The regressor `Y(q, qd, qdd)` (n x 10 n, row-major): `tau = Y pi` without drive terms.
        Regressor, |model| 10 * model.n * model.n, |model, data, x, out| {
            alg::regressor(model, data, x[0], x[1], x[2], out);
            Ok(())
        }
    );
    kernel!(
        /// The kinetic energy `K(q, qd)` (one number; rotor inertia included).
        KineticEnergy, |_model| 1, |model, data, x, out| {
            out[0] = alg::kinetic_energy(model, data, x[0], x[1]);
            Ok(())
        }
    );
    kernel!(
        /// The potential energy `P(q)` (one number).
        PotentialEnergy, |_model| 1, |model, data, x, out| {
            out[0] = alg::potential_energy(model, data, x[0]);
            Ok(())
        }
    );
    kernel!(
        /// `M(q)` (n x n, row-major).
        MassMatrix, |model| model.n * model.n, |model, data, x, out| {
            out.copy_from_slice(alg::crba(model, data, x[0]));
            Ok(())
        }
    );
    kernel!(
        /// `M(q)^-1` (n x n, row-major).
        MassMatrixInverse, |model| model.n * model.n, |model, data, x, out| {
            out.copy_from_slice(alg::mass_matrix_inverse(model, data, x[0])?);
            Ok(())
        }
    );
    kernel!(
        /// `qdd = aba(q, qd, tau[, f_ext])`.
        ForwardDynamics, |model| model.n, |model, data, x, out| {
            out.copy_from_slice(alg::aba(model, data, x[0], x[1], x[2], optional(x, 3))?);
            Ok(())
        }
    );
    kernel!(
        /// `[qdd; lambda]` of a model with closed loops at `(q, qd, tau[, f_ext])`
        /// (`constraints::constrained_forward_dynamics`, the default proximal settings).
        ConstrainedForwardDynamics, |model| model.n + model.loop_rows(), |model, data, x, out| {
            crate::constraints::constrained_forward_dynamics(
                model, data, x[0], x[1], x[2], optional(x, 3), &crate::constraints::PROXIMAL, out,
            )
        }
    );
    kernel!(
        /// `g(q)`.
        Gravity, |model| model.n, |model, data, x, out| {
            out.copy_from_slice(alg::gravity_torque(model, data, x[0]));
            Ok(())
        }
    );

    /// The poses of `frames` (4 x 4 row-major each) after forward kinematics.
    pub struct FramePoses<'a> {
        pub frames: &'a [usize],
    }
    impl Kernel for FramePoses<'_> {
        fn output_len(&self, _model: &Model) -> usize {
            16 * self.frames.len()
        }
        #[inline(always)]
        fn run<T: Real>(&self, model: &Model, data: &mut Data<T>, x: &[&[T]], out: &mut [T]) -> crate::Result<()> {
            alg::forward_kinematics(model, data, x[0]);
            for (slot, &f) in out.chunks_exact_mut(16).zip(self.frames) {
                let pose = alg::frame_pose(model, data, f);
                let (r, t) = (&pose.rot, &pose.trans);
                let (zero, one) = (T::zero(), T::one());
                slot.copy_from_slice(&[
                    r[(0, 0)],
                    r[(0, 1)],
                    r[(0, 2)],
                    t.x,
                    r[(1, 0)],
                    r[(1, 1)],
                    r[(1, 2)],
                    t.y,
                    r[(2, 0)],
                    r[(2, 1)],
                    r[(2, 2)],
                    t.z,
                    zero,
                    zero,
                    zero,
                    one,
                ]);
            }
            Ok(())
        }
    }

    /// The 6 x n Jacobian of a frame (or of a point fixed in it), row-major.
    pub struct Jacobian {
        pub frame: usize,
        pub reference: alg::Reference,
        pub point: Option<crate::spatial::Vec3>,
    }
    impl Kernel for Jacobian {
        fn output_len(&self, model: &Model) -> usize {
            6 * model.n
        }
        #[inline(always)]
        fn run<T: Real>(&self, model: &Model, data: &mut Data<T>, x: &[&[T]], out: &mut [T]) -> crate::Result<()> {
            alg::frame_jacobian(model, data, x[0], self.frame, self.reference, self.point.as_ref(), out);
            Ok(())
        }
    }
    kernel!(
        /// The Coriolis matrix `C(q, qd)` (n x n, row-major; Christoffel-consistent).
        Coriolis, |model| model.n * model.n, |model, data, x, out| {
            out.copy_from_slice(alg::coriolis_matrix(model, data, x[0], x[1]));
            Ok(())
        }
    );
    kernel!(
        /// Christoffel symbols of the first kind `c[i][j][k]` (n x n x n).
        Christoffel, |model| model.n * model.n * model.n, |model, data, x, out| {
            alg::christoffel(model, data, x[0], out);
            Ok(())
        }
    );
    kernel!(
        /// `dtau/dq`, `dtau/dqd` and `M` (n x n each, one after the other) at `(q, qd, qdd[, f_ext])`.
        InverseDynamicsDerivatives, |model| 3 * model.n * model.n, |model, data, x, out| {
            let nn = model.n * model.n;
            let (dq, rest) = out.split_at_mut(nn);
            let (dqd, m) = rest.split_at_mut(nn);
            alg::rnea_derivatives(model, data, x[0], x[1], x[2], optional(x, 3), dq, dqd, Some(m));
            Ok(())
        }
    );
    kernel!(
        /// `dqdd/dq`, `dqdd/dqd` and `M^-1` (n x n each, one after the other) at `(q, qd, tau[, f_ext])`.
        ForwardDynamicsDerivatives, |model| 3 * model.n * model.n, |model, data, x, out| {
            let nn = model.n * model.n;
            let (dq, rest) = out.split_at_mut(nn);
            let (dqd, minv) = rest.split_at_mut(nn);
            alg::aba_derivatives(model, data, x[0], x[1], x[2], optional(x, 3), dq, dqd, minv)
        }
    );
    kernel!(
        /// `C(q, qd) qd + g(q)` (no friction).
        Bias, |model| model.n, |model, data, x, out| {
            out.copy_from_slice(alg::bias_torque(model, data, x[0], x[1]));
            Ok(())
        }
    );
}

#[cfg(test)]
mod tests {
    use super::kernels::*;
    use super::*;
    use crate::algorithms as alg;
    use crate::testing::{dh_model, random_configuration, random_floating_model, random_model, Rng, UR5_DH};

    fn models() -> Vec<(&'static str, Model)> {
        vec![
            ("ur5", dh_model(&UR5_DH, 1)),
            ("chain", random_model(2, 7, false)),
            ("tree", random_model(3, 9, true)),
            ("floating", random_floating_model(4, 5, false)),
            ("floating tree", random_floating_model(5, 6, true)),
            // external wrenches about link-frame origins off the body origins
            ("floating tree, link origins", {
                let model = random_floating_model(5, 6, true);
                let origins = (0..model.n)
                    .map(|k| crate::spatial::Vec3::new(0.1 * k as f64, -0.2, 0.3))
                    .collect();
                model.with_link_origins(origins).unwrap()
            }),
            // direction-dependent Coulomb levels (the lanes' compare-and-blend friction)
            (
                "asymmetric friction",
                random_model(6, 4, false)
                    .with_coulomb_negative(vec![0.05, 0.7, 0.2, 0.4])
                    .unwrap(),
            ),
        ]
    }

    /// `states` random states of `model`: q (nq each), two n-vectors and external wrenches (6 n).
    fn states(model: &Model, states: usize, seed: u64) -> [Vec<f64>; 4] {
        let mut rng = Rng::new(seed);
        let q: Vec<f64> = (0..states)
            .flat_map(|_| random_configuration(model, &mut rng))
            .collect();
        let [a, b] = std::array::from_fn(|_| rng.vector(states * model.n, -2.0, 2.0));
        [q, a, b, rng.vector(states * 6 * model.n, -5.0, 5.0)]
    }

    /// Every supported lane kind gives the single call's numbers (to 1e-13 relative to the largest
    /// magnitude of the state's result), on chains, trees and floating bases, for batch sizes that
    /// are not multiples of the lane count (padded blocks) and a batch of one.
    fn lanes_equal_single_calls<K: Kernel>(kernel: K, inputs: usize) {
        let kinds: Vec<Simd> = [Simd::Portable, Simd::Avx2, Simd::Avx512]
            .into_iter()
            .filter(|s| s.is_supported())
            .collect();
        for (name, model) in models() {
            for count in [1usize, 5, 13] {
                let values = states(&model, count, 7 + count as u64);
                let widths = [model.nq, model.n, model.n, 6 * model.n];
                let x: Vec<Input> = (0..inputs)
                    .map(|k| Input {
                        values: &values[k],
                        width: widths[k],
                    })
                    .collect();
                let width = kernel.output_len(&model);
                let mut expected = vec![f64::NAN; count * width];
                let mut scratch = Scratch::new(&model);
                run(&model, &mut scratch, &kernel, &x, &mut expected, Simd::Off).unwrap();
                for &simd in &kinds {
                    let mut got = vec![f64::NAN; count * width];
                    run(&model, &mut scratch, &kernel, &x, &mut got, simd).unwrap();
                    for s in 0..count {
                        let (e, g) = (&expected[s * width..(s + 1) * width], &got[s * width..(s + 1) * width]);
                        let scale = e.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                        for (a, b) in e.iter().zip(g) {
                            assert!(
                                (a - b).abs() <= 1e-13 * scale,
                                "{name}, {simd:?}, batch of {count}, state {s}: {a} vs {b}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn energies_in_lanes() {
        lanes_equal_single_calls(KineticEnergy, 2);
        lanes_equal_single_calls(PotentialEnergy, 1);
    }

    #[test]
    fn regressor_in_lanes() {
        lanes_equal_single_calls(Regressor, 3);
    }

    #[test]
    fn inverse_dynamics_in_lanes() {
        lanes_equal_single_calls(InverseDynamics, 3);
        lanes_equal_single_calls(InverseDynamics, 4);
    }

    #[test]
    fn mass_matrix_in_lanes() {
        lanes_equal_single_calls(MassMatrix, 1);
    }

    #[test]
    fn coriolis_and_christoffel_in_lanes() {
        lanes_equal_single_calls(Coriolis, 2);
        lanes_equal_single_calls(Christoffel, 1);
    }

    #[test]
    fn derivatives_in_lanes() {
        lanes_equal_single_calls(InverseDynamicsDerivatives, 3);
        lanes_equal_single_calls(InverseDynamicsDerivatives, 4);
        lanes_equal_single_calls(ForwardDynamicsDerivatives, 3);
        lanes_equal_single_calls(ForwardDynamicsDerivatives, 4);
    }

    #[test]
    fn mass_matrix_inverse_in_lanes() {
        lanes_equal_single_calls(MassMatrixInverse, 1);
    }

    #[test]
    fn forward_dynamics_in_lanes() {
        lanes_equal_single_calls(ForwardDynamics, 3);
        lanes_equal_single_calls(ForwardDynamics, 4);
    }

    #[test]
    fn gravity_and_bias_in_lanes() {
        lanes_equal_single_calls(Gravity, 1);
        lanes_equal_single_calls(Bias, 2);
    }

    #[test]
    fn frame_poses_and_jacobians_in_lanes() {
        // every model above has frames 0 (a body's) ..; frame 0 is on a moving body
        lanes_equal_single_calls(FramePoses { frames: &[0] }, 1);
        let point = Some(crate::spatial::Vec3::new(0.1, -0.2, 0.3));
        for reference in [alg::Reference::World, alg::Reference::Local, alg::Reference::Spatial] {
            lanes_equal_single_calls(
                Jacobian {
                    frame: 0,
                    reference,
                    point,
                },
                1,
            );
            lanes_equal_single_calls(
                Jacobian {
                    frame: 0,
                    reference,
                    point: None,
                },
                1,
            );
        }
    }

    /// A state that makes the ABA fail fails the batch with the single call's error, naming it.
    #[test]
    fn a_failing_state_is_named() {
        let mut model = random_model(9, 4, false);
        let massless = model.n - 1;
        model.inertia[massless] = crate::spatial::Inertia::zero();
        model.armature[massless] = 0.0;
        let [q, qd, _, _] = states(&model, 6, 1);
        let tau = qd.clone();
        let x = [
            Input { values: &q, width: 4 },
            Input { values: &qd, width: 4 },
            Input { values: &tau, width: 4 },
        ];
        for simd in [Simd::Off, Simd::Portable] {
            let mut out = vec![0.0; 6 * 4];
            let err = run(&model, &mut Scratch::new(&model), &ForwardDynamics, &x, &mut out, simd).unwrap_err();
            assert_eq!(err.state, 0, "{simd:?}");
            assert!(
                err.error.to_string().contains(&format!("joint {massless}")),
                "{}",
                err.error
            );
        }
    }
}
