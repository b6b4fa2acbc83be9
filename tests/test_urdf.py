"""URDF reader: kinematics against an independent chain product built from the raw XML,
inertial origins, joint kinds, the Panda and UR5 from example-robot-data, and every error case."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from reference import PANDA, UR5, all_frame_poses, erd, frame_pose, joint_motion, pose, random_q, rpy

import kinedyn as kd
from kinedyn.robot_files import robot_from_urdf

# A small tree: base -> a (revolute) -> b (prismatic) -> tip (fixed); a -> side (continuous)
TREE = """<?xml version="1.0"?>
<robot name="tree">
  <link name="base"><inertial><mass value="100"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="a">
    <inertial>
      <origin xyz="0.1 0.2 0.3" rpy="0.3 -0.2 0.5"/>
      <mass value="2.0"/>
      <inertia ixx="0.3" ixy="0.01" ixz="-0.02" iyy="0.2" iyz="0.03" izz="0.25"/>
    </inertial>
  </link>
  <link name="b"><inertial><mass value="1.5"/><origin xyz="0 0 0.2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.05"/></inertial></link>
  <link name="tip"><inertial><mass value="0.5"/><origin xyz="0.05 0 0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <link name="side"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.4" rpy="0.1 0.2 0.3"/>
    <axis xyz="0 0 1"/>
    <limit lower="-2" upper="2.5" velocity="3" effort="40"/>
    <dynamics damping="0.7" friction="0.2"/>
  </joint>
  <joint name="j2" type="prismatic">
    <parent link="a"/><child link="b"/>
    <origin xyz="0.3 0 0" rpy="-0.4 0.5 0.1"/>
    <axis xyz="1 1 0"/>
    <limit lower="0" upper="0.5" velocity="1" effort="100"/>
  </joint>
  <joint name="j3" type="fixed">
    <parent link="b"/><child link="tip"/>
    <origin xyz="0 0.1 0.2" rpy="0 1.5707963267948966 0"/>
  </joint>
  <joint name="j4" type="continuous">
    <parent link="a"/><child link="side"/>
    <origin xyz="0 0.2 0"/>
    <limit velocity="5" effort="9"/>
  </joint>
