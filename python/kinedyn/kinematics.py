"""Velocity and force mapping through the Jacobian (Spong ch. 4; Yoshikawa 1985).

All functions take the task rows to use: ``task="full"`` (6 rows [v; w]), ``"position"`` (the 3
rows of the linear velocity), ``"orientation"``, ``"planar"`` (rows x, y: the tutorial's 2x2
Jacobian of a planar arm) or an explicit list of row indices. Jacobians are the ``reference``
Jacobians of :meth:`kinedyn.Robot.jacobian` (default "world": base axes, textbook J = [J_v; J_w]).

Second order: the kinematic Hessian ``dJ/dq`` (:func:`jacobian_hessian`, Robotics Toolbox's
``hessian0``; :func:`hessian_in_frame_axes`, its ``hessiane``) and the gradient of Yoshikawa's
manipulability (:func:`manipulability_jacobian`, RTB's ``jacobm``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Union

import numpy as np

from ._arrays import finite_result, real_array

if TYPE_CHECKING:
    from ._typing import ArrayLike
    from .robot import Robot

__all__ = [
    "ROW_NAMES",
    "task_rows",
    "spanned_rows",
    "analysis_rows",
    "task_jacobian",
    "tool_velocity",
    "joint_torques",
    "joint_velocities",
    "manipulability",
    "manipulability_jacobian",
    "jacobian_hessian",
    "hessian_in_frame_axes",
    "singular_values",
    "SingularityReport",
    "singularity_report",
]

_TASKS = {
    "full": [0, 1, 2, 3, 4, 5],
    "position": [0, 1, 2],
    "orientation": [3, 4, 5],
    "planar": [0, 1],
    "planar_pose": [0, 1, 5],
}
ROW_NAMES = ["vx", "vy", "vz", "wx", "wy", "wz"]

Task = Union[str, Sequence[int]]


def task_rows(task: Task) -> list:
    """Row indices of the 6-row Jacobian for a task name or an explicit list."""
    if isinstance(task, str):
        try:
            return list(_TASKS[task])
        except KeyError:
            raise ValueError(
                f"unknown task '{task}' (use one of {list(_TASKS)} or a list of row indices 0..5)"
            ) from None
    rows = [int(r) for r in task]
    if not rows or any(r < 0 or r > 5 for r in rows) or len(set(rows)) != len(rows):
        raise ValueError(f"task rows must be distinct indices in 0..5, got {list(task)}")
    return rows


def task_jacobian(
    robot: Robot, q: ArrayLike, frame: str | None = None, task: Task = "full", reference: str = "world"
) -> np.ndarray:
    """The selected rows of the frame Jacobian: (m, n), or (N, m, n) for a batch of q."""
    return robot.jacobian(q, frame, reference)[..., task_rows(task), :]


def _vector(x, size: int, what: str, J: np.ndarray) -> np.ndarray:
    """``x`` as (size,) or, next to a batch of Jacobians (N, m, n) or alone, as a batch (N, size)."""
    v = real_array(x, what)
    batch = J.shape[0] if J.ndim == 3 else None
    if v.shape != (size,) and not (v.ndim == 2 and v.shape[1] == size and (batch is None or v.shape[0] == batch)):
        want = f"({size},)" + (f" or ({batch}, {size})" if batch is not None else f" or (N, {size})")
        raise ValueError(f"{what} must have {size} components for this task, shape {want}; got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{what} contains NaN or inf")
    return v


def _mul(A: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A @ v for stacks of matrices (..., m, k) and of vectors (..., k)."""
    return (A @ v[..., None])[..., 0]


def tool_velocity(
    robot: Robot, q: ArrayLike, qd: ArrayLike, frame: str | None = None, task: Task = "full", reference: str = "world"
) -> np.ndarray:
    """Tool twist (selected rows) ``J(q) qd``; (N, m) for a batch of q and/or qd."""
    J = task_jacobian(robot, q, frame, task, reference)
    with np.errstate(over="ignore", invalid="ignore"):
        v = _mul(J, _vector(qd, robot.n, "qd", J))
    return finite_result(v, "tool_velocity: v", v.ndim - 1)


