"""``kinedyn.simulate``: integrate the equations of motion of a robot or a Lagrangian system.

Where the work happens (DESIGN.md: Rust does every hot loop):

- ``method="auto"`` (the default) is ``rk4``, or ``implicit`` (linearly implicit Euler with the
  analytical derivatives of the dynamics and of a PD-type controller) where RK4 would be unstable at
  ``dt`` (:func:`_choose_method`; the choice and why in ``traj.info["method_choice"]``).
- A robot, a fixed-step method (``rk4``, ``implicit``, ``semi_implicit``, ``euler``) and torques given as data (none,
  a constant, or samples per step): the whole trajectory, or a batch of initial states (in
  parallel), is one native call (``kinedyn._core.integrate_fixed``; the scheme is in
  ``crates/kinedyn-core/src/sim/``).
- A robot with a Python controller or a torque function ``u(t, q, qd)``: the core's integration loop
  calls the Python function through a callback, at every Runge-Kutta stage (a continuous-time control
  law, exact to the integrator's order) or, with ``hold=True``, once per step (a digital controller
  at the integration rate, torque held: 4x fewer Python calls with RK4, an O(dt) torque error).
  Trade-off: each call costs a few microseconds of Python against ~1-3 us for the articulated-body
  algorithm, so a Python controller sets the speed (~20-40 us per RK4 step instead of ~5-10 us);
  precompute open-loop torques as arrays where possible. A batch with a controller runs its states
  one after the other.
- External wrenches ``f_ext`` (they are given about the link frames, which move with q) and every
  :class:`~kinedyn.simulate.systems.MechanicalSystem` / ``LagrangianSystem`` integrate in Python
  with the same schemes, calling the compiled dynamics once per stage.
- Adaptive methods (``rk45``, ``rk23``, ``dop853``, ``radau``, ``bdf``, ``lsoda``) use
  ``scipy.integrate.solve_ivp`` with ``rtol``/``atol``; the samples are at multiples of ``dt``.

Blow-ups stop the run with :class:`SimulationError` (when, where, which joint; the samples before
it are in ``error.trajectory``) instead of returning NaN arrays. ``joint_limits=True`` makes the
limits inelastic stops; ``time_budget`` bounds the wall-clock time (a run cut short says so in
``traj.info["truncated"]`` and with a :class:`SimulationTruncatedWarning`); on a terminal a progress
bar on stderr appears once a run has taken a second.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Union, cast

import numpy as np

from .._core import NonFiniteResultError
from .._ui.progress import SHOW_AFTER, Delayed
from .systems import MechanicalSystem
from .trajectory import Trajectory

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..robot import Robot
    from ..symbolic.system import LagrangianSystem

__all__ = [
    "simulate",
    "SimulationError",
    "NonFiniteTorqueError",
    "SimulationTruncatedWarning",
    "FIXED_METHODS",
    "ADAPTIVE_METHODS",
    "RK4_STABLE",
]

FIXED_METHODS = ("rk4", "semi_implicit", "euler", "implicit")
ADAPTIVE_METHODS = {
    "rk45": "RK45",
    "rk23": "RK23",
    "dop853": "DOP853",
    "radau": "Radau",
    "bdf": "BDF",
    "lsoda": "LSODA",
}
_ALIASES = {
    "semi_implicit_euler": "semi_implicit",
    "symplectic_euler": "semi_implicit",
    "symplectic": "semi_implicit",
    "implicit_euler": "implicit",
}

#: ``method="auto"`` keeps RK4 while ``dt`` times the largest eigenvalue modulus of the linearised
#: dynamics stays below this; RK4's stability region reaches 2.79 on the negative real axis and 2.83
#: on the imaginary axis (Hairer & Wanner, *Solving ODEs II*, §IV.2, Fig. 2.1), so this leaves a margin
#: for the stiffness growing along the run.
RK4_STABLE = 2.0


class SimulationError(RuntimeError):
    """A simulation stopped early. ``t``, ``step``, ``joint`` (index or None), ``index`` (the
    trajectory of a batch), ``kind`` and ``trajectory`` (the samples before the failure)."""

    def __init__(self, message, *, t=None, step=None, joint=None, index=None, kind=None, trajectory=None):
        super().__init__(message)
        self.t, self.step, self.joint, self.index, self.kind, self.trajectory = t, step, joint, index, kind, trajectory


class NonFiniteTorqueError(SimulationError, ValueError):
    """The controller or torque input produced NaN or infinity."""


class SimulationOverflowError(SimulationError, NonFiniteResultError):
    """The state's numbers overflowed float64 (finite inputs, but a configuration or velocity far
    beyond any robot's): also a ``kinedyn.NonFiniteResultError``, hence a ``ValueError``."""


class SimulationTruncatedWarning(RuntimeWarning):
    """A simulation reached its ``time_budget`` (wall-clock seconds) and returned the samples it had;
    ``traj.info["truncated"]`` says where it stopped."""


# ------------------------------------------------------------------ helpers
class _TimeBar(Delayed):
    """Progress over simulated time: ``update(t)`` with the time reached."""

    def __init__(self, enabled: bool, t0: float, t1: float, label: str, delay: float):
        self.t0 = t0
        super().__init__(enabled, t1 - t0, label, "t = {task.completed:.3g} / {task.total:.3g} s", delay)

    def update(self, t: float) -> None:
        super().update(t - self.t0)


def _is_robot(system) -> bool:
    return hasattr(system, "_model") and hasattr(system, "forward_dynamics")


