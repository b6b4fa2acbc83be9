"""Which inverse kinematics a robot gets (``Robot.inverse_kinematics`` forwards here).

A robot whose coordinates are its joints goes straight to :func:`kinedyn.ik.solve.inverse_kinematics`
(closed form where the chain has one, else the native numeric solver). A robot with reduced mimic
joints (:mod:`kinedyn.description.mimic`) is solved as below, then read back in its own coordinates.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._arrays import real_array
from .branches import all_branches
from .redundancy import solve_redundant
from .solve import inverse_kinematics as solve

__all__ = ["inverse_kinematics"]


def inverse_kinematics(robot, target, q0=None, mask=None, method="auto", respect_limits=True, **kwargs):
    """``robot.inverse_kinematics(...)``: the solver that fits the robot (see the module docstring).

    ``redundancy={"joint": name, "value": v}`` or ``{"arm_angle": psi}`` solves a seven-joint arm
    in closed form at that value (:mod:`kinedyn.ik.redundancy`); ``all_branches=True`` returns every
    closed-form solution of each target of a batch (:mod:`kinedyn.ik.branches`)."""
    redundancy = kwargs.pop("redundancy", None)
    every = kwargs.pop("all_branches", False)
    if redundancy is not None or every:
        return _closed_forms(robot, target, q0, mask, method, respect_limits, redundancy, **kwargs)
    if robot.description.mimic_map is None:
        return solve(robot, target, q0, mask, method, respect_limits, **kwargs)
    return _with_mimic_joints(robot, target, q0, mask, method, respect_limits, **kwargs)


def _closed_forms(robot, target, q0, mask, method, respect_limits, redundancy, frame=None, tolerance=1e-9, **rest):
    """Every closed-form branch: a redundancy parameter's (seven-joint arms) or a batch's."""
    unused = sorted(k for k in rest if k not in ("seed", "progress", "max_iterations", "restarts"))
    if unused:
        raise TypeError(f"inverse_kinematics() got unexpected keyword argument(s) {unused}")
    if mask is not None or method not in ("auto", "analytic"):
        raise ValueError(
            "redundancy= and all_branches=True list closed-form branches: no mask, method 'auto' or 'analytic'"
        )
    if type(tolerance) is not float or not 0.0 < tolerance < np.inf:
        raise ValueError(f"tolerance must be a positive number (m and rad), got {tolerance!r}")
    if redundancy is not None:
        return solve_redundant(robot, target, q0, respect_limits, redundancy, frame, tolerance)
    return all_branches(robot, target, q0, respect_limits, frame, tolerance)


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
