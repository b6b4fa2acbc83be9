"""Writing a robot as the contents of a YAML/TOML robot file (docs/model-files.md): a DH table when
the robot has one its links agree with, a tree of links otherwise; angles in radians, numbers exact,
so that reading the file back gives the same kinematics, inertias and limits."""

from __future__ import annotations

import math
import sys
from typing import TYPE_CHECKING

import numpy as np

if sys.version_info >= (3, 11):
    pass
else:  # Python 3.10 (requires-python): tomllib is tomli, in the standard library since 3.11
    pass

from .._lazy import LazyModule, sympy_instance
from .._math import is_symbolic, matmul, pose_inverse, rpy_from_matrix
from .dh import links_from_dh
from .geometry import Box, Cylinder, Mesh, mesh_reference
from .inertia import Inertia
from .loop_files import loops_mapping

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

if TYPE_CHECKING:
    from ..robot import Robot
    from .description import Description

__all__ = ["robot_to_mapping"]

_TENSOR_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def robot_to_mapping(robot: Robot | Description, path: str | None = None) -> dict:
    """The YAML/TOML contents for ``robot``: DH flavour when it has a consistent DH table. ``path``:
    where it will be written (mesh files near it are then named relative to it, see
    :func:`~kinedyn.description.geometry.mesh_reference`)."""
    data: dict = {"name": robot.name, "gravity": [_dump(g) for g in robot.gravity]}
    if robot.source:
        data["source"] = robot.source
    base_pose = _dh_base_pose(robot)
    if base_pose is not None:
        data.update(_dh_mapping(robot, base_pose))
    else:
        data.update(_tree_mapping(robot))
    if robot.visuals:
        data["visuals"] = [_visual_mapping(v, path) for v in robot.visuals]
    if robot.loops:
        data["loops"] = loops_mapping(robot.loops)
    reference = getattr(robot, "description", robot).reference_configuration
    if reference:  # radians, as every angle this writer writes
        data["reference_configuration"] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in reference.items()}
    return data


def _visual_mapping(v, path: str | None) -> dict:
    out: dict = {"link": v.frame}
    s = v.shape
    if isinstance(s, Mesh):
        out["mesh"] = mesh_reference(s, path)
        out["scale"] = [float(x) for x in s.scale]
    elif isinstance(s, Box):
        out["box"] = [float(x) for x in s.size]
    elif isinstance(s, Cylinder):
        out["cylinder"] = {"radius": float(s.radius), "length": float(s.length)}
    else:
        out["sphere"] = float(s.radius)
    T = np.asarray(v.origin, dtype=float)
    if not np.allclose(T, np.eye(4)):
        out["origin"] = {"xyz": [float(x) for x in T[:3, 3]], "rpy": list(rpy_from_matrix(T[:3, :3]))}
    if v.rgba is not None:
        out["color"] = [float(x) for x in v.rgba]
    return out


def _dump(v):
    if sympy_instance(v, "Basic"):
        return float(v) if not v.free_symbols else str(v)
    return float(v)


def _is_identity(T) -> bool:
    if is_symbolic(T):
        return sp.Matrix(T) == sp.eye(4)
    return np.allclose(np.asarray(T, dtype=float), np.eye(4), atol=1e-15)


def _pose_mapping(T, what: str) -> dict:
    T = sp.Matrix(T) if is_symbolic(T) else np.asarray(T, dtype=float)
    if is_symbolic(T[:3, :3]):
        raise ValueError(f"cannot save {what}: its rotation is symbolic (only translations may hold symbols)")
    R = np.array(sp.Matrix(T[:3, :3]).tolist(), dtype=float) if sympy_instance(T, "MatrixBase") else T[:3, :3]
    return {"xyz": [_dump(T[i, 3]) for i in range(3)], "rpy": list(rpy_from_matrix(R))}


def _same_pose(A, B) -> bool:
    if is_symbolic(A) or is_symbolic(B):
        return sp.simplify(sp.Matrix(A) - sp.Matrix(B)) == sp.zeros(4, 4)
    return np.allclose(np.asarray(A, dtype=float), np.asarray(B, dtype=float), atol=1e-12)


def _dh_base_pose(robot: Robot | Description):
    """The base pose of the DH table if ``robot.links`` are exactly what its DH table gives, else None."""
    if robot.dh is None or robot.dh_convention is None:
        return None
    links, _ = links_from_dh(robot.dh, robot.dh_convention)
    if len(links) != len(robot.links):
        return None
    base_pose = matmul(robot.links[0].placement, pose_inverse(links[0].placement))
    for k, (mine, theirs) in enumerate(zip(robot.links, links)):
        placement = matmul(base_pose, theirs.placement) if k == 0 else theirs.placement
        same = (
            (mine.name, mine.parent, mine.joint, mine.inertia)
            == (theirs.name, theirs.parent, theirs.joint, theirs.inertia)
            and _same_pose(mine.placement, placement)
            and _same_pose(mine.post, theirs.post)
        )
        if not same:
            return None
    return base_pose


