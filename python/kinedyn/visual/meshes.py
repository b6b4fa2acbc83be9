"""Triangle meshes for drawing: mesh files read with trimesh (STL, OBJ, DAE/Collada through pycollada),
bounded, grouped by colour, decimated to a triangle budget (quadric decimation, Garland & Heckbert 1997,
through trimesh and fast-simplification) and cached per file; and the primitive shapes (box, cylinder,
sphere) built here with NumPy.

A :class:`Part` is one colour's triangles: ``vertices`` (V, 3) float32 in the shape's own frame,
``faces`` (F, 3) int32, ``rgba`` (None: no colour of its own).
"""

from __future__ import annotations

import io
import math
import os
import re
import warnings
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from .._ui.files import open_regular

__all__ = ["Part", "MAX_MESH_BYTES", "MAX_MESH_TRIANGLES", "read_mesh", "decimate", "box", "cylinder", "sphere"]

MAX_MESH_BYTES = 128 * 2**20  # a mesh file larger than this is refused (a robot's largest is a few MiB)
MAX_MESH_TRIANGLES = 4_000_000  # ... and so is one with more triangles than this


@dataclass(frozen=True)
class Part:
    vertices: np.ndarray  # (V, 3) float32, in the shape's frame [m]
    faces: np.ndarray  # (F, 3) int32, indices into vertices
    rgba: tuple[float, float, float, float] | None = None

    @property
    def triangles(self) -> int:
        return len(self.faces)

    def transformed(self, T: np.ndarray, scale=(1.0, 1.0, 1.0)) -> Part:
        """The part scaled per axis, then moved by the 4x4 ``T``."""
        v = self.vertices.astype(np.float64) * np.asarray(scale, dtype=float)
        v = v @ np.asarray(T, dtype=float)[:3, :3].T + np.asarray(T, dtype=float)[:3, 3]
        faces = self.faces
        if np.prod(np.sign(scale)) < 0:  # a mirroring scale turns the triangles inside out
            faces = faces[:, ::-1]
        return Part(v.astype(np.float32), np.ascontiguousarray(faces), self.rgba)


# ------------------------------------------------------------------------------ primitives
def box(size) -> Part:
    """A box of full side lengths ``size`` centred on its frame: 12 triangles, 24 vertices (flat faces)."""
    hx, hy, hz = (0.5 * float(s) for s in size)
    vertices: list = []
    faces: list = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = sign, a, b
                corners.append(p)
            k = len(vertices)
            vertices += corners
            faces += [[k, k + 1, k + 2], [k, k + 2, k + 3]] if sign > 0 else [[k, k + 2, k + 1], [k, k + 3, k + 2]]
    return Part((np.array(vertices) * [hx, hy, hz]).astype(np.float32), np.array(faces, dtype=np.int32))


def cylinder(radius: float, length: float, sections: int = 24) -> Part:
    """A closed cylinder along z, centred on its frame."""
    a = np.linspace(0.0, 2 * math.pi, sections, endpoint=False)
    ring = np.stack([radius * np.cos(a), radius * np.sin(a)], axis=1)
    h = 0.5 * length
    # side: two rings (s vertices each); caps: their own rings and centres, so the normals stay sharp
    bottom, top = np.c_[ring, np.full(sections, -h)], np.c_[ring, np.full(sections, h)]
    vertices = np.vstack([bottom, top, bottom, top, [[0, 0, -h], [0, 0, h]]])
    i = np.arange(sections)
    j = (i + 1) % sections
    s = sections
    side = np.r_[np.c_[i, j, s + j], np.c_[i, s + j, s + i]]
    cb, ct = 4 * s, 4 * s + 1
    caps = np.r_[np.c_[np.full(s, cb), 2 * s + j, 2 * s + i], np.c_[np.full(s, ct), 3 * s + i, 3 * s + j]]
    return Part(vertices.astype(np.float32), np.r_[side, caps].astype(np.int32))


