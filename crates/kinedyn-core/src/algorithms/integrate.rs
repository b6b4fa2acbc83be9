//! Fixed-step integration of the equations of motion over a whole trajectory.
//!
//! State `x = (q, qd)`, `dx/dt = (qd, qdd)`, `qdd = aba(q, qd, tau(t, q, qd))` (LaValle eq. 13.148,
//! the phase form of `M qdd + C qd + g + friction = tau`). The torque comes from a [`TorqueFn`]:
//! zero, a constant, samples held or interpolated over each step, or any closure (the Python
//! binding passes a controller through one).
//!
//! Methods (step `h`, `t_k = t0 + k h`):
//! - `Rk4`, classical Runge-Kutta (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.1, Table 1.2):
//!   `k1 = f(t_k, x_k)`, `k2 = f(t_k + h/2, x_k + h/2 k1)`, `k3 = f(t_k + h/2, x_k + h/2 k2)`,
//!   `k4 = f(t_k + h, x_k + h k3)`, `x_{k+1} = x_k + h/6 (k1 + 2 k2 + 2 k3 + k4)`; global error O(h^4).
//! - `SemiImplicitEuler` (symplectic Euler; Hairer, Lubich & Wanner, *Geometric Numerical
//!   Integration*, §VI.3): `qd_{k+1} = qd_k + h qdd(q_k, qd_k)`, `q_{k+1} = q_k + h qd_{k+1}`;
//!   first order, but the energy of a conservative system stays bounded instead of drifting.
//! - `Euler` (explicit): `x_{k+1} = x_k + h f(t_k, x_k)`; first order, energy grows. For comparison.
//!
//! Recorded per sample `k` (every `record_every` steps, and the last): `q_k`, `qd_k`, the torque
//! applied at `t_k` and `qdd_k = aba(q_k, qd_k, tau_k)`. A step that produces a non-finite state or a
//! joint speed above `max_speed`, a torque that is not finite, or a singular mass matrix stops the
//! run: the samples before it are kept and a [`Failure`] says when and where.
//!
//! | symbol      | here                  | meaning                                          |
//! |-------------|-----------------------|--------------------------------------------------|
//! | `h`         | `settings.dt`         | step (s)                                         |
//! | `x_k`       | `q`, `qd`             | state at `t_k`, each length `n`                  |
//! | `k1..k4`    | `kq[s]`, `kv[s]`      | stage derivatives of `q` and `qd`                |
//! | `tau`       | `tau`                 | joint torque at a stage, length `n`              |

use super::aba::aba;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;

/// The fixed-step schemes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Rk4,
    SemiImplicitEuler,
    Euler,
}

impl Method {
    /// Evaluations of the dynamics per step.
    pub fn stages(self) -> usize {
        match self {
            Method::Rk4 => 4,
            Method::SemiImplicitEuler | Method::Euler => 1,
        }
    }
}

/// Step size, length and stop conditions of a run.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub method: Method,
    /// Step `h` (s), > 0.
    pub dt: f64,
    /// Number of steps; the trajectory has `steps / record_every + 1` samples (the last step is
    /// always recorded).
    pub steps: usize,
    /// Start time (s).
    pub t0: f64,
    /// Record every `record_every`-th step (>= 1).
    pub record_every: usize,
    /// Evaluate the torque once per step, at `(t_k, x_k)`, and hold it over the stages (a digital
    /// controller at the integration rate); otherwise at every stage (a continuous-time law).
    pub hold: bool,
    /// A joint speed above this (rad/s or m/s) counts as a blow-up.
    pub max_speed: f64,
}

impl Settings {
    pub fn samples(&self) -> usize {
        self.steps.div_ceil(self.record_every.max(1)) + 1
    }
}

/// Why a run stopped early.
#[derive(Clone, Debug, PartialEq)]
pub enum FailureKind {
    /// A joint position or speed became NaN or infinite.
    NonFinite,
    /// A joint speed exceeded `max_speed` (value attached).
    Diverged(f64),
    /// The torque source returned a non-finite value.
    Torque(f64),
    /// The torque source reported an error (message attached).
    Source(String),
    /// The mass matrix was singular (message from the articulated-body algorithm).
    Singular(String),
}

