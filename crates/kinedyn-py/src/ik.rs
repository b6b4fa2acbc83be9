//! Inverse kinematics glue: `solve_ik` (batched Levenberg-Marquardt) and `AnalyticIk` (closed
//! forms detected from a model's geometry). Shapes and targets are checked here; the work is in
//! `kinedyn_core::ik`, run with the GIL released.

use std::sync::Mutex;

use crate::ik_branches::{all_branches, references_of, stated};
use kinedyn_core::ik::{self, ChainIk as CoreAnalytic, Settings};
use kinedyn_core::spatial::{Mat3, Transform, Vec3};
use kinedyn_core::{Data, Model};
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::guard::{self, guarded};
use crate::PyModel;

/// Batches of at least this many targets run interruptibly (`guard::detached`): Ctrl-C stops them
/// between targets. A numeric target takes microseconds (converging) to milliseconds (unreachable,
/// every restart tried), an analytic one microseconds; a few hundred outweigh the helper thread.
const INTERRUPTIBLE_TARGETS: usize = 256;

/// One target: a pose (4x4) or a position (3,), checked.
fn parse_target(values: &[f64], position: bool, index: Option<usize>) -> PyResult<Transform> {
    let at = index.map(|k| format!(" (target {k})")).unwrap_or_default();
    if let Some(k) = values.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "target contains a non-finite value (NaN or inf) at flat index {k}{at}"
        )));
    }
    if position {
        return Ok(Transform::new(
            Mat3::identity(),
            Vec3::new(values[0], values[1], values[2]),
        ));
    }
    let t = Transform::from_homogeneous(values);
    let bottom = &values[12..16];
    if bottom[0].abs() > 1e-9 || bottom[1].abs() > 1e-9 || bottom[2].abs() > 1e-9 || (bottom[3] - 1.0).abs() > 1e-9 {
        return Err(PyValueError::new_err(format!(
            "target is not an SE(3) matrix: its last row is {bottom:?}, not [0, 0, 0, 1]{at}"
        )));
    }
    let off = (t.rot.transpose() * t.rot - Mat3::identity()).abs().max();
    if off > 1e-6 || t.rot.determinant() < 0.0 {
        return Err(PyValueError::new_err(format!(
            "target is not an SE(3) matrix: its rotation part is not orthonormal with det +1 (|R^T R - I| = {off:.2e}, det = {:.6}){at}",
            t.rot.determinant()
        )));
    }
    Ok(t)
}

/// The numbers of a float64 array in C order, copied.
pub(crate) fn numbers(a: &Bound<'_, PyArrayDyn<f64>>) -> PyResult<Vec<f64>> {
    // SAFETY: read while this thread holds the GIL and runs no Python code, so nothing writes to
    // the array meanwhile (a plain type check instead of rust-numpy's borrow tracking, ~0.4 us each)
    let view = unsafe { a.as_array() };
    let mut v = guard::try_vec("inverse kinematics: copying an input", view.len())?;
    match view.as_slice() {
        Some(s) => v.extend_from_slice(s),
        None => v.extend(view.iter().copied()),
    }
    Ok(v)
}

/// Targets (4, 4) / (N, 4, 4) or positions (3,) / (N, 3): (transforms, batch size, position-only).
pub(crate) fn gather_targets(targets: &Bound<'_, PyArrayDyn<f64>>) -> PyResult<(Vec<Transform>, Option<usize>, bool)> {
    let shape = targets.shape().to_vec();
    let (batch, position) = match shape.as_slice() {
        [4, 4] => (None, false),
        [3] => (None, true),
        [b, 4, 4] => (Some(*b), false),
        [b, 3] => (Some(*b), true),
        _ => {
            return Err(PyValueError::new_err(format!(
                "target must be a 4x4 pose, a 3-vector position, or a batch (N, 4, 4) / (N, 3); got shape {shape:?}"
            )))
        }
    };
    let flat = numbers(targets)?;
    let width = if position { 3 } else { 16 };
    let mut list = guard::try_vec("inverse kinematics: the targets", flat.len() / width)?;
    for (k, c) in flat.chunks(width).enumerate() {
        list.push(parse_target(c, position, batch.map(|_| k))?);
    }
    Ok((list, batch, position))
}

pub(crate) fn vector(name: &str, a: &Bound<'_, PyArrayDyn<f64>>, len: usize) -> PyResult<Vec<f64>> {
    if a.shape() != [len] {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({len},), got {:?}",
            a.shape()
        )));
    }
    numbers(a)
}

