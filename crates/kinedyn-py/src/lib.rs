//! `kinedyn._core`: PyO3 + rust-numpy glue around kinedyn-core, and nothing else.
//!
//! One place converts and checks shapes (`Batch::gather`), one place runs a per-state kernel over
//! one state or a batch with the GIL released (`Batch::run`) and checks that finite inputs gave
//! finite results. Every kernel is a call into the core. Every binding runs inside
//! `guard::guarded` (a panic is a RuntimeError), allocates its results through `guard` (a MemoryError
//! naming the bytes, never an abort) and runs batches in `guard::install`'s fork-safe pool.

use std::borrow::Cow;

mod guard;
mod ik;
mod simulate;
use std::sync::atomic::Ordering;
use std::sync::Mutex;

use guard::{guarded, shape_text};

use kinedyn_core::algorithms::{self, Reference};
use kinedyn_core::batch::{self, kernels, Input, Kernel, Scratch, Simd};
use kinedyn_core::model::{Block, Coordinates};
use kinedyn_core::spatial::{Inertia, Transform, Vec3};
use kinedyn_core::{Data, Error as CoreError, Frame, Joint, JointKind, Model};
use numpy::{PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::IntoPyDict;
use rayon::prelude::*;

fn core_err(e: CoreError) -> PyErr {
    match e {
        CoreError::SingularMassMatrix(_) => PyRuntimeError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// Input `k` of a state if the call was given it (absent inputs are empty slices).
#[inline]
fn optional<'a>(x: &[&'a [f64]], k: usize) -> Option<&'a [f64]> {
    x.get(k).copied().filter(|v| !v.is_empty())
}

fn reshape_error(name: &str, expected: &[usize], got: &[usize]) -> PyErr {
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
trait StateArray<'a> {
    fn dims(&self) -> &[usize];
    /// The numbers in C order; `batch`: the call will release the GIL. A copy is allocated
    /// fallibly (MemoryError, not an abort, when it cannot be had).
    fn numbers(&'a self, name: &str, batch: bool) -> PyResult<Cow<'a, [f64]>>;
}

/// The elements of an array view in C order, in a fallibly allocated Vec.
fn collect_c_order<'v>(name: &str, view: impl Iterator<Item = &'v f64> + ExactSizeIterator) -> PyResult<Vec<f64>> {
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
fn f64_array<'py>(name: &str, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(array) = x.cast::<PyArrayDyn<f64>>() {
        return Ok(array.clone());
    }
    static ASARRAY: pyo3::sync::PyOnceLock<Py<PyAny>> = pyo3::sync::PyOnceLock::new();
    let py = x.py();
    let asarray = ASARRAY
        .get_or_try_init(py, || py.import("numpy")?.getattr("asarray").map(Bound::unbind))?
        .bind(py);
    // an array (or what NumPy makes of a list) of what dtype?
    let array = match x.cast::<numpy::PyUntypedArray>() {
        Ok(a) => a.clone(),
        Err(_) => asarray.call1((x,))?.cast_into::<numpy::PyUntypedArray>()?,
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
        // an object array holding something that is not a real number (complex, None, text ...)
        PyTypeError::new_err(format!("{name} must be real numbers: {}", e.value(py)))
    })?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

/// The most arrays a method takes per state (q, qd, qdd, f_ext).
const MAX_INPUTS: usize = 4;

/// Inputs of one call: `values[k]` holds `batch` states of `width[k]` numbers each, borrowed from
/// the NumPy array when it is C-contiguous (copied otherwise).
struct Batch<'a> {
    /// `None` for a single state (outputs lose the leading axis).
    batch: Option<usize>,
    /// At most `MAX_INPUTS` inputs, kept in arrays (no heap allocation per call).
    values: [Cow<'a, [f64]>; MAX_INPUTS],
    width: [usize; MAX_INPUTS],
    /// How many of them the call was given.
    count: usize,
}

