//! `kinedyn._core.Model`: the compiled model and its numeric methods, each a call into the core
//! run by `run.rs` over one state or a batch.

use std::borrow::Cow;
use std::sync::Mutex;

use kinedyn_core::algorithms;
use kinedyn_core::batch::{self, kernels, Input, Scratch, Simd};
use kinedyn_core::constraints::{self, Loop, LoopKind};
use kinedyn_core::spatial::Vec3;
use kinedyn_core::{Data, Model};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::conv::{self, f64_array, optional, vec_of, Batch};
use crate::guard::guarded;
use crate::run::{core_err, Arrays3};

/// The compiled model plus one cached `Data` for single-state calls.
#[pyclass(name = "Model", module = "kinedyn._core", frozen)]
pub(crate) struct PyModel {
    pub(crate) model: Model,
    pub(crate) data: Mutex<Data>,
}

impl PyModel {
    pub(crate) fn n(&self) -> usize {
        self.model.n
    }

    /// A frame of this model by index.
    pub(crate) fn frame(&self, frame: i64) -> PyResult<usize> {
        conv::frame(frame, self.model.frames.len())
    }

    /// The three state arrays of a dynamics call (q (nq,), then two of (n,)) and the optional
    /// external wrenches f_ext, one per link ((links, 6), one set shared by every state of a batch,
    /// or (N, links, 6)), checked against each other and laid out one per body for the core
    /// (`conv::wrenches_per_body`).
    fn gather_dynamics<'a>(
        &self,
        [(a, x), (b, y), (c, z)]: [(&str, &'a Bound<'_, PyArrayDyn<f64>>); 3],
        f_ext: Option<&'a Bound<'_, PyArrayDyn<f64>>>,
    ) -> PyResult<Batch<'a>> {
        let (n, nq) = (self.n(), self.model.nq);
        let (sq, s1) = ([nq], [n]);
        let states = [(a, x, &sq[..]), (b, y, &s1[..]), (c, z, &s1[..])];
        let Some(f) = f_ext else { return Batch::gather(&states) };
        let links = if self.model.plain {
            n
        } else {
            self.model.link_bodies().len()
        };
        let sl = [links, 6];
        let mut batch = Batch::gather(&states)?;
        match batch.batch {
            // one set of wrenches for every state of a batch, repeated as NumPy broadcasts it
            Some(count) if f.shape() == sl => {
                let one = Batch::gather(&[("f_ext", f, &sl[..])])?;
                batch.values[3] = Cow::Owned(one.values[0].repeat(count));
                (batch.width[3], batch.count) = (6 * links, 4);
            }
            _ => batch = Batch::gather(&[states[0], states[1], states[2], ("f_ext", f, &sl[..])])?,
        }
        if !self.model.plain {
            batch.values[3] = Cow::Owned(conv::wrenches_per_body(&self.model, &batch.values[3])?);
            batch.width[3] = 6 * n;
        }
        Ok(batch)
    }

    /// Every state of `q` (nq numbers each) passes the core's `Model::check_configuration`.
    pub(crate) fn check_configurations(&self, q: &[f64]) -> PyResult<()> {
        let model = &self.model;
        if model.plain || model.nq == 0 {
            return Ok(());
        }
        let batch = q.len() > model.nq;
        for (k, state) in q.chunks(model.nq).enumerate() {
            model
                .check_configuration(state, batch.then_some(k))
                .map_err(PyValueError::new_err)?;
        }
        Ok(())
    }
}

