"""The program every back-end prints: the equations' matrices with the state replaced by array reads
(``q[i]``, ``qd[i]``, ``qdd[i]``), the remaining parameters by ``p[i]``, and common subexpressions
eliminated; and :class:`CompiledEOM`, the one interface of the compiled callables (C, NumPy, JAX)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

__all__ = ["ARGS", "CompiledEOM", "blocks", "params_by_name"]

#: the state arguments of each generated function
ARGS = {"M": ("q",), "C": ("q", "qd"), "g": ("q",), "tau": ("q", "qd", "qdd"), "friction": ("qd",)}


def blocks(eom, what: Sequence[str], params=None):
    """[(name, shape, assignments, exprs)] with the state replaced by array reads and CSE applied."""
    state = {}
    for name, vec in (("q", eom.q), ("qd", eom.qd), ("qdd", eom.qdd)):
        for i, s in enumerate(vec):
            state[s] = sp.Symbol(f"{name}[{i}]")
    pars = [s for s in eom.parameters if params is None or s not in params]
    pmap = {s: sp.Symbol(f"p[{i}]") for i, s in enumerate(pars)}
    out = []
    for name in what:
        if name not in ARGS:
            raise ValueError(f"cannot generate {name!r}: choose from {list(ARGS)}")
        pre: list[tuple] = []
        closed = name in ("M", "C", "g") and getattr(eom, "closed_form", None) is not None
        if closed:  # a large model: the CSE form of kinedyn.symbolic.cse, never expanded
            block = eom.closed_form()[name]
            pre = list(block.assignments)
            exprs = list(block.entries)
            shape = tuple(block.shape)
        elif name == "tau" and eom.program is not None:
            pre = list(eom.program.assignments)
            exprs = [t + f for t, f in zip(eom.program.outputs["tau"], eom.friction)]
            shape = (eom.n,)
        else:
            m = getattr(eom, name)
            shape = tuple(m.shape) if m.shape[1] != 1 else (m.shape[0],)
            exprs = list(m)
        if params:
            pre = [(s, e.subs(params)) for s, e in pre]
            exprs = [sp.sympify(e).subs(params) for e in exprs]
        rep = {**state, **pmap}
        pre = [(s, e.xreplace(rep)) for s, e in pre]
        exprs = [sp.sympify(e).xreplace(rep) for e in exprs]
        free = set().union(*[e.free_symbols for e in exprs] + [e.free_symbols for _, e in pre]) if exprs else set()
        known = set(rep.values()) | {s for s, _ in pre}
        left = {s for s in free - known if "[" not in s.name}
        if left:
            raise ValueError(f"{name}: symbols {sorted(map(str, left))} have no value")
        if closed:  # already in CSE form (its own x1, x2, ... among pre)
            repl, red = [], exprs
        else:
            repl, red = sp.cse(exprs, symbols=sp.numbered_symbols("x"), order="none")
        out.append((name, shape, pre + list(repl), list(red)))
    return out, pars


def params_by_name(eom, params) -> dict:
    """``params`` ({symbol or name: value}) keyed by the equations' own symbols, matched by name so that
    symbols with other assumptions are found."""
    params = {(sp.Symbol(k) if isinstance(k, str) else k): v for k, v in dict(params or {}).items()}
    if params:
        names = {str(k): v for k, v in params.items()}
        params = {s: names[str(s)] for s in eom.parameters if str(s) in names}
    return params


class CompiledEOM:
    """Callables ``M(q)``, ``C(q, qd)``, ``g(q)``, ``tau(q, qd, qdd)`` (and ``friction(qd)`` if asked);
    each takes one state (n,) or a batch (N, n). ``backend`` is ``"c"`` or ``"numpy"``."""

    def __init__(self, backend: str, funcs: dict[str, object], n: int, source: str, p=()):
        self.backend = backend
        self.n = n
        self.source = source
        self._p = np.ascontiguousarray(p, dtype=float)
        for name, f in funcs.items():
            setattr(self, name, f)

    def __repr__(self) -> str:
        return f"CompiledEOM(backend={self.backend!r}, n={self.n})"
