"""The MJCF file as data: bounded XML with its ``<include>`` files, and the numbers, poses and solid
shapes its attributes describe, in MuJoCo's conventions (docs/model-files.md, "MJCF").

Every limit below bounds the work a hostile file can ask for; every problem is a ValueError naming
the file and line of the element.
"""

from __future__ import annotations

import math
import os
from dataclasses import replace

import numpy as np

from .._ui.files import open_regular
from .bounded_xml import parse_bounded
from .checks import LARGEST
from .joint import Mimic

__all__ = [
    "Sources",
    "parse_model",
    "numbers",
    "short",
    "pose",
    "quat_matrix",
    "axis_angle",
    "z_to",
    "translation_of",
    "REFUSED",
    "solid_volume_and_moments",
    "MAX_DEPTH",
    "MAX_INCLUDE_DEPTH",
    "MAX_FILE_BYTES",
    "MAX_INCLUDES",
    "with_joint_equalities",
]

MAX_DEPTH = 200  # deepest element nesting accepted (bodies nest; guards the parser's memory)
MAX_INCLUDE_DEPTH = 8  # <include> inside included files, at most this deep
MAX_FILE_BYTES = 16 * 2**20  # per file, and for all included files together
MAX_INCLUDES = 256  # <include> elements in one model
REFUSED = ("replicate", "attach", "composite", "flexcomp")


# ============================================================================== XML, bounded
class Sources:
    """Where each element came from: (file label, line), for messages; the model's folder."""

    def __init__(self, label: str, base_dir: str | None):
        self.label = label
        self.base_dir = base_dir
        self.where: dict = {}  # id(element) -> (label, line)
        self.total_bytes = 0
        self.includes = 0

    def at(self, element) -> str:
        label, line = self.where.get(id(element), (self.label, None))
        return label if line is None else f"{label}:{line}"

    def error(self, element, message: str) -> ValueError:
        return ValueError(f"{self.at(element)}: <{element.tag}> {message}")


def parse_model(path_or_string):
    text = os.fspath(path_or_string) if isinstance(path_or_string, os.PathLike) else path_or_string
    if isinstance(text, bytes):
        text = text.decode("utf-8", errors="replace") if b"<" in text or b"\n" in text else os.fsdecode(text)
    if not isinstance(text, str):
        raise TypeError(f"the MJCF reader expects a path or an XML string, got {type(path_or_string).__name__}")
    if "<" in text or "\n" in text:
        src = Sources("<MJCF string>", None)
        data = text.encode("utf-8")
        if len(data) > MAX_FILE_BYTES:
            raise ValueError(
                f"{src.label}: the XML is larger than {MAX_FILE_BYTES // 2**20} MiB, too large for a robot model"
            )
        src.total_bytes += len(data)
        root = parse_xml(data, src.label, src)
    else:
        src = Sources(text, os.path.dirname(os.path.abspath(text)))
        root = parse_xml(read_file(text, src), text, src)
    expand_includes(root, src, src.base_dir, 0)
    return src, root


def read_file(path: str, src: Sources, element=None) -> bytes:
    where = f"{src.at(element)}: <include> " if element is not None else ""
    try:
        with open_regular(path, "MJCF file") as f:  # a FIFO or a device: refused, never waited on
            data = f.read(MAX_FILE_BYTES + 1)
    except OSError as e:
        raise ValueError(f"{where or path + ': '}cannot read MJCF file '{path}' ({e.strerror or e})") from None
    except ValueError as e:
        raise ValueError(f"{where}{e}") from None
    src.total_bytes += len(data)
    if len(data) > MAX_FILE_BYTES or src.total_bytes > MAX_FILE_BYTES:
        raise ValueError(
            f"{path}: the model (with its includes) is larger than {MAX_FILE_BYTES // 2**20} MiB, too large for a robot model"
        )
    return data


def parse_xml(data: bytes, label: str, src: Sources):
    """The root element of ``data``, parsed by expat without entity declarations and with bounded depth."""

    def record(element, line):
        src.where[id(element)] = (label, line)

    return parse_bounded(data, label, "an MJCF model", MAX_DEPTH, record)


