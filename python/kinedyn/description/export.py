"""Robots out: :class:`kinedyn.Robot` -> URDF and MJCF (MuJoCo's XML).

Both writers read the frozen description (``robot.links``, ``robot.frames``, visuals, gravity) and
write numbers with 17 significant digits, so that a file read back gives the same kinematics and
dynamics to rounding (docs/model-files.md, "Converting robots").

**Joint offsets.** kinedyn moves a link by ``placement · motion(q + offset) · post``
(:mod:`kinedyn.description.link`); URDF and MJCF have no offset and no ``post``. A rotation (or
translation) about a fixed axis by ``q + offset`` is the motion by ``offset`` followed by the motion
by ``q`` (motions about one axis commute), so the offset is folded into the joint's origin:
``origin = placement · motion(offset)``, and ``q`` means the same in the file as in kinedyn.

**post.** URDF moves a child link about an axis through its own origin. A link with a ``post``
transform (a standard DH link, whose frame sits at the far end of the link) is written as two URDF
links: ``<name>_body`` moved by the joint (frame = the joint frame after motion, holding the mass),
and ``<name>`` fixed to it at ``post`` (the link frame, holding the visuals). MJCF needs no split:
a body is placed at the link frame and its hinge/slide joint is given a ``pos`` and ``axis`` in that
frame (``post⁻¹`` applied to the joint's axis line).

Extra frames (``robot.frames``, e.g. a DH robot's ``tool``) become massless links on fixed joints
(URDF) or massless bodies without joints (MJCF). Closed loops: a URDF ``<loop>`` between the links of
their frames, an MJCF ``<equality><connect|weld>`` between sites (a loop end that is an extra frame
is that site), :mod:`kinedyn.description.loop_files`.
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

import numpy as np

from .._math import pose_inverse, rot_axis, rpy_from_matrix, translation
from .._ui.files import write_text
from .geometry import Box, Cylinder, Mesh, Sphere, Visual, mesh_reference, resolve_mesh
from .inertia import Inertia
from .link import Link
from .loop_files import mjcf_loop_sites, urdf_loop_elements, urdf_reference_element, write_mjcf_loops

if TYPE_CHECKING:
    from .._typing import PathLike
    from ..robot import Robot

__all__ = ["to_urdf", "to_mjcf", "rpy_from_matrix", "quaternion_from_matrix", "default_visuals", "DRAKE_NAMESPACE"]

#: URDF has no rotor inertia: the writer keeps gear ratio and rotor inertia in Drake's extension of
#: ``<transmission>`` (``drake:gear_ratio``, ``drake:rotor_inertia``), which other readers ignore.
DRAKE_NAMESPACE = "http://drake.mit.edu"

#: MuJoCo refuses a principal moment of inertia that is not positive: smaller ones are raised to this
#: [kg m^2] (all three by the same amount, which keeps the triangle inequality) when writing MJCF.
MIN_MOMENT = 1e-12
# (a moving body with less mass than MIN_MOMENT, in kg, gets that much: MuJoCo refuses massless moving bodies)


# ---------------------------------------------------------------------------------------- numbers
def _f(x) -> str:
    """A float with 17 significant digits (round-trips exactly), no -0."""
    v = float(x) + 0.0
    if v == int(v) and abs(v) < 1e15:
        return str(int(v))
    return repr(v)


def _fs(values) -> str:
    return " ".join(_f(v) for v in values)


def quaternion_from_matrix(R) -> tuple[float, float, float, float]:
    """Unit quaternion (w, x, y, z) (MuJoCo's order) of a rotation matrix, w >= 0 (Shepperd's method:
    the largest of 4w², 4x², 4y², 4z² is the pivot, so no division by a small number)."""
    R = np.asarray(R, dtype=float)
    t = np.trace(R)
    candidates = [t, R[0, 0], R[1, 1], R[2, 2]]
    k = int(np.argmax(candidates))
    if k == 0:
        w = math.sqrt(1.0 + t) / 2
        q = (w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w))
    elif k == 1:
        x = math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2]) / 2
        q = ((R[2, 1] - R[1, 2]) / (4 * x), x, (R[0, 1] + R[1, 0]) / (4 * x), (R[0, 2] + R[2, 0]) / (4 * x))
    elif k == 2:
        y = math.sqrt(1.0 - R[0, 0] + R[1, 1] - R[2, 2]) / 2
        q = ((R[0, 2] - R[2, 0]) / (4 * y), (R[0, 1] + R[1, 0]) / (4 * y), y, (R[1, 2] + R[2, 1]) / (4 * y))
    else:
        z = math.sqrt(1.0 - R[0, 0] - R[1, 1] + R[2, 2]) / 2
        q = ((R[1, 0] - R[0, 1]) / (4 * z), (R[0, 2] + R[2, 0]) / (4 * z), (R[1, 2] + R[2, 1]) / (4 * z), z)
    n = math.sqrt(sum(c * c for c in q))
    s = 1.0 if q[0] >= 0 else -1.0
    return tuple(s * c / n + 0.0 for c in q)  # type: ignore[return-value]


# ---------------------------------------------------------------------------------------- checks
def _require_numeric(robot: Robot, what: str) -> None:
    if robot.is_symbolic:
        names = sorted(map(str, robot.symbols))
        raise ValueError(
            f"{what}: robot '{robot.name}' has symbolic parameters {names}; a {what.split()[-1]} file holds numbers: "
            f"substitute values first (robot.subs({{{', '.join(repr(n) + ': ...' for n in names)}}}))"
        )


def _np(T) -> np.ndarray:
    return np.asarray(T, dtype=float)


def _is_identity(T) -> bool:
    return bool(np.allclose(_np(T), np.eye(4), rtol=0.0, atol=1e-15))


def _motion(joint, x: float) -> np.ndarray:
    """The joint's motion by the coordinate x (rotation about / translation along its axis)."""
    if x == 0.0 or joint.kind not in ("revolute", "prismatic"):
        return np.eye(4)
    axis = [float(a) for a in joint.axis]
    if joint.kind == "revolute":
        return _np(rot_axis(axis, x))
    return _np(translation(*(a * x for a in axis)))


