"""Robot files: ``load(path)`` by extension (URDF, YAML, TOML) and ``save(robot, path)`` (YAML, TOML).

The YAML/TOML format (docs/model-files.md) has two flavours:

- DH-based, with a ``joints:`` list of DH rows (``convention: standard|modified``);
- tree-based, with a ``links:`` list of links, each with its joint and inertial data.

Both share ``name``, ``gravity``, ``units: {angle: deg|rad}``, ``frames:`` and ``source``. A string
that is not a number becomes a SymPy expression (``"l1"``, ``"m1*l1**2/12"``). ``save`` writes a
robot with a DH table as DH and any other robot as a tree, always in radians, so that ``load``
gives back the same kinematics, inertias and limits.
"""

from __future__ import annotations

import math
import os
import re
import reprlib
import sys
from typing import TYPE_CHECKING, NoReturn

import numpy as np
import sympy as sp
import tomli_w

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10 (requires-python): tomllib is tomli, in the standard library since 3.11
    import tomli as tomllib
import yaml

from .._math import is_symbolic, matmul, pose_inverse, rpy_to_matrix, translation
from .dh import DHRow, links_from_dh
from .expressions import parse_expression
from .inertia import Inertia
from .joint import Joint
from .link import Frame, Link

if TYPE_CHECKING:
    from .._typing import PathLike
    from ..robot import Robot

__all__ = ["load", "save", "robot_from_mapping", "robot_to_mapping"]

_TOP_COMMON = {"name", "gravity", "units", "frames", "source", "visuals"}
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
_VISUAL_KEYS = {"link", "origin", "color", "mesh", "scale", "box", "cylinder", "sphere"}
_SHAPE_KEYS = ("mesh", "box", "cylinder", "sphere")
_TENSOR_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")

# Bounds on a robot file, so that a small hostile file cannot ask for unbounded time or memory
MAX_FILE_BYTES = 16 * 2**20  # a robot file is text a person writes: 16 MiB is far beyond any robot
MAX_NESTING = 32  # mappings and lists inside each other (a robot file needs 5)
MAX_NODES = 1_000_000  # YAML nodes composed, counting every use of an alias as the nodes it repeats
MAX_TEXT = 1000  # characters of a name or other text field
_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxstring, _REPR.maxother, _REPR.maxlist, _REPR.maxdict = 2, 40, 40, 4, 4


