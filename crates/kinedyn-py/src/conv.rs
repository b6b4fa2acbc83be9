//! Every conversion of a Python argument into numbers for the core, and every check of its shape,
//! finiteness and range: one dialect for all bindings (`Batch::gather` for per-state arrays,
//! `numbers` for the model's joint records, `vec_of` for fixed-shape tables, `frame` / `reference` / `point` for the kinematics' options).

use std::borrow::Cow;

use kinedyn_core::algorithms::Reference;
use kinedyn_core::spatial::Vec3;
use numpy::{PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOverflowError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::IntoPyDict;

use crate::guard::{self, shape_text};

/// Input `k` of a state if the call was given it (absent inputs are empty slices).
#[inline]
pub(crate) fn optional<'a>(x: &[&'a [f64]], k: usize) -> Option<&'a [f64]> {
    x.get(k).copied().filter(|v| !v.is_empty())
}

pub(crate) fn reshape_error(name: &str, expected: &[usize], got: &[usize]) -> PyErr {
    let exp = expected.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ");
    let one = if expected.len() == 1 { "," } else { "" };
    PyValueError::new_err(format!(
        "{name} must have shape ({exp}{one}) or a batch (N, {exp}), got {}",
        shape_text(got)
    ))
}

/// A NumPy float64 array as the inputs of one call. Two kinds: `PyReadonlyArrayDyn` (rust-numpy's
/// borrow tracking, about 0.4 us per array) and a plain `Bound<PyArrayDyn<f64>>` (a type check
/// only), which the hot dynamics methods take.
pub(crate) trait StateArray<'a> {
    fn dims(&self) -> &[usize];
    /// The numbers in C order; `batch`: the call will release the GIL. A copy is allocated
    /// fallibly (MemoryError, not an abort, when it cannot be had).
    fn numbers(&'a self, name: &str, batch: bool) -> PyResult<Cow<'a, [f64]>>;
}

/// The elements of an array view in C order, in a fallibly allocated Vec.
fn collect_c_order<'v>(name: &str, view: impl ExactSizeIterator<Item = &'v f64>) -> PyResult<Vec<f64>> {
    let mut v = guard::try_vec(&format!("copying {name}"), view.len())?;
    v.extend(view.copied());
    Ok(v)
}

impl<'a> StateArray<'a> for PyReadonlyArrayDyn<'_, f64> {
    fn dims(&self) -> &[usize] {
        self.shape()
    }
    fn numbers(&'a self, name: &str, _batch: bool) -> PyResult<Cow<'a, [f64]>> {
        // as_slice() also accepts Fortran order (memory order != logical order): C order only
        match self.as_slice() {
            Ok(s) if self.is_c_contiguous() => Ok(Cow::Borrowed(s)),
            _ => Ok(Cow::Owned(collect_c_order(name, self.as_array().iter())?)),
        }
    }
}

impl<'a> StateArray<'a> for Bound<'_, PyArrayDyn<f64>> {
    fn dims(&self) -> &[usize] {
        self.shape()
    }
    fn numbers(&'a self, name: &str, batch: bool) -> PyResult<Cow<'a, [f64]>> {
        // SAFETY: a single state is read while this thread holds the GIL and runs no Python code,
        // so nothing writes to the array meanwhile; a batch (run with the GIL released) is copied
        // here, under the GIL, first.
        if self.is_c_contiguous() {
            if let Ok(s) = unsafe { self.as_slice() } {
                // a batch is copied with one memcpy (ndarray's element iterator was 4 % of a batch)
                return Ok(if batch {
                    Cow::Owned(guard::try_copy(&format!("copying {name}"), s)?)
                } else {
                    Cow::Borrowed(s)
                });
            }
        }
        Ok(Cow::Owned(collect_c_order(name, unsafe { self.as_array() }.iter())?))
    }
}

