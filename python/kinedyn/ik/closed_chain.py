"""Inverse kinematics of a frame on a robot with closed loops (docs/closed-loops.md, "Parallel robots").

The tree's solvers (closed forms, the native numeric one) know nothing of the loops: their answer
would put the frame at the target and leave the loops open. Here the frame's pose error and the
loops' closure are solved together, Gauss-Newton on the stacked residual

    r(q) = [W (x_target - x(q)); -phi(q)],   J(q) = [W J_frame(q); J_loop(q)],

with ``x - x(q)`` the position difference and the rotation vector of ``R_target R(q)^T`` (base axes,
the error whose derivative is the geometric Jacobian's angular rows, ``robot.jacobian(q, frame)``),
``W`` the mask, ``phi`` the closure (``robot.loop_residual``) and ``J_loop`` its Jacobian. Each step
is the least-norm solution of ``J dq = r`` (SVD, so the loops' redundant rows and the frame's unused
directions do no harm), applied on the configuration manifold (``robot.integrate``) and halved while
the residual grows (Nocedal and Wright, *Numerical Optimization*, section 10.3, Gauss-Newton with a
backtracking line search). A local method: it finds the closed configuration nearest ``q0`` on the
branch it starts on.

A batch of targets ``(N, 4, 4)`` / ``(N, 3)`` is one call returning an :class:`IKBatchResult`:

- **Vectorised**: the Gauss-Newton iterations run on every unsolved target at once: one batched call
  each for the frame poses, the frame Jacobians, the loop residuals and Jacobians (the core's batches),
  the least-norm steps by one stacked SVD (``numpy.linalg.pinv`` on the ``(N, 6 + m, nv)`` stack),
  the backtracking halving only the steps of the targets whose residual grew. A target's answer is
  the one a single call from the same start gives (to rounding: a single target runs the same
  iteration on vectors, ``_solve_one``, which NumPy's per-call overhead makes twice as fast there).
- **Warm-started along the batch**: each target starts from ``q0`` (its own row when ``q0`` is
  ``(N, nq)``); a target not reached from there is tried again from the solution of its neighbour in
  the batch (the previous target solved, then the next), pass after pass while a pass solves more,
  so a path of targets that leaves the basin of ``q0`` is followed along the batch.
- **Per target, never raised**: ``success`` (N,), the best iterate in ``q`` for the targets not
  reached, and ``extra["message"]`` (why, per target: not converged with the closure and pose left,
  or outside joint limits) and ``extra["closure"]`` (the largest loop residual of each ``q``).
"""

from __future__ import annotations

import numpy as np

from .solve import IKBatchResult, IKResult

__all__ = ["closed_chain_inverse_kinematics"]

HALVINGS = 16  # a Gauss-Newton step is a descent direction of |r|^2: 2^-16 of it falls unless stalled


def _rotation_vectors(rot: np.ndarray) -> np.ndarray:
    """(N, 3) rotation vectors of (N, 3, 3) rotation matrices: axis times angle, angle = atan2(|s|,
    (tr R - 1)/2) with s = vee(R - R^T)/2 = sin(angle) axis (Rodrigues' formula), exact near zero."""
    s = 0.5 * np.stack([rot[:, 2, 1] - rot[:, 1, 2], rot[:, 0, 2] - rot[:, 2, 0], rot[:, 1, 0] - rot[:, 0, 1]], axis=-1)
    sin = np.linalg.norm(s, axis=-1)
    angle = np.arctan2(sin, 0.5 * (np.trace(rot, axis1=1, axis2=2) - 1.0))
    scale = np.where(sin < 1e-12, 1.0, angle / np.where(sin < 1e-12, 1.0, sin))
    return s * scale[:, None]


def _batched(fn, q, *more):
    """``fn`` on the rows of q (k, ...) as a batch, and on a single row as one state: a batch of one
    would pay the core's batch runner (threads, chunks) for nothing."""
    if len(q) == 1:
        return np.asarray(fn(q[0], *(m[0] for m in more)))[None]
    return np.asarray(fn(q, *more))


