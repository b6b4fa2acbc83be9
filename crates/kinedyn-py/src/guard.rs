//! What keeps Rust's failure modes out of Python (issue 11, sections 6-8):
//!
//! - [`guarded`]: every binding runs its body through it, so a panic (a bug) reaches Python as a
//!   `RuntimeError` naming the binding and the panic message, not as pyo3's `PanicException` (a
//!   `BaseException` that `except Exception` does not catch).
//! - [`empty`] / [`zeros`] / [`try_vec`]: result arrays and buffers whose size follows from the
//!   input are allocated fallibly, with the size checked first: a result that cannot exist raises
//!   `MemoryError` naming its bytes and the method that asked, instead of panicking (rust-numpy's
//!   constructors panic on a NULL from NumPy) or aborting (Rust's allocator aborts on failure).
//! - [`install`]: the thread pool of batch calls, built lazily per process id, so that a child made
//!   by `fork` (which inherits the pool's bookkeeping but none of its threads) builds its own pool
//!   instead of queuing work for threads that do not exist and blocking forever.
//! - [`interruptible`]: long work without the GIL runs on a helper thread while the caller checks
//!   Python's signals, so Ctrl-C (KeyboardInterrupt) stops a long native run within a poll interval
//!   instead of when it ends; [`detached`] chooses it for a batch long enough to need it.
//! - [`non_finite_error`]: `kinedyn.NonFiniteResultError` (a `FloatingPointError` and a
//!   `ValueError`), raised when finite inputs give a non-finite result.

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::ptr;
use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};
use std::time::Duration;

use numpy::npyffi::{self, npy_intp, PY_ARRAY_API};
use numpy::{Element, PyArrayDescrMethods, PyArrayDyn};
use pyo3::exceptions::{PyMemoryError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

// ------------------------------------------------------------------ panic guard

/// The text of a panic payload (`panic!("...")` gives a `&str` or a `String`).
fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(a panic without a message)".to_string()
    }
}

/// Run the body of binding `name`; a panic anywhere inside it (this thread, or a worker of a batch:
/// rayon hands a worker's panic back to the caller) becomes a `RuntimeError` with context.
pub fn guarded<T>(name: &str, body: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(result) => result,
        Err(payload) => Err(PyRuntimeError::new_err(format!(
            "kinedyn internal error in {name}: {} (a bug in kinedyn's native core: please report it with the call that caused it)",
            panic_message(payload.as_ref())
        ))),
    }
}

/// `kinedyn._core._debug_panic(message)`: panics inside a guarded binding. TEST-ONLY: it exists so
/// that the test suite can check that a panic reaches Python as a RuntimeError.
#[pyfunction]
#[pyo3(signature = (message="deliberate panic for the test suite", in_worker=false))]
pub fn _debug_panic(py: Python<'_>, message: &str, in_worker: bool) -> PyResult<()> {
    guarded("_debug_panic", || {
        if in_worker {
            // the panic happens on a worker thread of the batch pool, without the GIL
            py.detach(|| install(|| rayon::join(|| (), || panic!("{message}"))))?;
        }
        panic!("{message}")
    })
}

// ------------------------------------------------------------------ sizes and allocation