def _as_mechanical(system, params, baumgarte, points) -> MechanicalSystem:
    if isinstance(system, MechanicalSystem):
        if baumgarte is not None:
            system.baumgarte = tuple(baumgarte)
        return system
    if hasattr(system, "euler_lagrange") and hasattr(system, "holonomic"):
        return MechanicalSystem.from_lagrangian(
            system, params=params, points=points, baumgarte=tuple(baumgarte) if baumgarte is not None else (10.0, 10.0)
        )
    raise TypeError(
        f"simulate needs a kinedyn.Robot, a kinedyn.symbolic.LagrangianSystem or a kinedyn.simulate.MechanicalSystem, got {type(system).__name__}"
    )


def _names(system) -> list:
    return list(system.joint_names) if hasattr(system, "joint_names") else list(system.names)


def _split_state(x0, n: int, name: str, nq: int | None = None):
    """(q0, qd0) from x0 = concatenate([q0, qd0]): nq + n numbers (nq = n without multi-DOF joints)."""
    from .._arrays import real_array

    nq = n if nq is None else nq
    x = real_array(x0, "x0")  # TypeError for complex, text or integers beyond float64
    if x.ndim not in (1, 2) or x.shape[-1] != nq + n:
        size = f"2 n = {2 * n}" if nq == n else f"nq + nv = {nq} + {n}"
        raise ValueError(
            f"x0 must be concatenate([q0, qd0]) with {size} entries for '{name}' ({n} coordinates), "
            f"or a batch (N, {nq + n}); got shape {x.shape}"
        )
    if not np.all(np.isfinite(x)):
        raise ValueError("x0 contains a non-finite value (NaN or inf)")
    return np.ascontiguousarray(x[..., :nq]), np.ascontiguousarray(x[..., nq:])


