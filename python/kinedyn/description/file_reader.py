"""Reading YAML/TOML robot files (docs/model-files.md) into a :class:`~kinedyn.description.description.Description`.

The file is text a person writes, and may come from anyone: it is read with bounds on its size,
nesting and YAML nodes (``MAX_*``), every tag beyond plain YAML refused, and every problem is a
ValueError naming the file, the line and the key. A string that is not a number becomes a SymPy
expression (``"l1"``, ``"m1*l1**2/12"``).
"""

from __future__ import annotations

import math
import os
import re
import sys
from dataclasses import replace
from typing import TYPE_CHECKING, NoReturn

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10 (requires-python): tomllib is tomli, in the standard library since 3.11
    import tomli as tomllib

from .._lazy import LazyModule, sympy_instance
from .._math import matmul, rpy_to_matrix, translation
from .._ui.files import open_regular
from .._ui.names import did_you_mean
from ..expressions import parse_expression
from .description import Description
from .dh import DHRow, description_from_dh
from .file_limits import MAX_NESTING, MAX_NODES, SHORT_REPR, LineDict, LineList
from .geometry import Box, Cylinder, Mesh, Sphere, Visual
from .inertia import Inertia
from .joint import Joint, Mimic
from .link import Frame, Link
from .loops import Loop

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = [
    "LineDict",
    "LineList",
    "SHORT_REPR",
    "description_from_mapping",
    "read_text",
    "parse_yaml",
    "parse_toml",
    "MAX_FILE_BYTES",
    "MAX_TEXT_BYTES",
    "MAX_NESTING",
    "MAX_NODES",
    "MAX_TEXT",
]

_TOP_COMMON = {"name", "gravity", "units", "frames", "source", "visuals", "loops", "reference_configuration"}
_TOP_DH = _TOP_COMMON | {"convention", "base_pose", "tool", "tool_frame", "joints"}
_TOP_TREE = _TOP_COMMON | {"base", "tool", "links"}
_ROW_KEYS = {
    "theta",
    "d",
    "a",
    "alpha",
    "type",
    "name",
    "limits",
    "mass",
    "com",
    "inertia",
    "gear_ratio",
    "rotor_inertia",
    "viscous",
    "coulomb",
}
_LINK_KEYS = {"name", "parent", "joint", "inertial", "post"}
_JOINT_KEYS = {
    "name",
    "type",
    "axis",
    "origin",
    "offset",
    "limits",
    "gear_ratio",
    "rotor_inertia",
    "viscous",
    "coulomb",
    "mimic",
}
_MIMIC_KEYS = {"joint", "multiplier", "offset"}  # URDF's <mimic> attributes (docs/model-files.md#mimic-joints)
_INERTIAL_KEYS = {"mass", "com", "inertia"}
_LIMIT_KEYS = {"lower", "upper", "velocity", "effort"}
_POSE_KEYS = {"xyz", "rpy"}
_FRAME_KEYS = {"name", "link", "origin"}
_LOOP_KEYS = {"name", "frame_a", "frame_b", "kind"}  # a Loop (kinedyn.description.loops)
_VISUAL_KEYS = {"link", "origin", "color", "mesh", "scale", "box", "cylinder", "sphere"}
_SHAPE_KEYS = ("mesh", "box", "cylinder", "sphere")
_TENSOR_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")

# Bounds on a robot file, so that a small hostile file cannot ask for unbounded time or memory
MAX_FILE_BYTES = 16 * 2**20  # a robot file is text a person writes: 16 MiB is far beyond any robot
MAX_TEXT = 1000  # characters of a name or other text field
# a YAML/TOML robot file: a 100-joint robot is ~20 KiB; the YAML parser reads ~0.1-1 MiB/s, so a larger
# file is refused on its size before parsing, not after seconds of it
MAX_TEXT_BYTES = 2**20


def read_text(path: str) -> str:
    """The file's text, refusing files too large to be a robot description before reading them."""
    try:
        with open_regular(path, "robot file") as f:  # a FIFO or /dev/zero: refused, never waited on
            size = os.fstat(f.fileno()).st_size
            if size > MAX_TEXT_BYTES:  # on its size, before a byte is read
                raise ValueError(
                    f"{path}: the file is larger than {MAX_TEXT_BYTES // 2**20} MiB, too large for a robot file"
                )
            raw = f.read(MAX_TEXT_BYTES + 1)
    except OSError as e:
        raise ValueError(f"{path}: cannot read robot file ({e.strerror or e})") from None
    if len(raw) > MAX_TEXT_BYTES:
        raise ValueError(f"{path}: the file is larger than {MAX_TEXT_BYTES // 2**20} MiB, too large for a robot file")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ValueError(f"{path}: the file is not UTF-8 text (byte {e.start})") from None


