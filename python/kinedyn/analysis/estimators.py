"""The estimators of :func:`~kinedyn.analysis.identify` on a stacked linear model ``y = W theta + e``
(rows sample by sample, joint by joint), and what the data can and cannot see.

- ``ols``: ordinary least squares, covariance ``sigma^2 (W^T W)^-1``.
- ``wls``: each joint's rows divided by its noise level estimated from the ordinary residuals
  (Gautier & Poignet, Control Eng. Practice 9(12), 2001).
- ``irls``: iteratively reweighted least squares with Huber's weights on the residuals standardised
  by each joint's robust scale (1.4826 x the median absolute residual): a sample far out of the
  noise (a current spike, a missed encoder count) loses its weight, the others keep the weighted
  fit's (Huber, "Robust estimation of a location parameter", Ann. Math. Stat. 35, 1964; Holland &
  Welsch, "Robust regression using iteratively reweighted least-squares", 1977).
- ``iv`` and ``didim`` (closed-loop data) are in :mod:`.closed_loop`: they need a simulation.

Two nonlinear parameters are found by a 1-D search on the profile of the linear fit (variable
projection, Golub & Pereyra, SIAM J. Numer. Anal. 10(2), 1973: for a trial value the linear
parameters are the least-squares ones, so the residual is a function of that value alone):

- the **delay** ``d`` of the torques behind the positions (motor-current torques arrive a few
  milliseconds after the encoder positions): the torques are read at ``t + d`` (cubic-spline
  interpolation of the band-limited log, so ``d`` need not be a whole sample) and the ``d`` of the
  smallest residual kept; ``W`` does not move with ``d``, so one QR factorisation serves every trial;
- the **Stribeck velocity** of each joint (:mod:`.friction`): coordinate descent over the joints,
  each a grid over decades then Brent's method on log v, the other columns' projection fixed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "Identifiability",
    "identifiability",
    "least_squares",
    "irls",
    "shift_torques",
    "estimate_delay",
    "stribeck_search",
    "METHODS",
    "resolve_method",
    "speed_rows",
]

#: the estimators by name (``auto``: ``iv`` when the controller is given, else ``ols``, or ``wls``
#: with ``weighted=True``)
METHODS = ("auto", "ols", "wls", "irls", "iv", "didim")


@dataclass
class Identifiability:
    """What the data can see. ``condition_number``: cond(W) with each column scaled to unit norm
    (the units of the parameters removed); ``singular_values`` of that scaled W; ``groups``: the
    parameter names of each direction the data cannot separate (a singular value below
    ``tolerance`` times the largest): only combinations of a group's parameters are identified, and
    the estimates of its members are the minimum-norm split (their ``std`` is reported infinite)."""

    condition_number: float
    singular_values: np.ndarray
    groups: tuple
    tolerance: float

    def to_dict(self) -> dict:
        return dict(
            scaled_condition_number=self.condition_number,
            unseparable=[list(g) for g in self.groups],
        )


def identifiability(W: np.ndarray, names, tolerance: float = 1e-8) -> Identifiability:
    """Scaled condition number and the groups of columns of ``W`` the data cannot separate."""
    norms = np.linalg.norm(W, axis=0)
    Ws = W / np.where(norms > 0, norms, 1.0)
    _, sv, Vt = np.linalg.svd(Ws, full_matrices=False)
    small = sv < tolerance * sv[0]
    groups = []
    for v in Vt[small]:
        members = np.flatnonzero(np.abs(v) > 0.05 * np.abs(v).max())
        groups.append(tuple(names[i] for i in members))
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    return Identifiability(cond, sv, tuple(groups), tolerance)


def unseparable_mask(ident: Identifiability, names) -> np.ndarray:
    """True for the parameters in one of the groups the data cannot separate."""
    members = {nm for g in ident.groups for nm in g}
    return np.array([nm in members for nm in names], dtype=bool)


def least_squares(W: np.ndarray, y: np.ndarray, n: int, weights: np.ndarray | None = None):
    """(estimate, covariance, residual (S, n)) of min |w (W theta - y)|^2 with per-row weights;
    covariance ``s^2 (W^T Lambda W)^+``, ``s^2`` the weighted residual variance."""
    w = np.ones(len(y)) if weights is None else weights
    Ww = W * w[:, None]
    est, *_ = np.linalg.lstsq(Ww, y * w, rcond=None)
    r = y - W @ est
    dof = max(len(y) - W.shape[1], 1)
    s2 = float(((r * w) ** 2).sum()) / dof
    cov = s2 * np.linalg.pinv(Ww.T @ Ww)
    return est, cov, r.reshape(-1, n)


def joint_noise(r: np.ndarray, p: int, rows: np.ndarray | None = None) -> np.ndarray:
    """Per-joint residual standard deviation (Gautier & Poignet 2001), never zero; ``rows`` (S, n):
    the rows in the fit (left-out rows, e.g. near zero speed, do not count)."""
    S, n = r.shape
    m = np.ones((S, n)) if rows is None else np.asarray(rows, dtype=float).reshape(S, n)
    sig = np.sqrt(((r * m) ** 2).sum(axis=0) / np.maximum(m.sum(axis=0) - p / n, 1.0))
    return np.where(sig > 0, sig, max(float(sig.max()), 1e-300))


def speed_rows(qd: np.ndarray, min_speed: float, spread: int = 0) -> np.ndarray:
    """1 for the rows (sample, joint) whose joint moves at ``|qd_j| >= min_speed``, else 0, flattened
    as the stacked rows. Near zero speed Coulomb friction is not ``Fc sign(qd)``: a joint sticks, or
    its speed chatters about zero within one sample, and the friction there is any torque within the
    static levels. Those rows are left out of the fit (the usual practice of identification with a
    Coulomb model: it holds away from zero speed, Armstrong-Helouvry, Dupont & Canudas de Wit 1994).
    ``spread``: samples left out on either side of a slow stretch too (a filtered log's torques carry
    the stick's torque as far as its low-pass reaches)."""
    if not (np.isfinite(min_speed) and min_speed >= 0):
        raise ValueError(f"min_speed must be a speed >= 0 (rad/s or m/s), got {min_speed}")
    slow = np.abs(np.asarray(qd, dtype=float)) < min_speed
    if spread > 0 and slow.any():
        box = np.ones(2 * spread + 1)
        slow = np.stack([np.convolve(c.astype(float), box, mode="same") > 0 for c in slow.T], axis=1)
    keep = (~slow).astype(float)
    moving = keep.sum(axis=0)
    if min_speed > 0 and np.any(moving < 0.2 * len(keep)):
        j = int(np.argmin(moving))
        raise ValueError(
            f"min_speed={min_speed:g} leaves {int(moving[j])} of {len(keep)} samples of joint {j + 1}: "
            "lower it, or move the joint faster"
        )
    return keep.reshape(-1)


def resolve_method(method: str, weighted: bool, controller) -> str:
    """The estimator ``method`` names (``auto``: IV with a controller, else OLS or WLS)."""
    method = str(method).lower()
    if method not in METHODS:
        raise ValueError(f"unknown identification method '{method}': use one of {', '.join(METHODS)}")
    if method == "auto":
        return "iv" if controller is not None else ("wls" if weighted else "ols")
    if method in ("iv", "didim") and controller is None:
        raise ValueError(
            f"method '{method}' simulates the identified model under the arm's controller: give controller=(t, q, qd) -> tau "
            "(the one that ran the experiment, with its reference)"
        )
    return method


def irls(
    W: np.ndarray,
    y: np.ndarray,
    n: int,
    k: float = 1.345,
    iterations: int = 30,
    tol: float = 1e-10,
    rows: np.ndarray | None = None,
):
    """Huber IRLS (see the module docstring): (estimate, covariance, residual (S, n), weights, iterations).
    ``k`` = 1.345 robust scales: 95 % efficiency on Gaussian noise (Huber 1964). ``rows``: 0/1 per
    stacked row, the rows in the fit (:func:`speed_rows`)."""
    keep = np.ones(len(y)) if rows is None else np.asarray(rows, dtype=float)
    est, _, r = least_squares(W, y, n, keep)
    w = keep
    it = 0
    while it < iterations:
        it += 1
        # per joint: a robust scale of its residuals in the fit (MAD of a Gaussian is 0.6745 sigma)
        kr = keep.reshape(-1, n) > 0
        scale = np.array([1.4826 * np.median(np.abs(c[m] - np.median(c[m]))) for c, m in zip(r.T, kr.T)])
        scale = np.where(scale > 0, scale, max(float(scale.max()), 1e-300))
        u = np.abs(r / scale).reshape(-1)
        huber = np.where(u <= k, 1.0, k / np.maximum(u, 1e-300))
        w = keep * np.sqrt(huber) * np.tile(1.0 / scale, len(r))
        new, _, r = least_squares(W, y, n, w)
        change = np.linalg.norm(new - est) / max(np.linalg.norm(new), 1e-300)
        est = new
        if change < tol:
            break
    _, cov, r = least_squares(W, y, n, w)
    return est, cov, r, w, it


def delay_window(t: np.ndarray, max_delay: float) -> tuple:
    """(edge, window): the samples a delay within ``+-max_delay`` can shift past either end, and the
    mask of the samples every trial delay keeps."""
    if not max_delay >= 0:
        raise ValueError(f"max_delay must be >= 0 s, got {max_delay}")
    edge = int(np.ceil(max_delay / float(np.median(np.diff(t))))) + 1
    window = np.zeros(len(t), dtype=bool)
    window[edge : len(t) - edge] = True
    return edge, window


def shift_torques(t: np.ndarray, tau: np.ndarray, delays) -> np.ndarray:
    """``tau`` read at ``t + delay`` (cubic spline; one delay, or one per trial: (D, S, n))."""
    from scipy.interpolate import CubicSpline  # scipy loads only when a delay is estimated or applied

    spline = CubicSpline(t, tau, axis=0)
    d = np.atleast_1d(np.asarray(delays, dtype=float))
    out = np.stack([spline(np.clip(t + di, t[0], t[-1])) for di in d])
    return out if np.ndim(delays) else out[0]


def _profile(Q: np.ndarray, y: np.ndarray) -> float:
    """Residual sum of squares of y after projection onto the columns of Q (orthonormal)."""
    return float(y @ y - np.sum((Q.T @ y) ** 2))


def estimate_delay(t, tau, W, known, keep, max_delay: float, weights=None) -> tuple[float, np.ndarray, np.ndarray]:
    """The delay of ``tau`` behind the motion in [-max_delay, max_delay] minimising the residual of
    the least-squares fit ``W theta = tau(t + d) - known`` on the samples ``keep`` (the same samples
    for every trial, so the residuals compare). Returns (delay, trial delays, their RSS)."""
    from scipy.optimize import minimize_scalar  # scipy loads only when a delay is estimated

    S, n = tau.shape
    rows = np.repeat(keep, n)
    w = np.ones(S * n) if weights is None else weights
    Wk = (W * w[:, None])[rows]
    Q, _ = np.linalg.qr(Wk / np.maximum(np.linalg.norm(Wk, axis=0), 1e-300))
    rate = 1.0 / float(np.median(np.diff(t)))

    def rss(d: float) -> float:
        y = (shift_torques(t, tau, d) - known).reshape(-1) * w
        return _profile(Q, y[rows])

    # a grid of half samples finds the basin (the residual is smooth in d over a fraction of a period
    # of the fastest motion), Brent's method the minimum inside it
    step = 0.5 / rate
    grid = np.arange(-max_delay, max_delay + step / 2, step) if max_delay > 0 else np.zeros(1)
    values = np.array([rss(d) for d in grid])
    k = int(np.argmin(values))
    if len(grid) < 3:
        return float(grid[k]), grid, values
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    best = minimize_scalar(rss, bounds=(lo, hi), method="bounded", options=dict(xatol=1e-3 / rate))
    d = float(best.x) if best.fun <= values[k] else float(grid[k])
    return d, grid, values


def stribeck_search(build, y: np.ndarray, columns, velocity_range, sweeps: int = 2, weights=None) -> np.ndarray:
    """Stribeck velocities by coordinate descent on the profile residual. ``build(v)`` returns the
    stacked W for the velocities ``v`` (n,); ``columns[j]``: the index of joint j's Stribeck column
    in it (None: no Stribeck term for j); ``velocity_range[j]``: (low, high) searched on a log scale."""
    from scipy.optimize import minimize_scalar  # scipy loads only for a Stribeck fit

    w = np.ones(len(y)) if weights is None else weights
    yw = y * w
    v = np.array([np.sqrt(lo * hi) for lo, hi in velocity_range])
    for _ in range(sweeps):
        for j, c in enumerate(columns):
            if c is None:
                continue
            W = build(v) * w[:, None]
            others = np.delete(W, c, axis=1)
            Q, _ = np.linalg.qr(others / np.maximum(np.linalg.norm(others, axis=0), 1e-300))
            r0 = yw - Q @ (Q.T @ yw)

            def rss(logv: float, j=j, c=c, Q=Q, r0=r0) -> float:
                trial = v.copy()
                trial[j] = np.exp(logv)
                col = build(trial)[:, c] * w
                perp = col - Q @ (Q.T @ col)
                nn = float(perp @ perp)
                return float(r0 @ r0) - (float(perp @ r0) ** 2 / nn if nn > 0 else 0.0)

            lo, hi = np.log(velocity_range[j])
            grid = np.linspace(lo, hi, 13)
            values = [rss(g) for g in grid]
            k = int(np.argmin(values))
            a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
            best = minimize_scalar(rss, bounds=(a, b), method="bounded", options=dict(xatol=1e-4))
            v[j] = np.exp(best.x if best.fun <= values[k] else grid[k])
    return v
