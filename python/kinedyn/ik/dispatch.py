"""Which inverse kinematics a robot gets (``Robot.inverse_kinematics`` forwards here).

A robot whose coordinates are its joints goes straight to :func:`kinedyn.ik.solve.inverse_kinematics`
(closed form where the chain has one, else the native numeric solver). A robot with reduced mimic
joints (:mod:`kinedyn.description.mimic`) is solved as below, then read back in its own coordinates.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._arrays import real_array
from .solve import inverse_kinematics as solve

__all__ = ["inverse_kinematics"]


def inverse_kinematics(robot, target, q0=None, mask=None, method="auto", respect_limits=True, **kwargs):
    """``robot.inverse_kinematics(...)``: the solver that fits the robot (see the module docstring)."""
    if robot.description.mimic_map is None:
        return solve(robot, target, q0, mask, method, respect_limits, **kwargs)
    return _with_mimic_joints(robot, target, q0, mask, method, respect_limits, **kwargs)


def _with_mimic_joints(robot, target, q0, mask, method, respect_limits, **kwargs):
    """``Robot.inverse_kinematics`` of a robot with reduced mimic joints.

    - A frame that no follower moves (the Panda's ``panda_hand_tcp``, not a finger): solved on the
      same robot with every joint independent (where the closed forms also apply), the followers'
      coordinates then dropped. Exact: the frame's pose depends only on the joints between it and
      the base, none a follower, so a full solution's independent coordinates put the frame at the
      target in the reduced robot too (a leader on that path moves its followers elsewhere, which
      the frame does not see).
    - A frame that a follower moves (a finger): the numeric solver in the reduced coordinates, with
      the Jacobian ``J G`` (chain rule, ``v_full = G v``) and the update ``q_full ⊕ G dq`` read back
      at the independent coordinates (crates/kinedyn-core/src/algorithms/ik.rs, ``Reduction``);
      limits are those of the independent joints."""
    frame = kwargs.get("frame") or robot.tool
    m = robot.description.mimic_map
    tree = robot.tree
    body = tree.frames[robot.frame_index(frame)].body
    while body >= 0:
        if tree.bodies[body].joint.name in m.relations:
            return solve(robot, target, q0, mask, method, respect_limits, **kwargs)
        body = tree.bodies[body].parent
    full = robot.__dict__.get("_independent_robot")
    if full is None:
        full = robot.__dict__["_independent_robot"] = robot.replace(mimic="independent")
    if q0 is not None and not hasattr(q0, "dask"):
        q0 = real_array(q0, "q0")
        if q0.shape[-1:] != (m.nq,) or q0.ndim > 2:
            raise ValueError(f"q0 must have shape ({m.nq},) or a batch (N, {m.nq}), got {q0.shape}")
        q0 = m.expand_q(q0)
    result = full.inverse_kinematics(target, q0, mask, method, respect_limits, **kwargs)
    if hasattr(result, "solutions"):  # IKResult
        nearest_q = None if result.nearest_q is None else np.asarray(result.nearest_q)[..., m.q_keep]
        return dataclasses.replace(result, solutions=np.asarray(result.solutions)[..., m.q_keep], nearest_q=nearest_q)
    return dataclasses.replace(result, q=np.asarray(result.q)[..., m.q_keep])  # IKBatchResult