/// `x` as a float64 NumPy array: itself when it is one (a type check), else
/// `numpy.asarray(x, dtype=float64)` (lists, integer, boolean or float32 arrays), so that every
/// method takes what NumPy would, except what NumPy would convert by losing information: complex
/// numbers (their imaginary part), strings, dates. Those raise a TypeError naming the argument.
pub(crate) fn f64_array<'py>(name: &str, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(array) = x.cast::<PyArrayDyn<f64>>() {
        return Ok(array.clone());
    }
    static ASARRAY: pyo3::sync::PyOnceLock<Py<PyAny>> = pyo3::sync::PyOnceLock::new();
    let py = x.py();
    let asarray = ASARRAY
        .get_or_try_init(py, || py.import("numpy")?.getattr("asarray").map(Bound::unbind))?
        .bind(py);
    // a Python integer beyond float64 (and int64): the ValueError of `_arrays.real_array`
    let too_large = |e: PyErr| {
        if e.is_instance_of::<PyOverflowError>(py) {
            PyValueError::new_err(format!("{name} holds an integer too large for float64"))
        } else {
            e
        }
    };
    // an array (or what NumPy makes of a list) of what dtype?
    let array = match x.cast::<numpy::PyUntypedArray>() {
        Ok(a) => a.clone(),
        Err(_) => asarray
            .call1((x,))
            .map_err(too_large)?
            .cast_into::<numpy::PyUntypedArray>()?,
    };
    let dtype = array.dtype();
    let kind = dtype.kind();
    if !matches!(kind, b'f' | b'i' | b'u' | b'b' | b'O') {
        let what = if kind == b'c' {
            "complex numbers (the imaginary part would be lost)".to_string()
        } else {
            format!("an array of dtype {dtype}")
        };
        return Err(PyTypeError::new_err(format!("{name} must be real numbers, got {what}")));
    }
    let kwargs = [("dtype", "float64")].into_py_dict(py)?;
    let converted = asarray.call((&array,), Some(&kwargs)).map_err(|e| {
        if e.is_instance_of::<PyOverflowError>(py) {
            return too_large(e);
        }
        // an object array holding something that is not a real number (complex, None, text ...)
        PyTypeError::new_err(format!("{name} must be real numbers: {}", e.value(py)))
    })?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

/// The most arrays a method takes per state (q, qd, qdd, f_ext).
pub(crate) const MAX_INPUTS: usize = 4;

/// Inputs of one call: `values[k]` holds `batch` states of `width[k]` numbers each, borrowed from
/// the NumPy array when it is C-contiguous (copied otherwise).
pub(crate) struct Batch<'a> {
    /// `None` for a single state (outputs lose the leading axis).
    pub(crate) batch: Option<usize>,
    /// At most `MAX_INPUTS` inputs, kept in arrays (no heap allocation per call).
    pub(crate) values: [Cow<'a, [f64]>; MAX_INPUTS],
    pub(crate) width: [usize; MAX_INPUTS],
    /// How many of them the call was given.
    pub(crate) count: usize,
}

impl<'a> Batch<'a> {
    /// Check each input against its per-state shape; all inputs share one batch size.
    pub(crate) fn gather<A: StateArray<'a> + ?Sized>(inputs: &[(&str, &'a A, &[usize])]) -> PyResult<Self> {
        let mut batch: Option<Option<usize>> = None;
        assert!(
            inputs.len() <= MAX_INPUTS,
            "a method takes at most {MAX_INPUTS} state arrays"
        );
        let mut values: [Cow<'a, [f64]>; MAX_INPUTS] = Default::default();
        let mut width = [0; MAX_INPUTS];
        for (k, (name, array, shape)) in inputs.iter().enumerate() {
            let got = array.dims();
            let this = if got == *shape {
                None
            } else if got.len() == shape.len() + 1 && &got[1..] == *shape {
                Some(got[0])
            } else {
                return Err(reshape_error(name, shape, got));
            };
            match batch {
                None => batch = Some(this),
                Some(b) if b != this => {
                    return Err(PyValueError::new_err(format!(
                        "{name} has shape {}, which does not match the other arguments ({})",
                        shape_text(got),
                        match b {
                            Some(b) => format!("a batch of {b} states"),
                            None => "a single state".to_string(),
                        }
                    )))
                }
                _ => {}
            }
            let data = array.numbers(name, this.is_some())?;
            let w: usize = shape.iter().product();
            if let Some(k) = data.iter().position(|x| !x.is_finite()) {
                let state = k.checked_div(w).unwrap_or(0);
                let at = if this.is_some() {
                    format!(" in state {state}")
                } else {
                    String::new()
                };
                return Err(PyValueError::new_err(format!(
                    "{name} contains a non-finite value (NaN or inf) at index {}{at}",
                    k % w.max(1)
                )));
            }
            values[k] = data;
            width[k] = w;
        }
        Ok(Self {
            batch: batch.flatten(),
            values,
            width,
            count: inputs.len(),
        })
    }

    /// The inputs of state `k` (at most 4 arguments per call).
    pub(crate) fn state(&self, k: usize) -> [&[f64]; 4] {
        let mut out: [&[f64]; 4] = [&[]; 4];
        for (slot, (v, w)) in out.iter_mut().zip(self.values.iter().zip(&self.width)) {
            *slot = &v[k * w..(k + 1) * w];
        }
        out
    }
}

