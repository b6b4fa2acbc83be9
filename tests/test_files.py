"""Robot files: round trips of every built-in (YAML and TOML), tree round trips of URDF robots,
degrees, symbols, the examples of docs/model-files.md, and every error case."""

from __future__ import annotations

import math
import pathlib
import re

import numpy as np
import pytest
import sympy as sp
from reference import PANDA, UR5, all_frame_poses, erd, random_q

import kinedyn as kd
from kinedyn.description.files import save
from kinedyn.robot_files import load

DOCS = pathlib.Path(__file__).resolve().parents[1] / "docs" / "model-files.md"


def assert_same_robot(a, b, seed=0):
    """Same frames and poses (reference FK), same inertias, limits, joints and gravity."""
    assert a.joint_names == b.joint_names
    assert a.frame_names == b.frame_names and a.tool == b.tool
    np.testing.assert_allclose(a.gravity, b.gravity)
    np.testing.assert_allclose(a.inertial_parameters(), b.inertial_parameters(), atol=1e-12)
    for attr in ("lower_limits", "upper_limits", "velocity_limits", "effort_limits"):
        np.testing.assert_array_equal(getattr(a, attr), getattr(b, attr))
    for ja, jb in zip(a.joints, b.joints):
        assert (ja.kind, ja.armature, ja.viscous, ja.coulomb) == pytest.approx(
            (jb.kind, jb.armature, jb.viscous, jb.coulomb)
        )
    rng = np.random.default_rng(seed)
    for _ in range(3):
        q = random_q(a, rng)
        pa, pb = all_frame_poses(a, q), all_frame_poses(b, q)
        for name in pa:
            np.testing.assert_allclose(pb[name], pa[name], atol=1e-12, err_msg=name)


@pytest.mark.parametrize("ext", ["yaml", "toml"])
@pytest.mark.parametrize("name", kd.robots.names())
def test_builtin_round_trip(name, ext, tmp_path):
    robot = kd.robots.get(name)
    path = tmp_path / f"{name}.{ext}"
    save(robot, path)
    again = load(path)
    assert again.dh is not None and again.dh_convention == robot.dh_convention
    assert "joints:" in path.read_text() or "[[joints]]" in path.read_text()
    assert_same_robot(robot, again)


@pytest.mark.parametrize("ext", ["yaml", "toml"])
def test_puma_with_friction_and_base_pose_round_trip(ext, tmp_path):
    robot = kd.Robot.from_dh(
        kd.robots.puma560(friction=True).dh,
        base_pose=np.array([[0, -1, 0, 0.1], [1, 0, 0, 0.2], [0, 0, 1, 0.6], [0, 0, 0, 1.0]]),
        tool=np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0.05], [0, 0, 0, 1.0]]),
        name="puma_on_a_stand",
    )
    path = tmp_path / f"p.{ext}"
    robot.save(path)
    assert_same_robot(robot, kd.load(path))


@pytest.mark.parametrize("ext", ["yaml", "toml"])
def test_modified_dh_round_trip(ext, tmp_path):
    rows = [dict(alpha=0.0, a=0.0, d=0.3), dict(alpha=math.pi / 2, a=0.1), dict(alpha=0.0, a=0.5, kind="prismatic")]
    robot = kd.Robot.from_dh(rows, convention="modified")
    robot.save(tmp_path / f"m.{ext}")
    again = kd.load(tmp_path / f"m.{ext}")
    assert again.dh_convention == "modified"
    assert_same_robot(robot, again)


@pytest.mark.parametrize("ext", ["yaml", "toml"])
@pytest.mark.parametrize("which", [UR5, PANDA])
def test_urdf_robot_round_trip_as_tree(which, ext, tmp_path):
    robot = kd.Robot.from_urdf(erd(*which))
    path = tmp_path / f"r.{ext}"
    robot.save(path)
    assert "links" in path.read_text()
    again = kd.load(path)
    assert again.dh is None and again.base == robot.base
    assert_same_robot(robot, again)


def test_locked_dh_robot_saves_as_tree(tmp_path):
    robot = kd.robots.puma560().lock_joints({"q6": 0.3})
    robot.save(tmp_path / "p.yaml")
    assert "links:" in (tmp_path / "p.yaml").read_text()
    assert_same_robot(robot, kd.load(tmp_path / "p.yaml"))


def test_rpy_round_trip_at_gimbal_lock(tmp_path):
    R = np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]) @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0.0]])
    T = np.eye(4)
    T[:3, :3] = R
    robot = kd.Robot([kd.Link("a", None, kd.Joint("j"), T)], [kd.Frame("f", "a", T)])
    robot.save(tmp_path / "g.yaml")
    assert_same_robot(robot, kd.load(tmp_path / "g.yaml"))