impl<'a> Batch<'a> {
    /// Check each input against its per-state shape; all inputs share one batch size.
    fn gather<A: StateArray<'a> + ?Sized>(inputs: &[(&str, &'a A, &[usize])]) -> PyResult<Self> {
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
                let state = if w > 0 { k / w } else { 0 };
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
    fn state(&self, k: usize) -> [&[f64]; 4] {
        let mut out: [&[f64]; 4] = [&[]; 4];
        for (slot, (v, w)) in out.iter_mut().zip(self.values.iter().zip(&self.width)) {
            *slot = &v[k * w..(k + 1) * w];
        }
        out
    }

    /// Run `kernel(model, data, inputs_of_state, out_of_state)` on every state, writing straight
    /// into a fresh NumPy array; `kernel` must write every element of `out_of_state` (it is not
    /// zeroed first). A single state runs with the cached `Data`, keeping the GIL (the
    /// call is shorter than releasing it); a batch runs with the GIL released, in parallel
    /// chunks of 64 states, each rayon job reusing one `Data` over its chunks.
    ///
    /// `what` names the call and its result (`Output`) for the errors: a result that cannot be
    /// allocated (MemoryError) and a non-finite number in a result of finite inputs
    /// (`NonFiniteResultError`: the outputs of each chunk of states are scanned right after its
    /// kernels wrote them, while they are in cache).
    fn run<'py, F>(
        &self,
        py: Python<'py>,
        m: &PyModel,
        what: Output,
        out_shape: &[usize],
        kernel: F,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>>
    where
        F: Fn(&Model, &mut Data, &[&[f64]], &mut [f64]) -> Result<(), CoreError> + Sync,
    {
        self.run_out(py, m, what, out_shape, None, kernel)
    }

    /// `run` writing into the caller's array `out` when given (NumPy's `out=`: no allocation per
    /// call), after checking that it is a writeable, C-contiguous float64 array of the result's
    /// shape that shares no memory with the inputs.
    fn run_out<'py, F>(
        &self,
        py: Python<'py>,
        m: &PyModel,
        what: Output,
        out_shape: &[usize],
        out: Option<Bound<'py, PyAny>>,
        kernel: F,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>>
    where
        F: Fn(&Model, &mut Data, &[&[f64]], &mut [f64]) -> Result<(), CoreError> + Sync,
    {
        let given = out.map(|o| self.checked_out(o, out_shape)).transpose()?;
        let [array] = self.run_many::<1, _>(
            py,
            m,
            (what.0, [what.1]),
            out_shape,
            [given],
            None,
            |model, data, x, [out]| kernel(model, data, x, out),
        )?;
        Ok(array)
    }

    /// `run_out` for a core [`Kernel`]: a batch computes several states at once in SIMD lanes
    /// (`kinedyn_core::batch`, the lane kind chosen from the CPU), a single state with the cached
    /// `Data`.
    fn run_kernel<'py, Kn: Kernel>(
        &self,
        py: Python<'py>,
        m: &PyModel,
        what: Output,
        out_shape: &[usize],
        out: Option<Bound<'py, PyAny>>,
        kernel: Kn,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let given = out.map(|o| self.checked_out(o, out_shape)).transpose()?;
        let simd = Simd::detected();
        let lanes = |model: &Model, scratch: &mut Scratch, x: &[Input], out: &mut [f64]| {
            batch::run(model, scratch, &kernel, x, out, simd)
        };
        let [array] = self.run_many::<1, _>(
            py,
            m,
            (what.0, [what.1]),
            out_shape,
            [given],
            Some(&lanes),
            |model, data, x, [out]| kernel.run(model, data, x, out),
        )?;
        Ok(array)
    }

    /// `out` as the destination of this call's result (see `run_out`), or a clear error.
    fn checked_out<'py>(&self, out: Bound<'py, PyAny>, out_shape: &[usize]) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let array = out.cast_into::<PyArrayDyn<f64>>().map_err(|e| {
            let given = e.into_inner();
            let what = match given.getattr("dtype") {
                Ok(dtype) => format!("an array of dtype {dtype}"),
                Err(_) => format!("{}", given.get_type()),
            };
            PyTypeError::new_err(format!("out must be a float64 NumPy array, got {what}"))
        })?;
        let expected: Vec<usize> = self.batch.iter().chain(out_shape).copied().collect();
        if array.shape() != expected.as_slice() {
            return Err(PyValueError::new_err(format!(
                "out must have shape {}, got {}",
                shape_text(&expected),
                shape_text(array.shape())
            )));
        }
        // SAFETY: reading the flags of a live array object
        let writeable = unsafe { (*array.as_array_ptr()).flags } & numpy::npyffi::flags::NPY_ARRAY_WRITEABLE != 0;
        if !array.is_c_contiguous() || !writeable {
            return Err(PyValueError::new_err("out must be a writeable, C-contiguous array"));
        }
        // SAFETY: only the address range is read, to compare it with the inputs'
        let range = unsafe { array.as_slice() }?.as_ptr_range();
        for values in &self.values {
            let input = values.as_ptr_range();
            if matches!(values, Cow::Borrowed(_)) && input.start < range.end && range.start < input.end {
                return Err(PyValueError::new_err("out must not share memory with the inputs"));
            }
        }
        Ok(array)
    }

    /// `run` for kernels with K outputs of the same per-state shape, returned as K arrays.
    ///
    /// `lanes`, when given (K = 1), computes a range of a batch's states at once (`run_kernel`).
    #[allow(clippy::too_many_arguments)]
    fn run_many<'py, const K: usize, F>(
        &self,
        py: Python<'py>,
        m: &PyModel,
        what: Outputs<K>,
        out_shape: &[usize],
        given: [Option<Bound<'py, PyArrayDyn<f64>>>; K],
        lanes: Option<&LaneRange>,
        kernel: F,
    ) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; K]>
    where
        F: Fn(&Model, &mut Data, &[&[f64]], [&mut [f64]; K]) -> Result<(), CoreError> + Sync,
    {
        m.check_configurations(&self.values[0])?;
        // numbers per state (1 for a scalar result, 0 for an empty one such as no frames)
        let per_state: usize = out_shape.iter().product();
        // the outputs' shape, [N,] + out_shape, in a fixed array (ndarray keeps up to 4 dims inline)
        let (mut dims, mut rank) = ([0usize; 5], 0);
        for d in self.batch.iter().chain(out_shape) {
            dims[rank] = *d;
            rank += 1;
        }
        // the caller's checked `out` arrays, or fresh ones. Fresh arrays are uninitialised
        // memory, not zeros (a 10k-state M batch spent 10 % of its time in the memset): every kernel
        // writes its whole output slices (its contract, see `run`), and on an error they are dropped
        // unread. Created here, nothing else refers to them. Their size is checked first and a
        // failed allocation is a MemoryError naming the method.
        guard::check_size(what.0, K, &dims[..rank])?;
        let mut arrays: [Option<Bound<'py, PyArrayDyn<f64>>>; K] = std::array::from_fn(|_| None);
        for (slot, g) in arrays.iter_mut().zip(given) {
            *slot = Some(match g {
                Some(g) => g,
                None => guard::empty(py, what.0, &dims[..rank])?,
            });
        }
        let arrays: [Bound<'py, PyArrayDyn<f64>>; K] = arrays.map(|a| a.expect("every slot was filled above"));
        let total = self.batch.unwrap_or(1) * per_state;
        let mut bases = [OutputBase(std::ptr::null_mut()); K];
        for (base, array) in bases.iter_mut().zip(&arrays) {
            let slice = unsafe { array.as_slice_mut()? };
            assert_eq!(slice.len(), total, "a fresh array has the requested size");
            base.0 = slice.as_mut_ptr();
        }
        // SAFETY (both paths): state k's outputs are the disjoint ranges [k per_state, (k + 1)
        // per_state) of the arrays, each written by exactly one kernel call (and read back by the
        // scan right after it, by the same thread).
        let outputs =
            |k: usize| bases.map(|b| unsafe { std::slice::from_raw_parts_mut(b.0.add(k * per_state), per_state) });
        let check = guard::CHECK_FINITE.load(Ordering::Relaxed);
        // states [a, b): the kernel on each, then one scan of the outputs they wrote (contiguous,
        // still in cache: a chunk of 64 states of M is 18 KiB for n = 6)
        let check_range = |a: usize, b: usize| -> Result<(), Fault> {
            if check && per_state > 0 {
                for (o, base) in bases.iter().enumerate() {
                    // SAFETY: the range just written by this thread (see `outputs`)
                    let written = unsafe { std::slice::from_raw_parts(base.0.add(a * per_state), (b - a) * per_state) };
                    if any_non_finite(written) {
                        let at = written.iter().position(|v| !v.is_finite()).unwrap_or(0);
                        return Err(Fault::NonFinite {
                            state: a + at / per_state,
                            output: o,
                            index: at % per_state,
                            value: written[at],
                        });
                    }
                }
            }
            Ok(())
        };
        let states_range = |scratch: &mut Scratch, a: usize, b: usize| -> Result<(), Fault> {
            match lanes {
                Some(lanes) if b - a > 1 => {
                    let inputs: [Input; MAX_INPUTS] = std::array::from_fn(|k| {
                        let w = self.width[k];
                        Input {
                            values: self.values[k].get(a * w..b * w).unwrap_or(&[]),
                            width: w,
                        }
                    });
                    if K == 1 {
                        // SAFETY: the range [a per_state, b per_state) of the one output, written by this thread only
                        let out = unsafe {
                            std::slice::from_raw_parts_mut(bases[0].0.add(a * per_state), (b - a) * per_state)
                        };
                        lanes(&m.model, scratch, &inputs[..self.count], out).map_err(|e| Fault::Core(e.error))?;
                    } else {
                        // the kernel writes a state's K outputs one after the other: gathered in the
                        // scratch's buffer, then copied to the K arrays
                        let mut buffer = std::mem::take(&mut scratch.buffer);
                        buffer.resize((b - a) * K * per_state, 0.0);
                        lanes(&m.model, scratch, &inputs[..self.count], &mut buffer)
                            .map_err(|e| Fault::Core(e.error))?;
                        for (state, values) in (a..b).zip(buffer.chunks_exact(K * per_state.max(1))) {
                            for (out, part) in outputs(state).into_iter().zip(values.chunks_exact(per_state.max(1))) {
                                out.copy_from_slice(part);
                            }
                        }
                        scratch.buffer = buffer;
                    }
                }
                _ => {
                    for k in a..b {
                        kernel(&m.model, &mut scratch.data, &self.state(k), outputs(k))?;
                    }
                }
            }
            check_range(a, b)
        };
        let result: Result<(), Fault> = match self.batch {
            None => {
                let mut guard = m.data.lock().unwrap_or_else(|e| e.into_inner());
                (0..1)
                    .try_for_each(|k| kernel(&m.model, &mut guard, &self.state(k), outputs(k)).map_err(Fault::from))
                    .and_then(|()| check_range(0, 1))
            }
            Some(states) => py.detach(|| {
                const CHUNK: usize = 64;
                // one Data per rayon job (made by `init`, reused for all its chunks), not per chunk
                guard::install(|| {
                    (0..states.div_ceil(CHUNK)).into_par_iter().try_for_each_init(
                        || Scratch::new(&m.model),
                        |scratch, c| states_range(scratch, c * CHUNK, ((c + 1) * CHUNK).min(states)),
                    )
                })
                .unwrap_or_else(|e| Err(Fault::Py(e)))
            }),
        };
        match result {
            Ok(()) => Ok(arrays),
            Err(Fault::Core(e)) => Err(core_err(e)),
            Err(Fault::Py(e)) => Err(e),
            Err(Fault::NonFinite {
                state,
                output,
                index,
                value,
            }) => Err(self.non_finite(py, what.0, what.1[output], out_shape, state, index, value)),
        }
    }

    /// The error of a non-finite result of finite inputs (every input was checked by `gather`).
    #[allow(clippy::too_many_arguments)]
    fn non_finite(
        &self,
        py: Python<'_>,
        method: &str,
        quantity: &str,
        out_shape: &[usize],
        state: usize,
        index: usize,
        value: f64,
    ) -> PyErr {
        // the element as an index of the per-state result: tau[2], M[1, 3]
        let mut rest = index;
        let mut idx = vec![0; out_shape.len()];
        for (slot, d) in idx.iter_mut().zip(out_shape).rev() {
            *slot = rest % d.max(&1);
            rest /= d.max(&1);
        }
        let element = if idx.is_empty() {
            quantity.to_string()
        } else {
            format!(
                "{quantity}[{}]",
                idx.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(", ")
            )
        };
        let at = match self.batch {
            Some(_) => format!(" at state {state} of the batch"),
            None => String::new(),
        };
        let largest = self
            .state(state)
            .iter()
            .flat_map(|x| x.iter())
            .fold(0.0f64, |a, x| a.max(x.abs()));
        guard::non_finite_error(
            py,
            format!(
                "{method}: {element} is {value}{at}, although every input is finite (the largest input magnitude is {largest:.3e}): \
                 the computation overflowed float64; the inputs are outside the range this model can be evaluated in"
            ),
        )
    }
}

/// Computes states `[a, b)` of a batch at once: (model, scratch, their inputs, their output).
type LaneRange<'f> = dyn Fn(&Model, &mut Scratch, &[Input], &mut [f64]) -> Result<(), batch::StateError> + Sync + 'f;

/// Names of a call and of its result(s), for error messages: ("mass_matrix", "M").
type Output = (&'static str, &'static str);
type Outputs<const K: usize> = (&'static str, [&'static str; K]);

