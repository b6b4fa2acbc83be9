//! Simulation glue: whole trajectories (one state or a batch) integrated by
//! `kinedyn_core::sim`, with the torque as samples (no GIL, batches in parallel) or
//! from a Python callable evaluated by the core's loop (GIL held while it runs).
//!
//! Both return `(q, qd, qdd, tau, steps, failures)`: arrays `(samples, n)` or `(N, samples, n)`,
//! the number of steps completed per trajectory, and per trajectory `None` or a dict saying when and
//! where it stopped (`step`, `t`, `joint`, `kind`, `value`, `message`).

use std::cell::RefCell;

use kinedyn_core::sim::{
    self, Failure, FailureKind, Limits, Method, Outcome, Record, Sampled, Settings, TorqueFn, WithWrenches,
};
use kinedyn_core::Data;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use rayon::prelude::*;

use crate::conv::{constant_wrenches, wrenches_per_body};
use crate::guard::{self, guarded};
use crate::{core_err, PyModel};

fn method(name: &str) -> PyResult<Method> {
    match name {
        "rk4" => Ok(Method::Rk4),
        "semi_implicit" | "semi_implicit_euler" | "symplectic_euler" => Ok(Method::SemiImplicitEuler),
        "euler" => Ok(Method::Euler),
        "implicit" | "implicit_euler" => Ok(Method::Implicit),
        _ => Err(PyValueError::new_err(format!(
            "unknown fixed-step method '{name}' (rk4, semi_implicit, euler, implicit)"
        ))),
    }
}

/// Joint limits from `lower`, `upper` ((n,) each, or both None): checked, flattened.
fn limits(
    n: usize,
    lower: Option<&PyReadonlyArrayDyn<f64>>,
    upper: Option<&PyReadonlyArrayDyn<f64>>,
) -> PyResult<Option<(Vec<f64>, Vec<f64>)>> {
    match (lower, upper) {
        (None, None) => Ok(None),
        (Some(lo), Some(hi)) => {
            let (lo, hi): (Vec<f64>, Vec<f64>) = (
                lo.as_array().iter().copied().collect(),
                hi.as_array().iter().copied().collect(),
            );
            if lo.len() != n || hi.len() != n {
                return Err(PyValueError::new_err(format!(
                    "lower and upper limits need {n} values each, got {} and {}",
                    lo.len(),
                    hi.len()
                )));
            }
            if let Some(j) = (0..n).find(|&j| lo[j].is_nan() || hi[j].is_nan() || lo[j] > hi[j]) {
                return Err(PyValueError::new_err(format!(
                    "joint {j} has limits [{}, {}]: lower must not exceed upper",
                    lo[j], hi[j]
                )));
            }
            Ok(Some((lo, hi)))
        }
        _ => Err(PyValueError::new_err(
            "give both lower and upper joint limits, or neither",
        )),
    }
}

fn flat(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<Vec<f64>> {
    let view = a.as_array();
    let mut v = guard::try_vec(&format!("simulate: copying {name}"), view.len())?;
    v.extend(view.iter().copied());
    if let Some(k) = v.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{name} contains a non-finite value (NaN or inf) at flat index {k}"
        )));
    }
    Ok(v)
}

fn failure_dict<'py>(py: Python<'py>, f: &Failure) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("step", f.step)?;
    d.set_item("t", f.t)?;
    d.set_item("joint", f.joint)?;
    let (kind, value, message) = match &f.kind {
        FailureKind::NonFinite => ("non_finite", None, String::new()),
        FailureKind::Diverged(v) => ("diverged", Some(*v), String::new()),
        FailureKind::Torque(v) => ("torque", Some(*v), String::new()),
        FailureKind::Source(m) => ("source", None, m.clone()),
        FailureKind::Singular(m) => ("singular", None, m.clone()),
        FailureKind::Cancelled => ("cancelled", None, String::new()),
    };
    d.set_item("kind", kind)?;
    d.set_item("value", value)?;
    d.set_item("message", message)?;
    Ok(d)
}

