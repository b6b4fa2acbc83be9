"""What a robot file says, for the audit (:mod:`kinedyn.description.audit`): its links (mass,
centre of mass, inertia as written and in the link's axes, the inertial frame's rotation, shapes)
and joints (kind, ends, limits as written, mimic), each with its file and line, read leniently so
that a file the loader refuses is still audited; and :class:`Finding`, one problem found in it.

A URDF is read from its XML (:func:`kinedyn.description.urdf.read_urdf_xml`); an MJCF file and a
YAML/TOML robot file through their description, with the lines of the MJCF bodies and joints.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field

import numpy as np

from .._math import rpy_to_matrix
from .checks import LARGEST
from .description import Description
from .geometry import Box, Cylinder, Mesh, Sphere
from .inertia import Inertia
from .mjcf import description_from_mjcf
from .mjcf_xml import parse_model
from .urdf import read_urdf_xml

__all__ = [
    "Finding",
    "Facts",
    "LinkFacts",
    "JointFacts",
    "urdf_facts",
    "mjcf_facts",
    "description_facts",
    "REVOLUTE_OR_PRISMATIC",
]

REVOLUTE_OR_PRISMATIC = ("revolute", "prismatic")


@dataclass(frozen=True)
class Finding:
    """One problem: ``severity`` (``error``, ``warning``, ``info``), a short ``code``, the
    ``element`` (``link 'x'``, ``joint 'j'``, ``robot``), where it is (``file``, ``line``), what is
    wrong (``message``) and what to do (``fix``)."""

    severity: str
    code: str
    element: str
    file: str
    line: int | None
    message: str
    fix: str = ""
    data: dict = field(default_factory=dict)

    @property
    def where(self) -> str:
        return self.file if self.line is None else f"{self.file}:{self.line}"

    def __str__(self) -> str:
        fix = f" Fix: {self.fix}" if self.fix else ""
        return f"{self.where}: {self.severity}: {self.element}: {self.message}.{fix}"


# ============================================================================== what a file says
@dataclass
class LinkFacts:
    name: str
    file: str
    line: int | None
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tensor: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # about the com, link axes
    given: np.ndarray | None = None  # the tensor as written, in the inertial frame's axes
    rpy: tuple = (0.0, 0.0, 0.0)
    has_inertial: bool = False
    shapes: list = field(default_factory=list)  # (role, shape, origin 4x4, "file:line")
    part_of_body: bool = False  # a link kinedyn makes between the joints of one MJCF body


@dataclass
class JointFacts:
    name: str
    file: str
    line: int | None
    kind: str
    parent: str
    child: str
    limit: dict | None = None  # attributes as written (lower, upper, effort, velocity: float or None)
    mimic: tuple | None = None  # (leader, multiplier)
    checks_limits: bool = True  # URDF requires <limit>; MJCF and kinedyn's own files do not


class Facts:
    def __init__(self, source: str):
        self.source = source
        self.base = ""  # the fixed frame a description's root joints hang from (no link of its own)
        self.links: list = []
        self.joints: list = []
        self.findings: list = []

    def add(self, severity, code, element, file, line, message, fix="", **data):
        self.findings.append(Finding(severity, code, element, file, line, message, fix, data))


# ---------------------------------------------------------------------------------------- URDF
def urdf_facts(path_or_string) -> Facts:
    src, root = read_urdf_xml(path_or_string)
    facts = Facts(src.label)
    base_dir = None if src.label.startswith("<") else os.path.dirname(os.path.abspath(src.label))

    def line(e):
        return src.line(e)

    def floats(e, attribute, n, default, element):
        text = e.get(attribute)
        if text is None:
            return default
        try:
            values = tuple(float(v) for v in text.split())
        except ValueError:
            values = ()
        # finite and at most LARGEST in magnitude, as the loader reads numbers
        if len(values) != n or not all(math.isfinite(v) and abs(v) <= LARGEST for v in values):
            facts.add(
                "error",
                "unreadable",
                element,
                src.label,
                line(e),
                f"'{attribute}' must be {n} finite numbers of magnitude at most {LARGEST:g}, got '{text[:40]}'",
            )
            return default
        return values

    for e in root.iterfind("link"):
        name = e.get("name") or ""
        what = f"link '{name}'"
        link = LinkFacts(name, src.label, line(e))
        inertial = e.find("inertial")
        if inertial is not None:
            link.has_inertial = True
            mass_el = inertial.find("mass")
            link.mass = floats(mass_el, "value", 1, (0.0,), what)[0] if mass_el is not None else 0.0
            if mass_el is None:
                facts.add(
                    "error",
                    "no-mass",
                    what,
                    src.label,
                    line(inertial),
                    "<inertial> has no <mass> (urdfdom, so Pinocchio and ROS, refuse the file)",
                    "add <mass value=...>",
                )
            tensor_el = inertial.find("inertia")
            keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            if tensor_el is None or any(tensor_el.get(k) is None for k in keys):
                facts.add(
                    "error",
                    "no-inertia",
                    what,
                    src.label,
                    line(tensor_el if tensor_el is not None else inertial),
                    "<inertial> lacks an <inertia> with all six of ixx ixy ixz iyy iyz izz (urdfdom refuses it)",
                    "write all six entries (0 where zero)",
                )
            v = [floats(tensor_el, k, 1, (0.0,), what)[0] if tensor_el is not None else 0.0 for k in keys]
            given = np.array([[v[0], v[1], v[2]], [v[1], v[3], v[4]], [v[2], v[4], v[5]]])
            origin = inertial.find("origin")
            xyz = floats(origin, "xyz", 3, (0.0, 0.0, 0.0), what) if origin is not None else (0.0, 0.0, 0.0)
            link.rpy = floats(origin, "rpy", 3, (0.0, 0.0, 0.0), what) if origin is not None else (0.0, 0.0, 0.0)
            R = np.array(rpy_to_matrix(*link.rpy), dtype=float)[:3, :3]
            link.com, link.given, link.tensor = np.array(xyz, dtype=float), given, R @ given @ R.T
        for role in ("collision", "visual"):
            for item in e.iterfind(role):
                shape = _urdf_shape(item.find("geometry"), base_dir, floats, what)
                if shape is None:
                    continue
                origin = item.find("origin")
                xyz = floats(origin, "xyz", 3, (0.0, 0.0, 0.0), what) if origin is not None else (0.0, 0.0, 0.0)
                rpy = floats(origin, "rpy", 3, (0.0, 0.0, 0.0), what) if origin is not None else (0.0, 0.0, 0.0)
                T = np.array(rpy_to_matrix(*rpy), dtype=float)
                T[:3, 3] = xyz
                link.shapes.append((role, shape, T, f"{src.label}:{line(item)}"))
        facts.links.append(link)
    for e in root.iterfind("joint"):
        name = e.get("name") or ""
        what = f"joint '{name}'"
        parent, child = e.find("parent"), e.find("child")
        joint = JointFacts(
            name,
            src.label,
            line(e),
            e.get("type") or "",
            parent.get("link", "") if parent is not None else "",
            child.get("link", "") if child is not None else "",
        )
        limit = e.find("limit")
        if limit is not None:
            joint.limit = {
                k: (floats(limit, k, 1, (None,), what)[0] if limit.get(k) is not None else None)
                for k in ("lower", "upper", "effort", "velocity")
            }
            joint.limit["line"] = line(limit)
        mimic = e.find("mimic")
        if mimic is not None:
            joint.mimic = (mimic.get("joint") or "", floats(mimic, "multiplier", 1, (1.0,), what)[0])
        facts.joints.append(joint)
    return facts


def _urdf_shape(geometry, base_dir, floats, what):
    if geometry is None:
        return None
    for child in geometry:
        try:
            if child.tag == "box":
                size = floats(child, "size", 3, None, what)
                return Box(size) if size and min(size) > 0 else None
            if child.tag == "cylinder":
                r, h = float(child.get("radius", "0")), float(child.get("length", "0"))
                return Cylinder(r, h) if r > 0 and h > 0 else None
            if child.tag == "sphere":
                r = float(child.get("radius", "0"))
                return Sphere(r) if r > 0 else None
            if child.tag == "mesh" and child.get("filename"):
                scale = floats(child, "scale", 3, (1.0, 1.0, 1.0), what)
                return Mesh(child.get("filename"), scale, base_dir) if all(scale) else None
        except ValueError:
            return None  # the loader names a malformed shape; the audit measures the readable ones
    return None


# ------------------------------------------------------------------------------ a description
def description_facts(description: Description, lines: dict | None = None) -> Facts:
    """What a description holds (an MJCF file's, or one built in Python); ``lines``: name ->
    (file, line) of its bodies and joints where the file is known."""
    lines = lines or {}
    source = description.source or description.name
    facts = Facts(source)
    facts.base = description.base
    shapes: dict = {}
    for role, items in (("collision", description.collisions), ("visual", description.visuals)):
        for v in items:
            shapes.setdefault(v.frame, []).append((role, v.shape, np.asarray(v.origin, dtype=float), v.where))
    for link in description.links:
        inertia: Inertia = link.inertia
        if inertia.is_symbolic:
            continue
        file, line = lines.get(("body", link.name), (source, None))
        facts.links.append(
            LinkFacts(
                link.name,
                file,
                line,
                float(inertia.mass),
                np.array(inertia.com, dtype=float),
                np.array(inertia.inertia, dtype=float),
                None,
                (0.0, 0.0, 0.0),
                True,
                shapes.get(link.name, []),
            )
        )
        j = link.joint
        file, line = lines.get(("joint", j.name), (file, line))
        limit = None
        if j.kind in REVOLUTE_OR_PRISMATIC:
            finite = lambda v: float(v) if math.isfinite(float(v)) else None  # noqa: E731
            limit = {
                k: finite(getattr(j, a))
                for k, a in (
                    ("lower", "lower"),
                    ("upper", "upper"),
                    ("effort", "effort_limit"),
                    ("velocity", "velocity_limit"),
                )
            }
            limit["line"] = line
        mimic = (j.mimic.leader, float(j.mimic.multiplier)) if j.mimic is not None else None
        facts.joints.append(
            JointFacts(j.name, file, line, j.kind, link.parent or description.base, link.name, limit, mimic, False)
        )
    return facts


def mjcf_facts(path_or_string) -> Facts:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the loader's warnings are its own; the audit reports findings
        description = description_from_mjcf(path_or_string, inertia="warn")
    src, root = parse_model(path_or_string)
    lines = {}
    bodies = joints = 0  # MuJoCo's numbering of unnamed elements, as the reader gives it: body{1..}, joint{0..}
    for world in root.iterfind("worldbody"):
        for e in world.iter():
            if e.tag == "body":
                bodies += 1
                key = ("body", e.get("name") or f"body{bodies}")
            elif e.tag in ("joint", "freejoint"):
                key = ("joint", e.get("name") or f"joint{joints}")
                joints += 1
            else:
                continue
            lines[key] = src.where.get(id(e), (src.label, None))
    facts = description_facts(description, lines)
    facts.source = src.label
    for link in facts.links:
        link.part_of_body = ("body", link.name) not in lines
    return facts
