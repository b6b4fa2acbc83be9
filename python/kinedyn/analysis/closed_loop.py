"""Identification from closed-loop data: instrumental variables (IDIM-IV) and the output-error
method DIDIM, both built on a simulation of the identified model under the arm's own controller.

A real arm tracks a reference under a controller, so the torque noise (measurement noise that the
controller feeds back, disturbances acting on the arm) moves the arm: the regressor W built from the
measured motion is correlated with the error in ``y = W theta + e``, and ordinary least squares is
biased. For a disturbance ``v`` acting on the arm, ``tau = W theta - v`` while the motion's
acceleration follows ``v``: the estimated inertias come out too small.

- **IDIM-IV** (Janot, Vandanjon & Gautier, "A generic instrumental variable approach for industrial
  robot identification", IEEE TCST 22(1), 2014): the instruments ``Z = W(q_s, qd_s, qdd_s)`` are the
  regressor of the motion of the model *simulated* under the same controller and reference, with the
  current estimate, from the log's first state. ``Z`` is correlated with W (the closed loop tracks the
  same reference) and not with the noise (the simulation has none), so
  ``theta = (Z^T W)^-1 Z^T y`` is consistent. Start: the least-squares estimate; repeat simulation and
  estimate until the estimate stops moving (a few iterations). Covariance
  ``s^2 (Z^T W)^-1 Z^T Z (W^T Z)^-1``.
- **DIDIM** (Gautier, Janot & Vandanjon, "A new closed-loop output error method for parameter
  identification of robot dynamics", IEEE TCST 21(2), 2013): the measured torques are fitted by the
  *simulated* closed loop's torques; since the simulated torque is ``W(q_s, qd_s, qdd_s) theta``, its
  Gauss-Newton step with that regressor is the linear least squares ``theta = argmin |Z theta - y|``,
  iterated with a new simulation until it stops moving. Covariance ``s^2 (Z^T Z)^-1``.

On a filtered log the simulated regressor goes through the log's low-pass at the control rate
before it is read at the log's samples (the parallel filtering its torques saw: a Coulomb column's
jump smeared alike), and the filter's start-up at either end of the simulated span gets no weight.
Both weight each joint's rows by its noise level from the first fit (Gautier & Poignet 2001), as
Janot et al. do. The simulation (:func:`simulate_model`) runs the model's inverse dynamics only (the
estimate need not be a physical robot, only have a positive-definite M along the motion): the
controller is held over each control period (a digital controller's zero-order hold) and the arm
integrated over it by RK4 with ``M(q) = [tau(q, qd, e_k) - tau(q, qd, 0)]_k``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["simulate_model", "instrumental_fit"]


def _forward(torque: Callable, q: np.ndarray, qd: np.ndarray, u: np.ndarray) -> np.ndarray:
    """qdd with torque(q, qd, qdd) = u: M from n + 1 inverse-dynamics rows in one batched call."""
    n = q.shape[0]
    Q = np.tile(q, (n + 1, 1))
    V = np.tile(qd, (n + 1, 1))
    A = np.vstack([np.eye(n), np.zeros((1, n))])
    tau = torque(Q, V, A)
    M = (tau[:n] - tau[n]).T
    return np.linalg.solve(M, u - tau[n])


def simulate_model(
    torque: Callable,
    controller: Callable,
    t: np.ndarray,
    q0,
    qd0,
    period: float = 1e-3,
    max_speed: float = 1e3,
    dense: bool = False,
):
    """The model ``torque(q, qd, qdd)`` (batched (S, n) -> (S, n)) under ``controller(t, q, qd)``, from
    ``(q0, qd0)`` at ``t[0]`` to ``t[-1]``, the controller held over each ``period``; q, qd, qdd at the
    times ``t``. ValueError naming the time where the motion diverges or M stops being invertible
    (an estimate that cannot be simulated). ``dense``: (grid, q, qd, qdd) at every control period
    instead."""
    t = np.asarray(t, dtype=float)
    steps = int(np.ceil((t[-1] - t[0]) / period - 1e-9))
    grid = t[0] + period * np.arange(steps + 1)
    n = len(q0)
    Qs, Vs, As = np.empty((steps + 1, n)), np.empty((steps + 1, n)), np.empty((steps + 1, n))
    q, qd = np.array(q0, dtype=float), np.array(qd0, dtype=float)
    if hasattr(controller, "reset"):
        controller.reset()
    h = period
    for k in range(steps + 1):
        u = np.asarray(controller(grid[k], q, qd), dtype=float).reshape(n)
        try:
            a = _forward(torque, q, qd, u)
        except np.linalg.LinAlgError:
            raise ValueError(
                f"the identified model cannot be simulated: its mass matrix is singular at t = {grid[k]:.4g} s"
            ) from None
        Qs[k], Vs[k], As[k] = q, qd, a
        if k == steps:
            break
        # RK4 over the control period, u held (kinedyn.simulate's rk4 with hold=True, step for step):
        # semi-implicit Euler at 1 ms left the PUMA 560's simulated loop 0.04 rad off its RK4 run
        # (its Coulomb reversals and stiff wrist), as large as the tracking error DIDIM fits
        try:
            a2 = _forward(torque, q + h / 2 * qd, qd + h / 2 * a, u)
            a3 = _forward(torque, q + h / 2 * qd + h * h / 4 * a, qd + h / 2 * a2, u)
            a4 = _forward(torque, q + h * qd + h * h / 2 * a2, qd + h * a3, u)
        except np.linalg.LinAlgError:
            raise ValueError(
                f"the identified model cannot be simulated: its mass matrix is singular near t = {grid[k]:.4g} s"
            ) from None
        q = q + h * qd + h * h / 6 * (a + a2 + a3)
        qd = qd + h / 6 * (a + 2 * a2 + 2 * a3 + a4)
        if not (np.all(np.isfinite(qd)) and np.abs(qd).max() <= max_speed):
            raise ValueError(
                f"the identified model diverges under the controller at t = {grid[k + 1]:.4g} s (a joint speed above "
                f"{max_speed:g}): its mass matrix is not positive definite along the motion, or the controller cannot "
                "hold it; try consistent=True or method='ols'"
            )
    if dense:
        return grid, Qs, Vs, As
    out = []
    for X in (Qs, Vs, As):
        out.append(np.column_stack([np.interp(t, grid, X[:, j]) for j in range(n)]))
    return tuple(out)


def instrumental_fit(
    kind: str,
    W: np.ndarray,
    y: np.ndarray,
    weights: np.ndarray,
    start: np.ndarray,
    instruments: Callable,
    iterations: int = 6,
    tol: float = 0.02,
    fallback: np.ndarray | None = None,
):
    """IDIM-IV (``kind='iv'``) or DIDIM (``'didim'``) from ``start``; ``instruments(theta)`` returns
    the stacked regressor of the model simulated with ``theta``. It stops when the estimate moves by
    less than ``tol`` (relative) or after ``iterations``: any noise-free model's motion gives valid
    instruments, so iterating only sharpens them, and IV's estimate keeps moving within its own
    standard deviation from one simulation to the next (Janot et al. stop on a few per cent).
    An estimate that cannot be simulated (a mass matrix not positive definite along the motion, as
    a least-squares start on poorly excited data may have): the first simulation falls back on
    ``fallback`` (the prior model's parameters: any simulable model gives valid instruments), a later
    one ends the iterations on the last instruments. Returns (estimate, covariance, iterations,
    relative change of the last iteration, a note of a fallback or None)."""
    w = weights
    Ww, yw = W * w[:, None], y * w
    est = start
    change = np.inf
    it = 0
    note = None
    Zw = None
    previous = None  # the last estimate whose model could be simulated
    best = None  # IV: (log det of the covariance, iteration, estimate, covariance) of the best instruments
    while it < iterations:
        it += 1
        try:
            Zw = instruments(est) * w[:, None]
        except ValueError as e:
            if Zw is None and fallback is not None:
                note = (
                    f"the least-squares start could not be simulated ({e}); the first instruments are the prior model's"
                )
                Zw = instruments(fallback) * w[:, None]
                est = fallback
            elif Zw is None:
                raise
            else:
                # a step of the iteration (a Gauss-Newton step for DIDIM) that overshoots into a model
                # that cannot be simulated: halved toward the last simulable estimate (step control,
                # Dennis & Schnabel, Numerical Methods for Unconstrained Optimization, §6.3)
                Zh, full = None, est
                for _ in range(4):
                    est = previous + 0.5 * (est - previous)
                    try:
                        Zh = instruments(est) * w[:, None]
                        break
                    except ValueError:
                        continue
                if Zh is None:
                    est = full  # the estimate of the last instruments that could be simulated
                    note = (
                        f"iteration {it} could not be simulated ({e}); stopped on the instruments of iteration {it - 1}"
                    )
                    it -= 1
                    break
                note = f"iteration {it}'s step was halved: the full step's model could not be simulated ({e})"
                Zw = Zh
        previous = est
        if kind == "iv":
            new = np.linalg.lstsq(Zw.T @ Ww, Zw.T @ yw, rcond=None)[0]
        else:
            new = np.linalg.lstsq(Zw, yw, rcond=None)[0]
        change = float(np.linalg.norm(new - est) / max(np.linalg.norm(new), 1e-300))
        est = new
        cov = _covariance(kind, Ww, yw, Zw, est)
        if kind == "iv":
            # every noise-free model's motion gives consistent instruments, but not equally good
            # ones: with weakly excited directions Z^T W is near singular for some and the iterates
            # jump (the TX40 under its PD: 24 %, 6 %, 86 % off, their std 700 %, 5 %, 900 %). Keep
            # the instruments of smallest covariance (D-optimal: log det, independent of the
            # parameters' units; Soderstrom & Stoica, "Instrumental variable methods for system
            # identification", 1983, ch. 6: the IV covariance depends on the instruments)
            logdet = np.linalg.slogdet(cov)
            score = logdet[1] if logdet[0] > 0 else np.inf
            if best is None or score < best[0]:
                best = (score, it, est, cov)
        if change < tol:
            break
    assert Zw is not None  # at least one iteration ran (iterations >= 1)
    cov = _covariance(kind, Ww, yw, Zw, est)
    if best is not None and best[1] != it and np.isfinite(best[0]):
        _, k, est, cov = best
        kept = f"kept iteration {k}'s estimate of {it}: its instruments give the smallest covariance (log det)"
        note = kept if note is None else f"{note}; {kept}"
    return est, cov, it, change, note


def _covariance(kind: str, Ww: np.ndarray, yw: np.ndarray, Zw: np.ndarray, est: np.ndarray) -> np.ndarray:
    """IV: ``s^2 (Z^T W)^-1 Z^T Z (W^T Z)^-1``; DIDIM: ``s^2 (Z^T Z)^-1`` (weighted rows)."""
    dof = max(len(yw) - Ww.shape[1], 1)
    if kind == "iv":
        r = yw - Ww @ est
        A = np.linalg.pinv(Zw.T @ Ww)
        return float(r @ r) / dof * A @ (Zw.T @ Zw) @ A.T
    r = yw - Zw @ est
    return float(r @ r) / dof * np.linalg.pinv(Zw.T @ Zw)
