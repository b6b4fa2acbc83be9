"""Hypothesis strategies for the fuzzer: mutations of real robot files and hostile numeric calls.

A file case starts from a real text (:mod:`fuzz.corpus`) and applies one to three mutations, each
recorded in ``Case.ops`` as one readable line, so that a failing case says what was done to which
file. The mutations are of three levels:

- bytes/characters: truncation, inserted or flipped bytes, invalid UTF-8, NUL;
- tokens: a number replaced by a hostile number (NaN, inf, 1e200, a 400-digit integer, ...), a
  string by a hostile expression ('9**9**9', 'factorial(10**7)', a chr-built exec canary, 5,000
  nested parentheses, ...), lines deleted, duplicated (duplicate keys) or swapped;
- structure: the parsed file (XML tree, YAML/TOML mapping) with an element deleted or duplicated,
  a value of the wrong type, a cycle in the parent links, an unknown joint type, a chain of up to
  3,000 fixed links, YAML alias bombs, names nested 5,000 deep.

An array case (:func:`array_cases`) calls one public numeric method of ``kd.Robot`` (or
``kd.simulate``) on a built-in or URDF robot, with arguments that are valid except for one or two
mutated ones: wrong shapes, dtypes (complex, object, strings), NaN/inf, huge finite values (1e154,
1e200, 1e300), empty batches, batch/single mixes, f_ext and out= of the wrong shape, non-contiguous
or read-only arrays, and hostile keyword values.
"""

from __future__ import annotations

import copy
import functools
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any

import numpy as np
import tomli_w
import yaml
from hypothesis import strategies as st

from . import corpus

# ============================================================================ the case
CANARY_ENV = "KD_FUZZ_PWNED"  # set by a successful code-execution payload
MARKER_ENV = "KD_FUZZ_MARKER"  # path of the marker file a successful payload creates


@dataclass
class Case:
    """One fuzz input. File cases carry ``data`` (str or bytes, written to a file of extension
    ``kind``); array cases carry ``call = (robot_spec, method, args, kwargs)``."""

    kind: str  # "urdf" | "yaml" | "toml" | "arrays"
    seed: str  # the seed file or the robot
    ops: tuple  # readable description of each mutation
    data: Any = None
    call: tuple | None = None
    index: int = -1  # position in the generated list (set by the runner)
    valid: bool = False  # the input is valid as documented: any error is a defect (valid input rejected)

    @property
    def ext(self) -> str:
        return {"urdf": ".urdf", "yaml": ".yaml", "toml": ".toml", "mjcf": ".xml"}.get(self.kind, ".pkl")


def _canary(function: str = "exec") -> str:
    """A robot-file expression made only of letters, digits, '(', ')' and '+' that, if evaluated as
    Python, runs code which sets $KD_FUZZ_PWNED and writes the file named by $KD_FUZZ_MARKER
    (``exec`` of statements, or ``eval`` of one expression doing the same)."""
    if function == "exec":
        code = f"import os;os.environ['{CANARY_ENV}']='1';open(os.environ['{MARKER_ENV}'],'w').write('pwned')"
    else:
        code = (
            f"(__import__('os').environ.__setitem__('{CANARY_ENV}','1'),"
            f"open(__import__('os').environ['{MARKER_ENV}'],'w').write('pwned'))"
        )
    return f"{function}(" + "+".join(f"chr({ord(c)})" for c in code) + ")"


CANARY = _canary("exec")

# ============================================================================ hostile values
DEEP = 5000
HOSTILE_NUMBER_TEXT = (
    "nan",
    "NaN",
    ".nan",
    "inf",
    "-inf",
    ".inf",
    "-.inf",
    "Infinity",
    "1e200",
    "-1e200",
    "1e308",
    "1e309",
    "-1e309",
    "1e300",
    "1e154",
    "-1e154",
    "1e-320",
    "5e-324",
    "0",
    "-0.0",
    "-1",
    "-1e-9",
    "4" * 400,
    "-" + "9" * 400,
    "1e99999",
    "1e",
    "0x1F",
    "1_000",
    "",
    " ",
    "1 2",
    "1,5",
    "--1",
    "+-1",
    "1e200 1e200 1e200",
    "nan nan nan",
    "0 0 0 0",
    "1" * 20 + ".5",
)
HOSTILE_EXPRESSIONS = (
    "9**9**9",
    "factorial(10**7)",
    "__import__('os')",
    "x.y",
    "sqrt(-1)",
    "(" * DEEP + "1" + ")" * DEEP,
    "-" * DEEP + "1",
    "1/0",
    "zoo",
    "oo",
    "-oo",
    "nan",
    "E**1000",
    "10**400",
    "2**-100000",
    "exp(10**6)",
    "Integer(10)**(10**8)",
    "l1**l2**l3**l4**l5",
    CANARY,
    _canary("eval"),
    "lambda: 1",
    "[1]*10**9",
    "'a'*10**10",
    "x" * 100_000,
    "a+" * 20_000 + "a",
    "Symbol('x')",
    "sin",
    "pi",
    "I",
    "E",
    "S",
    "Q",
    "N",
    "True",
    "None",
    "1e200*1e200",
    "(-1)**0.5",
    "0**-1",
    "log(0)",
    "gamma(10**10)",
    "x if y else z",
    "a;b",
    "`x`",
    "{}",
    "[]",
    "10**10**10",
    "2**(2**(2**(2**9)))",
    "binomial(10**9, 10**8)",
    "primepi(10**12)",
    "Float('1e100000')",
    "m1*l1**2/12",
    "l1 - lc1",
    "-g",
    "1" * 5000,
)
HOSTILE_NAMES = (
    "",
    " ",
    "a" * 10_000,
    "<!--<script>",
    "</script><script>alert(1)</script>",
    "名前",
    "base_link",
    "world",
    "tool",
    "a b",
    "a/b",
    "..",
    "a\tb",
    "{{x}}",
    "${HOME}",
    "%s%n",
)
HOSTILE_JOINT_TYPES = (
    "spherical",
    "floating",
    "planar",
    "screw",
    "REVOLUTE",
    "Revolute",
    "",
    "revolute ",
    "prismatic",
    "continuous",
    "fixed",
    "revolute_x",
    "ball",
    "free",
)
# values of the wrong type or range, for a parsed YAML/TOML value
HOSTILE_VALUES = (
    float("nan"),
    float("inf"),
    -float("inf"),
    1e200,
    -1e200,
    1e300,
    1e154,
    5e-324,
    10**400,
    -(10**400),
    2**64,
    -1,
    0,
    -0.0,
    True,
    None,
    [],
    {},
    [1, 2],
    [[1, 2], [3]],
    {"a": 1},
    "",
    "nan",
    [float("nan")] * 3,
    [1e200] * 3,
    [0.0] * 2,
    [0.0] * 4,
    ["x", "y", "z"],
    {"xyz": [0, 0, 0]},
    [[0.0] * 3] * 3,
)
XML_ENTITY_BOMB = (
    '<?xml version="1.0"?>\n<!DOCTYPE robot [\n <!ENTITY a "aaaaaaaaaa">\n'
    + "".join(f' <!ENTITY {c} "{("&" + p + ";") * 10}">\n' for p, c in zip("abcdefgh", "bcdefghi"))
    + "]>\n"
)


