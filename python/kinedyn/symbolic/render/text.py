"""Plain-text shorthand of symbolic results: the textbook's ``c12`` for cos(q1 + q2). The one
abbreviator of the package (``kinedyn.symbolic.abbreviate``); the tutorial's ``C12`` is the same with
``prefix=("C", "S")``."""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

__all__ = ["abbreviate"]


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
