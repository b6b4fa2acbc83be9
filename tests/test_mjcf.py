"""MJCF (MuJoCo XML) reader: MuJoCo itself as the oracle (mass matrix, bias forces, inverse dynamics,
body and site poses, body inertias) on models written here and on the `mujoco` package's own test
model; the structure of ball and free joints; includes, defaults and the security rules."""

from __future__ import annotations

import math
import os
import re
import warnings

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.mjcf import MAX_DEPTH, MAX_INCLUDE_DEPTH
from kinedyn.robot_files import robot_from_mjcf

mujoco = pytest.importorskip("mujoco", reason="MuJoCo (pip install mujoco) is an optional test oracle")

TOL = 1e-9

DOUBLE_PENDULUM = """<mujoco model="double_pendulum">
  <compiler angle="radian"/>
  <worldbody>
    <body name="upper" pos="0.1 0.2 0.3" euler="0.1 0.2 0.3">
      <joint name="shoulder" axis="0 1 0" pos="0 0 0.1" damping="0.4" armature="0.02"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/>
      <body name="lower" pos="0 0 -0.5" quat="0.9 0.1 0.2 0.3">
        <joint name="elbow" axis="1 0 1" pos="0.05 0 0.02" damping="0.1" armature="0.01"/>
        <geom type="box" size="0.05 0.06 0.2" pos="0 0 -0.2"/>
        <site name="tip" pos="0.01 0.02 -0.4" euler="0.3 0.2 0.1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

CART_POLE = """<mujoco model="cart_pole">
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="cart" pos="0 0 0.5">
      <joint name="slider" type="slide" axis="1 0 0" range="-2 2" ref="0.3" damping="0.5"/>
      <geom type="box" size="0.2 0.1 0.05" mass="2"/>
      <body name="pole" pos="0 0 0.05">
        <joint name="hinge" type="hinge" axis="0 1 0" pos="0 0 -0.02" range="-120 120" ref="10"/>
        <geom type="cylinder" fromto="0 0 0 0.001 0 0.8" size="0.02" mass="0.3"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

# A 3-D arm: default classes (nested, class=, childclass=), every way of writing an orientation,
# several joints in one body at different positions, inertials with quat and fullinertia, frames.
ARM = """<mujoco model="arm3d">
  <compiler angle="degree" eulerseq="{eulerseq}"/>
  <option gravity="0.3 -0.2 -9.7"/>
  <default>
    <joint damping="0.3" armature="0.05"/>
    <geom density="700"/>
    <default class="wrist">
      <joint axis="1 0 0" damping="0.1" range="-90 90"/>
      <geom type="box" size="0.03 0.02 0.05"/>
      <default class="fingertip">
        <geom type="ellipsoid" size="0.01 0.02 0.015"/>
      </default>
    </default>
    <default class="heavy">
      <geom density="2500" type="capsule" size="0.04"/>
    </default>
  </default>
  <worldbody>
    <geom type="plane" size="2 2 0.1"/>
    <body name="base_link" pos="0 0 0.2" axisangle="0 0 1 30">
      <geom type="cylinder" size="0.08 0.05"/>
      <site name="base_site" pos="0.1 0 0" zaxis="1 1 0"/>
      <body name="shoulder" pos="0 0.05 0.1" euler="10 20 30">
        <joint name="yaw" axis="0 0 1" pos="0.01 0 0"/>
        <joint name="pitch" axis="0 1 0" pos="0 0.02 0.03" ref="15"/>
        <geom class="heavy" fromto="0 0 0 0.3 0 0.1"/>
        <body name="elbow" pos="0.3 0 0.1" xyaxes="0 1 0 -1 0.2 0" childclass="wrist">
          <joint name="elbow" axis="0 1 1" pos="0.01 0.02 0.03"/>
          <inertial pos="0.1 0.01 0" quat="0.8 0.1 0.2 0.3" mass="1.2" diaginertia="0.01 0.02 0.025"/>
          <geom/>
          <body name="forearm" pos="0.25 0 0" zaxis="0 1 1">
            <joint name="roll"/>
            <joint name="extend" type="slide" axis="0 0 1" pos="0 0.1 0" class="main"/>
            <inertial pos="0.05 0 0" mass="0.7" fullinertia="0.004 0.005 0.006 0.0005 -0.0003 0.0002"/>
            <frame pos="0.1 0 0" euler="0 90 0">
              <site name="tool_site" pos="0 0 0.05" quat="0.7 0 0.7 0.1"/>
              <geom pos="0 0 0.02"/>
            </frame>
            <body name="hand" pos="0.12 0 0" quat="0.5 0.5 0.5 0.5">
              <joint name="hand" axis="0 0 1" pos="0.01 0 0"/>
              <geom size="0.05"/>
              <geom class="fingertip" pos="0.03 0 0.05" euler="10 0 40"/>
              <frame childclass="fingertip" pos="0 0.01 0.02"><geom/></frame>
              <site name="down" type="capsule" size="0.01" fromto="0 0 0 0 0 0.1"/>
              <site name="along" type="cylinder" size="0.01" fromto="0 0 0.1 0.05 0.02 0"/>
              <frame pos="0 0.02 0.04" axisangle="1 1 0 40">
                <geom type="sphere" size="0.015" pos="0.01 0 0"/>
              </frame>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

# Inertia from geoms only: every primitive, fromto on each shape that takes it, mass= and density=,
# a geom outside inertiagrouprange, a plane (no mass)
GEOMS = """<mujoco model="geoms">
  <compiler inertiagrouprange="0 2"/>
  <worldbody>
    <body name="lumpy" pos="0.1 0 0.2">
      <joint name="j" axis="0.3 1 0.2" pos="0.02 0.01 0"/>
      <geom type="sphere" size="0.05" pos="0.1 0 0"/>
      <geom type="box" size="0.05 0.04 0.03" pos="0 0.1 0" quat="0.9 0.3 0.1 0.2" density="300"/>
      <geom type="box" size="0.02 0.03" fromto="0 0 0 0.1 0.2 0.3"/>
      <geom type="capsule" size="0.03 0.1" pos="0 0 0.1" euler="20 30 40"/>
      <geom type="capsule" size="0.02" fromto="0.1 0.1 0.1 -0.1 0.2 0.0" mass="0.8"/>
      <geom type="cylinder" size="0.04 0.05" xyaxes="0 0 1 0 1 0"/>
      <geom type="cylinder" size="0.01" fromto="0 0 0 0 0 -0.3"/>
      <geom type="ellipsoid" size="0.03 0.05 0.07" pos="-0.1 0 0" axisangle="1 2 3 50"/>
      <geom type="ellipsoid" size="0.03 0.04" fromto="0 0 0 0.2 0 -0.1"/>
      <geom type="sphere" size="0.3" group="3"/>
    </body>
  </worldbody>
