//! `kinedyn._core`: PyO3 + rust-numpy glue around kinedyn-core, and nothing else.
//!
//! One place converts and checks shapes (`Batch::gather`), one place runs a per-state kernel over
//! one state or a batch with the GIL released (`Batch::run`) and checks that finite inputs gave
//! finite results. Every kernel is a call into the core. Every binding runs inside
//! `guard::guarded` (a panic is a RuntimeError), allocates its results through `guard` (a MemoryError
//! naming the bytes, never an abort) and runs batches in `guard::install`'s fork-safe pool.

mod codegen;
mod conv;
mod guard;
mod ik;
mod ik_branches;
mod ik_redundant;
mod lie;
mod model;
mod records;
mod run;
mod simulate;

use kinedyn_core::batch::Simd;
use pyo3::prelude::*;

pub(crate) use model::PyModel;
pub(crate) use run::core_err;

/// How batches run on this machine: (kind, states per block); the kind is "avx512", "avx2",
/// "portable" or "off", chosen from the CPU once per process, or by the environment variable
/// KINEDYN_SIMD when the CPU supports the kind it names.
#[pyfunction]
fn simd() -> (&'static str, usize) {
    let s = Simd::detected();
    (s.name(), s.lanes())
}

/// The in-plane unit axes (e1, e2) of a planar joint with unit normal `normal` (e1 x e2 = normal).
#[pyfunction]
fn planar_basis(normal: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let (e1, e2) = kinedyn_core::joint::planar_basis(kinedyn_core::spatial::Vec3::from(normal));
    (e1.into(), e2.into())
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()?;
    m.add_function(wrap_pyfunction!(simd, m)?)?;
    m.add_function(wrap_pyfunction!(planar_basis, m)?)?;
    m.add_function(wrap_pyfunction!(records::joint_transform, m)?)?;
    m.add(
        "SingularMassMatrixError",
        m.py().get_type::<run::SingularMassMatrixError>(),
    )?;
    codegen::register(m)?;
    guard::register(m)?;
    ik::register(m)?;
    ik_redundant::register(m)?;
    lie::register(m)?;
    simulate::register(m)?;
    Ok(())
}
