"""The command line never shows a traceback for a user's mistake (issue 11, section 9).

Every command is run on bad robot files of each kind, unwritable output paths, wrong counts of
values and symbolic robot files; each must end with exit status != 0 and one line on stderr that names
the file or the flag. The error mechanism itself (user error 1, internal error 70 with a "rerun with
--debug" line, Ctrl-C 130, out of memory) is checked by making a command raise each kind.
"""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
import kinedyn.cli as cli  # noqa: E402
import kinedyn.cli.commands.fk as fk_command  # noqa: E402
from kinedyn.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "robots"
SYMBOLIC = EXAMPLES / "two_link_symbolic.yaml"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def assert_one_line_error(code, err, *names):
    """Exit status != 0, exactly one line on stderr, no traceback, and every one of ``names`` in it."""
    assert code != 0, err
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for name in names:
        assert str(name) in lines[0], (name, lines[0])
    return lines[0]


# ------------------------------------------------------------------ commands, each with arguments that would run it
def commands(tmp: Path):
    """(command, arguments after ROBOT) for every command that reads a robot."""
    return [
        ("info", []),
        ("fk", []),
        ("jacobian", []),
        ("dynamics", []),
        ("ik", ["--xyz", "1", "1", "0"]),
        ("simulate", ["--t", "0.01"]),
        ("check", ["--samples", "2", "--t", "0.1"]),
        ("identify", ["--periods", "0.2"]),
        ("report", ["-o", tmp / "r.html", "--t", "0.01", "--eom-joints", "0"]),
        ("derive", []),
        ("codegen", ["--algorithms", "gravity"]),
        ("view", ["--no-wait", "--port", "0"]),  # the live viewer: starts its server and stops at once
        ("convert", [tmp / "converted.urdf"]),
    ]


def test_every_robot_command_is_covered(tmp_path):
    """The list above is every command of the parser that takes a ROBOT (a new command joins it)."""
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    with_robot = {name for name, p in sub.choices.items() if any(a.dest == "robot" for a in p._actions)}
    assert with_robot == {c for c, _ in commands(tmp_path)}


# ------------------------------------------------------------------ bad robot files
TREE_YAML = """name: tree
links:
  - {name: l1, parent: base, joint: {name: j1, type: revolute, axis: [0, 0, 1]}, inertial: {mass: 1, com: [0.5, 0, 0], inertia: {izz: 0.1}}}
  - {name: l2, parent: l1, joint: {name: j2, type: revolute, axis: [0, 0, 1], origin: {xyz: [1, 0, 0]}}, inertial: {mass: 1}}
"""


