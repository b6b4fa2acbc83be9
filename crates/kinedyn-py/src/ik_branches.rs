//! Every closed-form branch of one target or a batch, with each target's statement of
//! completeness, packed for Python (`AnalyticIk.solve_stated` / `solve_all`,
//! `RedundantIk.solve` / `solve_batch`): shapes checked here, the work in `kinedyn_core::ik`.

use kinedyn_core::ik::{self, AnalyticOutcome};
use kinedyn_core::{Data, Model};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::guard;
use crate::ik::{gather_targets, numbers, vector, PyAnalyticIk};

/// References `(N, n)`, checked.
pub(crate) fn references_of(references: &Bound<'_, PyArrayDyn<f64>>, count: usize, n: usize) -> PyResult<Vec<f64>> {
    if references.shape() != [count, n] {
        return Err(PyValueError::new_err(format!(
            "references must have shape ({count}, {n}), got {:?}",
            references.shape()
        )));
    }
    let refs = numbers(references)?;
    if refs.iter().any(|x| !x.is_finite()) {
        return Err(PyValueError::new_err("references contain a non-finite value"));
    }
    Ok(refs)
}

/// One target's outcome with its statement of completeness, as a tuple: (solutions (m, n),
/// position errors (m,), orientation errors (m,), found, singular, max_solutions, worst residual,
/// merged).
pub(crate) fn stated<'py>(py: Python<'py>, out: AnalyticOutcome, n: usize) -> PyResult<Bound<'py, PyAny>> {
    let m = out.solutions.len();
    let flat: Vec<f64> = out.solutions.concat();
    Ok((
        PyArray1::from_vec(py, flat).reshape([m, n])?,
        PyArray1::from_vec(py, out.position_error),
        PyArray1::from_vec(py, out.orientation_error),
        out.found,
        out.singular,
        out.max_solutions,
        out.worst_residual,
        out.merged,
    )
        .into_pyobject(py)?
        .into_any())
}

/// Every solution of `count` targets, one `solve(data, k)` per target on all threads, packed as
/// (solutions (N, width, n) NaN past each count, counts (N,), position errors (N, width),
/// orientation errors (N, width), found (N,), singular (N,), max_solutions (N,), worst residual
/// (N,), merged (N,)).
pub(crate) fn all_branches<'py>(
    py: Python<'py>,
    model: &Model,
    count: usize,
    width: usize,
    solve: impl Fn(&mut Data, usize) -> AnalyticOutcome + Sync,
) -> PyResult<Bound<'py, PyAny>> {
    const WHAT: &str = "inverse kinematics, every branch";
    let n = model.n;
    let outcomes: Vec<AnalyticOutcome> = py.detach(|| {
        guard::install(|| {
            (0..count)
                .into_par_iter()
                .map_init(|| Data::new(model), |data, k| solve(data, k))
                .collect()
        })
    })?;
    let width = outcomes.iter().map(|o| o.solutions.len()).fold(width, usize::max);
    let q = guard::empty::<f64>(py, WHAT, &[count, width, n])?;
    let [pe, oe] = [
        guard::empty::<f64>(py, WHAT, &[count, width])?,
        guard::empty::<f64>(py, WHAT, &[count, width])?,
    ];
    let [counts, found, most] = [
        guard::empty::<i64>(py, WHAT, &[count])?,
        guard::empty::<i64>(py, WHAT, &[count])?,
        guard::empty::<i64>(py, WHAT, &[count])?,
    ];
    let worst = guard::empty::<f64>(py, WHAT, &[count])?;
    let [singular, merged] = [
        guard::zeros::<bool>(py, WHAT, &[count])?,
        guard::zeros::<bool>(py, WHAT, &[count])?,
    ];
    // SAFETY: fresh arrays, referenced by nothing else until returned
    unsafe {
        let (qs, pes, oes) = (q.as_slice_mut()?, pe.as_slice_mut()?, oe.as_slice_mut()?);
        qs.fill(f64::NAN);
        pes.fill(f64::NAN);
        oes.fill(f64::NAN);
        let (cs, fs, ms, ws) = (
            counts.as_slice_mut()?,
            found.as_slice_mut()?,
            most.as_slice_mut()?,
            worst.as_slice_mut()?,
        );
        let (ss, gs) = (singular.as_slice_mut()?, merged.as_slice_mut()?);
        for (k, o) in outcomes.iter().enumerate() {
            for (b, sol) in o.solutions.iter().enumerate() {
                qs[(k * width + b) * n..(k * width + b + 1) * n].copy_from_slice(sol);
                pes[k * width + b] = o.position_error[b];
                oes[k * width + b] = o.orientation_error[b];
            }
            cs[k] = o.solutions.len() as i64;
            fs[k] = o.found as i64;
            ms[k] = o.max_solutions as i64;
            ws[k] = o.worst_residual;
            ss[k] = o.singular;
            gs[k] = o.merged;
        }
    }
    Ok((q, counts, pe, oe, found, singular, most, worst, merged)
        .into_pyobject(py)?
        .into_any())
}

impl PyAnalyticIk {
    /// Every solution for one target, checked and stated.
    pub(crate) fn one(
        &self,
        target: &Bound<'_, PyArrayDyn<f64>>,
        reference: &Bound<'_, PyArrayDyn<f64>>,
        respect_limits: bool,
        tolerance: f64,
    ) -> PyResult<ik::AnalyticOutcome> {
        let (targets, batch, position) = gather_targets(target)?;
        if batch.is_some() {
            return Err(PyValueError::new_err(
                "AnalyticIk.solve takes one target; use solve_nearest or solve_all for a batch",
            ));
        }
        let reference = vector("reference", reference, self.model.n)?;
        let mut data = self.data.lock().unwrap_or_else(|e| e.into_inner());
        Ok(ik::analytic_solutions(
            &self.model,
            &mut data,
            &self.solver,
            self.frame,
            &targets[0],
            position,
            &reference,
            &self.lower,
            &self.upper,
            respect_limits,
            tolerance,
        ))
    }
}