/// Fresh output arrays `(batch?, samples, n)` x 4 (q, qd, qdd, tau), their total size checked
/// first: a MemoryError naming the bytes when they cannot be had (e.g. a tiny dt over a long span).
fn outputs<'py>(
    py: Python<'py>,
    batch: Option<usize>,
    samples: usize,
    n: usize,
    nq: usize,
) -> PyResult<[Bound<'py, PyArrayDyn<f64>>; 4]> {
    let shape_of = |w: usize| -> Vec<usize> {
        match batch {
            Some(b) => vec![b, samples, w],
            None => vec![samples, w],
        }
    };
    let (shape, shape_q) = (shape_of(n), shape_of(nq));
    const WHAT: &str = "simulate (the recorded q, qd, qdd and tau)";
    guard::check_size(WHAT, 4, &shape_of(n.max(nq)))?;
    Ok([
        guard::zeros(py, WHAT, &shape_q)?,
        guard::zeros(py, WHAT, &shape)?,
        guard::zeros(py, WHAT, &shape)?,
        guard::zeros(py, WHAT, &shape)?,
    ])
}

fn result<'py>(
    py: Python<'py>,
    arrays: [Bound<'py, PyArrayDyn<f64>>; 4],
    outcomes: &[Outcome],
) -> PyResult<Bound<'py, PyTuple>> {
    let steps = PyArray1::from_iter(py, outcomes.iter().map(|o| o.steps as i64));
    let failures = PyList::empty(py);
    for o in outcomes {
        match &o.failure {
            Some(f) => failures.append(failure_dict(py, f)?)?,
            None => failures.append(py.None())?,
        }
    }
    let [q, qd, qdd, tau] = arrays;
    PyTuple::new(
        py,
        [
            q.into_any(),
            qd.into_any(),
            qdd.into_any(),
            tau.into_any(),
            steps.into_any(),
            failures.into_any(),
        ],
    )
}

/// Check `q0` ((nq,) or (N, nq)) and `qd0` ((n,) or (N, n), the same batch), and the unit blocks of
/// q0's multi-DOF joints: (batch, q0, qd0 flattened).
fn initial_states(
    m: &PyModel,
    q0: &PyReadonlyArrayDyn<f64>,
    qd0: &PyReadonlyArrayDyn<f64>,
) -> PyResult<(Option<usize>, Vec<f64>, Vec<f64>)> {
    let (n, nq) = (m.model.n, m.model.nq);
    let batch = match q0.shape() {
        [w] if *w == nq => None,
        [b, w] if *w == nq => Some(*b),
        s => {
            return Err(PyValueError::new_err(format!(
                "q0 must have shape ({nq},) or a batch (N, {nq}), got {s:?}"
            )))
        }
    };
    let expected: Vec<usize> = batch.into_iter().chain([n]).collect();
    if qd0.shape() != expected.as_slice() {
        return Err(PyValueError::new_err(format!(
            "qd0 has shape {:?}, q0 has shape {:?}: qd0 must have shape {expected:?}",
            qd0.shape(),
            q0.shape()
        )));
    }
    let q0 = flat("q0", q0)?;
    m.check_configurations(&q0)?;
    Ok((batch, q0, flat("qd0", qd0)?))
}

/// Runs of at least this many steps (all trajectories of a batch together) take milliseconds or
/// more and run interruptibly ([`guard::interruptible`]: a helper thread, a few tens of
/// microseconds); shorter ones run on the calling thread.
const INTERRUPTIBLE_STEPS: usize = 20_000;

