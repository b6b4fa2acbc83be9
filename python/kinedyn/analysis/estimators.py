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


def joint_noise(r: np.ndarray, p: int) -> np.ndarray:
    """Per-joint residual standard deviation (Gautier & Poignet 2001), never zero."""
    S, n = r.shape
    sig = np.sqrt((r**2).sum(axis=0) / max(S - p / n, 1.0))
    return np.where(sig > 0, sig, max(float(sig.max()), 1e-300))


def irls(W: np.ndarray, y: np.ndarray, n: int, k: float = 1.345, iterations: int = 30, tol: float = 1e-10):
    """Huber IRLS (see the module docstring): (estimate, covariance, residual (S, n), weights, iterations).
    ``k`` = 1.345 robust scales: 95 % efficiency on Gaussian noise (Huber 1964)."""
    est, _, r = least_squares(W, y, n)
    w = np.ones(len(y))
    it = 0
    while it < iterations:
        it += 1
        # per joint: a robust scale of its residuals (MAD of a Gaussian is 0.6745 sigma)
        scale = 1.4826 * np.median(np.abs(r - np.median(r, axis=0)), axis=0)
        scale = np.where(scale > 0, scale, max(float(scale.max()), 1e-300))
        u = np.abs(r / scale).reshape(-1)
        huber = np.where(u <= k, 1.0, k / np.maximum(u, 1e-300))
        w = np.sqrt(huber) * np.tile(1.0 / scale, len(r))
        new, _, r = least_squares(W, y, n, w)
        change = np.linalg.norm(new - est) / max(np.linalg.norm(new), 1e-300)
        est = new
        if change < tol:
            break
    _, cov, r = least_squares(W, y, n, w)
    return est, cov, r, w, it


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