def expand_includes(element, src: Sources, folder: str | None, depth: int) -> None:
    """Replace every ``<include file>`` below ``element`` by the children of the included ``<mujoco>``."""
    k = 0
    while k < len(element):
        child = element[k]
        if child.tag != "include":
            expand_includes(child, src, folder, depth)
            k += 1
            continue
        name = child.get("file")
        if not name:
            raise src.error(child, "has no 'file' attribute")
        if folder is None or src.base_dir is None:
            raise src.error(
                child, f"file='{name}': a model given as an XML string cannot include files (load it from its file)"
            )
        if depth >= MAX_INCLUDE_DEPTH:
            raise src.error(child, f"file='{name}': includes nested deeper than {MAX_INCLUDE_DEPTH} levels")
        src.includes += 1
        if src.includes > MAX_INCLUDES:
            raise src.error(child, f"file='{name}': more than {MAX_INCLUDES} includes in one model")
        path = os.path.realpath(os.path.join(folder, name))
        top = os.path.realpath(src.base_dir)
        if os.path.commonpath([path, top]) != top:
            raise src.error(
                child, f"file='{name}' is outside the model's folder {top} (an included file must lie inside it)"
            )
        label = os.path.relpath(path) if not os.path.isabs(src.label) else path
        included = parse_xml(read_file(path, src, child), label, src)
        if included.tag != "mujoco":
            raise src.error(
                child, f"file='{name}': the included file's root element is <{included.tag}>, expected <mujoco>"
            )
        expand_includes(included, src, os.path.dirname(path), depth + 1)
        element[k : k + 1] = list(included)
        k += len(included)


# ============================================================================== numbers, poses
def numbers(
    element, attribute: str, src: Sources, n: int | None = None, text: str | None = None, at_most: int | None = None
) -> tuple:
    text = element.get(attribute) if text is None else text
    assert text is not None
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        raise src.error(element, f"attribute '{attribute}' must be numbers, got '{short(text)}'") from None
    if n is not None and len(values) != n:
        raise src.error(element, f"attribute '{attribute}' must be {n} numbers, got {len(values)}: '{short(text)}'")
    if at_most is not None and not 1 <= len(values) <= at_most:
        raise src.error(
            element, f"attribute '{attribute}' must be 1 to {at_most} numbers, got {len(values)}: '{short(text)}'"
        )
    for v in values:
        if not math.isfinite(v) or abs(v) > LARGEST:
            raise src.error(
                element,
                f"attribute '{attribute}' must hold finite numbers of magnitude at most {LARGEST:g}, got '{short(text)}'",
            )
    return values


def short(text: str) -> str:
    return text if len(text) <= 60 else text[:57] + "..."


