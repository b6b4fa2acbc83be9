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
"""

from __future__ import annotations

import numpy as np

from .solve import IKResult

__all__ = ["closed_chain_inverse_kinematics"]


def _rotation_vector(rot: np.ndarray) -> np.ndarray:
    """The rotation vector of a rotation matrix: axis times angle, angle = atan2(|s|, (tr R - 1)/2)
    with s = vee(R - R^T)/2 = sin(angle) axis (Rodrigues' formula), exact near zero."""
    s = 0.5 * np.array([rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1]])
    sin = np.linalg.norm(s)
    angle = np.arctan2(sin, 0.5 * (np.trace(rot) - 1.0))
    return s if sin < 1e-12 else s * (angle / sin)


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
) -> IKResult:
    """``robot.inverse_kinematics`` of a robot with loops (see the module docstring): one target (a
    4x4 pose or a 3-vector position) from ``q0`` (default: the neutral configuration)."""
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
    if target.shape == (3,):
        pose, default_mask = np.eye(4), np.array([1.0, 1, 1, 0, 0, 0])
        pose[:3, 3] = target
    elif target.shape == (4, 4):
        pose, default_mask = target, np.ones(6)
    else:
        raise ValueError(
            f"robot '{robot.name}' has closed loops ({names}): inverse kinematics takes one target, a 4x4 pose or a "
            f"3-vector position, got shape {target.shape} (solve a batch one target at a time)"
        )
    weights = default_mask if mask is None else np.asarray(mask, dtype=float).reshape(6)
    frame = frame or robot.tool
    q = robot.neutral() if q0 is None else np.asarray(q0, dtype=float).copy()
    if q.shape != (robot.nq,):
        raise ValueError(f"q0 must have shape ({robot.nq},), got {q.shape}")

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
    closure = np.abs(robot.loop_residual(q)).max()
    position, orientation = np.linalg.norm(weights[:3] * error[:3]), np.linalg.norm(weights[3:] * error[3:])
    converged = max(position, orientation, closure) <= tolerance
    message = (
        "converged" if converged else f"did not converge in {max_iterations} iterations (loops open by {closure:.3g})"
    )
    if converged and respect_limits:
        finite = np.isfinite(robot.lower_limits) | np.isfinite(robot.upper_limits)
        outside = finite & ((q < robot.lower_limits - 1e-12) | (q > robot.upper_limits + 1e-12))
        if outside.any():
            converged, message = (
                False,
                f"the closed solution leaves joint limits (coordinates {np.flatnonzero(outside).tolist()})",
            )
    return IKResult(
        solutions=q[None, :] if converged else np.zeros((0, robot.nq)),
        success=converged,
        position_error=np.array([position]) if converged else np.zeros(0),
        orientation_error=np.array([orientation]) if converged else np.zeros(0),
        iterations=iterations,
        solver="numeric:closed-chain",
        reachable=None,
        message=message,
        structure="closed chain (numeric)",
        worst_residual=max(position, orientation, closure),
    )
