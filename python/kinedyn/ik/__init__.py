"""Inverse kinematics: every closed-form solution where the chain's geometry has one, a robust
numeric solver (Levenberg-Marquardt, batched, in the native core) everywhere else.

    result = kinedyn.ik.inverse_kinematics(robot, target, q0=None, mask=None, method="auto")
    robot.inverse_kinematics(target, ...)             # the same
    robot.inverse_kinematics(T, redundancy={"joint": "j7", "value": 0.3})   # a 7R arm, every branch
    kinedyn.ik.self_motion(robot, T)                  # every branch along the arm angle (SRS arms)

See docs/ik.md. ``symbolic_elbow_solution()`` gives the tutorial elbow arm's solution as SymPy
expressions of x, y, z and the link lengths.
"""

from typing import TYPE_CHECKING

from .branches import IKBranches
from .redundancy import SelfMotion, arm_angle, self_motion
from .solve import METHODS, IKBatchResult, IKResult, analytic_structure, inverse_kinematics

if TYPE_CHECKING:
    from .symbolic import ElbowSolution, symbolic_elbow_solution


def __getattr__(name: str):
    """The symbolic solution's names load SymPy, on first use (kinedyn._lazy)."""
    if name in ("ElbowSolution", "symbolic_elbow_solution"):
        from . import symbolic

        return getattr(symbolic, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [  # noqa: F822 - the symbolic names come from __getattr__
    "inverse_kinematics",
    "IKResult",
    "IKBatchResult",
    "IKBranches",
    "self_motion",
    "SelfMotion",
    "arm_angle",
    "analytic_structure",
    "METHODS",
    "symbolic_elbow_solution",
    "ElbowSolution",
]