def quat_matrix(w: float, x: float, y: float, z: float) -> np.ndarray:
    """Rotation matrix of a unit quaternion (w, x, y, z)."""
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def axis_angle(axis, angle: float) -> np.ndarray:
    x, y, z = axis
    c, s, v = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    return np.array(
        [
            [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
            [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
            [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
        ]
    )


def z_to(vector: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the z axis to the unit ``vector``."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, vector)
    s, c = np.linalg.norm(axis), float(vector @ z)
    if s < 1e-14:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])  # MuJoCo: 180 degrees about x
    return axis_angle(axis / s, math.atan2(s, c))


def pose(p, R) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def translation_of(p) -> np.ndarray:
    return pose(p, np.eye(3))


def solid_volume_and_moments(kind: str, s0: float, s1: float, s2: float) -> tuple:
    """(volume, principal moments per unit mass about the centre) of a solid MuJoCo geom of ``kind``
    with MuJoCo's half-sizes ``(s0, s1, s2)`` (radius / half-lengths; a cylinder's and a capsule's
    axis is z, s1 its half-length), as MuJoCo's inertiafromgeom computes them for a uniform density.
    ValueError when they are not finite numbers (sizes that underflow or overflow float64)."""
    try:
        volume, unit = _volume_and_moments(kind, s0, s1, s2)
    except (ZeroDivisionError, OverflowError):
        volume, unit = math.nan, (math.nan,)
    if not (math.isfinite(volume) and all(math.isfinite(u) for u in unit)):
        raise ValueError(
            f"its size ({s0:g}, {s1:g}, {s2:g}) gives a volume or moments of inertia that are not finite numbers"
        )
    return volume, unit


def _volume_and_moments(kind: str, s0: float, s1: float, s2: float) -> tuple:
    if kind == "sphere":
        volume = 4 / 3 * math.pi * s0**3
        unit = (2 / 5 * s0**2,) * 3  # moments per unit mass
    elif kind == "box":
        volume = 8 * s0 * s1 * s2
        unit = ((s1**2 + s2**2) / 3, (s0**2 + s2**2) / 3, (s0**2 + s1**2) / 3)
    elif kind == "ellipsoid":
        volume = 4 / 3 * math.pi * s0 * s1 * s2
        unit = ((s1**2 + s2**2) / 5, (s0**2 + s2**2) / 5, (s0**2 + s1**2) / 5)
    elif kind == "cylinder":
        volume = math.pi * s0**2 * 2 * s1
        across = (3 * s0**2 + (2 * s1) ** 2) / 12
        unit = (across, across, s0**2 / 2)
    else:  # capsule: a cylinder of length 2 s1 and two hemispherical caps of radius s0
        r, h = s0, 2 * s1
        cylinder, sphere = math.pi * r**2 * h, 4 / 3 * math.pi * r**3
        volume = cylinder + sphere
        # each cap (half the sphere's volume): about its own centre of mass (3r/8 from its flat
        # face) 83/320 m r^2 across, shifted to the capsule's centre by h/2 + 3r/8
        cap = (83 / 320 * r**2 + (h / 2 + 3 * r / 8) ** 2) * sphere  # both caps, times their volume
        across = (cylinder * (3 * r**2 + h**2) / 12 + cap) / volume
        axial = (cylinder * r**2 / 2 + sphere * 2 / 5 * r**2) / volume
        unit = (across, across, axial)
    return volume, unit


# ============================================================================== joint equalities
def with_joint_equalities(root, src: Sources, links: list, ignored: set) -> list:
    """``links`` with MuJoCo's linear joint equalities read as mimic joints (what ``to_mjcf`` writes
    for one). MJCF reference, equality/joint: ``y - y0 = a0 + a1 (x - x0) + a2 (x - x0)^2 + ...``
    with y = joint1, x = joint2 and y0, x0 their reference positions (kinedyn's offsets are
    ``-ref``), so a follower with a2 = a3 = a4 = 0 is ``q_y = a1 q_x + a0 - off_y + a1 off_x``. Welds
    and connects are loops (:mod:`kinedyn.description.mjcf_loops`); the other equalities (a
    polynomial, a joint held constant, tendons, flexes) are named in ``ignored``."""
    joints = {link.joint.name: k for k, link in enumerate(links)}
    out, unread = list(links), dict[str, int]()
    for section in root.iterfind("equality"):
        for element in section:
            if element.tag in ("connect", "weld"):
                continue
            if element.tag != "joint":
                unread[element.tag] = unread.get(element.tag, 0) + 1
                continue
            coefficients = numbers(element, "polycoef", src, at_most=5) if element.get("polycoef") else (0.0, 1.0)
            a = tuple(coefficients) + (0.0,) * (5 - len(coefficients))
            y, x = element.get("joint1"), element.get("joint2")
            readable = element.tag == "joint" and element.get("active", "true") == "true" and not any(a[2:])
            if not readable or y not in joints or x not in joints or y == x:
                unread["joint"] = unread.get("joint", 0) + 1
                continue
            follower, leader = out[joints[y]].joint, out[joints[x]].joint
            offset = a[0] - float(follower.offset) + a[1] * float(leader.offset)
            out[joints[y]] = replace(out[joints[y]], joint=replace(follower, mimic=Mimic(x, a[1], offset)))
    ignored.difference_update({e for e in ignored if e.startswith("<equality>")})
    for tag, count in sorted(unread.items()):
        what = "that are not a linear joint equality" if tag == "joint" else "(not modelled)"
        ignored.add(f"<equality><{tag}> ({count} element{'s' if count > 1 else ''} {what})")
    return out
