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


# ------------------------------------------------------------------ kinedyn convert
# a gripper whose second finger mimics the first (as the Panda's): nq = 2, MuJoCo keeps 3
GRIPPER = """<robot name="gripper">
  <link name="base"/>
  <link name="palm"><inertial><mass value="1.0"/><origin xyz="0 0 0.05"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="left"><inertial><mass value="0.1"/><origin xyz="0 0 0.02"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="right"><inertial><mass value="0.1"/><origin xyz="0 0 0.02"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="wrist" type="revolute"><parent link="base"/><child link="palm"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="10"/></joint>
  <joint name="finger1" type="prismatic"><parent link="palm"/><child link="left"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/></joint>
  <joint name="finger2" type="prismatic"><parent link="palm"/><child link="right"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 -1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/>
    <mimic joint="finger1" multiplier="1" offset="0"/></joint>
</robot>
"""


def test_convert_a_floating_base_to_mjcf_passes_its_check(capsys, legged, tmp_path):
    pytest.importorskip("mujoco")
    out = tmp_path / "legged.xml"
    code, text, err = run(capsys, "convert", legged, str(out), "--floating-base")
    assert code == 0, err
    assert "checked by reading it back" in text and out.exists()


def test_convert_writes_mimic_joints_as_mjcf_equalities(capsys, tmp_path):
    mujoco = pytest.importorskip("mujoco")
    src = tmp_path / "gripper.urdf"
    src.write_text(GRIPPER)
    out = tmp_path / "gripper.xml"
    code, text, err = run(capsys, "convert", str(src), str(out))
    assert code == 0, err
    assert "checked by reading it back" in text
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nq == kd.load(src).nq + 1 and model.neq == 1
    # MuJoCo holds the follower to its leader: at rest with gravity off, the constraint solver
    # pulls finger2 to finger1's value
    model.opt.gravity[:] = 0
    data = mujoco.MjData(model)
    f1 = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "finger1")]
    f2 = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "finger2")]
    data.qpos[f1] = 0.03
    for _ in range(2000):
        data.qpos[f1] = 0.03
        mujoco.mj_step(model, data)
    assert data.qpos[f2] == pytest.approx(0.03, abs=2e-3)


def test_convert_leaves_no_file_that_failed_its_check(capsys, tmp_path, monkeypatch):
    pytest.importorskip("mujoco")
    written = kd.Robot.to_mjcf

    def wrong_gravity(self, path=None, **kw):  # a writer bug: the file's gravity differs from the robot's
        text = written(self, None, **kw).replace('gravity="0 0 -9.81"', 'gravity="0 0 -5"')
        with open(path, "w") as f:
            f.write(text)
        return text

    monkeypatch.setattr(kd.Robot, "to_mjcf", wrong_gravity)
    out = tmp_path / "ur5.xml"
    code, text, err = run(capsys, "convert", "ur5", str(out))
    assert code == 1 and "nothing was written" in err and "did not write" in text
    assert not out.exists() and list(tmp_path.iterdir()) == []
    out.write_text("an older file")
    assert run(capsys, "convert", "ur5", str(out))[0] == 1
    assert out.read_text() == "an older file"


def test_convert_without_mujoco_says_the_check_did_not_run(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "mujoco", None)  # import mujoco raises ImportError
    out = tmp_path / "ur5.xml"
    code, text, err = run(capsys, "convert", "ur5", str(out))
    assert code == 0 and out.exists()
    assert "checked by reading it back" not in text
    assert "warning: not checked: MuJoCo is not installed" in err


# ------------------------------------------------------------------ meshes: the viz extra, relative paths
def binary_stl(path) -> None:
    """A tetrahedron as a binary STL (MuJoCo reads binary STL only, of at least 4 vertices)."""
    import struct

    v = [(0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(faces)))
        for a, b, c in faces:
            f.write(struct.pack("<12fH", 0, 0, 0, *v[a], *v[b], *v[c], 0))


MESHY = """<robot name="meshy">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1.0"/><origin xyz="0.1 0 0"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="meshes/tri.stl"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="10" velocity="10"/></joint>
</robot>
"""