</mujoco>
"""


# ------------------------------------------------------------------------------------- helpers
def both(xml: str, disable_constraints: bool = True):
    """(kinedyn robot, MuJoCo model, MuJoCo data) of one MJCF string."""
    robot = robot_from_mjcf(xml)
    model = mujoco.MjModel.from_xml_string(xml)
    if disable_constraints:
        model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    return robot, model, mujoco.MjData(model)


def mujoco_state(model, data, q, qd):
    data.qpos[:] = q
    data.qvel[:] = qd
    mujoco.mj_forward(model, data)


def compare_dynamics(robot, model, data, seed: int, states: int = 5):
    """M, the bias forces and inverse dynamics (with damping) of kinedyn and MuJoCo at random states."""
    rng = np.random.default_rng(seed)
    n = robot.n
    assert (model.nq, model.nv) == (n, n)
    for _ in range(states):
        q, qd, qdd = rng.uniform(-1.5, 1.5, n), rng.normal(size=n), rng.normal(size=n)
        mujoco_state(model, data, q, qd)
        M = full_mass_matrix(model, data)
        np.testing.assert_allclose(robot.mass_matrix(q), M, atol=TOL, rtol=0)
        # qfrc_bias = C qd + g (no friction, no damping)
        np.testing.assert_allclose(robot.bias_torque(q, qd), data.qfrc_bias, atol=TOL, rtol=0)
        data.qacc[:] = qdd
        mujoco.mj_inverse(model, data)
        # qfrc_inverse = M qacc + qfrc_bias - qfrc_passive, with qfrc_passive = -damping qvel here
        np.testing.assert_allclose(robot.inverse_dynamics(q, qd, qdd), data.qfrc_inverse, atol=TOL, rtol=0)
        compare_poses(robot, model, data, q)


def compare_poses(robot, model, data, q):
    """Every MuJoCo body's (xpos, xmat) and every site's against the frame of the same name."""
    mujoco.mj_kinematics(model, data)
    for b in range(1, model.nbody):
        name = model.body(b).name or f"body{b}"
        T = robot.pose(q, frame=name)
        np.testing.assert_allclose(T[:3, 3], data.xpos[b], atol=TOL, rtol=0, err_msg=name)
        np.testing.assert_allclose(T[:3, :3], data.xmat[b].reshape(3, 3), atol=TOL, rtol=0, err_msg=name)
    frames = set(robot.frame_names)
    for s in range(model.nsite):
        name = model.site(s).name
        name = name if f"site:{name}" not in frames else f"site:{name}"
        T = robot.pose(q, frame=name)
        np.testing.assert_allclose(T[:3, 3], data.site_xpos[s], atol=TOL, rtol=0, err_msg=name)
        np.testing.assert_allclose(T[:3, :3], data.site_xmat[s].reshape(3, 3), atol=TOL, rtol=0, err_msg=name)


def full_mass_matrix(model, data) -> np.ndarray:
    M = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, M)  # MuJoCo >= 3.4 (m, d, dst)
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)  # earlier (m, dst, qM)
    return M


def body_inertia_in_body_frame(model, b: int) -> tuple:
    """(mass, centre of mass, 3x3 inertia about it in body axes) of MuJoCo's compiled body ``b``."""
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, model.body_iquat[b])
    R = R.reshape(3, 3)
    return model.body_mass[b], model.body_ipos[b], R @ np.diag(model.body_inertia[b]) @ R.T


def link_inertia(robot, name: str):
    return next(link.inertia for link in robot.links if link.name == name)


def compare_inertias(robot, model):
    for b in range(1, model.nbody):
        name = model.body(b).name or f"body{b}"
        mass, com, tensor = body_inertia_in_body_frame(model, b)
        inertia = link_inertia(robot, name)
        assert inertia.mass == pytest.approx(mass, abs=TOL, rel=0), name
        if mass > 0:
            np.testing.assert_allclose(inertia.com, com, atol=TOL, rtol=0, err_msg=name)
            np.testing.assert_allclose(np.array(inertia.inertia), tensor, atol=TOL, rtol=0, err_msg=name)


# ------------------------------------------------------------------------- MuJoCo as the oracle
def test_double_pendulum_with_off_origin_hinges_agrees_with_mujoco():
    robot, model, data = both(DOUBLE_PENDULUM)
    assert robot.joint_names == ["shoulder", "elbow"]
    assert [j.rotor_inertia for j in robot.joints] == [0.02, 0.01]
    assert [j.viscous for j in robot.joints] == [0.4, 0.1]
    compare_inertias(robot, model)
    compare_dynamics(robot, model, data, seed=1)


def test_cart_pole_slide_and_hinge_with_ref_and_limits_agrees_with_mujoco():
    robot, model, data = both(CART_POLE)
    slider, hinge = robot.joints
    assert (slider.kind, hinge.kind) == ("prismatic", "revolute")
    # MuJoCo's qpos is kinedyn's q: the reference position ref becomes the offset -ref
    assert slider.offset == pytest.approx(-0.3) and hinge.offset == pytest.approx(-math.radians(10))
    assert (slider.lower, slider.upper) == (-2.0, 2.0)
    assert (hinge.lower, hinge.upper) == pytest.approx((-math.radians(120), math.radians(120)))
    np.testing.assert_allclose(model.jnt_range, [[-2, 2], [-math.radians(120), math.radians(120)]])
    compare_inertias(robot, model)
    compare_dynamics(robot, model, data, seed=2)


