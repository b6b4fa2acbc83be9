"""Seven-joint arms: every closed-form branch for a given value of a redundancy parameter, and the
self-motion manifold as the parameter sweeps.

Two parameters (``crates/kinedyn-core/src/ik/redundant.rs`` derives both):

- ``redundancy={"joint": name, "value": v}``: the joint held at ``v``; the six joints left form a
  chain solved in closed form when its axes have a structure, read from either end (the Panda with
  its last joint held has a spherical shoulder: ``reversed_spherical_wrist``, 8 branches). Where
  the six-joint chain has none, the robot with that joint locked goes to the numeric solver
  (``robot.lock_joints``), one solution.
- ``redundancy={"arm_angle": psi}``: SRS arms (axes 1-3 meet in a shoulder point, axes 5-7 in a
  wrist point, as the KUKA iiwa): psi turns the elbow about the shoulder-wrist line, 0 with the
  elbow on the side of the first joint's axis; up to 8 branches for each psi.

:func:`self_motion` sweeps either parameter and returns every branch at each sample, branches
numbered so that each is continuous along the sweep, with the parameter intervals where a branch
keeps every joint inside its limits (for the arm angle in closed form: ``self_motion.rs`` in the core).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._core import RedundantIk
from .branches import pack
from .solve import IKResult, chain_of, check_q0, check_target

__all__ = ["self_motion", "SelfMotion", "arm_angle", "solve_redundant", "default_redundancy"]


def _seven(robot, frame: str | None):
    """(chain, RedundantIk) of the frame's seven-joint chain, cached on the robot."""
    chain = chain_of(robot, frame)
    cache = robot.__dict__.setdefault("_ik_seven", {})
    key = frame or robot.tool
    if key not in cache:
        ok = not robot.has_multi_dof_joints and robot._mimic is None
        cache[key] = RedundantIk.detect(chain.model, chain.frame, chain.lower, chain.upper) if ok else None
    solver = cache[key]
    if solver is None:
        raise ValueError(
            f"robot '{robot.name}': a redundancy parameter needs a serial chain of 7 revolute or prismatic joints "
            f"ending at '{key}', and this robot has {robot.nq} coordinates; lock the joints outside the arm first "
            "(robot.lock_joints({...}), e.g. a gripper's fingers)"
        )
    return chain, solver


def _parameter(robot, redundancy, solver) -> tuple:
    """(mode, chain index of the held joint or -1, the joint's name or None, value) from the
    ``redundancy`` argument."""
    if not isinstance(redundancy, dict):
        raise ValueError(
            f"redundancy must be a dict: {{'joint': name, 'value': v}} or {{'arm_angle': psi}}, got {redundancy!r}"
        )
    keys = set(redundancy)
    if keys == {"arm_angle"}:
        if not solver.srs:
            raise ValueError(
                f"robot '{robot.name}' is not an SRS arm (its axes 1-3 or 5-7 do not meet in a point): "
                "the arm angle is not defined; hold a joint instead: redundancy={'joint': name, 'value': v}"
            )
        return "arm_angle", -1, None, redundancy["arm_angle"]
    if keys == {"joint", "value"}:
        joint = redundancy["joint"]
        names = robot.joint_names
        if isinstance(joint, (int, np.integer)) and not isinstance(joint, bool) and 0 <= joint < len(names):
            k = int(joint)
        elif joint in names:
            k = names.index(joint)
        else:
            raise ValueError(f"redundancy: unknown joint {joint!r}; the arm's joints are {names}")
        return "held", k, names[k], redundancy["value"]
    raise ValueError(f"redundancy takes the keys ('joint', 'value') or ('arm_angle',), got {sorted(keys)}")


def _value(value, name: str, count: int | None) -> float | np.ndarray:
    v = np.asarray(value, dtype=float)
    if count is None and v.shape == ():
        if not np.isfinite(v):
            raise ValueError(f"redundancy {name} must be finite, got {value!r}")
        return float(v)
    if v.shape not in ((), (count,)) or not np.all(np.isfinite(v)):
        raise ValueError(f"redundancy {name} must be a finite number or one per target ({count},), got {value!r}")
    assert count is not None  # a batch's values (a lone number returned above)
    return np.ascontiguousarray(np.broadcast_to(v, (count,)))