# ============================================================================ public functions
def load(path: PathLike, inertia: str = "warn", **kwargs) -> Robot:
    """A robot from ``.urdf`` (``kwargs``: gravity, tool), ``.xml``/``.mjcf`` (MuJoCo; the same
    ``kwargs``), ``.xacro`` (expanded to URDF; ``kwargs`` also ``xacro_args``, ``trust_xacro``,
    ``package_dirs``: see :meth:`kinedyn.Robot.from_urdf`), ``.yaml``/``.yml`` or ``.toml`` (``kwargs``
    replace constructor arguments, e.g. ``gravity=``). ``inertia`` is the policy for inertia tensors
    no rigid body has: "warn" (keep, with a PhysicalConsistencyWarning), "repair" (project onto the
    nearest consistent tensor) or "strict" (raise); see docs/model-files.md."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".xacro":  # robot.urdf.xacro; kwargs: xacro_args, trust_xacro, package_dirs, gravity, tool
        from ..robot import Robot

        return Robot.from_urdf(path, inertia=inertia, **kwargs)
    if ext == ".urdf":
        from .urdf import robot_from_urdf

        return robot_from_urdf(path, inertia=inertia, **kwargs)
    if ext in (".xml", ".mjcf"):
        from .mjcf import robot_from_mjcf

        return robot_from_mjcf(path, inertia=inertia, **kwargs)
    if ext not in (".yaml", ".yml", ".toml"):
        raise ValueError(
            f"{path}: unknown robot file extension '{ext}' (expected .urdf, .xacro, .xml (MJCF), .yaml, .yml or .toml)"
        )
    text = _read_text(path)
    data = _parse_toml(text, path) if ext == ".toml" else _parse_yaml(text, path)
    robot = robot_from_mapping(data, where=path, inertia=inertia)
    return robot.replace(**kwargs) if kwargs else robot


def save(robot: Robot, path: PathLike) -> None:
    """Write ``robot`` to a ``.yaml``/``.yml`` or ``.toml`` robot file (angles in radians)."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    data = robot_to_mapping(robot)
    if ext in (".yaml", ".yml"):
        text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=120)
    elif ext == ".toml":
        text = tomli_w.dumps(data)
    else:
        raise ValueError(f"{path}: can only save robots as .yaml, .yml or .toml, not '{ext}'")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def _read_text(path: str) -> str:
    """The file's text, refusing files too large to be a robot description before reading them."""
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)
    except OSError as e:
        raise ValueError(f"{path}: cannot read robot file ({e.strerror or e})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ValueError(f"{path}: the file is larger than {MAX_FILE_BYTES // 2**20} MiB, too large for a robot file")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ValueError(f"{path}: the file is not UTF-8 text (byte {e.start})") from None


# ---------------------------------------------------------------- YAML, bounded
class _LineDict(dict):
    """A mapping read from YAML that remembers the line of each key (1-based), for messages."""

    lines: dict


class _LineList(list):
    """A list read from YAML that remembers the line of each item (1-based), for messages."""

    lines: list


class _BoundedLoader(yaml.SafeLoader):
    """PyYAML's safe loader (plain data only: no Python objects) with three changes:

    - nesting deeper than ``MAX_NESTING`` is an error (PyYAML's composer recurses);
    - the size of the document is bounded with every alias counted as the nodes it repeats, so a
      small file of aliases to aliases (a "billion laughs") fails at once instead of filling memory;
    - a key given twice in one mapping is an error (YAML 1.2 forbids it; PyYAML keeps the last).
    """

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0
        self._expanded = 0  # nodes composed so far, aliases counted as what they repeat
        self._size_of: dict = {}  # id(anchored node) -> its expanded size

    def _refuse(self, problem: str, mark):
        raise yaml.composer.ComposerError(None, None, problem, mark)

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            node = self.anchors.get(event.anchor)
            if node is not None:
                if id(node) not in self._size_of:
                    self._refuse(f"the alias *{event.anchor} refers to a node that contains it", event.start_mark)
                self._count(self._size_of[id(node)], event.start_mark)
            return super().compose_node(parent, index)
        self._depth += 1
        if self._depth > MAX_NESTING:
            self._refuse(f"mappings and lists are nested more than {MAX_NESTING} deep", event.start_mark)
        before = self._expanded
        self._count(1, event.start_mark)
        node = super().compose_node(parent, index)
        self._depth -= 1
        self._size_of[id(node)] = self._expanded - before
        return node

    def _count(self, nodes: int, mark):
        self._expanded += nodes
        if self._expanded > MAX_NODES:
            self._refuse(
                f"the document expands to more than {MAX_NODES} values (aliases counted as what they repeat)", mark
            )

    def construct_line_mapping(self, node):
        data = _LineDict()
        data.lines = {}
        yield data
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":  # "<<: *anchor": merged keys may be overridden
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                repeated = key in data.lines
            except TypeError:
                raise yaml.constructor.ConstructorError(
                    None, None, "a mapping key must be a plain value", key_node.start_mark
                ) from None
            if repeated:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"the key {_REPR.repr(key)} appears twice in one mapping (first on line {data.lines[key]})",
                    key_node.start_mark,
                )
            data.lines[key] = key_node.start_mark.line + 1
        data.update(self.construct_mapping(node, deep=True))

    def construct_line_sequence(self, node):
        data = _LineList()
        data.lines = [item.start_mark.line + 1 for item in node.value]
        yield data
        data.extend(self.construct_sequence(node, deep=True))


def _refuse_tag(loader, node):
    raise yaml.constructor.ConstructorError(
        None,
        None,
        f"the YAML type {node.tag.rsplit(':', 1)[-1]} ({_REPR.repr(node.value) if isinstance(node.value, str) else '...'}) "
        "has no meaning in a robot file (numbers, text, lists and mappings only)",
        node.start_mark,
    )


# a robot file holds numbers, text, lists and mappings: YAML's other types (dates, which PyYAML's
# constructor can also fail on with an AttributeError, binary, sets, ordered pairs) are refused
for _tag in ("timestamp", "binary", "set", "omap", "pairs"):
    _BoundedLoader.add_constructor(f"tag:yaml.org,2002:{_tag}", _refuse_tag)
_BoundedLoader.add_constructor("tag:yaml.org,2002:map", _BoundedLoader.construct_line_mapping)
_BoundedLoader.add_constructor("tag:yaml.org,2002:seq", _BoundedLoader.construct_line_sequence)


def _parse_yaml(text: str, where: str):
    loader = None
    try:
        loader = _BoundedLoader(text)  # its reader already refuses control characters
        return loader.get_single_data()
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        line = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "unknown line"
        raise ValueError(f"{where}: invalid YAML at {line}: {e.problem or e.context}") from None
    except yaml.reader.ReaderError as e:  # a character YAML does not allow (NUL, other control characters)
        line_no = text.count("\n", 0, e.position) + 1
        shown = chr(e.character) if isinstance(e.character, int) else e.character
        raise ValueError(
            f"{where}: invalid YAML at line {line_no}: the character {shown!r} is not allowed in YAML"
        ) from None
    except yaml.YAMLError as e:
        raise ValueError(f"{where}: invalid YAML: {e}") from None
    finally:
        if loader is not None:
            loader.dispose()


_TOML_STRING_OR_COMMENT = re.compile(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:\\.|[^"\\\n])*"|\'[^\'\n]*\'|#[^\n]*')
_TOML_KEY = re.compile(r"(?:^|[{,])([^={},\[\]\n]*)=|^\s*\[\[?([^\]\n]*)\]", re.M)


def _toml_key_depth(text: str) -> int:
    """The most parts of one dotted key (``a.b.c`` has 3) in TOML text. tomllib's time grows with the
    square of a key's parts, so this linear scan runs first; strings and comments are blanked so
    that their dots do not count, and a float's dot is never in a key position."""
    bare = _TOML_STRING_OR_COMMENT.sub("s", text)
    return max((1 + (m.group(1) or m.group(2) or "").count(".") for m in _TOML_KEY.finditer(bare)), default=0)


def _parse_toml(text: str, where: str):
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
        if isinstance(container, _LineDict):
            for key, line in container.lines.items():
                self.lines.setdefault(f"{ctx}.{key}" if ctx else str(key), line)
        elif isinstance(container, _LineList):
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
                self.fail(ctx, f"unknown key {_REPR.repr(key)} (known keys: {', '.join(sorted(known))})")
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
        if isinstance(v, sp.Basic):
            self.fail(ctx, f"must be a number, got the expression '{_REPR.repr(raw)[1:-1]}'")
        return v

    def angle(self, raw, ctx: str):
        v = self.value(raw, ctx)
        if not self.deg:
            return v
        return v * sp.pi / 180 if isinstance(v, sp.Basic) else v * math.pi / 180

    def vector(self, raw, ctx: str, n: int = 3, angles: bool = False) -> tuple:
        if not isinstance(raw, (list, tuple)) or len(raw) != n:
            self.fail(ctx, f"expected a list of {n} values, got {_REPR.repr(raw)}")
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
                if not isinstance(v, sp.Basic) and v < 0:
                    self.fail(
                        f"{ctx}.coulomb[{i}]",
                        f"a Coulomb level is a magnitude >= 0, got {v} (Corke's Tc = [Tc+, Tc-] with Tc- < 0 is written [Tc+, -Tc-])",
                    )
            out["coulomb"] = levels
        return out


def robot_from_mapping(data, where: str = "<robot mapping>", inertia: str = "warn"):
    """A robot from the parsed contents of a YAML/TOML robot file (see docs/model-files.md)."""
    r = _Reader(where)
    if not isinstance(data, dict):
        raise ValueError(f"{where}: a robot file must hold a mapping at the top level, got {type(data).__name__}")
    if ("joints" in data) == ("links" in data):
        raise ValueError(f"{where}: a robot file needs exactly one of 'joints' (DH table) or 'links' (tree)")
    dh = "joints" in data
    r.check_keys(data, _TOP_DH if dh else _TOP_TREE, "top level")
    units = r.check_keys(data.get("units", {}), {"angle"}, "units")
    if units.get("angle", "rad") not in ("deg", "rad"):
        r.fail("units.angle", f"must be 'deg' or 'rad', got {_REPR.repr(units['angle'])}")
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
        robot = _dh_robot(r, data, common, frames) if dh else _tree_robot(r, data, common, frames)
        if visuals:
            unknown = sorted({v.frame for v in visuals} - set(robot.frame_names))
            if unknown:
                r.fail("visuals", f"names links {unknown} that the robot does not have (frames: {robot.frame_names})")
            robot = robot.replace(visuals=visuals)
        return robot
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


def _visuals(r: _Reader, raw, where: str) -> list:
    """``visuals:`` [{link, mesh|box|cylinder|sphere, scale, origin, color}] (docs/visualisation.md)."""
    from .geometry import Box, Cylinder, Mesh, Sphere, Visual

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
                r.text(v["link"], f"{ctx}.link"), shape, np.asarray(origin, dtype=float), rgba, None, f"{where} {ctx}"
            )
        )  # type: ignore[arg-type]
    return out