def _mutations():
    """(file name, text or bytes) of robot files that are wrong in one way each."""
    yaml_text = (EXAMPLES / "tutorial_two_link.yaml").read_text()
    toml_text = (EXAMPLES / "elbow_arm.toml").read_text()
    urdf_text = (EXAMPLES / "planar_2r.urdf").read_text()
    cut = yaml_text.index("com: [-1.5") + 8
    out = {
        # YAML
        "truncated.yaml": yaml_text[:cut],
        "wrong_type_list.yaml": yaml_text.replace("a: 2.0", "a: [2.0, 1]"),
        "wrong_type_mapping.yaml": yaml_text.replace("mass: 1.0", "mass: {kg: 1}", 1),
        "unknown_key.yaml": yaml_text + "colour: red\n",
        "non_numeric.yaml": yaml_text.replace("a: 3.0", "a: '3.0 m!'"),
        "bad_convention.yaml": yaml_text.replace("convention: standard", "convention: sideways"),
        "short_gravity.yaml": yaml_text.replace("gravity: [0, -9.81, 0]", "gravity: [0, -9.81]"),
        "joints_strings.yaml": "name: x\nconvention: standard\njoints: [q1, q2]\n",
        "no_joints.yaml": "name: x\nconvention: standard\n",
        "a_list.yaml": "- just\n- a list\n",
        "empty.yaml": "",
        "tabs.yaml": "name: x\n\tjoints: []\n",
        "invalid_utf8.yaml": yaml_text.encode() + b"\nname2: \xff\xfe\n",
        # kinds the issue found giving tracebacks (a loader raising other than ValueError)
        "attribute.yaml": yaml_text.replace("a: 2.0", "a: 'x.y'"),
        "complex.yaml": yaml_text.replace("a: 2.0", "a: 'sqrt(-1)'"),
        "huge_integer.yaml": yaml_text.replace("mass: 1.0", "mass: 1" + "0" * 400, 1),
        "parent_list.yaml": TREE_YAML.replace("parent: l1", "parent: [1, 2]"),
        "nested.yaml": yaml_text.replace("a: 2.0", "a: " + "[" * 3000 + "]" * 3000),
        # TOML
        "truncated.toml": toml_text[: toml_text.index("iyy = 0.33") + 6],
        "wrong_type.toml": toml_text.replace("d = 3.0", "d = [1, 2]"),
        "unknown_key.toml": "colour = 'red'\n" + toml_text,
        "bool_angle.toml": toml_text.replace("alpha = 90.0", "alpha = true"),
        "binary.toml": bytes(range(256)),
        # URDF
        "truncated.urdf": urdf_text[: len(urdf_text) // 2],
        "missing_parent.urdf": urdf_text.replace('<parent link="link1"/>', '<parent link="nowhere"/>'),
        "non_numeric.urdf": urdf_text.replace('xyz="2.0 0 0"', 'xyz="two 0 0"'),
        "short_axis.urdf": urdf_text.replace(
            '<axis xyz="0 0 1"/></joint>\n  <joint name="q2"', '<axis xyz="0 1"/></joint>\n  <joint name="q2"'
        ),
        "unknown_joint_type.urdf": urdf_text.replace('type="continuous"', 'type="spinning"', 1),
        "non_numeric_mass.urdf": urdf_text.replace('<mass value="1.0"/>', '<mass value="heavy"/>', 1),
        "not_xml.urdf": "hello, robot",
        "wrong_root.urdf": "<?xml version='1.0'?><robot2 name='x'/>",
    }
    return out


MUTATIONS = _mutations()


@pytest.fixture(scope="module")
def bad_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bad robots")  # a space in the path, as users have
    paths = {}
    for name, text in MUTATIONS.items():
        path = folder / name
        (path.write_bytes if isinstance(text, bytes) else path.write_text)(text)
        with pytest.raises(Exception):  # precondition: the mutation really is a bad file
            kd.load(path)
        paths[name] = path
    return paths


@pytest.mark.parametrize("name", sorted(MUTATIONS))
def test_bad_robot_file_is_one_line_naming_the_file(capsys, tmp_path, bad_files, name):
    path = bad_files[name]
    for command, extra in commands(tmp_path):
        code, out, err = run(capsys, command, path, *extra)
        assert_one_line_error(code, err, path)
        assert not (tmp_path / "r.html").exists()


def test_missing_and_unsupported_robot_files(capsys, tmp_path):
    for command, extra in commands(tmp_path):
        code, _, err = run(capsys, command, tmp_path / "missing.yaml", *extra)
        assert_one_line_error(code, err, "missing.yaml", "does not exist")
        # .sdf: the CLI accepts exactly what kinedyn.load reads, and says which extensions those are
        (tmp_path / "arm.sdf").write_text((EXAMPLES / "planar_2r.urdf").read_text())
        code, _, err = run(capsys, command, tmp_path / "arm.sdf", *extra)
        line = assert_one_line_error(code, err, "arm.sdf", ".urdf, .yaml, .yml, .toml, .xml, .xacro")
        with pytest.raises(ValueError, match="unknown robot file extension"):
            kd.load(tmp_path / "arm.sdf")
        code, _, err = run(capsys, command, tmp_path, *extra)  # a folder
        assert_one_line_error(code, err, str(tmp_path))
    assert line
    # the CLI's table is load()'s: every extension in it is one load() reads (an empty file fails
    # for its content, not its name), and .sdf is not
    for ext in cli.ROBOT_FILE_EXTENSIONS:
        empty = tmp_path / f"empty{ext}"
        empty.write_text("")
        with pytest.raises(Exception) as info:
            kd.load(empty)
        assert "extension" not in str(info.value), (ext, info.value)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(source=st.sampled_from(["tutorial_two_link.yaml", "elbow_arm.toml", "planar_2r.urdf"]), data=st.data())
def test_randomly_damaged_files_never_give_a_traceback(capsys, tmp_path, source, data):
    """Random cuts, deletions and insertions in real robot files: `info` and `fk` either work or
    fail with one line naming the file."""
    text = (EXAMPLES / source).read_text()
    a = data.draw(st.integers(0, len(text)))
    b = data.draw(st.integers(a, min(len(text), a + 40)))
    insert = data.draw(
        st.sampled_from(
            [
                "",
                "[",
                "{",
                "]",
                "}",
                ":",
                "- ",
                "\n",
                '"',
                "'",
                "=",
                "<",
                ">",
                "/>",
                "1e999",
                "-",
                "nan",
                "&",
                "x",
                "\t",
            ]
        )
    )
    damaged = text[:a] + insert + text[b:]
    path = tmp_path / f"damaged{Path(source).suffix}"
    path.write_text(damaged)
    for command in ("info", "fk"):
        code, _, err = run(capsys, command, path)
        if code != 0:
            assert_one_line_error(code, err, path)
        else:
            assert "Traceback" not in err


# ------------------------------------------------------------------ output paths
def output_options():
    """(command, flag) for every option that names a file to write, found in the parser."""
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    found = []
    for name, p in sub.choices.items():
        for a in p._actions:
            if isinstance(a, cli.OutputPath):  # an option, or a positional OUT (convert) named by its metavar
                found.append((name, a.option_strings[-1] if a.option_strings else a.metavar))
    return found


def test_every_file_option_is_checked():
    """Every option that writes a file is an OutputPath (checked by main before the work): the
    options are found by their help text, so a new writer that forgets the check fails here."""
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    writers = set()
    for name, p in sub.choices.items():
        for a in p._actions:
            text = f"{a.help or ''} {a.metavar or ''}".lower()
            if (a.option_strings or a.dest == "output") and (
                "write" in text or a.dest in ("output", "plot", "animate", "csv", "npz")
            ):
                writers.add((name, a.option_strings[-1] if a.option_strings else a.metavar))
    assert writers == set(output_options())
    assert ("report", "--output") in writers and ("derive", "--output") in writers and ("simulate", "--csv") in writers


def _unwritable(tmp_path):
    (tmp_path / "a folder").mkdir(exist_ok=True)
    return [
        (tmp_path / "a folder", "is a folder"),
        (tmp_path / "no such folder" / "out.txt", "does not exist"),
        (Path("/proc/self/kinedyn-out.txt"), "/proc"),
        (Path("/proc"), "/proc"),
        (Path("/sys/kinedyn.txt"), "/sys"),
        (tmp_path / "a file" / "out.txt", "is not a folder"),
        ("", "empty"),
    ]


def test_unwritable_outputs_fail_before_the_work(capsys, tmp_path, monkeypatch):
    """Each unwritable path on each output option: one line naming the flag and the reason, and the
    command's work never starts (its function is replaced by one that fails the test)."""
    (tmp_path / "a file").write_text("x")
    build = cli.build_parser

    def no_work_parser(*args, **kwargs):
        parser = build(*args, **kwargs)
        sub = next(a for a in parser._actions if a.dest == "command")
        for p in sub.choices.values():
            p.set_defaults(func=lambda args: pytest.fail("the command started its work before checking its outputs"))
        return parser

    monkeypatch.setattr(cli, "build_parser", no_work_parser)
    options = output_options()
    assert len(options) >= 6
    for command, flag in options:
        for path, reason in _unwritable(tmp_path):
            code, _, err = run(capsys, command, "planar_2r", *([flag, path] if flag.startswith("-") else [path]))
            line = assert_one_line_error(code, err, flag, reason)
            assert code == cli.EXIT_ERROR, line


def test_output_without_permission_as_the_system_says(capsys, tmp_path, monkeypatch):
    """No permission to write (checked with os.access, which answers no here for one folder, so the
    test runs the same as root, who may write anywhere)."""
    locked = tmp_path / "locked"
    locked.mkdir()
    (locked / "old.txt").write_text("x")
    real_access = os.access
    monkeypatch.setattr(
        cli.os,
        "access",
        lambda p, mode: False if Path(p).parent == locked or Path(p) == locked else real_access(p, mode),
    )
    code, _, err = run(capsys, "derive", "planar_2r", "-o", locked / "eom.txt")
    assert_one_line_error(code, err, "-o/--output", "no permission to create a file in")
    code, _, err = run(capsys, "derive", "planar_2r", "-o", locked / "old.txt")
    assert_one_line_error(code, err, "-o/--output", "no permission to write the file")


def test_output_may_not_overwrite_the_robot_file_or_another_output(capsys, tmp_path):
    robot = tmp_path / "arm.yaml"
    robot.write_text((EXAMPLES / "tutorial_two_link.yaml").read_text())
    before = robot.read_text()
    code, _, err = run(capsys, "derive", robot, "-o", robot)
    assert_one_line_error(code, err, "-o/--output", "robot file")
    assert robot.read_text() == before
    code, _, err = run(capsys, "simulate", "planar_2r", "--t", "0.01", "--csv", tmp_path / "x", "--npz", tmp_path / "x")
    assert_one_line_error(code, err, "--npz", "--csv")


def test_writable_outputs_still_work(capsys, tmp_path):
    code, out, err = run(capsys, "derive", "planar_2r", "-o", tmp_path / "eom.txt")
    assert code == 0, err
    assert "tau" in (tmp_path / "eom.txt").read_text()
    code, out, err = run(capsys, "simulate", "planar_2r", "--t", "0.02", "--csv", tmp_path / "s.csv", "--json")
    assert code == 0, err
    assert json.loads(out)["files"]["csv"] == str(tmp_path / "s.csv") and (tmp_path / "s.csv").stat().st_size > 0
    assert cli.check_output_path("/dev/null", "-o") == Path("/dev/null")  # a device is a fine place to write
    assert cli.check_output_path("/dev/stdout", "-o") == Path("/dev/stdout")  # a link into /proc, but written as /dev


# ------------------------------------------------------------------ wrong counts and bad values name the flag
COUNTS = [
    (["fk", "planar_2r", "--q", "1"], "--q needs 2 values"),
    (["jacobian", "planar_2r", "--q", "1", "2", "3"], "--q needs 2 values"),
    (["dynamics", "planar_2r", "--qd", "1"], "--qd needs 2 values"),
    (["dynamics", "planar_2r", "--qdd", "1", "2", "3"], "--qdd needs 2 values"),
    (["dynamics", "planar_2r", "--tau", "1"], "--tau needs 2 values"),
    (["ik", "elbow_3r", "--xyz", "1", "0", "0", "--q0", "1", "2"], "--q0 needs 3 values"),
    (["ik", "elbow_3r", "--xyz", "1", "0"], "argument --xyz: expected 3 arguments"),
    (["ik", "elbow_3r", "--xyz", "1", "0", "0", "--rpy", "1"], "argument --rpy: expected 3 arguments"),
    (["simulate", "planar_2r", "--q", "1"], "--q needs 2 values"),
    (["simulate", "planar_2r", "--qd", "1"], "--qd needs 2 values"),
    (["simulate", "planar_2r", "--controller", "pd", "--goal", "1"], "--goal needs 2 values"),
    (["report", "planar_2r", "--q", "1", "2", "3"], "--q needs 2 values"),
    (["report", "planar_2r", "--qd", "1"], "--qd needs 2 values"),
    (["fk", "planar_2r", "--q"], "argument --q: expected at least one argument"),
]
VALUES = [
    (["fk", "planar_2r", "--q", "1", "x"], "argument --q: invalid float value: 'x'"),
    (["dynamics", "planar_2r", "--q", "inf", "0"], "--q: value 1 (q1) is inf"),
    (["dynamics", "planar_2r", "--qd", "0", "nan"], "--qd: value 2 (q2) is nan"),
    (["ik", "elbow_3r", "--xyz", "1", "0", "0", "--q0", "0", "nan", "0"], "--q0: value 2"),
    (["ik", "elbow_3r", "--xyz", "1", "0", "nan"], "argument --xyz: must be a finite number"),
    (["simulate", "planar_2r", "--t", "-1"], "argument --t: must be a positive number"),
    (["simulate", "planar_2r", "--dt", "0"], "argument --dt: must be a positive number"),
    (["simulate", "planar_2r", "--dt", "nan"], "argument --dt: must be a positive number"),
    (["simulate", "planar_2r", "--t-move", "0"], "argument --t-move: must be a positive number"),
    (["simulate", "planar_2r", "--record-every", "0"], "argument --record-every: must be a whole number >= 1"),
    (["simulate", "planar_2r", "--record-every", "1.5"], "argument --record-every: must be a whole number >= 1"),
    (["check", "planar_2r", "--samples", "0"], "argument --samples: must be a whole number >= 1"),
    (["check", "planar_2r", "--t", "inf"], "argument --t: must be a positive number"),
    (["check", "planar_2r", "--seed", "-1"], "argument --seed: must be a whole number >= 0"),
    (["identify", "planar_2r", "--noise", "-1"], "argument --noise: must be a number >= 0"),
    (["identify", "planar_2r", "--rate", "0"], "argument --rate: must be a positive number"),
    (["identify", "planar_2r", "--period", "-2"], "argument --period: must be a positive number"),
    (["identify", "planar_2r", "--harmonics", "0"], "argument --harmonics: must be a whole number >= 1"),
    (["report", "planar_2r", "--t", "0"], "argument --t: must be a positive number"),
    (["report", "planar_2r", "--eom-joints", "-1"], "argument --eom-joints: must be a whole number >= 0"),
    (["jacobian", "planar_2r", "--reference", "sideways"], "argument --reference: invalid choice"),
    (["derive", "planar_2r", "--format", "pdf"], "argument --format: invalid choice"),
    (["fk", "planar_2r", "--no-such-flag"], "unrecognized arguments: --no-such-flag"),
    (["no-such-command"], "invalid choice: 'no-such-command'"),
]


@pytest.mark.parametrize("argv, message", COUNTS + VALUES)
def test_bad_values_name_the_flag(capsys, argv, message):
    code, _, err = run(capsys, *argv)
    assert_one_line_error(code, err, message)
    assert code == cli.EXIT_ERROR


def test_library_messages_use_the_flags(capsys, tmp_path):
    """The IK solver's messages name its Python arguments (respect_limits=False, method='numeric');
    the ik command says the flags."""
    code, _, err = run(capsys, "ik", "puma560", "--xyz", "0.4", "0.2", "0.3", "--method", "analytic")
    line = assert_one_line_error(code, err, "--method numeric", "--rpy")
    assert "method='numeric'" not in line and "4x4" not in line
    # an arm whose joint limits exclude every closed-form solution
    arm = tmp_path / "limited.yaml"
    arm.write_text(
        "name: limited\nconvention: standard\ngravity: [0, -9.81, 0]\njoints:\n"
        "  - {name: q1, a: 1.0, mass: 1, limits: {lower: 2.0, upper: 2.5}}\n"
        "  - {name: q2, a: 1.0, mass: 1, limits: {lower: 2.0, upper: 2.5}}\n"
    )
    code, out, err = run(capsys, "ik", arm, "--xyz", "1", "1", "0")
    assert code == cli.EXIT_NO, err
    assert "--ignore-limits" in out and "respect_limits" not in out
    code, out, err = run(capsys, "ik", arm, "--xyz", "1", "1", "0", "--json")
    assert json.loads(out)["message"].endswith("(--ignore-limits lists them)")
    code, out, err = run(capsys, "ik", arm, "--xyz", "1", "1", "0", "--ignore-limits", "--json")
    assert code == 0 and json.loads(out)["count"] == 2
    assert cli.in_cli_terms("set from q0; q0s; --q0", {"q0": "--q0"}) == "set from --q0; q0s; --q0"


# ------------------------------------------------------------------ symbolic robot files and --set
PLANAR_2R = {"l1": 2.0, "l2": 3.0, "m1": 1.0, "m2": 1.0, "lc1": 1.0, "lc2": 1.5, "I1": 1 / 3, "I2": 0.75, "g": 9.81}


def set_args(values):
    return [x for k, v in values.items() for x in ("--set", f"{k}={v!r}")]


def test_symbolic_file_on_a_numeric_command_says_how_to_give_values(capsys, tmp_path):
    for command, extra in commands(tmp_path):
        code, out, err = run(capsys, command, SYMBOLIC, *extra)
        if command in cli.SYMBOLIC_COMMANDS:  # info and derive show the symbols as they are
            assert code == 0, err
            continue
        line = assert_one_line_error(code, err, "l1", "m1", "--set l1=... ", "--set m1=...")
        assert code == cli.EXIT_ERROR and "use robot.subs" not in line
    # some values given: the message names only those still missing
    code, _, err = run(capsys, "fk", SYMBOLIC, "--set", "l1=2", "--set", "g=9.81")
    line = assert_one_line_error(code, err, "--set l2=...")
    assert "l1=" not in line and "g=..." not in line


def test_set_gives_a_symbolic_file_its_numbers(capsys):
    """With every value given the file is the tutorial arm: the same numbers as the built-in."""
    code, out, err = run(
        capsys, "dynamics", SYMBOLIC, "--q", "0.3", "-0.7", "--qd", "1", "2", *set_args(PLANAR_2R), "--json"
    )
    assert code == 0, err
    doc = json.loads(out)
    ref = kd.robots.planar_2r()
    q, qd = np.array([0.3, -0.7]), np.array([1.0, 2.0])
    np.testing.assert_allclose(doc["mass_matrix"], ref.mass_matrix(q), atol=1e-12)
    np.testing.assert_allclose(doc["gravity_torque"], ref.gravity_torque(q), atol=1e-12)
    np.testing.assert_allclose(doc["tau"], ref.inverse_dynamics(q, qd, np.zeros(2)), atol=1e-12)
    # before the command as a global option too
    code, out, err = main_json(capsys, *set_args(PLANAR_2R), "fk", SYMBOLIC, "--q", "0.3", "-0.7")
    np.testing.assert_allclose(out["frames"]["tool"]["pose"], ref.pose(q), atol=1e-12)
    # derive with values: fewer symbols in the equations
    code, out, err = run(capsys, "derive", SYMBOLIC, "--set", "g=9.81", "--json")
    assert code == 0, err
    assert "g" not in " ".join(json.loads(out)["g"]).replace("deg", "")


def main_json(capsys, *argv):
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0, err
    return code, json.loads(out), err


def test_set_on_built_ins_and_bad_set_values(capsys):
    _, doc, _ = main_json(capsys, "fk", "planar_2r", "--set", "l1=1", "--set", "l2=0.5", "--q", "0", "0")
    assert doc["frames"]["tool"]["position"] == pytest.approx([1.5, 0, 0])
    bad = [
        (["fk", "planar_2r", "--set", "nope=1"], "--set nope", "l1, l2"),
        (["fk", "puma560", "--set", "masses=1"], "--set masses", "a2, a3, d3, d4"),
        (["fk", SYMBOLIC, "--set", "zz=1"], "--set zz", "I1, I2, g, l1"),
        (["fk", EXAMPLES / "tutorial_two_link.yaml", "--set", "l1=1"], "--set l1", "no symbolic parameters"),
        (["fk", "planar_2r", "--set", "l1"], "argument --set: expected NAME=VALUE", "l1"),
        (["fk", "planar_2r", "--set", "l1=abc"], "argument --set: l1: the value must be a number", "abc"),
        (["fk", "planar_2r", "--set", "l1=inf"], "argument --set: l1: the value must be a number", "inf"),
        (
            ["fk", "planar_2r", "--set", "l1=exec(chr(49))"],
            "argument --set: l1: the value must be a number",
            "'exec' is not a known function",
        ),
        (["fk", "planar_2r", "--set", "l1=9**9**9"], "argument --set: l1: the value must be a number", "exponent"),
        (["fk", "planar_2r", "--set", "=1"], "argument --set: expected NAME=VALUE", "=1"),
        (["fk", "planar_2r", "--set", "l1=1", "--set", "l1=2"], "--set l1 is given twice", ""),
        (["derive", "--symbolic", "--set", "nope=1"], "--set nope", "l1"),
    ]
    for argv, first, second in bad:
        code, _, err = run(capsys, *argv)
        assert_one_line_error(code, err, first, second)
    assert cli.parse_set_value("0.25") == 0.25
    with pytest.raises(ValueError):
        cli.parse_set_value("1/0")


# ------------------------------------------------------------------ the mechanism: every exception is one line
class FakePanic(BaseException):
    """Like pyo3_runtime.PanicException: a BaseException that `except Exception` misses."""


@pytest.mark.parametrize(
    "exc, code, words",
    [
        (ValueError("bad thing"), 1, ["kinedyn fk: error: bad thing"]),
        (KeyError("unknown frame 'x'"), 1, ["kinedyn fk: error: unknown frame 'x'"]),
        (
            FileNotFoundError(2, "No such file or directory", "/x/y"),
            1,
            ["kinedyn fk: error: '/x/y': No such file or directory"],
        ),
        (PermissionError(13, "Permission denied", "out.html"), 1, ["'out.html': Permission denied"]),
        (RuntimeError("needs ffmpeg on the PATH"), 1, ["error: needs ffmpeg"]),
        (MemoryError(), 1, ["kinedyn fk: error: out of memory"]),
        (MemoryError("Unable to allocate 149. GiB"), 1, ["out of memory: Unable to allocate 149. GiB"]),
        (
            TypeError("float() argument"),
            70,
            ["kinedyn fk: internal error: TypeError: float() argument", "bug", "--debug"],
        ),
        (AttributeError("'x' has no attribute 'y'"), 70, ["internal error: AttributeError", "--debug"]),
        (RecursionError("maximum recursion depth exceeded"), 70, ["internal error: RecursionError", "--debug"]),
        (OverflowError("int too large"), 70, ["internal error: OverflowError", "--debug"]),
        (FakePanic("called `Option::unwrap()` on a `None` value"), 70, ["internal error: FakePanic", "--debug"]),
        (ValueError("line one\n  line two\n"), 1, ["error: line one line two"]),
    ],
)
def test_every_exception_is_one_line(capsys, monkeypatch, exc, code, words):
    def boom(args):
        raise exc

    monkeypatch.setattr(fk_command, "run", boom)
    got, _, err = run(capsys, "fk", "planar_2r")
    assert got == code
    assert_one_line_error(got, err, *words)
    # --debug (after the command or before it) adds the traceback, then the same line
    for argv in (["fk", "planar_2r", "--debug"], ["--debug", "fk", "planar_2r"]):
        got, _, err = run(capsys, *argv)
        assert got == code and "Traceback" in err and err.strip().splitlines()[-1].startswith("kinedyn fk: ")


def test_interrupt_exits_130_quietly(capsys, monkeypatch):
    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(fk_command, "run", interrupted)
    code, out, err = run(capsys, "fk", "planar_2r")
    assert code == 130 and err == ""


def test_a_loader_bug_names_the_file(capsys, monkeypatch, tmp_path):
    """A loader that raises something other than ValueError is a bug in kinedyn, reported as one,
    with the file it was reading."""
    import kinedyn.robot_files as files

    def broken(path, **kwargs):
        raise TypeError("unsupported operand")

    monkeypatch.setattr(files, "load", broken)
    path = tmp_path / "arm.yaml"
    path.write_text("name: x\n")
    code, _, err = run(capsys, "fk", path)
    assert code == cli.EXIT_INTERNAL
    assert_one_line_error(code, err, f"while loading robot file '{path}'", "TypeError: unsupported operand", "--debug")


def test_warnings_are_one_line(capsys, monkeypatch):
    import warnings

    def warns(args):
        warnings.warn(
            "inertia of link 'antenna' is not positive semi-definite\n(eigenvalues -3.5e-08)", UserWarning, stacklevel=1
        )
        return 0

    monkeypatch.setattr(fk_command, "run", warns)
    code, _, err = run(capsys, "fk", "planar_2r")
    assert (
        code == 0
        and err.strip()
        == "kinedyn fk: warning: inertia of link 'antenna' is not positive semi-definite (eigenvalues -3.5e-08)"
    )


# ------------------------------------------------------------------ the real command, in a subprocess
def kinedyn(*argv, timeout=120, **kw):
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(Path(kd.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])
    )
    return subprocess.run(
        [sys.executable, "-m", "kinedyn", *map(str, argv)],
        capture_output=True,
        text=True,
        env=env,
        timeout=timeout,
        **kw,
    )


