"""Robot files are data (issue 11, sections 1-3): an expression string can never run code, every
load is bounded in time and memory, and every bad file is a ValueError at load naming file and field.

The hostile files run in a child process with a time and memory limit, so that a regression shows
as a failed test, not as a hung or swapping test run.
"""

from __future__ import annotations

import cmath
import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import kinedyn as kd
from kinedyn.expressions import FUNCTIONS, parse_expression, parse_number

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _load_in_child(path, seconds: float = 20.0, memory_gib: float = 2.0) -> tuple[str, float]:
    """Load ``path`` in a child process under limits; returns (outcome, seconds) where outcome is
    'ok', 'ValueError: ...' or the name of another exception, 'killed' or 'timeout'."""
    code = textwrap.dedent(
        f"""
        import resource, sys, time
        resource.setrlimit(resource.RLIMIT_AS, ({int(memory_gib * 2**30)}, {int(memory_gib * 2**30)}))
        import kinedyn as kd
        # what kd.load loads on first use (the readers, PyYAML, SymPy) is loaded before the clock
        # starts: the time bounds the work the file itself causes
        import kinedyn.robot_files, kinedyn.description.yaml_reader
        from kinedyn.expressions import parse_expression
        parse_expression("exp(x) + 9**2")
        t = time.perf_counter()
        try:
            kd.load({os.fspath(path)!r})
            outcome = "ok"
        except ValueError as e:
            outcome = "ValueError: " + str(e)
        except BaseException as e:
            outcome = type(e).__name__ + ": " + str(e)[:200]
        print(repr((outcome, time.perf_counter() - t)))
        """
    )
    # the kinedyn this test imported (the working tree or an installed wheel), not necessarily ROOT/python
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join([os.path.dirname(os.path.dirname(kd.__file__)), os.environ.get("PYTHONPATH", "")]),
    )
    try:
        run = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, timeout=seconds + 15, env=env
        )
    except subprocess.TimeoutExpired:
        return "timeout", seconds
    if run.returncode != 0:
        return f"killed (exit {run.returncode}): {run.stderr[-300:]}", math.nan
    return eval(run.stdout.strip().splitlines()[-1])  # our own repr of (str, float)


def _write(tmp_path, name: str, text: str):
    path = tmp_path / name
    path.write_text(text)
    return path


# ------------------------------------------------------------------ 1. no code execution
def _exec_expression(marker) -> str:
    """A string of letters, digits, '(', ')' and '+' only that, handed to sympify (Python's eval),
    calls exec on text built with chr(): it creates ``marker``."""
    payload = f"open({str(marker)!r}, 'w').write('ran')"
    return "exec(" + "+".join(f"chr({ord(c)})" for c in payload) + ")"


@pytest.mark.parametrize("ext", ["yaml", "toml"])
def test_an_expression_in_a_robot_file_cannot_run_code(tmp_path, ext):
    marker = tmp_path / "code-ran"
    expression = _exec_expression(marker)
    assert set(expression) <= set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789()+")
    text = f"joints:\n  - {{a: '{expression}'}}\n" if ext == "yaml" else f"[[joints]]\na = '{expression}'\n"
    path = _write(tmp_path, f"arm.{ext}", text)
    outcome, _ = _load_in_child(path)
    assert not marker.exists(), "loading a robot file ran code"
    assert outcome.startswith("ValueError:") and "joints row 1.a" in outcome, outcome


def test_strings_given_to_the_python_api_are_not_evaluated(tmp_path):
    marker = tmp_path / "code-ran"
    short = "exec(chr(49))"  # short enough to reach the function check
    with pytest.raises(ValueError, match="'exec' is not a known function"):
        kd.Joint("j", "revolute", offset=short)
    with pytest.raises(ValueError, match="'exec' is not a known function"):
        kd.LagrangianSystem("x", L=short)
    for text in (_exec_expression(marker), short):
        with pytest.raises(ValueError):
            kd.Joint("j", "revolute", offset=text)
        with pytest.raises(ValueError):
            kd.LagrangianSystem("x", L=text)
    assert not marker.exists()


