"""Translation of SymPy expressions (the generated straight-line programs of
:mod:`kinedyn.symbolic.codegen`) into another library's expression objects, such as CasADi ``SX``
(:mod:`kinedyn.symbolic.casadi_export`; any library whose values support ``+ * / **`` will do). It
maps each SymPy node to the library's operation through a small table (``sin``, ``cos``, ``sqrt``, ``fabs``, ``sign`` ...) and memoises by node, so a subexpression that
occurs many times becomes one node of the target graph (shared, not copied)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import sympy as sp

__all__ = ["Walker"]


class Walker:
    """Evaluate SymPy expressions on values of another library.

    ``env``: {SymPy symbol: value} for the inputs; ``functions``: {name: callable} for ``sin``, ``cos``,
    ``tan``, ``exp``, ``log``, ``sqrt``, ``fabs``, ``sign``, ``asin``, ``acos``, ``atan``, ``atan2``,
    ``sinh``, ``cosh``, ``tanh``, ``fmax``, ``fmin`` (missing ones raise an error naming the function when
    an expression needs them). Values must support ``+``, ``*``, ``/``, ``**``."""

    def __init__(
        self, env: Mapping[sp.Symbol, Any], functions: Mapping[str, Callable], constant: Callable[[float], Any] = float
    ):
        self.env: dict[sp.Basic, Any] = dict(env)
        self.functions = dict(functions)
        self.constant = constant

    def assign(self, assignments: Sequence[tuple]) -> None:
        """Evaluate ``(symbol, expression)`` pairs in order, each defining its symbol for the next."""
        for s, e in assignments:
            self.env[s] = self(sp.sympify(e))

    def __call__(self, e) -> Any:
        e = sp.sympify(e)
        hit = self.env.get(e)
        if hit is not None:
            return hit
        value = self._node(e)
        self.env[e] = value
        return value

    def _fn(self, name: str, e):
        f = self.functions.get(name)
        if f is None:
            raise ValueError(f"cannot translate {type(e).__name__} in {e}: no {name!r} in this backend")
        return f

    def _node(self, e):
        if e.is_Symbol:
            raise ValueError(f"symbol {e} has no value (give it a number, or keep it in the parameter vector p)")
        if e.is_Number or e in (sp.pi, sp.E) or e.is_NumberSymbol:
            if e.is_infinite or e is sp.nan:
                raise ValueError(f"cannot translate the non-finite constant {e}")
            return self.constant(float(e))
        if e.is_Add:
            terms = [self(a) for a in e.args]
            out = terms[0]
            for t in terms[1:]:
                out = out + t
            return out
        if e.is_Mul:
            num, den = [], []
            for a in e.args:  # x * y**-1 as a division, the way a compiler writes it
                if a.is_Pow and a.exp.is_Integer and a.exp < 0:
                    den.append(self(a.base**-a.exp))
                else:
                    num.append(self(a))
            out = num[0] if num else self.constant(1.0)
            for t in num[1:]:
                out = out * t
            for t in den:
                out = out / t
            return out
        if e.is_Pow:
            base, ex = e.args
            if ex == sp.Rational(1, 2):
                return self._fn("sqrt", e)(self(base))
            if ex == sp.Rational(-1, 2):
                return self.constant(1.0) / self._fn("sqrt", e)(self(base))
            if ex.is_Integer:
                k = int(ex)
                b = self(base)
                if k < 0:
                    return self.constant(1.0) / (b ** (-k) if k != -1 else b)
                return b * b if k == 2 else b**k
            return self(base) ** self(ex)
        func = type(e)
        simple = {
            sp.sin: "sin",
            sp.cos: "cos",
            sp.tan: "tan",
            sp.exp: "exp",
            sp.log: "log",
            sp.Abs: "fabs",
            sp.sign: "sign",
            sp.asin: "asin",
            sp.acos: "acos",
            sp.atan: "atan",
            sp.sinh: "sinh",
            sp.cosh: "cosh",
            sp.tanh: "tanh",
        }
        if func in simple:
            if len(e.args) != 1:
                raise ValueError(f"cannot translate {e}: {simple[func]} with {len(e.args)} arguments")
            return self._fn(simple[func], e)(self(e.args[0]))
        if func == sp.atan2:
            return self._fn("atan2", e)(self(e.args[0]), self(e.args[1]))
        if func in (sp.Max, sp.Min):
            f = self._fn("fmax" if func == sp.Max else "fmin", e)
            vals = [self(a) for a in e.args]
            out = vals[0]
            for v in vals[1:]:
                out = f(out, v)
            return out
        raise ValueError(f"cannot translate {func.__name__} (in {e}) to this backend")
