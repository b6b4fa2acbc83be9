"""The mass properties a link's geometry would have at a uniform density, for the audit
(:mod:`kinedyn.description.audit`): volume, centre of the volume, second moments per unit density,
and the points of its convex hull, all in the link frame.

Solids (per unit density): a box of sides a, b, c has ``V = abc`` and ``I = V/12 diag(b^2 + c^2,
a^2 + c^2, a^2 + b^2)``; a cylinder of radius r and length l along z ``V = pi r^2 l``,
``I = V diag((3r^2 + l^2)/12, (3r^2 + l^2)/12, r^2/2)``; a sphere ``V = 4/3 pi r^3``, ``I = 2/5 V r^2 E``
(Meriam & Kraige, Engineering Mechanics: Dynamics, Appendix B). A mesh file is read by trimesh
(optional, the ``viz`` extra): a closed mesh gives its own volume and moments, an open one those of
its convex hull. Shapes are added as if they did not overlap (parallel-axis theorem), which is what
a link's collision shapes usually are.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from .geometry import Box, Cylinder, Mesh, MeshNotFound, Sphere, resolve_mesh

__all__ = ["Solid", "solid_of", "combined", "MAX_MESH_BYTES"]

MAX_MESH_BYTES = 64 * 2**20  # a mesh file larger than this is not read by the audit

# |x|, |y|, |z| of a mesh the audit measures, in the file's units (a robot in millimetres spans 1e4);
# beyond it the products of the volume integrals overflow
MAX_MEASURED_COORDINATE = 1e6
# directions for a sphere's hull points: the 26 of a cube's faces, edges and corners, normalised
_DIRECTIONS = np.array(
    [(x, y, z) for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1) if (x, y, z) != (0, 0, 0)]
)
_DIRECTIONS = _DIRECTIONS / np.linalg.norm(_DIRECTIONS, axis=1)[:, None]


@dataclass(frozen=True)
class Solid:
    """A uniform solid in the link frame: volume [m^3], centre of volume [m], second moments about
    that centre per unit density (``I / rho``, [m^5]), hull points [m]; ``note``: how it was measured."""

    volume: float
    centre: np.ndarray
    moments: np.ndarray
    points: np.ndarray
    note: str = ""
    extent: float = 0.0  # the largest side of the shape's bounding box as written in the file (for units)


def _placed(volume, centre, moments, points, origin, note="", extent=0.0) -> Solid:
    R, p = origin[:3, :3], origin[:3, 3]
    return Solid(volume, R @ centre + p, R @ moments @ R.T, points @ R.T + p, note, extent)


def solid_of(shape, origin: np.ndarray, cache: dict) -> Solid | str:
    """The solid of one shape placed at ``origin`` (4x4 in the link), or a sentence saying why not."""
    if isinstance(shape, Box):
        a, b, c = shape.size
        volume = a * b * c
        moments = volume / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
        corners = np.array([(x, y, z) for x in (-a / 2, a / 2) for y in (-b / 2, b / 2) for z in (-c / 2, c / 2)])
        return _placed(volume, np.zeros(3), moments, corners, origin, extent=max(shape.size))
    if isinstance(shape, Cylinder):
        r, h = shape.radius, shape.length
        volume = math.pi * r * r * h
        across = volume * (3 * r * r + h * h) / 12
        moments = np.diag([across, across, volume * r * r / 2])
        angles = np.linspace(0, 2 * math.pi, 16, endpoint=False)
        ring = np.column_stack([r * np.cos(angles), r * np.sin(angles)])
        points = np.vstack([np.column_stack([ring, np.full(16, z)]) for z in (-h / 2, h / 2)])
        return _placed(volume, np.zeros(3), moments, points, origin, extent=max(2 * r, h))
    if isinstance(shape, Sphere):
        r = shape.radius
        volume = 4 / 3 * math.pi * r**3
        return _placed(volume, np.zeros(3), 0.4 * volume * r * r * np.eye(3), r * _DIRECTIONS, origin, extent=2 * r)
    if isinstance(shape, Mesh):
        found = _mesh(shape, cache)
        if isinstance(found, str):
            return found
        volume, centre, moments, points, note, extent = found
        return _placed(volume, centre, moments, points, origin, note, extent)
    return f"unknown shape {type(shape).__name__}"


def _mesh(shape: Mesh, cache: dict):
    key = (shape.filename, shape.base_dir, tuple(shape.scale))
    if key in cache:
        return cache[key]
    cache[key] = result = _read_mesh(shape)
    return result


def _read_mesh(shape: Mesh):
    try:
        path = resolve_mesh(shape.filename, shape.base_dir)
    except (MeshNotFound, ValueError) as e:
        return f"not read ({e})"
    if os.path.getsize(path) > MAX_MESH_BYTES:
        return f"not read (larger than {MAX_MESH_BYTES // 2**20} MiB)"
    try:
        import trimesh  # only to measure meshes: an optional heavy library (the viz extra)
    except ImportError:
        return "not read (install trimesh, the viz extra, to measure meshes)"
    try:
        mesh: Any = trimesh.load(str(path), force="mesh")
    except Exception as e:  # trimesh raises many kinds for a broken file  # noqa: BLE001
        return f"not read by trimesh ({type(e).__name__}: {e})"
    if not hasattr(mesh, "vertices") or len(mesh.vertices) == 0 or len(getattr(mesh, "faces", ())) == 0:
        return "not read (no triangles)"
    vertices = np.asarray(mesh.vertices, dtype=float)
    if not np.all(np.isfinite(vertices)) or np.max(np.abs(vertices)) > MAX_MEASURED_COORDINATE:
        return f"not measured (a vertex beyond {MAX_MEASURED_COORDINATE:g} in the file's units)"
    try:
        return _measure(mesh, shape)
    except Exception as e:  # qhull and trimesh raise many kinds on a degenerate mesh  # noqa: BLE001
        return f"not measured ({type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''})"


def _measure(mesh: Any, shape: Mesh):
    extent = float(np.max(mesh.extents)) if len(mesh.vertices) else 0.0  # as written in the file, before scale
    mesh.apply_transform(np.diag([*shape.scale, 1.0]))
    note = ""
    if not mesh.is_watertight:
        mesh, note = mesh.convex_hull, "its convex hull (the mesh is not closed)"
    volume = abs(float(mesh.volume))
    if volume <= 0 or not math.isfinite(volume):
        return "not measured (the mesh encloses no volume)"
    # trimesh's moment_inertia is about the centre of mass, at density 1 (so I / rho)
    moments = np.array(mesh.moment_inertia, dtype=float) * (1.0 if mesh.volume > 0 else -1.0)
    points = np.asarray(mesh.convex_hull.vertices, dtype=float)
    return volume, np.asarray(mesh.center_mass, dtype=float), moments, points, note, extent


def combined(solids: list) -> Solid:
    """Several solids as one of uniform density (parallel-axis theorem; overlaps counted twice)."""
    volume = sum(s.volume for s in solids)
    centre = sum(s.volume * s.centre for s in solids) / volume
    moments = np.zeros((3, 3))
    for s in solids:
        d = s.centre - centre
        moments += s.moments + s.volume * (d @ d * np.eye(3) - np.outer(d, d))
    points = np.vstack([s.points for s in solids])
    notes = sorted({s.note for s in solids if s.note})
    return Solid(volume, centre, moments, points, "; ".join(notes), max(s.extent for s in solids))
