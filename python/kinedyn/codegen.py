"""Robot-specialised code: the dynamics of one robot as straight-line C or Rust.

The core's algorithms are generic over their scalar type; run once on a recording scalar
(``kinedyn_core::trace``) they write each arithmetic operation into a straight-line program for
that robot: constants (axes, placements, inertias) folded as they are recorded, ``x * 0``,
``x * 1``, ``x + 0`` dropped, repeated operations merged, unused ones removed, then the negations
absorbed by exact rewrites (no reassociation: the program's numbers are the generic core's). This is
code generation by operator overloading, as Pinocchio does with CppADCodeGen (Griewank & Walther,
*Evaluating Derivatives*, 2nd ed., ch. 6). :func:`generate` writes the programs as one C file or
Rust module (``kinedyn codegen``), for controllers that compile a robot's dynamics in;
:func:`operation_counts` measures them. docs/codegen.md has the layouts.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

from ._core import Model, trace_algorithms, trace_counts, trace_source
from ._version import __version__

if TYPE_CHECKING:
    from .robot import Robot

__all__ = ["ALGORITHMS", "LANGUAGES", "generate", "operation_counts", "parse_algorithms"]

#: The algorithms that can be generated, by name: inverse dynamics, the mass matrix, its inverse,
#: forward dynamics, the gravity torque, and the derivatives of inverse and forward dynamics.
ALGORITHMS: tuple[str, ...] = tuple(trace_algorithms())
#: The languages :func:`generate` writes.
LANGUAGES = ("c", "rust")


def parse_algorithms(algorithms: str | Iterable[str]) -> list[str]:
    """A list of algorithm names from ``"rnea,aba"`` (or an iterable of names; ``"all"``: every one),
    each checked (a ValueError names an unknown one and lists the others)."""
    names = [a.strip() for a in algorithms.split(",")] if isinstance(algorithms, str) else list(algorithms)
    if names == ["all"]:
        return list(ALGORITHMS)
    for name in names:
        if name not in ALGORITHMS:
            raise ValueError(f"unknown algorithm '{name}': one of {', '.join(ALGORITHMS)} (or all)")
    if not names:
        raise ValueError(f"no algorithm given: one or more of {', '.join(ALGORITHMS)}")
    return list(dict.fromkeys(names))


def _native(robot: Robot):
    """The robot's compiled model, refused where its coordinates are not the robot's own."""
    model = robot._model  # the facade's compiled model, as the IK solver reads it
    if not isinstance(model, Model):  # a mimic reduction around the native model
        raise ValueError(
            f"robot '{robot.name}' has mimic joints: generated code runs on a model whose every joint is "
            "independent (robot.lock_joints, or a description without mimics)"
        )
    return model


def generate(
    robot: Robot, algorithms: str | Iterable[str] = ALGORITHMS, language: str = "c", name: str | None = None
) -> str:
    """The source of one file with a function ``kinedyn_<name>_<algorithm>`` per algorithm.

    C: ``void kinedyn_ur5_rnea(const double *in, double *out)``; Rust: ``pub fn
    kinedyn_ur5_rnea(input: &[f64], out: &mut [f64])``. Inputs are ``q`` (nq), then ``qd`` and ``qdd``
    or ``tau`` (nv each) as the algorithm needs; outputs are row-major; each function's header
    comment gives its layout and operation counts (docs/codegen.md). The functions compute the
    core's numbers (``robot.inverse_dynamics`` and the rest, external wrenches off) to rounding (the
    rounding residue of right angles, ``cos(pi/2) = 6.1e-17``, taken as exact), and to the bit on a
    robot without such residue when the C compiler does not contract multiply-adds
    (``-ffp-contract=off``).
    ``name``: the robot's part of the function names (default ``robot.name``)."""
    if language not in LANGUAGES:
        raise ValueError(f"unknown language '{language}': one of {', '.join(LANGUAGES)}")
    return trace_source(_native(robot), name or robot.name, parse_algorithms(algorithms), language, __version__)


def operation_counts(robot: Robot, algorithm: str) -> dict[str, dict[str, int]]:
    """The operations of ``algorithm`` specialised for ``robot``: ``{"recorded": ..., "optimized":
    ...}``, each a dict of ``add`` (additions and subtractions), ``mul``, ``div``, ``neg``, ``sincos``
    (one per joint angle: sine and cosine together), ``select`` (Coulomb friction levels) and
    ``add_mul`` (adds + muls, the arithmetic floor's main term)."""
    (name,) = parse_algorithms([algorithm])
    recorded, optimized = trace_counts(_native(robot), name)
    return {"recorded": recorded, "optimized": optimized}
