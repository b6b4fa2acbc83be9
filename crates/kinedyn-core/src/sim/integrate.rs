//! The runner: one fixed-step trajectory, its inputs checked, stages evaluated, limits applied,
//! blow-ups caught and samples recorded (the schemes and their sources are in `sim/mod.rs`).
//!
//! | symbol      | here                  | meaning                                          |
//! |-------------|-----------------------|--------------------------------------------------|
//! | `h`         | `settings.dt`         | step (s)                                         |
//! | `x_k`       | `q`, `qd`             | state at `t_k`, each length `n`                  |
//! | `k1..k4`    | `kq[s]`, `kv[s]`      | stage derivatives of `q` and `qd`                |
//! | `tau`       | `tau`                 | joint torque at a stage, length `n`              |

use super::implicit::{implicit_step, ImplicitScratch};
use std::sync::atomic::Ordering;

use super::{Failure, FailureKind, Limits, Method, Outcome, Record, Settings, TorqueFn};
use crate::algorithms::aba::aba;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Model;

/// Scratch of one run (allocated once per trajectory).
struct Stage {
    /// The source's external wrenches at the last state evaluated (6 n).
    f_ext: Vec<f64>,
    /// RK4's weighted mean velocity (k1 + 2 k2 + 2 k3 + k4) / 6.
    mean: Vec<f64>,
    q: Vec<f64>,
    qd: Vec<f64>,
    tau: Vec<f64>,
    kq: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
}

/// `q = q ⊕ h v` in place (`scratch`: nq numbers).
pub(super) fn step_configuration(model: &Model, q: &mut [f64], v: &[f64], h: f64, scratch: &mut [f64]) {
    model.integrate_configuration(q, v, h, scratch);
    q.copy_from_slice(&scratch[..q.len()]);
}

/// Inelastic stops: a joint beyond a limit goes back on it, and a joint on a limit loses its
/// velocity into the limit.
fn apply_limits(model: &Model, limits: &Limits<'_>, q: &mut [f64], qd: &mut [f64]) {
    // limits per q coordinate; only 1-DOF joints have them (a multi-DOF joint's are infinite)
    for (j, v) in model.scalar_coordinates() {
        if q[j] <= limits.lower[j] {
            q[j] = limits.lower[j];
            qd[v] = qd[v].max(0.0);
        } else if q[j] >= limits.upper[j] {
            q[j] = limits.upper[j];
            qd[v] = qd[v].min(0.0);
        }
    }
}

/// `qdd = aba(q, qd, tau(t, q, qd), f_ext(t, q, qd))` into `kv`, with the torque into `tau` unless
/// `hold` and the source's external wrenches into `f_ext`; returns whether there are any.
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
    f_ext: &mut [f64],
    kv: &mut [f64],
) -> std::result::Result<bool, Failure> {
    let fail = |joint, kind| Failure { step, t, joint, kind };
    if evaluate_torque {
        source
            .torque(step, t, q, qd, tau)
            .map_err(|m| fail(None, FailureKind::Source(m)))?;
        if let Some(j) = tau.iter().position(|x| !x.is_finite()) {
            return Err(fail(Some(j), FailureKind::Torque(tau[j])));
        }
    }
    let wrenches = source
        .wrenches(step, t, q, qd, f_ext)
        .map_err(|m| fail(None, FailureKind::Source(m)))?;
    if let Some(k) = f_ext.iter().position(|x| !x.is_finite()).filter(|_| wrenches) {
        return Err(fail(
            None,
            FailureKind::Source(format!("the external wrench on body {} is not finite", k / 6)),
        ));
    }
    match aba(model, data, q, qd, tau, wrenches.then_some(&*f_ext)) {
        Ok(qdd) => {
            kv.copy_from_slice(qdd);
            Ok(wrenches)
        }
        Err(e) => Err(fail(singular_joint(&e), FailureKind::Singular(e.to_string()))),
    }
}

pub(super) fn singular_joint(e: &Error) -> Option<usize> {
    let Error::SingularMassMatrix { joint, .. } = e else {
        return None;
    };
    Some(*joint)
}

