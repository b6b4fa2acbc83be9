"""Values made fit for :func:`json.dumps`: the command line's ``--json`` output and the data the
HTML reports embed."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["jsonable"]


def jsonable(x):
    """``x`` with NumPy arrays and scalars turned into lists and Python numbers, a complex number
    into [real, imag], NaN into null and an infinity into "inf"/"-inf" (JSON has no non-finite
    numbers), dict keys into strings; containers are converted element by element."""
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