/// Why a state of a batch failed.
enum Fault {
    Core(CoreError),
    Py(PyErr),
    NonFinite {
        state: usize,
        output: usize,
        index: usize,
        value: f64,
    },
}

impl From<CoreError> for Fault {
    fn from(e: CoreError) -> Self {
        Fault::Core(e)
    }
}

/// Whether `x` holds a NaN or an infinity. Fast path: the numbers summed in 8 independent lanes
/// (one vectorised add per number, no branch); a NaN or inf makes its lane non-finite, and finite
/// numbers leave every lane finite unless a sum overflows, so only then are the numbers looked at
/// one by one (the exact test).
#[inline]
fn any_non_finite(x: &[f64]) -> bool {
    let mut lanes = [0.0f64; 8];
    let chunks = x.chunks_exact(8);
    let tail = chunks.remainder();
    for c in chunks {
        for (lane, v) in lanes.iter_mut().zip(c) {
            *lane += v;
        }
    }
    for (lane, v) in lanes.iter_mut().zip(tail) {
        *lane += v;
    }
    !lanes.iter().all(|l| l.is_finite()) && x.iter().any(|v| !v.is_finite())
}

/// Three arrays returned as a Python tuple.
type Arrays3<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
);

/// Where an output array's numbers start, shared by the threads of a batch, each writing its own
/// states' ranges (see `Batch::run_many`).
#[derive(Clone, Copy)]
struct OutputBase(*mut f64);
// SAFETY: only ever used to write disjoint ranges, one state per kernel call.
unsafe impl Send for OutputBase {}
unsafe impl Sync for OutputBase {}

