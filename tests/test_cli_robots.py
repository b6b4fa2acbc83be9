"""The command line on real robots: a floating base's degrees of freedom and coordinates labelled
in every table, readable poses, unit slips and misspelt names caught, mimic joints marked."""

from __future__ import annotations

import re

import numpy as np
import pytest
from reference import UR5, erd
from scipy.spatial.transform import Rotation

import kinedyn as kd
from kinedyn.cli import main
from kinedyn.coordinates import coordinate_labels, velocity_labels

pytest.importorskip("kinedyn._core", reason="the native module is not built")

# a floating body with one leg: nq = 7 + 2, nv = 6 + 2
LEGGED = """<robot name="legged">
  <link name="body"><inertial><mass value="2.0"/><origin xyz="0 0 0"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="thigh"><inertial><mass value="0.5"/><origin xyz="0 0 -0.1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="shank"><inertial><mass value="0.25"/><origin xyz="0 0 -0.1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="foot"/>
  <joint name="hip" type="revolute"><parent link="body"/><child link="thigh"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="10"/></joint>
  <joint name="knee" type="revolute"><parent link="thigh"/><child link="shank"/><origin xyz="0 0 -0.2"/>
    <axis xyz="0 1 0"/><limit lower="-2.5" upper="0.1" effort="10" velocity="10"/></joint>
  <joint name="ankle" type="fixed"><parent link="shank"/><child link="foot"/><origin xyz="0 0 -0.2"/></joint>
</robot>
"""


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture
def legged(tmp_path):
    path = tmp_path / "legged.urdf"
    path.write_text(LEGGED)
    return str(path)


def row_labels(text: str, title: str) -> list[str]:
    """The row labels of the table(s) titled ``title`` (a wide table is printed in parts, each with
    the labels), from the first part."""
    lines = text.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith(title))
    labels = []
    for line in lines[start + 1 :]:
        if line.startswith("└"):
            break
        if line.startswith("│"):
            labels.append(line.split("│")[1].strip())
    return labels


def header(text: str, title: str) -> list[str]:
    """Every column header of the table(s) titled ``title``, all parts together."""
    lines = text.splitlines()
    out: list[str] = []
    for k, line in enumerate(lines):
        if line.startswith(title):
            out += [c.strip() for c in lines[k + 2].split("┃")[2:-1]]
    return out


def test_dynamics_labels_every_degree_of_freedom_of_a_floating_base(capsys, legged):
    robot = kd.load(legged, floating_base=True)
    q = robot.neutral()
    code, out, err = run(capsys, "dynamics", legged, "--floating-base", "--q", *map(str, q))
    assert code == 0, err
    rows = row_labels(out, "g(q), gravity torque")
    assert rows == velocity_labels(robot) and len(rows) == robot.nv == 8
    # the body's weight is the free-flyer's vz entry, not a joint's
    weight = f"{(2.0 + 0.5 + 0.25) * 9.81:.6g}"
    vz = [x for x in out.splitlines() if x.startswith("│ root_joint.vz ")]
    assert any(weight in x for x in vz) and not any(weight in x for x in out.splitlines() if x.startswith("│ hip "))
    assert header(out, "M(q), mass matrix") == velocity_labels(robot)


def test_jacobian_labels_every_column_of_a_floating_base(capsys, legged):
    robot = kd.load(legged, floating_base=True)
    code, out, err = run(capsys, "jacobian", legged, "--floating-base", "--frame", "foot")
    assert code == 0, err
    assert header(out, "Jacobian") == velocity_labels(robot)
    doc = __import__("json").loads(run(capsys, "jacobian", legged, "--floating-base", "--json")[1])
    assert doc["velocity_labels"] == velocity_labels(robot) and doc["coordinate_labels"] == coordinate_labels(robot)


def test_fk_of_a_floating_base_does_not_call_quaternions_radians(capsys, legged):
    code, out, err = run(capsys, "fk", legged, "--floating-base")
    assert code == 0, err
    first = out.splitlines()[0]
    assert "quaternion" in first and "rad/m)" not in first


def test_fk_pose_table_is_labelled_and_rpy_is_fixed_notation(capsys):
    # example-robot-data's UR5 (angles 1.570796325) at zero: rpy has a 5.6e-10 deg entry
    path = erd(*UR5)
    code, out, err = run(capsys, "fk", path)
    assert code == 0, err
    assert header(out, "pose of") == ["x axis", "y axis", "z axis", "origin"]
    assert row_labels(out, "pose of") == ["x", "y", "z", "(homogeneous)"]
    rpy = re.search(r"rpy \[([^\]]*)\] deg", out).group(1)
    assert "e" not in rpy and "-0.0000" not in rpy
    roll, pitch, yaw = (float(v) for v in rpy.split())
    # R = Rz(yaw) Ry(pitch) Rx(roll) (SciPy's intrinsic z-y'-x'' angles) rebuilds the pose's rotation
    R = Rotation.from_euler("ZYX", [yaw, pitch, roll], degrees=True).as_matrix()
    np.testing.assert_allclose(R, kd.load(path).pose(np.zeros(6))[:3, :3], atol=1e-5)