def _time_grid(t_span, dt, method):
    try:
        if np.ndim(t_span) == 0:
            t0, t1 = 0.0, float(t_span)
        else:
            if len(t_span) != 2:
                raise ValueError
            t0, t1 = float(t_span[0]), float(t_span[1])
    except (TypeError, ValueError):
        raise ValueError(f"t_span must be a duration T or a pair (t0, t1) in seconds, got {t_span!r}") from None
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 <= t0:
        raise ValueError(f"t_span must end after it starts (t1 > t0), got ({t0}, {t1})")
    if dt is None:
        dt = 1e-3
    try:
        dt = float(dt)
    except (TypeError, ValueError):
        raise ValueError(f"dt must be a positive step in seconds, got {dt!r}") from None
    if not (dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt must be a positive step in seconds, got {dt}")
    dt = min(dt, t1 - t0)  # a step longer than the span: one step of the span
    ratio = (t1 - t0) / dt
    if not ratio < 2.0**53:  # beyond this, t0 + k dt no longer advances in float64 (and no run ends)
        raise ValueError(
            f"t_span ({t0}, {t1}) with dt = {dt} asks for {ratio:.3g} steps: more than 2**53; raise dt or shorten t_span"
        )
    steps = max(1, int(math.ceil(ratio - 1e-9)))
    return t0, t1, dt, steps


def _sampled_u(u, n: int, steps: int, batch: int | None):
    """u as data: None -> None; (n,) constant -> (1, n); (steps, n) held; (steps + 1, n) linear;
    (N, S, n) per trajectory. Returns (array or None, linear)."""
    if u is None:
        return None, False
    a = np.asarray(u, dtype=float)
    if a.ndim == 1:
        a = a[None, :]
    if a.shape[-1] != n:
        raise ValueError(f"u must give {n} generalised forces per sample, got shape {np.shape(u)}")
    if a.ndim == 3 and (batch is None or a.shape[0] != batch):
        raise ValueError(f"u of shape {a.shape} is per trajectory but the batch has {batch} initial states")
    rows = a.shape[-2]
    if rows not in (1, steps, steps + 1):
        raise ValueError(
            f"u has {rows} samples: give 1 (a constant), {steps} (one per step, held over it) or "
            f"{steps + 1} (one per sample time t0 + k dt, interpolated linearly)"
        )
    if not np.all(np.isfinite(a)):
        k = np.argwhere(~np.isfinite(a))[0]
        raise NonFiniteTorqueError(f"u contains a non-finite value at index {tuple(int(i) for i in k)}")
    return np.ascontiguousarray(a), rows == steps + 1 and rows > 1


def _u_at(a: np.ndarray, linear: bool, t0: float, dt: float, k: int, t: float):
    """Sample of data-u for step k at time t (a: (S, n))."""
    rows = a.shape[0]
    if rows == 1:
        return a[0]
    k = min(k, rows - 1)
    if linear and k + 1 < rows:
        s = min(max((t - (t0 + k * dt)) / dt, 0.0), 1.0)
        return (1 - s) * a[k] + s * a[k + 1]
    return a[k]


def _failure_message(system_name, names, f: dict, index, steps, unit_speed="rad/s or m/s") -> tuple:
    j = f.get("joint")
    where = f" at joint {j} ('{names[j]}')" if j is not None and j < len(names) else ""
    at = f"t = {f['t']:.6g} s (step {f['step']} of {steps})"
    which = f" (trajectory {index} of the batch)" if index is not None else ""
    kind = f["kind"]
    if kind == "torque":
        return (
            NonFiniteTorqueError,
            f"the controller / input returned a non-finite torque ({f['value']}){where} at {at}{which}",
        )
    if kind == "diverged":
        return SimulationError, (
            f"simulation of '{system_name}' blew up at {at}{which}: speed {f['value']:.3g} {unit_speed}{where} exceeds "
            f"max_speed; the samples before it are in error.trajectory (reduce dt, use method='implicit' for a stiff robot, check the gains / inputs)"
        )
    if kind == "non_finite":
        return (
            SimulationError,
            f"simulation of '{system_name}' blew up at {at}{which}: the state became non-finite{where}; the samples before it are in error.trajectory",
        )
    if kind == "singular":
        cls = SimulationOverflowError if "too large for float64" in (f["message"] or "") else SimulationError
        return cls, f"simulation of '{system_name}' stopped at {at}{which}: {f['message']}"
    return SimulationError, f"simulation of '{system_name}' stopped at {at}{which}: {f.get('message', '')}"


def _raise_failure(system, names, failures, steps_done, traj_factory, steps):
    for index, f in enumerate(failures):
        if f is not None:
            cls, message = _failure_message(
                getattr(system, "name", "system"), names, f, index if len(failures) > 1 else None, steps
            )
            if f["kind"] == "singular" and isinstance(f.get("joint"), int) and hasattr(system, "_nonphysical_note"):
                message += system._nonphysical_note(f["joint"])  # a kept non-physical inertia can make M singular
            partial = traj_factory(index, int(steps_done[index]))
            raise cls(
                message,
                t=f["t"],
                step=f["step"],
                joint=f.get("joint"),
                index=index if len(failures) > 1 else None,
                kind=f["kind"],
                trajectory=partial,
            )


# ------------------------------------------------------------------ stiffness and the implicit step
def _choose_method(robot, q0, qd0, t0, dt, jacobian, names) -> tuple:
    """``method="auto"``: RK4 unless ``dt |lambda|max`` of the linearised dynamics
    ``J = [[0, I], [dqdd/dq, dqdd/dqd]]`` (analytical derivatives; the controller's gains included
    when it has ``jacobian``) exceeds :data:`RK4_STABLE` at an initial state, else the implicit
    step. Returns (method, reason)."""
    states = [(q0, qd0)] if q0.ndim == 1 else list(zip(q0[:16], qd0[:16]))
    n = qd0.shape[-1]
    worst, joint = 0.0, None
    for q, qd in states:
        try:
            A_q, A_v, Minv = robot.forward_dynamics_derivatives(q, qd, np.zeros(n))
        except (RuntimeError, ValueError):
            return "rk4", "auto: rk4 (the linearised dynamics are not available at the initial state)"
        if jacobian is not None:
            K = jacobian(t0, q, qd)
            if K is not None:
                A_q, A_v = A_q + Minv @ K[0], A_v + Minv @ K[1]
        J = np.block([[np.zeros((n, n)), np.eye(n)], [A_q, A_v]])
        lam, vec = np.linalg.eig(J)
        i = int(np.argmax(np.abs(lam)))
        if abs(lam[i]) > worst:
            worst = float(abs(lam[i]))
            joint = int(np.argmax(np.abs(vec[:n, i]) + np.abs(vec[n:, i]) / max(worst, 1e-300)))
            joint = (
                int(robot._dof_body[joint]) if hasattr(robot, "_dof_body") else joint
            )  # a degree of freedom -> its joint
    stiffness = dt * worst
    if stiffness <= RK4_STABLE:
        return "rk4", f"auto: rk4 (dt |lambda|max = {stiffness:.3g} <= {RK4_STABLE:g}, inside RK4's stability region)"
    return "implicit", (
        f"auto: implicit Euler, because RK4 at dt = {dt:g} s would be unstable: dt |lambda|max = {stiffness:.3g} > {RK4_STABLE:g} "
        f"(stiffest mode at joint '{names[joint]}'; |lambda|max = {worst:.3g} 1/s); RK4 would need dt < {RK4_STABLE / worst:.2g} s"
    )


def _coulomb_torque(coulomb, v):
    """Coulomb friction torque at rates ``v`` for levels ``coulomb = (positive, negative)``, each
    (n,) and >= 0: ``positive`` for v > 0, ``-negative`` for v < 0, 0 at rest."""
    positive, negative = coulomb
    return np.where(v > 0, positive, 0.0) - np.where(v < 0, negative, 0.0)


def _implicit_step(q, qd, a, h, A_q, A_v, Minv, coulomb):
    """The linearly implicit Euler step of the core's ``sim/implicit.rs`` (``Method::Implicit``) in NumPy: returns the
    new (q, qd). ``a``: the acceleration at (q, qd) (Coulomb friction included), ``coulomb``: the
    levels (positive, negative), each (n,), or None."""
    n = q.size
    A = np.eye(n) - h * A_v - h * h * A_q
    lu = _lu(A)
    a0 = a if coulomb is None else a + Minv @ _coulomb_torque(coulomb, qd)
    v0 = qd + _solve(lu, h * (a0 + h * (A_q @ qd)))
    if coulomb is None:
        v = v0
    else:
        v = v0 + _solve(lu, -h * (Minv @ _coulomb_torque(coulomb, v0)))
        v = np.where(((coulomb[0] != 0) | (coulomb[1] != 0)) & (v * v0 < 0), 0.0, v)
    return q + h * v, v


def _lu(A):
    from scipy.linalg import lu_factor

    return lu_factor(A)


def _solve(lu, b):
    from scipy.linalg import lu_solve

    return lu_solve(lu, b)


def _derivatives_fn(target, robot, fext_fn):
    """(t, q, qd, tau) -> (dqdd/dq, dqdd/dqd, M^-1): analytical for robots, central differences of
    the accelerations for other mechanical systems."""
    if robot:
        if fext_fn is None:
            return lambda t, q, qd, tau: target.forward_dynamics_derivatives(q, qd, tau)
        return lambda t, q, qd, tau: target.forward_dynamics_derivatives(q, qd, tau, fext_fn(t, q, qd))
    accel = _accel_fn(target, robot, fext_fn)

    def numeric(t, q, qd, tau):
        n = q.size
        out = []
        for which in range(3):
            D = np.zeros((n, n))
            for j in range(n):
                args = [q.copy(), qd.copy(), np.array(tau, dtype=float)]
                h = 1e-6 * max(1.0, abs(args[which][j]))
                args[which][j] += h
                plus = accel(t, *args)
                args[which][j] -= 2 * h
                D[:, j] = (plus - accel(t, *args)) / (2 * h)
            out.append(D)
        return tuple(out)

    return numeric


def _clamp_to_limits(q, qd, lower, upper):
    """Inelastic stops (the core's ``sim/integrate.rs`` ``apply_limits``)."""
    low, high = q <= lower, q >= upper
    q = np.where(low, lower, np.where(high, upper, q))
    qd = np.where(low, np.maximum(qd, 0.0), np.where(high, np.minimum(qd, 0.0), qd))
    return q, qd


class _Deadline:
    """A wall-clock budget shared by the trajectories of a run: ``expired()`` once it is spent; the
    first trajectory to stop sets ``step``, and the others stop there too."""

    def __init__(self, budget):
        self.budget = budget
        self.end = None if budget is None else time.perf_counter() + budget
        self.step = None

    def expired(self) -> bool:
        return self.end is not None and time.perf_counter() > self.end


# ------------------------------------------------------------------ the Python fixed-step loop
def _fixed_python(
    accel,
    torque,
    method,
    t0,
    dt,
    steps,
    q0,
    qd0,
    record_every,
    max_speed,
    hold,
    progress,
    implicit=None,
    limits=None,
    deadline=None,
):
    """One trajectory with the schemes of the core's ``sim/``, the dynamics called from Python.
    ``implicit``: (derivatives(t, q, qd, tau), jacobian(t, q, qd) or None, coulomb or None) for the
    implicit method; ``limits``: (lower, upper) or None; ``deadline``: a :class:`_Deadline`."""
    n = q0.size
    samples = -(-steps // record_every) + 1
    Q, QD, QDD, TAU = (np.zeros((samples, n)) for _ in range(4))
    q, qd = q0.copy(), qd0.copy()
    s = 0
    failure = None

    def evaluate(k, t, q, qd):
        tau = np.asarray(torque(k, t, q, qd), dtype=float).reshape(n)
        bad = np.flatnonzero(~np.isfinite(tau))
        if bad.size:
            raise _Stop(dict(step=k, t=t, joint=int(bad[0]), kind="torque", value=float(tau[bad[0]]), message=""))
        return tau, accel(t, q, qd, tau)

    k = 0
    last = steps if deadline is None or deadline.step is None else min(steps, deadline.step)
    try:
        for k in range(last + 1):
            t = t0 + k * dt
            tau, a1 = evaluate(k, t, q, qd)
            if k % record_every == 0 or k == last:
                Q[s], QD[s], QDD[s], TAU[s] = q, qd, a1, tau
                s += 1
                if progress is not None and s % 50 == 0:
                    progress.update(t)
                if k < last and deadline is not None and k % record_every == 0 and deadline.expired():
                    deadline.step = k
                    break
            if k == last:
                break
            if method == "implicit":
                derivatives, jacobian, coulomb = implicit
                A_q, A_v, Minv = derivatives(t, q, qd, tau)
                K = jacobian(t, q, qd) if jacobian is not None else None
                if K is not None:
                    A_q, A_v = A_q + Minv @ K[0], A_v + Minv @ K[1]
                q, qd = _implicit_step(q, qd, a1, dt, A_q, A_v, Minv, coulomb)
            elif method == "euler":
                q, qd = q + dt * qd, qd + dt * a1
            elif method == "semi_implicit":
                qd = qd + dt * a1
                q = q + dt * qd
            else:
                f = (
                    (lambda tt, x, v: (tau, accel(tt, x, v, tau))[1])
                    if hold
                    else (lambda tt, x, v: evaluate(k, tt, x, v)[1])
                )
                q2, v2 = q + 0.5 * dt * qd, qd + 0.5 * dt * a1
                a2 = f(t + 0.5 * dt, q2, v2)
                q3, v3 = q + 0.5 * dt * v2, qd + 0.5 * dt * a2
                a3 = f(t + 0.5 * dt, q3, v3)
                q4, v4 = q + dt * v3, qd + dt * a3
                a4 = f(t + dt, q4, v4)
                q = q + dt / 6 * (qd + 2 * v2 + 2 * v3 + v4)
                qd = qd + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
            if limits is not None:
                q, qd = _clamp_to_limits(q, qd, *limits)
            bad = np.flatnonzero(~(np.isfinite(q) & np.isfinite(qd)))
            if bad.size:
                raise _Stop(dict(step=k, t=t, joint=int(bad[0]), kind="non_finite", value=None, message=""))
            fast = np.flatnonzero(np.abs(qd) > max_speed)
            if fast.size:
                raise _Stop(
                    dict(step=k, t=t, joint=int(fast[0]), kind="diverged", value=float(qd[fast[0]]), message="")
                )
    except _Stop as stop:
        failure = stop.failure
    except np.linalg.LinAlgError as e:
        failure = dict(
            step=k, t=t0 + k * dt, joint=None, kind="singular", value=None, message=f"singular system matrix ({e})"
        )
    except RuntimeError as e:
        if "singular" not in str(e):
            raise
        failure = dict(step=k, t=t0 + k * dt, joint=None, kind="singular", value=None, message=str(e))
    return Q, QD, QDD, TAU, (k if failure or k < steps else steps), s, failure


class _Stop(Exception):
    def __init__(self, failure):
        super().__init__(failure["kind"])
        self.failure = failure


# ------------------------------------------------------------------ simulate
def simulate(
    system: Union[Robot, LagrangianSystem, MechanicalSystem],
    t_span: Union[float, tuple[float, float]],
    x0: ArrayLike,
    u: Union[None, ArrayLike, Callable] = None,
    controller: Callable | None = None,
    method: str = "auto",
    dt: float | None = None,
    f_ext: Union[None, ArrayLike, Callable] = None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    progress: bool | None = None,
    *,
    params: dict | None = None,
    hold: bool = False,
    record_every: int = 1,
    max_speed: float = 1e6,
    baumgarte: tuple[float, float] | None = None,
    points: Callable | None = None,
    joint_limits: bool = False,
    time_budget: float | None = None,
) -> Trajectory:
    """Simulate ``system`` from ``x0 = concatenate([q0, qd0])`` over ``t_span`` (T or (t0, t1)).

    ``system``: a :class:`kinedyn.Robot` (friction, rotor inertia and gravity of the robot included),
    a :class:`kinedyn.symbolic.LagrangianSystem` (parameter values in ``params``; constraints
    stabilised with Baumgarte's method, ``baumgarte=(alpha, beta)``, default (10, 10)), or a
    :class:`~kinedyn.simulate.MechanicalSystem`. ``x0`` may be a batch (N, 2n).

    Generalised force = ``u`` + ``controller(t, q, qd)``: ``u`` is None, a constant (n,), samples
    (steps, n) held over each step or (steps + 1, n) at the sample times interpolated linearly (or
    (N, S, n) per trajectory), or a function ``u(t, q, qd)``; ``controller`` any callable
    ``(t, q, qd) -> tau`` (see :mod:`kinedyn.simulate.control`). Python callables are evaluated at
    every integrator stage, or once per step with ``hold=True``.

    ``method``: ``auto`` (default: ``rk4``, or ``implicit`` where RK4 at this ``dt`` would be
    unstable — stiff robots such as fingers of tiny inertia under PD gains; the choice and its reason
    are in ``traj.method`` and ``traj.info["method_choice"]``), ``rk4``, ``implicit`` (linearly
    implicit Euler with the analytical derivatives of the dynamics and of the controller where it
    has ``jacobian(t, q, qd)``, stable at any step), ``semi_implicit`` (symplectic Euler), ``euler``
    (fixed step ``dt``, default 1 ms) or ``rk45``, ``rk23``, ``dop853``, ``radau``, ``bdf``,
    ``lsoda`` (SciPy, adaptive, ``rtol``/``atol``; samples every ``dt``). ``f_ext``: external wrenches on a robot's links,
    (n, 6) constant or a function ``f(t, q, qd) -> (n, 6)`` (see :meth:`Robot.forward_dynamics`).
    ``record_every``: keep every k-th step (fixed-step methods). ``progress``: a progress bar on
    stderr (None: only on a terminal and for long runs). ``max_speed``: a joint speed above this is a
    blow-up (:class:`SimulationError`). ``joint_limits``: honour the robot's joint position limits
    (an inelastic stop: the position is put back on the limit and the velocity into it zeroed;
    fixed-step methods). ``time_budget``: wall-clock seconds; a run that reaches it stops and returns
    the samples it has, with ``traj.info["truncated"]`` saying where, and a
    :class:`SimulationTruncatedWarning`.
    """
    method = _ALIASES.get(str(method).lower(), str(method).lower())
    if method != "auto" and method not in FIXED_METHODS and method not in ADAPTIVE_METHODS:
        raise ValueError(
            f"unknown method '{method}': auto; fixed-step {', '.join(FIXED_METHODS)}; adaptive {', '.join(ADAPTIVE_METHODS)}"
        )
    if time_budget is not None and not (time_budget > 0):
        raise ValueError(f"time_budget must be a positive number of seconds, got {time_budget!r}")
    if int(record_every) < 1:
        raise ValueError(f"record_every must be >= 1, got {record_every}")
    record_every = int(record_every)
    if controller is not None and not callable(controller):
        raise TypeError(f"controller must be callable as controller(t, q, qd) -> tau, got {type(controller).__name__}")
    if not max_speed > 0:
        raise ValueError(f"max_speed must be a positive speed (rad/s or m/s), got {max_speed!r}")
    if method in ADAPTIVE_METHODS and not (rtol > 0 and atol > 0 and math.isfinite(rtol) and math.isfinite(atol)):
        raise ValueError(f"rtol and atol must be positive numbers, got rtol={rtol!r}, atol={atol!r}")
    robot = _is_robot(system)
    # a floating, spherical or planar joint: q (nq) and qd (nv) differ, and only the core's
    # fixed-step integrators step q on the manifold (q ⊕ h qd)
    multi_dof = robot and cast("Robot", system).has_multi_dof_joints
    mech = None if robot else _as_mechanical(system, params, baumgarte, points)
    target = system if robot else mech
    n = system.n if mech is None else mech.n
    name = getattr(system, "name", "system")
    names = _names(target)
    controller_n = getattr(controller, "n", None)
    if isinstance(controller_n, (int, np.integer)) and controller_n != n:
        raise ValueError(f"the controller is made for {controller_n} joints but '{name}' has {n}")
    q0, qd0 = _split_state(x0, n, name, cast("Robot", system).nq if multi_dof else n)
    batch = q0.shape[0] if q0.ndim == 2 else None
    t0, t1, dt, steps = _time_grid(t_span, dt, method)
    jac = getattr(controller, "jacobian", None) if controller is not None else None
    jac = jac if callable(jac) else None
    choice = None
    if method == "auto":
        method, choice = (
            _choose_method(system, q0, qd0, t0, dt, jac, names)
            if robot
            else ("rk4", "auto: rk4 (a mechanical system given as equations)")
        )
    if joint_limits:
        if not robot:
            raise ValueError("joint_limits applies to robots (their joints' lower and upper limits)")
        if method in ADAPTIVE_METHODS:
            raise ValueError(
                f"joint_limits needs a fixed-step method (auto, {', '.join(FIXED_METHODS)}), not '{method}'"
            )
        arm = cast("Robot", system)  # a robot: checked just above
        limits = (np.asarray(arm.lower_limits, dtype=float), np.asarray(arm.upper_limits, dtype=float))
    else:
        limits = None
    if method in ADAPTIVE_METHODS:
        record_every = 1
    if callable(u):
        u_fn, u_data, linear = u, None, False
    else:
        u_fn = None
        u_data, linear = _sampled_u(u, n, steps, batch)
    if callable(f_ext):
        fext_fn = f_ext
    elif f_ext is not None:
        if not robot:
            raise ValueError(
                "f_ext applies to robots (wrenches on links); for a Lagrangian system put the generalised force in u"
            )
        fe = np.asarray(f_ext, dtype=float)
        if fe.shape != (n, 6) or not np.all(np.isfinite(fe)):
            raise ValueError(
                f"f_ext must be a finite (n, 6) = ({n}, 6) array of link wrenches, or a function of (t, q, qd)"
            )
        fext_fn = lambda t, q, qd: fe  # noqa: E731
    else:
        fext_fn = None
    count = batch or 1
    work = steps * count * (4 if method == "rk4" else 1)
    # a robot with reduced mimic joints runs the Python loop on its reduced methods (the native
    # integrators take the full model)
    native = robot and method in FIXED_METHODS and fext_fn is None and not getattr(system, "mimic_joints", None)
    if multi_dof and not native:
        why = f"the method '{method}'" if method not in FIXED_METHODS else "f_ext or mimic joints"
        raise ValueError(
            f"simulation of robot '{name}' with multi-DOF joints (nq = {q0.shape[-1]}, nv = {n}) runs in the native fixed-step "
            f"integrators only ({', '.join(FIXED_METHODS)}, without f_ext or mimic joints); {why} needs the Python loop, which steps q + h qd"
        )
    pure_native = native and u_fn is None and controller is None
    delay = 0.0
    if progress is None:
        # on a terminal, a bar appears once a run has taken a second (runs over ~2 s show progress)
        progress = bool(work > 1000 and getattr(sys.stderr, "isatty", lambda: False)())
        delay = SHOW_AFTER
    bar = _TimeBar(bool(progress), t0, t0 + steps * dt, f"simulate {name}", delay)
    if controller is not None and hasattr(controller, "reset"):
        controller.reset()

    def u_data_for(index):
        if u_data is None:
            return None
        return u_data[index] if u_data.ndim == 3 else u_data

    def torque_for(index):
        """torque(k, t, q, qd) for trajectory `index` (None if no Python part)."""
        data = u_data_for(index)

        def torque(k, t, q, qd):
            tau = np.zeros(n)
            if data is not None:
                tau = tau + _u_at(data, linear, t0, dt, k, t)
            if u_fn is not None:
                tau = tau + _checked(u_fn(t, q, qd), "u", t)
            if controller is not None:
                tau = tau + _checked(controller(t, q, qd), "the controller", t)
            return np.ascontiguousarray(tau, dtype=float)

        def _checked(value, what, t):
            v = np.asarray(value, dtype=float)
            if v.shape != (n,):
                raise ValueError(
                    f"{what} returned torques of shape {v.shape} at t = {t:g} s; {name} has {n} joints (shape ({n},))"
                )
            return v

        return torque

    info = dict(method=method, steps=steps, batch=batch, native=native)
    if choice is not None:
        info["method_choice"] = choice
    if joint_limits:
        info["joint_limits"] = True
    deadline = _Deadline(time_budget)
    start = time.perf_counter()
    try:
        if native:
            out = _run_native(
                system,
                method,
                q0,
                qd0,
                t0,
                dt,
                steps,
                u_data,
                linear,
                None if pure_native else torque_for,
                hold,
                record_every,
                max_speed,
                bar,
                batch,
                jac,
                limits,
                deadline,
            )
        elif method in FIXED_METHODS:
            out = _run_python(
                system if robot else mech,
                robot,
                fext_fn,
                method,
                q0,
                qd0,
                t0,
                dt,
                steps,
                torque_for,
                hold,
                record_every,
                max_speed,
                bar,
                batch,
                jac,
                limits,
                deadline,
            )
        else:
            out, nfev = _run_adaptive(
                system if robot else mech,
                robot,
                fext_fn,
                ADAPTIVE_METHODS[method],
                q0,
                qd0,
                t0,
                t0 + steps * dt,
                dt,
                steps,
                torque_for,
                rtol,
                atol,
                max_speed,
                bar,
                batch,
                deadline,
                jac if u_fn is None else None,
            )
            info["nfev"] = nfev
    finally:
        bar.close()
    info["wall_time"] = time.perf_counter() - start
    Q, QD, QDD, TAU, steps_done, failures = out
    every = record_every if method in FIXED_METHODS else 1
    t = _sample_times(t0, dt, steps, every)
    if deadline.step is not None and not any(f is not None for f in failures):
        # the wall-clock budget ran out at step K: every trajectory keeps its samples up to K
        K = deadline.step
        t = _sample_times(t0, dt, K, every)
        Q, QD, QDD, TAU = (a[..., : t.size, :] for a in (Q, QD, QDD, TAU))
        info["truncated"] = (
            f"stopped by its time budget of {time_budget:g} s (wall clock) at t = {t[-1]:.6g} s, step {K} of {steps}; "
            f"the run was to end at t = {t0 + steps * dt:.6g} s"
        )
        info["steps_done"] = K
        import warnings

        warnings.warn(f"simulation of '{name}' {info['truncated']}", SimulationTruncatedWarning, stacklevel=3)

    def partial(index, done):
        k = done // record_every + 1 if method in FIXED_METHODS else done + 1
        k = max(1, min(k, len(t)))
        sl = (index, slice(0, k)) if batch is not None else (slice(0, k),)
        return Trajectory(target, t[:k], Q[sl], QD[sl], QDD[sl], TAU[sl], method=method, dt=dt, info=info)

    _raise_failure(target, names, failures, steps_done, partial, steps)
    traj = Trajectory(target, t, Q, QD, QDD, TAU, method=method, dt=dt, info=info)
    return traj


def _sample_times(t0, dt, steps, every):
    ks = np.arange(0, steps + 1, max(every, 1))
    if ks[-1] != steps:
        ks = np.append(ks, steps)
    return t0 + ks * dt


def _run_native(
    robot,
    method,
    q0,
    qd0,
    t0,
    dt,
    steps,
    u_data,
    linear,
    torque_for,
    hold,
    every,
    max_speed,
    bar,
    batch,
    jac=None,
    limits=None,
    deadline=None,
):
    """The core's integrator, in chunks when a progress bar is shown or a time budget is set
    (chunk boundaries on recorded steps, so the samples are the same as in one call)."""
    from .. import _core

    model = robot._model
    bounded = deadline is not None and deadline.end is not None
    chunks = 1 if (not bar.enabled and not bounded) else min(200 if bounded else 50, max(1, steps // every))
    per = -(-(steps // every) // chunks) * every if chunks > 1 else steps
    lower, upper = limits if limits is not None else (None, None)
    jacobian = None if jac is None or method != "implicit" else (lambda k, t, q, qd: jac(t, q, qd))
    parts: list[Any] = []
    k0, q, qd = 0, q0, qd0
    while True:
        m = min(per, steps - k0)
        res: tuple[Any, ...]
        if torque_for is None:
            tau = None
            if u_data is not None:
                rows = u_data.shape[-2]
                if rows == 1:
                    tau = u_data
                else:
                    tau = np.ascontiguousarray(u_data[..., k0 : k0 + m + (1 if linear else 0), :])
            res = _core.integrate_fixed(
                model, method, q, qd, t0 + k0 * dt, dt, m, tau, linear, every, max_speed, lower, upper
            )
        else:
            if batch is None:
                cb = _offset(torque_for(0), k0)
                res = _core.integrate_callback(
                    model, method, q, qd, t0 + k0 * dt, dt, m, cb, hold, every, max_speed, jacobian, lower, upper
                )
            else:
                results: list[tuple[Any, ...]] = [
                    _core.integrate_callback(
                        model,
                        method,
                        q[i],
                        qd[i],
                        t0 + k0 * dt,
                        dt,
                        m,
                        _offset(torque_for(i), k0),
                        hold,
                        every,
                        max_speed,
                        jacobian,
                        lower,
                        upper,
                    )
                    for i in range(batch)
                ]
                res = tuple(np.stack([r[j] for r in results]) for j in range(4)) + (
                    np.concatenate([r[4] for r in results]),
                    [r[5][0] for r in results],
                )
        Qc, QDc, QDDc, TAUc, done, failures = res
        done = np.asarray(done) + k0
        failures = [None if f is None else {**f, "step": f["step"] + k0} for f in failures]
        parts.append((Qc, QDc, QDDc, TAUc) if not parts else tuple(a[..., 1:, :] for a in (Qc, QDc, QDDc, TAUc)))
        k0 += m
        bar.update(t0 + k0 * dt)
        if any(f is not None for f in failures) or k0 >= steps:
            break
        if deadline is not None and deadline.expired():
            deadline.step = k0
            break
        q = np.ascontiguousarray(Qc[..., -1, :])
        qd = np.ascontiguousarray(QDc[..., -1, :])
    arrays = tuple(np.concatenate([p[j] for p in parts], axis=-2) if len(parts) > 1 else parts[0][j] for j in range(4))
    return arrays + (done, failures)


def _offset(torque, k0):
    return lambda k, t, q, qd: torque(k + k0, t, q, qd)


def _accel_fn(target, robot, fext_fn):
    if robot:
        if fext_fn is None:
            return lambda t, q, qd, tau: target.forward_dynamics(q, qd, tau)
        return lambda t, q, qd, tau: target.forward_dynamics(q, qd, tau, fext_fn(t, q, qd))
    return lambda t, q, qd, tau: target.accelerations(q, qd, tau)[0]


def _run_python(
    target,
    robot,
    fext_fn,
    method,
    q0,
    qd0,
    t0,
    dt,
    steps,
    torque_for,
    hold,
    every,
    max_speed,
    bar,
    batch,
    jac=None,
    limits=None,
    deadline=None,
):
    accel = _accel_fn(target, robot, fext_fn)
    implicit = None
    if method == "implicit":
        coulomb = np.array([[float(c) for c in j.coulomb_levels] for j in target.joints]).T if robot else None
        implicit = (
            _derivatives_fn(target, robot, fext_fn),
            jac,
            (coulomb[0], coulomb[1]) if coulomb is not None and np.any(coulomb) else None,
        )
    results = []
    for i in range(batch or 1):
        qi, qdi = (q0[i], qd0[i]) if batch is not None else (q0, qd0)
        results.append(
            _fixed_python(
                accel,
                torque_for(i),
                method,
                t0,
                dt,
                steps,
                qi,
                qdi,
                every,
                max_speed,
                hold,
                bar,
                implicit,
                limits,
                deadline,
            )
        )
    return _stack(results, batch)


def _stack(results, batch):
    def pick(j):
        return np.stack([r[j] for r in results]) if batch is not None else results[0][j]

    return (pick(0), pick(1), pick(2), pick(3), np.array([r[4] for r in results]), [r[6] for r in results])


class _Budget(Exception):
    """The wall-clock budget ran out inside an adaptive solve."""


def _run_adaptive(
    target,
    robot,
    fext_fn,
    scipy_method,
    q0,
    qd0,
    t0,
    t1,
    dt,
    steps,
    torque_for,
    rtol,
    atol,
    max_speed,
    bar,
    batch,
    deadline=None,
    controller_jac=None,
):
    """SciPy's solve_ivp per trajectory; with a time budget, over segments of the sample grid (a run
    that runs out of time keeps the segments it finished). The implicit methods (Radau, BDF, LSODA)
    of a robot get the analytical Jacobian ``[[0, I], [dqdd/dq, dqdd/dqd]]`` (the controller's
    gains included when it has ``jacobian``) instead of finite differences."""
    from scipy.integrate import solve_ivp

    accel = _accel_fn(target, robot, fext_fn)
    t_eval = t0 + np.arange(steps + 1) * dt
    t_eval[-1] = min(t_eval[-1], t1)
    n = q0.shape[-1]
    bounded = deadline is not None and deadline.end is not None
    results = []
    nfev = 0
    for i in range(batch or 1):
        torque = torque_for(i)
        qi, qdi = (q0[i], qd0[i]) if batch is not None else (q0, qd0)
        last = steps if not bounded or deadline.step is None else deadline.step

        def step_of(t):
            return int(min(max(math.floor((t - t0) / dt + 1e-9), 0), steps))

        def rhs(t, x):
            q, qd = x[:n], x[n:]
            tau = torque(step_of(t), t, q, qd)
            bad = np.flatnonzero(~np.isfinite(tau))
            if bad.size:
                raise _Stop(
                    dict(step=step_of(t), t=t, joint=int(bad[0]), kind="torque", value=float(tau[bad[0]]), message="")
                )
            if bounded and deadline.expired():
                raise _Budget()
            bar.update(t)
            return np.concatenate([qd, accel(t, q, qd, tau)])

        def too_fast(t, x):
            return max_speed - np.abs(x[n:]).max()

        too_fast.terminal = True  # solve_ivp reads its event options from the function's attributes
        options = {}
        if robot and scipy_method in ("Radau", "BDF", "LSODA"):
            derivatives = _derivatives_fn(target, robot, fext_fn)

            def jacobian(t, x):
                q, qd = x[:n], x[n:]
                A_q, A_v, Minv = derivatives(t, q, qd, torque(step_of(t), t, q, qd))
                K = controller_jac(t, q, qd) if controller_jac is not None else None
                if K is not None:
                    A_q, A_v = A_q + Minv @ K[0], A_v + Minv @ K[1]
                return np.block([[np.zeros((n, n)), np.eye(n)], [A_q, A_v]])

            options["jac"] = jacobian
        failure = None
        pieces = [np.concatenate([qi, qdi])[None, :]]
        edges = (
            np.unique(np.linspace(0, last, min(last, 20) + 1).round().astype(int)) if bounded else np.array([0, last])
        )
        try:
            for a, b in zip(edges[:-1], edges[1:]):
                sol = solve_ivp(
                    rhs,
                    (t_eval[a], t_eval[b]),
                    pieces[-1][-1],
                    method=scipy_method,
                    t_eval=t_eval[a : b + 1],
                    rtol=rtol,
                    atol=atol,
                    events=too_fast,
                    **options,
                )
                nfev += sol.nfev
                X = sol.y.T
                pieces.append(X[1:])
                if sol.status == 1:  # the speed event
                    te = float(sol.t_events[0][0])
                    xe = sol.y_events[0][0]
                    j = int(np.argmax(np.abs(xe[n:])))
                    failure = dict(step=step_of(te), t=te, joint=j, kind="diverged", value=float(xe[n + j]), message="")
                elif sol.status < 0 or not np.all(np.isfinite(X)):
                    failure = dict(
                        step=step_of(sol.t[-1] if sol.t.size else t0),
                        t=float(sol.t[-1]) if sol.t.size else t0,
                        joint=None,
                        kind="non_finite",
                        value=None,
                        message=f"the adaptive solver failed: {sol.message}",
                    )
                if failure is not None:
                    break
        except _Stop as stop:
            failure = stop.failure
            pieces = [np.zeros((0, 2 * n))]
        except _Budget:
            pass
        X = np.concatenate(pieces)
        S = X.shape[0]
        if bounded and failure is None and S - 1 < last:
            deadline.step = S - 1
        Q, QD = X[:, :n].copy(), X[:, n:].copy()
        QDD, TAU = np.zeros((steps + 1, n)), np.zeros((steps + 1, n))
        for k in range(S):
            TAU[k] = torque(k, t_eval[k], Q[k], QD[k])
            QDD[k] = accel(t_eval[k], Q[k], QD[k], TAU[k])
        full = [np.zeros((steps + 1, n)) for _ in range(2)]
        full[0][:S], full[1][:S] = Q, QD
        results.append((full[0], full[1], QDD, TAU, max(S - 1, 0), S, failure))
    return _stack(results, batch), nfev
