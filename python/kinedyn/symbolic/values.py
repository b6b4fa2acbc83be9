"""Description values as exact SymPy: the one converter every derivation uses, so that a robot given with
``1.0`` and ``0.5`` derives the same equations as one given with ``1`` and ``1/2``."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import sympy as sp

__all__ = ["exact", "matrix", "rational"]


def exact(value):
    """A description value as SymPy, with integer-valued floats made exact (1.0 -> 1) so that a
    symbolic robot stays exact; other floats are kept as given."""
    if isinstance(value, (float, np.floating)):
        f = float(value)
        if abs(f) < 1e-13:
            return sp.Integer(0)
        return sp.Integer(int(f)) if f.is_integer() else sp.Float(f)
    if isinstance(value, (int, np.integer)):
        return sp.Integer(int(value))
    e = sp.sympify(value)
    floats = e.atoms(sp.Float)
    if floats:
        # inside a symbolic expression a float is round-off of exact arithmetic done in floats by
        # the description (1.0/12 from a numpy rotation): recover the small rational it came from
        e = e.xreplace({f: (rational(float(f)) if e.free_symbols else exact(float(f))) for f in floats})
    return e


def rational(f: float):
    """``f`` as the small rational (denominator up to 10000) it equals to round-off, else :func:`exact`."""
    fr = Fraction(f).limit_denominator(10000)
    if abs(float(fr) - f) <= 1e-15 * max(1.0, abs(f)):
        return sp.Rational(fr.numerator, fr.denominator)
    return exact(f)


def matrix(value) -> list[list]:
    """A description matrix (NumPy or SymPy) as nested lists of :func:`exact` entries."""
    if isinstance(value, sp.MatrixBase):
        return [[exact(e) for e in row] for row in value.tolist()]
    return [[exact(e) for e in row] for row in np.asarray(value).tolist()]