# ---------------------------------------------------------------- YAML, bounded
def parse_yaml(text: str, where: str):
    """The YAML robot file ``text`` as plain data (kinedyn.description.yaml_reader)."""
    from .yaml_reader import parse_yaml as parse  # PyYAML loads only for YAML robot files

    return parse(text, where)


_TOML_STRING_OR_COMMENT = re.compile(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:\\.|[^"\\\n])*"|\'[^\'\n]*\'|#[^\n]*')
_TOML_KEY = re.compile(r"(?:^|[{,])([^={},\[\]\n]*)=|^\s*\[\[?([^\]\n]*)\]", re.M)


def _toml_key_depth(text: str) -> int:
    """The most parts of one dotted key (``a.b.c`` has 3) in TOML text. tomllib's time grows with the
    square of a key's parts, so this linear scan runs first; strings and comments are blanked so
    that their dots do not count, and a float's dot is never in a key position."""
    bare = _TOML_STRING_OR_COMMENT.sub("s", text)
    return max((1 + (m.group(1) or m.group(2) or "").count(".") for m in _TOML_KEY.finditer(bare)), default=0)


def parse_toml(text: str, where: str):
    depth = _toml_key_depth(text)
    if depth > MAX_NESTING:
        raise ValueError(f"{where}: a dotted key has {depth} parts, tables nested more than {MAX_NESTING} deep")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:  # the message ends with "(at line L, column C)"
        raise ValueError(f"{where}: invalid TOML: {e}") from None
    except (RecursionError, MemoryError):  # tomllib recurses into nested arrays and inline tables
        raise ValueError(f"{where}: invalid TOML: arrays or tables nested too deep") from None
    except ValueError as e:  # e.g. Python's limit on the digits of an integer literal
        raise ValueError(f"{where}: invalid TOML: {e}") from None
    depth = _nesting(data)
    if depth > MAX_NESTING:
        raise ValueError(f"{where}: tables and arrays are nested {depth} deep (at most {MAX_NESTING})")
    return data


def _nesting(data) -> int:
    """How deep mappings and lists nest in ``data`` (iterative: the data may be deeper than the stack)."""
    deepest, stack = 0, [(data, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, (dict, list)):
            deepest = max(deepest, depth)
            if depth > MAX_NESTING:
                break
            stack.extend((v, depth + 1) for v in (item.values() if isinstance(item, dict) else item))
    return deepest


# ============================================================================ reading a mapping
class _Reader:
    """Converts values of one robot file, knowing where it is (for messages), the line of each field
    (YAML) and the file's angle unit."""

    def __init__(self, where: str):
        self.where = where
        self.deg = False
        self.lines: dict = {}  # field path (as in messages) -> line, where the parser knew it

    def fail(self, ctx: str, message: str) -> NoReturn:
        line = self.line_of(ctx)
        at = f", line {line}" if line else ""
        raise ValueError(f"{self.where}{at}: {ctx}: {message}")

    def line_of(self, ctx: str) -> int | None:
        """The line of field ``ctx`` or of the nearest field that holds it."""
        while ctx:
            if ctx in self.lines:
                return self.lines[ctx]
            cut = max(ctx.rfind("."), ctx.rfind("["))
            if cut <= 0:
                return None
            ctx = ctx[:cut]
        return None

    def remember_lines(self, container, ctx: str, keys=None) -> None:
        """Note the lines of a YAML mapping's keys (``ctx.key``) or a list's items (``ctx[i]``)."""
        if isinstance(container, LineDict):
            for key, line in container.lines.items():
                self.lines.setdefault(f"{ctx}.{key}" if ctx else str(key), line)
        elif isinstance(container, LineList):
            for i, line in enumerate(container.lines):
                self.lines.setdefault(f"{ctx}[{i}]", line)
                if keys is not None:
                    self.lines.setdefault(keys(i), line)

    def check_keys(self, mapping, known: set, ctx: str) -> dict:
        if not isinstance(mapping, dict):
            self.fail(ctx, f"expected a mapping, got {_kind(mapping)}")
        self.remember_lines(mapping, "" if ctx == "top level" else ctx)
        for key in mapping:
            if key not in known:
                self.fail(ctx, f"unknown key {SHORT_REPR.repr(key)} (known keys: {', '.join(sorted(known))})")
        return mapping

    def items(self, raw, ctx: str, what: str, row_ctx) -> list:
        """A list from the file (``what`` says what it should hold), its items' lines noted under
        ``row_ctx(i)``, the context each item is read in."""
        if not isinstance(raw, list):
            self.fail(ctx, f"expected a list of {what}, got {_kind(raw)}")
        self.remember_lines(raw, ctx, row_ctx)
        return raw

    def text(self, raw, ctx: str) -> str:
        """A name or other short text (numbers are read as their text)."""
        if isinstance(raw, bool) or not isinstance(raw, (str, int, float)):
            self.fail(ctx, f"expected a name (text), got {_kind(raw)}")
        out = str(raw)
        if not out or len(out) > MAX_TEXT:
            self.fail(ctx, f"expected a name of 1 to {MAX_TEXT} characters, got {len(out)}")
        return out

    def value(self, raw, ctx: str, infinite: bool = False):
        """A finite float, or a SymPy expression for a string that is not a number (read by kinedyn's
        own parser: numbers, names, arithmetic and a fixed table of functions, never evaluated as
        code). ``infinite``: +-inf is allowed (a limit that is not set)."""
        if isinstance(raw, bool) or raw is None:
            self.fail(ctx, f"expected a number or an expression, got {raw!r}")
        if isinstance(raw, int):
            if raw.bit_length() > 1000:
                self.fail(
                    ctx,
                    f"the integer has about {int(raw.bit_length() * math.log10(2))} digits, too large for a robot's parameter",
                )
            raw = float(raw)
        if isinstance(raw, float):
            if math.isnan(raw) or (math.isinf(raw) and not infinite):
                self.fail(ctx, f"must be a finite number, got {raw}")
            return raw
        if isinstance(raw, str):
            try:
                return parse_expression(raw)
            except ValueError as e:
                self.fail(ctx, str(e))
        self.fail(ctx, f"expected a number or an expression, got {_kind(raw)}")

    def number(self, raw, ctx: str, infinite: bool = False) -> float:
        v = self.value(raw, ctx, infinite)
        if sympy_instance(v, "Basic"):
            self.fail(ctx, f"must be a number, got the expression '{SHORT_REPR.repr(raw)[1:-1]}'")
        return v

    def angle(self, raw, ctx: str):
        v = self.value(raw, ctx)
        if not self.deg:
            return v
        return v * sp.pi / 180 if sympy_instance(v, "Basic") else v * math.pi / 180

    def vector(self, raw, ctx: str, n: int = 3, angles: bool = False) -> tuple:
        if not isinstance(raw, (list, tuple)) or len(raw) != n:
            self.fail(ctx, f"expected a list of {n} values, got {SHORT_REPR.repr(raw)}")
        self.remember_lines(raw, ctx)
        f = self.angle if angles else self.value
        return tuple(f(v, f"{ctx}[{i}]") for i, v in enumerate(raw))

    def pose(self, raw, ctx: str):
        """``{xyz: [x, y, z], rpy: [roll, pitch, yaw]}`` -> 4x4 (rpy as in URDF)."""
        raw = self.check_keys(raw, _POSE_KEYS, ctx)
        xyz = self.vector(raw.get("xyz", [0, 0, 0]), f"{ctx}.xyz")
        rpy = self.vector(raw.get("rpy", [0, 0, 0]), f"{ctx}.rpy", angles=True)
        return matmul(translation(*xyz), rpy_to_matrix(*rpy))

    def limits(self, raw, revolute: bool, ctx: str) -> dict:
        raw = self.check_keys(raw, _LIMIT_KEYS, ctx)
        out = {}
        for key, field in (("lower", "lower"), ("upper", "upper"), ("velocity", "velocity_limit")):
            if key in raw:
                v = self.number(raw[key], f"{ctx}.{key}", infinite=True)
                out[field] = v * math.pi / 180 if (revolute and self.deg) else v
        if "effort" in raw:
            out["effort_limit"] = self.number(raw["effort"], f"{ctx}.effort", infinite=True)
        return out

    def inertia(self, raw: dict, ctx: str) -> Inertia:
        """mass, com (link frame) and inertia about the COM (mapping ixx.. or 3x3 list)."""
        mass = self.value(raw.get("mass", 0.0), f"{ctx}.mass")
        com = self.vector(raw.get("com", [0, 0, 0]), f"{ctx}.com")
        tensor = raw.get("inertia", {})
        if isinstance(tensor, dict):
            tensor = self.check_keys(tensor, set(_TENSOR_KEYS), f"{ctx}.inertia")
            ixx, ixy, ixz, iyy, iyz, izz = (self.value(tensor.get(k, 0.0), f"{ctx}.inertia.{k}") for k in _TENSOR_KEYS)
            tensor = ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))
        elif isinstance(tensor, (list, tuple)) and len(tensor) == 3:
            tensor = tuple(self.vector(r, f"{ctx}.inertia[{i}]") for i, r in enumerate(tensor))
        else:
            self.fail(f"{ctx}.inertia", "expected {ixx, ixy, ixz, iyy, iyz, izz} or a 3x3 list")
        try:
            return Inertia(mass, com, tensor)
        except ValueError as e:
            self.fail(ctx, str(e))

    def drive(self, raw: dict, ctx: str) -> dict:
        out = {k: self.value(raw[k], f"{ctx}.{k}") for k in ("gear_ratio", "rotor_inertia", "viscous") if k in raw}
        if "coulomb" in raw:
            c = raw["coulomb"]
            if not isinstance(c, (list, tuple)):
                out["coulomb"] = self.value(c, f"{ctx}.coulomb")
                return out
            # [positive, negative]: direction-dependent Coulomb levels (magnitudes)
            if len(c) != 2:
                self.fail(
                    f"{ctx}.coulomb",
                    f"expected one level or a list [positive, negative] of two levels, got {len(c)} values",
                )
            levels = tuple(self.value(v, f"{ctx}.coulomb[{i}]") for i, v in enumerate(c))
            for i, v in enumerate(levels):
                if not sympy_instance(v, "Basic") and v < 0:
                    self.fail(
                        f"{ctx}.coulomb[{i}]",
                        f"a Coulomb level is a magnitude >= 0, got {v} (Corke's Tc = [Tc+, Tc-] with Tc- < 0 is written [Tc+, -Tc-])",
                    )
            out["coulomb"] = levels
        return out


