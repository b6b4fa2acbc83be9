"""Robots from files: the readers of :mod:`kinedyn.description` return a description, and these
build the :class:`~kinedyn.Robot` from it (the description layer never imports the facade;
docs/architecture.md, the layers). ``kinedyn.load`` is :func:`load`."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .description.file_reader import description_from_mapping
from .description.files import read_description
from .description.mjcf import description_from_mjcf
from .description.urdf import description_from_urdf
from .robot import Robot

if TYPE_CHECKING:
    from ._typing import PathLike

__all__ = ["load", "robot_from_urdf", "robot_from_mjcf", "robot_from_mapping"]


def load(path: PathLike, inertia: str = "warn", **kwargs) -> Robot:
    """A robot from a URDF (.urdf, .xacro), MJCF (.xml, .mjcf), YAML (.yaml/.yml) or TOML (.toml)
    file, by extension (:func:`kinedyn.description.files.read_description` says what ``kwargs`` each
    takes). ``inertia``: the policy for an inertia no rigid body can have (docs/model-files.md)."""
    return Robot(read_description(path, inertia=inertia, **kwargs))


def robot_from_urdf(path_or_string, **kwargs) -> Robot:
    """A robot from a URDF file path or XML string (keywords as
    :func:`kinedyn.description.urdf.description_from_urdf`)."""
    return Robot(description_from_urdf(path_or_string, **kwargs))


def robot_from_mjcf(path_or_string, **kwargs) -> Robot:
    """A robot from an MJCF file path or XML string (keywords as
    :func:`kinedyn.description.mjcf.description_from_mjcf`)."""
    return Robot(description_from_mjcf(path_or_string, **kwargs))


def robot_from_mapping(data, where: str = "<robot mapping>", inertia: str = "warn") -> Robot:
    """A robot from the parsed contents of a YAML/TOML robot file (docs/model-files.md)."""
    return Robot(description_from_mapping(data, where, inertia))