# ------------------------------------------------------------------ 2. bounded work
ALIAS_BOMB = "\n".join(
    ["a: &a ['lol', 'lol', 'lol', 'lol', 'lol', 'lol', 'lol', 'lol', 'lol']"]
    + [f"{chr(c)}: &{chr(c)} [{', '.join(['*' + chr(c - 1)] * 9)}]" for c in range(ord("b"), ord("j") + 1)]
    + ["name: *j", "joints: [{a: 1}]"]
)
HOSTILE = {
    "power tower": ("yaml", "joints:\n  - {a: '9**9**9'}\n", "joints row 1.a"),
    "factorial": ("yaml", "joints:\n  - {a: 'factorial(10**7)'}\n", "joints row 1.a"),
    "exp tower": ("yaml", "joints:\n  - {a: 'exp(exp(exp(exp(10))))'}\n", "joints row 1.a"),
    "alias bomb in name": ("yaml", ALIAS_BOMB + "\n", "line"),
    "name nested 5000 deep (yaml)": ("yaml", "name: " + "[" * 5000 + "]" * 5000 + "\njoints: [{a: 1}]\n", "nested"),
    "name nested 5000 deep (toml)": ("toml", "name = " + "[" * 5000 + "]" * 5000 + "\n[[joints]]\na = 1\n", "nested"),
    "dotted keys 5000 deep (toml)": ("toml", "name." + ".".join(["k"] * 5000) + " = 1\n[[joints]]\na = 1\n", "nested"),
    "parentheses 5000 deep": ("yaml", "joints:\n  - {a: '" + "(" * 5000 + "1" + ")" * 5000 + "'}\n", "joints row 1.a"),
    "unary minus 900 deep": ("yaml", "joints:\n  - {a: '" + "-" * 900 + "1'}\n", "joints row 1.a"),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_a_hostile_file_fails_fast_with_a_value_error(tmp_path, case):
    ext, text, field = HOSTILE[case]
    path = _write(tmp_path, f"robot.{ext}", text)
    assert len(text.encode()) < 60_000
    outcome, seconds = _load_in_child(path, seconds=20.0, memory_gib=1.0)
    assert outcome.startswith("ValueError: ") and str(path) in outcome and field in outcome, outcome
    assert seconds < 2.0, f"{case}: took {seconds:.1f} s"


def test_aliases_that_repeat_a_little_still_load(tmp_path):
    path = _write(tmp_path, "ok.yaml", "joints:\n  - &row {a: 1.0, mass: 2.0}\n  - {<<: *row, a: 0.5}\n  - *row\n")
    robot = kd.load(path)
    assert [float(r.a) for r in robot.dh] == [1.0, 0.5, 1.0] and [float(r.inertia.mass) for r in robot.dh] == [2.0] * 3


# ------------------------------------------------------------------ 3. bad values: ValueError at load, naming file, line and field
BAD = {
    "400-digit integer": ("joints:\n  - {a: 1" + "0" * 400 + "}\n", "joints row 1.a", 2),
    "attribute access": ("joints:\n  - {a: 'x.y'}\n", "joints row 1.a", 2),
    "square root of -1": ("joints:\n  - {a: 'sqrt(-1)'}\n", "joints row 1.a", 2),
    "complex literal": ("joints:\n  - {a: '2j'}\n", "joints row 1.a", 2),
    "string literal": ("joints:\n  - {a: '\"x\"'}\n", "joints row 1.a", 2),
    "NaN gravity": ("gravity: [0, .nan, -9.81]\njoints:\n  - {a: 1}\n", "gravity[1]", 1),
    "inf offset": ("joints:\n  - {a: 1,\n     theta: .inf}\n", "joints row 1.theta", 3),
    "nan viscous": ("joints:\n  - {a: 1, viscous: .nan}\n", "joints row 1.viscous", 2),
    "nan as a name": ("joints:\n  - {a: 1, coulomb: nan}\n", "joints row 1.coulomb", 2),
    "inf as text": ("joints:\n  - {a: 1, gear_ratio: 'inf'}\n", "joints row 1.gear_ratio", 2),
    "overflowing literal": ("joints:\n  - {a: '1e400'}\n", "joints row 1.a", 2),
    "parent is a list": (
        "links:\n  - {name: a, joint: {type: revolute}}\n  - {name: b,\n     parent: [1, 2], joint: {type: revolute}}\n",
        "links row 2 ('b').parent",
        4,
    ),
    "name is a mapping": ("links:\n  - {name: {x: 1}, joint: {type: revolute}}\n", "links row 1.name", 2),
    "frames not a list": ("frames: 3\njoints: [{a: 1}]\n", "frames", 1),
    "frame placed beyond any robot": (
        "frames:\n  - {name: camera, origin: {xyz: [1.0e+150, 0, 0]}}\njoints: [{a: 1}]\n",
        "frames[0]",
        2,
    ),
    "duplicate key": ("joints:\n  - {a: 1}\njoints:\n  - {a: 2}\n", "appears twice", 3),
    "duplicate key in a row": ("joints:\n  - {a: 1, a: 2}\n", "appears twice", 2),
    "unknown function": ("joints:\n  - {a: 'gamma(3)'}\n", "joints row 1.a", 2),
    "symbolic exponent": ("joints:\n  - {a: 'l**n'}\n", "joints row 1.a", 2),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_value_is_a_value_error_naming_file_line_and_field(tmp_path, case):
    text, field, line = BAD[case]
    path = _write(tmp_path, "arm.yaml", text)
    with pytest.raises(ValueError) as info:
        kd.load(path)
    message = str(info.value)
    assert message.startswith(f"{path}, line {line}:") or message.startswith(f"{path}: invalid YAML at line {line},"), (
        message
    )
    assert field in message, message
    assert message.count(str(path)) == 1, message


def test_toml_errors_name_file_and_field(tmp_path):
    path = _write(tmp_path, "arm.toml", "gravity = [0, 0, nan]\n[[joints]]\na = 1\n")
    with pytest.raises(ValueError, match=r"arm\.toml: gravity\[2\]: must be a finite number, got nan"):
        kd.load(path)
    path = _write(tmp_path, "dup.toml", "[[joints]]\na = 1\na = 2\n")
    with pytest.raises(ValueError, match=r"dup\.toml: invalid TOML"):
        kd.load(path)


def test_limits_may_be_infinite_but_not_nan(tmp_path):
    robot = kd.load(_write(tmp_path, "ok.yaml", "joints:\n  - {a: 1, limits: {lower: -.inf, upper: .inf}}\n"))
    assert robot.lower_limits[0] == -math.inf and robot.upper_limits[0] == math.inf
    with pytest.raises(ValueError, match=r"joints row 1\.limits\.upper: must be a finite number, got nan"):
        kd.load(_write(tmp_path, "bad.yaml", "joints:\n  - {a: 1, limits: {upper: .nan}}\n"))


def test_a_file_too_large_is_refused_before_reading(tmp_path):
    from kinedyn.description import files

    path = tmp_path / "big.yaml"
    with open(path, "w") as f:
        f.write("joints: [{a: 1}]\n" + "#" * (files.MAX_TEXT_BYTES + 10) + "\n")
    with pytest.raises(ValueError, match=r"big\.yaml: the file is larger than 1 MiB"):
        kd.load(path)


# ------------------------------------------------------------------ the parser itself
_NAMES = st.sampled_from(["l1", "l2", "m1", "I", "E", "S", "N", "beta", "x_2"])
_NUMBERS = st.one_of(st.integers(-1000, 1000), st.floats(-1e3, 1e3, allow_nan=False).map(lambda v: round(v, 3)))


def _leaf():
    return st.one_of(
        _NUMBERS.map(lambda v: (repr(v), sp.Integer(v) if isinstance(v, int) else sp.Float(v))),
        _NAMES.map(lambda n: (n, sp.Symbol(n))),
    )


def _tree(children):
    """(text, the SymPy object built directly) pairs: the parser must build the same object."""
    binary = st.tuples(children, st.sampled_from(["+", "-", "*"]), children).map(
        lambda t: (
            f"({t[0][0]}) {t[1]} ({t[2][0]})",
            {"+": sp.Add, "-": lambda a, b: a - b, "*": sp.Mul}[t[1]](t[0][1], t[2][1]),
        )
    )
    power = st.tuples(children, st.integers(-3, 3)).map(lambda t: (f"({t[0][0]})**{t[1]}", t[0][1] ** t[1]))
    function = st.tuples(st.sampled_from(["sin", "cos", "sqrt", "exp", "atan"]), children).map(
        lambda t: (f"{t[0]}({t[1][0]})", FUNCTIONS[t[0]][0](t[1][1]))
    )
    return st.one_of(binary, power, function)


@settings(max_examples=200, deadline=None)
@given(st.recursive(_leaf(), _tree, max_leaves=8))
def test_the_parser_builds_the_expression_the_text_writes(pair):
    text, expected = pair
    try:
        got = parse_expression(text)
    except ValueError as e:  # only for values that are not finite reals, or too large
        assert any(
            w in str(e) for w in ("not a real", "not a finite", "division by zero", "larger than", "too large")
        ), e
        return
    if isinstance(got, float):
        assert not expected.free_symbols
        assert math.isclose(got, complex(expected.evalf()).real, rel_tol=1e-12, abs_tol=1e-12)
    else:
        # Same symbols, and the same value at sample points: symbolic equality is undecidable in
        # general (simplify leaves sin(l1 + 1.0) - sin(l1 + 1) alone), so compare numbers.
        assert got.free_symbols == expected.free_symbols
        for point in (0.37, -1.21):
            values = {s: point + 0.1 * i for i, s in enumerate(sorted(got.free_symbols, key=str))}
            want = complex(expected.evalf(30, subs=values))
            if cmath.isfinite(want) and abs(want) < 1e12:
                assert cmath.isclose(complex(got.evalf(30, subs=values)), want, rel_tol=1e-9, abs_tol=1e-9), text


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.sampled_from(list("0123456789.+-*/()e ,_abcxyzsinqrtpo") + ["**", "exp(", "9**9", "__", "nan"]), max_size=40
    ).map("".join)
)
def test_any_text_is_a_value_or_a_value_error(text):
    try:
        value = parse_expression(text)
    except ValueError:
        return
    assert isinstance(value, (float, sp.Expr))
    if isinstance(value, float):
        assert math.isfinite(value)