def description_from_mapping(data, where: str = "<robot mapping>", inertia: str = "warn") -> Description:
    """The description in the parsed contents of a YAML/TOML robot file (see docs/model-files.md)."""
    r = _Reader(where)
    if not isinstance(data, dict):
        raise ValueError(f"{where}: a robot file must hold a mapping at the top level, got {type(data).__name__}")
    if ("joints" in data) == ("links" in data):
        raise ValueError(f"{where}: a robot file needs exactly one of 'joints' (DH table) or 'links' (tree)")
    dh = "joints" in data
    r.check_keys(data, _TOP_DH if dh else _TOP_TREE, "top level")
    units = r.check_keys(data.get("units", {}), {"angle"}, "units")
    if units.get("angle", "rad") not in ("deg", "rad"):
        r.fail("units.angle", f"must be 'deg' or 'rad', got {SHORT_REPR.repr(units['angle'])}")
    r.deg = units.get("angle") == "deg"
    common = {
        "gravity": r.vector(data.get("gravity", [0, 0, -9.81]), "gravity"),
        "name": r.text(data.get("name", "robot"), "name"),
        "source": r.text(data.get("source", where), "source"),
        "inertia": inertia,
    }
    frames = _frames(r, data.get("frames", []))
    visuals = _visuals(r, data.get("visuals", []), where)
    try:
        description = _dh_description(r, data, common, frames) if dh else _tree_description(r, data, common, frames)
        if visuals:
            frame_names = [f.name for f in description.tree.frames]
            unknown = sorted({v.frame for v in visuals} - set(frame_names))
            if unknown:
                r.fail("visuals", f"names links {unknown} that the robot does not have (frames: {frame_names})")
            description = replace(description, visuals=tuple(visuals))
        if "loops" in data:
            description = replace(description, loops=_loops(r, data["loops"], description.frame_names))
        if "reference_configuration" in data:
            description = replace(
                description, reference_configuration=_reference(r, data["reference_configuration"], description)
            )
        return description
    except ValueError as e:
        if str(e).startswith(where):
            raise
        raise ValueError(f"{where}: {e}") from None