def test_subprocess_bad_file_bad_output_and_debug(tmp_path, bad_files):
    done = kinedyn("dynamics", bad_files["truncated.yaml"])
    assert done.returncode == 1 and done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert str(bad_files["truncated.yaml"]) in done.stderr
    done = kinedyn("report", "planar_2r", "-o", "/proc/self/report.html")
    assert done.returncode == 1 and done.stderr.strip() == (
        "kinedyn report: error: -o/--output: cannot write '/proc/self/report.html': it is in /proc, the kernel's virtual files, not a place for output"
    )
    done = kinedyn("fk", SYMBOLIC, "--debug")
    assert (
        done.returncode == 1
        and "Traceback" in done.stderr
        and done.stderr.strip().splitlines()[-1].startswith("kinedyn fk: error:")
    )
    done = kinedyn("fk", "planar_2r", "--q", "1")
    assert done.returncode == 1 and done.stderr.count("\n") == 1 and "--q needs 2 values" in done.stderr


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="a pseudo-terminal")
def test_subprocess_ctrl_c_exits_130_without_a_traceback(tmp_path):
    """Ctrl-C on a terminal during a long adaptive (SciPy) run. The child's output goes to a
    pseudo-terminal, so its progress bar shows once the run has gone a second: that is when the
    interrupt is sent (not after a fixed sleep, which on a loaded machine can fall inside Python's
    own start-up, before the command runs). tests/test_interrupts.py covers interrupts that a
    library swallows and long native runs."""
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join([str(Path(kd.__file__).parents[1]), os.environ.get("PYTHONPATH", "")]),
        PYTHONFAULTHANDLER="1",
        COLUMNS="120",
    )
    master, terminal = os.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "kinedyn", "simulate", "planar_2r", "--t", "1e6", "--dt", "0.5", "--method", "rk45"],
        stdin=subprocess.DEVNULL,
        stdout=terminal,
        stderr=terminal,
        env=env,
    )
    os.close(terminal)
    seen = b""

    def read_until(done, timeout):
        """Read the terminal (a full pty would block the child) until ``done(seen)`` or the end."""
        nonlocal seen
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and not done(seen):
            ready, _, _ = select.select([master], [], [], 0.2)
            if ready:
                try:
                    chunk = os.read(master, 65536)
                except OSError:  # EIO: the child closed the terminal (it exited)
                    return
                if not chunk:
                    return
                seen += chunk

    try:
        read_until(lambda text: b"simulate planar_2r" in text, 180)
        assert b"simulate planar_2r" in seen and proc.poll() is None, (proc.poll(), seen[-4000:])
        proc.send_signal(signal.SIGINT)
        read_until(lambda text: False, 60)  # until the child closes the terminal
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            pytest.fail(f"the child did not exit within 60 s of SIGINT: {seen[-4000:]!r}")
    finally:
        os.close(master)
    text = seen.decode(errors="replace")
    assert proc.returncode == 130 and "Traceback" not in text and "KeyboardInterrupt" not in text, text[-4000:]