def _dh_robot(r: _Reader, data: dict, common: dict, frames: list):
    from ..robot import Robot

    convention = data.get("convention", "standard")
    if convention not in ("standard", "modified"):
        r.fail("convention", f"must be 'standard' or 'modified', got {_REPR.repr(convention)}")
    joints = r.items(data["joints"], "joints", "DH rows", lambda i: f"joints row {i + 1}")
    if not joints:
        r.fail("joints", "expected a non-empty list of DH rows")
    rows = [_dh_row(r, row, i) for i, row in enumerate(joints)]
    base_pose = r.pose(data["base_pose"], "base_pose") if "base_pose" in data else None
    tool = r.pose(data["tool"], "tool") if "tool" in data else None
    robot = Robot.from_dh(rows, convention, base_pose=base_pose, tool=tool, **common)
    if frames or "tool_frame" in data:
        tool_frame = r.text(data["tool_frame"], "tool_frame") if "tool_frame" in data else "tool"
        robot = robot.replace(frames=robot.frames + tuple(frames), tool=tool_frame)
    return robot


def _dh_row(r: _Reader, row, i: int) -> DHRow:
    ctx = f"joints row {i + 1}"
    row = r.check_keys(row, _ROW_KEYS, ctx)
    kind = row.get("type", "revolute")
    if kind not in ("revolute", "prismatic"):
        r.fail(f"{ctx}.type", f"must be 'revolute' or 'prismatic', got {_REPR.repr(kind)}")
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