def sphere(radius: float, rings: int = 12, sections: int = 24) -> Part:
    """A UV sphere centred on its frame."""
    theta = np.linspace(0.0, math.pi, rings + 1)
    phi = np.linspace(0.0, 2 * math.pi, sections, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    vertices = radius * np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    faces = []
    for r in range(rings):
        for c in range(sections):
            a, b = r * sections + c, r * sections + (c + 1) % sections
            faces += [[a, a + sections, b + sections], [a, b + sections, b]]
    return Part(vertices.astype(np.float32), np.array(faces, dtype=np.int32))


# ------------------------------------------------------------------------------ mesh files
def _colour(geometry) -> tuple[float, float, float, float] | None:
    """The main colour trimesh found for a mesh (material colour or face/vertex colours), or None."""
    visual = getattr(geometry, "visual", None)
    if visual is None:
        return None
    try:
        material = getattr(visual, "material", None)
        if material is not None:
            c = getattr(material, "main_color", None)
        elif getattr(visual, "kind", None) is not None:  # ColorVisuals with colours the file gave
            c = visual.main_color
        else:
            return None
        if c is None:
            return None
        c = np.asarray(c, dtype=float).ravel()[:4] / 255.0
        return tuple(float(x) for x in np.clip(c, 0.0, 1.0))  # type: ignore[return-value]
    except Exception:  # a visual trimesh could not interpret: no colour of its own
        return None


# the files a mesh may name beside itself (an OBJ's mtllib, its textures, a DAE's images): read under
# the mesh's own rules (its folder, a regular file, MAX_MESH_BYTES), any other kind of file is not read
SIDE_FILE_EXTENSIONS = (".mtl", ".png", ".jpg", ".jpeg", ".bmp", ".gif", ".tga", ".tif", ".tiff", ".webp")
MAX_MESH_COORDINATE = 1e6  # |x|, |y|, |z| in the file's units: a robot in millimetres spans 1e4


def _side_files(path: str, refused: list):
    """trimesh's resolver for the files a mesh names, kept to kinedyn's rules (above); each file it
    does not read is a message in ``refused`` (trimesh then draws the mesh without it)."""
    from trimesh.resolvers import FilePathResolver  # trimesh (optional, heavy) loads only to read a mesh

    class SideFiles(FilePathResolver):
        def namespaced(self, namespace: str):
            return SideFiles(os.path.join(self.parent, namespace))

        def get(self, name: str):
            try:
                return self._get(name)
            except (OSError, ValueError) as e:
                refused.append(f"mesh '{path}': '{name}' not read: {getattr(e, 'strerror', None) or e}")
                raise

        def _get(self, name: str) -> bytes:
            if os.path.splitext(name.strip())[1].lower() not in SIDE_FILE_EXTENSIONS:
                raise ValueError(f"not a material or an image ({', '.join(SIDE_FILE_EXTENSIONS)})")
            target = self.absolute(name)  # trimesh's own rule: inside the mesh's folder
            with open_regular(target, "file") as f:
                data = f.read(MAX_MESH_BYTES + 1)
            if len(data) > MAX_MESH_BYTES:
                raise ValueError(f"more than the {MAX_MESH_BYTES // 2**20} MiB kinedyn reads")
            return data

    return SideFiles(path)


def counted_triangles(data: bytes, ext: str) -> int:
    """The triangles a mesh file declares, counted without parsing it: a binary STL's header count,
    an ASCII STL's facets, an OBJ's face lines (a polygon of k corners is k - 2 triangles or more),
    a DAE's primitive counts. A lower bound where it cannot be exact, so a refusal is never wrong."""
    if ext == ".stl":
        if data[:5].lower() == b"solid" and b"facet" in data[:4096]:
            return data.count(b"endfacet")
        return int.from_bytes(data[80:84], "little") if len(data) >= 84 else 0
    if ext == ".obj":
        return data.count(b"\nf ") + data.startswith(b"f ")
    if ext == ".dae":
        return sum(int(m) for m in re.findall(rb"<(?:triangles|polylist|polygons)\b[^>]*?\bcount=\"(\d{1,12})\"", data))
    return 0


_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])


def _binary_stl(data: bytes, path: str) -> Part | None:
    """A binary STL read with NumPy in the format's own layout (an 80-byte header, a triangle count,
    then 50 bytes a triangle: normal, three corners, an attribute), its corners merged into shared
    vertices by value: a few times the file's size in memory, where trimesh's general reader takes
    ~700 bytes a triangle (1.7 GB for a 119 MiB file). None for an ASCII STL or one whose length
    disagrees with its count (trimesh's reader then decides)."""
    if len(data) < 84 or (data[:5].lower() == b"solid" and b"facet" in data[:4096]):
        return None
    count = int.from_bytes(data[80:84], "little")
    if count == 0 or len(data) != 84 + _STL_RECORD.itemsize * count:
        return None
    corners = np.frombuffer(data, dtype=_STL_RECORD, count=count, offset=84)["corners"].reshape(-1, 3)
    if not np.all(np.isfinite(corners)):
        raise ValueError(f"mesh '{path}' has vertices that are not finite numbers")
    if np.max(np.abs(corners)) > MAX_MESH_COORDINATE:
        raise ValueError(
            f"mesh '{path}' has a vertex at {np.max(np.abs(corners)):.3g}, beyond the {MAX_MESH_COORDINATE:g} kinedyn draws"
        )
    # one vertex per position, positions equal to 8 decimals as trimesh's merge_vertices takes them
    # (tol.merge = 1e-8; + 0.0 makes -0.0 and 0.0 one position)
    keys = np.round(corners.astype(np.float64), 8) + 0.0
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    del keys
    return Part(np.ascontiguousarray(corners[first]), inverse.reshape(-1, 3).astype(np.int32), None)