def yaml_alias_bomb(levels: int, fan: int = 9) -> str:
    """A YAML flow value whose alias expansion has fan**levels leaves (the 'billion laughs')."""
    parts = ["&a0 [" + ", ".join(["lol"] * fan) + "]"]
    for i in range(1, levels):
        parts.append(f"&a{i} [" + ", ".join([f"*a{i - 1}"] * fan) + "]")
    return "[" + ", ".join(parts) + "]"


# ============================================================================ text-level mutations
_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")
_QUOTED = re.compile(r"\"([^\"\n]*)\"|'([^'\n]*)'")


def _pick(draw, n: int, label: str) -> int:
    return draw(st.integers(0, n - 1), label=label) if n > 1 else 0


def _as_text(data) -> str:
    return data if isinstance(data, str) else data.decode("utf-8", "replace")


def op_replace_number(draw, data, kind):
    text = _as_text(data)
    matches = list(_NUMBER.finditer(text))
    if not matches:
        return data, None
    m = matches[_pick(draw, len(matches), "number")]
    new = draw(st.sampled_from(HOSTILE_NUMBER_TEXT))
    if kind != "urdf" and draw(st.booleans()):
        new = f"'{new}'" if kind == "yaml" else f'"{new}"'
    return text[: m.start()] + new + text[m.end() :], f"number '{m.group()}' at offset {m.start()} -> {_short(new)}"


def op_replace_quoted(draw, data, kind):
    """A quoted string (XML attribute value, YAML/TOML string) -> a hostile expression or name."""
    text = _as_text(data)
    matches = list(_QUOTED.finditer(text))
    if not matches:
        return data, None
    m = matches[_pick(draw, len(matches), "string")]
    new = draw(st.sampled_from(HOSTILE_EXPRESSIONS + HOSTILE_NAMES))
    quote = m.group()[0]
    if kind == "urdf":
        body = new.replace("&", "&amp;").replace("<", "&lt;").replace('"', "&quot;").replace("'", "&apos;")
    elif quote == "'" and kind == "yaml":
        body = new.replace("'", "''")
    else:  # a double-quoted YAML or TOML string (TOML literal strings cannot hold a quote)
        quote = '"'
        body = new.replace("\\", "\\\\").replace('"', '\\"')
    text = text[: m.start()] + quote + body + quote + text[m.end() :]
    return text, f"string {_short(m.group())} at offset {m.start()} -> {_short(new)}"


def op_yaml_scalar(draw, data, kind):
    """A YAML plain scalar after 'key: ' -> a hostile expression (unquoted or quoted)."""
    text = _as_text(data)
    matches = list(re.finditer(r"(?m)(^\s*-?\s*\w+: |[{,] ?\w+: )([^\s,{}\[\]][^,{}\[\]\n]*)", text))
    if not matches:
        return data, None
    m = matches[_pick(draw, len(matches), "scalar")]
    new = draw(st.sampled_from(HOSTILE_EXPRESSIONS))
    new_text = "'" + new.replace("'", "''") + "'"
    return text[: m.start(2)] + new_text + text[
        m.end(2) :
    ], f"scalar {_short(m.group(2))} after {_short(m.group(1).strip())} -> {_short(new)}"


def op_truncate(draw, data, kind):
    n = len(data)
    if n < 2:
        return data, None
    at = draw(st.integers(0, n - 1), label="truncate")
    return data[:at], f"truncated at {at} of {n}"


def op_bytes(draw, data, kind):
    raw = data.encode("utf-8") if isinstance(data, str) else data
    at = draw(st.integers(0, max(len(raw) - 1, 0)), label="byte offset")
    how = draw(st.sampled_from(("insert", "flip", "delete", "nul", "invalid-utf8", "bom", "crlf")))
    if not raw and how in ("flip", "delete"):
        how = "insert"
    if how == "insert":
        blob = draw(st.binary(min_size=1, max_size=8))
        return raw[:at] + blob + raw[at:], f"inserted bytes {blob!r} at {at}"
    if how == "flip":
        bit = draw(st.integers(0, 7))
        return raw[:at] + bytes([raw[at] ^ (1 << bit)]) + raw[at + 1 :], f"flipped bit {bit} of byte {at}"
    if how == "delete":
        k = draw(st.integers(1, 16))
        return raw[:at] + raw[at + k :], f"deleted {k} bytes at {at}"
    if how == "nul":
        return raw[:at] + b"\x00" + raw[at:], f"inserted NUL at {at}"
    if how == "invalid-utf8":
        return raw[:at] + b"\xff\xfe\xc3" + raw[at:], f"inserted invalid UTF-8 at {at}"
    if how == "bom":
        return b"\xef\xbb\xbf" + raw, "UTF-8 byte-order mark prepended"
    return raw.replace(b"\n", b"\r\n"), "line ends -> CRLF"


def _lines(data):
    return _as_text(data).split("\n")


