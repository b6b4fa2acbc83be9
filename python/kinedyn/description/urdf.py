"""URDF -> :class:`kinedyn.Robot`.

Reads the kinematic and inertial parts of a URDF (ROS wiki, "urdf/XML/joint" and "urdf/XML/link"):

- ``<joint type="revolute|continuous|prismatic|fixed">`` with ``<parent link>``, ``<child link>``,
  ``<origin xyz rpy>`` (the joint frame in the parent link's frame; rpy is fixed-axis
  roll-pitch-yaw, R = Rz(yaw) Ry(pitch) Rx(roll)), ``<axis xyz>`` (default ``1 0 0``, in the joint
  frame), ``<limit lower upper velocity effort>`` (lower/upper default 0 as in the URDF spec;
  a continuous joint has no position limits) and ``<dynamics damping friction>`` (-> viscous and
  Coulomb friction of the joint).
- ``<link><inertial>`` with ``<origin xyz rpy>`` (the centre-of-mass frame in the link frame),
  ``<mass value>`` and ``<inertia ixx ixy ixz iyy iyz izz>`` (about the centre of mass, in the
  centre-of-mass frame's axes; rotated here into the link frame). A link without ``<inertial>``
  is massless.

- ``<link><visual>`` and ``<link><collision>`` (-> ``robot.visuals`` and ``robot.collisions``, see
  :mod:`kinedyn.description.geometry`): ``<origin>``, ``<geometry>`` with one of ``<box size>``,
  ``<cylinder radius length>``, ``<sphere radius>``, ``<mesh filename scale>``, and for visuals
  ``<material name>`` with ``<color rgba>`` (inline, or defined by name at the robot level). Mesh files
  are not read here: they are found and read when the robot is drawn.

- ``<loop name type><link1 link xyz rpy/><link2 .../></loop>``: a closed loop, kinedyn's extension
  (:mod:`kinedyn.description.loop_files`; other URDF readers skip the element).

Ignored: ``<texture>``, ``<transmission>``, ``<gazebo>``, ``<calibration>``,
``<safety_controller>``.

What urdfdom (the reference reader, which Pinocchio and ROS use) accepts is loaded, and where the
file says something kinedyn cannot use, a warning names the file, line and element:

- a degenerate shape (a ``<sphere>``, ``<cylinder>`` or ``<box>`` with a size that is zero or
  negative, a ``<mesh>`` scaled by 0 on an axis) is no shape;
- ``<limit lower upper>`` with lower above upper (``lower="2"`` alone, upper defaulting to 0) gives
  the joint no position limits (kinedyn cannot honour an empty interval; ``kinedyn audit`` flags it);
- ``<mimic multiplier="0">`` leaves the joint independent, as Pinocchio's default reader does;
- a URDF whose joints are all fixed is a robot with no degrees of freedom (nq = 0) on a fixed base,
  as Pinocchio builds it, or a free-flying body with ``floating_base=True``.

A zero joint axis is refused (MuJoCo refuses it too: the joint would move nothing).

- ``<joint><mimic joint multiplier offset>`` (multiplier default 1, offset 0): the joint follows
  ``joint`` with ``q = multiplier * q_joint + offset`` (-> ``Joint.mimic``). ``mimic="reduce"``
  (default) removes the followers' coordinates (as Pinocchio 3's ``buildModelFromUrdf(path,
  mimic=True)``); ``mimic="independent"`` keeps each a coordinate of its own (Pinocchio's default,
  and kinedyn's before mimic support), see :mod:`kinedyn.description.mimic`.

The robot has a fixed base: the root link (the one link that is no joint's child) is the Robot's
``base`` and its inertia is ignored. Joints are numbered in depth-first order from the root,
children in the order their joints appear in the file; every URDF link becomes a named frame.
"""

from __future__ import annotations

import importlib
import math
import os
import re
import warnings

import numpy as np

