"""The joints a target does not need: 1-DOF coordinates whose motion cannot change the part of the
frame's pose the target asks for (the other arm of a two-armed robot, a gripper's fingers beyond
the tool, a wrist roll about an axis through the tool for a position target). Their Jacobian
columns (in the target's rows) are zero. The solvers leave them where the random restarts and the
start's clipping put them; :func:`settle` puts them back at the reference q0 (the neutral
configuration within the joint limits when none is given), which changes neither the pose nor
the residuals (docs/ik.md, "Joints the target does not need").
"""

from __future__ import annotations

import numpy as np

# configurations at which a column must be zero to call it idle: a Jacobian column is an analytic
# function of q, so one that vanishes at several random configurations vanishes everywhere
# (almost surely), and its coordinate cannot move the frame's target rows
_SAMPLES = 4
_ZERO = 1e-12  # relative to the Jacobian's largest entry: columns that are exact zeros or rounding


def _moves(robot, frame: str) -> np.ndarray:
    """(6, nv) bool: whether a row of the frame's world-aligned Jacobian depends on each velocity,
    at any of a few random configurations; cached per robot and frame."""
    cache = robot.__dict__.setdefault("_ik_moves", {})
    if frame not in cache:
        qs = robot.random_configuration(np.random.default_rng(0), _SAMPLES)
        J = np.abs(np.asarray(robot.jacobian(qs, frame), dtype=float))  # (samples, 6, nv)
        cache[frame] = (J > _ZERO * max(float(J.max(initial=0.0)), 1.0)).any(axis=0)
    return cache[frame]


def idle_coordinates(robot, frame: str, weights) -> np.ndarray:
    """Indices into q of the 1-DOF coordinates that cannot move the target's rows (``weights``: six
    weights of ``[x, y, z, rx, ry, rz]``, zero for a row the target leaves free); cached."""
    rows = tuple(bool(w > 0) for w in np.asarray(weights, dtype=float))
    cache = robot.__dict__.setdefault("_ik_idle", {})
    key = (frame, rows)
    if key not in cache:
        moves = _moves(robot, frame)[np.array(rows)]
        idle, iq, iv = [], 0, 0
        for j in robot.joints:
            if not j.is_multi_dof and not moves[:, iv].any():
                idle.append(iq)
            iq, iv = iq + j.nq, iv + j.nv
        cache[key] = np.array(idle, dtype=np.intp)
    return cache[key]


def rest(robot, q0) -> np.ndarray:
    """Where an idle coordinate stays: the caller's q0, else the neutral configuration clipped
    into the joint limits."""
    if q0 is not None:
        return np.asarray(q0, dtype=float)
    return np.clip(robot.neutral(), robot.lower_limits, robot.upper_limits)


def settle(robot, frame: str | None, target, mask, q0, result):
    """``result`` (an IKResult or IKBatchResult) with its idle coordinates at :func:`rest`."""
    position = np.shape(target)[-1:] == (3,)  # a position (3,) or a batch of them (N, 3); poses are (4, 4), (N, 4, 4)
    if mask is None:
        # the common call: no mask; its idle set looked up once per frame and target kind (a
        # single call's overhead is microseconds here, docs/ik.md "Speed")
        cache = robot.__dict__.setdefault("_ik_idle_unmasked", {})
        key = (frame, position)
        idle = cache.get(key)
        if idle is None:
            weights = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0] if position else [1.0] * 6)
            idle = cache[key] = idle_coordinates(robot, frame or robot.tool, weights)
    else:
        weights = np.array(mask, dtype=float).reshape(6)
        if position:
            weights[3:] = 0.0
        idle = idle_coordinates(robot, frame or robot.tool, weights)
    if not idle.size:
        return result
    at = rest(robot, q0)
    names = ("q",) if hasattr(result, "success_rate") else ("solutions", "nearest_q")  # a batch, or one target
    for name in names:
        q = getattr(result, name, None)
        if q is None or not np.size(q):
            continue
        q = np.array(q, dtype=float)  # a copy: the solver's arrays may be read-only
        q[..., idle] = np.broadcast_to(at, q.shape)[..., idle]
        setattr(result, name, q)
    return result