/// When and where a run stopped: during step `step` (from `t` to `t + dt`), at joint `joint`.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub step: usize,
    pub t: f64,
    pub joint: Option<usize>,
    pub kind: FailureKind,
}

/// How a run ended: `steps` steps were completed and `samples` samples written.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    pub steps: usize,
    pub samples: usize,
    pub failure: Option<Failure>,
}

/// The torque source: `tau(t, q, qd, out)`; an `Err` stops the run with [`FailureKind::Source`].
pub trait TorqueFn {
    fn torque(&mut self, step: usize, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) -> std::result::Result<(), String>;
}

impl<F: FnMut(usize, f64, &[f64], &[f64], &mut [f64]) -> std::result::Result<(), String>> TorqueFn for F {
    fn torque(&mut self, step: usize, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) -> std::result::Result<(), String> {
        self(step, t, q, qd, out)
    }
}

/// Torque from samples at `t0 + k dt`, `k = 0..`, row-major `(samples, n)`: one row is a constant,
/// no rows is zero. `linear`: interpolate between samples `k` and `k + 1` (needs `steps + 1` rows);
/// else hold sample `k` over step `k` (zero-order hold; needs `steps` rows).
pub struct Sampled<'a> {
    pub values: &'a [f64],
    pub n: usize,
    pub t0: f64,
    pub dt: f64,
    pub linear: bool,
}

impl TorqueFn for Sampled<'_> {
    fn torque(&mut self, step: usize, t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]) -> std::result::Result<(), String> {
        let n = self.n;
        let rows = self.values.len() / n.max(1);
        match rows {
            0 => out.fill(0.0),
            1 => out.copy_from_slice(&self.values[..n]),
            _ => {
                let k = step.min(rows - 1);
                let row = |k: usize| &self.values[k * n..(k + 1) * n];
                if self.linear && k + 1 < rows {
                    // tau(t) = (1 - s) tau_k + s tau_{k+1},  s = (t - t_k) / dt
                    let s = ((t - (self.t0 + k as f64 * self.dt)) / self.dt).clamp(0.0, 1.0);
                    for ((o, a), b) in out.iter_mut().zip(row(k)).zip(row(k + 1)) {
                        *o = (1.0 - s) * a + s * b;
                    }
                } else {
                    out.copy_from_slice(row(k));
                }
            }
        }
        Ok(())
    }
}

/// Output arrays, each row-major `(settings.samples(), n)`.
pub struct Record<'a> {
    pub q: &'a mut [f64],
    pub qd: &'a mut [f64],
    pub qdd: &'a mut [f64],
    pub tau: &'a mut [f64],
}

/// Scratch of one run (allocated once per trajectory).
struct Stage {
    q: Vec<f64>,
    qd: Vec<f64>,
    tau: Vec<f64>,
    kq: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
}

/// `qdd = aba(q, qd, tau(t, q, qd))` into `kv`, with the torque into `tau` unless `hold`.
#[allow(clippy::too_many_arguments)]
fn derivative(
    model: &Model,
    data: &mut Data,
    source: &mut dyn TorqueFn,
    step: usize,
    t: f64,
    q: &[f64],
    qd: &[f64],
    tau: &mut [f64],
    evaluate_torque: bool,
    kv: &mut [f64],
) -> std::result::Result<(), Failure> {
    let fail = |joint, kind| Failure { step, t, joint, kind };
    if evaluate_torque {
        source.torque(step, t, q, qd, tau).map_err(|m| fail(None, FailureKind::Source(m)))?;
        if let Some(j) = tau.iter().position(|x| !x.is_finite()) {
            return Err(fail(Some(j), FailureKind::Torque(tau[j])));
        }
    }
    match aba(model, data, q, qd, tau, None) {
        Ok(qdd) => {
            kv.copy_from_slice(qdd);
            Ok(())
        }
        Err(e) => Err(fail(singular_joint(&e), FailureKind::Singular(e.to_string()))),
    }
}

fn singular_joint(e: &Error) -> Option<usize> {
    let Error::SingularMassMatrix(m) = e else { return None };
    m.strip_prefix("joint ")?.split_whitespace().next()?.parse().ok()
}