@lru_cache(maxsize=256)
def _read(path: str, mtime_ns: int, size: int) -> tuple[Part, ...]:
    import trimesh

    ext = os.path.splitext(path)[1].lower()
    with open_regular(path, "mesh") as f:  # a FIFO or a device: refused, never waited on
        data = f.read(MAX_MESH_BYTES + 1)
    if len(data) > MAX_MESH_BYTES:
        raise ValueError(f"mesh '{path}' is more than the {MAX_MESH_BYTES // 2**20} MiB kinedyn reads")
    declared = counted_triangles(data, ext)
    if declared > MAX_MESH_TRIANGLES:  # refused before trimesh builds it (gigabytes for a large file)
        raise ValueError(
            f"mesh '{path}' declares {declared:,} triangles, more than the {MAX_MESH_TRIANGLES:,} kinedyn reads "
            "(kinedyn draws robots, not scans)"
        )
    if ext == ".stl":
        part = _binary_stl(data, path)
        if part is not None:
            return (part,)
    refused: list[str] = []
    loaded = trimesh.load(
        io.BytesIO(data), file_type=ext.lstrip("."), force="scene", process=False, resolver=_side_files(path, refused)
    )
    del data
    for message in dict.fromkeys(refused):
        warnings.warn(message, stacklevel=2)
    meshes = loaded.dump(concatenate=False) if hasattr(loaded, "dump") else [loaded]
    by_colour: dict = {}
    total = 0
    for m in meshes:
        if not hasattr(m, "faces") or len(m.faces) == 0:
            continue
        total += len(m.faces)
        if total > MAX_MESH_TRIANGLES:
            raise ValueError(
                f"mesh '{path}' has more than {MAX_MESH_TRIANGLES:,} triangles (kinedyn draws robots, not scans)"
            )
        raw = np.asarray(m.vertices, dtype=np.float64)  # type: ignore[union-attr]
        if not np.all(np.isfinite(raw)):
            raise ValueError(f"mesh '{path}' has vertices that are not finite numbers")
        if raw.size and np.max(np.abs(raw)) > MAX_MESH_COORDINATE:  # 1e308 overflows float32 and the report's JSON
            raise ValueError(
                f"mesh '{path}' has a vertex at {np.max(np.abs(raw)):.3g}, beyond the {MAX_MESH_COORDINATE:g} kinedyn draws"
            )
        by_colour.setdefault(_colour(m), []).append(m)
    parts = []
    for rgba, group in by_colour.items():
        merged: Any = group[0] if len(group) == 1 else trimesh.util.concatenate(group)
        # one vertex per position (files often repeat them per face): smaller, and decimation then
        # collapses edges of a connected surface instead of tearing it
        merged = trimesh.Trimesh(np.asarray(merged.vertices), np.asarray(merged.faces), process=True)
        v = np.asarray(merged.vertices, dtype=np.float64)
        if not np.all(np.isfinite(v)):
            raise ValueError(f"mesh '{path}' has vertices that are not finite numbers")
        parts.append(Part(v.astype(np.float32), np.asarray(merged.faces, dtype=np.int32), rgba))
    if not parts:
        raise ValueError(f"mesh '{path}' holds no triangles")
    return tuple(parts)


def read_mesh(path) -> list[Part]:
    """The triangles of a mesh file, one :class:`Part` per colour (cached per file: path, size and
    modification time). ValueError naming the file for one too large, unreadable or empty."""
    path = Path(path)
    try:
        st = os.stat(path)
    except OSError as e:
        raise ValueError(f"mesh '{path}': cannot read it ({e.strerror or e})") from None
    if st.st_size > MAX_MESH_BYTES:
        raise ValueError(
            f"mesh '{path}' is {st.st_size / 2**20:.0f} MiB, more than the {MAX_MESH_BYTES // 2**20} MiB kinedyn reads"
        )
    try:
        import trimesh  # noqa: F401
    except ImportError:
        raise ValueError(f"mesh '{path}': reading mesh files needs trimesh (pip install 'kinedyn[viz]')") from None
    try:
        return list(_read(str(path.resolve()), st.st_mtime_ns, st.st_size))
    except ValueError as e:  # kinedyn's own name the mesh; trimesh's ("could not be read to its end") do not
        if str(path) in str(e) or str(path.resolve()) in str(e):
            raise
        raise ValueError(f"mesh '{path}' could not be read: {e}") from None
    except MemoryError:
        raise ValueError(f"mesh '{path}' needs more memory than this machine has") from None
    except Exception as e:  # whatever trimesh or pycollada raise on a broken file
        raise ValueError(f"mesh '{path}' could not be read: {type(e).__name__}: {e}") from None


def decimate(part: Part, faces: int) -> Part:
    """``part`` with at most about ``faces`` triangles (quadric decimation); unchanged if it has fewer
    or if fast-simplification is not installed."""
    if part.triangles <= faces:
        return part
    return _decimated(part, max(int(faces), 8))


_DECIMATED: dict = {}


def _decimated(part: Part, faces: int) -> Part:
    key = (id(part.vertices), part.triangles, faces)
    hit = _DECIMATED.get(key)
    if hit is not None and hit[0] is part.vertices:
        return hit[1]
    try:
        import fast_simplification
    except ImportError:
        return part
    v, f = fast_simplification.simplify(
        part.vertices.astype(np.float32), part.faces.astype(np.int32), target_count=faces
    )
    out = Part(np.asarray(v, dtype=np.float32), np.asarray(f, dtype=np.int32), part.rgba)
    if len(_DECIMATED) > 1024:
        _DECIMATED.clear()
    _DECIMATED[key] = (part.vertices, out)
    return out
