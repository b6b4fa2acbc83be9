"""The built-in catalogue. Each function returns a fresh :class:`kinedyn.Robot` and takes keyword
overrides for its parameters; each docstring cites the source of its numbers."""

from __future__ import annotations

from .basic import cartesian_2p, elbow_3r, planar_2r, planar_3r
from .industrial import puma560, stanford, ur5

CATALOGUE = {
    "planar_2r": planar_2r,
    "planar_3r": planar_3r,
    "elbow_3r": elbow_3r,
    "cartesian_2p": cartesian_2p,
    "puma560": puma560,
    "stanford": stanford,
    "ur5": ur5,
}

DEFAULT = "planar_2r"


def names() -> list:
    return list(CATALOGUE)


def get(name: str, **overrides):
    """A built-in robot by name."""
    try:
        factory = CATALOGUE[name]
    except KeyError:
        raise ValueError(f"unknown built-in robot '{name}' (built-ins: {', '.join(CATALOGUE)})") from None
    return factory(**overrides)


__all__ = ["CATALOGUE", "DEFAULT", "names", "get", *CATALOGUE]