# ------------------------------------------------------------------ names that look like terminal markup
MARKUP_ROBOT = """name: "[/bold] arm [red]"
source: "[/x] source"
convention: standard
joints:
  - {name: "[/q1]", a: 1.0, mass: 1}
  - {name: "q2 [link=x]", a: 1.0, mass: 1}
"""


def test_names_that_look_like_rich_markup_are_printed_as_they_are(capsys, tmp_path, monkeypatch):
    """rich reads '[/bold]' in printed text as a closing tag (MarkupError: a traceback before this
    was fixed); names from a robot file are escaped wherever the commands print them."""
    monkeypatch.setenv("COLUMNS", "200")  # wide enough that rich does not wrap the names in table cells
    path = tmp_path / "markup.yaml"
    path.write_text(MARKUP_ROBOT)
    for command, extra in commands(tmp_path):
        code, out, err = run(capsys, command, path, *extra)
        assert code == 0 and err == "", (command, err)
        if command != "derive":
            assert "[/bold] arm [red]" in out, (command, out)
    code, out, _ = run(capsys, "info", path)
    assert "[/q1]" in out and "q2 [link=x]" in out and "[/x] source" in out
    code, out, _ = run(capsys, "dynamics", path)
    assert "[/q1]" in out


def test_output_into_a_closed_pipe_is_quiet(capsys, monkeypatch):
    """`kinedyn derive ... | head`: the reader leaves early; status 0 and nothing on stderr."""

    def closed(args):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(fk_command, "run", closed)
    code, _, err = run(capsys, "fk", "planar_2r")
    assert code == 0 and err == ""


def test_set_reads_arithmetic_on_numbers(capsys):
    """--set values go through kinedyn's expression parser: arithmetic on numbers, never eval."""
    _, by_expression, _ = main_json(
        capsys, "fk", "planar_2r", "--set", "l1=sqrt(2)/2", "--set", "l2=pi/4", "--q", "0", "0"
    )
    _, by_number, _ = main_json(
        capsys,
        "fk",
        "planar_2r",
        "--set",
        f"l1={2**0.5 / 2!r}",
        "--set",
        f"l2={3.141592653589793 / 4!r}",
        "--q",
        "0",
        "0",
    )
    assert by_expression == by_number


def test_info_of_the_symbolic_example_file(capsys):
    """`kinedyn info examples/robots/two_link_symbolic.yaml` ended in a traceback (issue 12): it prints the
    robot with its parameters as symbols, in text and in JSON."""
    code, out, err = run(capsys, "info", SYMBOLIC)
    assert code == 0, err
    assert "Traceback" not in out + err
    assert "symbolic parameters: I1, I2, g, l1, l2, lc1, lc2, m1, m2" in " ".join(out.split())
    code, out, err = run(capsys, "info", SYMBOLIC, "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["n"] == 2 and d["gravity"] == [0.0, "-g", 0.0]