from .._math import matmul, rpy_to_matrix, translation
from .._ui.files import open_regular
from .bounded_xml import parse_bounded
from .checks import LARGEST, caller_level
from .description import Description
from .geometry import Box, Cylinder, Mesh, Sphere, Visual
from .inertia import Inertia, PhysicalConsistencyWarning
from .joint import Joint, Mimic
from .link import Link
from .loop_files import urdf_loops, urdf_reference
from .tool import default_tool
from .xacro import expand_xacro, is_xacro

__all__ = ["description_from_urdf", "read_urdf_xml", "MAX_DEPTH"]

_SUPPORTED = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
#: the name Pinocchio gives the free-flyer joint that ``floating_base=True`` adds above the root link
ROOT_JOINT = "root_joint"
#: the fixed frame a floating base moves in (Pinocchio's name for it)
FLOATING_BASE_FRAME = "universe"
MAX_FILE_BYTES = 16 * 2**20  # a URDF is text a person (or xacro) writes: read no more (docs/model-files.md)
MAX_DEPTH = 100  # deepest element nesting accepted (a URDF needs about 6; guards the parser's memory)


def description_from_urdf(
    path_or_string,
    *,
    gravity=(0.0, 0.0, -9.81),
    tool: str | None = None,
    inertia: str = "warn",
    floating_base: bool = False,
    source_path: str | None = None,
    mimic: str = "reduce",
    xacro_args=None,
    trust_xacro: bool = False,
    package_dirs=(),
) -> Description:
    """The :class:`~kinedyn.description.description.Description` of a URDF file path or an XML
    string (``kinedyn.Robot.from_urdf`` builds the robot from it).

    A string holding ``<`` or a line break is parsed as XML, anything else is a path.
    ``gravity``: the gravity vector in base (root link) coordinates. ``tool``: the name of the frame
    used as ``robot.tool``; by default a link the file names as its tool (``tool0`` of a UR arm,
    ``panda_hand_tcp`` of the Panda), else the end of the longest chain
    (:func:`kinedyn.description.tool.default_tool`). The root link's inertia is ignored (fixed base).
    ``floating_base=True``: the root link moves freely instead, on a free-flyer joint named
    ``root_joint`` from the fixed frame ``universe`` (Pinocchio's ``JointModelFreeFlyer`` root: q starts
    with the root's position and unit quaternion (x, y, z, w), v with its [linear; angular] velocity
    in its own frame); a URDF without any moving joint (a drone) loads this way.
    ``inertia``: the policy for an inertia no rigid body can have, ``"warn"`` (default), ``"repair"``
    or ``"strict"`` (see :func:`kinedyn.description.inertia.judge` and docs/model-files.md).

    Every problem with the file is a ValueError naming the file, the line, and the link, joint or
    attribute. ``source_path``: the file an XML string was made from (a xacro file): it names the
    source in messages and its folder is where relative mesh paths start. The XML may not declare entities (no DOCTYPE with an internal subset or an external
    DTD: entity expansion is unbounded work) nor nest elements deeper than ``MAX_DEPTH``; the work is
    linear in the size of the file.

    A path ending in ``.xacro`` is expanded by the ``xacro`` package first, with ``xacro_args``
    (its ``<xacro:arg>`` values) and ``package_dirs`` (where ``$(find PKG)`` looks); xacro runs
    Python expressions from the file, so it needs ``trust_xacro=True`` (:mod:`kinedyn.description.xacro`).
    """
    if is_xacro(path_or_string):
        text = expand_xacro(path_or_string, xacro_args, trust_xacro=trust_xacro, package_dirs=package_dirs)
        return description_from_urdf(
            text,
            gravity=gravity,
            tool=tool,
            inertia=inertia,
            floating_base=floating_base,
            source_path=os.fsdecode(path_or_string),
            mimic=mimic,
        )
    if xacro_args:
        raise ValueError("xacro_args are for a .xacro file")
    src, root = _parse(path_or_string, source_path)
    if root.tag != "robot":
        raise src.error(root, f"the root element is <{root.tag}>, expected <robot>")
    link_elements = _links(root, src)
    joints = [_joint(j, src) for j in root.iterfind("joint")]
    base, ordered = _order(joints, list(link_elements), src)
    links = []
    if floating_base:
        if FLOATING_BASE_FRAME in link_elements:
            raise ValueError(
                f"{src.label}: floating_base=True names the fixed frame '{FLOATING_BASE_FRAME}', "
                f"but the URDF has a link of that name"
            )
        links.append(
            Link(base, None, Joint(ROOT_JOINT, "floating"), np.eye(4), inertia=_inertial(link_elements[base], src))
        )
        base = FLOATING_BASE_FRAME
    for j in ordered:
        element = link_elements[j["child"]]
        body = _inertial(element, src)
        try:
            links.append(Link(j["child"], j["parent"], j["joint"], j["placement"], inertia=body))
        except ValueError as e:
            raise src.error(j["element"], str(e)) from None
    if tool is None:
        tool = default_tool(links, base)
    name = root.get("name") or "urdf_robot"
    source = src.label if not src.label.startswith("<") else "URDF string"
    visuals, collisions = _geometry(root, list(link_elements.items()), src)
    loop_frames, loops = urdf_loops(root, src, list(link_elements), _floats)  # kinedyn's <loop> extension
    moving = {link.joint.name: link.joint.nq for link in links if link.joint.is_moving}
    reference = urdf_reference(root, src, moving, _floats)  # and its <reference_configuration> (loop_files)
    for note in src.notes:
        warnings.warn(note, UserWarning, stacklevel=caller_level())
    # the Description judges the inertias (policy) and checks the tree: its errors and warnings name a
    # link or joint, to which the file and line are added here, once
    lines = {
        **{n: src.line(e) for n, e in link_elements.items()},
        **{j["name"]: src.line(j["element"]) for j in joints},
    }
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", PhysicalConsistencyWarning)
            description = Description(
                tuple(links),
                tuple(loop_frames),
                gravity=gravity,
                base=base,
                tool=tool,
                name=name,
                source=source,
                inertia=inertia,
                visuals=visuals,
                collisions=collisions,
                mimic=mimic,
                loops=tuple(loops),
                reference_configuration=reference,
            )
    except ValueError as e:
        raise ValueError(f"{src.at(_line_of(str(e), lines))}: {e}") from None
    for w in caught:
        message = str(w.message)
        if issubclass(w.category, PhysicalConsistencyWarning):
            message = f"{src.at(_line_of(message, lines))}: {message}"
        warnings.warn(message, w.category, stacklevel=caller_level())
    return description