/// Check a state after a step: finite, and no joint faster than `max_speed`.
fn check_state(q: &[f64], qd: &[f64], max_speed: f64, step: usize, t: f64) -> std::result::Result<(), Failure> {
    // joint: the velocity coordinate (the q coordinate when only q is non-finite)
    for (j, v) in qd.iter().enumerate() {
        if !v.is_finite() {
            return Err(Failure {
                step,
                t,
                joint: Some(j),
                kind: FailureKind::NonFinite,
            });
        }
        if v.abs() > max_speed {
            return Err(Failure {
                step,
                t,
                joint: Some(j),
                kind: FailureKind::Diverged(*v),
            });
        }
    }
    if let Some(j) = q.iter().position(|a| !a.is_finite()) {
        return Err(Failure {
            step,
            t,
            joint: Some(j.min(qd.len().saturating_sub(1))),
            kind: FailureKind::NonFinite,
        });
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
    let (n, nq) = (model.n, model.nq);
    let h = settings.dt;
    let every = settings.record_every;
    if !h.is_finite() || h <= 0.0 {
        return Err(Error::InvalidInput(format!(
            "the step dt must be a positive finite number, got {h}"
        )));
    }
    if every == 0 {
        return Err(Error::InvalidInput("record_every must be at least 1".into()));
    }
    if q0.len() != nq || qd0.len() != n {
        return Err(Error::InvalidInput(format!(
            "q0 and qd0 must have {nq} and {n} entries, got {} and {}",
            q0.len(),
            qd0.len()
        )));
    }
    if let Some(l) = &settings.limits {
        if l.lower.len() != nq || l.upper.len() != nq {
            return Err(Error::InvalidInput(format!(
                "joint limits must have {nq} lower and upper values, got {} and {}",
                l.lower.len(),
                l.upper.len()
            )));
        }
        if let Some(j) = (0..nq).find(|&j| l.lower[j].is_nan() || l.upper[j].is_nan() || l.lower[j] > l.upper[j]) {
            return Err(Error::InvalidInput(format!(
                "joint {j} has limits [{}, {}]: lower must not exceed upper",
                l.lower[j], l.upper[j]
            )));
        }
    }
    let need = settings.samples() * n;
    if out.q.len() < settings.samples() * nq || out.qd.len() < need || out.qdd.len() < need || out.tau.len() < need {
        return Err(Error::InvalidInput(format!(
            "output arrays must hold {} samples of {n} values",
            settings.samples()
        )));
    }
    let mut q = q0.to_vec();
    let mut qd = qd0.to_vec();
    let zeros = || vec![0.0; n];
    let mut s = Stage {
        f_ext: vec![0.0; 6 * n],
        mean: zeros(),
        q: vec![0.0; nq],
        qd: zeros(),
        tau: zeros(),
        kq: [zeros(), zeros(), zeros(), zeros()],
        kv: [zeros(), zeros(), zeros(), zeros()],
    };
    let mut next_q = vec![0.0; nq];
    let mut implicit = (settings.method == Method::Implicit).then(|| ImplicitScratch::new(n, nq));
    let mut samples = 0;
    let t_of = |k: usize| settings.t0 + k as f64 * h;

    // write sample `samples` from the state at step k, using k1 = (qd, qdd) and tau evaluated there
    let mut record = |samples: &mut usize, q: &[f64], qd: &[f64], qdd: &[f64], tau: &[f64]| {
        let r = *samples * n..(*samples + 1) * n;
        out.q[*samples * nq..(*samples + 1) * nq].copy_from_slice(q);
        out.qd[r.clone()].copy_from_slice(qd);
        out.qdd[r.clone()].copy_from_slice(qdd);
        out.tau[r].copy_from_slice(tau);
        *samples += 1;
    };

    if let Err(f) = check_state(&q, &qd, f64::INFINITY, 0, settings.t0) {
        return Err(Error::InvalidInput(format!(
            "the initial state has a non-finite value at joint {}",
            f.joint.unwrap_or(0)
        )));
    }
    for k in 0..=settings.steps {
        let t = t_of(k);
        // another thread asked the run to stop (one relaxed load per step: no measurable cost)
        if settings.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Ok(Outcome {
                steps: k,
                samples,
                failure: Some(Failure {
                    step: k,
                    t,
                    joint: None,
                    kind: FailureKind::Cancelled,
                }),
            });
        }
        // k1 = f(t_k, x_k): also the recorded qdd_k and tau_k
        let (kv0, rest) = s.kv.split_at_mut(1);
        let wrenches = match derivative(
            model,
            data,
            source,
            k,
            t,
            &q,
            &qd,
            &mut s.tau,
            true,
            &mut s.f_ext,
            &mut kv0[0],
        ) {
            Ok(w) => w,
            Err(f) => {
                return Ok(Outcome {
                    steps: k,
                    samples,
                    failure: Some(f),
                })
            }
        };
        if k % every == 0 || k == settings.steps {
            record(&mut samples, &q, &qd, &kv0[0], &s.tau);
        }
        if k == settings.steps {
            break;
        }
        let evaluate = !settings.hold;
        let step = match settings.method {
            Method::Euler => {
                // x_{k+1} = x_k + h f(t_k, x_k)  (q_{k+1} = q_k ⊕ h qd_k on a multi-DOF joint)
                step_configuration(model, &mut q, &qd, h, &mut next_q);
                for j in 0..n {
                    qd[j] += h * kv0[0][j];
                }
                Ok(())
            }
            Method::SemiImplicitEuler => {
                // qd_{k+1} = qd_k + h qdd_k ;  q_{k+1} = q_k ⊕ h qd_{k+1}
                for j in 0..n {
                    qd[j] += h * kv0[0][j];
                }
                step_configuration(model, &mut q, &qd, h, &mut next_q);
                Ok(())
            }
            Method::Implicit => {
                let scratch = implicit.as_mut().expect("allocated for the implicit method");
                // the wrenches at (t_k, x_k), from k1
                let f_ext = wrenches.then_some(&s.f_ext[..]);
                implicit_step(
                    model, data, source, scratch, k, t, h, &mut q, &mut qd, &kv0[0], &s.tau, f_ext,
                )
            }
            Method::Rk4 => (|| {
                let kq = &mut s.kq;
                kq[0].copy_from_slice(&qd);
                // k2 = f(t + h/2, x + h/2 k1) ;  k3 = f(t + h/2, x + h/2 k2) ;  k4 = f(t + h, x + h k3)
                for (stage, (c, dt_stage)) in [(0.5 * h, 0.5 * h), (0.5 * h, 0.5 * h), (h, h)].into_iter().enumerate() {
                    let prev_v = if stage == 0 { &kv0[0] } else { &rest[stage - 1] };
                    // stage configuration q ⊕ c k (the stages' velocities are tangent vectors at q)
                    model.integrate_configuration(&q, &kq[stage], c, &mut s.q);
                    for j in 0..n {
                        s.qd[j] = qd[j] + c * prev_v[j];
                    }
                    // RKMK4: the chart's rate dexp⁻¹(v) at Ω = c k_stage (v on 1-DOF joints)
                    for (m, k) in s.mean.iter_mut().zip(&kq[stage]) {
                        *m = c * k;
                    }
                    let (head, tail) = kq.split_at_mut(stage + 1);
                    model.chart_rate(&s.mean, &s.qd, &mut tail[0]);
                    let _ = head;
                    derivative(
                        model,
                        data,
                        source,
                        k,
                        t + dt_stage,
                        &s.q,
                        &s.qd,
                        &mut s.tau,
                        evaluate,
                        &mut s.f_ext,
                        &mut rest[stage],
                    )?;
                }
                // x_{k+1} = x_k + h/6 (k1 + 2 k2 + 2 k3 + k4), q_{k+1} = q_k ⊕ h/6 (k1 + ...): the
                // Runge-Kutta-Munthe-Kaas method (fourth order on the manifold too)
                for j in 0..n {
                    s.mean[j] = (kq[0][j] + 2.0 * kq[1][j] + 2.0 * kq[2][j] + kq[3][j]) / 6.0;
                    qd[j] += h / 6.0 * (kv0[0][j] + 2.0 * rest[0][j] + 2.0 * rest[1][j] + rest[2][j]);
                }
                step_configuration(model, &mut q, &s.mean, h, &mut next_q);
                Ok(())
            })(),
        };
        if let (Ok(()), Some(limits)) = (&step, &settings.limits) {
            apply_limits(model, limits, &mut q, &mut qd);
        }
        let checked = step.and_then(|_| check_state(&q, &qd, settings.max_speed, k, t));
        if let Err(f) = checked {
            return Ok(Outcome {
                steps: k,
                samples,
                failure: Some(f),
            });
        }
    }
    Ok(Outcome {
        steps: settings.steps,
        samples,
        failure: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Sampled;
    use crate::testing::random_model;

    fn run(
        model: &Model,
        method: Method,
        dt: f64,
        steps: usize,
        q0: &[f64],
        qd0: &[f64],
    ) -> (Outcome, Vec<f64>, Vec<f64>) {
        let n = model.n;
        let settings = Settings {
            method,
            dt,
            steps,
            t0: 0.0,
            record_every: 1,
            hold: false,
            max_speed: 1e6,
            limits: None,
            cancel: None,
        };
        let m = settings.samples() * n;
        let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut data = Data::new(model);
        let mut zero = Sampled {
            values: &[],
            n,
            t0: 0.0,
            dt,
            linear: false,
        };
        let out = integrate(
            model,
            &mut data,
            &settings,
            q0,
            qd0,
            &mut zero,
            Record {
                q: &mut q,
                qd: &mut qd,
                qdd: &mut qdd,
                tau: &mut tau,
            },
        )
        .unwrap();
        (out, q, qd)
    }

    /// A point mass on a massless rod about a horizontal axis: q'' = -(g / l) sin q (no armature).
    fn pendulum() -> Model {
        use crate::spatial::{Inertia, Mat3, Transform, Vec3};
        use crate::{Joint, JointKind};
        let inertia = Inertia::new(
            1.0,
            Vec3::new(1.0, 0.0, 0.0),
            Mat3::zeros() + Mat3::from_diagonal(&Vec3::new(0.0, 1.0, 1.0)),
        );
        Model::new(
            vec![None],
            vec![Joint {
                kind: JointKind::Revolute,
                axis: Vec3::z(),
            }],
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
            (0..=50)
                .map(|k| (q[k * every] - q_ref[k * every_ref]).abs())
                .fold(0.0, f64::max)
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
            crate::algorithms::energy::kinetic_energy(&model, &mut data, q, qd)
                + crate::algorithms::energy::potential_energy(&model, &mut data, q)
        };
        let e0 = energy(&q0, &qd0);
        let drift = |method| {
            let (o, q, qd) = run(&model, method, 1e-3, 2000, &q0, &qd0);
            assert!(o.failure.is_none(), "{:?}", o.failure);
            (q, qd)
        };
        let (q, qd) = drift(Method::Rk4);
        let e_rk4 = energy(&q[2000 * n..], &qd[2000 * n..]);
        assert!(
            ((e_rk4 - e0) / e0.abs().max(1.0)).abs() < 1e-7,
            "RK4 drift {}",
            e_rk4 - e0
        );
        let (q, qd) = drift(Method::Euler);
        let e_euler = energy(&q[2000 * n..], &qd[2000 * n..]);
        assert!(
            (e_euler - e0).abs() > 100.0 * (e_rk4 - e0).abs(),
            "explicit Euler should drift more"
        );
    }

    #[test]
    fn blow_up_is_reported_with_step_and_joint() {
        let model = pendulum();
        let n = model.n;
        let settings = Settings {
            method: Method::Rk4,
            dt: 1e-3,
            steps: 100,
            t0: 0.0,
            record_every: 1,
            hold: false,
            max_speed: 1e6,
            limits: None,
            cancel: None,
        };
        let m = settings.samples() * n;
        let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut data = Data::new(&model);
        // a torque that becomes infinite at t >= 0.05
        let mut source = |_k: usize, t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]| {
            out[0] = if t >= 0.05 { f64::INFINITY } else { 0.0 };
            Ok(())
        };
        let out = integrate(
            &model,
            &mut data,
            &settings,
            &[0.0],
            &[0.0],
            &mut source,
            Record {
                q: &mut q,
                qd: &mut qd,
                qdd: &mut qdd,
                tau: &mut tau,
            },
        )
        .unwrap();
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
        let out = integrate(
            &model,
            &mut data,
            &settings,
            &[0.0],
            &[0.0],
            &mut source,
            Record {
                q: &mut q,
                qd: &mut qd,
                qdd: &mut qdd,
                tau: &mut tau,
            },
        )
        .unwrap();
        assert!(matches!(out.failure.unwrap().kind, FailureKind::Diverged(_)));
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let model = pendulum();
        let settings = Settings {
            method: Method::Rk4,
            dt: 0.0,
            steps: 10,
            t0: 0.0,
            record_every: 1,
            hold: false,
            max_speed: 1e6,
            limits: None,
            cancel: None,
        };
        let mut v = vec![0.0; 11];
        let (mut a, mut b, mut c) = (v.clone(), v.clone(), v.clone());
        let mut zero = Sampled {
            values: &[],
            n: 1,
            t0: 0.0,
            dt: 1.0,
            linear: false,
        };
        let r = integrate(
            &model,
            &mut Data::new(&model),
            &settings,
            &[0.0],
            &[0.0],
            &mut zero,
            Record {
                q: &mut v,
                qd: &mut a,
                qdd: &mut b,
                tau: &mut c,
            },
        );
        assert!(matches!(r, Err(Error::InvalidInput(_))));
    }
    #[test]
    fn implicit_euler_is_first_order_on_a_pendulum() {
        let model = pendulum();
        let (_, q_ref, _) = run(&model, Method::Rk4, 1e-4, 20_000, &[1.0], &[0.0]);
        let reference = *q_ref.last().unwrap();
        let err = |dt: f64| {
            let steps = (2.0 / dt).round() as usize;
            let (o, q, _) = run(&model, Method::Implicit, dt, steps, &[1.0], &[0.0]);
            assert!(o.failure.is_none());
            (q[steps] - reference).abs()
        };
        let ratio = err(0.002) / err(0.001);
        assert!((ratio - 2.0).abs() < 0.3, "implicit Euler error ratio {ratio}");
    }

    /// A stiff PD law as a torque source that knows its Jacobian.
    struct StiffPd {
        kp: f64,
        kd: f64,
        goal: f64,
        tell_jacobian: bool,
    }

    impl TorqueFn for StiffPd {
        fn torque(
            &mut self,
            _k: usize,
            _t: f64,
            q: &[f64],
            qd: &[f64],
            out: &mut [f64],
        ) -> std::result::Result<(), String> {
            out[0] = self.kp * (self.goal - q[0]) - self.kd * qd[0];
            Ok(())
        }
        fn jacobian(
            &mut self,
            _k: usize,
            _t: f64,
            _q: &[f64],
            _qd: &[f64],
            dq: &mut [f64],
            dqd: &mut [f64],
        ) -> std::result::Result<bool, String> {
            dq[0] = -self.kp;
            dqd[0] = -self.kd;
            Ok(self.tell_jacobian)
        }
    }

    fn run_with(
        model: &Model,
        method: Method,
        dt: f64,
        steps: usize,
        source: &mut dyn TorqueFn,
        limits: Option<Limits<'_>>,
        q0: f64,
    ) -> (Outcome, Vec<f64>, Vec<f64>) {
        let settings = Settings {
            method,
            dt,
            steps,
            t0: 0.0,
            record_every: 1,
            hold: false,
            max_speed: 1e6,
            limits,
            cancel: None,
        };
        let m = settings.samples();
        let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let out = integrate(
            model,
            &mut Data::new(model),
            &settings,
            &[q0],
            &[0.0],
            source,
            Record {
                q: &mut q,
                qd: &mut qd,
                qdd: &mut qdd,
                tau: &mut tau,
            },
        )
        .unwrap();
        (out, q, qd)
    }

    #[test]
    fn implicit_euler_is_stable_on_stiff_damping_and_gains() {
        // viscous damping 10 N m s on an inertia of 1e-4 kg m^2 (pendulum scaled): h b / I = 100
        let mut model = pendulum();
        // mass 1e-4 at (1, 0, 0): first moment (1e-4, 0, 0), inertia about the joint diag(0, 1e-4, 1e-4)
        model.inertia[0] = crate::spatial::Inertia::new(
            1e-4,
            crate::spatial::Vec3::new(1e-4, 0.0, 0.0),
            crate::spatial::Mat3::from_diagonal(&crate::spatial::Vec3::new(0.0, 1e-4, 1e-4)),
        );
        model.viscous[0] = 10.0;
        let mut zero = Sampled {
            values: &[],
            n: 1,
            t0: 0.0,
            dt: 1e-3,
            linear: false,
        };
        let (o, _, _) = run_with(&model, Method::Rk4, 1e-3, 100, &mut zero, None, 1.0);
        assert!(o.failure.is_some(), "RK4 must blow up here (the test's premise)");
        let (o, q, qd) = run_with(&model, Method::Implicit, 1e-3, 2000, &mut zero, None, 1.0);
        assert!(o.failure.is_none(), "{:?}", o.failure);
        // overdamped: it creeps at the speed where damping balances gravity, b qd = -m g l cos q
        let creep = -1e-4 * 9.81 * q[2000].cos() / 10.0;
        assert!(
            (qd[2000] - creep).abs() < 1e-3 * creep.abs(),
            "qd(T) = {}, creep speed {creep}",
            qd[2000]
        );
        // a stiff PD law (kp = 1e4, kd = 1e2 on the same tiny inertia) converges to its set point;
        // without the gains in the Jacobian the same step is unstable
        let mut model = model.clone();
        model.viscous[0] = 0.0;
        model.gravity = crate::spatial::Vec3::zeros();
        let mut pd = StiffPd {
            kp: 1e4,
            kd: 1e2,
            goal: 0.5,
            tell_jacobian: true,
        };
        let (o, q, _) = run_with(&model, Method::Implicit, 1e-3, 500, &mut pd, None, 0.0);
        assert!(
            o.failure.is_none() && (q[500] - 0.5).abs() < 1e-6,
            "{:?} q = {}",
            o.failure,
            q[500]
        );
        let mut pd = StiffPd {
            kp: 1e4,
            kd: 1e2,
            goal: 0.5,
            tell_jacobian: false,
        };
        let (o, _, _) = run_with(&model, Method::Implicit, 1e-3, 500, &mut pd, None, 0.0);
        assert!(
            o.failure.is_some(),
            "without the controller's Jacobian the stiff PD law must blow up"
        );
    }

    #[test]
    fn coulomb_friction_holds_a_joint_that_it_can_hold() {
        // gravity torque at q = 0: m g l = 9.81 N m; Coulomb 20 N m holds it, 5 N m does not
        for (coulomb, holds) in [(20.0, true), (5.0, false)] {
            let mut model = pendulum();
            model.coulomb[0] = coulomb;
            let mut zero = Sampled {
                values: &[],
                n: 1,
                t0: 0.0,
                dt: 1e-3,
                linear: false,
            };
            let (o, q, _) = run_with(&model, Method::Implicit, 1e-3, 500, &mut zero, None, 0.0);
            assert!(o.failure.is_none());
            assert_eq!(q[500].abs() < 1e-9, holds, "coulomb {coulomb}: q(T) = {}", q[500]);
        }
    }

    #[test]
    fn joint_limits_stop_a_falling_pendulum() {
        let model = pendulum();
        let (lower, upper) = ([-0.3], [0.3]);
        for method in [Method::Rk4, Method::SemiImplicitEuler, Method::Euler, Method::Implicit] {
            let mut zero = Sampled {
                values: &[],
                n: 1,
                t0: 0.0,
                dt: 1e-3,
                linear: false,
            };
            let (o, q, qd) = run_with(
                &model,
                method,
                1e-3,
                1000,
                &mut zero,
                Some(Limits {
                    lower: &lower,
                    upper: &upper,
                }),
                0.0,
            );
            assert!(o.failure.is_none());
            assert!(q.iter().all(|x| (-0.3..=0.3).contains(x)), "{method:?} left its limits");
            // it falls onto the lower stop and rests there
            assert!(
                (q[1000] + 0.3).abs() < 1e-12 && qd[1000] == 0.0,
                "{method:?}: q(T) = {}, qd(T) = {}",
                q[1000],
                qd[1000]
            );
            let (_, q, _) = run_with(&model, method, 1e-3, 1000, &mut zero, None, 0.0);
            assert!(q.iter().any(|x| *x < -0.3), "{method:?} without limits passes through");
        }
        let mut zero = Sampled {
            values: &[],
            n: 1,
            t0: 0.0,
            dt: 1e-3,
            linear: false,
        };
        let settings = Settings {
            method: Method::Rk4,
            dt: 1e-3,
            steps: 1,
            t0: 0.0,
            record_every: 1,
            hold: false,
            max_speed: 1e6,
            limits: Some(Limits {
                lower: &[1.0],
                upper: &[0.0],
            }),
            cancel: None,
        };
        let mut v = vec![0.0; 2];
        let (mut a, mut b, mut c) = (v.clone(), v.clone(), v.clone());
        let r = integrate(
            &model,
            &mut Data::new(&model),
            &settings,
            &[0.0],
            &[0.0],
            &mut zero,
            Record {
                q: &mut v,
                qd: &mut a,
                qdd: &mut b,
                tau: &mut c,
            },
        );
        assert!(matches!(r, Err(Error::InvalidInput(_))));
    }

    /// The joint torque `J^T f = rnea(q, 0, 0) - rnea(q, 0, 0, f)` of external wrenches `f` held in
    /// base axes, and its derivative for the implicit step (`-d rnea(q, 0, 0, f)/dq` plus the same
    /// without f), evaluated at each state.
    struct Pushed<'a> {
        model: &'a Model,
        f: &'a [f64],
        data: Data,
    }

    impl TorqueFn for Pushed<'_> {
        fn torque(
            &mut self,
            _k: usize,
            _t: f64,
            q: &[f64],
            _qd: &[f64],
            out: &mut [f64],
        ) -> std::result::Result<(), String> {
            use crate::algorithms::rnea::{rnea_with, RneaTerms};
            let zeros = vec![0.0; self.model.n];
            let free = rnea_with(self.model, &mut self.data, q, &zeros, &zeros, None, RneaTerms::RIGID).to_vec();
            let pushed = rnea_with(
                self.model,
                &mut self.data,
                q,
                &zeros,
                &zeros,
                Some(self.f),
                RneaTerms::RIGID,
            );
            for (o, (a, b)) in out.iter_mut().zip(free.iter().zip(pushed)) {
                *o = a - b;
            }
            Ok(())
        }

        fn jacobian(
            &mut self,
            _k: usize,
            _t: f64,
            q: &[f64],
            _qd: &[f64],
            dq: &mut [f64],
            dqd: &mut [f64],
        ) -> std::result::Result<bool, String> {
            use crate::algorithms::derivatives::rnea_derivatives;
            let n = self.model.n;
            let zeros = vec![0.0; n];
            let (mut with_f, mut scratch) = (vec![0.0; n * n], vec![0.0; n * n]);
            rnea_derivatives(
                self.model,
                &mut self.data,
                q,
                &zeros,
                &zeros,
                None,
                dq,
                &mut scratch,
                None,
            );
            rnea_derivatives(
                self.model,
                &mut self.data,
                q,
                &zeros,
                &zeros,
                Some(self.f),
                &mut with_f,
                &mut scratch,
                None,
            );
            for (a, b) in dq.iter_mut().zip(&with_f) {
                *a -= b;
            }
            dqd.fill(0.0);
            Ok(true)
        }
    }

    /// Constant external wrenches (about link origins off the body origins) give the run that their
    /// joint torque ([`Pushed`]) gives: both routes through the same schemes.
    #[test]
    fn constant_wrenches_act_as_their_joint_torques() {
        let model = random_model(21, 5, true);
        let n = model.n;
        let mut rng = crate::testing::Rng::new(3);
        let origins = (0..n)
            .map(|_| crate::spatial::Vec3::from_column_slice(&rng.vector(3, -0.5, 0.5)))
            .collect();
        let model = model.with_link_origins(origins).unwrap();
        let f = rng.vector(6 * n, -2.0, 2.0);
        let (q0, qd0) = (rng.vector(n, -1.0, 1.0), rng.vector(n, -1.0, 1.0));
        for method in [Method::Rk4, Method::Implicit, Method::SemiImplicitEuler] {
            let settings = Settings {
                method,
                dt: 1e-3,
                steps: 200,
                t0: 0.0,
                record_every: 10,
                hold: false,
                max_speed: 1e6,
                limits: None,
                cancel: None,
            };
            let m = settings.samples() * n;
            let mut runs = Vec::new();
            for native in [true, false] {
                let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
                let zero = Sampled {
                    values: &[],
                    n,
                    t0: 0.0,
                    dt: settings.dt,
                    linear: false,
                };
                let mut with = crate::sim::WithWrenches {
                    source: zero,
                    f_ext: &f,
                };
                let mut pushed = Pushed {
                    model: &model,
                    f: &f,
                    data: Data::new(&model),
                };
                let source: &mut dyn TorqueFn = if native { &mut with } else { &mut pushed };
                let record = Record {
                    q: &mut q,
                    qd: &mut qd,
                    qdd: &mut qdd,
                    tau: &mut tau,
                };
                let out = integrate(&model, &mut Data::new(&model), &settings, &q0, &qd0, source, record).unwrap();
                assert!(out.failure.is_none(), "{method:?}: {:?}", out.failure);
                runs.push((q, qd));
            }
            let tol = 1e-11;
            for (a, b) in runs[0]
                .0
                .iter()
                .chain(&runs[0].1)
                .zip(runs[1].0.iter().chain(&runs[1].1))
            {
                assert!((a - b).abs() <= tol * (1.0 + b.abs()), "{method:?}: {a} vs {b}");
            }
        }
    }

    /// A cancellation flag set while the run goes (here by the torque source at step 10, as
    /// another thread would on Ctrl-C) stops it before the next step, samples so far kept.
    #[test]
    fn a_set_cancel_flag_stops_the_run_before_the_next_step() {
        use std::sync::atomic::{AtomicBool, Ordering};
        let model = random_model(2, 7, true);
        let flag = AtomicBool::new(false);
        let mut source = |k: usize, _t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]| {
            out.fill(0.0);
            if k == 10 {
                flag.store(true, Ordering::Relaxed);
            }
            Ok(())
        };
        let steps = 1_000_000;
        let settings = Settings {
            method: Method::Rk4,
            dt: 1e-3,
            steps,
            t0: 0.0,
            record_every: steps,
            hold: false,
            max_speed: 1e6,
            limits: None,
            cancel: Some(&flag),
        };
        let n = model.n;
        let m = settings.samples() * n;
        let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let out = integrate(
            &model,
            &mut Data::new(&model),
            &settings,
            &vec![0.1; model.nq],
            &vec![0.0; n],
            &mut source,
            Record {
                q: &mut q,
                qd: &mut qd,
                qdd: &mut qdd,
                tau: &mut tau,
            },
        )
        .unwrap();
        let failure = out.failure.expect("the run was cancelled");
        assert_eq!(failure.kind, FailureKind::Cancelled);
        assert_eq!((out.steps, failure.step), (11, 11));
        assert_eq!(out.samples, 1, "the first sample is kept");
    }
}
