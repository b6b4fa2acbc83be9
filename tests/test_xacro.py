"""xacro files: expanded by the `xacro` package, with arguments, macros and $(find), into the same robot
as the URDF written out by hand; refused without trust_xacro=True, because a xacro file can run code."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.xacro import XACRO_REFUSED

pytest.importorskip("xacro", reason="the xacro package (pip install xacro) reads .xacro files")

ARM_XACRO = """<?xml version="1.0"?>
<robot name="xarm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="length" default="0.5"/>
  <xacro:arg name="prefix" default=""/>
  <xacro:property name="L" value="$(arg length)"/>
  <xacro:property name="mass" value="2.0"/>
  <xacro:macro name="segment" params="name parent axis:='0 0 1' *origin">
    <link name="$(arg prefix)${name}">
      <inertial>
        <origin xyz="${L/2} 0 0"/>
        <mass value="${mass}"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="${mass*L**2/12}" iyz="0" izz="${mass*L**2/12}"/>
      </inertial>
      <visual><geometry><mesh filename="$(find arm_description)/meshes/${name}.stl"/></geometry></visual>
    </link>
    <joint name="$(arg prefix)${name}_joint" type="revolute">
      <parent link="$(arg prefix)${parent}"/><child link="$(arg prefix)${name}"/>
      <xacro:insert_block name="origin"/>
      <axis xyz="${axis}"/>
      <limit lower="${-pi/2}" upper="${pi/2}" effort="10" velocity="2"/>
    </joint>
  </xacro:macro>
  <link name="$(arg prefix)base"/>
  <xacro:segment name="upper" parent="base"><origin xyz="0 0 0.1" rpy="0 0 ${radians(30)}"/></xacro:segment>
  <xacro:segment name="lower" parent="upper" axis="0 1 0"><origin xyz="${L} 0 0"/></xacro:segment>
</robot>
"""


def arm_urdf(length: float, prefix: str, meshes: Path) -> str:
    """The URDF the xacro above expands to, written out by hand."""
    inertia = 2.0 * length**2 / 12

    def segment(name, parent, axis, origin):
        return f"""
  <link name="{prefix}{name}">
    <inertial><origin xyz="{length / 2} 0 0"/><mass value="2.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="{inertia}" iyz="0" izz="{inertia}"/></inertial>
    <visual><geometry><mesh filename="{meshes}/{name}.stl"/></geometry></visual>
  </link>
  <joint name="{prefix}{name}_joint" type="revolute">
    <parent link="{prefix}{parent}"/><child link="{prefix}{name}"/>{origin}<axis xyz="{axis}"/>
    <limit lower="{-np.pi / 2}" upper="{np.pi / 2}" effort="10" velocity="2"/>
  </joint>"""

    return (
        f'<robot name="xarm"><link name="{prefix}base"/>'
        + segment("upper", "base", "0 0 1", f'<origin xyz="0 0 0.1" rpy="0 0 {np.radians(30)}"/>')
        + segment("lower", "upper", "0 1 0", f'<origin xyz="{length} 0 0"/>')
        + "</robot>"
    )


@pytest.fixture
def package(tmp_path):
    """A description package (share/arm_description/meshes) and, outside it, a xacro file using it."""
    share = tmp_path / "share"
    (share / "arm_description" / "meshes").mkdir(parents=True)
    (tmp_path / "robots").mkdir()
    path = tmp_path / "robots" / "arm.urdf.xacro"
    path.write_text(ARM_XACRO)
    return share, path


def assert_same_robot(a, b, seed: int = 0):
    assert a.joint_names == b.joint_names and a.frame_names == b.frame_names
    assert [j.kind for j in a.joints] == [j.kind for j in b.joints]
    np.testing.assert_allclose(
        [(*j.axis, j.lower, j.upper) for j in a.joints], [(*j.axis, j.lower, j.upper) for j in b.joints], atol=1e-12
    )
    rng = np.random.default_rng(seed)
    for _ in range(3):
        q, qd = rng.uniform(-1, 1, a.n), rng.normal(size=a.n)
        np.testing.assert_allclose(a.frame_poses(q), b.frame_poses(q), atol=1e-12)
        np.testing.assert_allclose(a.mass_matrix(q), b.mass_matrix(q), atol=1e-12)
        np.testing.assert_allclose(a.bias_torque(q, qd), b.bias_torque(q, qd), atol=1e-12)


@pytest.mark.parametrize("args", [{}, {"length": 0.8, "prefix": "left_"}])
def test_xacro_with_args_macros_and_find_is_the_urdf_written_out(package, args):
    share, path = package
    robot = kd.Robot.from_urdf(path, xacro_args=args, trust_xacro=True, package_dirs=[share])
    expected = kd.Robot.from_urdf(
        arm_urdf(float(args.get("length", 0.5)), args.get("prefix", ""), share / "arm_description" / "meshes")
    )
    assert robot.joint_names == [args.get("prefix", "") + n for n in ("upper_joint", "lower_joint")]
    assert_same_robot(robot, expected)
    # $(find arm_description) found the package in package_dirs; the file names the source
    assert robot.visuals[0].shape.filename == f"{share}/arm_description/meshes/upper.stl"
    assert robot.source == str(path)
    # kd.load takes the same arguments
    assert_same_robot(kd.load(path, xacro_args=args, trust_xacro=True, package_dirs=[share]), expected)


def test_find_without_the_package_is_a_clear_error(package, monkeypatch):
    _, path = package
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    with pytest.raises(
        ValueError, match=r"arm\.urdf\.xacro: xacro could not expand the file: .*package 'arm_description' not found"
    ):
        kd.Robot.from_urdf(path, trust_xacro=True)


def test_errors_in_the_expanded_urdf_name_the_xacro_file(tmp_path):
    path = tmp_path / "bad.urdf.xacro"
    path.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n<link name="a"/>\n'
        '<joint name="j" type="revolute"><parent link="a"/><child link="missing"/></joint></robot>'
    )
    with pytest.raises(ValueError, match=r"bad\.urdf\.xacro:\d+: joint 'j' names child link 'missing'"):
        kd.load(path, trust_xacro=True)
    with pytest.raises(ValueError, match=r"xacro argument name 'a b' is not a name"):
        kd.load(path, trust_xacro=True, xacro_args={"a b": 1})


# --------------------------------------------------------------------------------- security
EVIL_XACRO = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="lp" value="("/>
  <xacro:property name="rp" value=")"/>
  <link name="$(eval exec${lp}'open${lp}&quot;MARKER&quot;, &quot;w&quot;${rp}.write${lp}&quot;ran&quot;${rp}', dict${lp}${rp}${rp} or 'base')"/>
  <link name="tip"/>
  <joint name="j" type="continuous"><parent link="base"/><child link="tip"/></joint>
</robot>
"""


