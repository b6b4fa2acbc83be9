"""Every closed-form branch of many targets in one native call (``all_branches=True``).

``robot.inverse_kinematics(T, all_branches=True)`` with ``T`` of shape (N, 4, 4) (or (N, 3) for a
chain whose closed form solves positions) returns an :class:`IKBranches`: every solution of each
target, padded with NaN to the widest, and each target's statement of completeness. The targets
run on all threads in the core (``AnalyticIk.solve_all`` / ``RedundantIk.solve_batch``,
crates/kinedyn-py/src/ik.rs ``all_branches``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .solve import IKResult, chain_of, check_q0, check_target

__all__ = ["IKBranches", "all_branches"]


@dataclass(slots=True)
class IKBranches:
    """Every solution of each of N targets.

    ``solutions`` (N, B, n): target k's solutions in rows ``[:count[k]]`` (nearest its q0 first),
    NaN beyond; ``count`` (N,); ``position_error``/``orientation_error`` (N, B); ``found`` (N,)
    solutions before the joint-limit filter; ``max_solutions`` (N,) the method's bound;
    ``worst_residual`` (N,); ``merged``, ``singular`` (N,); ``solver``; ``structure``.
    ``result(k)`` is target k as an :class:`~kinedyn.ik.solve.IKResult`."""

    solutions: np.ndarray
    count: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    found: np.ndarray
    singular: np.ndarray
    max_solutions: np.ndarray
    worst_residual: np.ndarray
    merged: np.ndarray
    solver: str
    structure: str

    def __len__(self) -> int:
        return len(self.count)

    @property
    def success(self) -> np.ndarray:
        return self.count > 0

    def result(self, k: int) -> IKResult:
        m = int(self.count[k])
        return IKResult(
            self.solutions[k, :m],
            m > 0,
            self.position_error[k, :m],
            self.orientation_error[k, :m],
            0,
            self.solver,
            bool(self.found[k] > 0) or None,
            bool(self.singular[k]),
            int(self.found[k]),
            message=f"{m} solution(s)",
            structure=self.structure,
            max_solutions=int(self.max_solutions[k]),
            worst_residual=float(self.worst_residual[k]),
            merged=bool(self.merged[k]),
        )


def pack(raw: tuple, solver: str, structure: str) -> IKBranches:
    """The core's all-branch tuple (ik.rs ``all_branches``) as an :class:`IKBranches`."""
    q, count, pe, oe, found, singular, most, worst, merged = raw
    return IKBranches(q, count, pe, oe, found, singular, most, worst, merged, solver, structure)


def all_branches(robot, target, q0, respect_limits: bool, frame: str | None, tolerance: float) -> IKBranches:
    """Every closed-form solution of a batch of targets (see the module docstring)."""
    chain = chain_of(robot, frame)
    solver = chain.solver
    if solver is None:
        raise ValueError(
            f"robot '{robot.name}' has no closed form for this frame, so it has no list of every branch "
            "(all_branches=True); without it the numeric solver gives one solution per target"
        )
    t, position, batch = check_target(target)
    if position and not chain.position_ok:
        raise ValueError(f"'{solver.structure}' solves 4x4 poses, not positions, in closed form")
    if not batch:
        t = t[None]
    refs = np.ascontiguousarray(np.broadcast_to(check_q0(q0, chain, len(t), robot), (len(t), chain.n)))
    raw = solver.solve_all(np.ascontiguousarray(t), refs, respect_limits, float(tolerance))
    return pack(raw, "analytic:" + solver.structure, solver.structure)
