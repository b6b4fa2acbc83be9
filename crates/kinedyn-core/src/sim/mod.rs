//! Fixed-step integration of the equations of motion over a whole trajectory.
//!
//! State `x = (q, qd)`, `dx/dt = (qd, qdd)`, `qdd = aba(q, qd, tau(t, q, qd), f_ext(t, q, qd))`
//! (LaValle eq. 13.148, the phase form of `M qdd + C qd + g + friction = tau + J^T f_ext`). The torque
//! comes from a [`TorqueFn`]: zero, a constant, samples held or interpolated over each step, or any
//! closure (the Python binding passes a controller through one); the external wrenches, if any, from
//! the same source ([`TorqueFn::wrenches`], evaluated at every stage even when the torque is held).
//!
//! Methods (step `h`, `t_k = t0 + k h`):
//! - `Rk4`, classical Runge-Kutta (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.1, Table 1.2):
//!   `k1 = f(t_k, x_k)`, `k2 = f(t_k + h/2, x_k + h/2 k1)`, `k3 = f(t_k + h/2, x_k + h/2 k2)`,
//!   `k4 = f(t_k + h, x_k + h k3)`, `x_{k+1} = x_k + h/6 (k1 + 2 k2 + 2 k3 + k4)`; global error O(h^4).
//! - `SemiImplicitEuler` (symplectic Euler; Hairer, Lubich & Wanner, *Geometric Numerical
//!   Integration*, §VI.3): `qd_{k+1} = qd_k + h qdd(q_k, qd_k)`, `q_{k+1} = q_k + h qd_{k+1}`;
//!   first order, but the energy of a conservative system stays bounded instead of drifting.
//! - `Euler` (explicit): `x_{k+1} = x_k + h f(t_k, x_k)`; first order, energy grows. For comparison.
//! - `Implicit`, the linearly implicit (Rosenbrock-) Euler step (Hairer & Wanner, *Solving ODEs II*,
//!   §IV.7, eq. 7.4 with gamma = 1): `x_{k+1} = x_k + (I - h J)^-1 h f(t_k, x_k)`, `J = df/dx` from the
//!   analytical derivatives of the articulated-body algorithm ([`aba_derivatives`](crate::algorithms::aba_derivatives): `A_q = dqdd/dq`,
//!   `A_v = dqdd/dqd`) plus, when the torque source knows them ([`TorqueFn::jacobian`], e.g. a PD
//!   law: `dtau/dq = -Kp`, `dtau/dqd = -Kd`), the controller's gains through `dqdd/dtau = M^-1`.
//!   With `J = [[0, I], [A_q, A_v]]` the 2n x 2n solve reduces to one n x n solve for the velocity
//!   increment, `(I - h A_v - h^2 A_q) dv = h (qdd_k + h A_q qd_k)`, then `qd_{k+1} = qd_k + dv`,
//!   `q_{k+1} = q_k + h qd_{k+1}`. First order, but exact for linear dynamics' stability: stable
//!   for any step on damped and spring-like (PD) terms however stiff (MuJoCo's `implicit`
//!   integrator linearises the damping the same way; this one also linearises the springs). It
//!   dissipates energy at O(h) (numerical damping), so free motion loses energy slowly.
//!   Coulomb friction `coulomb sign(qd)` is not differentiable: it is applied in the direction
//!   of the velocity the step predicts without it, through the same matrix, and it may stop a joint
//!   but not reverse it within one step (stiction, a per-joint approximation of the set-valued law
//!   of time-stepping schemes such as Stewart & Trinkle 1996).
//!
//! Joint limits (`settings.limits`): after every step a joint beyond a limit is put back on it
//! and its velocity into the limit set to zero (an inelastic stop; a projection, first order at the
//! impact).
//!
//! Recorded per sample `k` (every `record_every` steps, and the last): `q_k`, `qd_k`, the torque
//! applied at `t_k` and `qdd_k = aba(q_k, qd_k, tau_k)`. A step that produces a non-finite state or a
//! joint speed above `max_speed`, a torque that is not finite, or a singular mass matrix stops the
//! run: the samples before it are kept and a [`Failure`] says when and where. So does a set
//! cancellation flag (`settings.cancel`, polled before every step): long runs can be interrupted.
//!
//! Files: the types of a run are here; `integrate.rs` (the runner: checks, stages, limits, samples),
//! `implicit.rs` (the linearly implicit step), `torque.rs` (torque sources).
//!
//! | symbol      | here                  | meaning                                          |
//! |-------------|-----------------------|--------------------------------------------------|
//! | `h`         | `settings.dt`         | step (s)                                         |
//! | `x_k`       | `q`, `qd`             | state at `t_k`, each length `n`                  |
//! | `k1..k4`    | `kq[s]`, `kv[s]`      | stage derivatives of `q` and `qd`                |
//! | `tau`       | `tau`                 | joint torque at a stage, length `n`              |

use std::sync::atomic::AtomicBool;

mod implicit;
mod integrate;
mod torque;

pub use integrate::integrate;
pub use torque::{Sampled, TorqueFn, WithWrenches};

/// The fixed-step schemes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Rk4,
    SemiImplicitEuler,
    Euler,
    Implicit,
}

impl Method {
    /// Evaluations of the dynamics per step.
    pub fn stages(self) -> usize {
        match self {
            Method::Rk4 => 4,
            Method::SemiImplicitEuler | Method::Euler | Method::Implicit => 1,
        }
    }
}

/// Joint position limits, each length `n` (infinite for an unlimited joint).
#[derive(Clone, Copy, Debug)]
pub struct Limits<'a> {
    pub lower: &'a [f64],
    pub upper: &'a [f64],
}

/// Step size, length and stop conditions of a run.
#[derive(Clone, Copy, Debug)]
pub struct Settings<'a> {
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
    /// Joint position limits to honour (inelastic stops), or None: free motion passes through.
    pub limits: Option<Limits<'a>>,
    /// A cancellation flag polled before every step, or None: once it is set (by another thread,
    /// e.g. the Python binding's caller on Ctrl-C) the run stops with [`FailureKind::Cancelled`].
    pub cancel: Option<&'a AtomicBool>,
}

impl Settings<'_> {
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
    /// [`Settings::cancel`] was set: the caller asked the run to stop.
    Cancelled,
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

/// Output arrays, each row-major `(settings.samples(), n)`.
pub struct Record<'a> {
    pub q: &'a mut [f64],
    pub qd: &'a mut [f64],
    pub qdd: &'a mut [f64],
    pub tau: &'a mut [f64],
}