@pytest.mark.parametrize("eulerseq", ["xyz", "zyx", "XYZ", "zYx"])
def test_arm_with_defaults_frames_and_joint_chains_agrees_with_mujoco(eulerseq):
    xml = ARM.format(eulerseq=eulerseq)
    robot, model, data = both(xml)
    assert robot.joint_names == ["yaw", "pitch", "elbow", "roll", "extend", "hand"]
    # two joints in one body: a massless link at the first joint, the body's inertia on the second
    assert link_inertia(robot, "shoulder/yaw").mass == 0 and link_inertia(robot, "forearm/roll").mass == 0
    roll, extend, hand = robot.joints[3:]
    # childclass "wrist": axis, damping and range; class="main" overrides it; the top default's armature
    assert roll.axis == (1.0, 0.0, 0.0) and roll.viscous == 0.1 and roll.upper == pytest.approx(math.pi / 2)
    assert extend.kind == "prismatic" and extend.viscous == 0.3 and extend.upper == math.inf
    assert hand.rotor_inertia == 0.05 and hand.viscous == 0.1
    assert {"base_site", "tool_site"} <= set(robot.frame_names)
    compare_inertias(robot, model)
    compare_dynamics(robot, model, data, seed=3)


def test_inertia_from_geoms_agrees_with_mujoco():
    robot, model, data = both(GEOMS)
    compare_inertias(robot, model)
    compare_dynamics(robot, model, data, seed=4)


def test_inertiafromgeom_true_replaces_the_inertial_and_false_ignores_the_geoms():
    body = (
        '<body name="b"><joint name="j" axis="1 0 0"/><inertial pos="0.1 0 0" mass="3" diaginertia="1 2 3"/>'
        '<geom type="box" size="0.1 0.2 0.3" pos="0 0.1 0"/></body>'
    )
    for setting in ("true", "false", "auto"):
        xml = f'<mujoco><compiler inertiafromgeom="{setting}"/><worldbody>{body}</worldbody></mujoco>'
        robot, model, _ = both(xml)
        compare_inertias(robot, model)
        assert link_inertia(robot, "b").mass == pytest.approx(3.0 if setting != "true" else 1000 * 0.2 * 0.4 * 0.6)


def test_the_mujoco_test_model_with_its_free_and_ball_joints_turned_into_hinges_agrees():
    """The `mujoco` wheel's own testdata/model.xml (defaults with springs, fromto capsules, boxes and
    cylinders, ellipsoids, sites, tendons, actuators, sensors), its free and ball joints made hinges
    (so that every joint keeps its damping and armature; the whole model is compared below) and its
    mesh geom (whose inertia kinedyn does not compute) a box instead."""
    text = _mujoco_test_model()
    text = text.replace("<freejoint/>", '<joint type="hinge" axis="0.2 0.3 1"/>').replace('type="ball"', 'type="hinge"')
    text = without_mesh_geom(text)
    text = text.replace('<weld body1="world" body2="cylinder"/>', "")
    text = re.sub(r"<keyframe>.*?</keyframe>", "", text, flags=re.S)  # its qpos is for free and ball joints
    with pytest.warns(
        UserWarning, match=r"does not model.*<actuator>.*<sensor>.*<tendon>.*spring \(stiffness\) of joint 'hipy_0'"
    ):
        robot = robot_from_mjcf(text)
    model = mujoco.MjModel.from_xml_string(text)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_SPRING)
    model.opt.density = model.opt.viscosity = 0.0  # no fluid forces (kinedyn has no fluid model)
    model.body_gravcomp[:] = 0  # kinedyn does not model gravity compensation (named in the warning)
    assert robot.joint_names == [model.joint(i).name or f"joint{i}" for i in range(model.njnt)]
    compare_inertias(robot, model)
    compare_dynamics(robot, model, mujoco.MjData(model), seed=5, states=3)


def without_mesh_geom(text: str) -> str:
    mesh = '<geom type="mesh" mesh="icosahedron" size=".1" rgba="0 0 1 1"/>'
    assert mesh in text
    return text.replace(mesh, '<geom type="box" size=".1 .05 .08" rgba="0 0 1 1"/>')


def _mujoco_test_model() -> str:
    path = os.path.join(os.path.dirname(mujoco.__file__), "testdata", "model.xml")
    with open(path) as f:
        return f.read()


def test_the_mujoco_test_model_names_its_mesh_body_whose_inertia_is_not_computed():
    path = os.path.join(os.path.dirname(mujoco.__file__), "testdata", "model.xml")
    with pytest.raises(
        ValueError, match=r"model\.xml:\d+: <geom> geom of body 'body9': kinedyn does not compute a mesh's inertia"
    ):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            robot_from_mjcf(path)


# ----------------------------------------------------------------- ball and free joints: structure
def test_ball_and_free_joints_parse_with_mujoco_sizes_placements_and_inertias():
    text = without_mesh_geom(_mujoco_test_model())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = robot_from_mjcf(text)
    model = mujoco.MjModel.from_xml_string(text)
    kinds = {0: "floating", 1: "spherical", 2: "prismatic", 3: "revolute"}
    assert [j.kind for j in robot.joints] == [kinds[int(t)] for t in model.jnt_type]
    assert (robot.nq, robot.nv) == (model.nq, model.nv)
    assert robot.has_multi_dof_joints
    compare_inertias(robot, model)
    links = {link.name: link for link in robot.links}
    # a free body sits at qpos in the world: its placement is the identity (its pos/quat are qpos0)
    assert (
        np.array_equal(links["head"].placement, np.eye(4))
        and links["head"].parent is None
        or links["head"].parent == "world"
    )
    # the ball joint's link: its body's pose in the parent, at the joint position (here 0)
    wheel = next(l for l in robot.links if l.joint.name == "wheel_0")
    b = model.jnt_bodyid[model.joint("wheel_0").id]
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, model.body_quat[b])
    np.testing.assert_allclose(wheel.placement[:3, 3], model.body_pos[b], atol=TOL)
    np.testing.assert_allclose(wheel.placement[:3, :3], R.reshape(3, 3), atol=TOL)


def test_a_ball_joint_off_its_body_origin_is_placed_at_the_joint():
    xml = (
        '<mujoco><worldbody><body name="b" pos="1 2 3" euler="0 0 90"><joint name="ball" type="ball" pos="0.1 0.2 0.3"/>'
        '<geom size="0.1"/></body></worldbody></mujoco>'
    )
    link = robot_from_mjcf(xml).links[0]
    assert link.joint.kind == "spherical"
    np.testing.assert_allclose(link.placement[:3, 3], [1 - 0.2, 2 + 0.1, 3 + 0.3], atol=1e-12)
    np.testing.assert_allclose(link.post[:3, 3], [-0.1, -0.2, -0.3])