/// `x` as float64 numbers of exactly `shape`.
pub(crate) fn numbers(what: &str, x: &Bound<'_, PyAny>, shape: &[usize]) -> PyResult<Vec<f64>> {
    let array = f64_array(what, x)?;
    if array.shape() != shape {
        return Err(PyValueError::new_err(format!(
            "{what} must have shape {}, got {}",
            shape_text(shape),
            shape_text(array.shape())
        )));
    }
    Ok(array.readonly().as_array().iter().copied().collect())
}

pub(crate) fn vec_of(name: &str, a: &PyReadonlyArrayDyn<f64>, shape: &[usize]) -> PyResult<Vec<f64>> {
    if a.shape() != shape {
        return Err(reshape_error(name, shape, a.shape()));
    }
    Ok(a.as_array().iter().copied().collect())
}

pub(crate) fn reference(name: &str) -> PyResult<Reference> {
    Reference::from_name(name).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A frame index of a model with `nf` frames.
pub(crate) fn frame(frame: i64, nf: usize) -> PyResult<usize> {
    if frame < 0 || frame as usize >= nf {
        return Err(PyValueError::new_err(format!(
            "frame index {frame} out of range (the model has {nf} frames)"
        )));
    }
    Ok(frame as usize)
}

/// An optional point (3,) fixed in a frame, finite.
pub(crate) fn point(point: Option<PyReadonlyArrayDyn<f64>>) -> PyResult<Option<Vec3>> {
    point
        .map(|p| {
            let v = vec_of("point", &p, &[3])?;
            if v.iter().any(|x| !x.is_finite()) {
                return Err(PyValueError::new_err("point contains a non-finite value"));
            }
            Ok(Vec3::new(v[0], v[1], v[2]))
        })
        .transpose()
}

/// External wrenches given one per link (`links` = `Model::link_bodies` of 6 numbers each, per
/// state of `per_link`) laid out one per body of `model`, as the core's algorithms read them (its
/// `Model::link_wrenches`: a multi-DOF joint's link on its last body). A model of 1-DOF joints has
/// one body per link: the numbers as given.
pub(crate) fn wrenches_per_body(model: &kinedyn_core::Model, per_link: &[f64]) -> PyResult<Vec<f64>> {
    let width = 6 * model.link_bodies().len();
    if model.plain || width == 0 {
        return guard::try_copy("f_ext", per_link);
    }
    let states = per_link.len() / width;
    let mut out = guard::try_vec("f_ext per body", states * 6 * model.n)?;
    out.resize(states * 6 * model.n, 0.0);
    for (links, bodies) in per_link.chunks(width).zip(out.chunks_mut(6 * model.n)) {
        model
            .link_wrenches(links, bodies)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
    }
    Ok(out)
}

/// Constant external wrenches `f_ext` of a simulation, one per link ((links, 6), as
/// `Model.inverse_dynamics` takes them), checked (shape, finite) and laid out one per body.
pub(crate) fn constant_wrenches(
    model: &kinedyn_core::Model,
    f_ext: Option<&PyReadonlyArrayDyn<f64>>,
) -> PyResult<Option<Vec<f64>>> {
    let Some(f) = f_ext else { return Ok(None) };
    let links = model.link_bodies().len();
    let v = vec_of("f_ext", f, &[links, 6])?;
    if let Some(k) = v.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "f_ext contains a non-finite value (NaN or inf) at flat index {k}"
        )));
    }
    wrenches_per_body(model, &v).map(Some)
}
