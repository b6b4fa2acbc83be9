"""Plain-text shorthand of symbolic results: the textbook's ``c12`` for cos(q1 + q2). The one
abbreviator of the package (``kinedyn.symbolic.abbreviate``); the tutorial's ``C12`` is the same with
``prefix=("C", "S")``."""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

__all__ = ["abbreviate", "whole_numbers", "tidy", "equation_text", "inline", "GRID_WIDTH"]


def abbreviate(expr, q: Sequence[sp.Symbol], prefix=("c", "s")):
    """cos(q1 + q2) -> c12, sin(q2) -> s2 (the textbook's shorthand), for display only: the indices
    are the joints' positions in ``q``; angles with other terms (q2 - q3, q1 + pi/2) are kept."""
    expr = sp.sympify(expr)
    q = list(q)
    reps = {}
    for f in expr.atoms(sp.cos, sp.sin):
        arg = sp.expand(f.args[0])
        idx = []
        for term in sp.Add.make_args(arg):
            if term not in q:
                break
            idx.append(q.index(term) + 1)
        else:
            if idx:
                sep = "" if len(q) < 10 else "_"
                reps[f] = sp.Symbol(
                    (prefix[0] if isinstance(f, sp.cos) else prefix[1]) + sep.join(str(i) for i in sorted(idx)),
                    real=True,
                )
    return expr.xreplace(reps)


def whole_numbers(expr):
    """``expr`` with every float that is a whole number made an integer (1.0 -> 1, -3.0 -> -3), so that
    ``1.0*cos(q1)`` prints as ``cos(q1)`` and ``3.0*qd1`` as ``3*qd1``; other floats are kept as they
    are (the value is unchanged: only floats equal to an integer are replaced)."""
    if isinstance(expr, sp.MatrixBase):
        return expr.applyfunc(whole_numbers)
    expr = sp.sympify(expr)
    reps = {f: sp.Integer(int(f)) for f in expr.atoms(sp.Float) if float(f).is_integer()}
    return expr.xreplace(reps) if reps else expr


def tidy(expr, rates: Sequence[sp.Symbol] = ()):
    """The display form of a result: :func:`whole_numbers`, and, given the joint rates and
    accelerations, each sum collected by them (``(6 cos(q2) + 8.3) qddot1 + 3 (cos(q2) + 1) qddot2``
    rather than the expanded products); equal in value to ``expr``."""
    if isinstance(expr, sp.MatrixBase):
        return expr.applyfunc(lambda e: tidy(e, rates))
    expr = whole_numbers(expr)
    present = [r for r in rates if r in expr.free_symbols]
    if not present or not expr.is_Add:
        return expr
    try:  # one term per monomial of the rates (qddot1, qdot1*qdot2, ...), its coefficient gathered
        poly = sp.Poly(expr, *present)
    except sp.PolynomialError:  # e.g. sign(qdot1) of Coulomb friction: left as it is
        return expr
    terms = [sp.Mul(coeff, *[r**k for r, k in zip(present, powers)]) for powers, coeff in poly.terms()]
    return whole_numbers(sp.Add(*terms))  # Poly's float domain writes 3 as 3.0 again


#: a matrix is printed as a grid when it is at most this many characters wide, else entry by entry
GRID_WIDTH = 100


def equation_text(lhs: str, value, rates: Sequence[sp.Symbol] = ()) -> list[str]:
    """``lhs = value`` as plain-text lines: a scalar on one line; a matrix as an aligned grid of its
    entries (``[a  b]`` rows) when it fits :data:`GRID_WIDTH` characters, else one line per non-zero
    entry (``D(q)[1,2] = ...``; a column vector ``g(q)[1] = ...``), never SymPy's ``Matrix([[...]])``."""
    value = tidy(value, rates)
    if not isinstance(value, sp.MatrixBase):
        return [f"{lhs} = {value}"]
    cells = [[str(value[i, j]) for j in range(value.cols)] for i in range(value.rows)]
    widths = [max(len(row[j]) for row in cells) for j in range(value.cols)]
    if sum(widths) + 2 * value.cols + len(lhs) + 3 <= GRID_WIDTH:
        pad = " " * (len(lhs) + 3)
        rows = ["[" + "  ".join(c.rjust(w) for c, w in zip(row, widths)) + "]" for row in cells]
        mid = (len(rows) - 1) // 2
        return [(f"{lhs} = " if i == mid else pad) + r for i, r in enumerate(rows)]
    out = []
    column = value.cols == 1
    for i in range(value.rows):
        for j in range(value.cols):
            if value[i, j] != 0:
                out.append(f"{lhs}[{i + 1}{'' if column else f',{j + 1}'}] = {cells[i][j]}")
    if len(out) < value.rows * value.cols:
        out.append(f"(the other entries of {lhs} are 0)")
    return out


def inline(value) -> str:
    """A short value on one line: a matrix as ``[[1, 0], [0, 1]]`` (rows of its entries), whole-number
    floats as integers."""
    value = whole_numbers(value)
    if isinstance(value, sp.MatrixBase):
        return "[" + ", ".join("[" + ", ".join(str(e) for e in row) + "]" for row in value.tolist()) + "]"
    return str(value)