def joint_torques(
    robot: Robot,
    q: ArrayLike,
    wrench: ArrayLike,
    frame: str | None = None,
    task: Task = "full",
    reference: str = "world",
) -> np.ndarray:
    """Static joint torques balancing a tool wrench: ``tau = J^T F`` (Spong §4.10); (N, n) for a batch.

    ``wrench`` has one entry per task row (e.g. (Fx, Fy) with ``task="planar"``; [force; moment]
    with ``"full"``). These are the torques the joints must apply for the tool to exert F on the
    environment (equivalently, the joint torques caused by F applied to the tool, with a sign flip).
    """
    J = task_jacobian(robot, q, frame, task, reference)
    with np.errstate(over="ignore", invalid="ignore"):
        tau = _mul(np.swapaxes(J, -1, -2), _vector(wrench, J.shape[-2], "wrench", J))
    return finite_result(tau, "joint_torques: tau", tau.ndim - 1)


def joint_velocities(
    robot,
    q,
    velocity,
    frame: str | None = None,
    task: Task = "full",
    method: str = "pinv",
    damping: float = 1e-2,
    reference: str = "world",
) -> np.ndarray:
    """Joint rates producing a tool velocity: ``qd = J^-1 v`` (``method="inverse"``, square and
    non-singular J only), the Moore-Penrose pseudo-inverse (``"pinv"``: least-squares, minimum norm)
    or damped least squares (``"dls"``: ``J^T (J J^T + lambda^2 I)^-1 v``, Nakamura & Hanafusa 1986;
    Wampler 1986), which stays bounded near singularities. (N, n) for a batch of q and/or v.

    Both ``"pinv"`` and ``"dls"`` are computed from the SVD ``J = U S V^T`` as
    ``V diag(s_i / (s_i^2 + lambda^2)) U^T v`` (Wampler 1986, eq. 13; ``lambda = 0`` for pinv), so
    that ``damping=0`` is the minimum-norm least-squares answer even at a singularity: singular
    values below ``max(m, n) eps s_max`` (NumPy's ``matrix_rank`` tolerance) count as zero."""
    if method not in ("inverse", "pinv", "dls"):
        raise ValueError(f"method must be 'inverse', 'pinv' or 'dls', got '{method}'")
    J = task_jacobian(robot, q, frame, task, reference)
    v = _vector(velocity, J.shape[-2], "velocity", J)
    if method == "inverse":
        if J.shape[-2] != J.shape[-1]:
            raise ValueError(
                f"method='inverse' needs a square Jacobian; the task gives {J.shape[-2]}x{J.shape[-1]} (use 'pinv' or 'dls')"
            )
        qs = np.asarray(q, dtype=float).reshape(-1, robot.n)
        for k, Jk in enumerate(J.reshape(-1, *J.shape[-2:])):
            report = jacobian_rank_report(Jk, task_rows(task), robot.n, 1e-9)
            if report.singular:
                where = f" (configuration {k} of the batch)" if J.ndim == 3 else ""
                raise ValueError(
                    f"the Jacobian is singular at q = {np.array2string(qs[k], precision=6)}{where}: {report.summary()}"
                )
        with np.errstate(over="ignore", invalid="ignore"):
            qd = np.linalg.solve(J, v[..., None])[..., 0]
        return finite_result(qd, "joint_velocities: qd", qd.ndim - 1)
    damping = 0.0 if method == "pinv" else damping
    if isinstance(damping, (complex, np.complexfloating)) or not (
        np.isreal(damping) and damping >= 0 and np.isfinite(damping)
    ):
        raise ValueError(f"damping must be a finite number >= 0, got {damping!r}")
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    lam2 = float(damping) ** 2
    denominator = s * s + lam2
    if lam2 == 0.0:
        keep = s > max(J.shape[-2:]) * np.finfo(float).eps * s[..., :1]
    else:
        keep = denominator > 0
    gain = np.divide(s, denominator, out=np.zeros_like(s), where=keep)
    with np.errstate(over="ignore", invalid="ignore"):
        qd = _mul(np.swapaxes(Vt, -1, -2), gain * _mul(np.swapaxes(U, -1, -2), v))
    return finite_result(qd, "joint_velocities: qd", qd.ndim - 1)


