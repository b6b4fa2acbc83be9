"""Adaptive methods (``rk45``, ``rk23``, ``dop853``, ``radau``, ``bdf``, ``lsoda``): SciPy's
``solve_ivp`` per trajectory, sampled at multiples of ``dt``."""

from __future__ import annotations

import math

import numpy as np

from .errors import StopRun
from .runs import acceleration_fn, derivatives_fn, stack_runs

__all__ = ["run_adaptive"]


class _Budget(Exception):
    """The wall-clock budget ran out inside an adaptive solve."""


def run_adaptive(
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
    from scipy.integrate import solve_ivp  # scipy loads only for the adaptive methods

    accel = acceleration_fn(target, robot, fext_fn)
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
                raise StopRun(
                    dict(step=step_of(t), t=t, joint=int(bad[0]), kind="torque", value=float(tau[bad[0]]), message="")
                )
            if bounded and deadline.expired():
                raise _Budget()
            bar.update(t)
            return np.concatenate([qd, accel(t, q, qd, tau)])

        def too_fast(t, x):
            return max_speed - np.abs(x[n:]).max()

        too_fast.terminal = True  # type: ignore[attr-defined]  # solve_ivp reads its event options from the function's attributes
        options = {}
        if robot and scipy_method in ("Radau", "BDF", "LSODA"):
            derivatives = derivatives_fn(target, robot, fext_fn)

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
        except StopRun as stop:
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
    return stack_runs(results, batch), nfev
