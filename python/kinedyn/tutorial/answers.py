"""What a worked question returns (:class:`Answer`, :class:`Comparison`) and the helpers every question
shares: numbers as the tutorial prints them, the symbolic pose and Jacobian of a robot, the tutorial's
C/S abbreviations, and a numeric test that two expressions are the same function."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp

from .. import robots
from .. import symbolic as ks
from ..symbolic.render.text import whole_numbers
from .printed import th1, th2, thd1, thd2, thdd1, thdd2


# ------------------------------------------------------------------ results
@dataclass
class Comparison:
    """kinedyn's value of one quantity beside the tutorial's printed one."""

    quantity: str
    printed: str
    kinedyn: str
    agrees: bool
    #: the independent check that decides (always run; essential where they disagree)
    check: str = ""
    #: the correct value where the printed one is wrong
    correction: str = ""
    #: (printed, kinedyn) as SymPy expressions for symbolic answers (rendering only)
    exprs: tuple | None = None

    def to_dict(self) -> dict:
        return {
            "quantity": self.quantity,
            "printed": self.printed,
            "kinedyn": self.kinedyn,
            "agrees": self.agrees,
            "check": self.check,
            "correction": self.correction,
        }


@dataclass
class Answer:
    key: str
    title: str
    question: str
    #: ("text", str) | ("eq", name, value) | ("table", title, headers, rows)
    items: list[tuple] = field(default_factory=list)
    comparisons: list[Comparison] = field(default_factory=list)
    #: machine-readable results (numbers as floats/lists, expressions as strings)
    result: dict[str, Any] = field(default_factory=dict)

    def text(self, s: str):
        self.items.append(("text", s))

    def eq(self, name: str, value):
        self.items.append(("eq", name, value))

    def table(self, title: str, headers: Sequence[str], rows: Sequence[Sequence[Any]]):
        self.items.append(("table", title, list(headers), [list(r) for r in rows]))

    @property
    def misprints(self) -> list[Comparison]:
        return [c for c in self.comparisons if not c.agrees]


# ------------------------------------------------------------------ helpers
def fmt_number(x: float, digits: int = 6) -> str:
    x = float(x)
    if abs(x) < 1e-12:
        x = 0.0
    return f"{x:.{digits}g}"


def fmt_vector(v, digits: int = 6) -> str:
    return "(" + ", ".join(fmt_number(x, digits) for x in np.ravel(v)) + ")"


def matrix_rows(M, digits: int = 6) -> list[list[str]]:
    return [[fmt_number(x, digits) for x in row] for row in np.atleast_2d(M)]


def _decimals(s: str) -> int:
    return len(s.split(".")[1]) if "." in s else 0


def half_unit(s: str) -> float:
    return 0.5 * 10.0 ** (-_decimals(s))


def symbolic_frame_pose(robot, q: Sequence[sp.Symbol], frame: str | None = None) -> sp.Matrix:
    """The pose of a frame as a SymPy matrix in the joint symbols ``q``: kinedyn.symbolic.pose with the
    robot's joint symbols renamed to ``q``."""
    return ks.pose(robot, frame).xreplace(dict(zip(ks.joint_symbols(robot), q)))


def symbolic_jacobian(robot, q: Sequence[sp.Symbol], frame: str | None = None) -> sp.Matrix:
    """kinedyn.symbolic.jacobian (rows [v; w], base axes) in the joint symbols ``q``."""
    return ks.jacobian(robot, frame).xreplace(dict(zip(ks.joint_symbols(robot), q)))


def tutorial_display(expr, tutorial_symbols: bool = True):
    """A SymPy value in the tutorial's notation (theta, dots, C/S shorthand) for rendering."""
    if not isinstance(expr, (sp.Basic, sp.MatrixBase)):
        return expr
    names = {
        th1: "theta1",
        th2: "theta2",
        thd1: "thetadot1",
        thd2: "thetadot2",
        thdd1: "thetaddot1",
        thdd2: "thetaddot2",
    }
    reps = {s: sp.Symbol(n, real=True) for s, n in names.items()}
    expr = whole_numbers(expr)  # 1.0*L3 -> L3, -1.0*cos(theta1) -> -cos(theta1): a float axis' 1.0
    e = ks.abbreviate(expr, [th1, th2, sp.Symbol("th3", real=True)], prefix=("C", "S")) if tutorial_symbols else expr
    return e.xreplace(reps) if isinstance(e, sp.Basic) else e.applyfunc(lambda x: x.xreplace(reps))


def same_function(a, b, symbols: Sequence[sp.Symbol], trials: int = 4, seed: int = 7) -> bool:
    """Numeric equality of two expressions at random values of ``symbols`` (relative 1e-9)."""
    rng = np.random.default_rng(seed)
    fa = sp.lambdify(symbols, a, "numpy")
    fb = sp.lambdify(symbols, b, "numpy")
    for _ in range(trials):
        x = rng.uniform(0.3, 1.7, len(symbols)) * rng.choice([-1, 1], len(symbols))
        va, vb = np.asarray(fa(*x), dtype=float), np.asarray(fb(*x), dtype=float)
        if not np.allclose(va, vb, rtol=1e-9, atol=1e-9 * max(1.0, float(np.max(np.abs(va))))):
            return False
    return True


def arm_2r_symbolic():
    """The tutorial's two-link arm with its lengths, masses and g as symbols (Q1's Jacobian, Q3's dynamics)."""
    return robots.planar_2r(symbolic=True)
