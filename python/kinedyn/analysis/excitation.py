"""Optimised excitation trajectories for identification (Swevers, Ganseman, Tukel, De Schutter &
Van Brussel, "Optimal robot excitation and identification", IEEE T-RA 13(5), 1997).

Each joint follows a finite Fourier series with base angular frequency ``wf = 2 pi / period``:

    q_i(t)   = q_i0 + sum_l  a_il / (wf l) sin(wf l t) - b_il / (wf l) cos(wf l t)
    qd_i(t)  = sum_l  a_il cos(wf l t) + b_il sin(wf l t)
    qdd_i(t) = sum_l -a_il wf l sin(wf l t) + b_il wf l cos(wf l t)

(:class:`kinedyn.simulate.control.Fourier`). The series is periodic, so a log can cover whole
periods and the trajectory starts where it ends; it starts (and ends) at rest when ``qd(0) = sum_l
a_il = 0`` and ``qdd(0) = wf sum_l l b_il = 0``, which this module builds in by solving for the
first harmonic's ``a_i1`` and ``b_i1``. The free coefficients are chosen by SLSQP
(``scipy.optimize.minimize``) to minimise the condition number of the base regressor stacked over
the period, subject to the position, velocity, acceleration and torque limits at the sampled
instants (Swevers' criterion; the noise in the estimates grows with cond(W)).

The drive train joins the criterion when it is estimated (``armature=True``, ``friction=...``): the
armatures' columns ``qdd_j`` and the friction columns (:mod:`.friction`; the Coulomb sign smoothed
as ``tanh(qd / 0.05 rad/s)`` so that the objective stays smooth for SLSQP) stand beside the rigid
body's, the base parameters found for them together (:func:`~.parameters.base_parameters_with_rotors`),
and each column is scaled to unit norm so that the units of the parameters do not weigh.
"""

from __future__ import annotations

import os
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from .._ui.files import replacing
from ..simulate.control import Fourier
from .friction import parse_friction
from .parameters import base_parameters_with_rotors, rotor_regressor

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["optimize_excitation", "excitation_condition", "write_trajectory_csv"]


def _from_free(x: np.ndarray, n: int, L: int) -> tuple[np.ndarray, np.ndarray]:
    """a, b (n, L) from the free coefficients (harmonics 2..L) with qd(0) = qdd(0) = 0."""
    x = x.reshape(2, n, L - 1)
    a = np.empty((n, L))
    b = np.empty((n, L))
    a[:, 1:], b[:, 1:] = x[0], x[1]
    a[:, 0] = -a[:, 1:].sum(axis=1)
    b[:, 0] = -(b[:, 1:] * np.arange(2, L + 1)).sum(axis=1)
    return a, b


def _criterion(robot: Robot, armature: bool, friction):
    """W(q, qd, qdd) (S n, p) of the parameters estimated: the base columns (with every joint's
    armature when ``armature``), then the friction columns; scaled by the caller."""
    n = robot.n
    joints = tuple(range(n)) if armature else ()
    base = base_parameters_with_rotors(robot, joints) if armature else robot.base_parameters()
    model = parse_friction(friction, smoothing=0.05) if friction else None
    if model is not None and "stribeck" in model.terms:
        model = replace(model, velocities=(0.1,) * n)

    def W(q, qd, qdd):
        Y = robot.regressor(q, qd, qdd)
        if joints:
            Y = np.concatenate([Y, rotor_regressor(qdd, joints, n)], axis=2)
        Y = Y[..., base.indices]
        if model is not None and model.terms:
            Y = np.concatenate([Y, model.regressor(qd)], axis=2)
        return Y.reshape(-1, Y.shape[2])

    return W