def solve_redundant(robot, target, q0, respect_limits: bool, redundancy, frame, tolerance: float):
    """``robot.inverse_kinematics(target, redundancy=...)``: an IKResult (one pose) or IKBranches
    (a batch (N, 4, 4), the value a number or one per target)."""
    chain, solver = _seven(robot, frame)
    mode, k, name, value = _parameter(robot, redundancy, solver)
    t, position, batch = check_target(target)
    if position:
        raise ValueError("a redundancy parameter needs a 4x4 pose target (a position leaves four joints free)")
    what = "value" if mode == "held" else "arm_angle"
    tol = float(tolerance)
    if batch:
        values = np.asarray(_value(value, what, len(t)))
        refs = np.ascontiguousarray(np.broadcast_to(check_q0(q0, chain, len(t), robot), (len(t), 7)))
        raw = solver.solve_batch(np.ascontiguousarray(t), mode, k, values, refs, respect_limits, tol)
        structure = _structure(solver, mode, k, name, float(values[0]) if len(values) else 0.0)
        return pack(raw, "analytic:" + structure, structure)
    value = float(_value(value, what, None))
    ref = check_q0(q0, chain, None, robot)
    sols, pe, oe, found, singular, most, worst, merged = solver.solve(t, mode, k, value, ref, respect_limits, tol)
    structure = _structure(solver, mode, k, name, value)
    if mode == "held" and most == 0:
        return _locked_numeric(robot, t, q0, respect_limits, k, name, value, frame, tol)
    kept = len(sols)
    message = (
        f"{kept} solution(s)"
        if kept
        else (f"reachable, but all {found} solution(s) violate the joint limits" if found else "target out of reach")
    )
    return IKResult(
        sols,
        kept > 0,
        pe,
        oe,
        0,
        "analytic:" + structure,
        found > 0 or None,
        singular,
        found,
        message=message,
        structure=structure,
        max_solutions=most,
        worst_residual=worst,
        merged=merged,
    )


def default_redundancy(robot, q0=None, frame: str | None = None) -> dict | None:
    """A redundancy parameter that lists every closed-form branch near ``q0`` (default: the neutral
    configuration) on a seven-joint arm: the arm angle of ``q0`` on an SRS arm, else the last joint
    (then the others, last to first) whose holding at its ``q0`` value leaves a six-joint chain
    with a closed form; None when there is none (or the robot is no seven-joint chain)."""
    try:
        chain, solver = _seven(robot, frame)
    except ValueError:
        return None
    q = check_q0(q0, chain, None, robot)
    if solver.srs:
        psi = solver.arm_angle(np.ascontiguousarray(q, dtype=float))
        if psi is not None:
            return {"arm_angle": float(psi)}
    for k in range(6, -1, -1):
        if solver.held_structure(k, float(q[k])):
            return {"joint": robot.joint_names[k], "value": float(q[k])}
    return None


def _structure(solver, mode: str, k: int, name, value: float) -> str:
    if mode == "arm_angle":
        return "srs_arm_angle"
    held = solver.held_structure(k, value)
    return f"held[{name}]+{held}" if held else f"held[{name}]"


def _locked_numeric(robot, t, q0, respect_limits, k, name, value, frame, tol) -> IKResult:
    """The six-joint chain has no closed form: the robot with the joint locked, numerically."""
    locked = robot.lock_joints({name: value})
    q0_rest = None if q0 is None else np.delete(np.asarray(q0, dtype=float), k)
    r = locked.inverse_kinematics(t, q0_rest, respect_limits=respect_limits, frame=frame, tolerance=tol)
    sols = np.insert(r.solutions, k, value, axis=1) if len(r.solutions) else np.zeros((0, 7))
    r.solutions = sols
    r.solver = f"{r.solver} (held[{name}])"
    r.structure = None
    return r


def arm_angle(robot, q, frame: str | None = None) -> float | None:
    """The arm angle (rad) of ``q`` on an SRS arm (None where the elbow is straight)."""
    _, solver = _seven(robot, frame)
    if not solver.srs:
        raise ValueError(f"robot '{robot.name}' is not an SRS arm: the arm angle is not defined")
    return solver.arm_angle(np.ascontiguousarray(q, dtype=float))


