"""What a robot looks like: the visual (and collision) geometry of its links, and where mesh files are.

A :class:`Visual` is one shape fixed to a named frame of the robot (a URDF link), placed by its own
``origin`` (the URDF ``<visual><origin>``) and coloured ``rgba``. Shapes: :class:`Box` (full side
lengths), :class:`Cylinder` (along its z axis, centred), :class:`Sphere` and :class:`Mesh` (a file,
STL/OBJ/DAE, with a per-axis ``scale``). Only the description lives here; reading and decimating the
mesh files is :mod:`kinedyn.visual.meshes`, drawing them :mod:`kinedyn.visual`.

Mesh file names are resolved by :func:`resolve_mesh`, in this order (the first file found wins):

1. ``package://PKG/rest`` (also written ``package:///PKG/rest``, as example-robot-data's Talos does:
   ROS's resource_retriever and Pinocchio read the package as the first segment after the slashes): ``PKG`` looked up as ``DIR/PKG`` for each ``DIR`` of ``ROS_PACKAGE_PATH``;
   then as a folder named ``PKG`` among the robot file's folder and its parents, or ``ANCESTOR/PKG``
   for each of those; then in installed description packages: ``cmeel.prefix/share/PKG`` and
   ``cmeel.prefix/share/example-robot-data/robots/PKG`` of every site-packages folder (where
   example-robot-data installs its robots). ``rest`` may not hold ``..``: a package path stays
   inside its package.
2. ``file:///abs/path`` and absolute paths: that file, as written in the robot file (``file://rel/path``
   is a relative path, as ROS's resource_retriever reads it).
3. A relative path: against the robot file's folder, then each of its parents.

Whatever the route, the file must have a mesh extension (``.stl``, ``.obj``, ``.dae``; the file a
symbolic link points to too), so a robot file cannot make kinedyn read an arbitrary file as a mesh;
its size and triangle count are bounded when it is read (:mod:`kinedyn.visual.meshes`).
"""

from __future__ import annotations

import os
import site
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

import numpy as np

__all__ = [
    "Box",
    "Cylinder",
    "Sphere",
    "Mesh",
    "Shape",
    "Visual",
    "MESH_EXTENSIONS",
    "MeshNotFound",
    "resolve_mesh",
    "mesh_search_folders",
    "mesh_reference",
]

MESH_EXTENSIONS = (".stl", ".obj", ".dae")
DEFAULT_RGBA = (0.72, 0.74, 0.76, 1.0)  # a light grey, for shapes whose file gives no colour


@dataclass(frozen=True)
class Box:
    size: tuple[float, float, float]  # full side lengths along x, y, z [m]


@dataclass(frozen=True)
class Cylinder:
    radius: float  # [m]
    length: float  # along the shape's z axis, centred on its origin [m]


@dataclass(frozen=True)
class Sphere:
    radius: float  # [m]


@dataclass(frozen=True)
class Mesh:
    filename: str  # as written in the robot file (package://..., relative or absolute)
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    base_dir: str | None = None  # the folder of the robot file that named it (relative paths start here)


Shape = Union[Box, Cylinder, Sphere, Mesh]


@dataclass(frozen=True)
class Visual:
    """One shape fixed to the frame ``frame`` (a link name), at ``origin`` (4x4, in that frame)."""

    frame: str
    shape: Shape
    origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    rgba: tuple[float, float, float, float] | None = None  # None: the mesh file's colours (or a grey)
    material: str | None = None  # the material's name in the robot file, if any
    where: str = ""  # "file:line" of the element that described it (for messages)

    def describe(self) -> str:
        s = self.shape
        if isinstance(s, Mesh):
            return f"mesh '{s.filename}'"
        return type(s).__name__.lower()


class MeshNotFound(FileNotFoundError):
    """A mesh file named by a robot description that is not where any search route looks."""


# ------------------------------------------------------------------------------ resolution
def _site_folders() -> list[str]:
    folders = []
    try:
        folders += site.getsitepackages()
    except AttributeError:  # some virtualenv layouts
        pass
    try:
        folders.append(site.getusersitepackages())
    except AttributeError:
        pass
    import sys

    folders += [p for p in sys.path if p.endswith("site-packages")]
    seen, out = set(), []
    for f in folders:
        if f not in seen and os.path.isdir(f):
            seen.add(f)
            out.append(f)
    return out


def _ancestors(base_dir: str | None) -> list[Path]:
    if not base_dir:
        return []
    start = Path(base_dir).resolve()
    return [start, *start.parents]