def _frames(r: _Reader, raw) -> list:
    out = []
    for i, f in enumerate(r.items(raw, "frames", "{name, link, origin}", lambda i: f"frames[{i}]")):
        ctx = f"frames[{i}]"
        f = r.check_keys(f, _FRAME_KEYS, ctx)
        if "name" not in f:
            r.fail(ctx, "a frame needs a 'name'")
        origin = r.pose(f["origin"], f"{ctx}.origin") if "origin" in f else np.eye(4)
        link = r.text(f["link"], f"{ctx}.link") if f.get("link") is not None else None
        name = r.text(f["name"], f"{ctx}.name")
        try:
            out.append(Frame(name, link, origin))
        except ValueError as e:  # the description's own checks (finite, bounded placement)
            r.fail(ctx, str(e))
    return out


def _loops(r: _Reader, raw, frame_names: list) -> tuple:
    """``loops:`` [{name, frame_a, frame_b, kind}] (docs/model-files.md, "Closed loops")."""
    out, seen = [], set()
    for i, lp in enumerate(r.items(raw, "loops", "{name, frame_a, frame_b, kind}", lambda i: f"loops[{i}]")):
        ctx = f"loops[{i}]"
        lp = r.check_keys(lp, _LOOP_KEYS, ctx)
        missing = [k for k in ("name", "frame_a", "frame_b") if k not in lp]
        if missing:
            r.fail(ctx, f"a loop needs {', '.join(repr(k) for k in missing)}")
        name = r.text(lp["name"], f"{ctx}.name")
        if name in seen:
            r.fail(f"{ctx}.name", f"two loops are named '{name}'")
        seen.add(name)
        ends = []
        for key in ("frame_a", "frame_b"):
            frame = r.text(lp[key], f"{ctx}.{key}")
            if frame not in frame_names:
                r.fail(
                    f"{ctx}.{key}",
                    f"names no frame '{frame}'{did_you_mean(frame, frame_names)} (frames: {frame_names})",
                )
            ends.append(frame)
        try:
            out.append(Loop(name, ends[0], ends[1], r.text(lp.get("kind", "point"), f"{ctx}.kind")))
        except ValueError as e:  # the kind, or a frame closed on itself
            r.fail(ctx, str(e))
    return tuple(out)