def op_lines(draw, data, kind):
    lines = _lines(data)
    if len(lines) < 2:
        return data, None
    i = _pick(draw, len(lines), "line")
    how = draw(st.sampled_from(("delete", "duplicate", "swap", "repeat")))
    if how == "delete":
        k = draw(st.integers(1, 5))
        del lines[i : i + k]
        return "\n".join(lines), f"deleted lines {i + 1}-{i + k}"
    if how == "duplicate":
        lines.insert(i, lines[i])
        return "\n".join(lines), f"duplicated line {i + 1}: {_short(lines[i].strip())}"
    if how == "repeat":
        k = draw(st.sampled_from((2, 10, 1000)))
        lines[i : i + 1] = [lines[i]] * k
        return "\n".join(lines), f"line {i + 1} repeated {k} times: {_short(lines[i].strip())}"
    j = _pick(draw, len(lines), "other line")
    lines[i], lines[j] = lines[j], lines[i]
    return "\n".join(lines), f"swapped lines {i + 1} and {j + 1}"


# ============================================================================ URDF structure
def _xml(data):
    try:
        return ET.fromstring(_as_text(data))
    except ET.ParseError:
        return None


def _xml_text(root) -> str:
    return ET.tostring(root, encoding="unicode")


def op_urdf_tree(draw, data, kind):
    root = _xml(data)
    if root is None:
        return data, None
    elements = [(parent, child) for parent in root.iter() for child in parent]
    joints = root.findall("joint")
    links = [l.get("name") for l in root.findall("link") if l.get("name")]
    how = draw(
        st.sampled_from(
            (
                "delete",
                "duplicate",
                "attribute",
                "drop-attribute",
                "joint-type",
                "cycle",
                "self-parent",
                "dangling",
                "fixed-chain",
                "deep-nesting",
                "entity-bomb",
                "empty-robot",
                "swap-limits",
                "add-dynamics",
            )
        )
    )
    if how in ("delete", "duplicate", "attribute", "drop-attribute") and elements:
        parent, child = elements[_pick(draw, len(elements), "element")]
        where = f"<{child.tag} {_short(str(child.attrib), 60)}>"
        if how == "delete":
            parent.remove(child)
            return _xml_text(root), f"deleted {where}"
        if how == "duplicate":
            parent.append(copy.deepcopy(child))
            return _xml_text(root), f"duplicated {where}"
        if not child.attrib:
            return data, None
        keys = sorted(child.attrib)
        key = keys[_pick(draw, len(keys), "attribute")]
        if how == "drop-attribute":
            del child.attrib[key]
            return _xml_text(root), f"removed attribute {key} of {where}"
        new = draw(st.sampled_from(HOSTILE_NUMBER_TEXT + HOSTILE_EXPRESSIONS + HOSTILE_NAMES))
        child.set(key, new)
        return _xml_text(root), f"{where} {key} -> {_short(new)}"
    if how == "joint-type" and joints:
        j = joints[_pick(draw, len(joints), "joint")]
        new = draw(st.sampled_from(HOSTILE_JOINT_TYPES))
        old = j.get("type")
        j.set("type", new)
        return _xml_text(root), f"joint '{j.get('name')}' type {old} -> {new!r}"
    if how in ("cycle", "self-parent", "dangling") and joints:
        j = joints[_pick(draw, len(joints), "joint")]
        p, c = j.find("parent"), j.find("child")
        if p is None or c is None:
            return data, None
        if how == "cycle":  # the parent of a joint becomes a link below it (its child or the last link)
            target = draw(st.sampled_from((c.get("link"), links[-1] if links else c.get("link"))))
        elif how == "self-parent":
            target = p.get("link")
            c.set("link", target)
            return _xml_text(root), f"joint '{j.get('name')}' child -> its parent '{target}'"
        else:
            target = draw(st.sampled_from(("no_such_link", "", "a" * 5000)))
        p.set("link", target)
        return _xml_text(root), f"joint '{j.get('name')}' parent -> {_short(target)}"
    if how in ("swap-limits", "add-dynamics") and joints:
        j = joints[_pick(draw, len(joints), "joint")]
        if how == "swap-limits":
            limit = j.find("limit")
            if limit is None:
                limit = ET.SubElement(j, "limit", effort="10", velocity="1")
            limit.set("lower", "1.0")
            limit.set("upper", "-1.0")
            return _xml_text(root), f"joint '{j.get('name')}' limit lower 1 > upper -1"
        dyn = j.find("dynamics")
        if dyn is None:
            dyn = ET.SubElement(j, "dynamics")
        key = draw(st.sampled_from(("damping", "friction")))
        new = draw(st.sampled_from(HOSTILE_NUMBER_TEXT))
        dyn.set(key, new)
        return _xml_text(root), f"joint '{j.get('name')}' <dynamics {key}={new!r}>"
    if how == "fixed-chain" and links:
        k = draw(st.sampled_from((1, 10, 100, 2000, 3000)))
        last = links[-1]
        for i in range(k):
            ET.SubElement(root, "link", name=f"fz_fixed_{i}")
            jt = ET.SubElement(root, "joint", name=f"fz_fixed_joint_{i}", type="fixed")
            ET.SubElement(jt, "parent", link=last if i == 0 else f"fz_fixed_{i - 1}")
            ET.SubElement(jt, "child", link=f"fz_fixed_{i}")
            ET.SubElement(jt, "origin", xyz="0 0 0.01", rpy="0 0 0")
        return _xml_text(root), f"{k} fixed links appended after '{last}'"
    text = _as_text(data)
    if how == "deep-nesting":
        at = text.find(">", text.find("<robot")) + 1
        depth = draw(st.sampled_from((100, 1000, DEEP, 50_000)))
        return text[:at] + "<a>" * depth + "</a>" * depth + text[at:], f"{depth} nested <a> elements inside <robot>"
    if how == "entity-bomb":
        body = re.sub(r"^<\?xml[^>]*\?>\s*", "", text)
        body = re.sub(r'(<link name=")([^"]*)(")', r"\1&i;\3", body, count=1)
        return XML_ENTITY_BOMB + body, "XML entity bomb (10**9 characters) as the first link's name"
    if how == "empty-robot":
        return draw(
            st.sampled_from(('<robot name="r"/>', "<robot/>", "<notrobot/>", "", "<robot>", "<?xml version='1.0'?>"))
        ), "replaced by a tiny document"
    return data, None