def _line_of(message: str, lines: dict) -> int | None:
    """The line of the link or joint a description-layer message starts with ("link 'x': ...")."""
    match = re.match(r"(?:link|joint) '([^']*)'", message)
    return lines.get(match.group(1)) if match else None


# ---------------------------------------------------------------------------------------- parsing
class _Source:
    """Where the XML came from (a path or "<URDF string>") and the line of each element."""

    def __init__(self, label: str):
        self.label = label
        self.lines: dict = {}  # id(element) -> line of its start tag
        self.notes: list = []  # "file:line: what was read differently" (warned once the file is read)

    def note(self, element, message: str) -> None:
        self.notes.append(f"{self.at(self.line(element))}: {message}")

    def line(self, element) -> int | None:
        return self.lines.get(id(element))

    def at(self, line: int | None) -> str:
        return self.label if line is None else f"{self.label}:{line}"

    def error(self, element, message: str) -> ValueError:
        return ValueError(f"{self.at(self.line(element))}: {message}")


def read_urdf_xml(path_or_string, source_path: str | None = None):
    """(source, root element) of a URDF's XML, read as the loader reads it (bounded, no entities),
    for readers of the raw file (:mod:`kinedyn.description.audit`): ``source.label`` is the file,
    ``source.at(source.line(element))`` the "file:line" of an element."""
    return _parse(path_or_string, source_path)