/// Integrate from `q0, qd0` ((n,) or a batch (N, n)) over `steps` steps of `dt`, the torque given by
/// samples `tau`: None (zero), `(S, n)` shared by every trajectory or `(N, S, n)` one per trajectory;
/// S = 1 is a constant, else samples at `t0 + k dt` held over each step (`linear=False`, S >= steps)
/// or interpolated (`linear=True`, S >= steps + 1). A batch runs in parallel without the GIL.
/// `f_ext`: constant external wrenches (links, 6), one per link (as `Model.inverse_dynamics`), or None.
#[pyfunction]
#[pyo3(signature = (model, method_name, q0, qd0, t0, dt, steps, tau=None, linear=false, record_every=1, max_speed=1e6, lower=None, upper=None, f_ext=None))]
#[allow(clippy::too_many_arguments)]
pub fn integrate_fixed<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyModel>,
    method_name: &str,
    q0: PyReadonlyArrayDyn<'py, f64>,
    qd0: PyReadonlyArrayDyn<'py, f64>,
    t0: f64,
    dt: f64,
    steps: usize,
    tau: Option<PyReadonlyArrayDyn<'py, f64>>,
    linear: bool,
    record_every: usize,
    max_speed: f64,
    lower: Option<PyReadonlyArrayDyn<'py, f64>>,
    upper: Option<PyReadonlyArrayDyn<'py, f64>>,
    f_ext: Option<PyReadonlyArrayDyn<'py, f64>>,
) -> PyResult<Bound<'py, PyTuple>> {
    guarded("integrate_fixed", || {
        let m = model.get();
        let (n, nq) = (m.model.n, m.model.nq);
        let f_ext = constant_wrenches(&m.model, f_ext.as_ref())?;
        let bounds = limits(nq, lower.as_ref(), upper.as_ref())?;
        let limits = bounds.as_ref().map(|(lower, upper)| Limits { lower, upper });
        let settings = Settings {
            method: method(method_name)?,
            dt,
            steps,
            t0,
            record_every,
            hold: false,
            max_speed,
            limits,
            cancel: None,
        };
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "dt must be a positive finite step in seconds, got {dt}"
            )));
        }
        if record_every == 0 {
            return Err(PyValueError::new_err("record_every must be at least 1"));
        }
        let (batch, q0, qd0) = initial_states(m, &q0, &qd0)?;
        let count = batch.unwrap_or(1);
        // torque samples: (rows per trajectory, shared?)
        let (tau, rows, shared) = match tau.as_ref() {
            None => (Vec::new(), 0, true),
            Some(a) => {
                let (rows, shared) = match a.shape() {
                    [s, w] if *w == n => (*s, true),
                    [b, s, w] if *w == n && Some(*b) == batch => (*s, false),
                    s => {
                        return Err(PyValueError::new_err(format!(
                            "tau must have shape (S, {n}) or, for a batch of {count}, ({count}, S, {n}); got {s:?}"
                        )))
                    }
                };
                let need = if linear { steps + 1 } else { steps };
                if rows != 1 && rows < need {
                    return Err(PyValueError::new_err(format!(
                        "tau has {rows} samples; {steps} steps need {need} ({}), or 1 for a constant",
                        if linear {
                            "one per sample time, interpolated"
                        } else {
                            "one per step, held"
                        }
                    )));
                }
                (flat("tau", a)?, rows, shared)
            }
        };
        let samples = settings.samples();
        let arrays = outputs(py, batch, samples, n, nq)?;
        // SAFETY: the arrays were created above; nothing else refers to them yet.
        let mut views = Vec::with_capacity(4);
        for a in arrays.iter() {
            views.push(unsafe { a.as_slice_mut()? });
        }
        let [oq, oqd, oqdd, otau]: [&mut [f64]; 4] = views
            .try_into()
            .map_err(|_| PyValueError::new_err("internal: output views"))?;
        let (per, per_q) = (samples * n, samples * nq);
        let model_ref = &m.model;
        let run_one = |settings: &Settings,
                       i: usize,
                       q: &mut [f64],
                       qd: &mut [f64],
                       qdd: &mut [f64],
                       t: &mut [f64]|
         -> Result<Outcome, kinedyn_core::Error> {
            let values = if rows == 0 {
                &tau[..0]
            } else if shared {
                &tau[..]
            } else {
                &tau[i * rows * n..(i + 1) * rows * n]
            };
            let samples = Sampled {
                values,
                n,
                t0,
                dt,
                linear,
            };
            let (mut plain, mut pushed);
            let source: &mut dyn TorqueFn = match f_ext.as_deref() {
                None => {
                    plain = samples;
                    &mut plain
                }
                Some(f_ext) => {
                    pushed = WithWrenches { source: samples, f_ext };
                    &mut pushed
                }
            };
            let mut data = Data::new(model_ref);
            sim::integrate(
                model_ref,
                &mut data,
                settings,
                &q0[i * nq..(i + 1) * nq],
                &qd0[i * n..(i + 1) * n],
                source,
                Record { q, qd, qdd, tau: t },
            )
        };
        // the whole run without the GIL, the trajectories of a batch in parallel
        let mut run_all = |settings: &Settings| {
            if count == 1 {
                return Ok(run_one(settings, 0, oq, oqd, oqdd, otau).map(|o| vec![o]));
            }
            if per == 0 || per_q == 0 {
                // a model without coordinates: no rows to split the outputs by, the runs in turn
                let empty = || -> &mut [f64] { &mut [] };
                return Ok((0..count)
                    .map(|i| run_one(settings, i, empty(), empty(), empty(), empty()))
                    .collect::<Result<Vec<_>, _>>());
            }
            guard::install(|| {
                oq.par_chunks_mut(per_q)
                    .zip(oqd.par_chunks_mut(per))
                    .zip(oqdd.par_chunks_mut(per))
                    .zip(otau.par_chunks_mut(per))
                    .enumerate()
                    .map(|(i, (((q, qd), qdd), t))| run_one(settings, i, q, qd, qdd, t))
                    .collect::<Result<Vec<_>, _>>()
            })
        };
        let outcomes = if steps.saturating_mul(count) < INTERRUPTIBLE_STEPS {
            py.detach(|| run_all(&settings))?
        } else {
            // long: Ctrl-C stops it (the core polls the flag every step; guard::interruptible)
            guard::interruptible(py, |cancel| {
                run_all(&Settings {
                    cancel: Some(cancel),
                    ..settings
                })
            })??
        };
        let outcomes: Vec<Outcome> = outcomes.map_err(core_err)?;
        result(py, arrays, &outcomes)
    })
}