pub(crate) fn check_limits(lower: &[f64], upper: &[f64]) -> PyResult<()> {
    for i in 0..lower.len() {
        if lower[i].is_nan() || upper[i].is_nan() || lower[i] > upper[i] {
            return Err(PyValueError::new_err(format!(
                "joint {i}: limits [{}, {}] are not an interval",
                lower[i], upper[i]
            )));
        }
    }
    Ok(())
}

/// The reduced coordinates of a model with mimic joints, from their Python description:
/// (q_source (nq_full,), q_multiplier, q_offset, v_source (nv_full,), v_multiplier, q_keep (nq,), nv).
type ReductionArgs = (Vec<i64>, Vec<f64>, Vec<f64>, Vec<i64>, Vec<f64>, Vec<i64>, usize);

fn reduction(model: &Model, args: Option<ReductionArgs>) -> PyResult<Option<ik::Reduction>> {
    let Some((q_source, q_multiplier, q_offset, v_source, v_multiplier, q_keep, nv)) = args else {
        return Ok(None);
    };
    let index = |x: i64| usize::try_from(x).unwrap_or(usize::MAX);
    if q_multiplier.len() != q_source.len() || q_offset.len() != q_source.len() || v_multiplier.len() != v_source.len()
    {
        return Err(PyValueError::new_err(
            "reduction: q_source, q_multiplier and q_offset (and v_source, v_multiplier) must have one length",
        ));
    }
    let q = q_source
        .iter()
        .zip(&q_multiplier)
        .zip(&q_offset)
        .map(|((k, m), b)| (index(*k), *m, *b))
        .collect();
    let v = v_source
        .iter()
        .zip(&v_multiplier)
        .map(|(k, m)| (index(*k), *m))
        .collect();
    ik::Reduction::new(model, q, v, q_keep.into_iter().map(index).collect(), nv)
        .map(Some)
        .map_err(PyValueError::new_err)
}

