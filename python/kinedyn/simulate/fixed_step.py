"""The fixed-step schemes of the core's ``sim/`` (RK4, linearly implicit Euler, semi-implicit and
explicit Euler) written in Python, the dynamics called once per stage.

They exist for what the core's integrators cannot take: a
:class:`~kinedyn.simulate.systems.MechanicalSystem` (a ``LagrangianSystem``'s equations), and, until
external wrenches about link frames and mimic reduction are native, robots with ``f_ext`` or mimic
joints (:func:`~kinedyn.simulate.core.simulate` decides; see docs/architecture.md). Every robot that
the core can run goes through :mod:`.native_runner` instead."""

from __future__ import annotations

import numpy as np

from .errors import StopRun
from .runs import acceleration_fn, derivatives_fn, stack_runs

__all__ = ["run_fixed_step", "fixed_step_trajectory", "implicit_step", "coulomb_torque", "clamp_to_limits"]


def run_fixed_step(
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
    accel = acceleration_fn(target, robot, fext_fn)
    implicit = None
    if method == "implicit":
        coulomb = np.array([[float(c) for c in j.coulomb_levels] for j in target.joints]).T if robot else None
        implicit = (
            derivatives_fn(target, robot, fext_fn),
            jac,
            (coulomb[0], coulomb[1]) if coulomb is not None and np.any(coulomb) else None,
        )
    return run_each(accel, torque_for, method, t0, dt, steps, q0, qd0, batch, every, max_speed, hold, bar,
                    implicit, limits, deadline)  # fmt: skip


def run_each(accel, torque_for, method, t0, dt, steps, q0, qd0, batch, every, max_speed, hold, bar, implicit,
             limits, deadline, project=None, group=None):  # fmt: skip
    """:func:`fixed_step_trajectory` for each state of a batch (``batch`` None: one run), the runs
    stacked (``stack_runs``); ``torque_for(i)`` gives run i's torque law."""
    results = []
    for i in range(batch or 1):
        qi, qdi = (q0[i], qd0[i]) if batch is not None else (q0, qd0)
        results.append(
            fixed_step_trajectory(
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
                project,
                group,
            )  # fmt: skip
        )
    return stack_runs(results, batch)


def fixed_step_trajectory(
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
    project=None,
    group=None,
):
    """One trajectory with the schemes of the core's sim/, the dynamics called from Python.
    ``implicit``: (derivatives(t, q, qd, tau), jacobian(t, q, qd) or None, coulomb or None) for the
    implicit method; ``limits``: (lower, upper) or None; ``deadline``: a :class:`Deadline`;
    ``project``: None or ``(k, t, q, qd) -> (q, qd)`` after each step (closed loops: back onto their
    manifold, :mod:`.loops_runner`); ``group``: None (``q + h v``) or a :class:`.lie_steps.GroupStep`
    for robots with ball, planar or floating joints (``q ⊕ h v`` per stage: Lie-Euler, and RK4 as
    Runge-Kutta-Munthe-Kaas)."""
    n = qd0.size  # the velocities; q has nq >= n coordinates where a joint is ball, planar or floating
    samples = -(-steps // record_every) + 1
    Q = np.zeros((samples, q0.size))
    QD, QDD, TAU = (np.zeros((samples, n)) for _ in range(3))
    q, qd = q0.copy(), qd0.copy()
    s = 0
    failure = None

    def evaluate(k, t, q, qd):
        tau = np.asarray(torque(k, t, q, qd), dtype=float).reshape(n)
        bad = np.flatnonzero(~np.isfinite(tau))
        if bad.size:
            raise StopRun(dict(step=k, t=t, joint=int(bad[0]), kind="torque", value=float(tau[bad[0]]), message=""))
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
                q, qd = implicit_step(q, qd, a1, dt, A_q, A_v, Minv, coulomb)
            elif method == "euler":
                q, qd = (q + dt * qd if group is None else group.advance(q, qd, dt)), qd + dt * a1
            elif method == "semi_implicit":
                qd = qd + dt * a1
                q = q + dt * qd if group is None else group.advance(q, qd, dt)
            elif group is not None:
                q, qd = _munthe_kaas_rk4(group, accel if hold else None, evaluate, tau, k, t, dt, q, qd, a1)
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
                q, qd = clamp_to_limits(q, qd, *limits) if group is None else group.clamp(q, qd, *limits)
            if project is not None:
                q, qd = project(k, t + dt, q, qd)
            of_q, of_v = (None, None) if group is None else (group.joint_of_q, group.joint_of_v)
            bad = np.concatenate([np.flatnonzero(~np.isfinite(q)), np.flatnonzero(~np.isfinite(qd))])
            if bad.size:
                joint = int(bad[0] if of_q is None else np.concatenate([of_q, of_v])[bad[0]])
                raise StopRun(dict(step=k, t=t, joint=joint, kind="non_finite", value=None, message=""))
            fast = np.flatnonzero(np.abs(qd) > max_speed)
            if fast.size:
                joint = int(fast[0] if of_v is None else of_v[fast[0]])
                raise StopRun(dict(step=k, t=t, joint=joint, kind="diverged", value=float(qd[fast[0]]), message=""))
    except StopRun as stop:
        failure = stop.failure
        if failure["step"] is None:  # raised where the step is not known (the dynamics): this step
            failure["step"] = k
    except np.linalg.LinAlgError as e:
        failure = dict(
            step=k, t=t0 + k * dt, joint=None, kind="singular", value=None, message=f"singular system matrix ({e})"
        )
    except RuntimeError as e:
        if "singular" not in str(e):
            raise
        failure = dict(step=k, t=t0 + k * dt, joint=None, kind="singular", value=None, message=str(e))
    return Q, QD, QDD, TAU, (k if failure or k < steps else steps), s, failure


def _munthe_kaas_rk4(group, held, evaluate, tau, k, t, h, q, qd, a1):
    """One RK4 step with the configuration on its group (:mod:`.lie_steps`): the stages at
    ``q ⊕ Ω_i`` with ``Ω_2 = h/2 K_1``, ``Ω_3 = h/2 K_2``, ``Ω_4 = h K_3``, ``K_i = Jr(Ω_i)⁻¹ v_i``
    the chart's rates (``K_1 = qd``), and ``q ⊕ h (K_1 + 2 K_2 + 2 K_3 + K_4) / 6`` (HLW IV.8.2,
    Algorithm 8.4, the classical tableau). ``held``: the acceleration with the torque held over the
    step, or None to evaluate the torque law at each stage."""

    def f(tt, x, v):
        return held(tt, x, v, tau) if held is not None else evaluate(k, tt, x, v)[1]

    rates, accelerations = [qd], [a1]
    for c in (0.5 * h, 0.5 * h, h):
        omega = c * rates[-1]
        v = qd + c * accelerations[-1]
        accelerations.append(f(t + c, group.advance(q, rates[-1], c), v))
        rates.append(group.chart_rate(q, omega, v))
    mean = (rates[0] + 2 * rates[1] + 2 * rates[2] + rates[3]) / 6
    return group.advance(q, mean, h), qd + h / 6 * (a1 + 2 * accelerations[1] + 2 * accelerations[2] + accelerations[3])


def coulomb_torque(coulomb, v):
    """Coulomb friction torque at rates ``v`` for levels ``coulomb = (positive, negative)``, each
    (n,) and >= 0: ``positive`` for v > 0, ``-negative`` for v < 0, 0 at rest."""
    positive, negative = coulomb
    return np.where(v > 0, positive, 0.0) - np.where(v < 0, negative, 0.0)


def implicit_step(q, qd, a, h, A_q, A_v, Minv, coulomb):
    """The linearly implicit Euler step of the core's ``sim/implicit.rs`` (``Method::Implicit``) in NumPy: returns the
    new (q, qd). ``a``: the acceleration at (q, qd) (Coulomb friction included), ``coulomb``: the
    levels (positive, negative), each (n,), or None."""
    n = q.size
    A = np.eye(n) - h * A_v - h * h * A_q
    lu = _lu(A)
    a0 = a if coulomb is None else a + Minv @ coulomb_torque(coulomb, qd)
    v0 = qd + _solve(lu, h * (a0 + h * (A_q @ qd)))
    if coulomb is None:
        v = v0
    else:
        v = v0 + _solve(lu, -h * (Minv @ coulomb_torque(coulomb, v0)))
        v = np.where(((coulomb[0] != 0) | (coulomb[1] != 0)) & (v * v0 < 0), 0.0, v)
    return q + h * v, v


def _lu(A):
    from scipy.linalg import lu_factor  # scipy loads only when an implicit step runs

    return lu_factor(A)


def _solve(lu, b):
    from scipy.linalg import lu_solve  # scipy loads only when an implicit step runs

    return lu_solve(lu, b)


def clamp_to_limits(q, qd, lower, upper):
    """Inelastic stops (the core's ``sim/integrate.rs`` ``apply_limits``)."""
    low, high = q <= lower, q >= upper
    q = np.where(low, lower, np.where(high, upper, q))
    qd = np.where(low, np.maximum(qd, 0.0), np.where(high, np.minimum(qd, 0.0), qd))
    return q, qd