class _Problem:
    """The stacked residual and Jacobian of N targets (module docstring), evaluated in batches."""

    def __init__(self, robot, frame: str, poses: np.ndarray, weights: np.ndarray):
        self.robot, self.frame, self.poses, self.weights = robot, frame, poses, weights

    def residual(self, q: np.ndarray, rows: np.ndarray):
        """(r (k, 6 + m), pose error (k, 6)) of the targets ``rows`` at q (k, nq)."""
        robot, pose = self.robot, self.poses[rows]
        actual = _batched(lambda x: robot.frame_poses(x, [self.frame]), q)[:, 0]
        rotation = np.einsum("nij,nkj->nik", pose[:, :3, :3], actual[:, :3, :3])  # R_target R(q)^T
        error = np.concatenate([pose[:, :3, 3] - actual[:, :3, 3], _rotation_vectors(rotation)], axis=1)
        closure = _batched(robot.loop_residual, q).reshape(len(q), -1)
        return np.concatenate([self.weights * error, -closure], axis=1), error

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        robot = self.robot
        frame = _batched(lambda x: robot.jacobian(x, self.frame), q).reshape(len(q), 6, robot.nv)
        loops = _batched(robot.loop_jacobian, q).reshape(len(q), -1, robot.nv)
        return np.concatenate([self.weights[:, None] * frame, loops], axis=1)


def _gauss_newton(problem: _Problem, rows: np.ndarray, q: np.ndarray, tolerance: float, max_iterations: int):
    """Gauss-Newton with backtracking on the targets ``rows`` from q (k, nq), all at once: (q, pose
    error (k, 6), iterations (k,)). A target leaves the iteration when its residual is within
    ``tolerance`` or stops falling; a step is halved (up to ``HALVINGS`` times) only for the targets
    whose residual grew."""
    q = q.copy()
    r, error = problem.residual(q, rows)
    iterations = np.zeros(len(rows), dtype=np.int64)
    active = np.abs(r).max(axis=1) > tolerance
    for _ in range(max_iterations):
        if not active.any():
            break
        at = np.flatnonzero(active)
        iterations[at] += 1
        # least-norm steps (SVD, singular values below 1e-12 of the largest dropped), stacked
        step = np.einsum("kij,kj->ki", np.linalg.pinv(problem.jacobian(q[at]), rcond=1e-12), r[at])
        norm = np.linalg.norm(r[at], axis=1)
        trial_q = _batched(problem.robot.integrate, q[at], step).reshape(len(at), -1)
        trial_r, trial_e = problem.residual(trial_q, rows[at])
        for _ in range(HALVINGS):  # backtracking: halve the steps of the targets whose residual grew
            grew = np.linalg.norm(trial_r, axis=1) > norm
            if not grew.any():
                break
            step[grew] *= 0.5
            again = _batched(problem.robot.integrate, q[at[grew]], step[grew]).reshape(int(grew.sum()), -1)
            trial_q[grew] = again
            trial_r[grew], trial_e[grew] = problem.residual(again, rows[at[grew]])
        q[at], r[at], error[at] = trial_q, trial_r, trial_e
        # a target stops when within tolerance, or stalled: its residual no longer falls (a target out
        # of reach, at the least-squares point of its residual: more steps only cost halvings)
        stalled = np.linalg.norm(trial_r, axis=1) > (1.0 - 1e-9) * norm
        active[at] = (np.abs(trial_r).max(axis=1) > tolerance) & ~stalled
    return q, error, iterations