def singular_values(
    robot: Robot, q: ArrayLike, frame: str | None = None, task: Task = "full", reference: str = "world"
) -> np.ndarray:
    """Singular values of the task Jacobian, descending; (N, k) for a batch."""
    return np.linalg.svd(task_jacobian(robot, q, frame, task, reference), compute_uv=False)


def manipulability(
    robot: Robot, q: ArrayLike, frame: str | None = None, task: Task = "full", reference: str = "world"
) -> Union[float, np.ndarray]:
    """Yoshikawa's measure ``w = sqrt(det(J J^T))`` = the product of the singular values."""
    s = singular_values(robot, q, frame, task, reference)
    m = len(task_rows(task))
    if m > robot.n:  # J J^T is rank deficient by construction
        return np.zeros(s.shape[:-1]) if s.ndim > 1 else 0.0
    return np.prod(s, axis=-1)


def jacobian_hessian(
    robot: Robot, q: ArrayLike, frame: str | None = None, task: Task = "full", reference: str = "world"
) -> np.ndarray:
    """``dJ/dq`` of the task rows of the Jacobian: (n, m, n), or (N, n, m, n) for a batch, with
    ``H[i, :, j] = dJ[:, j]/dq_i`` (:meth:`kinedyn.Robot.jacobian_hessian`; Robotics Toolbox's
    ``(n, 6, n)`` layout, so ``reference="world"`` with ``task="full"`` is RTB's ``hessian0``)."""
    return robot.jacobian_hessian(q, frame, reference)[..., task_rows(task), :]


def hessian_in_frame_axes(robot: Robot, q: ArrayLike, frame: str | None = None) -> np.ndarray:
    """Robotics Toolbox's ``hessiane``: the world Hessian ``dJ_world/dq`` (RTB's ``hessian0``) with
    its linear and angular rows expressed in the frame's own axes, ``diag(R^T, R^T) H0[i]``;
    (n, 6, n) or (N, n, 6, n).

    RTB computes it by applying ``hessian0``'s cross-product formulas to the end-effector Jacobian,
    and cross products turn with the axes, so this equals that. It is *not* the derivative of the
    ``"local"`` Jacobian (``robot.jacobian_hessian(q, reference="local")``), which also carries the
    turning of the frame's axes: ``dJ_local/dq_i = diag(R^T, R^T) (H0[i] - [w_i x J_v; w_i x J_w])``.
    ``sum_ij hessian_in_frame_axes[i, :, j] qd_i qd_j`` is the world acceleration drift in the
    frame's axes, ``R^T (dJ_world/dt qd)``."""
    H0 = robot.jacobian_hessian(q, frame, "world")
    R = robot.pose(q, frame)[..., :3, :3]
    out = np.empty_like(H0)
    # (R^T x)_a = sum_b R[b, a] x_b for the linear rows 0..2 and the angular rows 3..5 of every H0[i][:, j]
    out[..., :3, :] = np.einsum("...ba,...ibj->...iaj", R, H0[..., :3, :])
    out[..., 3:, :] = np.einsum("...ba,...ibj->...iaj", R, H0[..., 3:, :])
    return out


