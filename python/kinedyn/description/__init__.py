"""Robot descriptions: inertias, joints, links, DH tables, URDF, MJCF and robot files; every reader
returns a :class:`Description`, from which the caller builds ``kinedyn.Robot(description)``."""

from .description import Description
from .dh import DHRow
from .inertia import Inertia
from .joint import Joint
from .link import Frame, Link
from .loops import Loop

__all__ = ["DHRow", "Description", "Inertia", "Joint", "Link", "Frame", "Loop"]
