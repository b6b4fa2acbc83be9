"""Checks of numeric arguments and results at the Python boundary (the native glue does the same
for the arrays it is given: ``crates/kinedyn-py/src/lib.rs``, ``f64_array`` and ``Batch::run_many``).

- :func:`real_array`: an argument as float64, refusing what NumPy would convert by losing
  information (complex numbers lose their imaginary part, strings and dates are not numbers).
- :func:`finite_result`: a result computed in Python from finite inputs must be finite, else
  :class:`NonFiniteResultError` naming the quantity (and the state of a batch).
- :func:`whole_number`: an integer setting in a range, as a ValueError naming it (not the
  OverflowError of a conversion to a C integer, nor a silent truncation of 2.5).
"""

from __future__ import annotations

import operator

import numpy as np

from ._core import NonFiniteResultError

__all__ = [
    "NonFiniteResultError",
    "real_array",
    "finite_result",
    "whole_number",
    "float64_array",
    "point_in_frame",
    "scalar_or_array",
]

_F64 = np.dtype(np.float64)
_REAL_KINDS = frozenset("fiubO")


def real_array(x, name: str) -> np.ndarray:
    """``x`` as a C-contiguous float64 array; TypeError naming ``name`` for complex numbers, text
    or other non-real dtypes."""
    if type(x) is np.ndarray and x.dtype is _F64:
        return x if x.flags.c_contiguous else np.ascontiguousarray(x)
    try:
        a = x if isinstance(x, np.ndarray) else np.asarray(x)
    except OverflowError:  # a Python integer beyond float64 (and int64)
        raise ValueError(f"{name} holds an integer too large for float64") from None
    if a.dtype.kind not in _REAL_KINDS:
        what = (
            "complex numbers (the imaginary part would be lost)"
            if a.dtype.kind == "c"
            else f"an array of dtype {a.dtype}"
        )
        raise TypeError(f"{name} must be real numbers, got {what}")
    try:
        return np.ascontiguousarray(a, dtype=np.float64)
    except OverflowError:  # an object array holding a Python integer beyond float64
        raise ValueError(f"{name} holds an integer too large for float64") from None
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name} must be real numbers: {e}") from None


def finite_result(x, what: str, batch_axes: int = 0):
    """``x`` unchanged if every number in it is finite, else NonFiniteResultError naming ``what``
    and, for a batch (``batch_axes`` leading axes), the state."""
    a = np.asarray(x)
    if a.dtype.kind in "fc" and not np.isfinite(a).all():
        bad = np.argwhere(~np.isfinite(a))[0]
        at = (
            f" at state {tuple(int(i) for i in bad[:batch_axes]) if batch_axes > 1 else int(bad[0])} of the batch"
            if batch_axes and a.ndim >= batch_axes
            else ""
        )
        element = f"{what}[{', '.join(str(int(i)) for i in bad[batch_axes:])}]" if a.ndim > batch_axes else what
        raise NonFiniteResultError(
            f"{element} is {a[tuple(bad)]}{at}, although every input is finite: the computation overflowed float64; "
            "the inputs are outside the range this model can be evaluated in"
        )
    return x


def whole_number(value, name: str, low: int = 0, high: int = 2**31 - 1) -> int:
    """``value`` as an int in ``[low, high]``; ValueError naming ``name`` otherwise (bools, floats
    and numbers out of range included)."""
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a whole number in [{low}, {high}], got {value!r}")
    try:
        v = operator.index(value)
    except TypeError:
        raise ValueError(
            f"{name} must be a whole number in [{low}, {high}], got {value!r} ({type(value).__name__})"
        ) from None
    if not low <= v <= high:
        raise ValueError(f"{name} must be a whole number in [{low}, {high}], got {v}")
    return v


_F64 = np.dtype(np.float64)


def float64_array(x, name: str = "q") -> np.ndarray:
    """``x`` for the native core: a float64 array passes through (the core reads any layout); anything
    else is converted by :func:`real_array` (complex numbers and text refused, naming ``name``)."""
    if type(x) is np.ndarray and x.dtype is _F64:
        return x
    return real_array(x, name)


def point_in_frame(point) -> np.ndarray | None:
    """A point given in a frame's axes: three finite coordinates, or None."""
    if point is None:
        return None
    p = real_array(point, "point")
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"point must be 3 finite coordinates in the frame's axes, got {point!r}")
    return p


def scalar_or_array(x):
    """A 0-d result as a Python float (one state), else the array (a batch)."""
    return float(x) if np.ndim(x) == 0 else x