/// A torque source made of Python callables: `torque(k, t, q, qd, out)` and, for the implicit
/// method, `jacobian(k, t, q, qd, dtau_dq, dtau_dqd) -> known`.
struct CallbackSource<T, J, W> {
    torque: T,
    jacobian: J,
    wrenches: W,
}

impl<T, J, W> TorqueFn for CallbackSource<T, J, W>
where
    T: FnMut(usize, f64, &[f64], &[f64], &mut [f64]) -> Result<(), String>,
    J: FnMut(usize, f64, &[f64], &[f64], &mut [f64], &mut [f64]) -> Result<bool, String>,
    W: FnMut(usize, f64, &[f64], &[f64], &mut [f64]) -> Result<bool, String>,
{
    fn wrenches(&mut self, step: usize, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) -> Result<bool, String> {
        (self.wrenches)(step, t, q, qd, out)
    }
    fn torque(&mut self, step: usize, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) -> Result<(), String> {
        (self.torque)(step, t, q, qd, out)
    }
    fn jacobian(
        &mut self,
        step: usize,
        t: f64,
        q: &[f64],
        qd: &[f64],
        dq: &mut [f64],
        dqd: &mut [f64],
    ) -> Result<bool, String> {
        (self.jacobian)(step, t, q, qd, dq, dqd)
    }
}