def _reference(r: _Reader, raw, description: Description) -> dict:
    """``reference_configuration: {joint: value}``: where the loops close on the mechanism's branch
    (docs/closed-loops.md, "The assembly mode"); a revolute joint's value in the file's angle unit, a
    multi-DOF joint's its block of q."""
    ctx = "reference_configuration"
    if not isinstance(raw, dict):
        r.fail(ctx, f"expected a mapping of joint names to values, got {_kind(raw)}")
    r.remember_lines(raw, ctx)
    joints = {b.joint.name: b.joint for b in description.tree.bodies}
    out: dict[str, float | tuple[float, ...]] = {}
    for name, value in raw.items():
        key = f"{ctx}.{name}"
        joint = joints.get(name)
        if joint is None:
            names = list(joints)
            r.fail(key, f"names no moving joint '{name}'{did_you_mean(str(name), names)} (moving joints: {names})")
        if joint.is_multi_dof:
            block = tuple(
                r.number(v, f"{key}[{i}]") for i, v in enumerate(r.items(value, key, f"{joint.nq} numbers", None))
            )
            if len(block) != joint.nq:
                r.fail(key, f"a {joint.kind} joint's value is its block of q: {joint.nq} numbers, got {len(block)}")
            out[name] = block
        else:
            out[name] = r.number(value, key) * (math.pi / 180 if r.deg and joint.kind == "revolute" else 1.0)
    return out