def _tree_robot(r: _Reader, data: dict, common: dict, frames: list):
    from ..robot import Robot

    raw_links = r.items(data["links"], "links", "links", lambda i: f"links row {i + 1}")
    if not raw_links:
        r.fail("links", "expected a non-empty list of links")
    links = [_tree_link(r, link, i) for i, link in enumerate(raw_links)]
    tool = data.get("tool")
    if tool is not None and not isinstance(tool, str):
        r.fail("tool", "in a tree-based file 'tool' names a frame or link")
    return Robot(links, frames, base=r.text(data.get("base", "base"), "base"), tool=tool, **common)


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
        r.fail(f"{ctx}.joint.type", f"must be revolute, continuous, prismatic or fixed, got {_REPR.repr(kind)}")
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


# ============================================================================ writing a mapping
def robot_to_mapping(robot: Robot) -> dict:
    """The YAML/TOML contents for ``robot``: DH flavour when it has a consistent DH table."""
    data: dict = {"name": robot.name, "gravity": [_dump(g) for g in robot.gravity]}
    if robot.source:
        data["source"] = robot.source
    base_pose = _dh_base_pose(robot)
    if base_pose is not None:
        data.update(_dh_mapping(robot, base_pose))
    else:
        data.update(_tree_mapping(robot))
    if robot.visuals:
        data["visuals"] = [_visual_mapping(v) for v in robot.visuals]
    return data


