"""External wrenches given about the link-frame origins, moved to the body (joint) frame origins the
core uses, and the correction this move adds to the analytic derivatives. A standard-DH link frame
sits at ``Tx(a)`` from its joint frame; a URDF link frame is its joint frame (no move).

This is the Python half of the seam that docs/architecture.md ("The joint seam") puts in the core:
until the core's model carries a per-body link offset, the numeric facade calls these around the
native kernels."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._arrays import real_array
from .._math import to_float_array

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["body_wrenches", "link_origin_in_body", "moment_shift_derivative"]


def link_origin_in_body(robot: Robot) -> np.ndarray | None:
    """(n, 3) ``R_bl^T t_bl`` of each link frame in its body (joint) frame, or None if every link
    frame has its origin at the joint frame's (URDF); DH links sit at ``Tx(a)`` from it."""
    u = np.zeros((len(robot.tree.bodies), 3))
    for i, name in enumerate(robot.body_names):
        T = to_float_array(robot.tree.frames[robot.frame_index(name)].placement, (4, 4), f"frame '{name}'")
        u[i] = T[:3, :3].T @ T[:3, 3]
    return u if np.any(u) else None


def body_wrenches(robot: Robot, q, f_ext):
    """Wrenches about the link-frame origins -> about the body-frame origins the core uses:
    ``n_body = n_link + (p_link - p_body) x f``, ``p_link - p_body = R_link R_bl^T t_bl``."""
    if f_ext is None:
        return None
    f = real_array(f_ext, "f_ext")
    links = len(robot.tree.bodies)
    if f.shape == (links, 6) and np.ndim(q) == 2:
        # one set of wrenches for every state of a batch
        f = np.ascontiguousarray(np.broadcast_to(f, (len(q), links, 6)))
    if robot._multi_dof:
        if f.shape[-2:] != (links, 6):
            raise ValueError(
                f"f_ext must have shape ({links}, 6): one wrench per moving link {robot.body_names}, got {f.shape}"
            )
        u = robot._link_origin_in_body
        if u is not None and f.ndim == np.ndim(q) + 1:
            R = robot.forward_kinematics(q)[..., :3, :3]
            f = f.copy()
            f[..., 3:] += np.cross(np.einsum("...ij,...j->...i", R, u), f[..., :3])
        # the native model has a body per degree of freedom: the link's wrench acts on its last
        full = np.zeros(f.shape[:-2] + (len(robot._dof_body), 6))  # every native body
        full[..., robot._body_last_dof, :] = f
        return full
    u = robot._link_origin_in_body
    if u is None or f.shape[-2:] != (links, 6) or f.ndim != np.ndim(q) + 1:
        return f  # (wrong shapes are reported by the core)
    R = robot.forward_kinematics(q)[..., :3, :3]
    d = np.einsum("...ij,...j->...i", R, u)
    f = f.copy()
    f[..., 3:] += np.cross(d, f[..., :3])
    return f


def moment_shift_derivative(robot: Robot, q, f_ext) -> np.ndarray | None:
    """The part of dtau/dq the core does not see: :func:`body_wrenches` moves each moment to the body
    origin with ``d_i(q) x f_i``, and ``d_i = R_i u_i`` turns with the joints supporting body i,
    ``dd_i/dq_j = w_j x d_i`` (``w_j``: joint j's world axis, column j of body i's angular
    Jacobian ``Jw_i``); tau has ``-Jw_i^T n_i``, so this adds ``-sum_i Jw_i^T ((w_j x d_i) x f_i)``
    to column j. None when every link frame sits at its body origin (URDF) or without f_ext."""
    if f_ext is None or robot._link_origin_in_body is None:
        return None
    u = robot._link_origin_in_body
    f = np.asarray(f_ext, dtype=np.float64)
    R = robot.forward_kinematics(q)[..., :3, :3]
    d = np.einsum("...bij,bj->...bi", R, u)
    Jw = np.stack([robot.jacobian(q, frame=name)[..., 3:, :] for name in robot.body_names], axis=-3)  # (..., b, 3, n)
    dd = np.cross(np.swapaxes(Jw, -1, -2), d[..., :, None, :])  # (..., b, j, 3): w_j x d_b
    dm = np.cross(dd, f[..., :, None, :3])  # (w_j x d_b) x f_b
    return -np.einsum("...bkr,...bjk->...rj", Jw, dm)