def _visuals(r: _Reader, raw, where: str) -> list:
    """``visuals:`` [{link, mesh|box|cylinder|sphere, scale, origin, color}] (docs/visualisation.md)."""
    base_dir = os.path.dirname(os.path.abspath(where)) if not where.startswith("<") else None
    out = []
    for i, v in enumerate(
        r.items(raw, "visuals", "{link, mesh | box | cylinder | sphere, ...}", lambda i: f"visuals[{i}]")
    ):
        ctx = f"visuals[{i}]"
        v = r.check_keys(v, _VISUAL_KEYS, ctx)
        if "link" not in v:
            r.fail(ctx, "a visual needs the 'link' it is fixed to")
        shapes = [k for k in _SHAPE_KEYS if k in v]
        if len(shapes) != 1:
            r.fail(ctx, f"a visual needs exactly one of {', '.join(_SHAPE_KEYS)}, got {shapes or 'none'}")
        kind = shapes[0]
        shape: object
        if kind == "mesh":
            sx, sy, sz = (r.number(x, f"{ctx}.scale") for x in r.vector(v.get("scale", [1, 1, 1]), f"{ctx}.scale"))
            if 0 in (sx, sy, sz):
                r.fail(f"{ctx}.scale", "may not hold 0")
            shape = Mesh(r.text(v["mesh"], f"{ctx}.mesh"), (sx, sy, sz), base_dir)
        elif kind == "box":
            size = tuple(r.number(x, f"{ctx}.box") for x in r.vector(v["box"], f"{ctx}.box"))
            if any(x <= 0 for x in size):
                r.fail(f"{ctx}.box", "needs 3 positive side lengths")
            shape = Box(size)  # type: ignore[arg-type]
        elif kind == "cylinder":
            c = r.check_keys(v["cylinder"], {"radius", "length"}, f"{ctx}.cylinder")
            radius, length = (
                r.number(c.get("radius", 0), f"{ctx}.cylinder.radius"),
                r.number(c.get("length", 0), f"{ctx}.cylinder.length"),
            )
            if radius <= 0 or length <= 0:
                r.fail(f"{ctx}.cylinder", "needs a positive radius and length")
            shape = Cylinder(radius, length)
        else:
            radius = r.number(v["sphere"], f"{ctx}.sphere")
            if radius <= 0:
                r.fail(f"{ctx}.sphere", "needs a positive radius")
            shape = Sphere(radius)
        rgba = None
        if "color" in v:
            rgba = tuple(r.number(x, f"{ctx}.color") for x in r.vector(v["color"], f"{ctx}.color", n=4))
            if any(not 0 <= x <= 1 for x in rgba):
                r.fail(f"{ctx}.color", "needs 4 numbers between 0 and 1 (r, g, b, alpha)")
        origin = r.pose(v["origin"], f"{ctx}.origin") if "origin" in v else np.eye(4)
        out.append(
            Visual(
                r.text(v["link"], f"{ctx}.link"),
                shape,
                np.asarray(origin, dtype=float),
                rgba,  # type: ignore[arg-type]  # four numbers: r.vector(..., n=4) checked the length
                None,
                f"{where} {ctx}",
            )
        )
    return out


def _dh_description(r: _Reader, data: dict, common: dict, frames: list) -> Description:
    convention = data.get("convention", "standard")
    if convention not in ("standard", "modified"):
        r.fail("convention", f"must be 'standard' or 'modified', got {SHORT_REPR.repr(convention)}")
    joints = r.items(data["joints"], "joints", "DH rows", lambda i: f"joints row {i + 1}")
    if not joints:
        r.fail("joints", "expected a non-empty list of DH rows")
    rows = [_dh_row(r, row, i) for i, row in enumerate(joints)]
    base_pose = r.pose(data["base_pose"], "base_pose") if "base_pose" in data else None
    tool = r.pose(data["tool"], "tool") if "tool" in data else None
    description = description_from_dh(rows, convention, base_pose=base_pose, tool=tool, **common)
    if frames or "tool_frame" in data:
        tool_frame = r.text(data["tool_frame"], "tool_frame") if "tool_frame" in data else "tool"
        description = replace(description, frames=description.frames + tuple(frames), tool=tool_frame)
    return description


def _dh_row(r: _Reader, row, i: int) -> DHRow:
    ctx = f"joints row {i + 1}"
    row = r.check_keys(row, _ROW_KEYS, ctx)
    kind = row.get("type", "revolute")
    if kind not in ("revolute", "prismatic"):
        r.fail(f"{ctx}.type", f"must be 'revolute' or 'prismatic', got {SHORT_REPR.repr(kind)}")
    limits = r.limits(row.get("limits", {}), kind == "revolute", f"{ctx}.limits")
    return DHRow(
        theta=r.angle(row.get("theta", 0.0), f"{ctx}.theta"),
        d=r.value(row.get("d", 0.0), f"{ctx}.d"),
        a=r.value(row.get("a", 0.0), f"{ctx}.a"),
        alpha=r.angle(row.get("alpha", 0.0), f"{ctx}.alpha"),
        kind=kind,
        name=None if row.get("name") is None else r.text(row["name"], f"{ctx}.name"),
        inertia=r.inertia(row, ctx),
        **limits,
        **r.drive(row, ctx),
    )