def excitation_condition(
    robot: Robot, reference, samples: int = 100, base=None, armature: bool = False, friction=None
) -> float:
    """cond(W) of ``reference`` sampled at ``samples`` instants over one period: the base regressor
    (``base``: given base parameters), or with ``armature``/``friction`` the drive-train columns beside
    it, each column scaled to unit norm (see the module docstring)."""
    t = np.arange(samples) * reference.period / samples
    q, qd, qdd = (np.ascontiguousarray(v) for v in reference(t))
    if not armature and not friction:
        base = robot.base_parameters() if base is None else base
        W = robot.regressor(q, qd, qdd)[..., base.indices].reshape(-1, base.count)
        return float(np.linalg.cond(W))
    W = _criterion(robot, armature, friction)(q, qd, qdd)
    return float(np.linalg.cond(W / np.maximum(np.linalg.norm(W, axis=0), 1e-300)))


def optimize_excitation(
    robot: Robot,
    period: float = 10.0,
    harmonics: int = 5,
    limits: dict | None = None,
    samples: int = 100,
    seed: int = 0,
    maxiter: int = 200,
    armature: bool = False,
    friction=None,
) -> Fourier:
    """A Fourier excitation at rest at t = 0 (and so at every period's end) minimising cond(Y_base)
    within ``limits``: a dict with ``q`` ((lower, upper) arrays; default the robot's finite joint
    limits, else +-pi about 0), ``qd`` and ``qdd`` (per joint maxima; default 1.5 rad/s and 5 rad/s^2)
    and ``tau`` (per joint maxima of the robot's inverse-dynamics torque; default its finite effort
    limits, else none). ``armature``, ``friction``: the drive-train columns estimated with it join the
    criterion (module docstring). The start is the SLSQP optimisation from a random (seeded)
    trajectory scaled into the limits."""
    from scipy.optimize import minimize  # scipy loads only when an excitation is optimised

    if harmonics < 2:
        raise ValueError(f"an excitation at rest at both ends needs at least 2 harmonics, got {harmonics}")
    if not period > 0:
        raise ValueError(f"period must be positive, got {period}")
    n, L = robot.n, harmonics
    limits = dict(limits or {})
    lo, hi = robot.lower_limits.copy(), robot.upper_limits.copy()
    lo = np.where(np.isfinite(lo), lo, -np.pi)
    hi = np.where(np.isfinite(hi), hi, np.pi)
    if "q" in limits:
        lo, hi = (np.broadcast_to(np.asarray(v, dtype=float), (n,)).copy() for v in limits["q"])
    if np.any(hi <= lo):
        raise ValueError(f"position limits: every lower limit must lie below its upper limit, got {lo} and {hi}")
    qd_max = np.broadcast_to(np.asarray(limits.get("qd", 1.5), dtype=float), (n,))
    qdd_max = np.broadcast_to(np.asarray(limits.get("qdd", 5.0), dtype=float), (n,))
    effort = np.array([float(j.effort_limit) for j in robot.joints])
    tau_max = np.broadcast_to(np.asarray(limits.get("tau", effort), dtype=float), (n,))
    torque_limited = bool(np.any(np.isfinite(tau_max)))
    if np.any(~(tau_max > 0)):
        raise ValueError(f"torque limits must be positive (inf: none), got {tau_max}")
    q0 = (lo + hi) / 2
    half = 0.95 * (hi - lo) / 2  # a small margin inside the position limits
    wf = 2 * np.pi / period
    base = robot.base_parameters()
    t = np.arange(samples) * period / samples
    l = np.arange(1, L + 1)
    wt = t[:, None] * wf * l
    S, C = np.sin(wt), np.cos(wt)  # (samples, L)

    def motion(x):
        a, b = _from_free(x, n, L)
        w = wf * l
        q = q0 + (S / w) @ a.T - (C / w) @ b.T
        qd = C @ a.T + S @ b.T
        qdd = -(S * w) @ a.T + (C * w) @ b.T
        return q, qd, qdd

    drive = _criterion(robot, armature, friction) if (armature or friction) else None

    def objective(x):
        q, qd, qdd = motion(x)
        q, qd, qdd = (np.ascontiguousarray(v) for v in (q, qd, qdd))
        if drive is not None:
            W = drive(q, qd, qdd)
            W = W / np.maximum(np.linalg.norm(W, axis=0), 1e-300)
        else:
            W = robot.regressor(q, qd, qdd)[..., base.indices].reshape(-1, base.count)
        # cond(W)^2 = cond(W^T W): the eigenvalues of the small Gram matrix cost a fraction of an SVD of
        # the tall W (which also ran 30x slower than this under a multi-threaded BLAS on a busy
        # machine); they are accurate while cond(W) is well below 1/sqrt(eps) ~ 1e8, else the SVD decides
        lam = np.linalg.eigvalsh(W.T @ W)
        if lam[0] > 1e-12 * lam[-1]:
            return float(0.5 * np.log(lam[-1] / lam[0]))  # log cond: smoother for the optimiser
        sv = np.linalg.svd(W, compute_uv=False)
        return float(np.log(sv[0] / max(sv[-1], 1e-300)))

    finite_tau = np.where(np.isfinite(tau_max), tau_max, 1.0)

    def margins(x):
        q, qd, qdd = motion(x)
        parts = [
            (half - np.abs(q - q0)).ravel() / half.max(),
            (qd_max - np.abs(qd)).ravel() / qd_max.max(),
            (qdd_max - np.abs(qdd)).ravel() / qdd_max.max(),
        ]
        if torque_limited:  # the prior model's torque along the trajectory, joint by joint
            tau = robot.inverse_dynamics(*(np.ascontiguousarray(v) for v in (q, qd, qdd)))
            slack = np.where(np.isfinite(tau_max), (finite_tau - np.abs(tau)) / finite_tau, 1.0)
            parts.append(slack.ravel())
        return np.concatenate(parts)

    rng = np.random.default_rng(seed)
    x0 = rng.normal(size=2 * n * (L - 1))
    q, qd, qdd = motion(x0)
    shrink = min(
        float((half / np.maximum(np.abs(q - q0).max(axis=0), 1e-12)).min()),
        float((qd_max / np.maximum(np.abs(qd).max(axis=0), 1e-12)).min()),
        float((qdd_max / np.maximum(np.abs(qdd).max(axis=0), 1e-12)).min()),
    )
    x0 = 0.9 * shrink * x0
    while torque_limited and np.min(margins(x0)) < 0 and shrink > 1e-6:  # slower until within the torques
        x0, shrink = 0.7 * x0, 0.7 * shrink
    result = minimize(
        objective,
        x0,
        method="SLSQP",
        constraints=[dict(type="ineq", fun=margins)],
        options=dict(maxiter=maxiter, ftol=1e-6),
    )
    x = result.x if np.all(margins(result.x) >= -1e-6) and objective(result.x) < objective(x0) else x0
    a, b = _from_free(x, n, L)
    return Fourier(a, b, wf, q0)


def write_trajectory_csv(reference, path, rate: float = 1000.0, periods: float = 1.0) -> None:
    """Write ``reference`` sampled at ``rate`` Hz over ``periods`` periods as CSV for a controller:
    columns t, q1..qn, qd1..qdn, qdd1..qddn (SI units), one header line."""
    if not rate > 0 or not periods > 0:
        raise ValueError(f"rate and periods must be positive, got {rate} and {periods}")
    t = np.arange(int(round(periods * reference.period * rate)) + 1) / rate
    q, qd, qdd = reference(t)
    n = q.shape[1]
    header = ",".join(["t"] + [f"{p}{j + 1}" for p in ("q", "qd", "qdd") for j in range(n)])
    with replacing(os.fspath(path)) as tmp:  # atomic: a failed run leaves the old file (kinedyn._ui.files)
        np.savetxt(tmp, np.column_stack([t, q, qd, qdd]), delimiter=",", header=header, comments="", fmt="%.10g")