/// Copy an (n, n) array returned by Python into `out` (row-major).
fn matrix_into(value: &Bound<'_, PyAny>, n: usize, what: &str, out: &mut [f64]) -> PyResult<()> {
    let a: PyReadonlyArrayDyn<f64> = value.extract()?;
    if a.shape() != [n, n] {
        return Err(PyValueError::new_err(format!(
            "{what} must have shape ({n}, {n}), got {:?}",
            a.shape()
        )));
    }
    out.iter_mut().zip(a.as_array().iter()).for_each(|(o, x)| *o = *x);
    Ok(())
}

/// Integrate with the torque from `callback(step, t, q, qd) -> tau` (a Python callable returning n
/// numbers; `step` is the index k of the step [t_k, t_k + dt] being taken), called by the core's loop at every stage (`hold=False`) or once per step, held
/// (`hold=True`). A batch (N, n) runs its trajectories one after the other. An exception raised by
/// the callback propagates unchanged. `jacobian(step, t, q, qd) -> (dtau_dq, dtau_dqd)` ((n, n)
/// each) or None: the torque's derivatives, used by the implicit method. `f_ext`: None, constant
/// wrenches (links, 6) or a callable `f_ext(t, q, qd) -> (links, 6)` evaluated at every stage.
#[pyfunction]
#[pyo3(signature = (model, method_name, q0, qd0, t0, dt, steps, callback, hold=false, record_every=1, max_speed=1e6, jacobian=None, lower=None, upper=None, f_ext=None))]
#[allow(clippy::too_many_arguments)]
pub fn integrate_callback<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyModel>,
    method_name: &str,
    q0: PyReadonlyArrayDyn<'py, f64>,
    qd0: PyReadonlyArrayDyn<'py, f64>,
    t0: f64,
    dt: f64,
    steps: usize,
    callback: Bound<'py, PyAny>,
    hold: bool,
    record_every: usize,
    max_speed: f64,
    jacobian: Option<Bound<'py, PyAny>>,
    lower: Option<PyReadonlyArrayDyn<'py, f64>>,
    upper: Option<PyReadonlyArrayDyn<'py, f64>>,
    f_ext: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    guarded("integrate_callback", || {
        let m = model.get();
        let (n, nq) = (m.model.n, m.model.nq);
        let bounds = limits(nq, lower.as_ref(), upper.as_ref())?;
        let limits = bounds.as_ref().map(|(lower, upper)| Limits { lower, upper });
        let settings = Settings {
            method: method(method_name)?,
            dt,
            steps,
            t0,
            record_every,
            hold,
            max_speed,
            limits,
            cancel: None,
        };
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "dt must be a positive finite step in seconds, got {dt}"
            )));
        }
        if record_every == 0 {
            return Err(PyValueError::new_err("record_every must be at least 1"));
        }
        let (batch, q0, qd0) = initial_states(m, &q0, &qd0)?;
        let count = batch.unwrap_or(1);
        let samples = settings.samples();
        let arrays = outputs(py, batch, samples, n, nq)?;
        let mut views = Vec::with_capacity(4);
        for a in arrays.iter() {
            views.push(unsafe { a.as_slice_mut()? });
        }
        let [oq, oqd, oqdd, otau]: [&mut [f64]; 4] = views
            .try_into()
            .map_err(|_| PyValueError::new_err("internal: output views"))?;
        let (per, per_q) = (samples * n, samples * nq);
        let error: RefCell<Option<PyErr>> = RefCell::new(None);
        let torque = |k: usize, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]| -> Result<(), String> {
            let mut call = || -> PyResult<()> {
                let qa = PyArray1::from_slice(py, q);
                let qda = PyArray1::from_slice(py, qd);
                let value = callback.call1((k, t, qa, qda))?;
                let got = match value.extract::<PyReadonlyArrayDyn<f64>>() {
                    Ok(a) if a.ndim() == 1 && a.len() == n => {
                        out.iter_mut().zip(a.as_array().iter()).for_each(|(o, x)| *o = *x);
                        return Ok(());
                    }
                    Ok(a) => a.shape().to_vec(),
                    Err(_) => {
                        let v: Vec<f64> = value.extract()?;
                        if v.len() == n {
                            out.copy_from_slice(&v);
                            return Ok(());
                        }
                        vec![v.len()]
                    }
                };
                Err(PyValueError::new_err(format!(
                    "the controller returned torques of shape {got:?} at t = {t}; the robot has {n} joints"
                )))
            };
            call().map_err(|e| {
                let message = e.to_string();
                *error.borrow_mut() = Some(e);
                message
            })
        };
        let derivatives =
            |k: usize, t: f64, q: &[f64], qd: &[f64], dq: &mut [f64], dqd: &mut [f64]| -> Result<bool, String> {
                let Some(f) = jacobian.as_ref() else { return Ok(false) };
                let mut call = || -> PyResult<bool> {
                    let value = f.call1((k, t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, qd)))?;
                    if value.is_none() {
                        return Ok(false);
                    }
                    let (a, b): (Bound<'_, PyAny>, Bound<'_, PyAny>) = value.extract()?;
                    matrix_into(&a, n, "dtau/dq", dq)?;
                    matrix_into(&b, n, "dtau/dqd", dqd)?;
                    Ok(true)
                };
                call().map_err(|e| {
                    let message = e.to_string();
                    *error.borrow_mut() = Some(e);
                    message
                })
            };
        // external wrenches, one per link: None, a constant array, or a callable f_ext(t, q, qd)
        let constant = match f_ext.as_ref() {
            Some(f) if !f.is_callable() => constant_wrenches(&m.model, Some(&f.extract()?))?,
            _ => None,
        };
        let links = m.model.link_bodies().len();
        let wrenches = |_k: usize, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]| -> Result<bool, String> {
            if let Some(c) = constant.as_deref() {
                out.copy_from_slice(c);
                return Ok(true);
            }
            let Some(f) = f_ext.as_ref() else { return Ok(false) };
            let mut call = || -> PyResult<bool> {
                let value = f.call1((t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, qd)))?;
                let a = crate::conv::f64_array("f_ext", &value)?.readonly();
                if a.shape() != [links, 6] {
                    return Err(PyValueError::new_err(format!(
                        "f_ext returned wrenches of shape {:?} at t = {t}; the robot has {links} links: ({links}, 6)",
                        a.shape()
                    )));
                }
                out.copy_from_slice(&wrenches_per_body(
                    &m.model,
                    &a.as_array().iter().copied().collect::<Vec<_>>(),
                )?);
                Ok(true)
            };
            call().map_err(|e| {
                let message = e.to_string();
                *error.borrow_mut() = Some(e);
                message
            })
        };
        let mut source = CallbackSource {
            torque,
            jacobian: derivatives,
            wrenches,
        };
        let mut outcomes = Vec::with_capacity(count);
        let mut data = Data::new(&m.model);
        for i in 0..count {
            let r = i * per..(i + 1) * per;
            let out = Record {
                q: &mut oq[i * per_q..(i + 1) * per_q],
                qd: &mut oqd[r.clone()],
                qdd: &mut oqdd[r.clone()],
                tau: &mut otau[r],
            };
            let outcome = sim::integrate(
                &m.model,
                &mut data,
                &settings,
                &q0[i * nq..(i + 1) * nq],
                &qd0[i * n..(i + 1) * n],
                &mut source,
                out,
            )
            .map_err(core_err)?;
            if let Some(e) = error.borrow_mut().take() {
                return Err(e);
            }
            outcomes.push(outcome);
        }
        result(py, arrays, &outcomes)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(integrate_fixed, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_callback, m)?)?;
    Ok(())
}