def _verdicts(robot, q, error, iterations, weights, tolerance, max_iterations, respect_limits):
    """Per target: (success, position error, orientation error, closure, message)."""
    closure = np.abs(_batched(robot.loop_residual, q).reshape(len(q), -1)).max(axis=1, initial=0.0)
    position = np.linalg.norm(weights[:3] * error[:, :3], axis=1)
    orientation = np.linalg.norm(weights[3:] * error[:, 3:], axis=1)
    success = np.maximum(np.maximum(position, orientation), closure) <= tolerance
    messages = [
        "converged"
        if ok
        else f"did not converge (stopped after {it} iterations, at most {max_iterations}: loops open by {c:.3g}, "
        f"frame off by {max(p, o):.3g})"
        for ok, c, p, o, it in zip(success, closure, position, orientation, iterations)
    ]
    if respect_limits:
        finite = np.isfinite(robot.lower_limits) | np.isfinite(robot.upper_limits)
        outside = finite & ((q < robot.lower_limits - 1e-12) | (q > robot.upper_limits + 1e-12))
        for k in np.flatnonzero(success & outside.any(axis=1)):
            success[k] = False
            messages[k] = f"the closed solution leaves joint limits (coordinates {np.flatnonzero(outside[k]).tolist()})"
    return success, position, orientation, closure, messages


def _solve_batch(problem, starts, tolerance, max_iterations, respect_limits, warm):
    """Every target from its start, then (``warm``) the ones not reached from their neighbours'
    solutions, pass after pass (module docstring)."""
    robot, n = problem.robot, len(starts)
    rows = np.arange(n)
    q, error, iterations = _gauss_newton(problem, rows, starts, tolerance, max_iterations)
    verdict = _verdicts(robot, q, error, iterations, problem.weights, tolerance, max_iterations, respect_limits)
    tried = set()
    while warm:
        solved = verdict[0]
        # a target not reached (or reached outside the limits) next to one solved: from the previous, else the next
        retry, sources = [], []
        for k in np.flatnonzero(~solved):
            for j in (k - 1, k + 1):
                if 0 <= j < n and solved[j] and (k, j) not in tried:
                    tried.add((k, j))
                    retry.append(k)
                    sources.append(j)
                    break
        if not retry:
            break
        retry_rows = np.array(retry)
        q2, e2, it2 = _gauss_newton(problem, retry_rows, q[sources], tolerance, max_iterations)
        v2 = _verdicts(robot, q2, e2, it2, problem.weights, tolerance, max_iterations, respect_limits)
        iterations[retry_rows] += it2
        better = v2[0]
        if not better.any():
            continue
        take = retry_rows[better]
        q[take], error[take] = q2[better], e2[better]
        verdict = _verdicts(robot, q, error, iterations, problem.weights, tolerance, max_iterations, respect_limits)
    return q, iterations, verdict


def _rotation_vector(rot: np.ndarray) -> np.ndarray:
    """The rotation vector of one rotation matrix (``_rotation_vectors`` of a stack of one, without
    the stack's overhead)."""
    s = 0.5 * np.array([rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1]])
    sin = np.linalg.norm(s)
    angle = np.arctan2(sin, 0.5 * (np.trace(rot) - 1.0))
    return s if sin < 1e-12 else s * (angle / sin)


def _solve_one(robot, frame, pose, weights, q, tolerance, max_iterations):
    """One target: the same Gauss-Newton as ``_gauss_newton`` on one state (``lstsq`` for the
    least-norm step, 30 halvings), in plain NumPy calls on vectors: a stack of one pays NumPy's
    per-call overhead on every small array (measured twice as slow). Returns (q, pose error (6,),
    iterations)."""

    def residual(q):
        actual = robot.frame_poses(q, [frame])[0]
        error = np.concatenate([pose[:3, 3] - actual[:3, 3], _rotation_vector(pose[:3, :3] @ actual[:3, :3].T)])
        return np.concatenate([weights * error, -robot.loop_residual(q)]), error

    r, error = residual(q)
    iterations = 0
    while np.abs(r).max() > tolerance and iterations < max_iterations:
        iterations += 1
        jac = np.vstack([weights[:, None] * robot.jacobian(q, frame), robot.loop_jacobian(q)])
        step = np.linalg.lstsq(jac, r, rcond=1e-12)[0]
        for _ in range(30):  # backtracking: halve until the residual does not grow
            trial = robot.integrate(q, step)
            r_trial, error_trial = residual(trial)
            if np.linalg.norm(r_trial) <= np.linalg.norm(r):
                break
            step = 0.5 * step
        q, r, error = trial, r_trial, error_trial
    return q, error, iterations


