"""The statement of completeness every inverse-kinematics result carries, in words.

A closed form knows the most real solutions its structure can have for one target (the product of
its subproblems' root counts: 8 for a spherical wrist, 8 for an SRS arm at one arm angle), so a
result can say how many of them it found; the numeric solver finds one solution and states no
bound. Thresholds of the merge flag: ``crates/kinedyn-core/src/ik/solutions.rs``
(``MERGE_DISTANCE``, ``MERGE_RATIO``).
"""

from __future__ import annotations

import math

__all__ = ["statement"]


def statement(result) -> str:
    """``result`` (an IKResult) in one sentence: structure, found of at most, residual, merge."""
    structure = getattr(result, "structure", None)
    most = getattr(result, "max_solutions", None)
    found = int(getattr(result, "found", 0))
    kept = len(result.solutions)
    worst = float(getattr(result, "worst_residual", math.nan))
    if structure is None or most is None:
        what = f"{result.solver}: {kept} solution(s); a numeric solver finds one branch and states no bound on their number"
    else:
        what = f"{structure}: {found} of at most {most} real solutions found"
        if kept != found:
            what += f" ({kept} within the joint limits)"
    if found or kept:
        what += f"; worst forward-kinematics residual {worst:.1e}"
    if getattr(result, "merged", False):
        what += "; branches merge at this target (near-duplicate solutions or a singular Jacobian)"
    elif getattr(result, "singular", False):
        what += "; singular target (a free joint was set from q0)"
    return what