@pytest.fixture
def meshy(tmp_path):
    (tmp_path / "robot" / "meshes").mkdir(parents=True)
    binary_stl(tmp_path / "robot" / "meshes" / "tri.stl")
    path = tmp_path / "robot" / "meshy.urdf"
    path.write_text(MESHY)
    return path


def test_report_without_the_viz_extra_says_so_on_the_terminal(capsys, meshy, tmp_path, monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "trimesh", None)  # as after pip install . without [viz]
    out = tmp_path / "report.html"
    code, text, err = run(capsys, "report", str(meshy), "-o", str(out), "--no-tutorial")
    assert code == 0 and out.exists()
    assert "draws 0 of the 1 visual shapes" in err and "pip install 'kinedyn[viz]'" in err
    # the page names the mesh as the robot file does, not by this machine's absolute path
    page = out.read_text()
    assert "'meshes/tri.stl'" in page and str(meshy.parent / "meshes") not in page


def test_converted_mjcf_holds_relative_mesh_paths(capsys, meshy, tmp_path):
    mujoco = pytest.importorskip("mujoco")
    (tmp_path / "out").mkdir()
    out = tmp_path / "out" / "meshy.xml"
    code, text, err = run(capsys, "convert", str(meshy), str(out))
    assert code == 0, err
    xml = out.read_text()
    assert str(tmp_path) not in xml and 'file="../robot/meshes/tri.stl"' in xml
    model = mujoco.MjModel.from_xml_path(str(out))  # MuJoCo finds the mesh from the file's folder
    assert model.nmesh == 1


def test_written_urdf_and_robot_files_name_meshes_relative_to_themselves(meshy, tmp_path):
    from kinedyn.description.geometry import resolve_mesh

    mesh = (meshy.parent / "meshes" / "tri.stl").resolve()
    robot = kd.load(meshy)
    # beside the robot file, in the mesh's own folder, and in a sibling folder of it (a ROS
    # package's urdf/ next to its meshes/): relative to the written file, which finds the mesh
    (tmp_path / "robot" / "urdf").mkdir()
    for out, expected in (
        (meshy.parent / "copy.urdf", "meshes/tri.stl"),
        (meshy.parent / "meshes" / "copy.urdf", "tri.stl"),
        (tmp_path / "robot" / "urdf" / "copy.urdf", "../meshes/tri.stl"),
        (tmp_path / "robot" / "urdf" / "copy.yaml", "../meshes/tri.stl"),
    ):
        if out.suffix == ".urdf":
            robot.to_urdf(out)
            assert f'filename="{expected}"' in out.read_text(), out.read_text()
        else:
            robot.save(out)
            assert f"mesh: {expected}" in out.read_text(), out.read_text()
        assert not [line for line in out.read_text().splitlines() if "tri.stl" in line and str(tmp_path) in line]
        shape = kd.load(out).visuals[0].shape
        assert resolve_mesh(shape.filename, shape.base_dir).resolve() == mesh
    # far from the mesh (two folders away), or as text without a file: its absolute path, which
    # finds it from wherever the file goes on this machine
    (tmp_path / "a" / "b").mkdir(parents=True)
    far = tmp_path / "a" / "b" / "copy.urdf"
    robot.to_urdf(far)
    assert f'filename="{mesh}"' in far.read_text() and f'filename="{mesh}"' in robot.to_urdf()
    assert kd.load(far).visuals[0].shape.filename == str(mesh)
    # package:// kept as read
    packaged = meshy.parent / "packaged.urdf"
    packaged.write_text(MESHY.replace("meshes/tri.stl", "package://robot/meshes/tri.stl"))
    written = kd.load(packaged).to_urdf(tmp_path / "robot" / "urdf" / "packaged.urdf")
    assert 'filename="package://robot/meshes/tri.stl"' in written