</robot>
"""


def _raw_chain(xml: str, q: dict) -> dict:
    """World poses of every link straight from the XML: product of origin @ motion down the tree."""
    root = ET.fromstring(xml)
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}

    def origin(el):
        o = el.find("origin")
        xyz = [float(v) for v in (o.get("xyz", "0 0 0") if o is not None else "0 0 0").split()]
        r = [float(v) for v in (o.get("rpy", "0 0 0") if o is not None else "0 0 0").split()]
        return pose(rpy(*r), xyz)

    def world(link):
        if link not in by_child:
            return np.eye(4)
        j = by_child[link]
        T = world(j.find("parent").get("link")) @ origin(j)
        kind = j.get("type")
        if kind == "fixed":
            return T
        axis = [float(v) for v in (j.find("axis").get("xyz") if j.find("axis") is not None else "1 0 0").split()]
        return T @ joint_motion("prismatic" if kind == "prismatic" else "revolute", axis, q[j.get("name")])

    return {l.get("name"): world(l.get("name")) for l in root.findall("link")}


def test_tree_matches_raw_chain_product():
    robot = robot_from_urdf(TREE)
    assert robot.joint_names == ["j1", "j2", "j4"]  # depth-first, children in file order
    assert robot.base == "base"
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-1, 1, robot.n)
        expected = _raw_chain(TREE, dict(zip(robot.joint_names, q)))
        got = all_frame_poses(robot, q)
        for name, T in expected.items():
            np.testing.assert_allclose(got[name], T, atol=1e-12, err_msg=name)


def test_joint_data_limits_friction_and_kinds():
    robot = robot_from_urdf(TREE)
    j1, j2, j4 = robot.joints
    assert (j1.kind, j1.lower, j1.upper, j1.velocity_limit, j1.effort_limit) == ("revolute", -2.0, 2.5, 3.0, 40.0)
    assert (j1.viscous, j1.coulomb) == (0.7, 0.2)
    assert j2.kind == "prismatic"
    np.testing.assert_allclose(j2.axis, np.array([1, 1, 0]) / math.sqrt(2))
    assert j4.kind == "revolute" and j4.lower == -math.inf and j4.upper == math.inf  # continuous
    assert (j4.velocity_limit, j4.effort_limit) == (5.0, 9.0)
    np.testing.assert_allclose(j4.axis, [1, 0, 0])  # URDF's default axis


def test_inertial_origin_with_rotation_and_fixed_merge():
    robot = robot_from_urdf(TREE)
    a = robot.tree.bodies[0].inertia
    # expected: I_link = R I_com R^T and com = xyz, with R from the inertial's rpy
    R = rpy(0.3, -0.2, 0.5)
    I_com = np.array([[0.3, 0.01, -0.02], [0.01, 0.2, 0.03], [-0.02, 0.03, 0.25]])
    np.testing.assert_allclose(np.array(a.inertia), R @ I_com @ R.T, atol=1e-12)
    np.testing.assert_allclose(a.com, [0.1, 0.2, 0.3])
    # body "b" carries the fixed link "tip": total mass and centre of mass preserved
    b = robot.tree.bodies[1].inertia
    assert b.mass == pytest.approx(2.0)
    tip_in_b = pose(rpy(0, math.pi / 2, 0), [0, 0.1, 0.2]) @ np.array([0.05, 0, 0, 1])
    expected_com = (1.5 * np.array([0, 0, 0.2]) + 0.5 * tip_in_b[:3]) / 2.0
    np.testing.assert_allclose(b.com, expected_com, atol=1e-12)


def test_missing_inertial_is_massless_and_base_inertia_ignored():
    robot = robot_from_urdf(TREE)
    side = robot.tree.bodies[robot.body_names.index("side")]
    assert side.inertia.mass == 0.0
    assert sum(b.inertia.mass for b in robot.tree.bodies) == pytest.approx(2.0 + 2.0)  # base's 100 kg ignored


def test_default_tool_and_explicit_tool(tmp_path):
    assert robot_from_urdf(TREE).tool == "side"  # last link moving with the last joint
    assert robot_from_urdf(TREE, tool="tip").tool == "tip"
    with pytest.raises(ValueError, match="tool frame 'nope'"):
        robot_from_urdf(TREE, tool="nope")
    path = tmp_path / "tree.urdf"
    path.write_text(TREE)
    for r in (robot_from_urdf(str(path)), robot_from_urdf(path), kd.Robot.from_urdf(path), kd.load(path)):
        assert r.joint_names == ["j1", "j2", "j4"]


def test_gravity_passed_through():
    assert robot_from_urdf(TREE, gravity=(0, 0, -3.7)).gravity == (0.0, 0.0, -3.7)


# ------------------------------------------------------------------------------- real robots
def test_ur5_urdf_matches_raw_chain():
    path = erd(*UR5)
    xml = open(path).read()
    robot = robot_from_urdf(path)
    assert robot.n == 6 and robot.tool == "tool0" and robot.base == "world"
    q = random_q(robot, np.random.default_rng(0))
    expected = _raw_chain(xml, dict(zip(robot.joint_names, q)))
    np.testing.assert_allclose(frame_pose(robot, q, "tool0"), expected["tool0"], atol=1e-12)


def test_panda_nine_joints_lock_fingers():
    path = erd(*PANDA)
    robot = robot_from_urdf(
        path, mimic="independent"
    )  # the second finger a coordinate of its own (tests/test_mimic.py reduces it)
    assert robot.n == 9
    assert robot.joint_names[:7] == [f"panda_joint{i}" for i in range(1, 8)]
    arm = robot.lock_joints({"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0})
    assert arm.n == 7 and arm.joint_names == robot.joint_names[:7]
    rng = np.random.default_rng(1)
    for _ in range(3):
        q = random_q(arm, rng)
        full = all_frame_poses(robot, np.concatenate([q, [0.0, 0.0]]))
        locked = all_frame_poses(arm, q)
        for name in ("panda_link7", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger"):
            np.testing.assert_allclose(locked[name], full[name], atol=1e-12)
    # total moving mass is kept when the fingers merge into the hand body
    total = lambda r: sum(b.inertia.mass for b in r.tree.bodies)
    assert total(arm) == pytest.approx(total(robot))


def _urdf_masses(path):
    root = ET.parse(path).getroot()
    out = {}
    for link in root.findall("link"):
        m = link.find("inertial/mass")
        out[link.get("name")] = float(m.get("value")) if m is not None else 0.0
    return out


def test_panda_inertias_agree_with_pinocchio():
    pin = pytest.importorskip("pinocchio", reason="pinocchio (pip: pin) is not installed")
    path = erd(*PANDA)
    robot = robot_from_urdf(path, mimic="independent")  # as Pinocchio's model without mimic=True
    model = pin.buildModelFromUrdf(path)
    assert model.nq == robot.n
    # sum of masses of moving bodies (pinocchio's body 0 is the universe, holding the root)
    ours = sum(b.inertia.mass for b in robot.tree.bodies)
    theirs = sum(model.inertias[i].mass for i in range(1, model.njoints))
    masses = _urdf_masses(path)
    assert ours == pytest.approx(theirs)
    assert ours == pytest.approx(sum(masses.values()) - masses["panda_link0"])
    # body by body: mass, com and the 10 parameters in the joint frame
    for _i, body in enumerate(robot.tree.bodies):
        Y = model.inertias[model.getJointId(body.joint.name)]
        assert body.inertia.mass == pytest.approx(Y.mass)
        np.testing.assert_allclose(body.inertia.com, Y.lever, atol=1e-12)
        np.testing.assert_allclose(np.array(body.inertia.inertia), Y.inertia, atol=1e-12)


def test_panda_kinematics_agree_with_pinocchio():
    pin = pytest.importorskip("pinocchio", reason="pinocchio (pip: pin) is not installed")
    path = erd(*PANDA)
    robot = robot_from_urdf(path, mimic="independent")  # as Pinocchio's model without mimic=True
    model = pin.buildModelFromUrdf(path)
    data = model.createData()
    q = random_q(robot, np.random.default_rng(5))
    pin.framesForwardKinematics(model, data, q)
    for name in ("panda_link7", "panda_hand_tcp", "panda_leftfinger"):
        np.testing.assert_allclose(frame_pose(robot, q, name), data.oMf[model.getFrameId(name)].homogeneous, atol=1e-10)


# ------------------------------------------------------------------------------- errors
def _one_joint(joint_xml: str, links=("base", "a")) -> str:
    link_xml = "".join(f'<link name="{n}"/>' for n in links)
    return f"<robot name='r'>{link_xml}{joint_xml}</robot>"


@pytest.mark.parametrize("kind", ["spherical", "screw"])  # not URDF joint types (floating and planar are)
def test_unsupported_joint_kind(kind):
    xml = _one_joint(f'<joint name="jx" type="{kind}"><parent link="base"/><child link="a"/></joint>')
    with pytest.raises(ValueError, match=rf"joint 'jx' has type '{kind}', which is not supported"):
        robot_from_urdf(xml)


def test_malformed_xml_reports_line():
    xml = "<robot name='r'>\n<link name='a'>\n<link name='b'/>\n</robot>"
    with pytest.raises(ValueError, match=r"malformed XML at line 4"):
        robot_from_urdf(xml)


def test_malformed_file_reports_path_and_line(tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text("<robot>\n\n<link name='a'></joint>\n</robot>")
    with pytest.raises(ValueError, match=r"bad\.urdf: malformed XML at line 3"):
        robot_from_urdf(str(path))


def test_missing_file():
    with pytest.raises(ValueError, match=r"no_such\.urdf: cannot read"):
        robot_from_urdf("no_such.urdf")


def test_missing_parent_link():
    xml = _one_joint('<joint name="j" type="revolute"><parent link="ghost"/><child link="a"/></joint>')
    with pytest.raises(ValueError, match=r"joint 'j' names parent link 'ghost', which is not defined"):
        robot_from_urdf(xml)


def test_missing_child_link():
    xml = _one_joint('<joint name="j" type="revolute"><parent link="base"/><child link="ghost"/></joint>')
    with pytest.raises(ValueError, match=r"joint 'j' names child link 'ghost'"):
        robot_from_urdf(xml)


def test_two_roots():
    xml = _one_joint(
        '<joint name="j" type="revolute"><parent link="base"/><child link="a"/></joint>', ("base", "a", "other")
    )
    with pytest.raises(ValueError, match=r"several root links \['base', 'other'\]"):
        robot_from_urdf(xml)


def test_cycle_without_root():
    joints = (
        '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="revolute"><parent link="b"/><child link="a"/></joint>'
    )
    with pytest.raises(ValueError, match=r"no root link: its joints form a cycle"):
        robot_from_urdf(_one_joint(joints, ("a", "b")))


def test_cycle_beside_a_root():
    joints = (
        '<joint name="j0" type="revolute"><parent link="base"/><child link="a"/></joint>'
        '<joint name="j1" type="revolute"><parent link="b"/><child link="c"/></joint>'
        '<joint name="j2" type="revolute"><parent link="c"/><child link="b"/></joint>'
    )
    with pytest.raises(ValueError, match=r"joints \['j1', 'j2'\] form a cycle"):
        robot_from_urdf(_one_joint(joints, ("base", "a", "b", "c")))


def test_link_with_two_parents():
    joints = (
        '<joint name="j1" type="revolute"><parent link="base"/><child link="b"/></joint>'
        '<joint name="j2" type="revolute"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j0" type="revolute"><parent link="base"/><child link="a"/></joint>'
    )
    with pytest.raises(ValueError, match=r"link 'b' is the child of two joints, 'j1' and 'j2'"):
        robot_from_urdf(_one_joint(joints, ("base", "a", "b")))


def test_bad_numbers_and_inertia():
    bad_origin = _one_joint(
        '<joint name="j" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 x 0"/></joint>'
    )
    with pytest.raises(ValueError, match=r"joint 'j' origin xyz must be 3 numbers"):
        robot_from_urdf(bad_origin)
    negative = TREE.replace('<mass value="1.5"/>', '<mass value="-1.5"/>')
    with pytest.raises(ValueError, match=r"link 'b' <inertial>: mass.* negative"):
        robot_from_urdf(negative)
    no_robot = "<model name='x'/>"
    with pytest.raises(ValueError, match=r"root element is <model>"):
        robot_from_urdf(no_robot)


def _gripper_urdf(tool_link: str, extra: str = "") -> str:  # extra: more XML inside <robot>
    """A 2-joint arm whose hand carries a fixed `tool_link` and two sliding fingers (the longer chains)."""
    body = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
    links = ["base", "l1", "l2", tool_link, "finger_a", "finger_b"]
    joints = [
        ("j1", "revolute", "base", "l1"),
        ("j2", "revolute", "l1", "l2"),
        ("jt", "fixed", "l2", tool_link),
        ("fa", "prismatic", "l2", "finger_a"),
        ("fb", "prismatic", "l2", "finger_b"),
    ]
    xml = "".join(f'<link name="{n}">{body}</link>' for n in links) + extra
    xml += "".join(
        f'<joint name="{j}" type="{k}"><parent link="{p}"/><child link="{c}"/><origin xyz="0 0 0.1"/>'
        f'<axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>'
        for j, k, p, c in joints
    )
    return f'<robot name="gripper">{xml}</robot>'


@pytest.mark.parametrize("tool_link", ["tcp", "tool0", "ee_link", "arm_hand_tcp", "arm_hand", "flange"])
def test_default_tool_prefers_a_named_tool_over_a_finger(tool_link):
    """Issue 13 §5: the Panda's default tool was a finger (the end of the last branch); a link named
    as a tool wins over the longer finger chains."""
    assert robot_from_urdf(_gripper_urdf(tool_link)).tool == tool_link


def test_default_tool_without_a_tool_name_is_the_end_of_the_longest_chain():
    assert robot_from_urdf(_gripper_urdf("wrist_plate")).tool == "finger_b"  # two chains of 3: the later one
    # a better-ranked name wins over a worse-ranked one (a *_tcp over a *_hand), wherever it is in the file
    hand = (
        '<link name="panda_hand"/><joint name="jh" type="fixed"><parent link="l2"/><child link="panda_hand"/></joint>'
    )
    assert robot_from_urdf(_gripper_urdf("panda_hand_tcp", hand)).tool == "panda_hand_tcp"
    assert robot_from_urdf(_gripper_urdf("wrist_plate", hand)).tool == "panda_hand"


def test_default_tool_of_the_panda_is_its_tcp():
    robot = robot_from_urdf(erd(*PANDA), mimic="independent")
    assert robot.tool == "panda_hand_tcp"
    J = robot.jacobian(np.zeros(robot.n))
    np.testing.assert_allclose(J[:, 7:], 0.0, atol=1e-12)  # the fingers do not move the tool