/// Check a state after a step: finite, and no joint faster than `max_speed`.
fn check_state(q: &[f64], qd: &[f64], max_speed: f64, step: usize, t: f64) -> std::result::Result<(), Failure> {
    for (j, (a, v)) in q.iter().zip(qd).enumerate() {
        if !a.is_finite() || !v.is_finite() {
            return Err(Failure { step, t, joint: Some(j), kind: FailureKind::NonFinite });
        }
        if v.abs() > max_speed {
            return Err(Failure { step, t, joint: Some(j), kind: FailureKind::Diverged(*v) });
        }
    }
    Ok(())
}

/// Integrate from `(q0, qd0)` at `settings.t0` over `settings.steps` steps, writing samples into
/// `out`. `Err` only for invalid inputs (lengths, `dt`); a blow-up is an [`Outcome::failure`].
pub fn integrate(
    model: &Model,
    data: &mut Data,
    settings: &Settings,
    q0: &[f64],
    qd0: &[f64],
    source: &mut dyn TorqueFn,
    out: Record<'_>,
) -> Result<Outcome> {
    let n = model.n;
    let h = settings.dt;
    let every = settings.record_every;
    if !(h > 0.0) || !h.is_finite() {
        return Err(Error::InvalidInput(format!("the step dt must be a positive finite number, got {h}")));
    }
    if every == 0 {
        return Err(Error::InvalidInput("record_every must be at least 1".into()));
    }
    if q0.len() != n || qd0.len() != n {
        return Err(Error::InvalidInput(format!("q0 and qd0 must have {n} entries, got {} and {}", q0.len(), qd0.len())));
    }
    let need = settings.samples() * n;
    if out.q.len() < need || out.qd.len() < need || out.qdd.len() < need || out.tau.len() < need {
        return Err(Error::InvalidInput(format!("output arrays must hold {} samples of {n} values", settings.samples())));
    }
    let mut q = q0.to_vec();
    let mut qd = qd0.to_vec();
    let zeros = || vec![0.0; n];
    let mut s = Stage { q: zeros(), qd: zeros(), tau: zeros(), kq: [zeros(), zeros(), zeros(), zeros()], kv: [zeros(), zeros(), zeros(), zeros()] };
    let mut samples = 0;
    let t_of = |k: usize| settings.t0 + k as f64 * h;

    // write sample `samples` from the state at step k, using k1 = (qd, qdd) and tau evaluated there
    let mut record = |samples: &mut usize, q: &[f64], qd: &[f64], qdd: &[f64], tau: &[f64]| {
        let r = *samples * n..(*samples + 1) * n;
        out.q[r.clone()].copy_from_slice(q);
        out.qd[r.clone()].copy_from_slice(qd);
        out.qdd[r.clone()].copy_from_slice(qdd);
        out.tau[r].copy_from_slice(tau);
        *samples += 1;
    };

    if let Err(f) = check_state(&q, &qd, f64::INFINITY, 0, settings.t0) {
        return Err(Error::InvalidInput(format!("the initial state has a non-finite value at joint {}", f.joint.unwrap_or(0))));
    }
    for k in 0..=settings.steps {
        let t = t_of(k);
        // k1 = f(t_k, x_k): also the recorded qdd_k and tau_k
        let (kv0, rest) = s.kv.split_at_mut(1);
        if let Err(f) = derivative(model, data, source, k, t, &q, &qd, &mut s.tau, true, &mut kv0[0]) {
            return Ok(Outcome { steps: k, samples, failure: Some(f) });
        }
        if k % every == 0 || k == settings.steps {
            record(&mut samples, &q, &qd, &kv0[0], &s.tau);
        }
        if k == settings.steps {
            break;
        }
        let evaluate = !settings.hold;
        let step = match settings.method {
            Method::Euler => {
                // x_{k+1} = x_k + h f(t_k, x_k)
                for j in 0..n {
                    q[j] += h * qd[j];
                    qd[j] += h * kv0[0][j];
                }
                Ok(())
            }
            Method::SemiImplicitEuler => {
                // qd_{k+1} = qd_k + h qdd_k ;  q_{k+1} = q_k + h qd_{k+1}
                for j in 0..n {
                    qd[j] += h * kv0[0][j];
                    q[j] += h * qd[j];
                }
                Ok(())
            }
            Method::Rk4 => (|| {
                let kq = &mut s.kq;
                kq[0].copy_from_slice(&qd);
                // k2 = f(t + h/2, x + h/2 k1) ;  k3 = f(t + h/2, x + h/2 k2) ;  k4 = f(t + h, x + h k3)
                for (stage, (c, dt_stage)) in [(0.5 * h, 0.5 * h), (0.5 * h, 0.5 * h), (h, h)].into_iter().enumerate() {
                    let prev_v = if stage == 0 { &kv0[0] } else { &rest[stage - 1] };
                    for j in 0..n {
                        s.q[j] = q[j] + c * kq[stage][j];
                        s.qd[j] = qd[j] + c * prev_v[j];
                    }
                    kq[stage + 1].copy_from_slice(&s.qd);
                    derivative(model, data, source, k, t + dt_stage, &s.q, &s.qd, &mut s.tau, evaluate, &mut rest[stage])?;
                }
                // x_{k+1} = x_k + h/6 (k1 + 2 k2 + 2 k3 + k4)
                for j in 0..n {
                    q[j] += h / 6.0 * (kq[0][j] + 2.0 * kq[1][j] + 2.0 * kq[2][j] + kq[3][j]);
                    qd[j] += h / 6.0 * (kv0[0][j] + 2.0 * rest[0][j] + 2.0 * rest[1][j] + rest[2][j]);
                }
                Ok(())
            })(),
        };
        let checked = step.and_then(|_| check_state(&q, &qd, settings.max_speed, k, t));
        if let Err(f) = checked {
            return Ok(Outcome { steps: k, samples, failure: Some(f) });
        }
    }
    Ok(Outcome { steps: settings.steps, samples, failure: None })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::random_model;

    fn run(model: &Model, method: Method, dt: f64, steps: usize, q0: &[f64], qd0: &[f64]) -> (Outcome, Vec<f64>, Vec<f64>) {
        let n = model.n;
        let settings = Settings { method, dt, steps, t0: 0.0, record_every: 1, hold: false, max_speed: 1e6 };
        let m = settings.samples() * n;
        let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut data = Data::new(model);
        let mut zero = Sampled { values: &[], n, t0: 0.0, dt, linear: false };
        let out = integrate(model, &mut data, &settings, q0, qd0, &mut zero, Record { q: &mut q, qd: &mut qd, qdd: &mut qdd, tau: &mut tau }).unwrap();
        (out, q, qd)
    }

    /// A point mass on a massless rod about a horizontal axis: q'' = -(g / l) sin q (no armature).
    fn pendulum() -> Model {
        use crate::spatial::{Inertia, Mat3, Transform, Vec3};
        use crate::{Joint, JointKind};
        let inertia = Inertia::new(1.0, Vec3::new(1.0, 0.0, 0.0), Mat3::zeros() + Mat3::from_diagonal(&Vec3::new(0.0, 1.0, 1.0)));
        Model::new(
            vec![None],
            vec![Joint { kind: JointKind::Revolute, axis: Vec3::z() }],
            vec![0.0],
            vec![Transform::identity()],
            vec![inertia],
            vec![0.0],
            vec![0.0],
            vec![0.0],
            Vec3::new(0.0, -9.81, 0.0),
            vec![],
        )
        .unwrap()
    }

    #[test]
    fn rk4_is_fourth_order_on_a_pendulum() {
        // error(h) / error(h/2) -> 2^4 against a fine reference
        let model = pendulum();
        let (_, q_ref, _) = run(&model, Method::Rk4, 1e-4, 20_000, &[1.0], &[0.0]);
        // max error over the common sample times t = 0.04 k
        let err = |dt: f64| {
            let steps = (2.0 / dt).round() as usize;
            let (_, q, _) = run(&model, Method::Rk4, dt, steps, &[1.0], &[0.0]);
            let (every, every_ref) = ((0.04 / dt).round() as usize, 400);
            (0..=50).map(|k| (q[k * every] - q_ref[k * every_ref]).abs()).fold(0.0, f64::max)
        };
        let ratio = err(0.02) / err(0.01);
        assert!((ratio - 16.0).abs() < 2.0, "RK4 error ratio {ratio}");
        let reference = *q_ref.last().unwrap();
        let (_, q_e, _) = run(&model, Method::SemiImplicitEuler, 0.01, 200, &[1.0], &[0.0]);
        let (_, q_e2, _) = run(&model, Method::SemiImplicitEuler, 0.005, 400, &[1.0], &[0.0]);
        let ratio = (q_e[200] - reference).abs() / (q_e2[400] - reference).abs();
        assert!((ratio - 2.0).abs() < 0.5, "semi-implicit Euler error ratio {ratio}");
    }

    #[test]
    fn energy_drift_by_method_on_a_random_chain() {
        let mut model = random_model(3, 5, false);
        model.viscous.fill(0.0);
        model.coulomb.fill(0.0);
        let n = model.n;
        let q0 = vec![0.3; n];
        let qd0 = vec![0.5; n];
        let mut data = Data::new(&model);
        let mut energy = |q: &[f64], qd: &[f64]| {
            super::super::energy::kinetic_energy(&model, &mut data, q, qd) + super::super::energy::potential_energy(&model, &mut data, q)
        };
        let e0 = energy(&q0, &qd0);
        let drift = |method| {
            let (o, q, qd) = run(&model, method, 1e-3, 2000, &q0, &qd0);
            assert!(o.failure.is_none(), "{:?}", o.failure);
            (q, qd)
        };
        let (q, qd) = drift(Method::Rk4);
        let e_rk4 = energy(&q[2000 * n..], &qd[2000 * n..]);
        assert!(((e_rk4 - e0) / e0.abs().max(1.0)).abs() < 1e-7, "RK4 drift {}", e_rk4 - e0);
        let (q, qd) = drift(Method::Euler);
        let e_euler = energy(&q[2000 * n..], &qd[2000 * n..]);
        assert!((e_euler - e0).abs() > 100.0 * (e_rk4 - e0).abs(), "explicit Euler should drift more");
    }

    #[test]
    fn blow_up_is_reported_with_step_and_joint() {
        let model = pendulum();
        let n = model.n;
        let settings = Settings { method: Method::Rk4, dt: 1e-3, steps: 100, t0: 0.0, record_every: 1, hold: false, max_speed: 1e6 };
        let m = settings.samples() * n;
        let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut data = Data::new(&model);
        // a torque that becomes infinite at t >= 0.05
        let mut source = |_k: usize, t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]| {
            out[0] = if t >= 0.05 { f64::INFINITY } else { 0.0 };
            Ok(())
        };
        let out = integrate(&model, &mut data, &settings, &[0.0], &[0.0], &mut source, Record { q: &mut q, qd: &mut qd, qdd: &mut qdd, tau: &mut tau }).unwrap();
        let f = out.failure.expect("must fail");
        assert_eq!(f.joint, Some(0));
        assert!(matches!(f.kind, FailureKind::Torque(_)));
        assert!((f.t - 0.05).abs() < 1e-3 + 1e-12, "{f:?}");
        assert_eq!(out.samples, out.steps + 1);
        // a huge torque: diverges past max_speed
        let mut source = |_k: usize, _t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]| {
            out[0] = 1e12;
            Ok(())
        };
        let out = integrate(&model, &mut data, &settings, &[0.0], &[0.0], &mut source, Record { q: &mut q, qd: &mut qd, qdd: &mut qdd, tau: &mut tau }).unwrap();
        assert!(matches!(out.failure.unwrap().kind, FailureKind::Diverged(_)));
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let model = pendulum();
        let settings = Settings { method: Method::Rk4, dt: 0.0, steps: 10, t0: 0.0, record_every: 1, hold: false, max_speed: 1e6 };
        let mut v = vec![0.0; 11];
        let (mut a, mut b, mut c) = (v.clone(), v.clone(), v.clone());
        let mut zero = Sampled { values: &[], n: 1, t0: 0.0, dt: 1.0, linear: false };
        let r = integrate(&model, &mut Data::new(&model), &settings, &[0.0], &[0.0], &mut zero, Record { q: &mut v, qd: &mut a, qdd: &mut b, tau: &mut c });
        assert!(matches!(r, Err(Error::InvalidInput(_))));
    }
}
