"""``inverse_kinematics``: closed forms where the chain's geometry has one, Levenberg-Marquardt else.

Both solvers run in the native core (``crates/kinedyn-core/src/ik/``); this module
checks the inputs, picks the solver and packs the answer into an :class:`IKResult`.

Target: a 4x4 pose of ``frame`` (default: the robot's tool) in the base, or a 3-vector position of
its origin; a batch ``(N, 4, 4)`` / ``(N, 3)`` returns an :class:`IKBatchResult`.
Residuals: position error ``|p_d - p(q)|`` (m) and orientation error ``|log(R_d R(q)^T)|`` (rad).
Mask: weights of the six error components ``[x, y, z, rx, ry, rz]`` in base axes (0 drops one).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import isfinite
from typing import TYPE_CHECKING, Any

import numpy as np

from .._arrays import real_array, whole_number
from .._core import AnalyticIk, solve_ik
from .._ui.progress import SHOW_AFTER, Delayed, wanted
from ..configuration import space
from ..display import ik_html, ik_markdown
from .completeness import statement
from .idle import settle

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..robot import Robot

__all__ = ["IKResult", "IKBatchResult", "inverse_kinematics", "analytic_structure", "METHODS"]

METHODS = ("auto", "analytic", "numeric")
_POSITION_MASK = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0)
_FULL_MASK = (1.0, 1.0, 1.0, 1.0, 1.0, 1.0)


_F64 = np.dtype(np.float64)


@dataclass(slots=True)
class IKResult:
    """Joint vectors that put a frame at a target, and how well they do.

    ``solutions``: (m, n), nearest to q0 first (m = 0 when none was found); ``position_error``,
    ``orientation_error``: (m,) residual of each (orientation 0 for position targets);
    ``success``: at least one solution within tolerance; ``solver``: ``"analytic:<structure>"`` or
    ``"numeric:lm"``; ``iterations``: LM iterations (0 for closed forms); ``reachable``: False when
    a closed form proved the target out of reach (None when unknown, e.g. the numeric solver failed);
    ``singular``: the target lies on a singularity (a joint was free: it was set from q0);
    ``found``: solutions before the joint-limit filter; ``nearest``: for an unreachable position
    target, the nearest point the frame can reach (``nearest_q`` puts it there).
    """

    solutions: np.ndarray
    success: bool
    position_error: np.ndarray
    orientation_error: np.ndarray
    iterations: int
    solver: str
    reachable: bool | None = True
    singular: bool = False
    found: int = 0
    nearest: np.ndarray | None = None
    nearest_q: np.ndarray | None = None
    message: str = ""
    structure: str | None = None
    max_solutions: int | None = None
    worst_residual: float = float("nan")
    merged: bool = False

    @property
    def completeness(self) -> str:
        """The statement of completeness in words (kinedyn.ik.completeness.statement)."""
        return statement(self)

    @property
    def q(self) -> np.ndarray | None:
        """The solution nearest q0, or None."""
        return self.solutions[0] if len(self.solutions) else None

    def __len__(self) -> int:
        return len(self.solutions)

    def __iter__(self):
        return iter(self.solutions)

    def to_dict(self) -> dict:
        return {
            "success": bool(self.success),
            "solver": self.solver,
            "solutions": self.solutions.tolist(),
            "position_error": self.position_error.tolist(),
            "orientation_error": self.orientation_error.tolist(),
            "iterations": int(self.iterations),
            "reachable": self.reachable,
            "singular": bool(self.singular),
            "found": int(self.found),
            "nearest": None if self.nearest is None else self.nearest.tolist(),
            "nearest_q": None if self.nearest_q is None else self.nearest_q.tolist(),
            "message": self.message,
            "structure": self.structure,
            "max_solutions": self.max_solutions,
            "worst_residual": float(self.worst_residual),
            "merged": bool(self.merged),
            "completeness": self.completeness,
        }

    def __repr__(self) -> str:
        return (
            f"IKResult(success={self.success}, solver={self.solver!r}, solutions={len(self.solutions)}, "
            f"max_position_error={_max(self.position_error):.3g}, max_orientation_error={_max(self.orientation_error):.3g}, "
            f"message={self.message!r})"
        )

    def _repr_html_(self) -> str:  # notebooks: the solutions table (kinedyn.display)
        return ik_html(self)

    def _repr_markdown_(self) -> str:
        return ik_markdown(self)


@dataclass(slots=True)
class IKBatchResult:
    """One answer per target of a batch: ``q`` (N, n) (the solution nearest each q0; where a closed
    form finds none or the numeric solver fails, the numeric solver's best iterate, with
    ``success`` False and its residuals), ``success`` (N,), ``position_error``/``orientation_error``
    (N,), ``iterations`` (N,), ``solver``."""

    q: np.ndarray
    success: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    iterations: np.ndarray
    solver: str
    extra: dict = field(default_factory=dict)

    @property
    def success_rate(self) -> float:
        return float(np.mean(self.success)) if len(self.success) else 0.0

    def __len__(self) -> int:
        return len(self.q)


def _max(a) -> float:
    return float(np.max(a)) if len(a) else float("nan")


# ------------------------------------------------------------------ per-robot cache
class _Chain:
    """What one (robot, frame) pair needs at every call, computed once. ``n`` is the size of a
    configuration (nq; reduced coordinates for a robot with reduced mimic joints)."""

    __slots__ = (
        "frame",
        "n",
        "lower",
        "upper",
        "free_lower",
        "free_upper",
        "start",
        "solver",
        "model",
        "revolute",
        "position_ok",
        "reduction",
        "multi_dof",
    )

    def __init__(self, robot: Robot, frame: str):
        self.frame = robot.frame_index(frame)
        self.n = robot.nq
        model = robot._model
        # reduced mimic joints: the native solver works on the reduced coordinates (ik.rs Reduction)
        self.reduction = None if robot._mimic is None else _reduction(robot._mimic)
        self.model = model if robot._mimic is None else model.native
        self.multi_dof = robot.has_multi_dof_joints
        self.lower = np.ascontiguousarray(robot.lower_limits, dtype=float)
        self.upper = np.ascontiguousarray(robot.upper_limits, dtype=float)
        self.free_lower = np.full(self.n, -np.inf)
        self.free_upper = np.full(self.n, np.inf)
        # default start / reference: the neutral configuration (zeros, identity rotations), 1-DOF
        # joints moved at least 10 % of the range away from finite limits
        span = np.where(np.isfinite(self.upper - self.lower), self.upper - self.lower, 0.0)
        self.start = np.clip(robot.neutral(), self.lower + 0.1 * span, self.upper - 0.1 * span)
        # the q entries that are revolute angles (wrapped into (-pi, pi] when limits are not kept)
        self.revolute = np.array([j.kind == "revolute" for j in robot.joints for _ in range(j.nq)], dtype=bool)
        plain = not self.multi_dof and self.reduction is None
        self.solver = AnalyticIk.detect(self.model, self.frame, self.lower, self.upper) if plain else None
        self.position_ok = self.solver is not None and self.solver.solves_position


def _reduction(m) -> tuple:
    """The native solver's description of a :class:`~kinedyn.description.mimic.MimicMap`: each full q
    entry is one reduced entry times a multiplier plus an offset, each full velocity one reduced
    velocity times a multiplier (the one nonzero of a row of ``Gq`` / ``G``)."""
    Gq = np.asarray(m.Gq_T, dtype=float).T  # (nq_full, nq)
    G = np.asarray(m.G, dtype=float)  # (nv_full, nv)
    q_source = np.argmax(np.abs(Gq), axis=1) if m.nq else np.zeros(len(Gq), dtype=np.intp)
    v_source = np.argmax(np.abs(G), axis=1) if m.nv else np.zeros(len(G), dtype=np.intp)
    rows_q, rows_v = np.arange(len(Gq)), np.arange(len(G))
    return (
        [int(k) for k in q_source],
        [float(x) for x in Gq[rows_q, q_source]],
        [float(x) for x in np.asarray(m.b, dtype=float)],
        [int(k) for k in v_source],
        [float(x) for x in G[rows_v, v_source]],
        [int(k) for k in m.q_keep],
        int(m.nv),
    )


def _chain(robot: Robot, frame: str | None) -> _Chain:
    cache = robot.__dict__.get("_ik_chains")
    if cache is None:
        cache = robot.__dict__["_ik_chains"] = {}
    key = frame or robot.tool
    chain = cache.get(key)
    if chain is None:
        chain = cache[key] = _Chain(robot, key)
    return chain


def analytic_structure(robot: Robot, frame: str | None = None) -> str | None:
    """Name of the closed-form structure detected from the robot's geometry for ``frame``
    (``"planar_2r"``, ``"planar_3r"``, ``"arm_intersecting_shoulder"``, ``"arm_parallel_elbow"``,
    ``"arm_prismatic_base"``, ``"arm_cartesian"``, ``"spherical_wrist"`` and its prismatic-arm forms,
    ``"three_parallel"``, the ``reversed_`` forms, ``"general_6r"``; docs/ik.md), or None."""
    solver = _chain(robot, frame).solver
    return None if solver is None else solver.structure


# ------------------------------------------------------------------ input checks
def _target(target: ArrayLike) -> tuple:
    """(array, position_only, batch)."""
    if isinstance(target, np.ndarray) and target.dtype == np.float64:
        t = target
    else:
        try:
            t = real_array(target, "target")
        except (TypeError, ValueError) as e:
            raise ValueError(
                f"target must be numbers (a 4x4 pose or a 3-vector position), got {type(target).__name__}: {e}"
            ) from None
    shape = t.shape
    if shape == (4, 4) or (len(shape) == 3 and shape[1:] == (4, 4)):
        position, batch = False, len(shape) == 3
    elif shape == (3,) or (len(shape) == 2 and shape[1] == 3):
        position, batch = True, len(shape) == 2
    else:
        raise ValueError(
            f"target must be a 4x4 pose, a 3-vector position, or a batch (N, 4, 4) / (N, 3); got shape {shape}"
        )
    # a target so far away that the solver's squared residuals would overflow float64 (NaN and inf
    # are checked natively)
    if not batch:
        # one target: three Python floats, cheaper than array reductions on a per-call path
        x, y, z = (t if position else t[:3, 3]).tolist()
        if isfinite(x) and isfinite(y) and isfinite(z) and max(abs(x), abs(y), abs(z)) > MAX_REACH:
            raise ValueError(
                f"target position is {max(abs(x), abs(y), abs(z)):.3g} m from the base: beyond {MAX_REACH:g} m, "
                "no robot reaches it (and float64 cannot solve for it)"
            )
        return t, position, batch
    reach = np.abs(t if position else t[..., :3, 3])
    if np.isfinite(reach).all() and reach.max(initial=0.0) > MAX_REACH:
        raise ValueError(
            f"target position is {reach.max():.3g} m from the base: beyond {MAX_REACH:g} m, no robot reaches it "
            "(and float64 cannot solve for it)"
        )
    return t, position, batch


MAX_REACH = 1e100  # m: the description's own bound on any length


def _mask(mask) -> tuple | None:
    if mask is None:
        return None
    try:
        m = real_array(mask, "mask").ravel()
    except (TypeError, ValueError):
        raise ValueError(f"mask must be 6 weights for [x, y, z, rx, ry, rz], got {mask!r}") from None
    if m.shape != (6,):
        raise ValueError(f"mask must have 6 weights for [x, y, z, rx, ry, rz], got {m.size}: {mask!r}")
    if not np.all(np.isfinite(m)) or np.any(m < 0) or not np.any(m > 0):
        raise ValueError(f"mask weights must be finite, >= 0 and not all zero, got {m.tolist()}")
    return tuple(float(v) for v in m)


def _q0(q0, chain: _Chain, batch: int | None, robot: Robot | None = None) -> np.ndarray:
    if q0 is None:
        return chain.start
    q = real_array(q0, "q0")
    n = chain.n
    if q.shape != (n,) and not (batch is not None and q.shape == (batch, n)):
        want = f"({n},)" + (f" or ({batch}, {n})" if batch is not None else "")
        what = (
            " (nq: a configuration; a free-flyer takes 7 entries, a spherical or planar joint 4)"
            if chain.multi_dof
            else ""
        )
        raise ValueError(f"q0 must have shape {want}{what}, got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise ValueError("q0 contains a non-finite value (NaN or inf)")
    if chain.multi_dof and robot is not None:
        # unit quaternions and (cos, sin) pairs, the error naming the joint (kinedyn.configuration)
        space(robot).check(q, "q0")
    return q


# ------------------------------------------------------------------ the solver
def inverse_kinematics(
    robot,
    target,
    q0=None,
    mask=None,
    method: str = "auto",
    respect_limits: bool = True,
    *,
    frame: str | None = None,
    tolerance: float = 1e-9,
    max_iterations: int = 50,
    restarts: int = 50,
    seed: int = 0,
    progress: bool | None = None,
):
    """Joint vectors that put ``frame`` (default: the tool) at ``target``.

    ``target``: 4x4 pose or 3-vector position of the frame origin (or a batch of either).
    ``q0``: start of the numeric solver and reference of the closed forms (solutions are ordered by
    their distance to it, revolute angles are moved by 2 pi k next to it, free joints at
    singularities take its value); default zeros, kept 10 % of the range inside finite limits. ``mask``: 6 weights of
    ``[x, y, z, rx, ry, rz]`` (base axes); ``(1, 1, 1, 0, 0, 0)`` is a position target.
    ``method``: ``"auto"`` (closed form when the geometry has one, else numeric), ``"analytic"``
    or ``"numeric"``. ``respect_limits``: drop (closed form) or never leave (numeric) joint limits.
    ``tolerance``: largest position (m) and orientation (rad) residual accepted.
    ``max_iterations``/``restarts``/``seed``: numeric solver (iterations per attempt, random restarts).
    ``progress``: a bar on stderr for a numeric batch that runs over a second (default: when stderr
    is a terminal); the answers are the same with or without it.

    Joints that cannot move the frame's target rows (outside its chain, or not needed by a
    position target) stay at ``q0`` (:mod:`kinedyn.ik.idle`).

    Returns an :class:`IKResult` (one target) or :class:`IKBatchResult` (a batch).
    """
    if not robot.__dict__.get("_ik_has_joints"):  # robot.nv sums over the joints: asked once
        if robot.nv == 0:
            raise ValueError(
                f"robot '{robot.name}' has no moving joint: no joint value can move its frames "
                "(floating_base=True makes a lone body a free flyer)"
            )
        robot.__dict__["_ik_has_joints"] = True
    result = _solve(
        robot, target, q0, mask, method, respect_limits, frame, tolerance, max_iterations, restarts, seed, progress
    )
    return settle(robot, frame, target, mask, q0, result)


def _solve(robot, target, q0, mask, method, respect_limits, frame, tolerance, max_iterations, restarts, seed, progress):
    if (
        type(max_iterations) is not int
        or type(restarts) is not int
        or type(seed) is not int
        or not 0 <= max_iterations <= _MAX_INT
        or not 0 <= restarts <= _MAX_INT
        or not 0 <= seed < 2**64
        or type(tolerance) is not float
        or not 0.0 < tolerance < np.inf
    ):
        max_iterations, restarts, seed, tolerance = _check_settings(tolerance, max_iterations, restarts, seed)
    chain = _chain(robot, frame)
    # fast path: one float64 target, closed form, no mask (checks of the target happen natively)
    if (
        mask is None
        and method == "auto"
        and type(target) is np.ndarray
        and target.dtype is _F64
        and chain.solver is not None
    ):
        shape = target.shape
        if shape == (4, 4) or (shape == (3,) and chain.position_ok):
            q_ref = chain.start if q0 is None else _q0(q0, chain, None, robot)
            return _analytic(robot, chain, target, q_ref, shape == (3,), respect_limits, tolerance, seed)
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    t, position, batch = _target(target)
    weights = _mask(mask)
    if weights is not None and not position:
        if weights == _POSITION_MASK:
            # a pose with a position mask is a position target
            t = t[..., :3, 3]
            position = True
            weights = None
        elif weights == _FULL_MASK:
            weights = None
    solver = chain.solver
    analytic_ok = solver is not None and weights is None and (not position or chain.position_ok)
    if method == "analytic" and not analytic_ok:
        raise ValueError(_why_not_analytic(robot, chain, position, weights))
    use_analytic = analytic_ok and method != "numeric"
    nb = len(t) if batch else None
    q_start = _q0(q0, chain, nb, robot)
    if batch:
        return _batch(
            robot,
            chain,
            t,
            q_start,
            position,
            weights,
            use_analytic,
            respect_limits,
            tolerance,
            max_iterations,
            restarts,
            seed,
            progress,
        )
    if use_analytic:
        return _analytic(robot, chain, t, q_start, position, respect_limits, tolerance, seed)
    return _numeric(
        robot, chain, t, q_start, position, weights, respect_limits, tolerance, max_iterations, restarts, seed
    )


_MAX_INT = 2**31 - 1


def _check_settings(tolerance, max_iterations, restarts, seed) -> tuple:
    """The numeric settings checked at the boundary (ValueError naming the argument, never the
    OverflowError of a conversion to a native integer): (max_iterations, restarts, seed, tolerance)."""
    try:
        tol = float(tolerance)
    except (TypeError, ValueError):
        raise ValueError(f"tolerance must be a positive number (m and rad), got {tolerance!r}") from None
    if isinstance(tolerance, (bool, complex)) or not 0.0 < tol < np.inf:
        raise ValueError(f"tolerance must be a positive number (m and rad), got {tolerance!r}")
    return (
        whole_number(max_iterations, "max_iterations", 0, _MAX_INT),
        whole_number(restarts, "restarts", 0, _MAX_INT),
        whole_number(seed, "seed", 0, 2**64 - 1),
        tol,
    )


def _why_not_analytic(robot: Robot, chain: _Chain, position: bool, weights) -> str:
    if chain.multi_dof or chain.reduction is not None:
        what = "floating, spherical or planar joints" if chain.multi_dof else "reduced mimic joints moving this frame"
        return f"robot '{robot.name}' has {what}: the closed forms solve chains of revolute and prismatic joints only; use method='numeric'"
    if chain.solver is None:
        return (
            f"robot '{robot.name}' has no closed-form inverse kinematics here: its axes match none of the "
            "structures kinedyn solves in closed form (planar 2R/3R, an RRR arm whose first two axes meet or whose "
            "2nd and 3rd are parallel, a prismatic first joint under axes that meet, a gantry, 6R with a spherical wrist, 6R with three parallel axes, any other 6R arm with "
            "finitely many solutions); use method='numeric'"
        )
    if weights is not None:
        return "a weighted mask has no closed form; use method='numeric' (or no mask / a position-only mask)"
    return (
        f"robot '{robot.name}' ({chain.solver.structure}, n={chain.n}) has no closed form for a position-only target "
        "(the position leaves joints free); give a 4x4 pose or use method='numeric'"
    )


def _analytic(
    robot: Robot, chain: _Chain, t, q_ref, position: bool, respect_limits: bool, tolerance: float, seed: int
) -> IKResult:
    solver = chain.solver
    assert solver is not None  # callers take this route only for a chain with a closed form
    sols, pe, oe, found, singular, most, worst, merged = solver.solve_stated(t, q_ref, respect_limits, tolerance)
    structure = solver.structure
    name = "analytic:" + structure
    stated: dict[str, Any] = dict(structure=structure, max_solutions=most, worst_residual=worst, merged=merged)
    if len(sols):
        message = f"{len(sols)} solution(s)" + (" (singular target: a free joint was set from q0)" if singular else "")
        # positional: this is the per-call path of every closed form (docs/ik.md, "Speed")
        return IKResult(
            sols, True, pe, oe, 0, name, True, singular, found, None, None, message, structure, most, worst, merged
        )
    if found:
        message = f"reachable, but all {found} solution(s) violate the joint limits (respect_limits=False lists them)"
        return IKResult(sols, False, pe, oe, 0, name, True, singular, found, message=message, **stated)
    result = IKResult(
        sols, False, pe, oe, 0, name, False, singular, 0, message="target out of reach: no solution exists", **stated
    )
    if position:
        _nearest(robot, chain, t, q_ref, result, seed)
    else:
        result.message = "target out of reach: no joint vector gives this pose"
    return result


def _nearest(robot: Robot, chain: _Chain, p, q_ref, result: IKResult, seed: int) -> None:
    """The reachable point nearest an unreachable position (least squares by LM with restarts)."""
    q, _, _, _, _ = solve_ik(
        chain.model, chain.frame, p, q_ref, chain.lower, chain.upper, np.ones(6), 200, 8, 1e-12, 1e-12, 1e-6, 0.5, seed
    )
    result.nearest_q = q
    result.nearest = robot.pose(q, robot.frame_names[chain.frame])[:3, 3]
    d = float(np.linalg.norm(result.nearest - p))
    result.message = f"target out of reach: no solution exists; the nearest reachable point is {np.array2string(result.nearest, precision=6)} ({d:.6g} m away)"


def _levenberg_marquardt(
    chain: _Chain,
    t,
    q0,
    w,
    respect_limits: bool,
    tolerance: float,
    max_iterations: int,
    restarts: int,
    seed: int,
    progress: bool | None = False,
) -> tuple:
    """The core's LM solver for one target or a batch: (q, converged, position error, orientation
    error, iterations), revolute angles wrapped when the limits are not kept. With progress, a batch
    goes to the core in chunks (each target's restarts follow from the seed and its index in the
    whole batch, so the answers do not change)."""
    lower, upper = (chain.lower, chain.upper) if respect_limits else (chain.free_lower, chain.free_upper)
    tol = min(tolerance, 1e-10)

    def solve(first: int, stop: int | None):
        tk = t if stop is None else t[first:stop]
        qk = q0 if (stop is None or q0.ndim == 1) else q0[first:stop]
        return solve_ik(
            chain.model,
            chain.frame,
            tk,
            qk,
            lower,
            upper,
            w,
            max_iterations,
            restarts,
            tol,
            tol,
            1e-6,
            0.5,
            seed,
            first,
            reduction=chain.reduction,
        )

    count = (
        len(t) if t.ndim == 3 or (t.ndim == 2 and t.shape[1] == 3) else 0
    )  # a batch: (N, 4, 4) poses or (N, 3) points
    if count <= IK_CHUNK or not wanted(progress):
        q, ok, pe, oe, it = solve(0, None)
    else:
        bar = Delayed(
            True,
            count,
            "inverse kinematics",
            "{task.completed:.0f} / {task.total:.0f} targets",
            SHOW_AFTER if progress is None else 0.0,
        )
        parts = []
        try:
            for first in range(0, count, IK_CHUNK):
                parts.append(solve(first, min(first + IK_CHUNK, count)))
                bar.update(min(first + IK_CHUNK, count))
        finally:
            bar.close()
        q, ok, pe, oe, it = (np.concatenate(arrays) for arrays in zip(*parts))
    if not respect_limits:
        q = _wrap(q, chain)
    return q, ok, pe, oe, it


def _numeric(
    robot: Robot,
    chain: _Chain,
    t,
    q0,
    position: bool,
    weights,
    respect_limits: bool,
    tolerance: float,
    max_iterations: int,
    restarts: int,
    seed: int,
) -> IKResult:
    w = np.asarray(weights if weights is not None else _FULL_MASK)
    q, ok, pe, oe, it = _levenberg_marquardt(chain, t, q0, w, respect_limits, tolerance, max_iterations, restarts, seed)
    ok = bool(ok) and pe <= tolerance and oe <= tolerance
    empty = np.zeros(0)
    if ok:
        singular = _is_singular(robot, chain, q, w if not position else np.asarray(_POSITION_MASK))
        return IKResult(
            q[None, :],
            True,
            np.array([pe]),
            np.array([oe]),
            int(it),
            "numeric:lm",
            True,
            singular,
            1,
            message="converged" + (" at a singular configuration" if singular else ""),
            worst_residual=max(float(pe), float(oe)),
            merged=singular,
        )
    result = IKResult(
        np.zeros((0, chain.n)),
        False,
        empty,
        empty,
        int(it),
        "numeric:lm",
        None,
        False,
        0,
        nearest_q=q,
        message=f"the numeric solver did not converge after {restarts} restarts (best residual {pe:.3g} m, {oe:.3g} rad); the target may be out of reach",
    )
    if position:
        result.nearest = robot.pose(q, robot.frame_names[chain.frame])[:3, 3]
        result.message += f"; nearest point reached {np.array2string(result.nearest, precision=6)}"
    return result


def _wrap(q: np.ndarray, chain: _Chain) -> np.ndarray:
    """Revolute angles into (-pi, pi] (numeric runs without limits)."""
    out = q.copy()
    r = chain.revolute
    out[..., r] = np.mod(out[..., r] + np.pi, 2 * np.pi) - np.pi
    return out


def _is_singular(robot: Robot, chain: _Chain, q: ArrayLike, weights) -> bool:
    J = robot.jacobian(q, robot.frame_names[chain.frame])[np.asarray(weights) > 0]
    s = np.linalg.svd(J, compute_uv=False)
    return bool(len(s) < J.shape[0] or s[-1] < 1e-6 * max(1.0, s[0]))


IK_CHUNK = 256  # targets per native call when a batch shows progress


def _batch(
    robot: Robot,
    chain: _Chain,
    t,
    q0,
    position,
    weights,
    use_analytic,
    respect_limits,
    tolerance,
    max_iterations,
    restarts,
    seed,
    progress,
) -> IKBatchResult:
    N = len(t)
    w = np.asarray(weights if weights is not None else _FULL_MASK)
    if use_analytic:
        solver = chain.solver
        assert solver is not None  # use_analytic means the chain has a closed form
        refs = np.ascontiguousarray(np.broadcast_to(q0, (N, chain.n)))
        q, ok, pe, oe = solver.solve_nearest(t, refs, respect_limits, tolerance)
        it = np.zeros(N, dtype=np.int64)
        none = ~ok
        if none.any():  # no closed-form solution: the numeric solver's best attempt, never a NaN row (§8)
            qn, okn, pen, oen, itn = _levenberg_marquardt(
                chain,
                np.ascontiguousarray(t[none]),
                np.ascontiguousarray(refs[none]),
                w,
                respect_limits,
                tolerance,
                max_iterations,
                restarts,
                seed,
            )
            q[none], pe[none], oe[none], it[none] = qn, pen, oen, itn
            ok[none] = okn & (pen <= tolerance) & (oen <= tolerance)
        return IKBatchResult(q, ok, pe, oe, it, "analytic:" + solver.structure)
    q, ok, pe, oe, it = _levenberg_marquardt(
        chain, t, q0, w, respect_limits, tolerance, max_iterations, restarts, seed, progress
    )
    ok = ok & (pe <= tolerance) & (oe <= tolerance)
    return IKBatchResult(q, ok, pe, oe, it, "numeric:lm")


# the per-(robot, frame) cache and the input checks, shared with the all-branch and seven-joint
# solvers (kinedyn.ik.branches, kinedyn.ik.redundancy)
chain_of = _chain
check_target = _target
check_q0 = _q0
