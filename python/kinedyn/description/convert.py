"""Deprecated: converting robots moved to :mod:`kinedyn.convert` (it builds robots, so it sits above
the description; docs/architecture.md, the layers). The names are loaded from there by name, on use."""

from __future__ import annotations

import importlib
import warnings

_NAMES = ("convert", "check_conversion", "Conversion", "FORMATS", "format_of")


def __getattr__(name: str):
    if name in _NAMES:
        warnings.warn(
            f"kinedyn.description.convert.{name} moved to kinedyn.convert.{name}", DeprecationWarning, stacklevel=2
        )
        return getattr(importlib.import_module("kinedyn.convert"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
