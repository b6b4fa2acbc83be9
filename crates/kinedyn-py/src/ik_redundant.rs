//! Seven-joint arms' closed forms (`kinedyn_core::ik::redundant`): a held joint or the arm angle
//! of an SRS arm as the redundancy parameter; every branch for one value, a batch of targets, or
//! a sweep of values (the self-motion manifold). Shapes are checked here, the work is the core's.

use std::sync::Mutex;

use kinedyn_core::ik::{self, AnalyticOutcome, Check, Met, Redundant, SRS_MAX_SOLUTIONS};
use kinedyn_core::spatial::Transform;
use kinedyn_core::{Data, Model};
use numpy::{PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::guard::{self, guarded};
use crate::ik::{check_limits, gather_targets, numbers, vector};
use crate::ik_branches::{all_branches, references_of, stated};
use crate::PyModel;

/// The redundancy parameter: joint `k` held at q = value, or the arm angle (rad).
#[derive(Clone, Copy)]
enum Param {
    Held(usize),
    ArmAngle,
}

/// Slots of a sweep's branches for a held joint: the most any structure here has.
const HELD_SLOTS: usize = 16;

#[pyclass(name = "RedundantIk", module = "kinedyn._core", frozen)]
pub struct PyRedundantIk {
    solver: Redundant,
    model: Model,
    data: Mutex<Data>,
    frame: usize,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl PyRedundantIk {
    fn param(&self, mode: &str, joint: i64) -> PyResult<Param> {
        match mode {
            "held" => {
                let k = usize::try_from(joint).ok().filter(|&k| k < 7).ok_or_else(|| {
                    PyValueError::new_err(format!("the held joint must be an index 0..6 of the chain, got {joint}"))
                })?;
                Ok(Param::Held(k))
            }
            "arm_angle" if self.solver.srs.is_some() => Ok(Param::ArmAngle),
            "arm_angle" => Err(PyValueError::new_err(
                "the arm angle needs an SRS arm (axes 1-3 meeting in a shoulder point, axes 5-7 in a wrist point); hold a joint instead",
            )),
            _ => Err(PyValueError::new_err(format!(
                "redundancy mode must be 'held' or 'arm_angle', got {mode:?}"
            ))),
        }
    }

    /// Every solution at one value of the parameter, checked and stated.
    #[allow(clippy::too_many_arguments)]
    fn outcome(
        &self,
        data: &mut Data,
        target: &Transform,
        param: Param,
        value: f64,
        reference: &[f64],
        respect_limits: bool,
        tolerance: f64,
    ) -> AnalyticOutcome {
        let m = &self.model;
        let theta_ref: Vec<f64> = (0..7).map(|i| reference[i] + m.offset[i]).collect();
        let check = |held: Option<usize>, most: usize, met: Met| Check {
            frame: self.frame,
            target,
            position_only: false,
            reference,
            lower: &self.lower,
            upper: &self.upper,
            respect_limits,
            tolerance,
            held,
            most,
            singular: met.singular,
            merged: met.merged,
        };
        match param {
            Param::Held(k) => {
                let mut rows = Vec::with_capacity(8);
                match self
                    .solver
                    .solve_held(target, k, value + m.offset[k], &theta_ref, &mut rows)
                {
                    Some((met, most)) => check(Some(k), most, met).finish(m, data, rows.as_flattened(), 7),
                    None => AnalyticOutcome::default(), // max_solutions 0: no closed form here
                }
            }
            Param::ArmAngle => {
                let mut rows = [None; SRS_MAX_SOLUTIONS];
                let met = self
                    .solver
                    .solve_arm_angle(target, value, &theta_ref, &mut rows)
                    .unwrap_or(Met {
                        singular: true,
                        merged: false,
                    });
                let flat: Vec<f64> = rows.iter().flatten().flatten().copied().collect();
                check(None, SRS_MAX_SOLUTIONS, met).finish(m, data, &flat, 7)
            }
        }
    }
}

#[pymethods]
impl PyRedundantIk {
    /// The seven-joint chain of `frame` (a serial chain of revolute or prismatic joints ending at
    /// it), or None.
    #[staticmethod]
    fn detect(
        model: &PyModel,
        frame: i64,
        lower: Bound<'_, PyArrayDyn<f64>>,
        upper: Bound<'_, PyArrayDyn<f64>>,
    ) -> PyResult<Option<Self>> {
        guarded("RedundantIk.detect", || {
            let frame = model.frame(frame)?;
            let m = model.model.clone();
            if !m.plain || m.n != 7 {
                return Ok(None);
            }
            let lower = vector("lower", &lower, m.n)?;
            let upper = vector("upper", &upper, m.n)?;
            check_limits(&lower, &upper)?;
            let mut data = Data::new(&m);
            let Some((screws, home)) = ik::chain_screws(&m, &mut data, frame) else {
                return Ok(None);
            };
            Ok(Redundant::new(screws, home).map(|solver| Self {
                solver,
                model: m,
                data: Mutex::new(data),
                frame,
                lower,
                upper,
            }))
        })
    }

    /// Whether the arm is SRS (the arm angle applies).
    #[getter]
    fn srs(&self) -> bool {
        self.solver.srs.is_some()
    }

    /// The structure of the six-joint chain left with joint `joint` held at q = `value` (None when
    /// it has none: then the numeric solver is the way).
    fn held_structure(&self, joint: usize, value: f64) -> PyResult<Option<&'static str>> {
        if joint >= 7 || !value.is_finite() {
            return Err(PyValueError::new_err(format!(
                "held joint {joint} at {value}: the index must be 0..6 and the value finite"
            )));
        }
        Ok(self
            .solver
            .held(joint, value + self.model.offset[joint])
            .map(|c| c.name()))
    }

    /// The arm angle of the joint vector `q` (SRS arms), or None (stretched elbow, not SRS).
    fn arm_angle(&self, q: Bound<'_, PyArrayDyn<f64>>) -> PyResult<Option<f64>> {
        let q = vector("q", &q, 7)?;
        let theta: Vec<f64> = (0..7).map(|i| q[i] + self.model.offset[i]).collect();
        Ok(self.solver.arm_angle(&theta))
    }

    /// The arm-angle intervals within [lo, hi] where each SRS branch (by its number, as in
    /// `sweep`) keeps every joint inside the limits, in closed form (`ik::self_motion`): a list of
    /// 8 lists of (start, end); None when psi is undefined at this target (stretched elbow).
    #[allow(clippy::type_complexity)]
    fn arm_angle_intervals(
        &self,
        target: Bound<'_, PyArrayDyn<f64>>,
        lo: f64,
        hi: f64,
    ) -> PyResult<Option<Vec<Vec<(f64, f64)>>>> {
        guarded("RedundantIk.arm_angle_intervals", || {
            self.param("arm_angle", -1)?;
            let (targets, batch, position) = gather_targets(&target)?;
            if batch.is_some() || position {
                return Err(PyValueError::new_err(
                    "RedundantIk.arm_angle_intervals takes one 4x4 pose",
                ));
            }
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(PyValueError::new_err(format!(
                    "the arm-angle span must be finite with lo <= hi, got [{lo}, {hi}]"
                )));
            }
            let off = &self.model.offset;
            let lower: Vec<f64> = (0..7).map(|i| self.lower[i] + off[i]).collect();
            let upper: Vec<f64> = (0..7).map(|i| self.upper[i] + off[i]).collect();
            Ok(self
                .solver
                .arm_angle_intervals(&targets[0], &lower, &upper, (lo, hi))
                .map(|found| found.into_iter().collect()))
        })
    }

    /// Every solution for one target (4, 4) at one value of the parameter (`mode` "held" with
    /// `joint` its chain index and `value` its q, or "arm_angle" with `value` psi): the tuple of
    /// `AnalyticIk.solve_stated`.
    #[pyo3(signature = (target, mode, joint, value, reference, respect_limits=true, tolerance=1e-9))]
    #[allow(clippy::too_many_arguments)]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        target: Bound<'py, PyArrayDyn<f64>>,
        mode: &str,
        joint: i64,
        value: f64,
        reference: Bound<'py, PyArrayDyn<f64>>,
        respect_limits: bool,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        guarded("RedundantIk.solve", || {
            let param = self.param(mode, joint)?;
            let (targets, batch, position) = gather_targets(&target)?;
            if batch.is_some() || position {
                return Err(PyValueError::new_err(
                    "RedundantIk.solve takes one 4x4 pose; use solve_batch for a batch",
                ));
            }
            if !value.is_finite() {
                return Err(PyValueError::new_err(format!(
                    "the redundancy value must be finite, got {value}"
                )));
            }
            let reference = vector("reference", &reference, 7)?;
            let out = {
                let mut data = self.data.lock().unwrap_or_else(|e| e.into_inner());
                self.outcome(
                    &mut data,
                    &targets[0],
                    param,
                    value,
                    &reference,
                    respect_limits,
                    tolerance,
                )
            };
            stated(py, out, 7)
        })
    }

    /// Every solution of each target (N, 4, 4) at its value (N,), on all threads: the tuple of
    /// `AnalyticIk.solve_all`.
    #[pyo3(signature = (targets, mode, joint, values, references, respect_limits=true, tolerance=1e-9))]
    #[allow(clippy::too_many_arguments)]
    fn solve_batch<'py>(
        &self,
        py: Python<'py>,
        targets: Bound<'py, PyArrayDyn<f64>>,
        mode: &str,
        joint: i64,
        values: Bound<'py, PyArrayDyn<f64>>,
        references: Bound<'py, PyArrayDyn<f64>>,
        respect_limits: bool,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        guarded("RedundantIk.solve_batch", || {
            let param = self.param(mode, joint)?;
            let (targets, _, position) = gather_targets(&targets)?;
            if position {
                return Err(PyValueError::new_err("a seven-joint arm's closed forms need 4x4 poses"));
            }
            let count = targets.len();
            let values = vector("values", &values, count)?;
            if let Some(k) = values.iter().position(|v| !v.is_finite()) {
                return Err(PyValueError::new_err(format!("values[{k}] is not finite")));
            }
            let refs = references_of(&references, count, 7)?;
            all_branches(py, &self.model, count, 8, |data, k| {
                self.outcome(
                    data,
                    &targets[k],
                    param,
                    values[k],
                    &refs[k * 7..(k + 1) * 7],
                    respect_limits,
                    tolerance,
                )
            })
        })
    }

    /// The branches along a sweep of the parameter for one target: (q (M, B, 7), singular (M,)),
    /// `q[m, b]` the b-th branch at `values[m]` (NaN where it does not exist or misses the target
    /// by more than `tolerance`), joint limits not applied; revolute angles moved by 2 pi k next
    /// to `reference`. For the arm angle, b is the branch number of the core (stable in psi); for a
    /// held joint, the six-joint solver's candidate order.
    #[pyo3(signature = (target, mode, joint, values, reference, tolerance=1e-9))]
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn sweep<'py>(
        &self,
        py: Python<'py>,
        target: Bound<'py, PyArrayDyn<f64>>,
        mode: &str,
        joint: i64,
        values: Bound<'py, PyArrayDyn<f64>>,
        reference: Bound<'py, PyArrayDyn<f64>>,
        tolerance: f64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        guarded("RedundantIk.sweep", || {
            let param = self.param(mode, joint)?;
            let (targets, batch, position) = gather_targets(&target)?;
            if batch.is_some() || position {
                return Err(PyValueError::new_err("RedundantIk.sweep takes one 4x4 pose"));
            }
            let values = numbers(&values)?;
            if let Some(k) = values.iter().position(|v| !v.is_finite()) {
                return Err(PyValueError::new_err(format!("values[{k}] is not finite")));
            }
            let reference = vector("reference", &reference, 7)?;
            let width = match param {
                Param::Held(_) => HELD_SLOTS,
                Param::ArmAngle => SRS_MAX_SOLUTIONS,
            };
            let count = values.len();
            let m = &self.model;
            let target = targets[0];
            let theta_ref: Vec<f64> = (0..7).map(|i| reference[i] + m.offset[i]).collect();
            let rows: Vec<(Vec<f64>, bool)> = py.detach(|| {
                guard::install(|| {
                    values
                        .par_iter()
                        .map_init(
                            || Data::new(m),
                            |data, &value| {
                                let check = Check {
                                    frame: self.frame,
                                    target: &target,
                                    position_only: false,
                                    reference: &reference,
                                    lower: &self.lower,
                                    upper: &self.upper,
                                    respect_limits: false,
                                    tolerance,
                                    held: match param {
                                        Param::Held(k) => Some(k),
                                        Param::ArmAngle => None,
                                    },
                                    most: width,
                                    singular: false,
                                    merged: false,
                                };
                                let mut slots = vec![f64::NAN; width * 7];
                                let mut put = |b: usize, theta: &[f64]| {
                                    if b < width {
                                        if let Some((q, ..)) = check.one(m, data, theta) {
                                            slots[b * 7..(b + 1) * 7].copy_from_slice(&q);
                                        }
                                    }
                                };
                                let singular = match param {
                                    Param::Held(k) => {
                                        let mut cands = Vec::with_capacity(8);
                                        let s = self.solver.solve_held(
                                            &target,
                                            k,
                                            value + m.offset[k],
                                            &theta_ref,
                                            &mut cands,
                                        );
                                        for (b, row) in cands.iter().enumerate() {
                                            put(b, row);
                                        }
                                        s.is_none_or(|(s, _)| s.singular)
                                    }
                                    Param::ArmAngle => {
                                        let mut cands = [None; SRS_MAX_SOLUTIONS];
                                        let s = self.solver.solve_arm_angle(&target, value, &theta_ref, &mut cands);
                                        for (b, row) in cands.iter().enumerate() {
                                            if let Some(row) = row {
                                                put(b, row);
                                            }
                                        }
                                        s.is_none_or(|s| s.singular)
                                    }
                                };
                                (slots, singular)
                            },
                        )
                        .collect()
                })
            })?;
            let q = guard::empty::<f64>(py, "RedundantIk.sweep", &[count, width, 7])?;
            let flags = guard::zeros::<bool>(py, "RedundantIk.sweep", &[count])?;
            // SAFETY: fresh arrays, referenced by nothing else until returned
            unsafe {
                let (qs, fs) = (q.as_slice_mut()?, flags.as_slice_mut()?);
                for (k, (slots, s)) in rows.iter().enumerate() {
                    qs[k * width * 7..(k + 1) * width * 7].copy_from_slice(slots);
                    fs[k] = *s;
                }
            }
            Ok((q.into_any(), flags.into_any()))
        })
    }
}

/// Register `RedundantIk` in `kinedyn._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyRedundantIk>()?;
    Ok(())
}