def _parse(path_or_string, source_path: str | None = None):
    """(source, root element): the XML parsed by expat with line numbers, no entity declarations
    (billion laughs, external entities) and a bounded nesting depth."""
    text = os.fspath(path_or_string) if isinstance(path_or_string, os.PathLike) else path_or_string
    if isinstance(text, bytes):
        text = text.decode("utf-8", errors="replace") if b"<" in text or b"\n" in text else os.fsdecode(text)
    if not isinstance(text, str):
        raise TypeError(f"a URDF reader expects a path or an XML string, got {type(path_or_string).__name__}")
    data: str | bytes
    if "<" in text or "\n" in text:  # XML (perhaps malformed), never a file name
        src, data = _Source(os.fspath(source_path) if source_path is not None else "<URDF string>"), text
    else:
        src = _Source(text)
        try:
            with open_regular(text, "URDF file") as f:  # a FIFO or a device: refused, never waited on
                data = f.read(MAX_FILE_BYTES + 1)  # bytes: expat honours the file's encoding declaration
            if len(data) > MAX_FILE_BYTES:
                raise ValueError(f"{text}: the file is larger than {MAX_FILE_BYTES // 2**20} MiB, too large for a URDF")
        except OSError as e:
            raise ValueError(f"{text}: cannot read URDF file ({e.strerror or e})") from None

    def record(element, line):
        src.lines[id(element)] = line

    return src, parse_bounded(data, src.label, "a URDF", MAX_DEPTH, record)


def _floats(text: str | None, n: int, default, what: str, element, src: _Source) -> tuple:
    if text is None:
        return tuple(default)
    parts = text.split()
    try:
        values = tuple(float(v) for v in parts)
    except ValueError:
        raise src.error(element, f"{what} must be {n} numbers, got '{_short(text)}'") from None
    if len(values) != n:
        raise src.error(element, f"{what} must be {n} numbers, got {len(values)}: '{_short(text)}'")
    for v in values:
        if not math.isfinite(v):
            raise src.error(element, f"{what} must be {n} finite numbers, got '{_short(text)}'")
        if abs(v) > LARGEST:
            raise src.error(
                element, f"{what} has {v:g}, larger in magnitude than {LARGEST:g}, the most a description number may be"
            )
    return values


def _short(text: str) -> str:
    return text if len(text) <= 60 else text[:57] + "..."


def _float(element, attribute: str, default, what: str, src: _Source) -> float:
    text = element.get(attribute)
    if text is None:
        if default is None:
            raise src.error(element, f"{what} has no '{attribute}' attribute")
        return default
    return _floats(text, 1, (), f"{what} attribute '{attribute}'", element, src)[0]


def _origin(element, what: str, src: _Source):
    """The pose of an ``<origin xyz rpy>`` child (identity when absent)."""
    origin = element.find("origin")
    if origin is None:
        return translation(0.0, 0.0, 0.0)
    xyz = _floats(origin.get("xyz"), 3, (0, 0, 0), f"{what} origin xyz", origin, src)
    rpy = _floats(origin.get("rpy"), 3, (0, 0, 0), f"{what} origin rpy", origin, src)
    return matmul(translation(*xyz), rpy_to_matrix(*rpy))


def _links(root, src: _Source) -> dict:
    """Link elements by name, in document order."""
    links: dict = {}
    for element in root.iterfind("link"):
        name = element.get("name")
        if not name:
            raise src.error(element, "a <link> has no name")
        if name in links:
            raise src.error(element, f"link '{name}' is defined twice (first at line {src.line(links[name])})")
        links[name] = element
    if not links:
        raise src.error(root, "the URDF has no <link>")
    return links


