"""Robot files: ``read_description(path)`` by extension (URDF, xacro, MJCF, YAML, TOML) and
``save(robot, path)`` (YAML, TOML); ``kinedyn.load`` builds the Robot from the description.

The YAML/TOML format (docs/model-files.md) has two flavours:

- DH-based, with a ``joints:`` list of DH rows (``convention: standard|modified``);
- tree-based, with a ``links:`` list of links, each with its joint and inertial data.

Both share ``name``, ``gravity``, ``units: {angle: deg|rad}``, ``frames:`` and ``source``. A string
that is not a number becomes a SymPy expression (``"l1"``, ``"m1*l1**2/12"``). ``save`` writes a
robot with a DH table as DH and any other robot as a tree, always in radians, so that ``load``
gives back the same kinematics, inertias and limits.
"""

from __future__ import annotations

import dataclasses
import importlib
import os
import warnings
from typing import TYPE_CHECKING

import tomli_w

from .._ui.files import require_regular, write_text
from .description import Description
from .file_reader import MAX_FILE_BYTES, MAX_TEXT_BYTES, description_from_mapping, parse_toml, parse_yaml, read_text
from .file_writer import robot_to_mapping
from .mjcf import description_from_mjcf
from .urdf import description_from_urdf

if TYPE_CHECKING:
    from .._typing import PathLike
    from ..robot import Robot

__all__ = [
    "read_description",
    "save",
    "description_from_mapping",
    "robot_to_mapping",
    "MAX_FILE_BYTES",
    "MAX_TEXT_BYTES",
]


def read_description(path: PathLike, inertia: str = "warn", **kwargs) -> Description:
    """The description in ``.urdf`` (``kwargs``: gravity, tool), ``.xml``/``.mjcf`` (MuJoCo; the same
    ``kwargs``), ``.xacro`` (expanded to URDF; ``kwargs`` also ``xacro_args``, ``trust_xacro``,
    ``package_dirs``: see :meth:`kinedyn.Robot.from_urdf`), ``.yaml``/``.yml`` or ``.toml`` (``kwargs``
    replace constructor arguments, e.g. ``gravity=``). ``inertia`` is the policy for inertia tensors
    no rigid body has: "warn" (keep, with a PhysicalConsistencyWarning), "repair" (project onto the
    nearest consistent tensor) or "strict" (raise); see docs/model-files.md."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if os.path.exists(path):  # a FIFO or a device would block the reader (xacro's too): refused first
        require_regular(path, "robot file")
    if ext in (".urdf", ".xacro"):  # robot.urdf.xacro; kwargs: xacro_args, trust_xacro, package_dirs, gravity, tool
        return description_from_urdf(path, inertia=inertia, **kwargs)
    if ext in (".xml", ".mjcf"):
        return description_from_mjcf(path, inertia=inertia, **kwargs)
    if ext not in (".yaml", ".yml", ".toml"):
        raise ValueError(
            f"{path}: unknown robot file extension '{ext}' (expected .urdf, .xacro, .xml (MJCF), .yaml, .yml or .toml)"
        )
    text = read_text(path)
    data = parse_toml(text, path) if ext == ".toml" else parse_yaml(text, path)
    description = description_from_mapping(data, where=path, inertia=inertia)
    return dataclasses.replace(description, **kwargs) if kwargs else description


def save(robot: Robot | Description, path: PathLike) -> None:
    """Write ``robot`` to a ``.yaml``/``.yml`` or ``.toml`` robot file (angles in radians)."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    data = robot_to_mapping(robot, path)
    if ext in (".yaml", ".yml"):
        import yaml  # PyYAML loads only to write a YAML file

        text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=120)
    elif ext == ".toml":
        text = tomli_w.dumps(data)
    else:
        raise ValueError(f"{path}: can only save robots as .yaml, .yml or .toml, not '{ext}'")
    write_text(path, text)  # atomic: a failed run leaves the old file (kinedyn._ui.files)


def __getattr__(name: str):
    # load and robot_from_mapping built a Robot from this layer; they live above the description now
    # (kinedyn.robot_files), loaded by name so that the description never imports the facade
    if name in ("load", "robot_from_mapping"):
        warnings.warn(
            f"kinedyn.description.files.{name} moved to kinedyn.robot_files.{name} (kinedyn.load for load)",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(importlib.import_module("kinedyn.robot_files"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