# ============================================================================ YAML / TOML structure
def _load(data, kind):
    try:
        import tomllib

        return tomllib.loads(_as_text(data)) if kind == "toml" else yaml.safe_load(_as_text(data))
    except Exception:
        return None


def _dump(obj, kind) -> str | None:
    try:
        return (
            tomli_w.dumps(obj)
            if kind == "toml"
            else yaml.safe_dump(obj, sort_keys=False, default_flow_style=None, width=120)
        )
    except Exception:
        return None


def _slots(obj, path=()):
    """Every (container, key, path) below obj, containers first."""
    out = []
    items = obj.items() if isinstance(obj, dict) else enumerate(obj) if isinstance(obj, list) else ()
    for k, v in items:
        out.append((obj, k, path + (k,)))
        out.extend(_slots(v, path + (k,)))
    return out


_ALIAS = re.compile(r"(^|[\s\[,{:])[&*][^\s,\]}]")


def _joint_rows(obj) -> list:
    """The joint mappings of a parsed robot file (DH rows or the links' joints), whatever an earlier
    mutation did to its structure."""
    joints, links = obj.get("joints"), obj.get("links")
    rows = (
        joints
        if isinstance(joints, list)
        else [l.get("joint") for l in links if isinstance(l, dict)]
        if isinstance(links, list)
        else []
    )
    return [r for r in rows if isinstance(r, dict)]


def op_mapping(draw, data, kind):
    # a text with YAML anchors/aliases (an alias bomb from an earlier mutation) is not expanded here
    if kind == "yaml" and _ALIAS.search(_as_text(data)):
        return data, None
    obj = _load(data, kind)
    if not isinstance(obj, dict):
        return data, None
    try:
        slots = _slots(obj)
    except RecursionError:  # a deeply nested value from an earlier mutation
        return data, None
    how = draw(
        st.sampled_from(
            ("value", "expression", "delete", "duplicate", "joint-type", "cycle", "name", "add-field", "swap-limits")
        )
    )
    desc = None
    if how in ("value", "expression", "delete", "duplicate") and slots:
        container, key, path = slots[_pick(draw, len(slots), "slot")]
        where = ".".join(map(str, path))
        if how == "value":
            new = draw(st.sampled_from(HOSTILE_VALUES))
            container[key] = copy.deepcopy(new)
            desc = f"{where} -> {_short(repr(new))}"
        elif how == "expression":
            new = draw(st.sampled_from(HOSTILE_EXPRESSIONS))
            container[key] = new
            desc = f"{where} -> {_short(new)}"
        elif how == "delete":
            del container[key]
            desc = f"deleted {where}"
        elif isinstance(container, list):
            container.insert(key, copy.deepcopy(container[key]))
            desc = f"duplicated {where}"
        else:
            return data, None
    elif how == "joint-type":
        rows = _joint_rows(obj)
        if not rows:
            return data, None
        row = rows[_pick(draw, len(rows), "joint")]
        new = draw(st.sampled_from(HOSTILE_JOINT_TYPES))
        row["type"] = new
        desc = f"joint '{row.get('name')}' type -> {new!r}"
    elif how == "cycle":
        links = [l for l in obj.get("links") if isinstance(l, dict)] if isinstance(obj.get("links"), list) else []
        if len(links) < 2:
            return data, None
        i = _pick(draw, len(links), "link")
        j = draw(st.integers(i, len(links) - 1))
        links[i]["parent"] = links[j].get("name")
        desc = f"links[{i}].parent -> '{links[j].get('name')}' (links[{j}], itself or below it)"
    elif how in ("add-field", "swap-limits"):
        rows = _joint_rows(obj)
        if not rows:
            return data, None
        row = rows[_pick(draw, len(rows), "joint")]
        if how == "swap-limits":
            row["limits"] = {"lower": 1.0, "upper": -1.0}
            desc = f"joint '{row.get('name')}' limits lower 1 > upper -1"
        else:
            key = draw(
                st.sampled_from(
                    ("gear_ratio", "rotor_inertia", "viscous", "coulomb", "offset", "limits", "origin", "axis")
                )
            )
            new = draw(st.sampled_from(HOSTILE_VALUES + HOSTILE_EXPRESSIONS[:12]))
            row[key] = copy.deepcopy(new)
            desc = f"joint '{row.get('name')}' {key} = {_short(repr(new))}"
    elif how == "name":
        new = draw(st.sampled_from(HOSTILE_NAMES))
        obj["name"] = new
        desc = f"name -> {_short(new)}"
    if desc is None:
        return data, None
    try:
        text = _dump(obj, kind)
    except RecursionError:
        text = None
    return (data, None) if text is None else (text, desc)


def op_yaml_special(draw, data, kind):
    """YAML-only: alias bombs, deep nesting, duplicate keys, tags, anchors."""
    text = _as_text(data)
    how = draw(st.sampled_from(("alias-bomb", "deep-list", "deep-map", "duplicate-key", "tag", "merge", "self-alias")))
    m = re.search(r"(?m)^name: .*$", text)
    if m is None:
        return data, None
    if how == "alias-bomb":
        levels = draw(st.sampled_from((3, 6, 9, 10)))
        return text[: m.start()] + "name: " + yaml_alias_bomb(levels) + text[
            m.end() :
        ], f"name: a YAML alias bomb of 9**{levels} leaves"
    if how == "deep-list":
        depth = draw(st.sampled_from((100, 1000, DEEP)))
        return text[: m.start()] + "name: " + "[" * depth + "]" * depth + text[
            m.end() :
        ], f"name: a list nested {depth} deep"
    if how == "deep-map":
        depth = draw(st.sampled_from((100, 1000, DEEP)))
        return text[: m.start()] + "name: " + "{a: " * depth + "1" + "}" * depth + text[
            m.end() :
        ], f"name: a mapping nested {depth} deep"
    if how == "duplicate-key":
        key = draw(
            st.sampled_from(("name: other", "gravity: [0, 0, 9.81]", "convention: modified", "units: {angle: deg}"))
        )
        return text + "\n" + key + "\n", f"duplicate top-level key '{key}'"
    if how == "tag":
        tag = draw(
            st.sampled_from(
                (
                    "!!python/object/apply:os.system ['true']",
                    "!!binary aGVsbG8=",
                    "!!timestamp 2001-12-14",
                    "!!set {a, b}",
                    "!!float nan",
                    "!!int 0x" + "f" * 400,
                    "!!str 1",
                    "!custom x",
                )
            )
        )
        return text[: m.start()] + "name: " + tag + text[m.end() :], f"name: {tag}"
    if how == "merge":
        return text + "\nbase_defaults: &d {mass: 1}\n", "unknown top-level key with an anchor"
    return "&top " + text.replace("gravity:", "gravity: *top\nold_gravity:", 1), "the document aliases itself"