def _joint(element, src: _Source) -> dict:
    """One ``<joint>`` as {name, parent, child, placement, joint, element}."""
    name = element.get("name")
    if not name:
        raise src.error(element, "a <joint> has no name")
    kind = element.get("type")
    what = f"joint '{name}'"
    if kind is None:
        raise src.error(element, f"{what} has no type attribute (supported: {', '.join(_SUPPORTED)})")
    if kind not in _SUPPORTED:
        raise src.error(
            element,
            f"{what} has type '{kind}', which is not supported (supported: {', '.join(_SUPPORTED)})",
        )
    ends = {}
    for end in ("parent", "child"):
        e = element.find(end)
        if e is None or not e.get("link"):
            raise src.error(element, f"{what} has no <{end} link=...>")
        ends[end] = e.get("link")
    axis = (1.0, 0.0, 0.0)
    axis_element = element.find("axis")
    if axis_element is not None:
        axis = _floats(axis_element.get("xyz"), 3, axis, f"{what} axis", axis_element, src)
    # a floating or planar joint has no scalar limits or friction (its <limit>/<dynamics> are ignored)
    multi = kind in ("floating", "planar")
    limits = {} if multi else _limits(element.find("limit"), kind, what, src)
    friction = {} if multi else _dynamics(element.find("dynamics"), what, src)
    # a fixed joint has no coordinate to follow with: its <mimic> is ignored (Talos's talos_left_arm.urdf has one)
    mimic = _mimic(element.find("mimic"), what, src) if kind != "fixed" else None
    try:
        joint = Joint(name, "revolute" if kind == "continuous" else kind, axis, **limits, **friction, mimic=mimic)
    except ValueError as e:
        raise src.error(element, str(e)) from None
    return {"name": name, **ends, "placement": _origin(element, what, src), "joint": joint, "element": element}


def _mimic(element, what: str, src: _Source) -> Mimic | None:
    """``<mimic joint multiplier offset>`` (URDF defaults: multiplier 1, offset 0), or None."""
    if element is None:
        return None
    leader = element.get("joint")
    if not leader:
        raise src.error(element, f"{what}: <mimic> has no joint attribute (the joint it follows)")
    multiplier, offset = (
        _float(element, "multiplier", 1.0, f"{what} <mimic>", src),
        _float(element, "offset", 0.0, f"{what} <mimic>", src),
    )
    if multiplier == 0:
        # a follower with multiplier 0 would be locked at the offset; urdfdom accepts it and
        # Pinocchio's default reader keeps the joint a coordinate of its own, as kinedyn does here
        src.note(element, f"{what}: <mimic> multiplier 0 follows nothing: the joint is read as an independent joint")
        return None
    try:
        return Mimic(leader, multiplier, offset)
    except ValueError as e:
        raise src.error(element, f"{what}: {e}") from None


def _limits(limit, kind: str, what: str, src: _Source) -> dict:
    if limit is None or kind == "fixed":
        return {}
    out = {
        "velocity_limit": _float(limit, "velocity", math.inf, f"{what} <limit>", src),
        "effort_limit": _float(limit, "effort", math.inf, f"{what} <limit>", src),
    }
    if kind != "continuous":
        lower = _float(limit, "lower", 0.0, f"{what} <limit>", src)
        upper = _float(limit, "upper", 0.0, f"{what} <limit>", src)
        if lower > upper:
            # urdfdom and Pinocchio keep the empty interval; no position satisfies it, so kinedyn
            # reads no position limits (URDF spec: an absent lower or upper is 0)
            src.note(
                limit,
                f"{what}: <limit> lower {lower:g} is above upper {upper:g} (an absent one is 0): "
                "the joint is read without position limits",
            )
        else:
            out["lower"], out["upper"] = lower, upper
    return out


def _dynamics(dynamics, what: str, src: _Source) -> dict:
    if dynamics is None:
        return {}
    return {
        "viscous": _float(dynamics, "damping", 0.0, f"{what} <dynamics>", src),
        "coulomb": _float(dynamics, "friction", 0.0, f"{what} <dynamics>", src),
    }