def test_parse_number_refuses_names_and_reads_constants():
    assert parse_number("pi/2") == pytest.approx(math.pi / 2)
    assert parse_number(" 2.5e-3 ") == 2.5e-3
    with pytest.raises(ValueError, match="'l1' is a name, but a number is needed"):
        parse_number("2*l1")
    with pytest.raises(ValueError, match="'sin' is a function"):
        parse_expression("sin")


def test_values_given_as_text_to_subs_are_parsed_not_evaluated(tmp_path):
    robot = kd.load(os.path.join(ROOT, "examples", "robots", "two_link_symbolic.yaml"))
    name = sorted(map(str, robot.symbols))[0]
    marker = tmp_path / "code-ran"
    with pytest.raises(ValueError, match="not a known function"):
        robot.subs({name: "exec(chr(49))"})
    with pytest.raises(ValueError):
        robot.subs({name: _exec_expression(marker)})
    assert not marker.exists()
    numeric = robot.subs({s: "pi/4" for s in map(str, robot.symbols)})
    assert not numeric.symbols


@pytest.mark.parametrize(
    "text",
    [
        "joints:\n  - {a: 1, mass: 1, inertia: {ixx: 1, iyy: 1, izz: -0.1}}\n",
        "links:\n  - {name: link1, joint: {type: revolute}, inertial: {mass: 1, inertia: {ixx: 1, iyy: 1, izz: -0.2}}}\n",
    ],
)
def test_the_inertia_policy_applies_to_robot_files(tmp_path, text):
    path = _write(tmp_path, "arm.yaml", text)
    with pytest.raises(ValueError, match=r"arm\.yaml: link 'link1': inertia tensor is not positive semi-definite"):
        kd.load(path, inertia="strict")
    with pytest.warns(kd.PhysicalConsistencyWarning, match="link 'link1'"):
        kept = kd.load(path)
    with pytest.warns(kd.PhysicalConsistencyWarning, match="repaired"):
        repaired = kd.load(path, inertia="repair")

    def smallest_moment(robot):
        return min(np.linalg.eigvalsh(np.array(robot.tree.bodies[0].inertia.inertia, dtype=float)))

    assert smallest_moment(kept) < 0 and smallest_moment(repaired) >= -1e-15