/// A shape as Python prints it: `(5,)`, `(2, 3)`.
pub fn shape_text(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// Bytes as a person reads them: `192000000000048 bytes (174.6 TiB)`.
fn bytes_text(bytes: u128) -> String {
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let (mut x, mut u) = (bytes as f64, 0);
    while x >= 1024.0 && u + 1 < units.len() {
        x /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{bytes} bytes ({x:.1} {})", units[u])
    }
}

/// Check that `count` float64 arrays of `shape` can exist at all (their bytes fit in `isize`,
/// the most any allocation may hold); `what` names the caller for the message.
pub fn check_size(what: &str, count: usize, shape: &[usize]) -> PyResult<()> {
    // every call asks: the common answer in machine words first (no 128-bit products)
    let small = shape
        .iter()
        .try_fold(8usize.saturating_mul(count), |b, &d| b.checked_mul(d));
    if small.is_some_and(|b| b <= isize::MAX as usize) {
        return Ok(());
    }
    let elements = shape.iter().map(|&d| d as u128).product::<u128>();
    let bytes = elements * 8 * count as u128;
    if bytes > isize::MAX as u128 {
        let arrays = if count == 1 {
            "an array".to_string()
        } else {
            format!("{count} arrays")
        };
        return Err(PyMemoryError::new_err(format!(
            "{what}: the result needs {arrays} of shape {} (float64), {} in all, more than any allocation can hold",
            shape_text(shape),
            bytes_text(bytes)
        )));
    }
    Ok(())
}

/// The MemoryError of a failed allocation, naming the caller and the bytes.
fn out_of_memory(py: Python<'_>, what: &str, shape: &[usize], detail: Option<PyErr>) -> PyErr {
    let bytes = shape.iter().map(|&d| d as u128).product::<u128>() * 8;
    let detail = detail.map(|e| format!(" ({})", e.value(py))).unwrap_or_default();
    PyMemoryError::new_err(format!(
        "{what}: cannot allocate the result of shape {} (float64, {}){detail}",
        shape_text(shape),
        bytes_text(bytes)
    ))
}

/// A fresh C-ordered array (float64 for results; the size check counts 8 bytes per element, an
/// upper bound for bool and int64 too), uninitialised (`zeroed = false`) or zeros; MemoryError naming
/// `what` and the size when it cannot be had (rust-numpy's `PyArray::new` / `zeros` panic then).
fn allocate<'py, T: Element>(
    py: Python<'py>,
    what: &str,
    shape: &[usize],
    zeroed: bool,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    check_size(what, 1, shape)?;
    // the dimensions on the stack: a per-call Vec was a malloc and a free on every single call
    const MAX_DIMS: usize = 32; // NumPy 1.x's NPY_MAXDIMS; kinedyn's results have at most 5
    if shape.len() > MAX_DIMS {
        return Err(PyRuntimeError::new_err(format!(
            "{what}: a result of {} dimensions (NumPy allows {MAX_DIMS})",
            shape.len()
        )));
    }
    let mut dims: [npy_intp; MAX_DIMS] = [0; MAX_DIMS];
    for (d, &s) in dims.iter_mut().zip(shape) {
        *d = s as npy_intp;
    }
    let ndim = shape.len() as i32;
    // SAFETY: the NumPy C API with a valid descriptor (its reference is stolen by the call) and
    // `ndim` dimensions; a NULL result leaves a Python error set, fetched below.
    unsafe {
        let descr = T::get_dtype(py).into_dtype_ptr();
        let ptr = if zeroed {
            PY_ARRAY_API.PyArray_Zeros(py, ndim, dims.as_mut_ptr(), descr, 0)
        } else {
            PY_ARRAY_API.PyArray_NewFromDescr(
                py,
                PY_ARRAY_API.get_type_object(py, npyffi::NpyTypes::PyArray_Type),
                descr,
                ndim,
                dims.as_mut_ptr(),
                ptr::null_mut(),
                ptr::null_mut(),
                0,
                ptr::null_mut(),
            )
        };
        if ptr.is_null() {
            return Err(out_of_memory(py, what, shape, PyErr::take(py)));
        }
        Ok(Bound::from_owned_ptr(py, ptr).cast_into_unchecked())
    }
}

/// An uninitialised array of `shape` (see [`allocate`]).
pub fn empty<'py, T: Element>(py: Python<'py>, what: &str, shape: &[usize]) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    allocate(py, what, shape, false)
}

/// An array of zeros (false) of `shape` (see [`allocate`]).
pub fn zeros<'py, T: Element>(py: Python<'py>, what: &str, shape: &[usize]) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    allocate(py, what, shape, true)
}

/// An empty Vec with room for `len` items, or a MemoryError naming `what` (`Vec::with_capacity`
/// aborts the process when the allocator says no, e.g. under `ulimit -v`).
pub fn try_vec<T>(what: &str, len: usize) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        PyMemoryError::new_err(format!(
            "{what}: cannot allocate a working buffer of {}",
            bytes_text(len as u128 * std::mem::size_of::<T>() as u128)
        ))
    })?;
    Ok(v)
}

/// `slice` copied into a fallibly allocated Vec.
pub fn try_copy(what: &str, slice: &[f64]) -> PyResult<Vec<f64>> {
    let mut v = try_vec(what, slice.len())?;
    v.extend_from_slice(slice);
    Ok(v)
}

// ------------------------------------------------------------------ a fork-safe thread pool

/// The batch pool and the process that built it. Leaked on purpose: in a forked child the old
/// pool's threads do not exist, and dropping it would wait for them.
struct Pool {
    pid: u32,
    pool: rayon::ThreadPool,
}

static POOL: AtomicPtr<Pool> = AtomicPtr::new(ptr::null_mut());

/// The pool of this process, built on first use (and again in a forked child).
fn pool() -> PyResult<&'static rayon::ThreadPool> {
    let pid = std::process::id();
    loop {
        let current = POOL.load(Ordering::Acquire);
        // SAFETY: pools are leaked, never freed, so a non-null pointer stays valid
        if let Some(p) = unsafe { current.as_ref() } {
            if p.pid == pid {
                return Ok(&p.pool);
            }
        }
        let built = rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("kinedyn-batch-{i}"))
            .build()
            .map_err(|e| PyRuntimeError::new_err(format!("kinedyn: cannot start the threads of a batch call: {e}")))?;
        let fresh = Box::into_raw(Box::new(Pool { pid, pool: built }));
        match POOL.compare_exchange(current, fresh, Ordering::AcqRel, Ordering::Acquire) {
            // the previous pool (if any) belongs to the parent process: leaked, see `Pool`
            Ok(_) => return Ok(unsafe { &(*fresh).pool }),
            // another thread of this process installed one first: use it, drop ours
            Err(_) => drop(unsafe { Box::from_raw(fresh) }),
        }
    }
}