/// Writes `#[pymethods] impl PyModel` from one table of the methods whose arguments are state
/// arrays, each row `fn name(input: width, ..; f_ext) -> "result" [per-state shape], out = how;`
/// (`; f_ext` where the call takes external wrenches (links, 6), `, out` where it takes NumPy's
/// `out=`), where `how` is `kernel K` (a core batch `Kernel`, over SIMD lanes) or
/// `per_state |model, data, x, out| ..` (one state at a time), followed by the methods written by
/// hand (`by_hand { .. }`: those with options or several results). `|n, nq|` names the model's
/// velocity and configuration sizes for the table.
macro_rules! model_methods {
    (
        |$n:ident, $nq:ident|
        $(
            $(#[doc = $doc:literal])*
            fn $name:ident ( $($arg:ident : $w:ident),+ $(; $fext:ident)? ) -> $quantity:literal [$($dim:expr),*]
            $(, $out:ident)? = $how:ident $kernel:expr;
        )*
        by_hand { $($by_hand:tt)* }
    ) => {
        #[pymethods]
        impl PyModel {
            $(
                $(#[doc = $doc])*
                #[pyo3(signature = ($($arg),+ $(, $fext = None)? $(, $out = None)?))]
                fn $name<'py>(
                    &self,
                    py: Python<'py>,
                    $($arg: Bound<'py, PyAny>,)+
                    $($fext: Option<Bound<'py, PyAny>>,)?
                    $($out: Option<Bound<'py, PyAny>>,)?
                ) -> PyResult<Bound<'py, PyAny>> {
                    guarded(concat!("Model.", stringify!($name)), || {
                        $(let $fext = $fext.map(|f| f64_array("f_ext", &f)).transpose()?;)?
                        $(let $arg = f64_array(stringify!($arg), &$arg)?;)+
                        #[allow(unused_variables)]
                        let ($n, $nq) = (self.n(), self.model.nq);
                        let batch = model_methods!(@gather self [$(($arg, $w)),+] $($fext)?);
                        let out = model_methods!(@out $($out)?);
                        model_methods!(@run $how batch, py, self, (stringify!($name), $quantity), &[$($dim),*], out, $kernel)
                    })
                }
            )*
            $($by_hand)*
        }
    };
    (@gather $self:ident [$(($arg:ident, $w:ident)),+]) => {
        Batch::gather(&[$((stringify!($arg), &$arg, &[$w] as &[usize])),+])?
    };
    (@gather $self:ident [$(($arg:ident, $w:ident)),+] $fext:ident) => {
        $self.gather_dynamics([$((stringify!($arg), &$arg)),+], $fext.as_ref())?
    };
    (@run kernel $batch:ident, $($args:expr),+) => {
        $batch.run_kernel($($args),+).map(Bound::into_any)
    };
    // a scalar per state: a Python float for a single state (no 0-d array), else an array
    (@run scalar $batch:ident, $py:expr, $m:expr, $what:expr, $dims:expr, $out:expr, $kernel:expr) => {{
        let _none: Option<Bound<'_, PyAny>> = $out;
        $batch.run_scalar($py, $m, $what, $kernel)
    }};
    // one state at a time; no `out=` (a row of this form never has one)
    (@run per_state $batch:ident, $py:expr, $m:expr, $what:expr, $dims:expr, $out:expr, $kernel:expr) => {{
        let _none: Option<Bound<'_, PyAny>> = $out;
        $batch.run($py, $m, $what, $dims, $kernel).map(Bound::into_any)
    }};
    (@out) => {
        None
    };
    (@out $out:ident) => {
        $out
    };
}

model_methods! {
    |n, nq|
    /// tau (n,) | (N, n): recursive Newton-Euler with gravity, friction, armature and f_ext.
    fn inverse_dynamics(q: nq, qd: n, qdd: n; f_ext) -> "tau" [n], out = kernel kernels::InverseDynamics;
    /// qdd (n,) | (N, n): articulated-body algorithm; RuntimeError for a singular mass matrix.
    fn forward_dynamics(q: nq, qd: n, tau: n; f_ext) -> "qdd" [n], out = kernel kernels::ForwardDynamics;
    /// M (n, n) | (N, n, n): composite-rigid-body algorithm, exactly symmetric.
    fn mass_matrix(q: nq) -> "M" [n, n], out = kernel kernels::MassMatrix;
    /// M^-1 (n, n) | (N, n, n).
    fn mass_matrix_inverse(q: nq) -> "M^-1" [n, n], out = kernel kernels::MassMatrixInverse;
    /// C (n, n) | (N, n, n): the Christoffel-consistent Coriolis matrix.
    fn coriolis_matrix(q: nq, qd: n) -> "C" [n, n], out = kernel kernels::Coriolis;
    /// c[i, j, k] (n, n, n) | (N, n, n, n): Christoffel symbols of the first kind.
    fn christoffel(q: nq) -> "c" [n, n, n] = kernel kernels::Christoffel;
    /// g (n,) | (N, n).
    fn gravity_torque(q: nq) -> "g" [n], out = kernel kernels::Gravity;
    /// C qd + g (n,) | (N, n), without friction.
    fn bias_torque(q: nq, qd: n) -> "bias" [n], out = kernel kernels::Bias;
    /// K, a float | (N,).
    fn kinetic_energy(q: nq, qd: n) -> "K" [] = scalar kernels::KineticEnergy;
    /// P, a float | (N,).
    fn potential_energy(q: nq) -> "P" [] = scalar kernels::PotentialEnergy;
    /// Y (n, 10 n) | (N, n, 10 n).
    fn regressor(q: nq, qd: n, qdd: n) -> "Y" [n, 10 * n] = kernel kernels::Regressor;
    /// Centre of mass (3,) | (N, 3) in base coordinates.
    fn center_of_mass(q: nq) -> "com" [3] = per_state |model, data, x, out| {
        out.copy_from_slice(algorithms::center_of_mass(model, data, x[0])?.as_slice());
        Ok(())
    };
    /// Centroidal momentum matrix A_G (6, n) | (N, 6, n): [linear; angular about the centre of mass], base axes.
    fn centroidal_momentum_matrix(q: nq) -> "A_G" [6, n] = per_state |model, data, x, out| {
        algorithms::centroidal_momentum_matrix(model, data, x[0], out)?;
        Ok(())
    };
    /// Spatial momentum [p; L about the base origin] (6,) | (N, 6), base axes.
    fn momentum(q: nq, qd: n) -> "h" [6] = per_state |model, data, x, out| {
        out.copy_from_slice(&algorithms::spatial_momentum(model, data, x[0], x[1]).to_array());
        Ok(())
    };

    by_hand {
        /// The model of a robot's joints, each a mapping taken whole (see `_core.pyi`):
        /// `records::build` converts them and the core's `ModelBuilder` expands and checks them.
        #[new]
        #[pyo3(signature = (joints, gravity, frames=Vec::new()))]
        fn new(
            joints: Vec<Bound<'_, PyDict>>,
            gravity: Bound<'_, PyAny>,
            frames: Vec<(i64, Bound<'_, PyAny>)>,
        ) -> PyResult<Self> {
            guarded("Model.__new__", || {
                let model = crate::records::build(&joints, &gravity, &frames)?;
                let data = Mutex::new(Data::new(&model));
                Ok(Self { model, data })
            })
        }

        /// This model with external wrenches taken about link-frame origins: `origins` (n, 3), body
        /// i's link-frame origin in body i's frame (the core's `Model::with_link_origins`).
        fn with_link_origins(&self, origins: PyReadonlyArrayDyn<f64>) -> PyResult<Self> {
            guarded("Model.with_link_origins", || {
                let u = vec_of("origins", &origins, &[self.n(), 3])?;
                let model = self
                    .model
                    .clone()
                    .with_link_origins(u.chunks(3).map(Vec3::from_column_slice).collect())
                    .map_err(core_err)?;
                let data = Mutex::new(Data::new(&model));
                Ok(Self { model, data })
            })
        }

        /// The body that carries each link, in joint order (the core's `Model::link_bodies`: a
        /// multi-DOF joint's last body), as an int64 array (links,).
        #[getter]
        fn link_bodies<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
            let bodies: Vec<i64> = self.model.link_bodies().iter().map(|&b| b as i64).collect();
            PyArray1::from_vec(py, bodies)
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
            q: Bound<'py, PyAny>,
            frames: Bound<'py, PyArray1<i64>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.frame_poses", || {
                // SAFETY: read under the GIL with no Python code running, so nothing writes to it meanwhile
                let ids = unsafe { frames.as_array() }
                    .iter()
                    .map(|&f| self.frame(f))
                    .collect::<PyResult<Vec<_>>>()?;
                self.poses(py, "frame_poses", &q, &ids, &[ids.len(), 4, 4])
            })
        }

        /// Pose of one frame: (4, 4) or (N, 4, 4) (`frame_poses` of one frame, without the frames'
        /// axis: no id array to build and no view to take per call).
        fn frame_pose<'py>(&self, py: Python<'py>, q: Bound<'py, PyAny>, frame: i64) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.frame_pose", || self.poses(py, "frame_pose", &q, &[self.frame(frame)?], &[4, 4]))
        }

        /// Jacobian (6, n) or (N, 6, n) of a frame or a point fixed in it.
        #[pyo3(signature = (q, frame, reference, point=None))]
        fn jacobian<'py>(
            &self,
            py: Python<'py>,
            q: Bound<'py, PyAny>,
            frame: i64,
            reference: &str,
            point: Option<PyReadonlyArrayDyn<f64>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.jacobian", || {
                let (f, r, p) = (self.frame(frame)?, conv::reference(reference)?, conv::point(point)?);
                let (n, nq, q) = (self.n(), self.model.nq, f64_array("q", &q)?);
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
            q: Bound<'py, PyAny>,
            frame: i64,
            reference: &str,
            point: Option<PyReadonlyArrayDyn<f64>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.jacobian_hessian", || {
                let (f, r, p) = (self.frame(frame)?, conv::reference(reference)?, conv::point(point)?);
                let (n, nq, q) = (self.n(), self.model.nq, f64_array("q", &q)?);
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
            q: Bound<'py, PyAny>,
            qd: Bound<'py, PyAny>,
            frame: i64,
            reference: &str,
            point: Option<PyReadonlyArrayDyn<f64>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.frame_velocity", || {
                let (f, r, p) = (self.frame(frame)?, conv::reference(reference)?, conv::point(point)?);
                let (n, nq, q, qd) = (self.n(), self.model.nq, f64_array("q", &q)?, f64_array("qd", &qd)?);
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
            q: Bound<'py, PyAny>,
            qd: Bound<'py, PyAny>,
            frame: i64,
            reference: &str,
            point: Option<PyReadonlyArrayDyn<f64>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.jdot_qd", || {
                let (f, r, p) = (self.frame(frame)?, conv::reference(reference)?, conv::point(point)?);
                let (n, nq, q, qd) = (self.n(), self.model.nq, f64_array("q", &q)?, f64_array("qd", &qd)?);
                let batch = Batch::gather(&[("q", &q, &[nq]), ("qd", &qd, &[n])])?;
                batch.run(py, self, ("jdot_qd", "dJ/dt qd"), &[6], |model, data, x, out| {
                    out.copy_from_slice(&algorithms::jacobian_dot_qd(model, data, x[0], x[1], f, r, p.as_ref()).to_array());
                    Ok(())
                })
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
                let n = self.n();
                let batch = self.gather_dynamics([("q", &q), ("qd", &qd), ("qdd", &qdd)], f_ext.as_ref())?;
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
                let n = self.n();
                let batch = self.gather_dynamics([("q", &q), ("qd", &qd), ("tau", &tau)], f_ext.as_ref())?;
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

        /// This model with closed loops, each `(frame_a, frame_b, kind, name)` (kind "point" or
        /// "weld"), checked by the core's `Model::with_loops`.
        fn with_loops(&self, loops: Vec<(i64, i64, String, String)>) -> PyResult<Self> {
            guarded("Model.with_loops", || {
                let mut records = Vec::with_capacity(loops.len());
                for (a, b, kind, name) in loops {
                    records.push(Loop {
                        frame_a: self.frame(a)?,
                        frame_b: self.frame(b)?,
                        kind: LoopKind::from_name(&kind).map_err(core_err)?,
                        name,
                    });
                }
                let model = self.model.clone().with_loops(records).map_err(core_err)?;
                let data = Mutex::new(Data::new(&model));
                Ok(Self { model, data })
            })
        }

        /// Constraint rows m of the loops.
        #[getter]
        fn loop_rows(&self) -> usize {
            self.model.loop_rows()
        }

        /// The closure residual r (m,) | (N, m): per loop p_a - p_b, then R_b log3(R_b^T R_a) for a weld.
        fn loop_residual<'py>(&self, py: Python<'py>, q: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.loop_residual", || {
                let q = f64_array("q", &q)?;
                let batch = Batch::gather(&[("q", &q, &[self.model.nq])])?;
                batch.run(py, self, ("loop_residual", "r"), &[self.model.loop_rows()], |model, data, x, out| {
                    constraints::loop_residual(model, data, x[0], out);
                    Ok(())
                })
            })
        }

        /// The loops' Jacobian J (m, n) | (N, m, n), base axes.
        fn loop_jacobian<'py>(&self, py: Python<'py>, q: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.loop_jacobian", || {
                let q = f64_array("q", &q)?;
                let batch = Batch::gather(&[("q", &q, &[self.model.nq])])?;
                let shape = [self.model.loop_rows(), self.n()];
                batch.run(py, self, ("loop_jacobian", "J"), &shape, |model, data, x, out| {
                    constraints::loop_jacobian(model, data, x[0], out);
                    Ok(())
                })
            })
        }

        /// gamma = dJ/dt qd (m,) | (N, m).
        fn loop_gamma<'py>(
            &self,
            py: Python<'py>,
            q: Bound<'py, PyAny>,
            qd: Bound<'py, PyAny>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.loop_gamma", || {
                let (q, qd) = (f64_array("q", &q)?, f64_array("qd", &qd)?);
                let batch = Batch::gather(&[("q", &q, &[self.model.nq]), ("qd", &qd, &[self.n()])])?;
                batch.run(py, self, ("loop_gamma", "gamma"), &[self.model.loop_rows()], |model, data, x, out| {
                    constraints::loop_gamma(model, data, x[0], x[1], out);
                    Ok(())
                })
            })
        }

        /// [qdd; lambda] (n + m,) | (N, n + m): M qdd + h = tau + J^T lambda, J qdd + gamma = 0
        /// (the core's proximal solve, over SIMD lanes for a batch).
        #[pyo3(signature = (q, qd, tau, f_ext=None))]
        fn constrained_forward_dynamics<'py>(
            &self,
            py: Python<'py>,
            q: Bound<'py, PyAny>,
            qd: Bound<'py, PyAny>,
            tau: Bound<'py, PyAny>,
            f_ext: Option<Bound<'py, PyAny>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.constrained_forward_dynamics", || {
                let (q, qd, tau) = (f64_array("q", &q)?, f64_array("qd", &qd)?, f64_array("tau", &tau)?);
                let f_ext = f_ext.map(|f| f64_array("f_ext", &f)).transpose()?;
                let batch = self.gather_dynamics([("q", &q), ("qd", &qd), ("tau", &tau)], f_ext.as_ref())?;
                let width = self.n() + self.model.loop_rows();
                let what = ("constrained_forward_dynamics", "[qdd; lambda]");
                batch.run_kernel(py, self, what, &[width], None, kernels::ConstrainedForwardDynamics)
            })
        }

        /// tau (n,) | (N, n), zero off the `actuated` velocity columns, producing the closed motion qdd.
        #[pyo3(signature = (q, qd, qdd, actuated, f_ext=None))]
        fn constrained_inverse_dynamics<'py>(
            &self,
            py: Python<'py>,
            q: Bound<'py, PyAny>,
            qd: Bound<'py, PyAny>,
            qdd: Bound<'py, PyAny>,
            actuated: Vec<usize>,
            f_ext: Option<Bound<'py, PyAny>>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.constrained_inverse_dynamics", || {
                let (q, qd, qdd) = (f64_array("q", &q)?, f64_array("qd", &qd)?, f64_array("qdd", &qdd)?);
                let f_ext = f_ext.map(|f| f64_array("f_ext", &f)).transpose()?;
                let batch = self.gather_dynamics([("q", &q), ("qd", &qd), ("qdd", &qdd)], f_ext.as_ref())?;
                batch.run(py, self, ("constrained_inverse_dynamics", "tau"), &[self.n()], |model, data, x, out| {
                    constraints::constrained_inverse_dynamics(model, data, x[0], x[1], x[2], optional(x, 3), &actuated, out)
                })
            })
        }

        /// A configuration (nq,) | (N, nq) near q closing the loops, the `hold` velocity columns fixed.
        #[pyo3(signature = (q, hold, tolerance, max_iter))]
        fn project_configuration<'py>(
            &self,
            py: Python<'py>,
            q: Bound<'py, PyAny>,
            hold: Vec<usize>,
            tolerance: f64,
            max_iter: usize,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.project_configuration", || {
                let q = f64_array("q", &q)?;
                let batch = Batch::gather(&[("q", &q, &[self.model.nq])])?;
                let nq = self.model.nq;
                batch.run(py, self, ("project_configuration", "q"), &[nq], |model, data, x, out| {
                    constraints::project_configuration(model, data, x[0], &hold, tolerance, max_iter, out).map(|_| ())
                })
            })
        }

        /// The velocity (n,) | (N, n) nearest qd with J qd = 0.
        fn project_velocity<'py>(
            &self,
            py: Python<'py>,
            q: Bound<'py, PyAny>,
            qd: Bound<'py, PyAny>,
        ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
            guarded("Model.project_velocity", || {
                let (q, qd) = (f64_array("q", &q)?, f64_array("qd", &qd)?);
                let batch = Batch::gather(&[("q", &q, &[self.model.nq]), ("qd", &qd, &[self.n()])])?;
                batch.run(py, self, ("project_velocity", "qd"), &[self.n()], |model, data, x, out| {
                    constraints::project_velocity(model, data, x[0], x[1], out);
                    Ok(())
                })
            })
        }
    }
}
