"""Heavy libraries loaded on first use, so that ``import kinedyn`` and numeric work stay fast.

SymPy takes about 0.3 s to import (half of what ``import kinedyn`` once cost) and only symbolic
values need it: a description of plain numbers never touches it. Modules that handle values which
*may* be symbolic hold ``sp = LazyModule("sympy")`` (under ``TYPE_CHECKING`` the real module, for
the type checker): the first attribute read, ``sp.Symbol`` say, imports SymPy. Type tests go through
:func:`sympy_instance`, which never imports it: nothing can be a SymPy object before SymPy is loaded.
"""

from __future__ import annotations

import importlib
import sys
from typing import Any

__all__ = ["LazyModule", "sympy_instance"]


class LazyModule:
    """A module imported on the first attribute access (it delays a heavy library)."""

    def __init__(self, name: str):
        self._name = name

    def __getattr__(self, attr: str) -> Any:
        module = importlib.import_module(self._name)
        return getattr(module, attr)

    def __repr__(self) -> str:
        return f"<{self._name}, imported on first use>"


def sympy_instance(x: Any, *names: str) -> bool:
    """``isinstance(x, (sympy.<name>, ...))`` without importing SymPy (``names`` default: ``Basic``
    and ``MatrixBase``, any SymPy value)."""
    sympy = sys.modules.get("sympy")
    if sympy is None:
        return False
    return isinstance(x, tuple(getattr(sympy, n) for n in (names or ("Basic", "MatrixBase"))))