def closed_chain_inverse_kinematics(
    robot,
    target,
    q0=None,
    mask=None,
    method="auto",
    respect_limits=True,
    *,
    frame=None,
    tolerance=1e-9,
    max_iterations=50,
    **options,
):
    """``robot.inverse_kinematics`` of a robot with loops (see the module docstring): one target (a
    4x4 pose or a 3-vector position) from ``q0`` (default: the neutral configuration), an
    :class:`IKResult`; or a batch (N, 4, 4) / (N, 3) from ``q0`` (nq,) or (N, nq), an
    :class:`IKBatchResult`."""
    names = ", ".join(loop.name for loop in robot.loops)
    # restarts, seed, progress steer the tree solver's random restarts: one local solve here
    refused = sorted(set(options) - {"restarts", "seed", "progress"})
    if refused:
        raise ValueError(
            f"robot '{robot.name}' has closed loops ({names}): inverse kinematics on a closed chain does not take {refused}"
        )
    if method == "analytic":
        raise ValueError(
            f"robot '{robot.name}' has closed loops ({names}): no closed-form inverse kinematics; use method='numeric'"
        )
    target = np.asarray(target, dtype=float)
    batch = target.ndim in (2, 3) and target.shape[1:] in ((3,), (4, 4))
    if target.shape[-1:] == (3,) and target.ndim in (1, 2):
        poses = np.broadcast_to(np.eye(4), (*target.shape[:-1], 4, 4)).copy()
        poses[..., :3, 3] = target
        default_mask = np.array([1.0, 1, 1, 0, 0, 0])
    elif target.shape[-2:] == (4, 4) and target.ndim in (2, 3):
        poses, default_mask = target.copy(), np.ones(6)
    else:
        raise ValueError(
            f"robot '{robot.name}' has closed loops ({names}): inverse kinematics takes a 4x4 pose or a 3-vector "
            f"position, or a batch of them (N, 4, 4) / (N, 3), got shape {target.shape}"
        )
    poses = poses.reshape(-1, 4, 4)
    if not np.all(np.isfinite(poses)):
        raise ValueError(f"robot '{robot.name}': the inverse kinematics target holds a non-finite value")
    weights = default_mask if mask is None else np.asarray(mask, dtype=float).reshape(6)
    frame = frame or robot.tool
    n = len(poses)
    q = robot.neutral() if q0 is None else np.asarray(q0, dtype=float).copy()
    if q.shape == (robot.nq,):
        starts, warm = np.broadcast_to(q, (n, robot.nq)).copy(), batch
    elif batch and q.shape == (n, robot.nq):
        starts, warm = q, True
    else:
        want = f"({robot.nq},)" + (f" or ({n}, {robot.nq})" if batch else "")
        raise ValueError(f"q0 must have shape {want}, got {q.shape}")
    if not batch:
        q, error, iterations = _solve_one(robot, frame, poses[0], weights, starts[0], tolerance, max_iterations)
        q, error, iterations = q[None], error[None], np.array([iterations])
        success, position, orientation, closure, messages = _verdicts(
            robot, q, error, iterations, weights, tolerance, max_iterations, respect_limits
        )
    else:
        problem = _Problem(robot, frame, poses, weights)
        q, iterations, (success, position, orientation, closure, messages) = _solve_batch(
            problem, starts, tolerance, max_iterations, respect_limits, warm
        )
    if batch:
        extra = {"message": messages, "closure": closure}
        return IKBatchResult(q, success, position, orientation, iterations, "numeric:closed-chain", extra)
    ok = bool(success[0])
    return IKResult(
        solutions=q if ok else np.zeros((0, robot.nq)),
        success=ok,
        position_error=position if ok else np.zeros(0),
        orientation_error=orientation if ok else np.zeros(0),
        iterations=int(iterations[0]),
        solver="numeric:closed-chain",
        reachable=None,
        message=messages[0],
        structure="closed chain (numeric)",
        worst_residual=float(max(position[0], orientation[0], closure[0])),
    )