def _visual_mapping(v) -> dict:
    from .geometry import Box, Cylinder, Mesh

    out: dict = {"link": v.frame}
    s = v.shape
    if isinstance(s, Mesh):
        out["mesh"] = (
            s.filename
            if s.base_dir is None or "://" in s.filename or os.path.isabs(s.filename)
            else os.path.join(s.base_dir, s.filename)
        )
        out["scale"] = [float(x) for x in s.scale]
    elif isinstance(s, Box):
        out["box"] = [float(x) for x in s.size]
    elif isinstance(s, Cylinder):
        out["cylinder"] = {"radius": float(s.radius), "length": float(s.length)}
    else:
        out["sphere"] = float(s.radius)
    T = np.asarray(v.origin, dtype=float)
    if not np.allclose(T, np.eye(4)):
        out["origin"] = {"xyz": [float(x) for x in T[:3, 3]], "rpy": [float(x) for x in _rpy(T[:3, :3])]}
    if v.rgba is not None:
        out["color"] = [float(x) for x in v.rgba]
    return out


def _dump(v):
    if isinstance(v, sp.Basic):
        return float(v) if not v.free_symbols else str(v)
    return float(v)


def _rpy(R) -> list:
    """Inverse of rpy_to_matrix: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    R = np.asarray(R, dtype=float)
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    if math.hypot(R[0, 0], R[1, 0]) < 1e-12:  # gimbal lock: put everything in yaw
        angles = [0.0, pitch, math.atan2(-R[0, 1], R[1, 1])]
    else:
        angles = [math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0])]
    return [a + 0.0 for a in angles]  # no -0.0 in files


def _is_identity(T) -> bool:
    if is_symbolic(T):
        return sp.Matrix(T) == sp.eye(4)
    return np.allclose(np.asarray(T, dtype=float), np.eye(4), atol=1e-15)


def _pose_mapping(T, what: str) -> dict:
    T = sp.Matrix(T) if is_symbolic(T) else np.asarray(T, dtype=float)
    if is_symbolic(T[:3, :3]):
        raise ValueError(f"cannot save {what}: its rotation is symbolic (only translations may hold symbols)")
    R = np.array(sp.Matrix(T[:3, :3]).tolist(), dtype=float) if isinstance(T, sp.MatrixBase) else T[:3, :3]
    return {"xyz": [_dump(T[i, 3]) for i in range(3)], "rpy": _rpy(R)}


def _same_pose(A, B) -> bool:
    if is_symbolic(A) or is_symbolic(B):
        return sp.simplify(sp.Matrix(A) - sp.Matrix(B)) == sp.zeros(4, 4)
    return np.allclose(np.asarray(A, dtype=float), np.asarray(B, dtype=float), atol=1e-12)


def _dh_base_pose(robot: Robot):
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


def _dh_mapping(robot: Robot, base_pose) -> dict:
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


def _mimic(r, raw, ctx: str):
    """``mimic: {joint: leader, multiplier: m, offset: o}`` (multiplier 1 and offset 0 by default)."""
    from .joint import Mimic

    m = r.check_keys(raw, _MIMIC_KEYS, ctx)
    if "joint" not in m:
        r.fail(ctx, "needs 'joint': the name of the joint it follows")
    values = [r.value(m.get(k, default), f"{ctx}.{k}") for k, default in (("multiplier", 1.0), ("offset", 0.0))]
    try:
        return Mimic(r.text(m["joint"], f"{ctx}.joint"), *values)
    except ValueError as e:
        r.fail(ctx, str(e))


def _tree_mapping(robot: Robot) -> dict:
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


def _kind(raw) -> str:
    """A short description of a value from a file, for messages (never its whole text)."""
    kind = "mapping" if isinstance(raw, dict) else "list" if isinstance(raw, list) else type(raw).__name__
    return f"{kind} {_REPR.repr(dict(raw) if isinstance(raw, dict) else list(raw) if isinstance(raw, list) else raw)}"