def test_report_and_info_show_the_robot_file_resolved_not_as_typed(capsys, meshy, tmp_path, monkeypatch):
    from kinedyn.report.html import write_report

    monkeypatch.setenv("COLUMNS", "400")  # the source line on one line
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    typed = "../robot/../robot/meshy.urdf"
    resolved = str(meshy.resolve())
    monkeypatch.setenv("HOME", str(tmp_path / "home"))  # a home that does not hold the file
    out = tmp_path / "r.html"
    code, _, err = run(capsys, "report", typed, "-o", str(out), "--no-tutorial", "--t", "0.1")
    assert code == 0, err
    header = re.search(r"<header>.*?</header>", out.read_text(), re.S).group(0)
    # a page leaves the machine: no absolute path in it, the folder and the file name instead
    assert "· .../robot/meshy.urdf ·" in header and typed not in header and str(tmp_path) not in header, header
    monkeypatch.chdir(tmp_path)  # a file under the working folder: relative to it
    code, _, err = run(capsys, "report", "elsewhere/" + typed, "-o", str(out), "--no-tutorial", "--t", "0.1")
    assert code == 0 and "· robot/meshy.urdf ·" in re.search(r"<header>.*?</header>", out.read_text(), re.S).group(0)
    monkeypatch.chdir(tmp_path / "elsewhere")
    code, text, _ = run(capsys, "info", typed)
    assert code == 0 and f"source: {resolved}\n" in text, text
    monkeypatch.setenv("HOME", str(tmp_path))  # the file in the home folder: written from ~
    code, text, _ = run(capsys, "info", typed, "--json")
    assert code == 0 and '"source": "~/robot/meshy.urdf"' in text, text
    # robots that no file holds: the header says what it knows and never "robot file"
    dh = kd.Robot.from_dh([{"a": 0.5, "inertia": kd.Inertia.rod(1.0, 0.5)}])
    string = kd.Robot.from_urdf(meshy.read_text())
    for robot, shown in ((dh, None), (string, "URDF string")):
        write_report(robot, out, t_end=0.1)
        header = re.search(r"<header>.*?</header>", out.read_text(), re.S).group(0)
        assert "robot file" not in header and (shown is None or f"· {shown} ·" in header), header


