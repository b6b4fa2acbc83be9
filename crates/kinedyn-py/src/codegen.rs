//! Robot-specialised code (`kinedyn_core::trace`): an algorithm recorded for one model, its operation
//! counts, and its source as C or Rust (`kinedyn codegen`).

use kinedyn_core::trace::emit::{self, Language};
use kinedyn_core::trace::{record_algorithm, Algorithm, Counts};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::guard::guarded;
use crate::PyModel;

/// The algorithm of a name (`rnea`, `crba`, `minv`, `aba`, `gravity`, `rnea_derivatives`,
/// `aba_derivatives`), or a ValueError listing them.
fn algorithm(name: &str) -> PyResult<Algorithm> {
    Algorithm::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.name()).collect();
        PyValueError::new_err(format!("unknown algorithm '{name}': one of {}", names.join(", ")))
    })
}

/// The names of the algorithms that can be recorded, in order.
#[pyfunction]
fn trace_algorithms() -> Vec<&'static str> {
    Algorithm::ALL.iter().map(|a| a.name()).collect()
}

fn counts_dict<'py>(py: Python<'py>, c: &Counts) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in [
        ("add", c.add),
        ("mul", c.mul),
        ("div", c.div),
        ("neg", c.neg),
        ("sincos", c.sincos),
        ("select", c.select),
        ("add_mul", c.add_mul()),
    ] {
        d.set_item(k, v)?;
    }
    Ok(d)
}

/// Operation counts of `algorithm` recorded for `model`: `(recorded, optimized)`, each a dict of
/// `add` (additions and subtractions), `mul`, `div`, `neg`, `sincos`, `select` (Coulomb levels) and
/// `add_mul` (the arithmetic floor's adds + muls).
#[pyfunction]
fn trace_counts<'py>(
    py: Python<'py>,
    model: &PyModel,
    algorithm: &str,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    guarded("trace_counts", || {
        let program = record_algorithm(&model.model, self::algorithm(algorithm)?);
        let optimized = program.optimized();
        Ok((
            counts_dict(py, &program.counts())?,
            counts_dict(py, &optimized.counts())?,
        ))
    })
}

/// The source of one file with `kinedyn_<robot>_<algorithm>` for each of `algorithms`, in
/// `language` (`c` or `rust`); `version` is written in the headers.
#[pyfunction]
fn trace_source(
    model: &PyModel,
    robot: &str,
    algorithms: Vec<String>,
    language: &str,
    version: &str,
) -> PyResult<String> {
    guarded("trace_source", || {
        let language = Language::from_name(language)
            .ok_or_else(|| PyValueError::new_err(format!("unknown language '{language}': c or rust")))?;
        let algorithms = algorithms.iter().map(|a| algorithm(a)).collect::<PyResult<Vec<_>>>()?;
        Ok(emit::source(&model.model, robot, &algorithms, language, version))
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(trace_algorithms, m)?)?;
    m.add_function(wrap_pyfunction!(trace_counts, m)?)?;
    m.add_function(wrap_pyfunction!(trace_source, m)?)?;
    Ok(())
}