def op_toml_special(draw, data, kind):
    text = _as_text(data)
    how = draw(st.sampled_from(("deep-array", "deep-table", "duplicate-key", "huge-int")))
    m = re.search(r"(?m)^name = .*$", text)
    if m is None:
        return data, None
    if how == "deep-array":
        depth = draw(st.sampled_from((100, 1000, DEEP)))
        return text[: m.start()] + "name = " + "[" * depth + "]" * depth + text[
            m.end() :
        ], f"name = an array nested {depth} deep"
    if how == "deep-table":
        depth = draw(st.sampled_from((100, 1000, DEEP)))
        return text[: m.start()] + "name = " + "{a = " * depth + "1" + "}" * depth + text[
            m.end() :
        ], f"name = an inline table nested {depth} deep"
    if how == "duplicate-key":
        return text[: m.end()] + "\n" + text[m.start() : m.end()] + text[m.end() :], "duplicate key 'name'"
    return text[: m.start()] + "name = " + "9" * 5000 + text[m.end() :], "name = a 5000-digit integer"


TEXT_OPS = (op_replace_number, op_replace_quoted, op_truncate, op_bytes, op_lines)
OPS = {
    "urdf": TEXT_OPS + (op_urdf_tree, op_urdf_tree, op_urdf_tree),
    "yaml": TEXT_OPS + (op_yaml_scalar, op_mapping, op_mapping, op_mapping, op_yaml_special),
    "toml": TEXT_OPS + (op_mapping, op_mapping, op_mapping, op_toml_special),
}