@dataclass(slots=True)
class SelfMotion:
    """Every branch along a sweep of the redundancy parameter for one target.

    ``values`` (M,) the parameter (arm angle in rad, or the held joint's q); ``q`` (M, B, 7):
    branch b at sample m (NaN where it does not exist), each branch continuous along the sweep
    (revolute angles unwrapped); ``inside`` (M, B): the branch keeps every joint within its
    limits; ``singular`` (M,); ``parameter``: "arm_angle" or the held joint's name."""

    values: np.ndarray
    q: np.ndarray
    inside: np.ndarray
    singular: np.ndarray
    parameter: str
    _solver: Any  # the native solver (_core)
    _slots: np.ndarray
    _args: tuple
    _limits: tuple
    _cache: dict = field(default_factory=dict)

    @property
    def branches(self) -> int:
        return self.q.shape[1]

    def intervals(self, branch: int, refine: int = 40) -> list[tuple[float, float]]:
        """The parameter intervals where ``branch`` exists inside the joint limits.

        For the arm angle: in closed form over ``[min(values), max(values)]`` (each joint's limit
        crossings are the roots of a sinusoid in psi, Shimizu et al. 2008; inner ends lie on a
        limit), whatever the sampling. For a held joint: runs of samples, each end moved between
        its sample and the next by bisection (``refine`` halvings), so an interval narrower than
        one sample step can be missed."""
        if self.parameter == "arm_angle":
            exact = self._exact()
            if exact is not None:
                return [(float(a), float(z)) for a, z in exact[self._slots[branch]]]
        ok = self.inside[:, branch]
        out = []
        m = 0
        while m < len(ok):
            if not ok[m]:
                m += 1
                continue
            start = m
            while m + 1 < len(ok) and ok[m + 1]:
                m += 1
            lo = (
                self.values[start]
                if start == 0
                else self._edge(branch, self.values[start], self.values[start - 1], refine)
            )
            hi = self.values[m] if m == len(ok) - 1 else self._edge(branch, self.values[m], self.values[m + 1], refine)
            out.append((float(lo), float(hi)))
            m += 1
        return out

    def _exact(self):
        """Every SRS branch's arm-angle intervals (by core branch number), computed once; None
        where psi is undefined at the target."""
        if "exact" not in self._cache:
            t = self._args[0]
            self._cache["exact"] = self._solver.arm_angle_intervals(
                t, float(self.values.min()), float(self.values.max())
            )
        return self._cache["exact"]

    def _edge(self, branch: int, good: float, bad: float, refine: int) -> float:
        for _ in range(refine):
            mid = 0.5 * (good + bad)
            t, mode, k, ref, tol = self._args
            q, _ = self._solver.sweep(t, mode, k, np.array([mid]), ref, tol)
            if _inside_limits(q[0, self._slots[branch]], self._limits):
                good = mid
            else:
                bad = mid
        return good


def _inside_limits(q, limits) -> bool:
    lower, upper = limits
    return bool(np.all(np.isfinite(q)) and np.all(q >= lower - 1e-12) and np.all(q <= upper + 1e-12))


def self_motion(
    robot,
    target,
    parameter="arm_angle",
    samples: int = 361,
    values=None,
    q0=None,
    frame: str | None = None,
    tolerance: float = 1e-9,
) -> SelfMotion:
    """Every branch of a seven-joint arm at ``target`` along a sweep of the redundancy parameter.

    ``parameter``: ``"arm_angle"`` (SRS arms; ``values`` default: ``samples`` angles over
    [-pi, pi]) or a joint's name or index (held; default: ``samples`` values over its limits, or
    [-pi, pi]). ``q0``: the reference revolute angles are moved next to (default: the neutral
    configuration). Returns a :class:`SelfMotion`."""
    chain, solver = _seven(robot, frame)
    t, position, batch = check_target(target)
    if position or batch:
        raise ValueError("self_motion takes one 4x4 pose")
    if parameter == "arm_angle":
        mode, k, name, _ = _parameter(robot, {"arm_angle": 0.0}, solver)
        span = (-np.pi, np.pi)
    else:
        mode, k, name, _ = _parameter(robot, {"joint": parameter, "value": 0.0}, solver)
        lo, hi = chain.lower[k], chain.upper[k]
        span = (lo, hi) if np.isfinite(lo) and np.isfinite(hi) else (-np.pi, np.pi)
    if values is None:
        if type(samples) is not int or samples < 2:
            raise ValueError(f"samples must be an integer >= 2, got {samples!r}")
        values = np.linspace(span[0], span[1], samples)
    values = np.ascontiguousarray(values, dtype=float)
    if values.ndim != 1 or not np.all(np.isfinite(values)):
        raise ValueError("values must be a 1-D array of finite parameter values")
    ref = check_q0(q0, chain, None, robot)
    q, singular = solver.sweep(t, mode, k, values, ref, float(tolerance))
    keep = np.isfinite(q[..., 0]).any(axis=0)
    q = q[:, keep]
    lower, upper = chain.lower, chain.upper
    inside = np.isfinite(q).all(axis=2) & (q >= lower - 1e-12).all(axis=2) & (q <= upper + 1e-12).all(axis=2)
    q = _unwrapped(q, chain.revolute)
    args = (t, mode, k, ref, float(tolerance))
    return SelfMotion(
        values, q, inside, singular, name or "arm_angle", solver, np.flatnonzero(keep), args, (lower, upper)
    )


def _unwrapped(q: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """Each branch's revolute angles moved by 2 pi k to follow on from the previous sample."""
    q = q.copy()
    for b in range(q.shape[1]):
        prev = None
        for m in range(q.shape[0]):
            row = q[m, b]
            if not np.isfinite(row).all():
                prev = None
                continue
            if prev is not None:
                row[revolute] += 2 * np.pi * np.round((prev[revolute] - row[revolute]) / (2 * np.pi))
            prev = row
    return q
