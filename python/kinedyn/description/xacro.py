"""xacro files (ROS's XML macros, ``robot.urdf.xacro``) -> URDF text, through the PyPI ``xacro`` package.

Expanding xacro RUNS CODE FROM THE FILE. xacro evaluates ``${...}`` with Python's ``eval`` (its
builtins removed, but ``type``, ``vars`` and its helpers exposed) and ``$(eval ...)`` with ``eval``
whose globals hold Python's full builtins, so a file can call ``exec`` and import any module:
``$(eval exec('import os; os.system(...)', dict()))`` runs a shell command (its parentheses smuggled
in through properties, as ``tests/test_xacro.py`` shows). ``<xacro:include>``,
``xacro.load_yaml`` and ``$(env VAR)`` also read any file or environment variable. kinedyn's robot
files are data (docs/architecture.md, "Robot files are data"), so a xacro file is expanded only when the caller
says it trusts it: ``trust_xacro=True`` (CLI ``--trust-xacro``); without it loading refuses, saying why.

``xacro_args``: the file's ``<xacro:arg>`` values (``name:=value`` on xacro's command line).
``package_dirs``: folders where ``$(find PKG)`` looks for ``PKG`` (each folder may hold ``PKG`` or be
it), before ``ROS_PACKAGE_PATH`` and the installed description packages that mesh paths use
(:func:`kinedyn.description.geometry.mesh_search_folders`).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Mapping, Sequence
from pathlib import Path

from .geometry import mesh_search_folders

__all__ = ["expand_xacro", "is_xacro", "XACRO_REFUSED"]

XACRO_REFUSED = (
    "expanding xacro runs the file's Python expressions (its $(eval ...) reaches Python's builtins, so a "
    "xacro file can run any code, and its includes, load_yaml and $(env) read any file or variable); "
    "kinedyn reads robot files as data and expands xacro only for a file you trust: pass trust_xacro=True "
    "(command line: --trust-xacro), or expand it yourself (xacro FILE > robot.urdf) and load the URDF"
)

_LOCK = threading.Lock()  # xacro keeps its state in module globals: one expansion at a time


def is_xacro(path) -> bool:
    return isinstance(path, (str, os.PathLike)) and os.fspath(path).lower().endswith(".xacro")


def expand_xacro(
    path, xacro_args: Mapping[str, object] | None = None, *, trust_xacro: bool = False, package_dirs: Sequence = ()
) -> str:
    """The URDF text a xacro file expands to (see the module docstring: needs ``trust_xacro=True``).
    Every failure is a ValueError naming the file."""
    path = os.fspath(path)
    if trust_xacro is not True:
        raise ValueError(f"{path}: {XACRO_REFUSED}")
    args = {str(k): str(v) for k, v in (xacro_args or {}).items()}
    for key in args:
        if not key or any(c.isspace() for c in key) or ":=" in key:
            raise ValueError(f"{path}: xacro argument name {key!r} is not a name")
    if not os.path.isfile(path):
        raise ValueError(f"{path}: cannot read xacro file (no such file)")
    try:
        import xacro  # type: ignore[import-untyped]
        from xacro import substitution_args
    except ImportError:
        raise ValueError(
            f"{path}: reading xacro files needs the 'xacro' package (pip install xacro, or kinedyn[ros])"
        ) from None
    folders = [Path(d) for d in package_dirs]

    def find(package: str) -> str:
        candidates = [c for d in folders for c in (d / package, d)] + list(
            mesh_search_folders(package, os.path.dirname(os.path.abspath(path)))
        )
        for candidate in candidates:
            if candidate.name == package and candidate.is_dir():
                return str(candidate)
        raise ValueError(
            f"$(find {package}): package '{package}' not found (give its folder's parent in package_dirs, or set ROS_PACKAGE_PATH)"
        )

    with _LOCK:
        saved_find, saved_eval_find = substitution_args._eval_find, substitution_args._eval_dict.get("find")
        substitution_args._eval_find = find
        substitution_args._eval_dict["find"] = find
        try:
            document = xacro.process_file(path, mappings=args, verbosity=0)
            return document.toprettyxml(indent="  ")
        except ValueError as e:
            raise ValueError(f"{path}: xacro could not expand the file: {e}") from None
        except Exception as e:  # XacroException, XML errors, and whatever the file's expressions raise
            raise ValueError(f"{path}: xacro could not expand the file: {type(e).__name__}: {e}") from None
        finally:
            substitution_args._eval_find = saved_find
            if saved_eval_find is not None:
                substitution_args._eval_dict["find"] = saved_eval_find
