"""Numeric dynamics helpers that live above the native core: base (identifiable) parameters, and
the linearisation of the equations of motion about a state (for LQR and other linear design).

The regressor ``Y(q, qd, qdd)`` (n, 10 n) of :meth:`kinedyn.Robot.regressor` is linear in the
10 standard inertial parameters of every body (``robot.inertial_parameters()``, per body
``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` about the body-frame origin). Some columns
are zero (a parameter that never affects the torques) and some are linear combinations of others
(parameters that only act in fixed groups), so ``pi`` is not identifiable from torques. The base
parameters are a minimal set found numerically (Gautier, "Numerical calculation of the base
inertial parameters of robots", J. Robotic Systems 8(4), 1991): stack ``Y`` at random states into
``W``, take a QR decomposition with column pivoting ``W P = Q R``; the first ``b`` pivots (``b`` the
numerical rank) are independent columns ``W_1``, the rest satisfy ``W_2 = W_1 beta`` with
``beta = R_11^-1 R_12``. Then ``W pi = W_1 (pi_1 + beta pi_2)``: ``pi_base = grouping @ pi``.

Operational space (Khatib, "A unified approach for motion and force control of robot manipulators:
the operational space formulation", IEEE J. Robotics and Automation 3(1), 1987): the inertia a
frame presents to forces along the task rows, ``Lambda = (J M^-1 J^T)^-1``
(:func:`operational_space_inertia`), and the dynamically consistent generalised inverse
``J_bar = M^-1 J^T Lambda`` (:func:`dynamically_consistent_inverse`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ._arrays import finite_result, real_array
from .kinematics import jacobian_rank_report, task_jacobian, task_rows

if TYPE_CHECKING:
    from ._typing import ArrayLike, SeedLike
    from .robot import Robot

__all__ = [
    "BaseParameters",
    "friction_torque",
    "base_parameters",
    "linearize",
    "operational_space_inertia",
    "dynamically_consistent_inverse",
]


@dataclass(frozen=True)
class BaseParameters:
    """A minimal identifiable parameter set.

    ``indices`` (b,): the columns of the full regressor kept, ascending (``Y_base = Y[..., indices]``);
    ``grouping`` (b, 10 n): ``pi_base = grouping @ pi`` for any parameter vector ``pi``;
    ``values`` (b,): ``grouping @ robot.inertial_parameters()``;
    ``names`` (b,): the kept standard parameters, e.g. ``"link2.m cx"``.
    ``Y_base @ pi_base == Y @ pi == tau`` (rigid-body torque, without friction and rotor inertia).
    """

    indices: np.ndarray
    grouping: np.ndarray
    values: np.ndarray
    names: tuple

    @property
    def count(self) -> int:
        return len(self.indices)

    def regressor(self, Y: np.ndarray) -> np.ndarray:
        """The base regressor from a full one (n, 10 n) or a batch (N, n, 10 n)."""
        return np.asarray(Y)[..., self.indices]


PARAMETER_NAMES = ("m", "m cx", "m cy", "m cz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")


def base_parameters(robot: Robot, samples: int = 200, rng: SeedLike = 0, tol: float = 1e-9) -> BaseParameters:
    """Base parameters of ``robot`` from ``samples`` random states (seeded by ``rng``).

    ``tol``: a pivot ``|R_kk| <= tol |R_00|`` ends the independent set (numerical rank).
    """
    from scipy.linalg import qr, solve_triangular

    if not (isinstance(samples, (int, np.integer)) and samples >= 1):
        raise ValueError(f"samples must be a whole number of random states >= 1, got {samples!r}")
    n = robot.n
    rng = np.random.default_rng(rng)
    q = robot.random_configuration(rng, size=samples)
    qd = rng.uniform(-2.0, 2.0, size=(samples, n))
    qdd = rng.uniform(-4.0, 4.0, size=(samples, n))
    p = robot.inertial_parameters().size  # 10 per moving link (n of them unless a joint has several DOF)
    W = robot.regressor(q, qd, qdd).reshape(samples * n, p)
    # scale columns so that the rank test does not depend on the units of each parameter
    scale = np.linalg.norm(W, axis=0)
    # a column that is rounding noise (e.g. PUMA link2's m cz, norm ~1e-15) is structurally zero:
    # normalising it would make noise look independent
    nonzero = scale > 1e-10 * scale.max(initial=0.0)
    Ws = W[:, nonzero] / scale[nonzero]
    cols = np.flatnonzero(nonzero)
    _, R, piv = qr(Ws, mode="economic", pivoting=True)
    diag = np.abs(np.diag(R))
    b = int(np.sum(diag > tol * diag[0])) if diag.size else 0
    # W_2 = W_1 beta  (scaled columns: undo the scaling on both sides)
    beta_s = solve_triangular(R[:b, :b], R[:b, b:]) if b < R.shape[1] else np.zeros((b, 0))
    independent = cols[piv[:b]]
    dependent = cols[piv[b:]]
    beta = beta_s * scale[dependent][None, :] / scale[independent][:, None]
    beta[np.abs(beta) < 1e-10 * max(1.0, np.abs(beta).max(initial=0.0))] = 0.0
    order = np.argsort(independent)
    grouping = np.zeros((b, p))
    grouping[np.arange(b), independent] = 1.0
    grouping[:, dependent] = beta
    grouping = grouping[order]
    indices = independent[order]
    names = tuple(f"{robot.body_names[k // 10]}.{PARAMETER_NAMES[k % 10]}" for k in indices)
    return BaseParameters(
        indices=indices, grouping=grouping, values=grouping @ robot.inertial_parameters(), names=names
    )


def linearize(
    robot: Robot, q: ArrayLike, qd: ArrayLike | None = None, tau: ArrayLike | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of ``d/dt [dq; dqd] = A [dq; dqd] + B dtau``: the equations of motion
    ``qdd = FD(q, qd, tau)`` linearised about ``(q, qd, tau)`` with the analytical derivatives
    (:meth:`kinedyn.Robot.forward_dynamics_derivatives`)::

        A = [[0, I], [dqdd/dq, dqdd/dqd]],    B = [[0], [M^-1]]

    ``qd`` defaults to zero and ``tau`` to the torque that holds the state without acceleration,
    ``inverse_dynamics(q, qd, 0)`` (gravity and friction): an equilibrium when ``qd = 0``.
    A batch of states gives ``(N, 2n, 2n)`` and ``(N, 2n, n)``."""
    q = np.asarray(q, dtype=np.float64)
    qd = np.zeros_like(q) if qd is None else np.asarray(qd, dtype=np.float64)
    if tau is None:
        tau = robot.inverse_dynamics(q, qd, np.zeros_like(q))
    dq, dqd, minv = robot.forward_dynamics_derivatives(q, qd, tau)
    n = robot.n
    batch = q.shape[:-1]
    A = np.zeros(batch + (2 * n, 2 * n))
    A[..., :n, n:] = np.eye(n)
    A[..., n:, :n], A[..., n:, n:] = dq, dqd
    B = np.zeros(batch + (2 * n, n))
    B[..., n:, :] = minv
    return A, B


