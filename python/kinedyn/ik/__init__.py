"""Inverse kinematics: every closed-form solution where the chain's geometry has one, a robust
numeric solver (Levenberg-Marquardt, batched, in the native core) everywhere else.

    result = kinedyn.ik.inverse_kinematics(robot, target, q0=None, mask=None, method="auto")
    robot.inverse_kinematics(target, ...)             # the same

See docs/ik.md. ``symbolic_elbow_solution()`` gives the tutorial elbow arm's solution as SymPy
expressions of x, y, z and the link lengths.
"""

from .solve import METHODS, IKBatchResult, IKResult, analytic_structure, inverse_kinematics
from .symbolic import ElbowSolution, symbolic_elbow_solution

__all__ = [
    "inverse_kinematics",
    "IKResult",
    "IKBatchResult",
    "analytic_structure",
    "METHODS",
    "symbolic_elbow_solution",
    "ElbowSolution",
]