def test_a_free_joint_must_be_the_only_joint_of_a_top_level_body():
    xml = (
        '<mujoco><worldbody><body><geom size="1"/><body><freejoint/><geom size="1"/></body></body></worldbody></mujoco>'
    )
    with pytest.raises(
        ValueError, match=r"<MJCF string>:1: <freejoint> joint 'joint0': a free joint must be the only joint"
    ):
        robot_from_mjcf(xml)


# ------------------------------------------------------------------------------ files and includes
def test_kd_load_reads_an_mjcf_file_with_includes(tmp_path):
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "pole.xml").write_text(
        '<mujoco><body name="pole" pos="0 0 0.05"><joint name="hinge" axis="0 1 0"/>'
        '<geom type="cylinder" fromto="0 0 0 0 0 0.8" size="0.02" mass="0.3"/></body></mujoco>'
    )
    (tmp_path / "defaults.xml").write_text('<mujoco><default><joint damping="0.25"/></default></mujoco>')
    (tmp_path / "model.xml").write_text(
        '<mujoco model="included"><include file="defaults.xml"/><worldbody><body name="cart">'
        '<joint name="slider" type="slide" axis="1 0 0"/><geom type="box" size="0.2 0.1 0.05"/>'
        '<include file="parts/pole.xml"/></body></worldbody></mujoco>'
    )
    robot = kd.load(tmp_path / "model.xml")
    assert robot.name == "included" and robot.joint_names == ["slider", "hinge"]
    assert [j.viscous for j in robot.joints] == [0.25, 0.25]
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "model.xml"))
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    compare_dynamics(robot, model, mujoco.MjData(model), seed=6, states=2)
    assert kd.Robot.from_mjcf(str(tmp_path / "model.xml")).joint_names == robot.joint_names


def test_an_include_may_not_leave_the_model_folder(tmp_path):
    (tmp_path / "secret.xml").write_text("<mujoco/>")
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "model.xml").write_text('<mujoco><include file="../secret.xml"/><worldbody/></mujoco>')
    with pytest.raises(
        ValueError, match=r"model\.xml:1: <include> file='\.\./secret\.xml' is outside the model's folder"
    ):
        kd.load(tmp_path / "m" / "model.xml")


def test_includes_are_depth_bounded(tmp_path):
    (tmp_path / "loop.xml").write_text('<mujoco><include file="loop.xml"/></mujoco>')
    with pytest.raises(
        ValueError, match=rf"<include> file='loop\.xml': includes nested deeper than {MAX_INCLUDE_DEPTH} levels"
    ):
        robot_from_mjcf(str(tmp_path / "loop.xml"))


def test_a_string_cannot_include():
    with pytest.raises(
        ValueError, match=r"<MJCF string>:1: <include> file='x\.xml': a model given as an XML string cannot include"
    ):
        robot_from_mjcf('<mujoco><include file="x.xml"/></mujoco>')


# ----------------------------------------------------------------------------------- security
def test_entities_and_doctype_declarations_are_refused():
    bomb = (
        '<?xml version="1.0"?><!DOCTYPE m [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]>'
        '<mujoco model="&b;"><worldbody/></mujoco>'
    )
    with pytest.raises(ValueError, match="DOCTYPE with declarations"):
        robot_from_mjcf(bomb)


def test_nesting_is_bounded():
    xml = "<mujoco><worldbody>" + "<body>" * (MAX_DEPTH + 1) + "</body>" * (MAX_DEPTH + 1) + "</worldbody></mujoco>"
    with pytest.raises(ValueError, match=f"nested deeper than {MAX_DEPTH}"):
        robot_from_mjcf(xml)


@pytest.mark.parametrize(
    "inner, message",
    [
        ('<joint name="j" range="1 a"/>', r"<joint> attribute 'range' must be numbers, got '1 a'"),
        (
            '<joint name="j" range="2 1" limited="true"/>',
            r"<joint> joint 'j': attribute 'range' has lower 2 above upper 1",
        ),
        ('<joint name="j" type="universal"/>', r"<joint> joint 'j': attribute 'type' is 'universal'"),
        ('<joint name="j" axis="0 0 0"/>', r"<joint> joint 'j': axis .* zero"),
        ('<joint name="j" axis="0 0 nan"/>', r"<joint> attribute 'axis' must hold finite numbers"),
        ('<joint name="j" class="nope"/>', r"<joint> class='nope' names no <default> class"),
        ('<joint name="j"/><geom type="box" size="1 1"/>', r"<geom> geom: a box needs 3 positive size numbers"),
        ('<joint name="j"/><geom type="torus"/>', r"<geom> geom: attribute 'type' is 'torus'"),
        (
            '<joint name="j"/><geom size="1" quat="1 0 0 0" euler="0 0 0"/>',
            r"<geom> gives its orientation twice \(quat, euler\)",
        ),
        (
            '<joint name="j"/><inertial pos="0 0 0" mass="1"/>',
            r"<inertial> of body 'b' has neither 'diaginertia' nor 'fullinertia'",
        ),
        (
            '<joint name="j"/><inertial mass="1" diaginertia="1 1 1"/>',
            r"<inertial> of body 'b' has no 'pos' attribute \(MuJoCo requires it\)",
        ),
        (
            '<joint name="j"/><inertial pos="0 0 0" mass="-1" diaginertia="1 1 1"/>',
            r"<inertial> of body 'b': attribute 'mass' is negative",
        ),
        ('<joint name="j"/><geom type="mesh" mesh="m"/>', r"<geom> geom: mesh='m' names no <asset><mesh>"),
    ],
)
def test_every_error_names_the_line_the_element_and_the_attribute(inner, message):
    xml = f'<mujoco>\n<worldbody>\n<body name="b">{inner}</body></worldbody></mujoco>'
    with pytest.raises(ValueError, match=r"^<MJCF string>:3: " + message):
        robot_from_mjcf(xml)


