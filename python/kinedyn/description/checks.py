"""Value checks shared by every description route (Python calls, URDF, YAML/TOML, DH tables).

A description holds plain numbers or SymPy expressions. A number that reaches the numeric engine
must be real, finite and of a sane size: the algorithms multiply up to three description numbers
together (``m c c^T`` in the parallel-axis theorem, ``r^2 J_m``, ``m g . c``), so a magnitude above
``LARGEST`` = 1e100 could overflow to inf in the first numeric call. Such values are rejected when
the description is built, by a ``ValueError`` naming the field (the caller adds the joint or link;
a file loader adds the file once).
"""

from __future__ import annotations

import math
import numbers
import os
import sys
import types
from typing import TYPE_CHECKING, Any

import numpy as np

from .._lazy import LazyModule, sympy_instance
from .._math import as_value

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = ["LARGEST", "number", "real", "real_array", "vector"]

LARGEST = 1e100  # largest magnitude accepted for a description number (see module docstring)


def _describe(x: Any) -> str:
    text = repr(x)
    return text if len(text) <= 40 else text[:37] + "..."


def real(value: Any, what: str, *, infinite: bool = False) -> float:
    """``value`` as a float: a real number, not NaN, ``|value| <= LARGEST`` (or +-inf when
    ``infinite``, as for joint limits). ValueError naming ``what`` otherwise (never OverflowError or
    TypeError: a 400-digit integer, a complex number or a string is a ValueError too)."""
    if type(value) is float and -LARGEST <= value <= LARGEST:  # the common case, fast (NaN fails it)
        return value
    if (
        isinstance(value, bool)
        or not (isinstance(value, numbers.Real) or sympy_instance(value, "Basic"))
        and not hasattr(value, "__float__")
    ):
        raise ValueError(f"{what} must be a real number, got {_describe(value)}")
    if sympy_instance(value, "Basic") and (not value.is_number or value.is_extended_real is False):
        raise ValueError(f"{what} must be a real number, got {_describe(value)}")
    if isinstance(value, numbers.Complex) and not isinstance(value, numbers.Real):
        raise ValueError(f"{what} must be a real number, got {_describe(value)}")
    try:
        v = float(value)
    except OverflowError:
        raise ValueError(f"{what} is too large ({len(str(value))} digits; at most {LARGEST:g} in magnitude)") from None
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a real number, got {_describe(value)}") from None
    if math.isnan(v):
        raise ValueError(f"{what} is NaN" if infinite else f"{what} is not finite (NaN)")
    if math.isinf(v):
        if infinite:
            return v
        raise ValueError(f"{what} is not finite ({v})")
    if abs(v) > LARGEST:
        raise ValueError(f"{what} is {v:g}: larger in magnitude than {LARGEST:g}, the most a description number may be")
    return v


def number(value: Any, what: str) -> Any:
    """A description number: a SymPy expression with free symbols is kept as it is; anything else
    must pass :func:`real` and is returned as a float."""
    if sympy_instance(value, "Basic") and value.free_symbols:
        return value
    if isinstance(value, str):
        value = as_value(value)  # the expression parser of kinedyn._math
        if sympy_instance(value, "Basic") and value.free_symbols:
            return value
    return real(value, what)


def vector(values: Any, n: int, what: str, noun: str = "components") -> tuple:
    """``n`` description numbers (each as in :func:`number`)."""
    try:
        items = list(values)
    except TypeError:
        raise ValueError(f"{what} must be {n} numbers, got {_describe(values)}") from None
    if len(items) != n:
        raise ValueError(f"{what} must have {n} {noun}, got {len(items)}")
    return tuple(number(v, f"{what}[{i}]") for i, v in enumerate(items))


def real_array(value: Any, shape: tuple) -> Any:
    """``value`` as a float array of ``shape`` when it plainly is one (an int or float dtype, finite,
    at most ``LARGEST`` in magnitude), else None: the caller then checks element by element, which
    gives the precise error (or keeps SymPy expressions). A fast path for long robot files."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError, OverflowError):
        return None
    if a.dtype.kind not in "fiu" or a.shape != shape:  # complex, bool, str, object (SymPy): slow path
        return None
    a = a.astype(float)
    if not np.all(np.abs(a) <= LARGEST):  # NaN fails the comparison too
        return None
    return a


def caller_level() -> int:
    """The ``stacklevel`` for a warning raised in the function that calls this: that of the first
    frame outside kinedyn, so the warning points at the user's call (a file load, a robot built)."""
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    frame: types.FrameType | None = sys._getframe(1)
    level = 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(package + os.sep):
        frame, level = frame.f_back, level + 1
    return level