def _tree_description(r: _Reader, data: dict, common: dict, frames: list) -> Description:
    raw_links = r.items(data["links"], "links", "links", lambda i: f"links row {i + 1}")
    if not raw_links:
        r.fail("links", "expected a non-empty list of links")
    links = [_tree_link(r, link, i) for i, link in enumerate(raw_links)]
    tool = data.get("tool")
    if tool is not None and not isinstance(tool, str):
        r.fail("tool", "in a tree-based file 'tool' names a frame or link")
    return Description(tuple(links), tuple(frames), base=r.text(data.get("base", "base"), "base"), tool=tool, **common)


def _tree_link(r: _Reader, raw, i: int) -> Link:
    ctx = f"links row {i + 1}"
    raw = r.check_keys(raw, _LINK_KEYS, ctx)
    if "name" not in raw:
        r.fail(ctx, "a link needs a 'name'")
    name = r.text(raw["name"], f"{ctx}.name")
    row_line = r.line_of(ctx)
    ctx = f"{ctx} ('{name}')"
    if row_line:
        r.lines[ctx] = row_line
    r.remember_lines(raw, ctx)
    j = r.check_keys(raw.get("joint", {"type": "fixed"}), _JOINT_KEYS, f"{ctx}.joint")
    kind = j.get("type", "revolute")
    if kind not in ("revolute", "continuous", "prismatic", "fixed"):
        r.fail(f"{ctx}.joint.type", f"must be revolute, continuous, prismatic or fixed, got {SHORT_REPR.repr(kind)}")
    revolute = kind in ("revolute", "continuous")
    offset_reader = r.angle if revolute else r.value
    joint = Joint(
        name=r.text(j.get("name", f"{name}_joint"), f"{ctx}.joint.name"),
        kind=kind,
        axis=r.vector(j.get("axis", [0, 0, 1]), f"{ctx}.joint.axis"),
        offset=offset_reader(j.get("offset", 0.0), f"{ctx}.joint.offset"),
        **r.limits(j.get("limits", {}), revolute, f"{ctx}.joint.limits"),
        **r.drive(j, f"{ctx}.joint"),
        mimic=_mimic(r, j["mimic"], f"{ctx}.joint.mimic") if "mimic" in j else None,
    )
    placement = r.pose(j["origin"], f"{ctx}.joint.origin") if "origin" in j else np.eye(4)
    post = r.pose(raw["post"], f"{ctx}.post") if "post" in raw else np.eye(4)
    inertial = r.check_keys(raw.get("inertial", {}), _INERTIAL_KEYS, f"{ctx}.inertial")
    parent = r.text(raw["parent"], f"{ctx}.parent") if raw.get("parent") is not None else None
    return Link(name, parent, joint, placement, post, r.inertia(inertial, f"{ctx}.inertial"))


def _mimic(r, raw, ctx: str):
    """``mimic: {joint: leader, multiplier: m, offset: o}`` (multiplier 1 and offset 0 by default)."""
    m = r.check_keys(raw, _MIMIC_KEYS, ctx)
    if "joint" not in m:
        r.fail(ctx, "needs 'joint': the name of the joint it follows")
    values = [r.value(m.get(k, default), f"{ctx}.{k}") for k, default in (("multiplier", 1.0), ("offset", 0.0))]
    try:
        return Mimic(r.text(m["joint"], f"{ctx}.joint"), *values)
    except ValueError as e:
        r.fail(ctx, str(e))


def _kind(raw) -> str:
    """A short description of a value from a file, for messages (never its whole text)."""
    kind = "mapping" if isinstance(raw, dict) else "list" if isinstance(raw, list) else type(raw).__name__
    return (
        f"{kind} {SHORT_REPR.repr(dict(raw) if isinstance(raw, dict) else list(raw) if isinstance(raw, list) else raw)}"
    )