def _short(s: str, n: int = 50) -> str:
    s = str(s)
    return repr(s) if len(s) <= n else repr(s[: n // 2]) + f"...({len(s)} chars)..." + repr(s[-n // 4 :])


@st.composite
def file_cases(draw, kind: str) -> Case:
    """A real robot file of ``kind`` with one to three mutations."""
    seeds = corpus.seeds(kind)
    seed = seeds[draw(st.integers(0, len(seeds) - 1), label="seed")]
    data, ops = seed.text, []
    for _ in range(draw(st.integers(1, 3), label="mutations")):
        op = draw(st.sampled_from(OPS[kind]))
        try:
            new, desc = op(draw, data, kind)
        except RecursionError:  # parsing a deeply nested text made by an earlier mutation
            new, desc = data, None
        except (TypeError, AttributeError, KeyError, IndexError, ValueError):
            # a structure an earlier mutation broke in a way this one does not expect: skip it
            new, desc = data, None
        if desc is not None:
            data = new
            ops.append(desc)
    if not ops:  # every mutation drawn found nothing to act on: the seed itself, which must load
        return Case(kind=kind, seed=seed.name, ops=("unchanged",), data=data, valid=True)
    return Case(kind=kind, seed=seed.name, ops=tuple(ops), data=data)


# ============================================================================ numeric calls
# robot specs: "builtin:<name>" or "erd:<path under example-robot-data/robots>"
ARRAY_ROBOTS = (
    "builtin:planar_2r",
    "builtin:puma560",
    "builtin:stanford",
    "builtin:ur5",
    "builtin:cartesian_2p",
    "erd:panda_description/urdf/panda.urdf",
    "erd:solo_description/robots/solo.urdf",
)


@functools.cache
def make_robot(spec: str):
    import os

    import kinedyn as kd

    where, name = spec.split(":", 1)
    if where == "builtin":
        return kd.robots.get(name)
    root = corpus.erd_robots_dir()
    if root is None:
        return None
    return kd.Robot.from_urdf(os.path.join(root, name))


@functools.cache
def robot_facts(spec: str):
    robot = make_robot(spec)
    if robot is None:
        return None
    return robot.n, robot.tool, tuple(robot.body_names)


# method -> roles of its positional arguments; "*" marks optional keyword arguments
METHODS = {
    "inverse_dynamics": ("q", "qd", "qdd", "*f_ext", "*out"),
    "mass_matrix": ("q", "*out"),
    "mass_matrix_inverse": ("q",),
    "forward_dynamics": ("q", "qd", "tau", "*f_ext", "*out"),
    "coriolis_matrix": ("q", "qd"),
    "christoffel": ("q",),
    "gravity_torque": ("q",),
    "bias_torque": ("q", "qd"),
    "kinetic_energy": ("q", "qd"),
    "potential_energy": ("q",),
    "center_of_mass": ("q",),
    "momentum": ("q", "qd"),
    "regressor": ("q", "qd", "qdd"),
    "jacobian": ("q", "*frame", "*reference", "*point"),
    "frame_velocity": ("q", "qd", "*frame", "*reference"),
    "jacobian_dot_qd": ("q", "qd", "*frame"),
    "pose": ("q", "*frame"),
    "forward_kinematics": ("q",),
    "frame_poses": ("q",),
    "friction_torque": ("qd",),
    "inverse_kinematics": ("target", "*q0", "*mask", "*method", "*tolerance", "*max_iterations", "*restarts"),
    "inverse_dynamics_derivatives": ("q", "qd", "qdd", "*f_ext"),
    "forward_dynamics_derivatives": ("q", "qd", "tau", "*f_ext"),
    "random_configuration": ("*rng", "*size"),
    "simulate": ("t_span", "x0", "*dt", "*method"),
    "lock_joints": ("values",),
}
HUGE = (1e154, -1e154, 1e200, 1e300, -1e300, 1.7e308)
NONFINITE = (float("nan"), float("inf"), -float("inf"))
KEYWORD_VALUES = {
    "frame": lambda tool, bodies: (tool, bodies[0], bodies[-1], "", "no_such_frame", 5, None, b"tool"),
    "reference": lambda *_: ("world", "local", "spatial", "WORLD", "", None, 3),
    "point": lambda *_: (None, [0.1, 0.0, 0.0], [float("nan"), 0, 0], [1e300, 0, 0], [0.0, 0.0], "x", np.zeros((2, 3))),
    "mask": lambda *_: (
        None,
        (1, 1, 1, 0, 0, 0),
        (1, 1, 1, 1, 1, 1),
        (0,) * 6,
        (1, 1, 1),
        (float("nan"),) * 6,
        (-1,) * 6,
        "xyz",
    ),
    "method_ik": lambda *_: ("auto", "analytic", "numeric", "lm", "", None),
    "tolerance": lambda *_: (1e-9, 0.0, -1.0, float("nan"), float("inf"), 1e-300, 1.0, "1e-9"),
    "max_iterations": lambda *_: (50, 0, -1, 2**63, 2**64, 1.5, "10", None, True),
    "restarts": lambda *_: (0, 1, 5, -1, 2**64, None),
    "rng": lambda *_: (None, 0, 1, -1, 2**64, "seed", 1.5),
    "size": lambda *_: (None, 0, 3, -1, 10**12, 2**64, 3.0, (2, 3)),
    "dt": lambda *_: (None, 1e-3, 1e-12, 0.0, -1e-3, float("nan"), 1e300, "0.01"),
    "method_sim": lambda *_: ("rk4", "euler", "rk45", "semi-implicit", "", None),
}


def _mutated_array(draw, rng, shape, scale: float, label: str):
    """A float64 array of ``shape`` (valid) or a mutation of it; returns (value, description)."""
    base = rng.uniform(-scale, scale, size=shape)
    how = draw(
        st.sampled_from(("huge", "huge-one", "nonfinite", "shape", "dtype", "layout", "python", "scalar", "zero")),
        label=label,
    )
    if how == "zero":
        return np.zeros(shape), "zeros"
    if how in ("huge", "huge-one"):
        v = draw(st.sampled_from(HUGE))
        if how == "huge" or base.size == 0:
            return np.full(shape, v), f"all {v:g}"
        flat = base.reshape(-1).copy()
        flat[draw(st.integers(0, flat.size - 1))] = v
        return flat.reshape(shape), f"one element {v:g}"
    if how == "nonfinite":
        v = draw(st.sampled_from(NONFINITE))
        flat = base.reshape(-1).copy()
        if flat.size:
            flat[draw(st.integers(0, flat.size - 1))] = v
        return flat.reshape(shape), f"one element {v}"
    if how == "shape":
        n = shape[-1] if shape else 1
        new = draw(
            st.sampled_from(
                (
                    (n + 1,),
                    (max(n - 1, 0),),
                    (0,),
                    (),
                    (n, 1),
                    (1, n),
                    (0, n),
                    (2, n, 1),
                    (3, n + 1),
                    (2, 2, n),
                    (n * 2,),
                )
            )
        )
        return rng.uniform(-scale, scale, size=new), f"shape {new}"
    if how == "dtype":
        dt = draw(
            st.sampled_from(
                (
                    "int64",
                    "int32",
                    "bool",
                    "float32",
                    "float16",
                    "complex-imag",
                    "complex-real",
                    "object",
                    "object-str",
                    "str",
                    "uint8",
                    "longdouble",
                )
            )
        )
        if dt == "complex-imag":
            return base + 1j, "complex with imaginary part 1"
        if dt == "complex-real":
            return base.astype(complex), "complex with zero imaginary part"
        if dt == "object":
            return base.astype(object), "object array of floats"
        if dt == "object-str":
            return np.array(["1.0"] * base.size, dtype=object).reshape(shape), "object array of strings"
        if dt == "str":
            return base.astype(str), "str array"
        return base.astype(dt), f"dtype {dt}"
    if how == "layout":
        lay = draw(st.sampled_from(("strided", "reversed", "fortran", "readonly", "0-stride")))
        if lay == "strided":
            big = np.zeros(shape[:-1] + (2 * shape[-1],)) if shape else np.zeros(2)
            big[..., ::2] = base
            return big[..., ::2], "non-contiguous (every other element)"
        if lay == "reversed":
            return base[..., ::-1], "reversed view"
        if lay == "fortran":
            return np.asfortranarray(base), "Fortran order"
        if lay == "readonly":
            base.flags.writeable = False
            return base, "read-only"
        return np.broadcast_to(base.reshape(-1)[:1], shape) if base.size else base, "broadcast view (stride 0)"
    if how == "python":
        kind = draw(st.sampled_from(("list", "tuple", "ragged", "nested-str", "dict", "generator-like")))
        if kind == "list":
            return base.tolist(), "Python list"
        if kind == "tuple":
            return tuple(base.reshape(-1).tolist()), "Python tuple (flattened)"
        if kind == "ragged":
            return [[0.0], [0.0, 1.0]], "ragged nested list"
        if kind == "nested-str":
            return ["a"] * (shape[-1] if shape else 1), "list of str"
        if kind == "dict":
            return {"q": base.tolist()}, "dict"
        return range(shape[-1] if shape else 1), "range"
    v = draw(st.sampled_from((0.0, 1.0, None, "abc", 1j, float("nan"), 10**400, True)))
    return v, f"scalar {v!r}"


@st.composite
def array_cases(draw) -> Case:
    """One call of a public numeric method with one or two mutated arguments."""
    specs = [s for s in ARRAY_ROBOTS if robot_facts(s) is not None]
    spec = draw(st.sampled_from(specs), label="robot")
    n, tool, bodies = robot_facts(spec)
    method = draw(st.sampled_from(sorted(METHODS)), label="method")
    roles = METHODS[method]
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1), label="rng"))
    valid = draw(st.integers(0, 4), label="valid call") == 0  # one call in five is valid as documented
    batch = draw(st.sampled_from((None, None, 1, 3) if valid else (None, None, 1, 3, 0)), label="batch")
    state_shape = (n,) if batch is None else (batch, n)
    mutate = (
        set()
        if valid
        else set(draw(st.lists(st.sampled_from(roles), min_size=1, max_size=2, unique=True), label="mutated"))
    )
    args, kwargs, ops = [], {}, [f"batch {batch}" if batch is not None else "single state"]
    for role in roles:
        optional = role.startswith("*")
        name = role.lstrip("*")
        if optional and name not in {r.lstrip("*") for r in mutate} and draw(st.booleans()):
            continue  # left at its default
        bad = role in mutate
        if name in ("q", "qd", "qdd", "tau", "q0"):
            shape = (n,) if name == "q0" else state_shape
            scale = {"q": math.pi, "qd": 3.0, "qdd": 5.0, "tau": 20.0, "q0": 1.0}[name]
            value, desc = (
                _mutated_array(draw, rng, shape, scale, name) if bad else (rng.uniform(-scale, scale, shape), "valid")
            )
        elif name == "f_ext":
            shape = (n, 6) if batch is None else (batch, n, 6)
            if bad and batch is not None and draw(st.booleans()):
                # undocumented: one f_ext for a whole batch (broadcasting it, or a clear error, are both fine)
                value, desc = rng.uniform(-10, 10, (n, 6)), "one (n, 6) for every state"
            elif bad:
                value, desc = _mutated_array(draw, rng, shape, 10.0, name)
            else:
                value, desc = draw(st.sampled_from(((None, "None"), (rng.uniform(-10, 10, shape), "valid"))))
        elif name == "out":
            out_shape = {
                "inverse_dynamics": state_shape,
                "forward_dynamics": state_shape,
                "mass_matrix": state_shape + (n,),
            }[method]
            value, desc = _mutated_array(draw, rng, out_shape, 1.0, name) if bad else (np.zeros(out_shape), "valid")
        elif name == "target":
            R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
            T = np.eye(4)
            T[:3, :3] = R * np.sign(np.linalg.det(R))
            T[:3, 3] = rng.uniform(-0.5, 0.5, 3)
            tshape = (4, 4) if batch is None else (batch, 4, 4)
            T = T if batch is None else np.broadcast_to(T, tshape).copy()
            if bad:
                value, desc = _mutated_array(draw, rng, tshape, 1.0, name)
            else:
                value, desc = draw(st.sampled_from(((T, "pose"), (T[..., :3, 3].copy(), "position"))))
        elif name == "values":
            joint = make_robot(spec).joint_names[0]
            choices = (
                {joint: 0.1},
                [joint],
                (joint,),
                {"no_such_joint": 0.0},
                {joint: float("nan")},
                {joint: "x"},
                {joint: 1e300},
                {joint: 1j},
                {joint: [0.1, 0.2]},
                joint,
                {},
            )
            value = draw(st.sampled_from(choices[1:])) if bad else choices[0]
            desc = _short(repr(value))
        elif name in ("t_span", "x0"):
            if name == "x0":
                value, desc = (
                    _mutated_array(draw, rng, (2 * n,), 1.0, name) if bad else (rng.uniform(-1, 1, 2 * n), "valid")
                )
            else:
                value = (
                    draw(
                        st.sampled_from(
                            ((0.0, 0.02), 0.02, (0.0, 1e300), (0.0, float("nan")), (1.0, 0.0), (0.0,), "1", (0.0, 1.0))
                        )
                    )
                    if bad
                    else (0.0, 0.02)
                )
                desc = repr(value)
        else:
            key = {"method": "method_ik" if method == "inverse_kinematics" else "method_sim"}.get(name, name)
            choices = KEYWORD_VALUES[key](tool, bodies)
            value = draw(st.sampled_from(choices[1:] if bad and len(choices) > 1 else choices[:1]))
            desc = repr(value)
        if optional or method in ("simulate",) and name not in ("t_span", "x0"):
            kwargs[name] = value
        else:
            args.append(value)
        ops.append(f"{name}: {desc}{' (mutated)' if bad else ''}")
    if method == "simulate" and "dt" not in kwargs:
        kwargs["dt"] = 1e-3
    return Case(kind="arrays", seed=spec, ops=tuple(ops), call=(spec, method, tuple(args), kwargs), valid=valid)


