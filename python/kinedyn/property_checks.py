"""The verdicts of property checks, numeric or symbolic: :class:`Check` (one property, its residual,
tolerance and how it was decided), :class:`PropertiesReport` (a list of them), and the global search
for the inertia bounds of Spong eq. 9.120 (:func:`global_inertia_bounds`). Both the numeric checks of a
robot (:mod:`kinedyn.analysis.properties`) and the exact proofs on symbolic equations
(:mod:`kinedyn.symbolic.derive.proofs`) report in these terms."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from . import display
from ._ui.progress import SHOW_AFTER, Delayed, wanted

__all__ = ["STATUSES", "Check", "PropertiesReport", "InertiaBounds", "global_inertia_bounds"]


#: how a check was decided: exact simplification, numbers at random states, a global optimisation, a
#: simulated trajectory; "failed" (a counterexample) and "skipped" (could not be evaluated, says why)
STATUSES = ("proved", "sampled", "searched", "simulated", "failed", "skipped")


@dataclass
class Check:
    """One property: ``passed`` when ``residual <= tolerance``; ``detail`` says what was measured;
    ``status`` how it was decided (one of :data:`STATUSES`; "sampled" or "failed" when not given)."""

    name: str
    passed: bool
    residual: float
    tolerance: float
    detail: str = ""
    source: str = ""
    data: dict = field(default_factory=dict)
    status: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            self.status = "sampled" if self.passed else "failed"
        elif not self.passed:
            self.status = "failed"
        if self.status not in STATUSES:
            raise ValueError(f"check status must be one of {STATUSES}, got {self.status!r}")

    @property
    def proved(self) -> bool:
        return self.status == "proved"

    def to_dict(self) -> dict:
        return dict(
            name=self.name,
            passed=self.passed,
            status=self.status,
            residual=self.residual,
            tolerance=self.tolerance,
            detail=self.detail,
            source=self.source,
            **{k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.data.items()},
        )


@dataclass
class PropertiesReport:
    robot: str
    samples: int
    checks: list

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def __getitem__(self, name: str) -> Check:
        for c in self.checks:
            if c.name == name or c.name.startswith(name):
                return c
        raise KeyError(f"no check named '{name}' (checks: {[c.name for c in self.checks]})")

    def to_dict(self) -> dict:
        return dict(
            robot=self.robot, samples=self.samples, passed=self.passed, checks=[c.to_dict() for c in self.checks]
        )

    def _repr_html_(self) -> str:  # notebooks: the checks as a table (kinedyn.display)
        return display.properties_html(self)

    def __str__(self) -> str:
        lines = [f"properties of '{self.robot}' over {self.samples} sampled states:"]
        for c in self.checks:
            mark = "FAIL" if not c.passed else c.status
            lines.append(f"  [{mark:9s}] {c.name}: residual {c.residual:.3g} (tolerance {c.tolerance:.3g}); {c.detail}")
        return "\n".join(lines)


@dataclass
class InertiaBounds:
    """Uniform bounds ``lambda_min I <= M(q) <= lambda_max I`` over a box of configurations (Spong eq.
    9.120), each with the configuration that attains it (``eigvalsh(M(q_lambda_min))[0] ==
    lambda_min``), and the extremes of the random sample the search started from."""

    lambda_min: float
    q_lambda_min: np.ndarray
    lambda_max: float
    q_lambda_max: np.ndarray
    sampled_min: float
    sampled_max: float
    samples: int
    starts: int
    lower: np.ndarray
    upper: np.ndarray
    periodic: np.ndarray
    #: how the configurations were searched, when not the box ``lower``/``upper`` of the coordinates
    #: themselves (a robot with multi-DOF joints: the chart of :class:`_ManifoldChart`)
    space: str = ""
    #: local searches run and planned: fewer run when the time budget ran out, and the bounds are
    #: then the extremes of the sample and of the searches that ran (an estimate, flagged as such)
    searched: int = 0
    planned: int = 0
    time_budget: float | None = None

    @property
    def complete(self) -> bool:
        """Every planned local search ran (the time budget, if any, did not cut the search short)."""
        return self.searched >= self.planned

    def describe(self) -> str:
        box = self.space or ", ".join(
            ("periodic" if p else f"[{lo:.3g}, {hi:.3g}]") for lo, hi, p in zip(self.lower, self.upper, self.periodic)
        )
        if self.starts == 0 and self.space:  # nothing to search (M constant)
            return f"lambda_min = {self.lambda_min:.8g}, lambda_max = {self.lambda_max:.8g} at q = {np.array2string(self.q_lambda_min, precision=4)} ({self.space})"
        how = (
            f"global search: {self.starts} truncated-Newton starts with the analytic eigenvalue gradient from the best of "
            f"{self.samples} random configurations, whose extremes were {self.sampled_min:.8g} and {self.sampled_max:.8g}; q in {box}"
        )
        if not self.complete:
            how = (
                f"a sampled bound, not a searched one: the time budget of {self.time_budget:g} s ran out with "
                f"{self.searched} of {self.planned} local searches finished, so these are the extremes of {self.samples} random "
                f"configurations and the searches that ran (the true lambda_min may be lower, lambda_max higher; "
                f"a larger budget searches further); q in {box}"
            )
        return (
            f"lambda_min = {self.lambda_min:.8g} at q = {np.array2string(self.q_lambda_min, precision=4)}, "
            f"lambda_max = {self.lambda_max:.8g} at q = {np.array2string(self.q_lambda_max, precision=4)} ({how})"
        )


class _OutOfTime(Exception):
    """Raised inside a local search when the inertia-bound search's time budget is spent."""