def _task_mobility(robot: Robot, q, frame, task, reference) -> tuple:
    """``(J, Minv, A)``: the task Jacobian (..., m, n), ``M^-1`` (..., n, n) and the inverse
    operational-space inertia ``A = J M^-1 J^T`` (..., m, m), symmetrised."""
    J = task_jacobian(robot, q, frame, task, reference)
    Minv = robot.mass_matrix_inverse(q)
    A = J @ Minv @ np.swapaxes(J, -1, -2)
    return J, Minv, (A + np.swapaxes(A, -1, -2)) / 2


def _check_task_rank(robot: Robot, q, J: np.ndarray, task, tol: float, what: str) -> None:
    """ValueError naming the configuration and the lost task direction if J has rank < its rows."""
    rows = task_rows(task)
    m, n = J.shape[-2:]
    if m > n:
        raise ValueError(
            f"{what}: the task has {m} rows but the robot only {n} joints, so J M^-1 J^T ({m}x{m}) is singular "
            "everywhere; choose at most n rows with task=..., or method='pinv'"
        )
    s = np.linalg.svd(J, compute_uv=False)
    deficient = s[..., -1] <= tol * np.maximum(1.0, s[..., 0])
    if np.any(deficient):
        k = int(np.argmax(np.reshape(deficient, -1)))
        qs = np.asarray(q, dtype=float).reshape(-1, n)
        where = f" (configuration {k} of the batch)" if J.ndim == 3 else ""
        report = jacobian_rank_report(J.reshape(-1, m, n)[k], rows, n, tol)
        raise ValueError(
            f"{what}: the task Jacobian is singular at q = {np.array2string(qs[k], precision=6)}{where}, so "
            f"J M^-1 J^T has no inverse ({report.summary()}); method='pinv' gives the pseudo-inverse"
        )