/// Levenberg-Marquardt inverse kinematics of `frame` for one target or a batch, on the
/// configuration manifold (multi-DOF joints: q ⊕ dq; see `kinedyn_core::ik`).
///
/// targets: (4, 4) | (3,) | (N, 4, 4) | (N, 3) (positions use weights on x, y, z only);
/// q0: (nq,) or (N, nq); lower, upper: (nq,) (infinite on multi-DOF joints' entries);
/// weights: (6,) for [x, y, z, rx, ry, rz]; reduction: the mimic joints' reduced coordinates
/// (then q0, lower, upper and the answers are reduced configurations).
/// Returns (q, success, position_error, orientation_error, iterations) with a leading N for a batch.
#[pyfunction]
#[pyo3(signature = (model, frame, targets, q0, lower, upper, weights, max_iterations=50, restarts=50, position_tolerance=1e-10, orientation_tolerance=1e-10, lambda_min=1e-6, max_step=0.5, seed=0, first_index=0, reduction=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn solve_ik<'py>(
    py: Python<'py>,
    model: &PyModel,
    frame: i64,
    targets: Bound<'py, PyArrayDyn<f64>>,
    q0: Bound<'py, PyArrayDyn<f64>>,
    lower: Bound<'py, PyArrayDyn<f64>>,
    upper: Bound<'py, PyArrayDyn<f64>>,
    weights: Bound<'py, PyArrayDyn<f64>>,
    max_iterations: usize,
    restarts: usize,
    position_tolerance: f64,
    orientation_tolerance: f64,
    lambda_min: f64,
    max_step: f64,
    seed: u64,
    first_index: u64,
    reduction: Option<ReductionArgs>,
) -> PyResult<Bound<'py, PyAny>> {
    guarded("solve_ik", || {
        let m: &Model = &model.model;
        let reduced = self::reduction(m, reduction)?;
        let reduced = reduced.as_ref();
        // configurations have n entries (nq), steps nv
        let (n, _) = ik::solver_sizes(m, reduced);
        if n == 0 {
            // no joint value moves a frame: nothing to solve (and no rows to split the batch by)
            return Err(PyValueError::new_err(
                "inverse kinematics: the model has no moving joint",
            ));
        }
        let frame = model.frame(frame)?;
        let (targets, batch, position) = gather_targets(&targets)?;
        let count = targets.len();
        let lower = vector("lower", &lower, n)?;
        let upper = vector("upper", &upper, n)?;
        check_limits(&lower, &upper)?;
        let w = vector("weights", &weights, 6)?;
        if w.iter().any(|x| !x.is_finite() || *x < 0.0) || w.iter().all(|x| *x == 0.0) {
            return Err(PyValueError::new_err(format!(
                "weights must be 6 finite values >= 0, not all zero; got {w:?}"
            )));
        }
        let mut weights: [f64; 6] = [w[0], w[1], w[2], w[3], w[4], w[5]];
        if position {
            weights[3..].fill(0.0);
        }
        let q0_shape = q0.shape().to_vec();
        let q0s: Vec<f64> = numbers(&q0)?;
        let per_target = match (q0_shape.as_slice(), batch) {
            ([k], _) if *k == n => false,
            ([b, k], Some(nb)) if *k == n && *b == nb => true,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "q0 must have shape ({n},) or ({count}, {n}), got {q0_shape:?}"
                )))
            }
        };
        if q0s.iter().any(|x| !x.is_finite()) {
            return Err(PyValueError::new_err("q0 contains a non-finite value"));
        }
        for (k, start) in q0s.chunks(n.max(1)).enumerate() {
            ik::check_start(m, reduced, start, &lower, &upper)
                .map_err(|e| PyValueError::new_err(if per_target { format!("{e} (start {k})") } else { e }))?;
        }
        let settings = Settings {
            weights,
            max_iterations,
            restarts,
            position_tolerance,
            orientation_tolerance,
            lambda_min,
            max_step,
        };
        let solve_one = |data: &mut Data, k: usize| {
            let start = if per_target { &q0s[k * n..(k + 1) * n] } else { &q0s[..] };
            // a seed per target, from its index in the whole batch (`first_index` + k when the caller
            // sends the batch in chunks): results do not depend on how the batch is split
            let index = first_index.wrapping_add(k as u64);
            ik::numeric_ik_reduced(
                m,
                reduced,
                data,
                frame,
                &targets[k],
                start,
                &lower,
                &upper,
                &settings,
                seed.wrapping_mul(0x2545_F491_4F6C_DD1D).wrapping_add(index),
            )
        };
        // the results, allocated fallibly before the work (MemoryError, not an abort), each target
        // writing its own row
        let q = guard::empty::<f64>(py, "solve_ik", &[count, n])?;
        let success = guard::zeros::<bool>(py, "solve_ik", &[count])?; // (zeros: no invalid bools)
        let [pe, oe] = [
            guard::empty::<f64>(py, "solve_ik", &[count])?,
            guard::empty::<f64>(py, "solve_ik", &[count])?,
        ];
        let it = guard::empty::<i64>(py, "solve_ik", &[count])?;
        // SAFETY: fresh arrays, referenced by nothing else until returned
        let (q_out, s_out, pe_out, oe_out, it_out) = unsafe {
            (
                q.as_slice_mut()?,
                success.as_slice_mut()?,
                pe.as_slice_mut()?,
                oe.as_slice_mut()?,
                it.as_slice_mut()?,
            )
        };
        let write = |data: &mut Data, k: usize, qk: &mut [f64], s: &mut bool, p: &mut f64, o: &mut f64, i: &mut i64| {
            let out = solve_one(data, k);
            qk.copy_from_slice(&out.q);
            (*s, *p, *o, *i) = (
                out.success,
                out.position_error,
                out.orientation_error,
                out.iterations as i64,
            );
        };
        // a batch stops between targets on Ctrl-C (a target takes microseconds to milliseconds)
        guard::detached(py, count >= INTERRUPTIBLE_TARGETS, |cancel| {
            let rows = q_out
                .chunks_mut(n)
                .zip(s_out.iter_mut())
                .zip(pe_out.iter_mut())
                .zip(oe_out.iter_mut())
                .zip(it_out.iter_mut());
            if count <= 4 {
                // the model's cached Data, unless another thread holds it (then a fresh one: a lock
                // held by a thread of the parent at a fork would otherwise never be released)
                let mut fresh;
                let mut cached = model.data.try_lock();
                let data: &mut Data = match cached.as_deref_mut() {
                    Ok(d) => d,
                    Err(_) => {
                        fresh = Data::new(m);
                        &mut fresh
                    }
                };
                for (k, ((((qk, s), p), o), i)) in rows.enumerate() {
                    write(data, k, qk, s, p, o, i);
                }
                Ok(())
            } else {
                guard::install(|| {
                    q_out
                        .par_chunks_mut(n)
                        .zip(s_out.par_iter_mut())
                        .zip(pe_out.par_iter_mut())
                        .zip(oe_out.par_iter_mut())
                        .zip(it_out.par_iter_mut())
                        .enumerate()
                        .try_for_each_init(
                            || Data::new(m),
                            |data, (k, ((((qk, s), p), o), i))| {
                                if guard::cancelled(cancel) {
                                    return Err(());
                                }
                                write(data, k, qk, s, p, o, i);
                                Ok(())
                            },
                        )
                })
                // (cancelled: `detached` returns the signal's exception)
                .map(|_| ())
            }
        })??;
        let result = match batch {
            Some(_) => (
                q.into_any(),
                success.into_any(),
                pe.into_any(),
                oe.into_any(),
                it.into_any(),
            ),
            None => (
                q.reshape([n])?.into_any(),
                s_out[0].into_pyobject(py)?.to_owned().into_any(),
                pe_out[0].into_pyobject(py)?.into_any(),
                oe_out[0].into_pyobject(py)?.into_any(),
                it_out[0].into_pyobject(py)?.into_any(),
            ),
        };
        Ok(result.into_pyobject(py)?.into_any())
    })
}

