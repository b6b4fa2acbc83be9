"""Values made ready for :func:`json.dumps`: NumPy arrays and scalars become Python lists and numbers."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["jsonable"]


def jsonable(x):
    """``x`` with every NumPy array and scalar replaced by its Python value, tuples by lists, dict keys by
    strings; a non-finite float becomes None (NaN) or "inf"/"-inf", a complex number [real, imag]."""
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, np.generic):
        # every NumPy scalar (np.bool_, integers, floats, complex): its Python value, converted in turn
        # (a non-finite float, a complex) -- json knows none of NumPy's scalar types
        return jsonable(x.item())
    if isinstance(x, complex):
        return [jsonable(x.real), jsonable(x.imag)]
    if isinstance(x, float) and not math.isfinite(x):
        return None if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    return x