def _inertial(link, src: _Source) -> Inertia:
    """The link's inertia in the link frame (massless when there is no ``<inertial>``)."""
    inertial = link.find("inertial")
    if inertial is None:
        return Inertia()
    what = f"link '{link.get('name')}' <inertial>"
    mass_el, tensor_el = inertial.find("mass"), inertial.find("inertia")
    mass = 0.0 if mass_el is None else _float(mass_el, "value", None, f"{what} <mass>", src)
    keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    entries = [0.0] * 6 if tensor_el is None else [_float(tensor_el, k, 0.0, f"{what} <inertia>", src) for k in keys]
    # the tensor is given in the centre-of-mass frame <origin xyz rpy>: rotate/shift into the link
    com_frame = _origin(inertial, what, src)
    try:
        return Inertia.from_urdf(mass, *entries).transformed(com_frame)
    except ValueError as e:
        raise src.error(inertial, f"{what}: {e}") from None


# ------------------------------------------------------------------------------------ geometry
MAX_MESH_NAME = 4096  # characters of a mesh file name


def _rgba(element, what: str, src: _Source) -> tuple:
    rgba = _floats(element.get("rgba"), 4, (), f"{what} <color> rgba", element, src)
    if not rgba or any(not 0.0 <= c <= 1.0 for c in rgba):
        raise src.error(
            element, f"{what} <color> rgba must be 4 numbers between 0 and 1, got '{_short(element.get('rgba') or '')}'"
        )
    return rgba


def _materials(root, src: _Source) -> dict:
    """Colours of the materials defined at the robot level, by name."""
    out: dict = {}
    for m in root.iterfind("material"):
        name = m.get("name")
        color = m.find("color")
        if name and color is not None:
            out[name] = _rgba(color, f"material '{name}'", src)
    return out


def _degenerate(child, what: str, src: _Source, detail: str) -> None:
    """A shape with no volume: urdfdom (and so Pinocchio and ROS) accepts it (ARMAR-4 ships a
    ``<sphere radius="0"/>``); kinedyn keeps no shape for it and says so."""
    src.note(child, f"{what} <{child.tag}> is degenerate ({detail}): no shape is kept for it")


def _shape(geometry, what: str, src: _Source, base_dir):
    """The shape ``<geometry>`` holds, or None for a degenerate one (noted)."""
    for child in geometry:
        tag = child.tag
        if tag == "box":
            size = _floats(child.get("size") or "", 3, (), f"{what} <box> size", child, src)
            if any(v <= 0 for v in size):
                _degenerate(child, what, src, f"size '{_short(child.get('size') or '')}' is not 3 positive numbers")
                return None
            return Box(size)
        if tag == "cylinder":
            radius = _float(child, "radius", None, f"{what} <cylinder>", src)
            length = _float(child, "length", None, f"{what} <cylinder>", src)
            if radius <= 0 or length <= 0:
                _degenerate(child, what, src, f"radius {radius:g} and length {length:g} are not both positive")
                return None
            return Cylinder(radius, length)
        if tag == "sphere":
            radius = _float(child, "radius", None, f"{what} <sphere>", src)
            if radius <= 0:
                _degenerate(child, what, src, f"radius {radius:g} is not positive")
                return None
            return Sphere(radius)
        if tag == "mesh":
            filename = child.get("filename")
            if not filename or len(filename) > MAX_MESH_NAME:
                raise src.error(child, f"{what} <mesh> needs a filename (of at most {MAX_MESH_NAME} characters)")
            scale = _floats(child.get("scale"), 3, (1.0, 1.0, 1.0), f"{what} <mesh> scale", child, src)
            if any(v == 0 for v in scale):
                _degenerate(child, what, src, f"scale '{_short(child.get('scale') or '')}' holds 0")
                return None
            return Mesh(filename, scale, base_dir)
    raise src.error(geometry, f"{what} <geometry> holds none of <box>, <cylinder>, <sphere>, <mesh>")