def _wrap(q: np.ndarray, periodic: np.ndarray) -> np.ndarray:
    q = np.array(q, dtype=float)
    q[periodic] = (q[periodic] + np.pi) % (2 * np.pi) - np.pi
    return q


def global_inertia_bounds(
    mass_matrix: Callable[[np.ndarray], np.ndarray],
    mass_matrix_gradient: Callable[[np.ndarray], np.ndarray],
    lower,
    upper,
    periodic=None,
    samples: int = 256,
    starts: int = 12,
    seed: int = 0,
    wrap: Callable[[np.ndarray], np.ndarray] | None = None,
    time_budget: float | None = None,
    progress: bool | None = False,
) -> InertiaBounds:
    """The least and greatest eigenvalue of M(q) over the box ``lower <= q <= upper`` (coordinates
    marked ``periodic`` are searched without bounds, M being 2 pi-periodic in them, and reported in
    [-pi, pi)), by a multistart local optimisation: ``samples`` uniform random configurations, then
    truncated Newton (SciPy TNC: bounded, and free of the BLAS threading that made L-BFGS-B 30x slower on a
    loaded machine) from the ``starts`` best of them (and as many more random ones), minimising lambda_min(q)
    and -lambda_max(q) with the analytic gradient of a simple eigenvalue, d lambda / dq_k = v^T (dM/dq_k) v
    (v its unit eigenvector). ``mass_matrix(q)``: (n, n) for one q, (N, n, n) for a batch (N, n);
    ``mass_matrix_gradient(q)``: (n_q, n, n), dM/dq_k stacked. ``wrap(q)``: the representative of a
    searched point to report (default: periodic coordinates into [-pi, pi)); the box of the periodic
    coordinates is where the samples are drawn. A search, not a proof: the reported bounds are
    attained (at the returned configurations) and no worse than every sample. ``time_budget``
    (seconds, default none): half of it for the least eigenvalue's searches, the rest for the
    greatest's; a search running when its share is spent stops at the best point it reached, and the
    result says how many searches finished (:attr:`InertiaBounds.complete`); ``progress``: a bar on stderr over the local searches
    (None: when stderr is a terminal and the search runs over a second)."""
    from scipy.optimize import minimize  # scipy loads only when bounds are searched

    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    nq = len(lower)
    periodic = np.zeros(nq, dtype=bool) if periodic is None else np.asarray(periodic, dtype=bool)
    if (
        upper.shape != lower.shape
        or periodic.shape != lower.shape
        or np.any(~np.isfinite(lower))
        or np.any(~np.isfinite(upper))
        or np.any(upper < lower)
    ):
        raise ValueError(
            f"the search box must be finite with lower <= upper, one entry per coordinate: lower {lower}, upper {upper}"
        )
    if samples < 1 or starts < 0:
        raise ValueError(f"samples must be >= 1 and starts >= 0, got {samples} and {starts}")
    rng = np.random.default_rng(seed)
    Q = rng.uniform(lower, upper, size=(samples, nq))
    eig = np.linalg.eigvalsh(np.asarray(mass_matrix(Q), dtype=float))
    lo_s, hi_s = eig[:, 0], eig[:, -1]
    bounds = [(None, None) if p else (a, b) for a, b, p in zip(lower, upper, periodic)]

    def picks(sign: float, column: int) -> tuple[np.ndarray, np.ndarray, list[int]]:
        values = sign * (lo_s if column == 0 else hi_s)
        order = np.argsort(values)
        chosen = list(order[:starts]) + list(rng.choice(samples, size=min(starts, samples), replace=False))
        return values, order, list(dict.fromkeys(int(i) for i in chosen))

    low, high = picks(1.0, 0), picks(-1.0, -1)
    planned = len(low[2]) + len(high[2])
    start_time, done = time.perf_counter(), 0
    bar = Delayed(
        wanted(progress),
        planned,
        "inertia bounds",
        "{task.completed:.0f} / {task.total:.0f} searches",
        SHOW_AFTER if progress is None else 0.0,
    )

    def extreme(sign: float, column: int, values, order, chosen, deadline):
        nonlocal done
        seen: list = [np.inf, None]  # the best point a search has evaluated (kept when time runs out)

        def f(q):
            if deadline is not None and time.perf_counter() > deadline:
                raise _OutOfTime
            w, V = np.linalg.eigh(np.asarray(mass_matrix(q), dtype=float))
            v = V[:, column]
            dM = np.asarray(mass_matrix_gradient(q), dtype=float)
            if sign * w[column] < seen[0]:
                seen[:] = [sign * w[column], np.array(q, dtype=float)]
            return sign * w[column], sign * np.einsum("i,kij,j->k", v, dM, v)

        best_q, best = Q[order[0]].copy(), values[order[0]]
        for k in chosen:
            seen[:] = [np.inf, None]
            try:
                res = minimize(
                    f,
                    Q[k],
                    jac=True,
                    method="TNC",
                    bounds=bounds,
                    options=dict(maxfun=400, ftol=1e-15, xtol=1e-12, gtol=1e-12),
                )
                x, finished = np.array(res.x, dtype=float), True
            except _OutOfTime:  # the budget ran out inside this search: keep the best point it reached
                if seen[1] is None:
                    break
                x, finished = seen[1], False
            x[~periodic] = np.clip(x[~periodic], lower[~periodic], upper[~periodic])
            x = _wrap(x, periodic) if wrap is None else wrap(x)
            val = sign * np.linalg.eigvalsh(np.asarray(mass_matrix(x), dtype=float))[column]
            if val < best:
                best, best_q = val, x
            if not finished:
                break
            done += 1
            bar.update(done)
        return sign * best, best_q

    # the budget is shared: the least eigenvalue's searches end at half of it, the greatest's at all of it
    deadlines = (None, None) if time_budget is None else (start_time + time_budget / 2, start_time + time_budget)
    try:
        lmin, qmin = extreme(1.0, 0, *low, deadlines[0])
        lmax, qmax = extreme(-1.0, -1, *high, deadlines[1])
    finally:
        bar.close()
    return InertiaBounds(
        float(lmin),
        qmin,
        float(lmax),
        qmax,
        float(lo_s.min()),
        float(hi_s.max()),
        samples,
        starts,
        lower,
        upper,
        periodic,
        searched=done,
        planned=planned,
        time_budget=time_budget,
    )