def test_characters_and_encodings_the_formats_refuse_are_value_errors(tmp_path):
    path = _write(tmp_path, "nul.yaml", "joints:\n  - {a: 1}\x00\n")
    with pytest.raises(ValueError, match=r"nul\.yaml: invalid YAML at line 2: the character '\\x00' is not allowed"):
        kd.load(path)
    path = tmp_path / "bad.yaml"
    path.write_bytes(b"joints:\n  - {a: 1}\n# \xff\xfe\n")
    with pytest.raises(ValueError, match=r"bad\.yaml: the file is not UTF-8 text"):
        kd.load(path)
    path = _write(tmp_path, "enc.urdf", '<?xml version="1.0" encoding="utf-nan"?><robot name="x"/>')
    with pytest.raises(ValueError, match=r"enc\.urdf: the XML declaration names an unknown encoding"):
        kd.load(path)


def test_a_toml_integer_beyond_pythons_digit_limit_names_the_file(tmp_path):
    path = _write(tmp_path, "big.toml", "name = " + "7" * 5000 + "\n[[joints]]\na = 1\n")
    with pytest.raises(ValueError, match=r"big\.toml: invalid TOML: Exceeds the limit"):
        kd.load(path)


@pytest.mark.parametrize("value", ["2001-12-14", "!!timestamp 2001-12-14nan", "!!binary aGVsbG8=", "!!set {a: null}"])
def test_yaml_types_a_robot_file_has_no_use_for_are_refused_with_their_line(tmp_path, value):
    path = _write(tmp_path, "arm.yaml", f"name: arm\njoints:\n  - {{a: 1, d: {value}}}\n")
    with pytest.raises(
        ValueError,
        match=r"arm\.yaml: invalid YAML at line 3, column \d+: the YAML type \w+ .*has no meaning in a robot file",
    ):
        kd.load(path)