# the surfaces of issue 25 (fuzz.surfaces): MJCF with includes, meshes, logs, the viewer's address, outputs
KINDS = ("urdf", "yaml", "toml", "arrays", "mjcf", "mesh", "log", "viewer", "output")


def cases(kind: str):
    """The strategy for one kind of case."""
    if kind in ("mjcf", "mesh", "log", "viewer", "output"):
        from .surfaces import surface_cases  # (it builds on this module's mutations)

        return surface_cases(kind)
    return array_cases() if kind == "arrays" else file_cases(kind)


# ============================================================================ the issue's reproducers
def issue_cases() -> list:
    """The inputs issue 11 names, each as one case (so that every class it lists is tried on every
    run, whatever Hypothesis draws): code execution, unbounded work, non-ValueError loader errors,
    errors deferred past load, silent non-finite results, bad input accepted."""
    import os

    root = corpus.ROOT
    two_link = open(os.path.join(root, "examples", "robots", "tutorial_two_link.yaml"), encoding="utf-8").read()
    elbow = open(os.path.join(root, "examples", "robots", "elbow_arm.toml"), encoding="utf-8").read()
    planar = open(os.path.join(root, "examples", "robots", "planar_2r.urdf"), encoding="utf-8").read()
    tree = corpus.FULL_TREE_YAML
    out = []

    def add(kind, what, data=None, call=None, valid=False):
        out.append(Case(kind=kind, seed="issue 11", ops=(what,), data=data, call=call, valid=valid))

    def a(value):  # the first DH row's 'a' of the tutorial arm
        return two_link.replace("a: 2.0", f"a: {value}", 1)

    add("yaml", "§1 a: the chr-built exec canary", a(f"'{CANARY}'"))
    add("yaml", "§1 mass: the chr-built eval canary", two_link.replace("mass: 1.0", f"mass: '{_canary('eval')}'", 1))
    add("toml", "§1 d = the chr-built exec canary", elbow.replace("d = 3.0", f'd = "{CANARY}"', 1))
    add("yaml", "§2 a: '9**9**9'", a("'9**9**9'"))
    add("yaml", "§2 a: 'factorial(10**7)'", a("'factorial(10**7)'"))
    add(
        "yaml",
        "§2 a YAML alias bomb in name:",
        two_link.replace("name: tutorial_two_link", "name: " + yaml_alias_bomb(9), 1),
    )
    add(
        "yaml",
        "§2 name: a list nested 5,000 deep",
        two_link.replace("name: tutorial_two_link", "name: " + "[" * DEEP + "]" * DEEP, 1),
    )
    add(
        "toml",
        "§2 name = an array nested 5,000 deep",
        elbow.replace('name = "elbow_arm"', "name = " + "[" * DEEP + "]" * DEEP, 1),
    )
    add("yaml", "§2 a: 5,000 nested parentheses", a("'" + "(" * DEEP + "1" + ")" * DEEP + "'"))
    links = "".join(
        f'<link name="fz{i}"/><joint name="fzj{i}" type="fixed"><parent link="{"link2" if i == 0 else f"fz{i - 1}"}"/>'
        f'<child link="fz{i}"/></joint>'
        for i in range(2000)
    )
    add("urdf", "§2 2,000 fixed links after the last moving joint", planar.replace("</robot>", links + "</robot>"))
    add("yaml", "§3 a: a 400-digit integer", a("4" * 400))
    add("yaml", "§3 gear_ratio: 1e200", two_link.replace("mass: 1.0,", "gear_ratio: 1e200, mass: 1.0,", 1))
    add("yaml", "§3 a: 'x.y'", a("'x.y'"))
    add("yaml", "§3 a: 'sqrt(-1)'", a("'sqrt(-1)'"))
    add("yaml", "§3 parent: [1, 2]", tree.replace("parent: pan", "parent: [1, 2]", 1))
    add(
        "yaml",
        "§3 gravity: [.nan, -9.81, 0]",
        two_link.replace("gravity: [0, -9.81, 0]", "gravity: [.nan, -9.81, 0]", 1),
    )
    add("yaml", "§3 offset: .nan", tree.replace("offset: 0.1", "offset: .nan", 1))
    add("yaml", "§3 viscous: .inf", tree.replace("viscous: 0.01", "viscous: .inf", 1))
    add("yaml", "§3 coulomb: .nan", tree.replace("coulomb: 0.02", "coulomb: .nan", 1))
    add("yaml", "§3 gear_ratio: .nan", tree.replace("gear_ratio: 100", "gear_ratio: .nan", 1))
    add(
        "yaml",
        "§3 origin xyz: [1e200, 0, 0] (of the second link)",
        tree.replace("xyz: [0, 0, 0.05]", "xyz: [1e200, 0, 0]", 1),
    )
    add("yaml", "§3 a duplicate key", two_link + "\nname: again\n")
    add(
        "urdf",
        "§3 an inertial origin of NaN (the URDF prefix repeated)",
        planar.replace('<origin xyz="', '<origin xyz="nan ', 1),
    )
    erd = corpus.erd_robots_dir()
    for path in ("tiago_description/robots/tiago_no_hand.urdf", "romeo_description/urdf/romeo.urdf"):
        if erd is not None and os.path.exists(os.path.join(erd, path)):  # loaded by Pinocchio: must load here
            add(
                "urdf",
                f"§4 example-robot-data/{path} as it is",
                open(os.path.join(erd, path), encoding="utf-8").read(),
                valid=True,
            )
    add(
        "yaml",
        "§11 limits lower > upper",
        tree.replace("limits: {lower: -3.0, upper: 3.0,", "limits: {lower: 3.0, upper: -3.0,", 1),
    )
    add("yaml", "unknown joint type 'spherical'", tree.replace("type: continuous", "type: spherical", 1))

    n = 6
    rng = np.random.default_rng(11)
    q = rng.uniform(-1, 1, n)
    T = np.eye(4)
    T[:3, 3] = (0.3, 0.1, 0.2)
    add(
        "arrays",
        "§8 inverse_dynamics(q, 1e154 * ones, 0)",
        call=("builtin:puma560", "inverse_dynamics", (q, 1e154 * np.ones(n), np.zeros(n)), {}),
    )
    add(
        "arrays",
        "§8 kinetic_energy(q, 1e200 * ones)",
        call=("builtin:puma560", "kinetic_energy", (q, 1e200 * np.ones(n)), {}),
    )
    add(
        "arrays",
        "§8 mass_matrix_inverse at q = 1e154",
        call=("builtin:stanford", "mass_matrix_inverse", (np.full(n, 1e154),), {}),
    )
    add("arrays", "§11 complex q", call=("builtin:puma560", "forward_kinematics", (q + 1j,), {}))
    add(
        "arrays",
        "§11 inverse_kinematics(max_iterations=2**64)",
        call=("builtin:puma560", "inverse_kinematics", (T,), {"method": "numeric", "max_iterations": 2**64}),
    )
    add(
        "arrays",
        "§11 a batch of states with one f_ext on a DH robot",
        call=(
            "builtin:puma560",
            "inverse_dynamics",
            (rng.uniform(-1, 1, (3, n)), np.zeros((3, n)), np.zeros((3, n))),
            {"f_ext": rng.uniform(-1, 1, (n, 6))},
        ),
    )
    # (a clear ValueError/TypeError would be right here too; today's TypeError is not clear, which the
    # classes cannot tell: this one is for the figures, the regression test is the fixer's)
    add("arrays", "§11 lock_joints with a list", call=("builtin:puma560", "lock_joints", (["q1"],), {}))
    add(
        "arrays",
        "§6 simulate(puma560, (0, 1), x0, dt=1e-12)",
        call=("builtin:puma560", "simulate", ((0.0, 1.0), np.zeros(2 * n)), {"dt": 1e-12}),
    )
    return out