def manipulability_jacobian(
    robot: Robot,
    q: ArrayLike,
    frame: str | None = None,
    task: Task = "full",
    reference: str = "world",
    tol: float = 1e-9,
) -> np.ndarray:
    """Gradient ``dw/dq`` of Yoshikawa's manipulability ``w = sqrt(det(J J^T))`` on the task rows
    (the rows :func:`manipulability` uses): (n,), or (N, n) for a batch. Robotics Toolbox's
    ``jacobm`` (which returns it as an (n, 1) column).

    With ``A = J J^T`` and ``H_i = dJ/dq_i`` (the task rows of :func:`jacobian_hessian`),
    ``d det A = det A tr(A^-1 dA)`` (Jacobi's formula) and ``dA = H_i J^T + J H_i^T`` give
    ``dw/dq_i = w tr(A^-1 J H_i^T)`` (Yoshikawa 1985; Park & Kim 1998; Haviland & Corke 2022,
    Part I). It is evaluated from the SVD ``J = U S V^T`` as ``sum_k (prod_{l != k} s_l) u_k^T H_i v_k``,
    which is the same number without dividing by a small singular value.

    Where exactly one singular value of the task Jacobian is zero (below ``tol * max(1, s_max)``),
    ``w`` has a kink like ``|x|`` at 0 and no derivative: ValueError naming the configuration and
    the lost direction. With two or more zero, the gradient is 0. More task rows than joints: ``w``
    is 0 everywhere, and so is its gradient."""
    rows = task_rows(task)
    J = task_jacobian(robot, q, frame, rows, reference)
    H = robot.jacobian_hessian(q, frame, reference)[..., rows, :]
    n, m = robot.n, len(rows)
    if m > n:  # J J^T is rank deficient by construction: w = 0 identically
        return np.zeros(J.shape[:-2] + (n,))
    U, s, Vt = np.linalg.svd(J, full_matrices=False)  # s: (..., m), U: (..., m, m), Vt: (..., m, n)
    threshold = tol * np.maximum(1.0, s[..., :1])
    zero = s <= threshold
    one_zero = np.sum(zero, axis=-1) == 1
    if np.any(one_zero):
        k = int(np.argmax(one_zero.reshape(-1)))
        qs = np.asarray(q, dtype=float).reshape(-1, n)
        where = f" (configuration {k} of the batch)" if J.ndim == 3 else ""
        report = jacobian_rank_report(J.reshape(-1, m, n)[k], rows, n, tol)
        raise ValueError(
            f"manipulability_jacobian: w = sqrt(det(J J^T)) is 0 at q = {np.array2string(qs[k], precision=6)}{where} "
            f"and has no derivative there (one singular value of the task Jacobian is 0: {report.summary()})"
        )
    # others[..., k] = prod_{l != k} s_l, without dividing by s_k
    others = np.stack([np.prod(np.delete(s, k, axis=-1), axis=-1) for k in range(m)], axis=-1)
    # u_k^T H_i v_k for every i and k: (..., n, m)
    projected = np.einsum("...ak,...iab,...kb->...ik", U, H, Vt)
    return finite_result(projected @ others[..., :, None], "manipulability_jacobian: dw/dq", J.ndim - 2)[..., 0]


@dataclass
class SingularityReport:
    """Rank of the task Jacobian at q and what is lost when it drops."""

    rank: int
    rows: int
    n_joints: int
    singular_values: np.ndarray
    #: task-space directions the tool cannot move in (unit vectors over the task rows)
    lost_directions: list = field(default_factory=list)
    #: joint-space directions that do not move the tool (null space of J)
    null_motions: list = field(default_factory=list)
    row_names: list = field(default_factory=list)
    condition_number: float = float("inf")

    @property
    def singular(self) -> bool:
        """True when the rank is below the largest possible, min(task rows, joints)."""
        return self.rank < min(self.rows, self.n_joints)

    def summary(self) -> str:
        if not self.singular:
            return f"full rank {self.rank} (condition number {self.condition_number:.3g})"
        dirs = "; ".join(
            "[" + ", ".join(f"{c:+.3f} {name}" for c, name in zip(d, self.row_names) if abs(c) > 1e-9) + "]"
            for d in self.lost_directions
        )
        return f"rank {self.rank} < {min(self.rows, self.n_joints)}: the tool cannot move along {dirs}"


