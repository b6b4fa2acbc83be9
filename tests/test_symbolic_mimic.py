"""The symbolic engine on robots with reduced mimic joints (issue 14): a follower's coordinate is
``m q_leader + o``, so the equations live in the independent coordinates only.

Oracles: the numeric engine's reduced model (kinedyn/native/mimic.py: M_r = G^T M G, C_r = G^T C G,
g_r = G^T g, J_r = J G), evaluated at random states; the Lagrange route against the customised
Newton-Euler route and its CSE (forward-mode) form; dM/dt formed here by SymPy's own differentiation
of the printed M (not the ring's chain rule) against C + C^T, and dM/dt - 2C skew-symmetric."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.symbolic.cse import closed_form, evaluate_block

pytestmark = pytest.mark.filterwarnings("ignore::kinedyn.description.inertia.PhysicalConsistencyWarning")

# a 3-link arm whose third joint follows the second (revolute, MULT and OFF), and a two-finger gripper
# on it whose right finger follows the left (prismatic, multiplier 1, offset 0.01); inertias off-axis
ARM = """<robot name="mimic_arm">
<link name="base"/>
<link name="l1"><inertial><origin xyz="0 0 0.2" rpy="0.1 0 0"/><mass value="1.3"/><inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0.002" izz="0.015"/></inertial></link>
<link name="l2"><inertial><origin xyz="0.25 0.01 0"/><mass value="0.9"/><inertia ixx="0.01" ixy="0" ixz="0.001" iyy="0.02" iyz="0" izz="0.015"/></inertial></link>
<link name="l3"><inertial><origin xyz="0.2 0 0.02" rpy="0 0.2 0"/><mass value="0.6"/><inertia ixx="0.005" ixy="0" ixz="0" iyy="0.01" iyz="0.001" izz="0.008"/></inertial></link>
<link name="fl"><inertial><origin xyz="0 0.01 0.03"/><mass value="0.1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0005"/></inertial></link>
<link name="fr"><inertial><origin xyz="0 -0.01 0.03"/><mass value="0.12"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0005"/></inertial></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.4" rpy="0.3 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
<joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0.5 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/><mimic joint="j2" multiplier="MULT" offset="OFF"/></joint>
<joint name="finger_left" type="prismatic"><parent link="l3"/><child link="fl"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/></joint>
<joint name="finger_right" type="prismatic"><parent link="l3"/><child link="fr"/><origin xyz="0.4 0 0"/><axis xyz="0 -1 0"/><limit lower="0" upper="0.04" effort="10" velocity="1"/><mimic joint="finger_left" multiplier="1" offset="0.01"/></joint>
</robot>"""

# followers of the other kind: a revolute joint following a prismatic one (cos(0.7 p1 + 0.1)) and a
# prismatic one following a revolute one (-0.05 r3 + 0.02), each with friction and rotor inertia
MIXED = """<robot name="mixed_mimic"><link name="base"/>
<link name="a"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>
<link name="b"><inertial><origin xyz="0.2 0.05 0"/><mass value="0.7"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
<link name="c"><inertial><origin xyz="0.2 0 0.1"/><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial></link>
<link name="d"><inertial><origin xyz="0 0 0.05"/><mass value="0.3"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.003" iyz="0" izz="0.001"/></inertial></link>
<joint name="p1" type="prismatic"><parent link="base"/><child link="a"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/><dynamics damping="0.3" friction="0.2"/></joint>
<joint name="r2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="p1" multiplier="0.7" offset="0.1"/><dynamics damping="0.2" friction="0.1"/></joint>
<joint name="r3" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
<joint name="p4" type="prismatic"><parent link="c"/><child link="d"/><origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="r3" multiplier="-0.05" offset="0.02"/><dynamics damping="0.1" friction="0.05"/></joint>
</robot>"""


def arm(multiplier="-1.5", offset="0.2"):
    return kd.Robot.from_urdf(ARM.replace("MULT", multiplier).replace("OFF", offset))


def mixed():
    robot = kd.Robot.from_urdf(MIXED)
    drive = lambda joint: (
        dataclasses.replace(joint, gear_ratio=2.0, rotor_inertia=0.01) if joint.kind != "fixed" else joint
    )
    return robot.replace(links=[dataclasses.replace(link, joint=drive(link.joint)) for link in robot.links])


def states(robot, count=2, seed=0):
    rng = np.random.default_rng(seed)
    return [tuple(rng.uniform(-1, 1, robot.n) for _ in range(3)) for _ in range(count)]


def values(eom, q, qd, qdd):
    return dict(zip(eom.q, q)) | dict(zip(eom.qd, qd)) | dict(zip(eom.qdd, qdd))


def number(expr, at):
    return np.array(sp.Matrix(expr).xreplace(at).evalf(), dtype=float)


def check_against_numeric(robot, eom, seed=0):
    for q, qd, qdd in states(robot, seed=seed):
        at = values(eom, q, qd, qdd)
        np.testing.assert_allclose(number(eom.M, at), robot.mass_matrix(q), atol=1e-10)
        np.testing.assert_allclose(number(eom.C, at), robot.coriolis_matrix(q, qd), atol=1e-10)
        np.testing.assert_allclose(number(eom.g, at).ravel(), robot.gravity_torque(q), atol=1e-10)
        np.testing.assert_allclose(number(eom.tau, at).ravel(), robot.inverse_dynamics(q, qd, qdd), atol=1e-10)
        np.testing.assert_allclose(number(eom.friction, at).ravel(), robot.friction_torque(qd), atol=1e-10)
        c = np.array([[[float(sp.sympify(x).xreplace(at)) for x in row] for row in plane] for plane in eom.christoffel])
        np.testing.assert_allclose(c, robot.christoffel(q), atol=1e-10)


@pytest.mark.parametrize("multiplier, offset", [("-1.5", "0.2"), ("-1", "0"), ("2", "0.3")])
def test_lagrange_equations_in_reduced_coordinates_equal_the_numeric_reduced_model(multiplier, offset):
    robot = arm(multiplier, offset)
    assert robot.joint_names == ["j1", "j2", "finger_left"]
    eom = robot.equations_of_motion()
    assert [str(s) for s in eom.q] == ["j1", "j2", "finger_left"] and eom.M.shape == (3, 3)
    check_against_numeric(robot, eom)


def test_a_fractional_multiplier_prints_as_the_followers_angle():
    eom = arm("-1.5", "0.2").equations_of_motion()
    j2 = eom.q[1]
    trig = {f.args[0] for f in sp.Matrix(eom.M).atoms(sp.cos, sp.sin)}
    assert 3 * j2 / 2 in trig  # the relative angle of l3 is j3 = -3/2 j2 + 0.2


def test_followers_of_the_other_kind_with_friction_and_rotor_inertia():
    robot = mixed()
    assert robot.joint_names == ["p1", "r3"]
    assert np.abs(robot.friction_torque([0.3, -0.2])).min() > 0
    for method in ("lagrange", "newton_euler"):
        check_against_numeric(robot, robot.equations_of_motion(method=method), seed=1)


@pytest.mark.parametrize("make", [arm, mixed], ids=["arm", "mixed"])
def test_lagrange_newton_euler_and_cse_routes_agree(make):
    robot = make()
    lagrange = robot.equations_of_motion()
    newton_euler = robot.equations_of_motion(method="newton_euler")
    cse = closed_form(robot, lagrange.q, lagrange.qd, lagrange.qdd)
    for q, qd, qdd in states(robot, seed=2):
        at = values(lagrange, q, qd, qdd)
        for name in ("M", "C", "g", "tau"):
            reference = number(getattr(lagrange, name), at)
            np.testing.assert_allclose(number(getattr(newton_euler, name), at), reference, atol=1e-12, err_msg=name)
            if name != "tau":
                block = np.array([float(x) for x in evaluate_block(cse[name], at)]).reshape(reference.shape)
                np.testing.assert_allclose(block, reference, atol=1e-12, err_msg=name)


def test_newton_euler_steps_show_the_mapping_of_joint_forces_to_the_coordinates():
    steps = arm().equations_of_motion(method="newton_euler").steps
    last = steps[-1]
    assert (
        "G^T" in last.title and "j3 = -1.5 j2 + 0.2" in last.text and "finger_right = 1 finger_left + 0.01" in last.text
    )
    assert len(last.equations) == 3


@pytest.mark.parametrize("make", [arm, mixed], ids=["arm", "mixed"])
def test_dm_dt_equals_c_plus_c_transpose_and_dm_dt_minus_2c_is_skew(make):
    robot = make()
    eom = robot.equations_of_motion()
    M, C = eom.M, eom.C
    # dM/dt by SymPy's differentiation of the printed M (cos(3 j2/2) differentiated as written)
    Mdot = sum((M.diff(q) * v for q, v in zip(eom.q, eom.qd)), sp.zeros(*M.shape))
    for q, qd, qdd in states(robot, seed=3):
        at = values(eom, q, qd, qdd)
        Md, Cn = number(Mdot, at), number(C, at)
        np.testing.assert_allclose(Md, Cn + Cn.T, atol=1e-10)
        N = Md - 2 * Cn
        np.testing.assert_allclose(N, -N.T, atol=1e-10)
        assert np.abs(Cn).max() > 1e-3  # a real check: the Coriolis terms are there


def test_symbolic_pose_and_jacobians_of_follower_moved_frames_equal_the_numeric_ones():
    robot = arm()
    q = np.random.default_rng(4).uniform(-1, 1, robot.n)
    at = dict(zip(kd.symbolic.joint_symbols(robot), q))
    for frame in ("l3", "fr"):  # moved by j3 (follows j2) and by finger_right (follows finger_left)
        np.testing.assert_allclose(number(kd.symbolic.pose(robot, frame), at), robot.pose(q, frame=frame), atol=1e-12)
        for reference in ("world", "local", "spatial"):
            J = number(kd.symbolic.jacobian(robot, frame, reference=reference, simplify=False), at)
            assert J.shape == (6, 3)
            np.testing.assert_allclose(
                J, robot.jacobian(q, frame=frame, reference=reference), atol=1e-12, err_msg=f"{frame} {reference}"
            )


def test_panda_closed_form_with_its_mimic_finger():
    from kinedyn.testing import example_robot_data_dir

    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    robot = kd.Robot.from_urdf(os.path.join(root, "panda_description/urdf/panda.urdf"))
    assert robot.mimic_joints and robot.n == 8
    q_symbols = kd.symbolic.joint_symbols(robot)
    qd_symbols = sp.symbols("v1:9", real=True)
    qdd_symbols = sp.symbols("a1:9", real=True)
    cse = closed_form(robot, q_symbols, qd_symbols, qdd_symbols)
    rng = np.random.default_rng(5)
    q, qd = rng.uniform(-1, 1, 8) * [1, 1, 1, 1, 1, 1, 1, 0.04], rng.uniform(-1, 1, 8)
    at = dict(zip(q_symbols, q)) | dict(zip(qd_symbols, qd))
    for name, reference in (
        ("M", robot.mass_matrix(q)),
        ("C", robot.coriolis_matrix(q, qd)),
        ("g", robot.gravity_torque(q)),
    ):
        block = np.array([float(x) for x in evaluate_block(cse[name], at)]).reshape(reference.shape)
        np.testing.assert_allclose(block, reference, atol=1e-10, err_msg=name)


def test_general_parameters_are_per_body_and_the_regressor_reproduces_tau():
    robot = arm()
    eom = robot.equations_of_motion(parameters="general")  # ten symbols per body: 5 bodies, 3 coordinates
    Y, theta = eom.regressor()
    assert Y.shape[0] == 3
    from kinedyn.symbolic.robot_eom import general_parameters

    numbers = {
        s: v
        for row, values in zip(general_parameters(robot), robot.inertial_parameters().reshape(-1, 10))
        for s, v in zip(row, values)
    }
    for q, qd, qdd in states(robot, seed=6):
        at = values(eom, q, qd, qdd)
        tau = np.array((Y * sp.Matrix(theta)).xreplace(at).xreplace(numbers).evalf(), dtype=float).ravel()
        np.testing.assert_allclose(tau, robot.inverse_dynamics(q, qd, qdd) - robot.friction_torque(qd), atol=1e-10)


def test_cli_derives_a_mimic_robot(tmp_path, capsys):
    import json

    from kinedyn.cli import main

    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace("MULT", "-1.5").replace("OFF", "0.2"))
    assert main(["derive", str(path), "--json", "--no-simplify"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["q"] == ["j1", "j2", "finger_left"] and len(out["M"]) == 3
    assert "3*j2/2" in out["M"][1][1]


def test_property_search_does_not_take_a_fractional_multiple_for_2pi_periodic():
    from kinedyn.analysis import prove_properties

    report = prove_properties(arm().equations_of_motion(steps=False), samples=2, starts=2)
    bounds = next(c for c in report.checks if c.name.startswith("inertia bounds"))
    # j1 only in cos/sin of integer multiples: periodic; j2 in cos(3 j2 / 2): 4 pi-periodic, searched in a range
    assert bounds.detail.endswith("q in periodic, [-1, 1], [-1, 1])") and bounds.passed