def _limits_mapping(joint) -> dict:
    out = {}
    for key, field in (
        ("lower", "lower"),
        ("upper", "upper"),
        ("velocity", "velocity_limit"),
        ("effort", "effort_limit"),
    ):
        v = getattr(joint, field)
        if math.isfinite(v):
            out[key] = float(v)
    return out


def _drive_mapping(obj) -> dict:
    defaults = {"gear_ratio": 1.0, "rotor_inertia": 0.0, "viscous": 0.0, "coulomb": 0.0}
    out = {k: _dump(getattr(obj, k)) for k, d in defaults.items() if getattr(obj, k) != d}
    negative = getattr(obj, "coulomb_negative", None)
    if negative is not None and negative != obj.coulomb:  # direction-dependent: [positive, negative]
        out["coulomb"] = [_dump(obj.coulomb), _dump(negative)]
    return out


def _inertia_mapping(inertia: Inertia) -> dict:
    I = inertia.inertia
    tensor = {k: _dump(I[r][c]) for k, (r, c) in zip(_TENSOR_KEYS, ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))}
    return {"mass": _dump(inertia.mass), "com": [_dump(c) for c in inertia.com], "inertia": tensor}


def _frames_mapping(frames) -> list:
    out = []
    for f in frames:
        entry: dict = {"name": f.name}
        if f.link is not None:
            entry["link"] = f.link
        entry["origin"] = _pose_mapping(f.placement, f"frame '{f.name}'")
        out.append(entry)
    return out


def _dh_mapping(robot: Robot | Description, base_pose) -> dict:
    out: dict = {"convention": robot.dh_convention, "units": {"angle": "rad"}}
    if not _is_identity(base_pose):
        out["base_pose"] = _pose_mapping(base_pose, "the base pose")
    last = robot.links[-1].name
    tool = [f for f in robot.frames if f.name == "tool" and f.link == last]
    if tool and not _is_identity(tool[0].placement):
        out["tool"] = _pose_mapping(tool[0].placement, "the tool frame")
    extra = [f for f in robot.frames if not (f.name == "tool" and f.link == last)]
    if extra:
        out["frames"] = _frames_mapping(extra)
    if robot.tool != "tool":
        out["tool_frame"] = robot.tool
    assert robot.dh is not None  # robot_to_mapping writes a DH table only for a robot that has one
    rows = []
    for _k, (row, link) in enumerate(zip(robot.dh, robot.links)):
        entry: dict = {"name": link.joint.name, "type": row.kind}
        entry.update({key: _dump(getattr(row, key)) for key in ("theta", "d", "a", "alpha")})
        limits = _limits_mapping(link.joint)
        if limits:
            entry["limits"] = limits
        entry.update(_inertia_mapping(row.inertia))
        entry.update(_drive_mapping(row))
        rows.append(entry)
    out["joints"] = rows
    return out


def _tree_mapping(robot: Robot | Description) -> dict:
    out: dict = {"base": robot.base, "tool": robot.tool, "units": {"angle": "rad"}}
    links = []
    for link in robot.links:
        j = link.joint
        joint: dict = {"name": j.name, "type": j.kind, "axis": [_dump(a) for a in j.axis]}
        if not _is_identity(link.placement):
            joint["origin"] = _pose_mapping(link.placement, f"the joint origin of link '{link.name}'")
        if _dump(j.offset) != 0.0:
            joint["offset"] = _dump(j.offset)
        limits = _limits_mapping(j)
        if limits:
            joint["limits"] = limits
        joint.update(_drive_mapping(j))
        if j.mimic is not None:
            joint["mimic"] = {"joint": j.mimic.leader, "multiplier": j.mimic.multiplier, "offset": j.mimic.offset}
        entry: dict = {"name": link.name}
        if link.parent is not None:
            entry["parent"] = link.parent
        entry["joint"] = joint
        if not _is_identity(link.post):
            entry["post"] = _pose_mapping(link.post, f"the post transform of link '{link.name}'")
        entry["inertial"] = _inertia_mapping(link.inertia)
        links.append(entry)
    out["links"] = links
    if robot.frames:
        out["frames"] = _frames_mapping(robot.frames)
    return out