def _unique(name: str, taken: set) -> str:
    out, k = name, 2
    while out in taken:
        out, k = f"{name}_{k}", k + 1
    taken.add(out)
    return out


def _coulomb(joint, fmt: str) -> float:
    positive, negative = joint.coulomb_levels
    if float(positive) != float(negative):
        warnings.warn(
            f"{fmt} holds one Coulomb friction level per joint: joint '{joint.name}' has {float(positive)} for qd > 0 "
            f"and {float(negative)} for qd < 0; writing {float(positive)}",
            stacklevel=4,
        )
    return float(positive)


def _relative_to(file: str, written: str) -> str:
    """``file`` relative to the folder of the file being ``written`` (a written model then holds no
    absolute path of the machine that wrote it); absolute when no relative path exists (another
    drive)."""
    try:
        return os.path.relpath(file, os.path.dirname(os.path.abspath(written)))
    except ValueError:
        return file


def _mesh_file(shape: Mesh) -> str:
    name = shape.filename
    if shape.base_dir is None or "://" in name or os.path.isabs(name):
        return name
    return os.path.join(shape.base_dir, name)


# ---------------------------------------------------------------------------------------- geometry
def default_visuals(robot: Robot, radius: float | None = None) -> list[Visual]:
    """Solid links for a robot without geometry (a DH robot): a cylinder along each joint axis at
    the joint, and cylinders along each link's offsets — from the joint along its own axis, then
    across (a standard DH link's ``d`` then ``a``), and from the link frame across, then along the
    next joint's axis (a modified DH row's ``a`` then ``d``) — to each child joint and extra frame.
    ``radius``: of the link cylinders (default: 4% of the robot's reach, at least 1 cm); joint
    cylinders are 1.5 times as thick and 6 radii long. All shapes are attached to link frames."""
    _require_numeric(robot, "default visuals")
    pieces: list[tuple[str, np.ndarray, np.ndarray]] = []  # (frame, p0, p1) in the frame's coordinates
    joints: list[tuple[str, np.ndarray, np.ndarray]] = []  # (frame, point, axis)
    children: dict[str, list] = {}
    for link in robot.links:
        children.setdefault(link.parent or robot.base, []).append((_np(link.placement), link.joint))
    for extra in robot.frames:
        children.setdefault(extra.link or robot.base, []).append((_np(extra.placement), None))

    def polyline(frame: str, start: np.ndarray, end: np.ndarray, axis: np.ndarray | None, axis_first: bool) -> None:
        d = end - start
        if axis is not None and np.linalg.norm(d) > 1e-12:
            along = float(d @ axis) * axis
            corner = start + along if axis_first else end - along
            for a, b in ((start, corner), (corner, end)):
                if np.linalg.norm(b - a) > 1e-9:
                    pieces.append((frame, a, b))
        elif np.linalg.norm(d) > 1e-9:
            pieces.append((frame, start, end))

    for link in robot.links:
        post = _np(link.post)
        if link.joint.is_moving:
            # the joint origin and axis seen from the link frame (post^-1)
            inv = _np(pose_inverse(post))
            origin = inv[:3, 3]
            axis = inv[:3, :3] @ np.array([float(a) for a in link.joint.axis])
            joints.append((link.name, origin, axis))
            polyline(link.name, origin, np.zeros(3), axis, True)
    for owner, items in children.items():
        for placement, joint in items:
            end = placement[:3, 3]
            axis = (
                placement[:3, :3] @ np.array([float(a) for a in joint.axis])
                if joint is not None and joint.is_moving
                else None
            )
            polyline(owner, np.zeros(3), end, axis, False)
    lengths = [float(np.linalg.norm(b - a)) for _, a, b in pieces]
    reach = sum(lengths) if lengths else 0.5
    r = radius if radius is not None else max(0.04 * reach, 0.01)
    out: list[Visual] = []
    grey, blue = (0.72, 0.74, 0.76, 1.0), (0.25, 0.45, 0.8, 1.0)
    for frame, a, b in pieces:
        out.append(Visual(frame, Cylinder(r, float(np.linalg.norm(b - a))), _segment_pose(a, b), grey))
    for frame, point, axis in joints:
        pose = _segment_pose(point - 3 * r * axis, point + 3 * r * axis)
        out.append(Visual(frame, Cylinder(1.5 * r, 6 * r), pose, blue))
    return out


