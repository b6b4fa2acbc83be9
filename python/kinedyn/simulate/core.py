"""``kinedyn.simulate``: integrate the equations of motion of a robot or a Lagrangian system.

Where the work happens (docs/architecture.md: Rust does every hot loop):

- ``method="auto"`` (the default) is ``rk4``, or ``implicit`` (linearly implicit Euler with the
  analytical derivatives of the dynamics and of a PD-type controller) where RK4 would be unstable at
  ``dt`` (:func:`~kinedyn.simulate.stiffness.choose_method`; the choice and why in
  ``traj.info["method_choice"]``).
- A robot, a fixed-step method (``rk4``, ``implicit``, ``semi_implicit``, ``euler``) and torques given as data (none,
  a constant, or samples per step): the whole trajectory, or a batch of initial states (in
  parallel), is one native call (``kinedyn._core.integrate_fixed``; the scheme is in
  ``crates/kinedyn-core/src/sim/``; :mod:`.native_runner`).
- A robot with a Python controller or a torque function ``u(t, q, qd)``: the core's integration loop
  calls the Python function through a callback, at every Runge-Kutta stage (a continuous-time control
  law, exact to the integrator's order) or, with ``hold=True``, once per step (a digital controller
  at the integration rate, torque held: 4x fewer Python calls with RK4, an O(dt) torque error).
  Trade-off: each call costs a few microseconds of Python against ~1-3 us for the articulated-body
  algorithm, so a Python controller sets the speed (~20-40 us per RK4 step instead of ~5-10 us);
  precompute open-loop torques as arrays where possible. A batch with a controller runs its states
  one after the other.
- External wrenches ``f_ext`` (about the link frames' origins, which move with q) are the core's: a
  constant array goes with the run as data, a function ``f_ext(t, q, qd)`` is called back at every
  stage. Every :class:`~kinedyn.simulate.systems.MechanicalSystem` / ``LagrangianSystem`` (and a robot
  with reduced mimic joints) integrates in Python with the same schemes, calling the compiled
  dynamics once per stage (:mod:`.fixed_step`).
- Adaptive methods (``rk45``, ``rk23``, ``dop853``, ``radau``, ``bdf``, ``lsoda``) use
  ``scipy.integrate.solve_ivp`` with ``rtol``/``atol``; the samples are at multiples of ``dt``
  (:mod:`.adaptive`).

Blow-ups stop the run with :class:`SimulationError` (when, where, which joint; the samples before
it are in ``error.trajectory``) instead of returning NaN arrays. ``joint_limits=True`` makes the
limits inelastic stops; ``time_budget`` bounds the wall-clock time (a run cut short says so in
``traj.info["truncated"]`` and with a :class:`SimulationTruncatedWarning`); on a terminal a progress
bar on stderr appears once a run has taken a second.

This module checks the arguments and picks the runner; the arguments' forms are in :mod:`.inputs`,
the failures in :mod:`.errors`.
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Union, cast

import numpy as np

from .._ui.progress import SHOW_AFTER
from .adaptive import run_adaptive
from .errors import (
    NonFiniteTorqueError,
    SimulationError,
    SimulationOverflowError,
    SimulationTruncatedWarning,
    raise_failure,
)
from .fixed_step import run_fixed_step
from .inputs import (
    ADAPTIVE_METHODS,
    FIXED_METHODS,
    METHOD_ALIASES,
    as_mechanical,
    coordinate_names,
    external_wrenches,
    is_robot,
    sampled_u,
    split_state,
    time_grid,
    torque_sources,
)
from .loops_runner import LOOP_METHODS, closed_start, loop_forces, run_closed_loops
from .native_runner import run_native
from .runs import Deadline, TimeBar
from .stiffness import RK4_STABLE, choose_method
from .systems import MechanicalSystem
from .trajectory import Trajectory

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..robot import Robot
    from ..symbolic.systems.system import LagrangianSystem

__all__ = [
    "simulate",
    "SimulationError",
    "SimulationOverflowError",
    "NonFiniteTorqueError",
    "SimulationTruncatedWarning",
    "FIXED_METHODS",
    "ADAPTIVE_METHODS",
    "RK4_STABLE",
]


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
    method = METHOD_ALIASES.get(str(method).lower(), str(method).lower())
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
    robot = is_robot(system)
    # a floating, spherical or planar joint: q (nq) and qd (nv) differ, and only the core's
    # fixed-step integrators and the closed loops' runner step q on the manifold (q ⊕ h qd)
    multi_dof = robot and cast("Robot", system).has_multi_dof_joints
    # closed loops: the constrained dynamics and a projection after each step (:mod:`.loops_runner`)
    loops = robot and bool(getattr(system, "loops", ()))
    mech = None if robot else as_mechanical(system, params, baumgarte, points)
    target = system if robot else mech
    n = system.n if mech is None else mech.n
    name = getattr(system, "name", "system")
    names = coordinate_names(target)
    controller_n = getattr(controller, "n", None)
    if isinstance(controller_n, (int, np.integer)) and controller_n != n:
        raise ValueError(f"the controller is made for {controller_n} joints but '{name}' has {n}")
    q0, qd0 = split_state(x0, n, name, cast("Robot", system).nq if multi_dof else n)
    batch = q0.shape[0] if q0.ndim == 2 else None
    t0, t1, dt, steps = time_grid(t_span, dt, method)
    jac = getattr(controller, "jacobian", None) if controller is not None else None
    jac = jac if callable(jac) else None
    choice = None
    if loops:
        _check_loops(cast("Robot", system), method)
        q0, qd0, moved_q, moved_qd = closed_start(system, q0, qd0)
    if method == "auto" and loops:
        method, choice = "rk4", "auto: rk4 (closed loops: projected onto their manifold after each step)"
    elif method == "auto":
        method, choice = (
            choose_method(system, q0, qd0, t0, dt, jac, names)
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
        u_data, linear = sampled_u(u, n, steps, batch)
    # one wrench per moving link (a multi-DOF joint's link counts once)
    fext_fn = external_wrenches(f_ext, len(cast("Robot", system).body_names) if robot else n, robot)
    native_wrenches = f_ext if callable(f_ext) or f_ext is None else np.asarray(f_ext, dtype=float)
    count = batch or 1
    work = steps * count * (4 if method == "rk4" else 1)
    # The one place that sends a robot to the Python fixed-step loop (:mod:`.fixed_step`): a robot
    # with reduced mimic joints runs on its reduced methods (the native integrators take the full
    # model). Wrenches about link frames (f_ext), one per link, are the core's (docs/architecture.md).
    native = robot and method in FIXED_METHODS and not getattr(system, "mimic_joints", None) and not loops
    if multi_dof and not native and not loops:
        why = f"the method '{method}'" if method not in FIXED_METHODS else "mimic joints"
        raise ValueError(
            f"simulation of robot '{name}' with multi-DOF joints (nq = {q0.shape[-1]}, nv = {n}) runs in the native fixed-step "
            f"integrators only ({', '.join(FIXED_METHODS)}, without mimic joints); {why} needs the Python loop, which steps q + h qd"
        )
    # constant wrenches go to the core as data (a batch in parallel); a function of (t, q, qd) is called back
    pure_native = native and u_fn is None and controller is None and not callable(f_ext)
    delay = 0.0
    if progress is None:
        # on a terminal, a bar appears once a run has taken a second (runs over ~2 s show progress)
        progress = bool(work > 1000 and getattr(sys.stderr, "isatty", lambda: False)())
        delay = SHOW_AFTER
    bar = TimeBar(bool(progress), t0, t0 + steps * dt, f"simulate {name}", delay)
    if controller is not None and hasattr(controller, "reset"):
        controller.reset()

    torque_for = torque_sources(n, name, u_data, linear, u_fn, controller, t0, dt)

    info = dict(method=method, steps=steps, batch=batch, native=native)
    if choice is not None:
        info["method_choice"] = choice
    if joint_limits:
        info["joint_limits"] = True
    deadline = Deadline(time_budget)
    start = time.perf_counter()
    if loops:
        info["loops"] = "projection after each step (Hairer, Lubich and Wanner, GNI IV.4)"
        info["loop_start_shift"] = {"q": moved_q, "qd": moved_qd}
    try:
        if loops:
            out = run_closed_loops(
                system, fext_fn, method, q0, qd0, t0, dt, steps, torque_for, hold, record_every, max_speed, bar,
                batch, limits, deadline,
            )  # fmt: skip
        elif native:
            out = run_native(
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
                native_wrenches,
            )
        elif method in FIXED_METHODS:  # a MechanicalSystem, or a robot the core cannot run (see `native`)
            out = run_fixed_step(
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
            out, nfev = run_adaptive(
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
        warnings.warn(f"simulation of '{name}' {info['truncated']}", SimulationTruncatedWarning, stacklevel=3)

    def partial(index, done):
        k = done // record_every + 1 if method in FIXED_METHODS else done + 1
        k = max(1, min(k, len(t)))
        sl = (index, slice(0, k)) if batch is not None else (slice(0, k),)
        return Trajectory(target, t[:k], Q[sl], QD[sl], QDD[sl], TAU[sl], method=method, dt=dt, info=info)

    raise_failure(target, names, failures, steps_done, partial, steps)
    traj = Trajectory(target, t, Q, QD, QDD, TAU, method=method, dt=dt, info=info)
    if loops:
        traj.loop_forces = loop_forces(system, fext_fn, t, Q, QD, TAU)
        info["loop_residual_max"] = float(np.abs(cast("Robot", system).loop_residual(Q.reshape(-1, Q.shape[-1]))).max())
        traj.info = info
    return traj


def _check_loops(robot, method):
    if method != "auto" and method not in LOOP_METHODS:
        raise ValueError(
            f"robot '{robot.name}' has closed loops: simulate it with a fixed-step method that projects onto them "
            f"after each step (auto, {', '.join(LOOP_METHODS)}), not '{method}'"
        )


def _sample_times(t0, dt, steps, every):
    ks = np.arange(0, steps + 1, max(every, 1))
    if ks[-1] != steps:
        ks = np.append(ks, steps)
    return t0 + ks * dt
