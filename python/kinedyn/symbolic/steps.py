"""A step of a derivation (title, sentence, equations) and the operation counts of expressions: the
bottom of the symbolic package, which every derivation, rendering and back-end may import."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import sympy as sp

from .. import display
from .render.latex import align, equation_rows, latex_text
from .render.mathml import equation_mathml

__all__ = ["Step", "op_counts"]


@dataclass
class Step:
    """One step of a derivation: a title, a sentence, and equations ``(lhs LaTeX, SymPy value)``."""

    title: str
    text: str = ""
    equations: list[tuple] = field(default_factory=list)
    #: the EquationsOfMotion whose derivation this step is (its names for q̇, q̈), given when the
    #: equations are built; None for a step on its own
    owner: Any = field(default=None, repr=False, compare=False)

    def to_latex(self, names=None) -> str:
        """An amsmath ``align*`` block: the title (prose escaped for TeX) and the equations, long ones
        broken over lines (see :mod:`kinedyn.symbolic.latex`)."""

        rows = [r"&\text{" + latex_text(self.title) + r"} \\"]
        for lhs, value in self.equations:
            rows += equation_rows(lhs, value, names=names or {})
        return align(rows)

    def equation_mathml(self, lhs, value) -> str:
        """One equation of this step as a ``<math>`` element; a step of an :class:`EquationsOfMotion`
        prints q̇, q̈ by its owner's names."""
        if self.owner is not None:
            return self.owner.equation_mathml(lhs, value)
        return equation_mathml(lhs, value)

    # notebooks (kinedyn.display): the step typeset, q̇ and q̈ with its owner's names
    def _repr_html_(self) -> str:
        return display.step_html(self, mathml=[self.equation_mathml(lhs, value) for lhs, value in self.equations])

    def _repr_latex_(self) -> str:
        return display.step_latex(self, self.owner.latex_names if self.owner is not None else None)

    def _repr_markdown_(self) -> str:
        return display.step_markdown(self, self.owner.latex_names if self.owner is not None else None)


def op_counts(exprs) -> dict[str, int]:
    """Counts of multiplications, additions (subtractions and negations included), divisions and
    function calls (sin, cos, sign) in expressions, the way Khalil & Dombre count them (x**2 counts as
    one product; sign changes are listed under "neg" and left out of the total)."""
    counts = {"mul": 0, "add": 0, "div": 0, "fun": 0, "neg": 0}
    for e in exprs:
        v = sp.count_ops(e, visual=True)
        if v == 0:
            continue
        for term in sp.Add.make_args(v):
            coeff, sym = term.as_coeff_Mul()
            name = str(sym)
            if name in ("MUL", "POW"):
                counts["mul"] += int(coeff)
            elif name in ("ADD", "SUB"):
                counts["add"] += int(coeff)
            elif name == "NEG":  # a sign change, folded into the next addition by any compiler
                counts["neg"] += int(coeff)
            elif name == "DIV":
                counts["div"] += int(coeff)
            else:
                counts["fun"] += int(coeff)
    counts["total"] = counts["mul"] + counts["add"] + counts["div"] + counts["fun"]
    return counts
