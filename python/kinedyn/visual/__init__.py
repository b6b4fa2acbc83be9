"""Seeing a robot: its visual geometry as coloured triangles (:mod:`.scene`, :mod:`.meshes`), drawn in
the report's 3-D view (:mod:`kinedyn.report`) and in a live browser viewer (:mod:`.viewer`, viser).
See docs/visualisation.md."""

from .meshes import Part
from .scene import MissingMeshWarning, Scene, ScenePart, robot_scene

__all__ = ["Part", "Scene", "ScenePart", "MissingMeshWarning", "robot_scene"]