def singularity_report(
    robot: Robot,
    q: ArrayLike,
    frame: str | None = None,
    task: Task = "full",
    reference: str = "world",
    tol: float = 1e-9,
) -> SingularityReport:
    """Rank, singular values and the lost task directions of the Jacobian at one configuration.

    A singular value below ``tol * max(1, sigma_max)`` counts as zero."""
    rows = task_rows(task)
    J = task_jacobian(robot, q, frame, rows, reference)
    if J.ndim != 2:
        raise ValueError(f"singularity_report takes one configuration q of shape ({robot.n},), got shape {np.shape(q)}")
    return jacobian_rank_report(J, rows, robot.n, tol)


def jacobian_rank_report(J: np.ndarray, rows: list, n: int, tol: float) -> SingularityReport:
    """The singularity report of a Jacobian J (m, n) whose rows are the task's ``rows``: its rank by SVD (singular
    values above ``tol`` times the largest), the lost task directions and the joint motions that do nothing."""
    U, s, Vt = np.linalg.svd(J)
    threshold = tol * max(1.0, s[0] if s.size else 1.0)
    rank = int(np.sum(s > threshold))
    # left singular vectors beyond the rank span the directions the tool cannot move in
    lost = [U[:, k] for k in range(rank, J.shape[0])]
    null = [Vt[k] for k in range(rank, J.shape[1])]
    cond = float(s[0] / s[-1]) if s.size and s[-1] > 0 else float("inf")
    return SingularityReport(
        rank=rank,
        rows=len(rows),
        n_joints=n,
        singular_values=s,
        lost_directions=lost,
        null_motions=null,
        row_names=[ROW_NAMES[r] for r in rows],
        condition_number=cond,
    )


def spanned_rows(robot: Robot, frame: str | None = None, reference: str = "world", samples: int = 8, seed: int = 0):
    """The task rows an arm with fewer than six joints can span, for its manipulability: the linear rows
    that move at some configuration, then the angular ones, kept when there are at most n of them and
    they have rank min(rows, n) at a generic configuration; None when no such subset exists (then the
    measure is taken in the Jacobian's column space, sqrt(det J^T J)).

    Rows are tested at ``samples`` seeded random configurations inside the finite joint limits, so
    the choice is deterministic (elbow_3r: vx, vy, vz; planar_2r: vx, vy; a SCARA: vx, vy, vz, wz)."""
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(robot.lower_limits), robot.lower_limits, -np.pi)
    hi = np.where(np.isfinite(robot.upper_limits), robot.upper_limits, np.pi)
    Js = np.array([robot.jacobian(lo + (hi - lo) * rng.random(robot.n), frame, reference) for _ in range(samples)])
    scale = max(1.0, float(np.abs(Js).max(initial=0.0)))
    moving = [r for r in range(6) if np.abs(Js[:, r, :]).max(initial=0.0) > 1e-9 * scale]
    linear, angular = [r for r in moving if r < 3], [r for r in moving if r >= 3]
    rows = linear if len(linear) >= robot.n else linear + angular
    if not rows or len(rows) > robot.n:
        return None
    if max(np.linalg.matrix_rank(J[rows], tol=1e-9 * scale) for J in Js) < len(rows):
        return None
    return rows


def analysis_rows(robot: Robot, rows: list, explicit: bool, frame: str | None = None, reference: str = "world"):
    """(rows, why): the task rows on which to measure rank and manipulability, and why those.
    ``rows`` given ``explicit``-ly are kept ("given"); otherwise all six are kept for n >= 6 ("all"),
    or the rows a shorter arm spans (:func:`spanned_rows`, "spanned"), or, when it spans no subset,
    all six, the measure then taken in the Jacobian's column space ("column_space")."""
    if explicit:
        return rows, "given"
    if len(rows) <= robot.n:
        return rows, "all"
    chosen = spanned_rows(robot, frame, reference)
    if chosen is None:
        return rows, "column_space"
    return chosen, "spanned"