def test_errors_from_a_file_name_the_file(tmp_path):
    path = tmp_path / "bad.xml"
    path.write_text('<mujoco>\n<worldbody>\n<body>\n<joint name="j" ref="x"/></body></worldbody></mujoco>')
    with pytest.raises(ValueError, match=r"bad\.xml:4: <joint> attribute 'ref' must be numbers"):
        kd.load(path)
    with pytest.raises(ValueError, match=r"cannot read MJCF file"):
        kd.load(tmp_path / "missing.xml")


def test_a_model_without_joints_loads_as_mujoco_loads_it_and_one_without_worldbody_is_refused():
    xml = '<mujoco><worldbody><body><geom size="1"/></body></worldbody></mujoco>'
    robot = robot_from_mjcf(xml)
    assert robot.nq == robot.nv == mujoco.MjModel.from_xml_string(xml).nq == 0
    assert robot.mass_matrix(np.zeros(0)).shape == (0, 0)
    with pytest.raises(ValueError, match=r"<mujoco> has no <worldbody>"):
        robot_from_mjcf("<mujoco></mujoco>")
    with pytest.raises(ValueError, match=r"the root element is <robot>, expected <mujoco>"):
        robot_from_mjcf("<robot/>")


@pytest.mark.parametrize("tag", ["replicate", "composite", "attach", "flexcomp"])
def test_elements_that_generate_bodies_are_refused(tag):
    with pytest.raises(ValueError, match=rf"<{tag}> is not read by kinedyn"):
        robot_from_mjcf(f'<mujoco><worldbody><body><joint/><geom size="1"/><{tag}/></body></worldbody></mujoco>')


# --------------------------------------------------------------------------------- geometry
def test_geoms_become_visuals_and_collisions():
    xml = (
        '<mujoco><asset><material name="red" rgba="1 0 0 1"/><mesh name="part" file="part.stl" scale="2 2 2"/></asset>'
        '<worldbody><geom name="floor" type="plane" size="1 1 1"/><body name="b"><joint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
        '<geom type="box" size="0.1 0.2 0.3" material="red" pos="1 0 0"/>'
        '<geom type="capsule" size="0.1 0.5" contype="0" conaffinity="0" rgba="0 1 0 1"/>'
        '<geom type="mesh" mesh="part" group="3"/></body></worldbody></mujoco>'
    )
    robot = robot_from_mjcf(xml)
    shapes = [(v.frame, v.describe(), v.rgba) for v in robot.visuals]
    assert shapes == [("b", "box", (1.0, 0.0, 0.0, 1.0)), ("b", "cylinder", (0.0, 1.0, 0.0, 1.0))]
    assert robot.visuals[0].shape.size == (0.2, 0.4, 0.6) and robot.visuals[0].origin[0, 3] == 1.0
    assert robot.visuals[1].shape.length == pytest.approx(1.2)
    assert [v.describe() for v in robot.collisions] == ["box", "mesh 'part.stl'"]
    assert robot.collisions[1].shape.scale == (2.0, 2.0, 2.0)


def test_the_warning_names_what_is_ignored_and_points_at_the_caller():
    xml = (
        '<mujoco><worldbody><body gravcomp="1"><joint name="j" stiffness="3"/><geom size="1"/></body></worldbody>'
        '<actuator><motor joint="j"/></actuator></mujoco>'
    )
    with pytest.warns(
        UserWarning, match=r"<actuator> \(1 elements\); gravcomp of body 'body1'; the spring \(stiffness\) of joint 'j'"
    ) as caught:
        robot_from_mjcf(xml)
    assert len(caught) == 1 and caught[0].filename == __file__


