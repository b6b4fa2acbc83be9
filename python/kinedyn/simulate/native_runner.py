"""A robot integrated by the core (``kinedyn._core.integrate_fixed`` / ``integrate_callback``; the
schemes are in ``crates/kinedyn-core/src/sim/``): torques as data in one native
call, or a Python controller / torque function called back from the core's loop."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._core import integrate_callback, integrate_fixed

__all__ = ["run_native"]


def run_native(
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
    f_ext=None,
):
    """The core's integrator, in chunks when a progress bar is shown or a time budget is set
    (chunk boundaries on recorded steps, so the samples are the same as in one call). ``f_ext``:
    None, constant link wrenches (links, 6) or a function ``(t, q, qd) -> (links, 6)``: the core
    places each link's wrench on the body that carries it."""
    model = robot._model
    wrenches: Any = None if f_ext is None or callable(f_ext) else np.asarray(f_ext, dtype=float)
    if callable(f_ext):
        wrenches = f_ext

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
            res = integrate_fixed(
                model, method, q, qd, t0 + k0 * dt, dt, m, tau, linear, every, max_speed, lower, upper, wrenches
            )
        else:

            def callback_run(qi, qdi, i):
                return integrate_callback(
                    model, method, qi, qdi, t0 + k0 * dt, dt, m, _offset(torque_for(i), k0), hold, every,
                    max_speed, jacobian, lower, upper, wrenches,
                )  # fmt: skip

            if batch is None:
                res = callback_run(q, qd, 0)
            else:
                results: list[tuple[Any, ...]] = [callback_run(q[i], qd[i], i) for i in range(batch)]
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