/// Run `work` (which uses rayon's parallel iterators) in this process's pool. Every parallel
/// batch of the glue goes through here, never through rayon's global pool (which cannot be rebuilt
/// after a fork).
pub fn install<R: Send>(work: impl FnOnce() -> R + Send) -> PyResult<R> {
    Ok(pool()?.install(work))
}

// ------------------------------------------------------------------ interrupts

/// How often the caller of [`interruptible`] work checks Python's signals.
const SIGNAL_POLL: Duration = Duration::from_millis(20);

/// Run `work` without the GIL and stop it on a signal. Python runs signal handlers only in the main
/// thread and only while it holds the GIL (Python docs, `signal`: "Python signal handlers are always
/// executed in the main Python thread"), so a long native call would see Ctrl-C only when it ends.
/// Here `work` runs on a scoped helper thread and polls the cancellation flag it is given, while the
/// calling thread checks Python's signals every [`SIGNAL_POLL`]: when a handler raises (Ctrl-C's
/// `KeyboardInterrupt`), the flag is set, the work stops at its next poll, and that exception is
/// returned. A panic of `work` is resumed on the calling thread (for [`guarded`]).
pub fn interruptible<R: Send>(py: Python<'_>, work: impl FnOnce(&AtomicBool) -> R + Send) -> PyResult<R> {
    let cancel = AtomicBool::new(false);
    let caller = std::thread::current();
    let (joined, raised) = py.detach(|| {
        std::thread::scope(|scope| {
            let helper = scope.spawn(|| {
                let r = work(&cancel);
                caller.unpark(); // the caller need not wait out its poll interval
                r
            });
            let mut raised = None;
            while !helper.is_finished() {
                std::thread::park_timeout(SIGNAL_POLL);
                if raised.is_none() && !helper.is_finished() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        cancel.store(true, Ordering::Relaxed);
                        raised = Some(e);
                    }
                }
            }
            (helper.join(), raised)
        })
    });
    let result = joined.unwrap_or_else(|payload| std::panic::resume_unwind(payload));
    match raised {
        Some(e) => Err(e),
        None => Ok(result),
    }
}

/// Run batch `work` without the GIL: interruptibly ([`interruptible`]) when `long`, else on the
/// calling thread (the helper thread costs tens of microseconds, more than a short batch takes).
/// `work` is given the cancellation flag to poll between its pieces (see [`cancelled`]), or None.
pub fn detached<R: Send>(
    py: Python<'_>,
    long: bool,
    work: impl FnOnce(Option<&AtomicBool>) -> R + Send,
) -> PyResult<R> {
    if long {
        interruptible(py, |cancel| work(Some(cancel)))
    } else {
        Ok(py.detach(|| work(None)))
    }
}

/// Whether the flag of [`detached`] work is set: stop, the caller raises the signal's exception.
#[inline]
pub fn cancelled(flag: Option<&AtomicBool>) -> bool {
    flag.is_some_and(|f| f.load(Ordering::Relaxed))
}

// ------------------------------------------------------------------ non-finite results

/// Whether batch results are scanned for NaN/inf (on unless a benchmark turns it off).
pub static CHECK_FINITE: AtomicBool = AtomicBool::new(true);

/// `kinedyn._core._set_check_finite(on)`: BENCHMARK-ONLY switch of the output scan (to measure
/// its cost); returns the previous setting.
#[pyfunction]
pub fn _set_check_finite(on: bool) -> bool {
    CHECK_FINITE.swap(on, Ordering::Relaxed)
}

static NON_FINITE: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// `NonFiniteResultError(FloatingPointError, ValueError)`, made once.
fn non_finite_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    NON_FINITE
        .get_or_try_init(py, || {
            let builtins = py.import("builtins")?;
            let bases = PyTuple::new(
                py,
                [builtins.getattr("FloatingPointError")?, builtins.getattr("ValueError")?],
            )?;
            let namespace = PyDict::new(py);
            namespace.set_item("__module__", "kinedyn")?;
            namespace.set_item(
                "__doc__",
                "Finite inputs gave a non-finite result (NaN or inf): the numbers overflowed float64. \
                 A FloatingPointError and a ValueError (the inputs are outside what the model can represent).",
            )?;
            let ty = py
                .get_type::<PyType>()
                .call1(("NonFiniteResultError", bases, namespace))?;
            Ok::<_, PyErr>(ty.cast_into::<PyType>()?.unbind())
        })
        .map(|t| t.bind(py))
}

/// The error for a non-finite result.
pub fn non_finite_error(py: Python<'_>, message: String) -> PyErr {
    match non_finite_type(py) {
        Ok(ty) => PyErr::from_type(ty.clone(), message),
        Err(e) => e,
    }
}

/// Add the guard's Python-facing pieces to `kinedyn._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("NonFiniteResultError", non_finite_type(m.py())?)?;
    m.add_function(wrap_pyfunction!(_debug_panic, m)?)?;
    m.add_function(wrap_pyfunction!(_set_check_finite, m)?)?;
    Ok(())
}