def test_a_xacro_file_is_refused_without_trust_and_its_code_does_not_run(tmp_path):
    marker = tmp_path / "ran.txt"
    path = tmp_path / "evil.urdf.xacro"
    path.write_text(EVIL_XACRO.replace("MARKER", str(marker)))
    for load in (lambda: kd.Robot.from_urdf(path), lambda: kd.load(path), lambda: kd.load(path, trust_xacro="yes")):
        with pytest.raises(
            ValueError, match=r"evil\.urdf\.xacro: expanding xacro runs the file's Python expressions.*trust_xacro=True"
        ):
            load()
    assert not marker.exists()


def test_the_refusal_is_needed_a_trusted_xacro_file_runs_code(tmp_path):
    """Why the opt-in: xacro's $(eval) gives the file Python's builtins (exec, open, import)."""
    marker = tmp_path / "ran.txt"
    path = tmp_path / "evil.urdf.xacro"
    path.write_text(EVIL_XACRO.replace("MARKER", str(marker)))
    robot = kd.Robot.from_urdf(path, trust_xacro=True)
    assert robot.joint_names == ["j"] and marker.read_text() == "ran"
    assert "can run any code" in XACRO_REFUSED


def test_the_cli_refuses_xacro_without_trust_and_passes_xacro_args(package):
    share, path = package
    env = {**os.environ, "PYTHONPATH": str(Path(kd.__file__).parents[1]), "ROS_PACKAGE_PATH": str(share)}
    run = lambda *extra: subprocess.run(
        [sys.executable, "-m", "kinedyn", "info", str(path), "--json", *extra],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    refused = run()
    assert refused.returncode == 1 and "--trust-xacro" in refused.stderr and "can run any code" in refused.stderr
    done = run("--trust-xacro", "--xacro-arg", "prefix:=right_", "--xacro-arg", "length:=0.7")
    assert done.returncode == 0, done.stderr
    assert "right_upper_joint" in done.stdout and "right_lower_joint" in done.stdout