# ------------------------------------------------------------------------ degrees, symbols, flavours
def test_degrees(tmp_path):
    path = tmp_path / "d.yaml"
    path.write_text(
        "units: {angle: deg}\n"
        "base_pose: {rpy: [0, 0, 90]}\n"
        "joints:\n"
        "  - {theta: 90, alpha: -90, a: 1, limits: {lower: -90, upper: 45, velocity: 180}}\n"
        "  - {type: prismatic, theta: 30, limits: {lower: 0.1, upper: 0.5}}\n"
    )
    robot = kd.load(path)
    same_in_radians = kd.Robot.from_dh(
        [dict(theta=math.pi / 2, alpha=-math.pi / 2, a=1.0), dict(kind="prismatic", theta=math.pi / 6)],
        base_pose=np.array([[0, -1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]),
    )
    q = np.array([0.3, 0.2])
    np.testing.assert_allclose(
        all_frame_poses(robot, q)["tool"], all_frame_poses(same_in_radians, q)["tool"], atol=1e-12
    )
    np.testing.assert_allclose(robot.lower_limits, [-math.pi / 2, 0.1])
    np.testing.assert_allclose(robot.upper_limits, [math.pi / 4, 0.5])
    assert robot.velocity_limits[0] == pytest.approx(math.pi)


def test_symbolic_values(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(
        "gravity: [0, -g, 0]\n"
        "joints:\n"
        "  - {a: l1, mass: m1, com: ['-l1/2', 0, 0], inertia: {iyy: 'm1*l1**2/12', izz: 'm1*l1**2/12'}}\n"
        "  - {a: L2, alpha: 'pi/2', mass: 2, inertia: {ixx: I, iyy: I, izz: I}}\n"
    )
    robot = kd.load(path)
    assert {str(s) for s in robot.symbols} == {"g", "l1", "m1", "L2", "I"}
    assert robot.dh[1].alpha == pytest.approx(math.pi / 2)  # numeric expressions become floats
    values = {"g": 9.81, "l1": 2.0, "m1": 3.0, "L2": 0.5, "I": 0.1}
    numeric = robot.subs(values)
    expected = kd.Robot.from_dh(
        [
            dict(a=2.0, inertia=kd.Inertia(3.0, (-1.0, 0, 0), np.diag([0, 1.0, 1.0]))),
            dict(a=0.5, alpha=math.pi / 2, inertia=kd.Inertia(2.0, (0, 0, 0), np.diag([0.1, 0.1, 0.1]))),
        ],
        gravity=(0, -9.81, 0),
    )
    assert_same_robot(numeric, expected)
    # a symbolic robot saves its expressions as strings and loads back the same expressions
    robot.save(tmp_path / "s2.toml")
    again = kd.load(tmp_path / "s2.toml")
    assert sp.simplify(again.dh[0].inertia.inertia[2][2] - sp.sympify("m1*l1**2/12")) == 0
    assert_same_robot(numeric, again.subs(values))


def test_load_kwargs_and_urdf_dispatch(tmp_path):
    kd.robots.planar_2r().save(tmp_path / "p.yml")
    assert kd.load(tmp_path / "p.yml", gravity=(0, 0, -1.0)).gravity == (0.0, 0.0, -1.0)
    urdf = kd.load(erd(*UR5), tool="wrist_3_link")
    assert urdf.tool == "wrist_3_link"


@pytest.mark.parametrize("block", re.findall(r"```python\n(.*?)```", DOCS.read_text(), re.S) if DOCS.exists() else [])
def test_docs_examples_run(block):
    exec(compile(block, str(DOCS), "exec"), {})


def test_docs_have_examples():
    assert len(re.findall(r"```python\n", DOCS.read_text())) >= 3


# ------------------------------------------------------------------------ errors
def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_malformed_yaml_names_file_and_line(tmp_path):
    path = _write(tmp_path, "bad.yaml", "name: x\njoints:\n  - {a: 1\n  - {a: 2}\n")
    with pytest.raises(ValueError, match=r"bad\.yaml: invalid YAML at line 4"):
        load(path)


def test_malformed_toml_names_file_and_line(tmp_path):
    path = _write(tmp_path, "bad.toml", 'name = "x"\n\n[[joints]]\na = = 1\n')
    with pytest.raises(ValueError, match=r"bad\.toml: invalid TOML: .*line 4"):
        load(path)


def test_unknown_row_key_names_file_row_and_key(tmp_path):
    path = _write(tmp_path, "arm.yaml", "joints:\n  - {a: 1}\n  - {a: 1, mas: 2}\n")
    with pytest.raises(ValueError, match=r"arm\.yaml, line 3: joints row 2: unknown key 'mas'"):
        load(path)


def test_unknown_nested_keys(tmp_path):
    cases = {
        "limits": ("joints:\n  - {a: 1, limits: {lowr: 0}}\n", r"joints row 1\.limits: unknown key 'lowr'"),
        "inertia": (
            "joints:\n  - {a: 1, mass: 1, inertia: {ixx: 1, iyx: 0}}\n",
            r"joints row 1\.inertia: unknown key 'iyx'",
        ),
        "top": ("joints:\n  - {a: 1}\ngravty: [0, 0, -9.8]\n", r"top level: unknown key 'gravty'"),
        "tree": (
            "links:\n  - {name: a, joint: {type: revolute, axes: [0, 0, 1]}}\n",
            r"links row 1 \('a'\)\.joint: unknown key 'axes'",
        ),
        "link": ("links:\n  - {name: a, inertia: {}}\n", r"links row 1: unknown key 'inertia'"),
        "pose": ("base_pose: {xyz: [0, 0, 1], rot: [0, 0, 0]}\njoints: [{a: 1}]\n", r"base_pose: unknown key 'rot'"),
        "units": ("units: {angle: grad}\njoints: [{a: 1}]\n", r"units\.angle: must be 'deg' or 'rad'"),
    }
    for name, (text, message) in cases.items():
        path = _write(tmp_path, f"{name}.yaml", text)
        with pytest.raises(ValueError, match=rf"{name}\.yaml(, line \d+)?: {message}"):
            load(path)


def test_bad_values(tmp_path):
    cases = {
        "neg": ("joints:\n  - {a: 1, mass: -2}\n", r"joints row 1: mass.* negative"),
        "expr": (
            "joints:\n  - {a: '__import__(\"os\")'}\n",
            r"joints row 1\.a: .* not a number or an arithmetic expression",
        ),
        "vec": ("joints:\n  - {a: 1, com: [0, 0]}\n", r"joints row 1\.com: expected a list of 3 values"),
        "kind": ("joints:\n  - {type: fixed}\n", r"joints row 1\.type: must be 'revolute' or 'prismatic'"),
        "lim": ("joints:\n  - {limits: {lower: 1, upper: 0}}\n", r"lower limit 1\.0 exceeds upper limit 0\.0"),
        "symlim": ("joints:\n  - {limits: {lower: qmin}}\n", r"joints row 1\.limits\.lower: must be a number"),
        "parent": (
            "links:\n  - {name: a, parent: ghost, joint: {type: revolute}}\n",
            r"parent link 'ghost' does not exist",
        ),
        "both": ("joints: [{a: 1}]\nlinks: [{name: a}]\n", r"exactly one of 'joints'"),
        "list": ("- 1\n- 2\n", r"must hold a mapping"),
    }
    for name, (text, message) in cases.items():
        path = _write(tmp_path, f"{name}.yaml", text)
        with pytest.raises(ValueError, match=rf"{name}\.yaml(, line \d+)?: .*{message}"):
            load(path)


def test_unknown_extension_and_missing_file(tmp_path):
    with pytest.raises(ValueError, match=r"unknown robot file extension '\.json'"):
        load(tmp_path / "r.json")
    with pytest.raises(ValueError, match=r"missing\.yaml: cannot read"):
        load(tmp_path / "missing.yaml")
    with pytest.raises(ValueError, match=r"can only save robots as"):
        save(kd.robots.planar_2r(), tmp_path / "r.urdf")


def test_toml_reader_imports_tomli_before_python_3_11(monkeypatch, tmp_path):
    """requires-python is 3.10, where the standard library has no tomllib: the file reader takes
    tomli (the same parser, a dependency there). Simulated here: the version says 3.10, tomllib
    cannot be imported and tomllib itself stands in for tomli."""
    import importlib.util
    import sys

    import tomllib

    import kinedyn.description.file_reader as files

    path = tmp_path / "robot.toml"
    save(kd.robots.planar_2r(), path)
    monkeypatch.setattr(sys, "version_info", (3, 10, 14, "final", 0))
    monkeypatch.setitem(sys.modules, "tomllib", None)  # import tomllib raises ImportError
    monkeypatch.setitem(sys.modules, "tomli", tomllib)
    name = "kinedyn.description._file_reader_on_310"
    spec = importlib.util.spec_from_file_location(name, files.__file__)
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, name, module)
    spec.loader.exec_module(module)
    assert module.tomllib is tomllib
    data = module.parse_toml(module.read_text(str(path)), str(path))
    assert kd.Robot(module.description_from_mapping(data, str(path))).n == 2
