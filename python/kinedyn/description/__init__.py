"""Robot descriptions: inertias, joints, links, DH tables, URDF and robot files."""

from .dh import DHRow
from .inertia import Inertia
from .joint import Joint
from .link import Frame, Link

__all__ = ["DHRow", "Inertia", "Joint", "Link", "Frame"]
