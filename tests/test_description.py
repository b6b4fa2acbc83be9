"""The Description the readers return, the Robot built from it, and the direction of the imports."""

import ast
import dataclasses
import pathlib
import warnings

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.description import Description
from kinedyn.description.dh import description_from_dh
from kinedyn.description.files import read_description
from kinedyn.description.joint import planar_basis
from kinedyn.description.urdf import description_from_urdf

PACKAGE = pathlib.Path(kd.__file__).parent
URDF = """<robot name="two"><link name="base"/><link name="a"><inertial><mass value="1"/>
<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def test_readers_return_a_description_and_the_robot_is_built_from_it():
    d = description_from_urdf(URDF)
    assert isinstance(d, Description)
    assert d.name == "two" and d.tree.n == 2 and d.tool == "b"
    robot = kd.Robot(d)
    assert robot.description is d
    assert kd.Robot.from_description(d).joint_names == ["j1", "j2"]
    np.testing.assert_allclose(robot.mass_matrix(np.zeros(2)), kd.Robot.from_urdf(URDF).mass_matrix(np.zeros(2)))


def test_read_description_by_extension(tmp_path):
    path = tmp_path / "arm.yaml"
    kd.robots.planar_2r().save(path)
    d = read_description(path, gravity=(0, -9.81, 0))
    assert isinstance(d, Description) and d.gravity == (0.0, -9.81, 0.0)
    assert kd.load(path).joint_names == kd.Robot(read_description(path)).joint_names


def test_a_description_checks_itself():
    with pytest.raises(ValueError, match="tool frame 'nope'"):
        dataclasses.replace(description_from_urdf(URDF), tool="nope")
    # a description of no moving joint is a robot with no degrees of freedom (Pinocchio's nq = 0)
    assert kd.Robot(Description((), name="empty")).nq == 0


def test_dh_description_matches_from_dh():
    rows = [(0, 0.3, 0, np.pi / 2), (0, 0, 0.4, 0)]
    d = description_from_dh(rows, name="arm")
    assert d.dh_convention == "standard" and d.tool == "tool"
    q = np.array([0.3, -0.2])
    np.testing.assert_allclose(kd.Robot(d).pose(q), kd.Robot.from_dh(rows).pose(q))


def test_robot_is_immutable():
    robot = kd.robots.planar_2r()
    robot.mass_matrix(np.zeros(2))  # the native model is built and cached
    with pytest.raises(AttributeError, match="immutable"):
        robot.gravity = (0.0, 0.0, 0.0)
    with pytest.raises(AttributeError, match="immutable"):
        del robot.name
    with pytest.raises(dataclasses.FrozenInstanceError):
        robot.description.gravity = (0.0, 0.0, 0.0)
    lighter = robot.replace(gravity=(0.0, 0.0, 0.0))
    assert lighter.gravity == (0.0, 0.0, 0.0) and robot.gravity != lighter.gravity
    assert np.allclose(lighter.gravity_torque(np.zeros(2)), 0.0)
    assert not np.allclose(robot.gravity_torque(np.zeros(2)), 0.0)


@pytest.mark.parametrize("normal", [(0, 0, 1), (1, 0, 0), (0, 1, 0), (0.6, 0, 0.8), (0.36, 0.48, 0.8)])
def test_planar_basis_is_right_handed_and_in_the_plane(normal):
    n = np.asarray(normal, dtype=float)
    e1, e2 = planar_basis(n)
    np.testing.assert_allclose([e1 @ e1, e2 @ e2, e1 @ e2, e1 @ n, e2 @ n], [1, 1, 0, 0, 0], atol=1e-15)
    np.testing.assert_allclose(np.cross(e1, e2), n, atol=1e-15)


def test_old_paths_warn_and_still_build_robots():
    import kinedyn.description.convert as old_convert
    import kinedyn.description.files as old_files
    import kinedyn.description.urdf as old_urdf
    from kinedyn.convert import convert

    with pytest.warns(DeprecationWarning, match="robot_from_urdf moved"):
        robot = old_urdf.robot_from_urdf(URDF)
    assert isinstance(robot, kd.Robot)
    with pytest.warns(DeprecationWarning, match="moved to kinedyn.robot_files.load"):
        assert old_files.load is kd.robot_files.load
    with pytest.warns(DeprecationWarning, match="moved to kinedyn.convert.convert"):
        assert old_convert.convert is convert
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(AttributeError):
            old_urdf.no_such_name  # noqa: B018


def _runtime_imports(tree):
    """(line, module) of every import outside ``if TYPE_CHECKING:``, relative ones resolved against
    kinedyn.description."""
    out = []

    def visit(node, typing_only):
        for child in ast.iter_child_nodes(node):
            guarded = typing_only or (isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test))
            if isinstance(child, ast.ImportFrom) and not typing_only:
                base = "kinedyn.description".split(".")[: 2 - child.level + 1] if child.level else []
                out.append((child.lineno, ".".join([*base, child.module or ""]).strip(".")))
            elif isinstance(child, ast.Import) and not typing_only:
                out.extend((child.lineno, a.name) for a in child.names)
            visit(child, guarded)

    visit(tree, False)
    return out


def test_the_description_never_imports_the_robot():
    """Imports run one way (docs/architecture.md): nothing under kinedyn/description reaches the
    facade or what builds robots (a type annotation under TYPE_CHECKING is fine)."""
    above = ("kinedyn.robot", "kinedyn.robot_files", "kinedyn.convert", "kinedyn.robots", "kinedyn.ik")
    found = [
        f"{path.name}:{line}: {module}"
        for path in sorted((PACKAGE / "description").glob("*.py"))
        for line, module in _runtime_imports(ast.parse(path.read_text()))
        if module in above or module.startswith(tuple(a + "." for a in above))
    ]
    assert found == []
    assert "kinedyn.robot" in {m for _, m in _runtime_imports(ast.parse("from ..robot import Robot"))}