def _lambda(A: np.ndarray, method: str, tol: float) -> np.ndarray:
    if method == "inverse":
        return np.linalg.inv(A)
    # symmetric pseudo-inverse: eigenvalues below tol * max(1, largest) count as zero
    w, V = np.linalg.eigh(A)
    keep = w > tol * np.maximum(1.0, w[..., -1:])
    inv_w = np.divide(1.0, w, out=np.zeros_like(w), where=keep)
    return (V * inv_w[..., None, :]) @ np.swapaxes(V, -1, -2)


def operational_space_inertia(
    robot: Robot,
    q: ArrayLike,
    frame: str | None = None,
    task="full",
    reference: str = "world",
    method: str = "inverse",
    tol: float = 1e-9,
) -> np.ndarray:
    """Khatib's operational-space (task-space) inertia ``Lambda(q) = (J M^-1 J^T)^-1`` of ``frame``
    (default the tool) on the task rows (``task`` as in :mod:`kinedyn.kinematics`, Jacobian in
    ``reference``): (m, m), or (N, m, m) for a batch. The tool then obeys ``Lambda a + mu + p = F``.

    ``method="inverse"`` (default): ValueError naming the configuration and the direction the tool
    cannot move in where the task Jacobian loses rank (a singular value below ``tol * max(1, s_max)``)
    or the task has more rows than the robot has joints. ``method="pinv"``: the Moore-Penrose
    pseudo-inverse of ``J M^-1 J^T`` (eigenvalues below ``tol * max(1, largest)`` count as zero):
    finite everywhere, the inertia felt along the directions the tool can move, zero along the lost
    ones. ``M`` includes the reflected rotor inertia."""
    if method not in ("inverse", "pinv"):
        raise ValueError(f"method must be 'inverse' or 'pinv', got '{method}'")
    J, _, A = _task_mobility(robot, q, frame, task, reference)
    if method == "inverse":
        _check_task_rank(robot, q, J, task, tol, "operational_space_inertia")
    L = _lambda(A, method, tol)
    return (L + np.swapaxes(L, -1, -2)) / 2


def dynamically_consistent_inverse(
    robot: Robot,
    q: ArrayLike,
    frame: str | None = None,
    task="full",
    reference: str = "world",
    method: str = "inverse",
    tol: float = 1e-9,
) -> np.ndarray:
    """Khatib's dynamically consistent generalised inverse ``J_bar = M^-1 J^T Lambda`` (n, m), or
    (N, n, m) for a batch, with ``Lambda`` from :func:`operational_space_inertia` (same arguments).

    ``J J_bar = I`` (a right inverse of J), and it is the inverse weighted by the mass matrix: the
    null-space torques ``(I - J^T J_bar^T) tau_0`` cause no tool acceleration (Khatib 1987, the dynamically consistent null space).
    With ``method="pinv"`` at a singular configuration, ``J J_bar`` is the projector onto the
    directions the tool can move in instead of I."""
    if method not in ("inverse", "pinv"):
        raise ValueError(f"method must be 'inverse' or 'pinv', got '{method}'")
    J, Minv, A = _task_mobility(robot, q, frame, task, reference)
    if method == "inverse":
        _check_task_rank(robot, q, J, task, tol, "dynamically_consistent_inverse")
    L = _lambda(A, method, tol)
    return Minv @ np.swapaxes(J, -1, -2) @ ((L + np.swapaxes(L, -1, -2)) / 2)


def friction_torque(robot: Robot, qd: ArrayLike) -> np.ndarray:
    """viscous * qd + Coulomb friction of ``robot``'s joints, (n,) or (N, n): ``coulomb`` for qd > 0,
    ``-coulomb_negative`` for qd < 0, 0 at rest (``coulomb * sign(qd)`` when symmetric)."""
    qd = real_array(qd, "qd")
    if qd.shape[-1:] != (robot.n,) or qd.ndim > 2:
        raise ValueError(f"qd must have shape ({robot.n},) or a batch (N, {robot.n}), got {qd.shape}")
    if not np.all(np.isfinite(qd)):
        raise ValueError("qd contains a non-finite value (NaN or inf)")
    with np.errstate(over="ignore"):
        tau = robot.viscous * qd + np.where(qd > 0, robot.coulomb, 0.0) - np.where(qd < 0, robot.coulomb_negative, 0.0)
    return finite_result(tau, "friction_torque: tau_f", qd.ndim - 1)
