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

Ignored: ``<visual>``, ``<collision>``, meshes, ``<transmission>``, ``<gazebo>``, ``<calibration>``,
``<safety_controller>``; ``<mimic>`` is ignored too, so a mimic joint becomes an independent
coordinate (as Pinocchio's ``buildModelFromUrdf`` does by default). Floating and planar joints are
rejected.

The robot has a fixed base: the root link (the one link that is no joint's child) is the Robot's
``base`` and its inertia is ignored. Joints are numbered in depth-first order from the root,
children in the order their joints appear in the file; every URDF link becomes a named frame.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from typing import Optional

from .._math import matmul, rpy_to_matrix, translation
from .inertia import Inertia
from .joint import Joint
from .link import Link

__all__ = ["robot_from_urdf"]

_SUPPORTED = ("revolute", "continuous", "prismatic", "fixed")


def robot_from_urdf(path_or_string, *, gravity=(0.0, 0.0, -9.81), tool: Optional[str] = None):
    """A :class:`kinedyn.Robot` from a URDF file path or an XML string.

    A string whose first non-blank character is ``<`` is parsed as XML, anything else is a path.
    ``gravity``: the gravity vector in base (root link) coordinates. ``tool``: the name of the frame
    used as ``robot.tool``; by default the last link, in depth-first order, that moves with the last
    joint (e.g. ``tool0`` of a UR arm). The root link's inertia is ignored (fixed base).
    """
    from ..robot import Robot

    root, where = _parse(path_or_string)
    if root.tag != "robot":
        raise ValueError(f"{where}: the root element is <{root.tag}>, expected <robot>")
    link_elements = _links(root, where)
    joints = [_joint(j, where) for j in root.findall("joint")]
    base, ordered = _order(joints, list(link_elements), where)
    links = [
        Link(j["child"], j["parent"], j["joint"], j["placement"], inertia=_inertial(link_elements[j["child"]], where))
        for j in ordered
    ]
    if tool is None:
        tool = _default_tool(links, base)
    name = root.get("name") or "urdf_robot"
    source = where if not where.startswith("<") else "URDF string"
    return Robot(links, gravity=gravity, base=base, tool=tool, name=name, source=source)


# ---------------------------------------------------------------------------------------- parsing
def _parse(path_or_string):
    """(root element, a description of where it came from for error messages)."""
    text = os.fspath(path_or_string) if isinstance(path_or_string, os.PathLike) else path_or_string
    if isinstance(text, bytes):
        text = text.decode()
    if not isinstance(text, str):
        raise TypeError(f"robot_from_urdf expects a path or an XML string, got {type(path_or_string).__name__}")
    if text.lstrip().startswith("<"):
        where, xml = "<URDF string>", text
    else:
        where = text
        try:
            with open(text, encoding="utf-8") as f:
                xml = f.read()
        except OSError as e:
            raise ValueError(f"{where}: cannot read URDF file ({e.strerror or e})") from None
    try:
        return ET.fromstring(xml), where
    except ET.ParseError as e:
        line, column = e.position
        raise ValueError(f"{where}: malformed XML at line {line}, column {column + 1}: {e}") from None


def _floats(text: Optional[str], n: int, default, what: str, where: str) -> tuple:
    if text is None:
        return tuple(default)
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        raise ValueError(f"{where}: {what} must be {n} numbers, got '{text}'") from None
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{where}: {what} must be {n} finite numbers, got '{text}'")
    return values


def _float(element, attribute: str, default, what: str, where: str) -> float:
    text = element.get(attribute)
    if text is None:
        if default is None:
            raise ValueError(f"{where}: {what} has no '{attribute}' attribute")
        return default
    return _floats(text, 1, (), f"{what} attribute '{attribute}'", where)[0]


def _origin(element, what: str, where: str):
    """The pose of an ``<origin xyz rpy>`` child (identity when absent)."""
    origin = element.find("origin")
    if origin is None:
        return translation(0.0, 0.0, 0.0)
    xyz = _floats(origin.get("xyz"), 3, (0, 0, 0), f"{what} origin xyz", where)
    rpy = _floats(origin.get("rpy"), 3, (0, 0, 0), f"{what} origin rpy", where)
    return matmul(translation(*xyz), rpy_to_matrix(*rpy))


def _links(root, where: str) -> dict:
    """Link elements by name, in document order."""
    links: dict = {}
    for element in root.findall("link"):
        name = element.get("name")
        if not name:
            raise ValueError(f"{where}: a <link> has no name")
        if name in links:
            raise ValueError(f"{where}: link '{name}' is defined twice")
        links[name] = element
    if not links:
        raise ValueError(f"{where}: the URDF has no <link>")
    return links


def _joint(element, where: str) -> dict:
    """One ``<joint>`` as {name, parent, child, placement, joint}."""
    name = element.get("name")
    if not name:
        raise ValueError(f"{where}: a <joint> has no name")
    kind = element.get("type")
    what = f"joint '{name}'"
    if kind not in _SUPPORTED:
        raise ValueError(
            f"{where}: {what} has type '{kind}', which is not supported "
            f"(supported: {', '.join(_SUPPORTED)}; kinedyn robots have a fixed base and 1-DOF joints)"
        )
    ends = {}
    for end in ("parent", "child"):
        e = element.find(end)
        if e is None or not e.get("link"):
            raise ValueError(f"{where}: {what} has no <{end} link=...>")
        ends[end] = e.get("link")
    axis = (1.0, 0.0, 0.0)
    if element.find("axis") is not None:
        axis = _floats(element.find("axis").get("xyz"), 3, axis, f"{what} axis", where)
    limits = _limits(element.find("limit"), kind, what, where)
    friction = _dynamics(element.find("dynamics"), what, where)
    try:
        joint = Joint(name, "revolute" if kind == "continuous" else kind, axis, **limits, **friction)
    except ValueError as e:
        raise ValueError(f"{where}: {e}") from None
    return {"name": name, **ends, "placement": _origin(element, what, where), "joint": joint}


def _limits(limit, kind: str, what: str, where: str) -> dict:
    if limit is None or kind == "fixed":
        return {}
    out = {
        "velocity_limit": _float(limit, "velocity", math.inf, f"{what} <limit>", where),
        "effort_limit": _float(limit, "effort", math.inf, f"{what} <limit>", where),
    }
    if kind != "continuous":
        out["lower"] = _float(limit, "lower", 0.0, f"{what} <limit>", where)
        out["upper"] = _float(limit, "upper", 0.0, f"{what} <limit>", where)
    return out


def _dynamics(dynamics, what: str, where: str) -> dict:
    if dynamics is None:
        return {}
    return {
        "viscous": _float(dynamics, "damping", 0.0, f"{what} <dynamics>", where),
        "coulomb": _float(dynamics, "friction", 0.0, f"{what} <dynamics>", where),
    }


def _inertial(link, where: str) -> Inertia:
    """The link's inertia in the link frame (massless when there is no ``<inertial>``)."""
    inertial = link.find("inertial")
    if inertial is None:
        return Inertia()
    what = f"link '{link.get('name')}' <inertial>"
    mass_el, tensor_el = inertial.find("mass"), inertial.find("inertia")
    mass = 0.0 if mass_el is None else _float(mass_el, "value", None, f"{what} <mass>", where)
    keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    entries = [0.0] * 6 if tensor_el is None else [_float(tensor_el, k, 0.0, f"{what} <inertia>", where) for k in keys]
    try:
        about_com = Inertia.from_urdf(mass, *entries)
        # the tensor is given in the centre-of-mass frame <origin xyz rpy>: rotate/shift into the link
        return about_com.transformed(_origin(inertial, what, where))
    except ValueError as e:
        raise ValueError(f"{where}: {what}: {e}") from None


# --------------------------------------------------------------------------------- tree structure
def _order(joints: list, link_names: list, where: str):
    """(root link, joints in depth-first order with children in file order); checks the tree."""
    known = set(link_names)
    parent_joint: dict = {}
    children: dict = {name: [] for name in link_names}
    names = set()
    for j in joints:
        if j["name"] in names:
            raise ValueError(f"{where}: joint '{j['name']}' is defined twice")
        names.add(j["name"])
        for end in ("parent", "child"):
            if j[end] not in known:
                raise ValueError(f"{where}: joint '{j['name']}' names {end} link '{j[end]}', which is not defined")
        if j["child"] in parent_joint:
            raise ValueError(
                f"{where}: link '{j['child']}' is the child of two joints, '{parent_joint[j['child']]['name']}' "
                f"and '{j['name']}' (a URDF must be a tree)"
            )
        parent_joint[j["child"]] = j
        children[j["parent"]].append(j)
    roots = [name for name in link_names if name not in parent_joint]
    if len(roots) > 1:
        raise ValueError(f"{where}: the URDF has several root links {roots}; connect them with joints to one root")
    if not roots:
        raise ValueError(f"{where}: the URDF has no root link: its joints form a cycle ({_cycle(parent_joint)})")
    ordered = []
    stack = list(reversed(children[roots[0]]))
    while stack:
        j = stack.pop()
        ordered.append(j)
        stack.extend(reversed(children[j["child"]]))
    if len(ordered) != len(joints):
        reached = {j["name"] for j in ordered}
        cyclic = [j["name"] for j in joints if j["name"] not in reached]
        raise ValueError(f"{where}: joints {cyclic} form a cycle not connected to the root link '{roots[0]}'")
    return roots[0], ordered


def _cycle(parent_joint: dict) -> str:
    """A readable cycle 'a -> b -> a' by following parents from any link."""
    link = next(iter(parent_joint))
    path = [link]
    while True:
        link = parent_joint[link]["parent"]
        if link in path:
            return " <- ".join(path[path.index(link):] + [link])
        path.append(link)


def _default_tool(links: list, base: str) -> str:
    """The last link, in depth-first order, carried by the last moving joint."""
    moving = [l.name for l in links if l.joint.is_moving]
    if not moving:
        return base
    parent = {l.name: l.parent for l in links}

    def carried_by_last(name: str) -> bool:
        while name != moving[-1]:
            if name not in parent:
                return False
            link = next(l for l in links if l.name == name)
            if link.joint.is_moving:
                return False
            name = parent[name]
        return True

    return [l.name for l in links if carried_by_last(l.name)][-1]