def _geometry(root, links: list, src: _Source) -> tuple:
    """(visuals, collisions) of every link, in file order."""
    materials = _materials(root, src)
    base_dir = None if src.label.startswith("<") else os.path.dirname(os.path.abspath(src.label))
    visuals: list = []
    collisions: list = []
    for link_name, element in links:
        for kind, out in (("visual", visuals), ("collision", collisions)):
            for k, item in enumerate(element.iterfind(kind)):
                what = f"link '{link_name}' <{kind}>" + (f" {k + 1}" if k else "")
                geometry = item.find("geometry")
                if geometry is None:
                    raise src.error(item, f"{what} has no <geometry>")
                shape = _shape(geometry, what, src, base_dir)
                if shape is None:
                    continue
                rgba, material = None, None
                m = item.find("material") if kind == "visual" else None
                if m is not None:
                    material = m.get("name")
                    color = m.find("color")
                    if color is not None:
                        rgba = _rgba(color, f"{what} <material>", src)
                    elif material in materials:
                        rgba = materials[material]
                out.append(
                    Visual(
                        link_name,
                        shape,
                        np.asarray(_origin(item, what, src), dtype=float),
                        rgba,
                        material,
                        src.at(src.line(item)),
                    )
                )
    return visuals, collisions


# --------------------------------------------------------------------------------- tree structure
def _order(joints: list, link_names: list, src: _Source):
    """(root link, joints in depth-first order with children in file order); checks the tree."""
    known = set(link_names)
    parent_joint: dict = {}
    children: dict = {name: [] for name in link_names}
    names: dict = {}
    for j in joints:
        if j["name"] in names:
            raise src.error(
                j["element"], f"joint '{j['name']}' is defined twice (first at line {src.line(names[j['name']])})"
            )
        names[j["name"]] = j["element"]
        for end in ("parent", "child"):
            if j[end] not in known:
                raise src.error(j["element"], f"joint '{j['name']}' names {end} link '{j[end]}', which is not defined")
        if j["child"] in parent_joint:
            raise src.error(
                j["element"],
                f"link '{j['child']}' is the child of two joints, '{parent_joint[j['child']]['name']}' "
                f"and '{j['name']}' (a URDF must be a tree)",
            )
        parent_joint[j["child"]] = j
        children[j["parent"]].append(j)
    roots = [name for name in link_names if name not in parent_joint]
    if len(roots) > 1:
        shown = roots if len(roots) <= 10 else roots[:10] + [f"... {len(roots) - 10} more"]
        raise ValueError(f"{src.label}: the URDF has several root links {shown}; connect them with joints to one root")
    if not roots:
        raise ValueError(f"{src.label}: the URDF has no root link: its joints form a cycle ({_cycle(parent_joint)})")
    ordered = []
    stack = list(reversed(children[roots[0]]))
    while stack:
        j = stack.pop()
        ordered.append(j)
        stack.extend(reversed(children[j["child"]]))
    if len(ordered) != len(joints):
        reached = {j["name"] for j in ordered}
        cyclic = [j["name"] for j in joints if j["name"] not in reached]
        shown = cyclic if len(cyclic) <= 10 else cyclic[:10] + [f"... {len(cyclic) - 10} more"]
        raise ValueError(f"{src.label}: joints {shown} form a cycle not connected to the root link '{roots[0]}'")
    return roots[0], ordered


def _cycle(parent_joint: dict) -> str:
    """A readable cycle 'a <- b <- a' by following parents from any link (linear time)."""
    link = next(iter(parent_joint))
    path, position = [link], {link: 0}
    while True:
        link = parent_joint[link]["parent"]
        if link in position:
            cycle = path[position[link] :] + [link]
            if len(cycle) > 12:
                cycle = cycle[:5] + [f"... {len(cycle) - 10} more ..."] + cycle[-5:]
            return " <- ".join(cycle)
        position[link] = len(path)
        path.append(link)


def __getattr__(name: str):
    # robot_from_urdf built a Robot from this layer; it lives above the description now
    # (kinedyn.robot_files), loaded by name so that the description never imports the facade
    if name == "robot_from_urdf":
        warnings.warn(
            "kinedyn.description.urdf.robot_from_urdf moved: use kinedyn.Robot.from_urdf "
            "(or description_from_urdf for the description alone)",
            DeprecationWarning,
            stacklevel=2,
        )
        return importlib.import_module("kinedyn.robot_files").robot_from_urdf
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