# ------------------------------------------------------------------ info, units, names
def test_info_counts_degrees_of_freedom_and_marks_mimic_joints(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")  # the table on one line per joint
    src = tmp_path / "gripper.urdf"
    src.write_text(GRIPPER)
    code, out, err = run(capsys, "info", str(src))
    assert code == 0, err
    first = out.splitlines()[0]
    assert "2 degrees of freedom" in first and "3 moving joints" in first and "1 of them a mimic joint" in first
    row = next(line for line in out.splitlines() if "finger2" in line)
    assert "mimics finger1" in row
    doc = __import__("json").loads(run(capsys, "info", str(src), "--json")[1])
    mimic = {j["name"]: j["mimics"] for j in doc["joints"]}
    assert mimic["finger2"] == {"leader": "finger1", "multiplier": 1.0, "offset": 0.0} and mimic["finger1"] is None


@pytest.mark.parametrize(
    "argv, flag",
    [
        (["ik", "ur5", "--xyz", "0.3", "0.2", "0.4", "--rpy", "180", "0", "0"], "--rpy roll is 180 rad"),
        (["fk", "ur5", "--q", "90", "0", "0", "0", "0", "0"], "--q value 1 (shoulder_pan_joint) is 90 rad"),
        (["fk", "puma560", "--q", "0", "0", "0", "0", "100", "0"], "--q value 5 (q5) is 100 rad"),
    ],
)
def test_angles_that_look_like_degrees_warn_and_name_deg(capsys, argv, flag):
    code, out, err = run(capsys, *argv)
    assert flag in err and "--deg" in err and "did you mean degrees" in err
    code, out, err = run(capsys, *argv, "--deg")
    assert "did you mean degrees" not in err


def test_plausible_radians_do_not_warn(capsys):
    code, out, err = run(capsys, "fk", "ur5", "--q", "3.1", "-1.5", "6.2", "0", "0", "0")
    assert code == 0 and "warning" not in err
    # a prismatic joint's metres are not angles
    code, out, err = run(capsys, "fk", "cartesian_2p", "--q", "50", "40")
    assert code == 0 and "did you mean degrees" not in err


@pytest.mark.parametrize(
    "argv, suggestion",
    [
        (["fk", "ur5", "--frame", "linkk3"], "did you mean 'link3'"),
        (["fk", "ur6"], "did you mean 'ur5'"),
        (["fk", "planar_2r", "--set", "l_1=2"], "did you mean 'l1'"),
        (["convert", "ur5", "OUT.yaml", "--lock", "wrist_3"], "did you mean 'wrist_3_joint'"),
    ],
)
def test_misspelt_names_get_a_suggestion(capsys, tmp_path, argv, suggestion):
    argv = [str(tmp_path / a) if a == "OUT.yaml" else a for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 1 and suggestion in err


# ------------------------------------------------------------------ simulate --plot, --csv
def test_simulate_plot_keeps_its_legends_in_the_figure_and_labels_every_column(capsys, legged, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    robot = kd.load(legged, floating_base=True)
    png, csv = tmp_path / "run.png", tmp_path / "run.csv"
    code, out, err = run(
        capsys, "simulate", legged, "--floating-base", "--t", "0.05", "--plot", str(png), "--csv", str(csv)
    )
    assert code == 0, err
    assert png.stat().st_size > 0
    header = csv.read_text().splitlines()[0].split(",")
    assert [h for h in header if h.startswith("q[")] == [f"q[{n}]" for n in coordinate_labels(robot)]
    assert [h for h in header if h.startswith("tau[")] == [f"tau[{n}]" for n in velocity_labels(robot)]
    traj = kd.simulate(robot, 0.05, np.concatenate([robot.neutral(), np.zeros(robot.nv)]), dt=1e-3)
    fig = traj.plot(tmp_path / "again.png")  # saving lays the figure out, as the command does
    legends = [a.get_legend() for a in fig.axes if a.get_legend() is not None]
    assert [t.get_text() for t in legends[0].get_texts()] == coordinate_labels(robot)
    assert [t.get_text() for t in legends[1].get_texts()] == velocity_labels(robot)
    for legend in legends:  # nothing cut off at the figure's edges
        box = legend.get_window_extent()
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= fig.bbox.x1 + 0.5 and box.y1 <= fig.bbox.y1 + 0.5


def test_convert_to_a_device_checks_then_writes_into_it(capsys):
    import os
    import stat

    code, text, err = run(capsys, "convert", "ur5", os.devnull, "--to", "urdf")
    assert code == 0, err
    assert "checked by reading it back" in text
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)  # still the device, not a file renamed over it


def test_kinedyn_reads_the_mjcf_joint_equalities_it_writes_as_mimic_joints(capsys, tmp_path):
    src = tmp_path / "gripper.urdf"
    src.write_text(GRIPPER)
    out = tmp_path / "gripper.xml"
    assert run(capsys, "convert", str(src), str(out), "--no-check")[0] == 0
    urdf, mjcf = kd.load(src), kd.load(out)
    assert mjcf.nq == urdf.nq == 2 and set(mjcf.mimic_joints) == {"finger2"}
    q = urdf.random_configuration(3)
    np.testing.assert_allclose(mjcf.mass_matrix(q), urdf.mass_matrix(q), atol=1e-12)
    np.testing.assert_allclose(mjcf.frame_poses(q, ["right"]), urdf.frame_poses(q, ["right"]), atol=1e-12)
    # an equality that is not linear in its joint stays unmodelled, and says so
    text = out.read_text().replace('polycoef="0 1 0 0 0"', 'polycoef="0 1 0.5 0 0"')
    assert 'polycoef="0 1 0.5 0 0"' in text
    with pytest.warns(UserWarning, match="not a linear joint equality"):
        assert kd.Robot.from_mjcf(text).nq == 3


def test_a_joint_equality_with_reference_positions_reads_as_mujoco_holds_it():
    mujoco = pytest.importorskip("mujoco")
    xml = """<mujoco><option gravity="0 0 0"/><worldbody>
      <body name="a"><joint name="x" type="slide" axis="1 0 0" ref="0.2"/>
        <inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/>
        <body name="b"><joint name="y" type="slide" axis="0 1 0" ref="-0.1"/>
          <inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/></body></body>
      </worldbody><equality><joint joint1="y" joint2="x" polycoef="0.05 2 0 0 0"/></equality></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    for _ in range(3000):  # MuJoCo's constraint solver pulls y to where the equality holds x
        data.qpos[0], data.qvel[0] = 0.7, 0.0
        mujoco.mj_step(model, data)
    relation = kd.Robot.from_mjcf(xml).mimic_joints["y"]
    assert relation.leader == "x"
    assert relation.multiplier * 0.7 + relation.offset == pytest.approx(data.qpos[1], abs=1e-6)