/// The compiled model plus one cached `Data` for single-state calls.
#[pyclass(name = "Model", module = "kinedyn._core", frozen)]
struct PyModel {
    model: Model,
    data: Mutex<Data>,
}

fn vec_of(name: &str, a: &PyReadonlyArrayDyn<f64>, shape: &[usize]) -> PyResult<Vec<f64>> {
    if a.shape() != shape {
        return Err(reshape_error(name, shape, a.shape()));
    }
    Ok(a.as_array().iter().copied().collect())
}

fn reference(code: i64) -> PyResult<Reference> {
    match code {
        0 => Ok(Reference::World),
        1 => Ok(Reference::Local),
        2 => Ok(Reference::Spatial),
        _ => Err(PyValueError::new_err(format!(
            "reference code must be 0 (world), 1 (local) or 2 (spatial), got {code}"
        ))),
    }
}

impl PyModel {
    fn n(&self) -> usize {
        self.model.n
    }

    /// Every multi-DOF joint's block of q (all states of `q`, nq numbers each) is unit where it must
    /// be (a quaternion, or (cos, sin) of a planar joint) to 1e-6: the algorithms read it as a
    /// rotation, so any other number would give a silently wrong result.
    fn check_configurations(&self, q: &[f64]) -> PyResult<()> {
        let model = &self.model;
        if model.plain || model.nq == 0 {
            return Ok(());
        }
        for (k, state) in q.chunks(model.nq).enumerate() {
            for (i, c) in model.coordinates.iter().enumerate() {
                if let Coordinates::Head { block, at } = *c {
                    let (unit, what) = match block {
                        Block::FreeFlyer => (&state[at + 3..at + 7], "quaternion (qx, qy, qz, qw)"),
                        Block::Spherical => (&state[at..at + 4], "quaternion (qx, qy, qz, qw)"),
                        Block::Planar => (&state[at + 2..at + 4], "(cos, sin) pair"),
                    };
                    let norm = unit.iter().map(|x| x * x).sum::<f64>().sqrt();
                    if (norm - 1.0).abs() > 1e-6 {
                        let batch = if q.len() > model.nq {
                            format!(" of state {k}")
                        } else {
                            String::new()
                        };
                        return Err(PyValueError::new_err(format!(
                            "q[{}..{}]{batch}, the {what} of the {block:?} joint at body {i}, has norm {norm}, not 1 \
                             (to 1e-6): normalise it (robot.normalize(q))",
                            at + if block == Block::FreeFlyer {
                                3
                            } else if block == Block::Planar {
                                2
                            } else {
                                0
                            },
                            at + block.nq()
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    fn frame(&self, frame: i64) -> PyResult<usize> {
        let nf = self.model.frames.len();
        if frame < 0 || frame as usize >= nf {
            return Err(PyValueError::new_err(format!(
                "frame index {frame} out of range (the model has {nf} frames)"
            )));
        }
        Ok(frame as usize)
    }

    fn point(point: Option<PyReadonlyArrayDyn<f64>>) -> PyResult<Option<Vec3>> {
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
}

#[pymethods]
impl PyModel {
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (parent, kind, axis, offset, placement, inertia, armature, viscous, coulomb, gravity, frame_body, frame_placement, coulomb_negative=None, blocks=None))]
    fn new(
        parent: Vec<i64>,
        kind: Vec<i64>,
        axis: PyReadonlyArrayDyn<f64>,
        offset: Vec<f64>,
        placement: PyReadonlyArrayDyn<f64>,
        inertia: PyReadonlyArrayDyn<f64>,
        armature: Vec<f64>,
        viscous: Vec<f64>,
        coulomb: Vec<f64>,
        gravity: Vec<f64>,
        frame_body: Vec<i64>,
        frame_placement: PyReadonlyArrayDyn<f64>,
        coulomb_negative: Option<Vec<f64>>,
        blocks: Option<Vec<i64>>,
    ) -> PyResult<Self> {
        guarded("Model.__new__", || {
            let n = parent.len();
            let nf = frame_body.len();
            let axis = vec_of("axis", &axis, &[n, 3])?;
            let placement = vec_of("placement", &placement, &[n, 4, 4])?;
            let inertia = vec_of("inertia", &inertia, &[n, 10])?;
            let frame_placement = vec_of("frame_placement", &frame_placement, &[nf, 4, 4])?;
            if kind.len() != n {
                return Err(PyValueError::new_err(format!(
                    "kind has {} entries for {n} bodies",
                    kind.len()
                )));
            }
            if gravity.len() != 3 {
                return Err(PyValueError::new_err(format!(
                    "gravity must have 3 components, got {}",
                    gravity.len()
                )));
            }
            let body_index = |what: &str, k: usize, p: i64| -> PyResult<Option<usize>> {
                match p {
                    -1 => Ok(None),
                    p if p >= 0 && (p as usize) < n => Ok(Some(p as usize)),
                    p => Err(PyValueError::new_err(format!(
                        "{what} {k}: body index {p} is out of range (-1..{n})"
                    ))),
                }
            };
            let parent = parent
                .iter()
                .enumerate()
                .map(|(i, &p)| body_index("parent of body", i, p))
                .collect::<PyResult<Vec<_>>>()?;
            let joints = kind
                .iter()
                .enumerate()
                .map(|(i, &k)| {
                    let kind = match k {
                        0 => JointKind::Revolute,
                        1 => JointKind::Prismatic,
                        _ => return Err(PyValueError::new_err(format!("joint {i}: unknown kind code {k}"))),
                    };
                    Ok(Joint {
                        kind,
                        axis: Vec3::new(axis[3 * i], axis[3 * i + 1], axis[3 * i + 2]),
                    })
                })
                .collect::<PyResult<Vec<_>>>()?;
            let placements = placement.chunks(16).map(Transform::from_homogeneous).collect();
            let inertias = inertia.chunks(10).map(Inertia::from_parameters).collect();
            let frames = frame_body
                .iter()
                .enumerate()
                .map(|(k, &b)| {
                    Ok(Frame {
                        body: body_index("frame", k, b)?,
                        body_from_frame: Transform::from_homogeneous(&frame_placement[16 * k..16 * k + 16]),
                    })
                })
                .collect::<PyResult<Vec<_>>>()?;
            let mut model = Model::new(
                parent,
                joints,
                offset,
                placements,
                inertias,
                armature,
                viscous,
                coulomb,
                Vec3::new(gravity[0], gravity[1], gravity[2]),
                frames,
            )
            .map_err(core_err)?;
            if let Some(levels) = coulomb_negative {
                model = model.with_coulomb_negative(levels).map_err(core_err)?;
            }
            if let Some(codes) = blocks {
                // per body: 0 a 1-DOF joint, 1 / 2 / 3 the head of a free-flyer / spherical / planar
                // joint, -1 a further member of the multi-DOF joint before it
                if codes.len() != n {
                    return Err(PyValueError::new_err(format!(
                        "blocks has {} entries for {n} bodies",
                        codes.len()
                    )));
                }
                let mut at = 0;
                let mut coordinates = Vec::with_capacity(n);
                for (i, &code) in codes.iter().enumerate() {
                    let c = match code {
                        0 => Coordinates::Scalar { at },
                        1 => Coordinates::Head {
                            block: Block::FreeFlyer,
                            at,
                        },
                        2 => Coordinates::Head {
                            block: Block::Spherical,
                            at,
                        },
                        3 => Coordinates::Head {
                            block: Block::Planar,
                            at,
                        },
                        -1 => Coordinates::Member,
                        _ => return Err(PyValueError::new_err(format!("body {i}: unknown block code {code}"))),
                    };
                    at += match c {
                        Coordinates::Scalar { .. } => 1,
                        Coordinates::Head { block, .. } => block.nq(),
                        Coordinates::Member => 0,
                    };
                    coordinates.push(c);
                }
                model = model.with_coordinates(coordinates).map_err(core_err)?;
            }
            let data = Mutex::new(Data::new(&model));
            Ok(Self { model, data })
        })
    }

    #[getter(n)]
    fn get_n(&self) -> usize {
        self.model.n
    }

    /// Length of a configuration q.
    #[getter]
    fn nq(&self) -> usize {
        self.model.nq
    }

    #[getter]
    fn n_frames(&self) -> usize {
        self.model.frames.len()
    }

    /// Poses of the given frames: (k, 4, 4) or (N, k, 4, 4).
    fn frame_poses<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyArrayDyn<f64>>,
        frames: Bound<'py, PyArray1<i64>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.frame_poses", || {
            // SAFETY: read under the GIL with no Python code running, so nothing writes to it meanwhile
            let ids = unsafe { frames.as_array() }
                .iter()
                .map(|&f| self.frame(f))
                .collect::<PyResult<Vec<_>>>()?;
            let nq = self.model.nq;
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run_kernel(
                py,
                self,
                ("frame_poses", "pose"),
                &[ids.len(), 4, 4],
                None,
                kernels::FramePoses { frames: &ids },
            )
        })
    }

    /// Jacobian (6, n) or (N, 6, n) of a frame or a point fixed in it.
    #[pyo3(signature = (q, frame, reference, point=None))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyArrayDyn<f64>>,
        frame: i64,
        reference: i64,
        point: Option<PyReadonlyArrayDyn<f64>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.jacobian", || {
            let (f, r, p) = (self.frame(frame)?, self::reference(reference)?, Self::point(point)?);
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run_kernel(
                py,
                self,
                ("jacobian", "J"),
                &[6, n],
                None,
                kernels::Jacobian {
                    frame: f,
                    reference: r,
                    point: p,
                },
            )
        })
    }

    /// Kinematic Hessian dJ/dq (n, 6, n) or (N, n, 6, n): `H[i, r, j] = dJ[r, j]/dq_i`.
    #[pyo3(signature = (q, frame, reference, point=None))]
    fn jacobian_hessian<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyArrayDyn<f64>>,
        frame: i64,
        reference: i64,
        point: Option<PyReadonlyArrayDyn<f64>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.jacobian_hessian", || {
            let (f, r, p) = (self.frame(frame)?, self::reference(reference)?, Self::point(point)?);
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run(
                py,
                self,
                ("jacobian_hessian", "dJ/dq"),
                &[n, 6, n],
                |model, data, x, out| {
                    algorithms::frame_jacobian_hessian(model, data, x[0], f, r, p.as_ref(), out);
                    Ok(())
                },
            )
        })
    }

    /// Twist J qd (6,) or (N, 6).
    #[pyo3(signature = (q, qd, frame, reference, point=None))]
    fn frame_velocity<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyArrayDyn<f64>>,
        qd: Bound<'py, PyArrayDyn<f64>>,
        frame: i64,
        reference: i64,
        point: Option<PyReadonlyArrayDyn<f64>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.frame_velocity", || {
            let (f, r, p) = (self.frame(frame)?, self::reference(reference)?, Self::point(point)?);
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n])])?;
            batch.run(py, self, ("frame_velocity", "twist"), &[6], |model, data, x, out| {
                out.copy_from_slice(&algorithms::frame_velocity(model, data, x[0], x[1], f, r, p.as_ref()).to_array());
                Ok(())
            })
        })
    }

    /// Acceleration drift dJ/dt qd (6,) or (N, 6).
    #[pyo3(signature = (q, qd, frame, reference, point=None))]
    fn jdot_qd<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyArrayDyn<f64>>,
        qd: Bound<'py, PyArrayDyn<f64>>,
        frame: i64,
        reference: i64,
        point: Option<PyReadonlyArrayDyn<f64>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.jdot_qd", || {
            let (f, r, p) = (self.frame(frame)?, self::reference(reference)?, Self::point(point)?);
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n])])?;
            batch.run(py, self, ("jdot_qd", "dJ/dt qd"), &[6], |model, data, x, out| {
                out.copy_from_slice(&algorithms::jacobian_dot_qd(model, data, x[0], x[1], f, r, p.as_ref()).to_array());
                Ok(())
            })
        })
    }

    // ---- dynamics (issue 3): each method takes one state or a batch, like the kinematics above ----

    /// tau (n,) | (N, n): recursive Newton-Euler with gravity, friction, armature and f_ext.
    #[pyo3(signature = (q, qd, qdd, f_ext=None, out=None))]
    fn inverse_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
        qdd: Bound<'py, PyAny>,
        f_ext: Option<Bound<'py, PyAny>>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.inverse_dynamics", || {
            let f_ext = f_ext.map(|f| f64_array("f_ext", &f)).transpose()?;
            let q = f64_array("q", &q)?;
            let qd = f64_array("qd", &qd)?;
            let qdd = f64_array("qdd", &qdd)?;
            let (n, nq) = (self.n(), self.model.nq);
            let (s1, s6) = ([n], [n, 6]);
            let batch = match f_ext.as_ref() {
                Some(f) => Batch::gather(&[
                    ("q", &q, &[nq]),
                    ("qd", &qd, &s1),
                    ("qdd", &qdd, &s1),
                    ("f_ext", f, &s6),
                ])?,
                None => Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &s1), ("qdd", &qdd, &s1)])?,
            };
            batch.run_kernel(
                py,
                self,
                ("inverse_dynamics", "tau"),
                &[n],
                out,
                kernels::InverseDynamics,
            )
        })
    }

    /// M (n, n) | (N, n, n): composite-rigid-body algorithm, exactly symmetric.
    #[pyo3(signature = (q, out=None))]
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.mass_matrix", || {
            let q = f64_array("q", &q)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run_kernel(py, self, ("mass_matrix", "M"), &[n, n], out, kernels::MassMatrix)
        })
    }

    /// M^-1 (n, n) | (N, n, n).
    #[pyo3(signature = (q, out=None))]
    fn mass_matrix_inverse<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.mass_matrix_inverse", || {
            let q = f64_array("q", &q)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run_kernel(
                py,
                self,
                ("mass_matrix_inverse", "M^-1"),
                &[n, n],
                out,
                kernels::MassMatrixInverse,
            )
        })
    }

    /// qdd (n,) | (N, n): articulated-body algorithm; RuntimeError for a singular mass matrix.
    #[pyo3(signature = (q, qd, tau, f_ext=None, out=None))]
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
        tau: Bound<'py, PyAny>,
        f_ext: Option<Bound<'py, PyAny>>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.forward_dynamics", || {
            let f_ext = f_ext.map(|f| f64_array("f_ext", &f)).transpose()?;
            let q = f64_array("q", &q)?;
            let qd = f64_array("qd", &qd)?;
            let tau = f64_array("tau", &tau)?;
            let (n, nq) = (self.n(), self.model.nq);
            let (s1, s6) = ([n], [n, 6]);
            let batch = match f_ext.as_ref() {
                Some(f) => Batch::gather(&[
                    ("q", &q, &[nq]),
                    ("qd", &qd, &s1),
                    ("tau", &tau, &s1),
                    ("f_ext", f, &s6),
                ])?,
                None => Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &s1), ("tau", &tau, &s1)])?,
            };
            batch.run_kernel(
                py,
                self,
                ("forward_dynamics", "qdd"),
                &[n],
                out,
                kernels::ForwardDynamics,
            )
        })
    }

    /// (dtau/dq, dtau/dqd, M), each (n, n) | (N, n, n): analytical derivatives of the RNEA.
    #[pyo3(signature = (q, qd, qdd, f_ext=None))]
    fn inverse_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
        qdd: Bound<'py, PyAny>,
        f_ext: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Arrays3<'py>> {
        guarded("Model.inverse_dynamics_derivatives", || {
            let (q, qd, qdd) = (f64_array("q", &q)?, f64_array("qd", &qd)?, f64_array("qdd", &qdd)?);
            let f_ext = f_ext.map(|f| f64_array("f_ext", &f)).transpose()?;
            let (n, nq) = (self.n(), self.model.nq);
            let (s1, s6) = ([n], [n, 6]);
            let batch = match f_ext.as_ref() {
                Some(f) => Batch::gather(&[
                    ("q", &q, &[nq]),
                    ("qd", &qd, &s1),
                    ("qdd", &qdd, &s1),
                    ("f_ext", f, &s6),
                ])?,
                None => Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &s1), ("qdd", &qdd, &s1)])?,
            };
            let simd = Simd::detected();
            let lanes = |model: &Model, scratch: &mut Scratch, x: &[Input], out: &mut [f64]| {
                batch::run(model, scratch, &kernels::InverseDynamicsDerivatives, x, out, simd)
            };
            let [dq, dqd, m] = batch.run_many::<3, _>(
                py,
                self,
                ("inverse_dynamics_derivatives", ["dtau/dq", "dtau/dqd", "M"]),
                &[n, n],
                [None, None, None],
                Some(&lanes),
                |model, data, x, [dq, dqd, m]| {
                    algorithms::rnea_derivatives(model, data, x[0], x[1], x[2], optional(x, 3), dq, dqd, Some(m));
                    Ok(())
                },
            )?;
            Ok((dq, dqd, m))
        })
    }

    /// (dqdd/dq, dqdd/dqd, dqdd/dtau = M^-1), each (n, n) | (N, n, n): derivatives of the ABA.
    #[pyo3(signature = (q, qd, tau, f_ext=None))]
    fn forward_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
        tau: Bound<'py, PyAny>,
        f_ext: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Arrays3<'py>> {
        guarded("Model.forward_dynamics_derivatives", || {
            let (q, qd, tau) = (f64_array("q", &q)?, f64_array("qd", &qd)?, f64_array("tau", &tau)?);
            let f_ext = f_ext.map(|f| f64_array("f_ext", &f)).transpose()?;
            let (n, nq) = (self.n(), self.model.nq);
            let (s1, s6) = ([n], [n, 6]);
            let batch = match f_ext.as_ref() {
                Some(f) => Batch::gather(&[
                    ("q", &q, &[nq]),
                    ("qd", &qd, &s1),
                    ("tau", &tau, &s1),
                    ("f_ext", f, &s6),
                ])?,
                None => Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &s1), ("tau", &tau, &s1)])?,
            };
            let simd = Simd::detected();
            let lanes = |model: &Model, scratch: &mut Scratch, x: &[Input], out: &mut [f64]| {
                batch::run(model, scratch, &kernels::ForwardDynamicsDerivatives, x, out, simd)
            };
            let [dq, dqd, dtau] = batch.run_many::<3, _>(
                py,
                self,
                ("forward_dynamics_derivatives", ["dqdd/dq", "dqdd/dqd", "M^-1"]),
                &[n, n],
                [None, None, None],
                Some(&lanes),
                |model, data, x, [dq, dqd, dtau]| {
                    algorithms::aba_derivatives(model, data, x[0], x[1], x[2], optional(x, 3), dq, dqd, dtau)
                },
            )?;
            Ok((dq, dqd, dtau))
        })
    }

    /// C (n, n) | (N, n, n): the Christoffel-consistent Coriolis matrix.
    #[pyo3(signature = (q, qd, out=None))]
    fn coriolis_matrix<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.coriolis_matrix", || {
            let q = f64_array("q", &q)?;
            let qd = f64_array("qd", &qd)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n])])?;
            batch.run_kernel(py, self, ("coriolis_matrix", "C"), &[n, n], out, kernels::Coriolis)
        })
    }

    /// c[i, j, k] (n, n, n) | (N, n, n, n): Christoffel symbols of the first kind.
    fn christoffel<'py>(&self, py: Python<'py>, q: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.christoffel", || {
            let q = f64_array("q", &q)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run_kernel(py, self, ("christoffel", "c"), &[n, n, n], None, kernels::Christoffel)
        })
    }

    /// g (n,) | (N, n).
    #[pyo3(signature = (q, out=None))]
    fn gravity_torque<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.gravity_torque", || {
            let q = f64_array("q", &q)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run_kernel(py, self, ("gravity_torque", "g"), &[n], out, kernels::Gravity)
        })
    }

    /// C qd + g (n,) | (N, n), without friction.
    #[pyo3(signature = (q, qd, out=None))]
    fn bias_torque<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.bias_torque", || {
            let q = f64_array("q", &q)?;
            let qd = f64_array("qd", &qd)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n])])?;
            batch.run_kernel(py, self, ("bias_torque", "bias"), &[n], out, kernels::Bias)
        })
    }

    /// K () | (N,).
    fn kinetic_energy<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.kinetic_energy", || {
            let q = f64_array("q", &q)?;
            let qd = f64_array("qd", &qd)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n])])?;
            batch.run_kernel(py, self, ("kinetic_energy", "K"), &[], None, kernels::KineticEnergy)
        })
    }

    /// P () | (N,).
    fn potential_energy<'py>(&self, py: Python<'py>, q: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.potential_energy", || {
            let q = f64_array("q", &q)?;
            let nq = self.model.nq;
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run_kernel(py, self, ("potential_energy", "P"), &[], None, kernels::PotentialEnergy)
        })
    }

    /// Y (n, 10 n) | (N, n, 10 n).
    fn regressor<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
        qdd: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.regressor", || {
            let q = f64_array("q", &q)?;
            let qd = f64_array("qd", &qd)?;
            let qdd = f64_array("qdd", &qdd)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n]), ("qdd", &qdd, &[n])])?;
            batch.run_kernel(py, self, ("regressor", "Y"), &[n, 10 * n], None, kernels::Regressor)
        })
    }

    /// Centre of mass (3,) | (N, 3) in base coordinates.
    fn center_of_mass<'py>(&self, py: Python<'py>, q: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.center_of_mass", || {
            let q = f64_array("q", &q)?;
            let nq = self.model.nq;
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run(py, self, ("center_of_mass", "com"), &[3], |model, data, x, out| {
                out.copy_from_slice(algorithms::center_of_mass(model, data, x[0])?.as_slice());
                Ok(())
            })
        })
    }

    /// Centroidal momentum matrix A_G (6, n) | (N, 6, n): [linear; angular about the centre of mass], base axes.
    fn centroidal_momentum_matrix<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.centroidal_momentum_matrix", || {
            let q = f64_array("q", &q)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq])])?;
            batch.run(
                py,
                self,
                ("centroidal_momentum_matrix", "A_G"),
                &[6, n],
                |model, data, x, out| {
                    algorithms::centroidal_momentum_matrix(model, data, x[0], out)?;
                    Ok(())
                },
            )
        })
    }

    /// Spatial momentum [p; L about the base origin] (6,) | (N, 6), base axes.
    fn momentum<'py>(
        &self,
        py: Python<'py>,
        q: Bound<'py, PyAny>,
        qd: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        guarded("Model.momentum", || {
            let q = f64_array("q", &q)?;
            let qd = f64_array("qd", &qd)?;
            let (n, nq) = (self.n(), self.model.nq);
            let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n])])?;
            batch.run(py, self, ("momentum", "h"), &[6], |model, data, x, out| {
                out.copy_from_slice(&algorithms::spatial_momentum(model, data, x[0], x[1]).to_array());
                Ok(())
            })
        })
    }
}

/// How batches run on this machine: (kind, states per block); the kind is "avx512", "avx2",
/// "portable" or "off", chosen from the CPU once per process, or by the environment variable
/// KINEDYN_SIMD when the CPU supports the kind it names.
#[pyfunction]
fn simd() -> (&'static str, usize) {
    let s = Simd::detected();
    (s.name(), s.lanes())
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()?;
    m.add_function(wrap_pyfunction!(simd, m)?)?;
    guard::register(m)?;
    ik::register(m)?;
    simulate::register(m)?;
    Ok(())
}
