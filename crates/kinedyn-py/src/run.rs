//! The batch runner: one state with the cached `Data` (GIL kept) or a batch in parallel chunks
//! with the GIL released, writing into fresh or caller-given (`out=`) NumPy arrays, and the faults
//! of a state (a core error, a non-finite result of finite inputs) turned into Python errors.

use std::borrow::Cow;
use std::sync::atomic::Ordering;

use kinedyn_core::batch::{self, kernels, Input, Kernel, Scratch, Simd};
use kinedyn_core::{Data, Error as CoreError, Model};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::conv::{f64_array, Batch, MAX_INPUTS};
use crate::guard::{self, shape_text};
use crate::model::PyModel;

pyo3::create_exception!(
    kinedyn._core,
    SingularMassMatrixError,
    PyRuntimeError,
    "The core's singular mass matrix: attributes `joint` (the degree of freedom whose pivot failed), \
     `overflow` (numbers too large for float64 rather than a physically singular M) and `message`."
);

/// A core error as a Python exception: `SingularMassMatrixError` (a RuntimeError) carrying the
/// joint, else a ValueError.
pub(crate) fn core_err(e: CoreError) -> PyErr {
    match e {
        CoreError::SingularMassMatrix {
            joint,
            overflow,
            ref message,
        } => Python::attach(|py| {
            let err = SingularMassMatrixError::new_err(e.to_string());
            let value = err.value(py);
            let set = value
                .setattr("joint", joint)
                .and_then(|()| value.setattr("overflow", overflow))
                .and_then(|()| value.setattr("message", message.as_str()));
            match set {
                Ok(()) => err,
                Err(failed) => failed,
            }
        }),
        _ => PyValueError::new_err(e.to_string()),
    }
}

impl PyModel {
    /// Poses of the frames `ids` at `q` (any array NumPy takes) as `shape` per state (the core's
    /// `FramePoses`); `name` is the method's, for the errors.
    pub(crate) fn poses<'py>(
        &self,
        py: Python<'py>,
        name: &'static str,
        q: &Bound<'py, PyAny>,
        ids: &[usize],
        shape: &[usize],
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let q = f64_array("q", q)?;
        let batch = Batch::gather(&[("q", &q, &[self.model.nq])])?;
        batch.run_kernel(
            py,
            self,
            (name, "pose"),
            shape,
            None,
            kernels::FramePoses { frames: ids },
        )
    }
}

/// Computes states `[a, b)` of a batch at once: (model, scratch, their inputs, their output).
pub(crate) type LaneRange<'f> =
    dyn Fn(&Model, &mut Scratch, &[Input], &mut [f64]) -> Result<(), batch::StateError> + Sync + 'f;

/// Names of a call and of its result(s), for error messages: ("mass_matrix", "M").
pub(crate) type Output = (&'static str, &'static str);
pub(crate) type Outputs<const K: usize> = (&'static str, [&'static str; K]);

/// Why a state of a batch failed.
enum Fault {
    Core(CoreError),
    Py(PyErr),
    /// The cancellation flag was set (a signal handler raised): the remaining states are skipped.
    Cancelled,
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

/// A batch whose states times numbers per state (degrees of freedom plus result numbers) reach this
/// runs interruptibly (`guard::detached`): about 5 ms of work or more (UR5 inverse dynamics: ~22k
/// states), where the helper thread's tens of microseconds are lost in the noise.
const INTERRUPTIBLE_WORK: usize = 1 << 18;

/// Three arrays returned as a Python tuple.
pub(crate) type Arrays3<'py> = (
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

impl<'a> Batch<'a> {
    /// Run `kernel(model, data, inputs_of_state, out_of_state)` on every state, writing straight
    /// into a fresh NumPy array; `kernel` must write every element of `out_of_state` (it is not
    /// zeroed first). A single state runs with the cached `Data`, keeping the GIL (the
    /// call is shorter than releasing it); a batch runs with the GIL released, in parallel
    /// chunks of 64 states, each rayon job reusing one `Data` over its chunks; a long batch stops
    /// between chunks on Ctrl-C (KeyboardInterrupt, the `out=` array partly written).
    ///
    /// `what` names the call and its result (`Output`) for the errors: a result that cannot be
    /// allocated (MemoryError) and a non-finite number in a result of finite inputs
    /// (`NonFiniteResultError`: the outputs of each chunk of states are scanned right after its
    /// kernels wrote them, while they are in cache).
    pub(crate) fn run<'py, F>(
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
    pub(crate) fn run_out<'py, F>(
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
    pub(crate) fn run_kernel<'py, Kn: Kernel>(
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

    /// `run_kernel` for a kernel of one number per state: a single state's result as a Python
    /// float, computed into a stack slot (no 0-d array to allocate, read and free: the energies'
    /// per-call cost, issue 30). A failing state (a core error, a non-finite result) is run again
    /// by `run_kernel`, which raises its error with the batch path's messages.
    pub(crate) fn run_scalar<'py, Kn: Kernel>(
        &self,
        py: Python<'py>,
        m: &PyModel,
        what: Output,
        kernel: Kn,
    ) -> PyResult<Bound<'py, PyAny>> {
        if self.batch.is_none() {
            m.check_configurations(&self.values[0])?;
            let mut value = [0.0];
            let done = {
                let mut data = m.data.lock().unwrap_or_else(|e| e.into_inner());
                kernel.run(&m.model, &mut data, &self.state(0), &mut value)
            };
            if done.is_ok() && value[0].is_finite() {
                return Ok(pyo3::types::PyFloat::new(py, value[0]).into_any());
            }
        }
        self.run_kernel(py, m, what, &[], None, kernel).map(Bound::into_any)
    }

    /// `out` as the destination of this call's result (see `run_out`), or a clear error.
    pub(crate) fn checked_out<'py>(
        &self,
        out: Bound<'py, PyAny>,
        out_shape: &[usize],
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
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
    pub(crate) fn run_many<'py, const K: usize, F>(
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
            Some(states) => {
                const CHUNK: usize = 64;
                // long batches stop on Ctrl-C: every chunk first looks at the flag
                let long = states.saturating_mul(m.model.n + per_state) >= INTERRUPTIBLE_WORK;
                guard::detached(py, long, |cancel| {
                    // one Data per rayon job (made by `init`, reused for all its chunks), not per chunk
                    guard::install(|| {
                        (0..states.div_ceil(CHUNK)).into_par_iter().try_for_each_init(
                            || Scratch::new(&m.model),
                            |scratch, c| {
                                if guard::cancelled(cancel) {
                                    return Err(Fault::Cancelled);
                                }
                                states_range(scratch, c * CHUNK, ((c + 1) * CHUNK).min(states))
                            },
                        )
                    })
                    .unwrap_or_else(|e| Err(Fault::Py(e)))
                })
                .unwrap_or_else(|raised| Err(Fault::Py(raised)))
            }
        };
        match result {
            Ok(()) => Ok(arrays),
            Err(Fault::Core(e)) => Err(core_err(e)),
            Err(Fault::Py(e)) => Err(e),
            // (`detached` returns the signal's own exception instead; this is its fallback)
            Err(Fault::Cancelled) => Err(PyKeyboardInterrupt::new_err("interrupted")),
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