/// A closed-form solver detected from a model's geometry (`None` from `detect` when there is none).
#[pyclass(name = "AnalyticIk", module = "kinedyn._core", frozen)]
pub struct PyAnalyticIk {
    pub(crate) solver: CoreAnalytic,
    pub(crate) model: Model,
    pub(crate) data: Mutex<Data>,
    pub(crate) frame: usize,
    pub(crate) lower: Vec<f64>,
    pub(crate) upper: Vec<f64>,
}

#[pymethods]
impl PyAnalyticIk {
    /// The solver of `frame`'s chain, or None if its geometry has no closed form here.
    #[staticmethod]
    fn detect(
        model: &PyModel,
        frame: i64,
        lower: Bound<'_, PyArrayDyn<f64>>,
        upper: Bound<'_, PyArrayDyn<f64>>,
    ) -> PyResult<Option<Self>> {
        guarded("AnalyticIk.detect", || {
            let frame = model.frame(frame)?;
            if !model.model.plain {
                return Ok(None); // a multi-DOF joint is no screw: no closed form here
            }
            let m = model.model.clone();
            let lower = vector("lower", &lower, m.n)?;
            let upper = vector("upper", &upper, m.n)?;
            check_limits(&lower, &upper)?;
            let mut data = Data::new(&m);
            Ok(ik::detect_analytic(&m, &mut data, frame).map(|solver| Self {
                solver,
                model: m,
                data: Mutex::new(data),
                frame,
                lower,
                upper,
            }))
        })
    }