def mesh_search_folders(package: str, base_dir: str | None = None) -> Iterator[Path]:
    """Where ``package://package/...`` is looked for, in order (see the module docstring)."""
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            yield Path(entry) / package
            if Path(entry).name == package:  # an entry may be the package folder itself
                yield Path(entry)
    for folder in _ancestors(base_dir):
        if folder.name == package:
            yield folder
        yield folder / package
    for root in _site_folders():
        share = Path(root) / "cmeel.prefix" / "share"
        yield share / package
        yield share / "example-robot-data" / "robots" / package


def _is_mesh_file(path: Path) -> bool:
    if path.suffix.lower() not in MESH_EXTENSIONS or not path.is_file():
        return False
    return path.resolve().suffix.lower() in MESH_EXTENSIONS  # a symbolic link must point at a mesh file too


def resolve_mesh(filename: str, base_dir: str | None = None) -> Path:
    """The mesh file ``filename`` names (see the module docstring for the order of the search).
    Raises :class:`MeshNotFound` listing where it looked, ValueError for a name that is not a mesh
    file or a package path with ``..``."""
    name = filename.strip()
    if Path(name.split("?")[0]).suffix.lower() not in MESH_EXTENSIONS:
        raise ValueError(f"mesh '{filename}': not a mesh file name (kinedyn reads {', '.join(MESH_EXTENSIONS)})")
    tried: list[Path] = []
    if name.startswith("package://"):
        # package:///PKG/rest (an empty authority) names the same file as package://PKG/rest
        package, _, rest = name[len("package://") :].lstrip("/").partition("/")
        parts = Path(rest).parts
        if not package or not rest or ".." in parts or Path(rest).is_absolute() or ".." == package:
            raise ValueError(
                f"mesh '{filename}': a package path is package://PACKAGE/path inside the package, without '..'"
            )
        for folder in mesh_search_folders(package, base_dir):
            candidate = folder / rest
            tried.append(candidate)
            if _is_mesh_file(candidate):
                return candidate
    else:
        if name.startswith("file://"):
            name = name[len("file://") :]
        path = Path(os.path.expanduser(name))
        if path.is_absolute():
            tried.append(path)
            if _is_mesh_file(path):
                return path
        else:
            for folder in _ancestors(base_dir) or [Path.cwd()]:
                candidate = folder / path
                tried.append(candidate)
                if _is_mesh_file(candidate):
                    return candidate
    shown = ", ".join(str(p) for p in tried[:6]) + (f" and {len(tried) - 6} more places" if len(tried) > 6 else "")
    odd = [p for p in tried if p.exists() and not p.is_file()]  # a FIFO, a device, a folder: never opened
    if odd:
        raise MeshNotFound(f"mesh '{filename}': {odd[0]} is not a regular file; kinedyn reads only regular files")
    raise MeshNotFound(
        f"mesh '{filename}' was not found (looked in {shown or 'no folder'}; set ROS_PACKAGE_PATH to the folder holding its package)"
    )


def mesh_reference(shape: Mesh, written: str | os.PathLike | None = None) -> str:
    """How a robot file written to ``written`` names ``shape``'s mesh file.

    ``package://`` (and other URLs) as read: ROS tools resolve them wherever the file goes. A file
    under the written file's folder, or under that folder's parent (the ``../meshes`` of a ROS
    package, whose robot files sit in ``urdf/``), relative to that folder, with ``/``: the written
    file then holds no absolute path of this machine and moves with its meshes, and every reader
    (URDF, MJCF, robot files) resolves a relative path against the file's folder. Anything else, or
    without ``written``, the file's absolute path (where it was found, see :func:`resolve_mesh`),
    which finds it from wherever the file is written on this machine. A name given without a robot
    file (``base_dir`` None) and relative stays as given."""
    name = shape.filename
    if "://" in name and not name.startswith("file://"):
        return name
    plain = name[len("file://") :] if name.startswith("file://") else name
    if shape.base_dir is None and not os.path.isabs(plain):
        return name
    try:
        file = str(resolve_mesh(name, shape.base_dir))
    except (MeshNotFound, ValueError):  # a missing mesh is reported where it is drawn: keep its name
        file = plain if os.path.isabs(plain) else os.path.join(shape.base_dir or "", plain)
    if written is None:
        return file
    # folders compared with symbolic links resolved (resolve_mesh resolves the robot file's folder);
    # the mesh's own name kept, so a linked mesh stays the link
    here = os.path.dirname(os.path.realpath(os.fspath(written)))
    there = os.path.join(os.path.realpath(os.path.dirname(file)), os.path.basename(file))
    try:
        relative = Path(os.path.relpath(there, here))
    except ValueError:  # another drive: no relative path exists
        return file
    if relative.parts[:2] == ("..", ".."):
        return file
    return relative.as_posix()


def visuals_of_frames(visuals: Sequence[Visual], frames: Sequence[str]) -> list[Visual]:
    """The visuals attached to known frames (those of links removed from the robot are dropped)."""
    known = set(frames)
    return [v for v in visuals if v.frame in known]