def test_the_cli_reads_an_mjcf_file(tmp_path):
    import json
    import subprocess
    import sys
    from pathlib import Path

    path = tmp_path / "cart_pole.xml"
    path.write_text(CART_POLE)
    env = {**os.environ, "PYTHONPATH": str(Path(kd.__file__).parents[1])}
    done = subprocess.run(
        [sys.executable, "-m", "kinedyn", "info", str(path), "--json"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert "slider" in done.stdout and "hinge" in done.stdout and json.loads(done.stdout)


# ------------------------------------------------------------------------------ random models
def random_model(seed: int) -> str:
    """A random tree of bodies: each hangs from an earlier one, with 0-3 hinge/slide joints at random
    positions and axes, its pose written in a random one of MuJoCo's five orientation forms, and an
    <inertial> (diagonal with a quat, or full) or geoms only."""
    rng = np.random.default_rng(seed)
    angle = rng.choice(["degree", "radian"])
    scale = 180 / np.pi if angle == "degree" else 1.0
    vec = lambda n: " ".join(f"{v:.6f}" for v in rng.uniform(-1, 1, n))

    def orientation():
        form = rng.integers(6)
        if form == 0:
            return ""
        if form == 1:
            return f' quat="{vec(4)}"'
        if form == 2:
            return f' axisangle="{vec(3)} {rng.uniform(-3, 3) * scale:.6f}"'
        if form == 3:
            return f' euler="{" ".join(f"{a * scale:.6f}" for a in rng.uniform(-3, 3, 3))}"'
        if form == 4:
            return f' xyaxes="{vec(6)}"'
        return f' zaxis="{vec(3)}"'

    def body(k: int, depth: int) -> str:
        parts = [f'<body name="b{k}" pos="{vec(3)}"{orientation()}>']
        for j in range(rng.integers(0 if depth else 1, 4)):
            kind = rng.choice(["hinge", "slide"])
            parts.append(
                f'<joint name="j{k}_{j}" type="{kind}" axis="{vec(3)}" pos="{vec(3)}" armature="{rng.uniform(0, 0.1):.4f}" damping="{rng.uniform(0, 1):.4f}"/>'
            )
        if rng.random() < 0.5:
            m = rng.uniform(0.5, 3)
            d = np.sort(rng.uniform(0.05, 0.2, 3))
            parts.append(
                f'<inertial pos="{vec(3)}"{orientation()} mass="{m:.4f}" diaginertia="{d[0] + d[1]:.5f} {d[1] + d[2]:.5f} {d[0] + d[2]:.5f}"/>'
            )
        else:
            for _ in range(rng.integers(1, 3)):
                shape = rng.choice(["box", "sphere", "capsule", "cylinder", "ellipsoid"])
                parts.append(
                    f'<geom type="{shape}" size="{" ".join(f"{s:.4f}" for s in rng.uniform(0.02, 0.2, 3))}" pos="{vec(3)}"{orientation()}/>'
                )
        return "\n".join(parts)

    text, open_bodies, k = [], 0, 0
    for k in range(int(rng.integers(2, 7))):
        # close 0..open-1 bodies, so the next hangs from a random ancestor
        close = int(rng.integers(0, open_bodies)) if open_bodies > 1 else 0
        text += ["</body>"] * close
        open_bodies -= close
        text.append(body(k, open_bodies))
        open_bodies += 1
    text += ["</body>"] * open_bodies
    return (
        f'<mujoco><compiler angle="{angle}"/><option gravity="{vec(3)}"/><worldbody>'
        + "\n".join(text)
        + "</worldbody></mujoco>"
    )


@pytest.mark.parametrize("seed", range(12))
def test_random_models_agree_with_mujoco(seed):
    xml = random_model(seed)
    robot, model, data = both(xml)
    compare_inertias(robot, model)
    compare_dynamics(robot, model, data, seed=seed, states=3)


# ------------------------------------------- ball and free joints: numbers, through Pinocchio
FREE, BALL = int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL)


def mujoco_to_pinocchio_state(model, qpos, qvel, qacc):
    """(q, v, vdot) in kinedyn's (Pinocchio's) conventions and T with qvel = T v, from MuJoCo's.

    Quaternions: MuJoCo (w, x, y, z) -> (x, y, z, w). Free joint: MuJoCo's qvel is [linear velocity of
    the body origin in world axes; angular velocity in body axes], Pinocchio's [linear; angular] both
    in body axes: v_lin = R^T qvel_lin, and d/dt (R^T v_world) = R^T a_world - w x v_lin. Ball joint:
    angular velocity in the child's axes in both."""
    q, v, vd, T = [], np.array(qvel, float), np.array(qacc, float), np.eye(model.nv)
    for j in range(model.njnt):
        a, b, kind = model.jnt_qposadr[j], model.jnt_dofadr[j], int(model.jnt_type[j])
        if kind == FREE:
            R = np.zeros(9)
            mujoco.mju_quat2Mat(R, qpos[a + 3 : a + 7])
            R = R.reshape(3, 3)
            q += [*qpos[a : a + 3], *qpos[a + 4 : a + 7], qpos[a + 3]]
            v[b : b + 3] = R.T @ qvel[b : b + 3]
            vd[b : b + 3] = R.T @ qacc[b : b + 3] - np.cross(qvel[b + 3 : b + 6], v[b : b + 3])
            T[b : b + 3, b : b + 3] = R
        elif kind == BALL:
            q += [*qpos[a + 1 : a + 4], qpos[a]]
        else:
            q.append(qpos[a])
    return np.array(q), v, vd, T


def random_qpos(model, rng):
    qpos = model.qpos0.copy()
    for j in range(model.njnt):
        a, kind = model.jnt_qposadr[j], int(model.jnt_type[j])
        if kind == FREE:
            qpos[a : a + 3] = rng.normal(size=3)
            a += 3
        if kind in (FREE, BALL):
            quat = rng.normal(size=4)
            qpos[a : a + 4] = quat / np.linalg.norm(quat)
        else:
            qpos[a] = rng.uniform(-1.5, 1.5)
    return qpos


def pinocchio_model_of(robot):
    """A Pinocchio model made from kinedyn's compiled tree (joint kinds, placements, inertias, rotor
    inertias) and nothing else: it checks the MJCF reader's description of ball and free joints
    independently of kinedyn's numeric engine."""
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is an optional test oracle")
    model = pin.Model()
    model.gravity.linear = np.array(robot.gravity, dtype=float)
    armature = []
    for _i, body in enumerate(robot.tree.bodies):
        j = body.joint
        if j.kind == "revolute":
            joint = pin.JointModelRevoluteUnaligned(np.array(j.axis, dtype=float))
        elif j.kind == "prismatic":
            joint = pin.JointModelPrismaticUnaligned(np.array(j.axis, dtype=float))
        elif j.kind == "spherical":
            joint = pin.JointModelSpherical()
        else:
            assert j.kind == "floating"
            joint = pin.JointModelFreeFlyer()
        placement = np.array(body.placement, dtype=float)
        index = model.addJoint(body.parent + 1, joint, pin.SE3(placement[:3, :3], placement[:3, 3]), j.name)
        inertia = body.inertia
        model.appendBodyToJoint(
            index,
            pin.Inertia(
                float(inertia.mass), np.array(inertia.com, dtype=float), np.array(inertia.inertia, dtype=float)
            ),
            pin.SE3.Identity(),
        )
        armature += [float(j.armature)] * j.nv
        assert j.offset == 0  # (the models below have no ref)
    model.armature = np.array(armature)
    return model


def compare_multi_dof(robot, model, seed: int, states: int = 3):
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is an optional test oracle")
    pm = pinocchio_model_of(robot)
    pd = pm.createData()
    assert (pm.nq, pm.nv) == (model.nq, model.nv) == (robot.nq, robot.nv)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    for _ in range(states):
        qpos, qvel, qacc = random_qpos(model, rng), rng.normal(size=model.nv), rng.normal(size=model.nv)
        mujoco_state(model, data, qpos, qvel)
        M = full_mass_matrix(model, data)
        data.qacc[:] = qacc
        mujoco.mj_inverse(model, data)
        q, v, vd, T = mujoco_to_pinocchio_state(model, qpos, qvel, qacc)
        Mp = pin.crba(pm, pd, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        # the mass matrix and generalised forces in kinedyn's velocity coordinates: T^T M T, T^T tau
        np.testing.assert_allclose(Mp, T.T @ M @ T, atol=TOL, rtol=0)
        np.testing.assert_allclose(pin.rnea(pm, pd, q, v, vd), T.T @ data.qfrc_inverse, atol=TOL, rtol=0)
        pin.forwardKinematics(pm, pd, q)
        mujoco.mj_kinematics(model, data)
        for b in range(1, model.nbody):
            frame = robot.tree.frames[robot.tree.frame_index(model.body(b).name or f"body{b}")]
            pose = (pd.oMi[frame.body + 1].homogeneous if frame.body >= 0 else np.eye(4)) @ np.array(
                frame.placement, dtype=float
            )
            np.testing.assert_allclose(pose[:3, 3], data.xpos[b], atol=TOL, rtol=0)
            np.testing.assert_allclose(pose[:3, :3], data.xmat[b].reshape(3, 3), atol=TOL, rtol=0)


BALLS = """<mujoco model="balls">
  <option gravity="0.1 -0.2 -9.81"/>
  <worldbody>
    <body name="torso" pos="0 0 1" euler="10 20 30">
      <freejoint name="root"/>
      <inertial pos="0.1 0.02 0.03" mass="3" diaginertia="0.1 0.2 0.15" quat="0.9 0.1 0.2 0.1"/>
      <body name="arm" pos="0.3 0 0" axisangle="1 1 0 30">
        <joint name="shoulder" type="ball" pos="0.05 0.02 -0.03" armature="0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
        <body name="forearm" pos="0.3 0 0">
          <joint name="elbow" axis="0 1 0" pos="0.01 0 0" armature="0.02"/>
          <joint name="twist" axis="1 0 0"/>
          <geom type="box" size="0.1 0.02 0.03" pos="0.1 0 0"/>
          <body name="hand" pos="0.2 0 0"><joint name="wrist" type="ball"/><geom type="sphere" size="0.04" pos="0.04 0 0"/></body>
        </body>
      </body>
    </body>
    <body name="ball" pos="1 0 0"><freejoint/><geom type="ellipsoid" size="0.1 0.2 0.3"/></body>
  </worldbody>
</mujoco>
"""


def test_free_and_ball_joints_off_their_origins_agree_with_mujoco_through_pinocchio():
    robot = robot_from_mjcf(BALLS)
    assert [j.kind for j in robot.joints] == ["floating", "spherical", "revolute", "revolute", "spherical", "floating"]
    model = mujoco.MjModel.from_xml_string(BALLS)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    compare_multi_dof(robot, model, seed=7)


def test_the_mujoco_test_model_with_free_and_ball_joints_agrees_through_pinocchio():
    text = without_mesh_geom(_mujoco_test_model())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = robot_from_mjcf(text)
    model = mujoco.MjModel.from_xml_string(text)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_SPRING)
    model.opt.density = model.opt.viscosity = 0.0
    model.body_gravcomp[:] = 0
    model.dof_damping[:] = 0  # Pinocchio's rnea has no damping (kinedyn's does: see the 1-DOF tests)
    for j in range(model.njnt):  # kinedyn ignores (and names in its warning) a ball joint's armature
        if int(model.jnt_type[j]) == BALL:
            model.dof_armature[model.jnt_dofadr[j] : model.jnt_dofadr[j] + 3] = 0
    compare_multi_dof(robot, model, seed=8)


@pytest.mark.parametrize(
    "options, extra",
    [
        (
            'boundmass="2" boundinertia="0.05"',
            '<body name="light" pos="0 0 1"><joint name="y"/><geom size="0.01" pos="0.1 0 0" mass="0.1"/></body>',
        ),
        ('settotalmass="7"', ""),
        (
            'balanceinertia="true"',
            '<body name="flat" pos="0 0 1"><joint name="x"/><inertial pos="0.1 0 0" mass="1" diaginertia="0.01 0.01 0.05"/></body>',
        ),
        (
            'boundmass="0.5" boundinertia="0.01" settotalmass="3" balanceinertia="true"',
            '<body name="flat" pos="0 0 1"><joint name="x"/><inertial pos="0.1 0 0" mass="1" diaginertia="0.01 0.01 0.05"/>'
            '<body name="empty"><joint name="y"/></body></body>',
        ),
    ],
)
def test_compiler_inertia_adjustments_agree_with_mujoco(options, extra, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warning (settotalmass is deprecated) to ./MUJOCO_LOG.TXT
    xml = random_model(3).replace("<compiler ", f"<compiler {options} ").replace("</worldbody>", extra + "</worldbody>")
    robot, model, data = both(xml)
    compare_inertias(robot, model)
    compare_dynamics(robot, model, data, seed=9, states=2)


# ----------------------------------------------------- the MJCF files pybullet ships (gym's models)
def pybullet_mjcf_files():
    """pybullet_data's MJCF files that today's MuJoCo compiles (a few are in MuJoCo 1.x syntax)."""
    try:
        import pybullet_data
    except ImportError:
        return []
    folder = os.path.join(pybullet_data.getDataPath(), "mjcf")
    out = []
    for name in sorted(os.listdir(folder)):
        try:
            if name.endswith(".xml"):
                mujoco.MjModel.from_xml_path(os.path.join(folder, name))
                out.append(os.path.join(folder, name))
        except ValueError:
            pass
    return out


def test_pybullet_data_holds_the_mjcf_models():
    pytest.importorskip("pybullet_data", reason="pybullet (the peers extra) ships gym's MJCF models")
    names = {os.path.basename(p) for p in pybullet_mjcf_files()}
    assert len(names) >= 18 and {"ant.xml", "humanoid.xml", "striker.xml", "thrower.xml", "reacher.xml"} <= names


@pytest.mark.parametrize("path", pybullet_mjcf_files(), ids=os.path.basename)
def test_every_mjcf_file_of_pybullet_data_that_mujoco_compiles_agrees_with_mujoco(path):
    """pybullet_data (the peers extra) ships gym's MJCF models (ant, humanoid, reacher, pusher,
    striker, ...): kinedyn reads every one MuJoCo compiles, with the same M, inverse dynamics and
    body poses (through Pinocchio where a model has free or ball joints)."""
    model = mujoco.MjModel.from_xml_path(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = robot_from_mjcf(path)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_SPRING)
    model.opt.density = model.opt.viscosity = 0.0
    model.body_gravcomp[:] = 0
    compare_inertias(robot, model)
    if robot.has_multi_dof_joints:
        for j in range(model.njnt):  # kinedyn ignores (and names in its warning) these of ball and free joints
            if int(model.jnt_type[j]) in (FREE, BALL):
                dofs = slice(model.jnt_dofadr[j], model.jnt_dofadr[j] + (6 if int(model.jnt_type[j]) == FREE else 3))
                model.dof_armature[dofs] = model.dof_damping[dofs] = 0
        compare_multi_dof_kinedyn(robot, model, seed=10, states=2)
        model.dof_damping[:] = 0  # Pinocchio's rnea has no damping
        compare_multi_dof(robot, model, seed=10, states=2)
    else:
        compare_dynamics(robot, model, mujoco.MjData(model), seed=10, states=2)


# ---------------------------------------------- ball and free joints: kinedyn's own numbers
def mujoco_acceleration(model, qpos, qvel, vd):
    """MuJoCo's qacc for kinedyn's vdot (the inverse of mujoco_to_pinocchio_state's map): a free
    joint's world linear acceleration is R (vdot_lin + w x v_lin)."""
    qacc = np.array(vd, float)
    for j in range(model.njnt):
        a, b = model.jnt_qposadr[j], model.jnt_dofadr[j]
        if int(model.jnt_type[j]) == FREE:
            R = np.zeros(9)
            mujoco.mju_quat2Mat(R, qpos[a + 3 : a + 7])
            R = R.reshape(3, 3)
            v_lin = R.T @ qvel[b : b + 3]
            qacc[b : b + 3] = R @ (vd[b : b + 3] + np.cross(qvel[b + 3 : b + 6], v_lin))
    return qacc


def compare_multi_dof_kinedyn(robot, model, seed: int, states: int = 3):
    """kinedyn's M, bias forces, inverse and forward dynamics and body poses against MuJoCo's, in
    kinedyn's coordinates (M_kd = T^T M T, tau_kd = T^T tau_mj with qvel = T v)."""
    assert (robot.nq, robot.nv) == (model.nq, model.nv)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    for _ in range(states):
        qpos, qvel = random_qpos(model, rng), rng.normal(size=model.nv)
        mujoco_state(model, data, qpos, qvel)
        M = full_mass_matrix(model, data)
        q, v, _, T = mujoco_to_pinocchio_state(model, qpos, qvel, np.zeros(model.nv))
        np.testing.assert_allclose(robot.mass_matrix(q), T.T @ M @ T, atol=TOL, rtol=0)
        for vd in (np.zeros(model.nv), rng.normal(size=model.nv)):
            data.qacc[:] = mujoco_acceleration(model, qpos, qvel, vd)
            mujoco.mj_inverse(model, data)
            tau = T.T @ data.qfrc_inverse
            np.testing.assert_allclose(robot.inverse_dynamics(q, v, vd), tau, atol=TOL, rtol=0)
            if not vd.any():  # kinedyn's bias torque: C v + g (+ friction, zero here)
                np.testing.assert_allclose(robot.bias_torque(q, v) + robot.friction_torque(v), tau, atol=TOL, rtol=0)
            np.testing.assert_allclose(robot.forward_dynamics(q, v, tau), vd, atol=1e-7, rtol=0)
        mujoco.mj_kinematics(model, data)
        for b in range(1, model.nbody):
            T_b = robot.pose(q, frame=model.body(b).name or f"body{b}")
            np.testing.assert_allclose(T_b[:3, 3], data.xpos[b], atol=TOL, rtol=0)
            np.testing.assert_allclose(T_b[:3, :3], data.xmat[b].reshape(3, 3), atol=TOL, rtol=0)


def test_free_and_ball_joints_agree_with_mujoco_in_kinedyns_engine():
    robot = robot_from_mjcf(BALLS)
    model = mujoco.MjModel.from_xml_string(BALLS)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    compare_multi_dof_kinedyn(robot, model, seed=11)


def test_the_mujoco_test_model_agrees_with_mujoco_in_kinedyns_engine():
    """testdata/model.xml whole (bar its mesh geom): free bodies, ball joints, hinges and a slide,
    with their damping and armature (but a ball joint's, which kinedyn names in its warning)."""
    text = without_mesh_geom(_mujoco_test_model())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = robot_from_mjcf(text)
    model = mujoco.MjModel.from_xml_string(text)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_SPRING)
    model.opt.density = model.opt.viscosity = 0.0
    model.body_gravcomp[:] = 0
    for j in range(model.njnt):
        if int(model.jnt_type[j]) == BALL:
            model.dof_armature[model.jnt_dofadr[j] : model.jnt_dofadr[j] + 3] = 0
            model.dof_damping[model.jnt_dofadr[j] : model.jnt_dofadr[j] + 3] = 0
    compare_multi_dof_kinedyn(robot, model, seed=12)


def test_a_ball_joints_range_and_damping_are_named_as_ignored():
    xml = (
        '<mujoco><worldbody><body><joint name="b" type="ball" range="0 30" damping="1"/><geom size="0.1"/></body>'
        "</worldbody></mujoco>"
    )
    with pytest.warns(UserWarning, match=r"damping of the ball joint 'b'; the range \(a cone\) of the ball joint 'b'"):
        robot = robot_from_mjcf(xml)
    assert robot.joints[0].kind == "spherical" and robot.joints[0].viscous == 0


# ------------------------------------------------------------ round trip with kinedyn's writer
@pytest.mark.parametrize("seed", range(4))
def test_robot_to_mjcf_reads_back_as_the_same_robot(seed):
    """robot.to_mjcf (kinedyn's writer) then from_mjcf: the same frames, M and inverse dynamics, for
    random trees with spherical joints (random_robot places its free-flyer off the origin, which MJCF
    cannot hold; planar joints have no MJCF reading here)."""
    from kinedyn.testing import random_robot

    robot = random_robot(seed, n=5, branching=True, friction=False, spherical=0.4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        back = robot_from_mjcf(robot.to_mjcf(geometry=False))
    assert (back.nq, back.nv) == (robot.nq, robot.nv)
    assert [j.kind for j in back.joints] == [j.kind for j in robot.joints]
    rng = np.random.default_rng(seed)
    for _ in range(3):
        q, v, vd = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        np.testing.assert_allclose(back.mass_matrix(q), robot.mass_matrix(q), atol=1e-9, rtol=0)
        np.testing.assert_allclose(back.inverse_dynamics(q, v, vd), robot.inverse_dynamics(q, v, vd), atol=1e-9, rtol=0)
        for name in robot.body_names:
            np.testing.assert_allclose(back.pose(q, frame=name), robot.pose(q, frame=name), atol=1e-9, rtol=0)