    /// Name of the detected structure (e.g. "spherical_wrist"; "reversed_..." when it was found
    /// from the tool end).
    #[getter]
    fn structure(&self) -> &'static str {
        self.solver.name()
    }

    /// Name of the arm of a spherical-wrist chain, else None.
    #[getter]
    fn arm(&self) -> Option<&'static str> {
        self.solver.ik.arm.map(|a| a.name())
    }

    /// The most real solutions the structure's closed form has for one target.
    #[getter]
    fn max_solutions(&self) -> usize {
        self.solver.max_solutions()
    }

    /// `solve` with the statement of completeness: (solutions, position errors, orientation
    /// errors, found, singular, max_solutions, worst residual, merged).
    #[pyo3(signature = (target, reference, respect_limits=true, tolerance=1e-9))]
    fn solve_stated<'py>(
        &self,
        py: Python<'py>,
        target: Bound<'py, PyArrayDyn<f64>>,
        reference: Bound<'py, PyArrayDyn<f64>>,
        respect_limits: bool,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        guarded("AnalyticIk.solve_stated", || {
            let out = self.one(&target, &reference, respect_limits, tolerance)?;
            stated(py, out, self.model.n)
        })
    }

    /// Every solution of each target of a batch, in one call on all threads (see `all_branches`).
    #[pyo3(signature = (targets, references, respect_limits=true, tolerance=1e-9))]
    fn solve_all<'py>(
        &self,
        py: Python<'py>,
        targets: Bound<'py, PyArrayDyn<f64>>,
        references: Bound<'py, PyArrayDyn<f64>>,
        respect_limits: bool,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        guarded("AnalyticIk.solve_all", || {
            let n = self.model.n;
            let (targets, _, position) = gather_targets(&targets)?;
            let refs = references_of(&references, targets.len(), n)?;
            let width = self.solver.max_solutions();
            all_branches(py, &self.model, targets.len(), width, |data, k| {
                ik::analytic_solutions(
                    &self.model,
                    data,
                    &self.solver,
                    self.frame,
                    &targets[k],
                    position,
                    &refs[k * n..(k + 1) * n],
                    &self.lower,
                    &self.upper,
                    respect_limits,
                    tolerance,
                )
            })
        })
    }

    /// Whether position-only targets (3,) have a closed form (else only full poses do).
    #[getter]
    fn solves_position(&self) -> bool {
        self.solver.solves_position()
    }

    /// All solutions for one target (4, 4) or position (3,):
    /// (solutions (m, n) nearest `reference` first, position errors (m,), orientation errors (m,),
    ///  distinct solutions found before the limit filter, singular flag).
    #[pyo3(signature = (target, reference, respect_limits=true, tolerance=1e-9))]
    #[allow(clippy::type_complexity)]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        target: Bound<'py, PyArrayDyn<f64>>,
        reference: Bound<'py, PyArrayDyn<f64>>,
        respect_limits: bool,
        tolerance: f64,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        usize,
        bool,
    )> {
        guarded("AnalyticIk.solve", || {
            let n = self.model.n;
            let out = self.one(&target, &reference, respect_limits, tolerance)?;
            let m = out.solutions.len();
            let flat: Vec<f64> = out.solutions.concat();
            Ok((
                PyArray1::from_vec(py, flat).reshape([m, n])?,
                PyArray1::from_vec(py, out.position_error),
                PyArray1::from_vec(py, out.orientation_error),
                out.found,
                out.singular,
            ))
        })
    }

    /// The solution nearest each reference for a batch of targets: (q (N, n), success (N,),
    /// position errors (N,), orientation errors (N,)); q is NaN where no solution exists.
    #[pyo3(signature = (targets, references, respect_limits=true, tolerance=1e-9))]
    #[allow(clippy::type_complexity)]
    fn solve_nearest<'py>(
        &self,
        py: Python<'py>,
        targets: Bound<'py, PyArrayDyn<f64>>,
        references: Bound<'py, PyArrayDyn<f64>>,
        respect_limits: bool,
        tolerance: f64,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        guarded("AnalyticIk.solve_nearest", || {
            let n = self.model.n;
            let (targets, _, position) = gather_targets(&targets)?;
            let count = targets.len();
            let refs: Vec<f64> = numbers(&references)?;
            if references.shape() != [count, n] {
                return Err(PyValueError::new_err(format!(
                    "references must have shape ({count}, {n}), got {:?}",
                    references.shape()
                )));
            }
            // the results, allocated fallibly before the work, each target writing its own row
            const WHAT: &str = "AnalyticIk.solve_nearest";
            let q = guard::empty::<f64>(py, WHAT, &[count, n])?;
            let success = guard::zeros::<bool>(py, WHAT, &[count])?;
            let [pe, oe] = [
                guard::empty::<f64>(py, WHAT, &[count])?,
                guard::empty::<f64>(py, WHAT, &[count])?,
            ];
            // SAFETY: fresh arrays, referenced by nothing else until returned
            let (q_out, s_out, pe_out, oe_out) = unsafe {
                (
                    q.as_slice_mut()?,
                    success.as_slice_mut()?,
                    pe.as_slice_mut()?,
                    oe.as_slice_mut()?,
                )
            };
            guard::detached(py, count >= INTERRUPTIBLE_TARGETS, |cancel| {
                guard::install(|| {
                    q_out
                        .par_chunks_mut(n)
                        .zip(s_out.par_iter_mut())
                        .zip(pe_out.par_iter_mut())
                        .zip(oe_out.par_iter_mut())
                        .enumerate()
                        .try_for_each_init(
                            || Data::new(&self.model),
                            |data, (k, (((qk, s), p), o))| {
                                if guard::cancelled(cancel) {
                                    return Err(());
                                }
                                let r = &refs[k * n..(k + 1) * n];
                                let out = ik::analytic_solutions(
                                    &self.model,
                                    data,
                                    &self.solver,
                                    self.frame,
                                    &targets[k],
                                    position,
                                    r,
                                    &self.lower,
                                    &self.upper,
                                    respect_limits,
                                    tolerance,
                                );
                                match out.solutions.first() {
                                    Some(best) => {
                                        qk.copy_from_slice(best);
                                        (*s, *p, *o) = (true, out.position_error[0], out.orientation_error[0]);
                                    }
                                    None => {
                                        qk.fill(f64::NAN);
                                        (*s, *p, *o) = (false, f64::NAN, f64::NAN);
                                    }
                                }
                                Ok(())
                            },
                        )
                })
                // (cancelled: `detached` returns the signal's exception)
                .map(|_| ())
            })??;
            Ok((
                q.cast_into::<PyArray2<f64>>()?,
                success.cast_into::<PyArray1<bool>>()?,
                pe.cast_into::<PyArray1<f64>>()?,
                oe.cast_into::<PyArray1<f64>>()?,
            ))
        })
    }
}

/// Register the IK functions and classes in `kinedyn._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(solve_ik, m)?)?;
    m.add_class::<PyAnalyticIk>()?;
    Ok(())
}