def _segment_pose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """A pose whose z axis runs from a to b, centred between them (a cylinder's frame)."""
    z = (b - a) / np.linalg.norm(b - a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = (a + b) / 2
    return T


def _visuals_for_writing(robot: Robot, geometry: bool) -> tuple[list, list]:
    visuals, collisions = list(robot.visuals), list(robot.collisions)
    if geometry and not visuals:
        visuals = default_visuals(robot)
    return visuals, collisions


def _default_inertias(robot: Robot) -> Robot:
    """The robot with the documented default inertia for every moving link whose subtree has no
    mass at all (a DH table without inertial data): 1 kg spread along the link's cylinders,
    approximated as a solid cylinder of the link's length and 4% of it in radius."""
    carried: dict[str, float] = {}
    for link in reversed(robot.links):
        carried[link.name] = carried.get(link.name, 0.0) + float(link.inertia.mass)
        parent = link.parent or robot.base
        carried[parent] = carried.get(parent, 0.0) + carried[link.name]
    if all(carried[l.name] > 0 for l in robot.links if l.joint.is_moving):
        return robot
    links = []
    for link in robot.links:
        if link.joint.is_moving and carried[link.name] == 0:
            post = _np(link.post)
            length = max(float(np.linalg.norm(post[:3, 3])), 0.1)
            inv = _np(pose_inverse(post))
            centre = inv[:3, 3] / 2  # halfway between the joint and the link frame
            inertia = Inertia.cylinder(1.0, 0.04 * length, length, com=tuple(centre))
            link = Link(link.name, link.parent, link.joint, link.placement, link.post, inertia)
        links.append(link)
    return robot.replace(links=links)


# ---------------------------------------------------------------------------------------- URDF
def _origin(parent: ET.Element, T: np.ndarray) -> None:
    if _is_identity(T):
        return
    ET.SubElement(parent, "origin", xyz=_fs(T[:3, 3]), rpy=_fs(rpy_from_matrix(T[:3, :3])))


def _urdf_shape(parent: ET.Element, shape, written: str | None) -> None:
    g = ET.SubElement(parent, "geometry")
    if isinstance(shape, Box):
        ET.SubElement(g, "box", size=_fs(shape.size))
    elif isinstance(shape, Cylinder):
        ET.SubElement(g, "cylinder", radius=_f(shape.radius), length=_f(shape.length))
    elif isinstance(shape, Sphere):
        ET.SubElement(g, "sphere", radius=_f(shape.radius))
    else:
        attributes = {"filename": mesh_reference(shape, written)}  # relative to the file where it can be
        if tuple(shape.scale) != (1.0, 1.0, 1.0):
            attributes["scale"] = _fs(shape.scale)
        ET.SubElement(g, "mesh", attributes)


def _urdf_inertial(parent: ET.Element, inertia) -> None:
    m = float(inertia.mass)
    I = np.array(inertia.inertia, dtype=float)
    if m == 0.0 and not I.any():
        return
    el = ET.SubElement(parent, "inertial")
    com = [float(c) for c in inertia.com]
    if any(com):
        ET.SubElement(el, "origin", xyz=_fs(com), rpy="0 0 0")
    ET.SubElement(el, "mass", value=_f(m))
    ET.SubElement(
        el,
        "inertia",
        ixx=_f(I[0, 0]),
        ixy=_f(I[0, 1]),
        ixz=_f(I[0, 2]),
        iyy=_f(I[1, 1]),
        iyz=_f(I[1, 2]),
        izz=_f(I[2, 2]),
    )


def floating_trunk(robot: Robot):
    """The link a free-flyer carries when it is the robot's only link on the base, with identity
    placement and post and nothing else on the base (the shape ``from_urdf(path, floating_base=True)``
    gives a URDF's root), else None."""
    on_base = [l for l in robot.links if l.parent is None]
    if len(on_base) != 1 or on_base[0].joint.kind != "floating":
        return None
    link = on_base[0]
    if not (_is_identity(_np(link.placement)) and _is_identity(_np(link.post))):
        return None
    if (
        any(f.link is None for f in robot.frames)
        or any(v.frame == robot.base for v in (*robot.visuals, *robot.collisions))
        or any(robot.base in (lp.frame_a, lp.frame_b) for lp in robot.loops)
    ):
        return None
    return link


def to_urdf(
    robot: Robot, path: PathLike | None = None, *, geometry: bool = True, floating_base_as_root: bool = True
) -> str:
    """The robot as URDF text (written to ``path`` when given).

    Every link becomes a ``<link>`` (a link with a ``post`` transform becomes two, see the module
    docstring), the base the root link, every extra frame a massless link on a fixed joint.
    Joints: revolute (``continuous`` without position limits), prismatic, fixed, floating and
    planar (its ``axis`` the plane's normal); a spherical joint has no URDF type (ValueError).
    Joint offsets are folded into the origins. ``<dynamics damping friction>``: viscous and Coulomb
    friction (one level: a direction-dependent pair writes its positive level, with a warning);
    gear ratio and rotor inertia go into Drake's ``<transmission>`` extension (``drake:gear_ratio``,
    ``drake:rotor_inertia``) since URDF has no rotor inertia. Gravity is not part of URDF.
    ``geometry``: give a robot without visuals the cylinders of :func:`default_visuals`.
    ``floating_base_as_root``: a robot whose base carries only a free-flyer to one link (what
    ``Robot.from_urdf(path, floating_base=True)`` makes of a legged robot's URDF, see
    :func:`floating_trunk`) is written with that link as the URDF root and no floating joint, the
    usual form of such files, to be read back with ``floating_base=True``; otherwise (or with False)
    the base is the root and the free-flyer a URDF ``floating`` joint.
    A symbolic robot is refused: substitute numbers first (``robot.subs``)."""
    _require_numeric(robot, "to_urdf: URDF")
    for link in robot.links:
        if link.joint.kind == "spherical":
            raise ValueError(
                f"to_urdf: joint '{link.joint.name}' (link '{link.name}') is spherical, and URDF has no spherical joint type "
                "(write MJCF, whose ball joint holds it, or a robot file)"
            )
    visuals, collisions = _visuals_for_writing(robot, geometry)
    root = ET.Element("robot", name=robot.name)
    if any(float(l.joint.armature) != 0 for l in robot.links if l.joint.is_moving):
        root.set("xmlns:drake", DRAKE_NAMESPACE)
    taken = {robot.base} | {l.name for l in robot.links} | {f.name for f in robot.frames}
    link_elements: dict[str, ET.Element] = {}
    # where each named frame's geometry goes: (URDF link, pose of the named frame in that link)
    geometry_home: dict[str, tuple[str, np.ndarray]] = {}
    trunk = floating_trunk(robot) if floating_base_as_root else None
    links = list(robot.links)
    if trunk is None:
        geometry_home[robot.base] = (robot.base, np.eye(4))
        link_elements[robot.base] = ET.SubElement(root, "link", name=robot.base)
    else:  # the trunk is the URDF root; its free-flyer is what from_urdf(..., floating_base=True) adds back
        links.remove(trunk)
        link_elements[trunk.name] = ET.SubElement(root, "link", name=trunk.name)
        _urdf_inertial(link_elements[trunk.name], trunk.inertia)
        geometry_home[trunk.name] = (trunk.name, np.eye(4))
    joints: list[ET.Element] = []
    transmissions: list[ET.Element] = []
    joint_names = {l.joint.name for l in robot.links}

    def add_link(name: str) -> ET.Element:
        el = ET.Element("link", name=name)
        link_elements[name] = el
        return el

    def add_joint(name: str, kind: str, parent: str, child: str, origin: np.ndarray) -> ET.Element:
        el = ET.Element("joint", name=name, type=kind)
        _origin(el, origin)
        ET.SubElement(el, "parent", link=parent)
        ET.SubElement(el, "child", link=child)
        joints.append(el)
        return el

    for link in links:
        j = link.joint
        parent = link.parent or robot.base
        post = _np(link.post)
        # joint origin: placement · motion(offset) (the offset folded in: the module docstring)
        origin = _np(link.placement) @ _motion(j, float(j.offset))
        if not j.is_moving:
            add_link(link.name)
            _urdf_inertial(link_elements[link.name], link.inertia)
            add_joint(j.name, "fixed", parent, link.name, origin @ post)
            geometry_home[link.name] = (link.name, np.eye(4))
            continue
        split = not _is_identity(post)
        body = _unique(f"{link.name}_body", taken) if split else link.name
        add_link(body)
        _urdf_inertial(link_elements[body], link.inertia.transformed(post) if split else link.inertia)
        kind = {"revolute": "revolute", "prismatic": "prismatic", "floating": "floating", "planar": "planar"}[j.kind]
        if kind == "revolute" and not (math.isfinite(j.lower) or math.isfinite(j.upper)):
            kind = "continuous"
        el = add_joint(j.name, kind, parent, body, origin)
        if kind in ("revolute", "continuous", "prismatic", "planar"):
            ET.SubElement(el, "axis", xyz=_fs(float(a) for a in j.axis))
        if kind in ("revolute", "continuous", "prismatic"):
            limit: dict[str, str] = {}
            if kind != "continuous":
                limit["lower"] = _f(j.lower) if math.isfinite(j.lower) else _f(-1e9)
                limit["upper"] = _f(j.upper) if math.isfinite(j.upper) else _f(1e9)
            for key, v in (("effort", j.effort_limit), ("velocity", j.velocity_limit)):
                if math.isfinite(v):
                    limit[key] = _f(v)
            if limit:
                ET.SubElement(el, "limit", limit)
            viscous, coulomb = float(j.viscous), _coulomb(j, "URDF")
            if viscous or coulomb:
                ET.SubElement(el, "dynamics", damping=_f(viscous), friction=_f(coulomb))
            if j.mimic is not None:  # q = multiplier * q_leader + offset (docs/model-files.md, "Mimic joints")
                ET.SubElement(
                    el, "mimic", joint=j.mimic.leader, multiplier=_f(j.mimic.multiplier), offset=_f(j.mimic.offset)
                )
            if float(j.armature) != 0:
                tr = ET.Element("transmission", name=_unique(f"{j.name}_transmission", set(joint_names)))
                ET.SubElement(tr, "type").text = "transmission_interface/SimpleTransmission"
                ET.SubElement(
                    ET.SubElement(tr, "joint", name=j.name), "hardwareInterface"
                ).text = "hardware_interface/EffortJointInterface"
                actuator = ET.SubElement(tr, "actuator", name=f"{j.name}_motor")
                ET.SubElement(actuator, "mechanicalReduction").text = _f(j.gear_ratio)
                ET.SubElement(actuator, "drake:gear_ratio", value=_f(j.gear_ratio))
                ET.SubElement(actuator, "drake:rotor_inertia", value=_f(j.rotor_inertia))
                transmissions.append(tr)
        if split:
            add_link(link.name)
            add_joint(_unique(f"{link.name}_post", joint_names | taken), "fixed", body, link.name, post)
        geometry_home[link.name] = (link.name, np.eye(4))
    for frame in robot.frames:
        add_link(frame.name)
        add_joint(
            _unique(f"{frame.name}_joint", joint_names | taken),
            "fixed",
            frame.link or robot.base,
            frame.name,
            _np(frame.placement),
        )
        geometry_home[frame.name] = (frame.name, np.eye(4))

    for tag, items in (("visual", visuals), ("collision", collisions)):
        for k, v in enumerate(items):
            if v.frame not in geometry_home:
                raise ValueError(
                    f"to_urdf: a {tag} is attached to '{v.frame}', which is no link or frame of robot '{robot.name}'"
                )
            home, pose = geometry_home[v.frame]
            el = ET.SubElement(link_elements[home], tag)
            _origin(el, pose @ _np(v.origin))
            _urdf_shape(el, v.shape, None if path is None else os.fspath(path))
            if tag == "visual" and v.rgba is not None:
                material = ET.SubElement(el, "material", name=v.material or f"{v.frame}_color_{k}")
                ET.SubElement(material, "color", rgba=_fs(v.rgba))

    # links first, then joints, then transmissions (the order readers print them in)
    for el in link_elements.values():
        if el not in list(root):
            root.append(el)
    for el in joints + urdf_loop_elements(robot) + urdf_reference_element(robot) + transmissions:  # loop_files
        root.append(el)
    ET.indent(root)
    text = (
        '<?xml version="1.0"?>\n'
        + f"<!-- written by kinedyn from robot '{robot.name}' -->\n"
        + ET.tostring(root, encoding="unicode")
        + "\n"
    )
    if path is not None:
        write_text(os.fspath(path), text)  # atomic (kinedyn._ui.files)
    return text


# ---------------------------------------------------------------------------------------- MJCF
def _mj_pose(el: ET.Element, T: np.ndarray) -> None:
    if not np.allclose(T[:3, 3], 0.0, rtol=0.0, atol=0.0):
        el.set("pos", _fs(T[:3, 3]))
    if not np.allclose(T[:3, :3], np.eye(3), rtol=0.0, atol=1e-15):
        el.set("quat", _fs(quaternion_from_matrix(T[:3, :3])))


def to_mjcf(robot: Robot, path: PathLike | None = None, *, geometry: bool = True, default_inertia: bool = True) -> str:
    """The robot as MuJoCo XML (MJCF) text (written to ``path`` when given).

    Nested ``<body>`` elements, one per link and extra frame, each at its link frame; joints:
    revolute -> hinge, prismatic -> slide (with ``pos`` and ``axis`` in the body frame, so a link's
    ``post`` and joint offset need no extra body), floating -> free (top-level bodies only, as
    MuJoCo requires), spherical -> ball, planar (about z) -> two slides and a hinge; a mimic follower
    is a joint tied to its leader by an ``<equality><joint>`` (MuJoCo keeps its coordinate). ``<inertial>``
    with ``fullinertia`` about the centre of mass; armature = r² J_m, damping = viscous friction,
    frictionloss = Coulomb friction (one level); ``range`` from finite position limits;
    ``<option gravity>``. Geoms come from the visuals (``contype``/``conaffinity`` 0, group 1) and
    collisions (group 3); mesh files MuJoCo cannot read (``.dae``) are left out with a warning, and
    the others are written relative to ``path``'s folder when a path is given.
    ``<compiler inertiafromgeom="false">``: the inertials are the robot's, never the geoms'.
    ``geometry``: cylinders of :func:`default_visuals` for a robot without visuals;
    ``default_inertia``: MuJoCo refuses a moving body that carries no mass; a link whose whole
    subtree is massless gets 1 kg as a solid cylinder of its length (documented default; the
    dynamics then differ from the source's, which had none)."""
    _require_numeric(robot, "to_mjcf: MJCF")
    if default_inertia:
        robot = _default_inertias(robot)
    visuals, collisions = _visuals_for_writing(robot, geometry)
    root = ET.Element("mujoco", model=robot.name)
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    ET.SubElement(root, "option", gravity=_fs(float(g) for g in robot.gravity))
    asset = ET.Element("asset")
    world = ET.SubElement(root, "worldbody")
    bodies: dict[str, ET.Element] = {robot.base: world}
    names: set = set()
    for link in robot.links:
        j = link.joint
        parent = link.parent or robot.base
        post = _np(link.post)
        body = ET.SubElement(bodies[parent], "body", name=link.name)
        bodies[link.name] = body
        _mj_pose(body, _np(link.placement) @ _motion(j, float(j.offset)) @ post)
        inertia = link.inertia
        m = float(inertia.mass)
        if j.is_moving and m < MIN_MOMENT:  # MuJoCo refuses a moving body without mass (a rotor-only link)
            m = MIN_MOMENT
        if m > 0:
            I = np.array(inertia.inertia, dtype=float)
            a, b, c = np.linalg.eigvalsh(I)
            if a + b < c - 1e-12 * max(c, 1.0) or a < -1e-12 * max(c, 1.0):
                what = "rotational inertia without mass (a rotor), " if float(inertia.mass) == 0 else ""
                raise ValueError(
                    f"to_mjcf: link '{link.name}' has {what}principal moments ({a:.6g}, {b:.6g}, {c:.6g}) that no rigid body has "
                    f"({a:.6g} + {b:.6g} < {c:.6g}); MuJoCo refuses them: give the link a physical inertia first "
                    "(robot.replace(inertia='repair') projects massive ones; --inertia repair on the command line)"
                )
            el = ET.SubElement(body, "inertial", pos=_fs(float(c) for c in inertia.com), mass=_f(m))
            smallest = float(np.linalg.eigvalsh(I)[0])
            if smallest < MIN_MOMENT:  # MuJoCo needs positive principal moments (a thin rod has a zero one)
                I = I + (MIN_MOMENT - smallest) * np.eye(3)
            el.set("fullinertia", _fs([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]))
        if not j.is_moving:
            continue
        # the joint's axis line seen from the link frame: post^-1 (module docstring)
        inv = _np(pose_inverse(post))
        anchor, axis = inv[:3, 3], inv[:3, :3] @ np.array([float(a) for a in j.axis])
        drive = {}
        if float(j.armature):
            drive["armature"] = _f(j.armature)
        if float(j.viscous):
            drive["damping"] = _f(j.viscous)
        coulomb = _coulomb(j, "MJCF") if j.kind in ("revolute", "prismatic") else 0.0
        if coulomb:
            drive["frictionloss"] = _f(coulomb)
        if j.kind in ("revolute", "prismatic"):
            el = ET.SubElement(
                body,
                "joint",
                {"name": j.name, "type": "hinge" if j.kind == "revolute" else "slide", "axis": _fs(axis), **drive},
            )
            if np.any(anchor) and j.kind == "revolute":
                el.set("pos", _fs(anchor))
            if math.isfinite(j.lower) and math.isfinite(j.upper):
                el.set("range", _fs((j.lower, j.upper)))
            elif math.isfinite(j.lower) or math.isfinite(j.upper):
                warnings.warn(
                    f"MJCF limits a joint on both sides or none: joint '{j.name}' has limits [{j.lower}, {j.upper}]; writing none",
                    stacklevel=2,
                )
        elif j.kind == "floating":
            if link.parent is not None or not _is_identity(post) or not _is_identity(_np(link.placement)):
                raise ValueError(
                    f"to_mjcf: floating joint '{j.name}' (link '{link.name}'): MuJoCo's free joint moves a top-level body "
                    "from the world origin, so it must hang from the base with identity placement and post"
                )
            ET.SubElement(body, "freejoint", name=j.name)
        elif j.kind == "spherical":
            el = ET.SubElement(body, "joint", {"name": j.name, "type": "ball", **drive})
            if np.any(anchor):
                el.set("pos", _fs(anchor))
        else:  # planar
            if not np.allclose(axis, (0.0, 0.0, 1.0)) or not _is_identity(post):
                raise ValueError(
                    f"to_mjcf: planar joint '{j.name}': MJCF has no planar joint; kinedyn writes one about z "
                    "(two slides and a hinge) only for an axis (0, 0, 1) and no post transform"
                )
            for suffix, kind, ax in (("x", "slide", "1 0 0"), ("y", "slide", "0 1 0"), ("theta", "hinge", "0 0 1")):
                ET.SubElement(body, "joint", {"name": f"{j.name}_{suffix}", "type": kind, "axis": ax, **drive})
    loop_sites = mjcf_loop_sites(robot, {v.frame for v in (*visuals, *collisions)})
    for frame in robot.frames:
        if frame.name in loop_sites:  # a loop end: a site (write_mjcf_loops)
            continue
        body = ET.SubElement(bodies[frame.link or robot.base], "body", name=frame.name)
        bodies[frame.name] = body
        _mj_pose(body, _np(frame.placement))
    if robot.mimic_joints:
        # MuJoCo's joint equality (MJCF reference, equality/joint): y - y0 = a0 + a1 (x - x0) + ...,
        # y = joint1 (the follower), x = joint2 (the leader); both written with reference 0 (the
        # offsets are in the body poses), so polycoef = (offset, multiplier, 0, 0, 0)
        equality = ET.SubElement(root, "equality")
        for follower, relation in robot.mimic_joints.items():
            ET.SubElement(
                equality,
                "joint",
                joint1=follower,
                joint2=relation.leader,
                polycoef=_fs((float(relation.offset), float(relation.multiplier), 0.0, 0.0, 0.0)),
            )
    write_mjcf_loops(robot, root, bodies, loop_sites, _mj_pose)  # sites and <equality><connect|weld>
    for group, items in ((1, visuals), (3, collisions)):
        for _k, v in enumerate(items):
            if v.frame not in bodies:
                raise ValueError(
                    f"to_mjcf: a visual is attached to '{v.frame}', which is no link or frame of robot '{robot.name}'"
                )
            shape = v.shape
            geom = ET.Element("geom", contype="0", conaffinity="0", group=str(group))
            if isinstance(shape, Box):
                geom.set("type", "box")
                geom.set("size", _fs(s / 2 for s in shape.size))
            elif isinstance(shape, Cylinder):
                geom.set("type", "cylinder")
                geom.set("size", _fs((shape.radius, shape.length / 2)))
            elif isinstance(shape, Sphere):
                geom.set("type", "sphere")
                geom.set("size", _f(shape.radius))
            else:
                file = _mesh_file(shape)
                if os.path.splitext(file)[1].lower() not in (".stl", ".obj"):
                    warnings.warn(
                        f"MuJoCo reads STL and OBJ meshes, not '{file}' (on '{v.frame}'): left out of the MJCF",
                        stacklevel=2,
                    )
                    continue
                if file.startswith("package://"):
                    file = str(resolve_mesh(file, shape.base_dir))
                if path is not None and os.path.isabs(file):  # MuJoCo reads it relative to the MJCF's folder
                    file = _relative_to(file, os.fspath(path))
                mesh_name = _unique(f"{v.frame}_mesh", names)
                mesh = ET.SubElement(asset, "mesh", name=mesh_name, file=file)
                if tuple(shape.scale) != (1.0, 1.0, 1.0):
                    mesh.set("scale", _fs(shape.scale))
                geom.set("type", "mesh")
                geom.set("mesh", mesh_name)
            _mj_pose(geom, _np(v.origin))
            if v.rgba is not None:
                geom.set("rgba", _fs(v.rgba))
            bodies[v.frame].append(geom)
    if len(asset):
        root.insert(2, asset)
    ET.indent(root)
    text = f"<!-- written by kinedyn from robot '{robot.name}' -->\n" + ET.tostring(root, encoding="unicode") + "\n"
    if path is not None:
        write_text(os.fspath(path), text)  # atomic (kinedyn._ui.files)
    return text
