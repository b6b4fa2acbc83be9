"""Mimic joints (URDF ``<mimic>``, issue 14 §1 and §4): the follower's coordinate is
``multiplier * q_leader + offset``; ``mimic="reduce"`` (default) removes it.

Oracles: (1) a reduced model built by hand here, ``G^T M_full G`` etc. from the same file loaded with
``mimic="independent"`` and a G assembled in this file from the XML (not from kinedyn's map);
(2) Pinocchio's mimic models (``buildModelFromUrdf(path, mimic=True)``), on a gripper written here and
on the example-robot-data URDFs it can build; (3) identities on the reduced robot (rnea == M qdd +
bias, forward dynamics == solve, dM/dt == C + C^T by finite differences, derivatives by finite
differences).
"""

from __future__ import annotations

import os
import pickle
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.joint import Joint, Mimic
from kinedyn.description.link import Link
from kinedyn.description.mimic import mimic_map

pytest.importorskip("kinedyn._core", reason="the native module is not built")

INERTIAL = """<inertial><origin xyz="{c}" rpy="0.1 -0.2 0.3"/><mass value="{m}"/>
  <inertia ixx="{i}" ixy="{xy}" ixz="{xz}" iyy="{j}" iyz="{yz}" izz="{k}"/></inertial>"""


def link(name, m=0.5, c="0.01 0.02 0.03", i=0.02, j=0.03, k=0.025):
    s = min(i, j, k)
    return (
        f'<link name="{name}">{INERTIAL.format(m=m, c=c, i=i, j=j, k=k, xy=0.05 * s, xz=-0.1 * s, yz=0.07 * s)}</link>'
    )


def joint(name, kind, parent, child, xyz="0 0 0.1", rpy="0 0 0", axis="0 0 1", mimic="", limit=True, dynamics=""):
    lim = '<limit lower="-1.5" upper="1.5" effort="10" velocity="2"/>' if limit else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>{lim}{mimic}{dynamics}</joint>'
    )


def gripper_urdf(chain: bool = False) -> str:
    """An arm joint, a wrist, and a parallel gripper: the right finger follows the left one with
    multiplier -1 and an offset, a revolute 'knuckle' follows the wrist with 0.5 and an offset (with
    friction of its own); with ``chain``, a 'tip' follows the knuckle (a follower of a follower)."""
    parts = [
        link("base"),
        link("upper", 1.2, "0.1 0 0.05"),
        link("palm", 0.8, "0.02 -0.01 0.04"),
        link("left", 0.1, "0 0.01 0.02", 0.001, 0.002, 0.0015),
        link("right", 0.12, "0 -0.01 0.02", 0.0012, 0.002, 0.0011),
        link("knuckle", 0.2, "0.03 0 0.01"),
        joint("shoulder", "revolute", "base", "upper", axis="0 0 1"),
        joint("wrist", "revolute", "upper", "palm", xyz="0.3 0 0.05", rpy="0.3 0 0", axis="0 1 0"),
        joint(
            "left_finger",
            "prismatic",
            "palm",
            "left",
            xyz="0 0.02 0.08",
            axis="0 1 0",
            dynamics='<dynamics damping="0.3" friction="0.1"/>',
        ),
        joint(
            "right_finger",
            "prismatic",
            "palm",
            "right",
            xyz="0 -0.02 0.08",
            axis="0 1 0",
            mimic='<mimic joint="left_finger" multiplier="-1" offset="0.01"/>',
            dynamics='<dynamics damping="0.2" friction="0.05"/>',
        ),
        joint(
            "knuckle_joint",
            "revolute",
            "palm",
            "knuckle",
            xyz="0.05 0 0.02",
            axis="1 0 0",
            mimic='<mimic joint="wrist" multiplier="0.5" offset="0.2"/>',
            dynamics='<dynamics damping="0.4"/>',
        ),
    ]
    if chain:
        parts += [
            link("tip", 0.05, "0.01 0.01 0.01", 0.0005, 0.0006, 0.0007),
            joint(
                "tip_joint",
                "revolute",
                "knuckle",
                "tip",
                xyz="0 0.04 0",
                axis="0 0 1",
                mimic='<mimic joint="knuckle_joint" multiplier="2.0" offset="-0.1"/>',
            ),
        ]
    return '<robot name="gripper">' + "".join(parts) + "</robot>"


def hand_G(xml: str, independent_robot, reduced_robot):
    """(G, b) with q_full = G q + b, from the file's <mimic> elements (chains followed here)."""
    root = ET.fromstring(xml) if xml.lstrip().startswith("<") else ET.parse(xml).getroot()
    rel = {}
    for j in root.iter("joint"):
        m = j.find("mimic")
        if m is not None:
            rel[j.get("name")] = (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))

    def resolve(name):
        mult, off = 1.0, 0.0
        while name in rel:
            leader, m, o = rel[name]
            # q_x = mult q_name + off and q_name = m q_leader + o: q_x = mult m q_leader + (mult o + off)
            mult, off = mult * m, mult * o + off
            name = leader
        return name, mult, off

    full, red = independent_robot.joint_names, reduced_robot.joint_names
    G, b = np.zeros((len(full), len(red))), np.zeros(len(full))
    for a, name in enumerate(full):
        leader, mult, off = resolve(name)
        G[a, red.index(leader)] = mult
        b[a] = off
    return G, b


def _resolve_check():
    # q_tip = 2 q_knuckle - 0.1, q_knuckle = 0.5 q_wrist + 0.2 -> q_tip = q_wrist + 0.3
    rel = Mimic("knuckle_joint", 2.0, -0.1)
    return Mimic("wrist", 0.5, 0.2).then(rel)


@pytest.fixture(params=[False, True], ids=["gripper", "chain"], scope="module")
def pair(request):
    xml = gripper_urdf(request.param)
    reduced, full = kd.Robot.from_urdf(xml), kd.Robot.from_urdf(xml, mimic="independent")
    G, b = hand_G(xml, full, reduced)
    return reduced, full, G, b


def states(robot, count=4, seed=1):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield robot.random_configuration(rng), rng.uniform(-2, 2, robot.n), rng.uniform(-3, 3, robot.n)


# ------------------------------------------------------------------ description
def test_urdf_mimic_is_read_and_reduced():
    robot = kd.Robot.from_urdf(gripper_urdf(chain=True))
    assert robot.joint_names == ["shoulder", "wrist", "left_finger"]
    assert robot.n == robot.nq == robot.nv == 3 and robot.lower_limits.shape == (3,)
    assert robot.mimic_joints == {
        "right_finger": Mimic("left_finger", -1.0, 0.01),
        "knuckle_joint": Mimic("wrist", 0.5, 0.2),
        "tip_joint": Mimic("wrist", 1.0, 0.30000000000000004),
    }
    tip = next(
        j for j in kd.Robot.from_urdf(gripper_urdf(chain=True), mimic="independent").joints if j.name == "tip_joint"
    )
    assert tip.mimic == Mimic("knuckle_joint", 2.0, -0.1)  # the joint records the file's relation
    assert _resolve_check() == Mimic("wrist", 1.0, 0.2 + 0.1)
    full = kd.Robot.from_urdf(gripper_urdf(chain=True), mimic="independent")
    assert full.n == 6 and full.mimic_joints == {}
    assert len(robot.body_names) == 6  # every moving link stays (and takes external wrenches)
    assert pickle.loads(pickle.dumps(robot)).mimic_joints == robot.mimic_joints
    assert robot.replace(name="other").n == 3 and robot.subs({}).n == 3


@pytest.mark.filterwarnings("ignore::kinedyn.description.inertia.PhysicalConsistencyWarning")
def test_a_fixed_joints_mimic_is_ignored():
    """Talos's talos_left_arm.urdf fixes gripper_left_inner_double_joint and keeps its <mimic>."""
    fixed = gripper_urdf().replace(
        '<joint name="right_finger" type="prismatic"', '<joint name="right_finger" type="fixed"'
    )
    robot = kd.Robot.from_urdf(fixed)
    assert robot.joint_names == ["shoulder", "wrist", "left_finger"] and "right_finger" not in robot.mimic_joints
    arm = kd.Robot.from_urdf(erd_path("talos_data/robots/talos_left_arm.urdf"))
    assert "gripper_left_inner_double_joint" not in arm.joint_names + list(arm.mimic_joints)


def test_mimic_errors_name_the_joint():
    base = gripper_urdf()
    missing = base.replace('mimic joint="left_finger"', 'mimic joint="no_such_joint"')
    with pytest.raises(ValueError, match=r"joint 'right_finger' mimics joint 'no_such_joint'.*mimic='independent'"):
        kd.Robot.from_urdf(missing)
    assert kd.Robot.from_urdf(missing, mimic="independent").n == 5
    zero = base.replace('multiplier="-1"', 'multiplier="0"')
    # urdfdom accepts multiplier 0 and Pinocchio's default reader keeps the joint independent: so does
    # kinedyn, with a warning naming the line (tests/test_wild_files.py checks it against Pinocchio)
    with pytest.warns(UserWarning, match=r"URDF string>:\d+: joint 'right_finger': <mimic> multiplier 0"):
        robot = kd.Robot.from_urdf(zero)
    assert "right_finger" in robot.joint_names and "right_finger" not in robot.mimic_joints
    with pytest.raises(
        ValueError,
        match=r"URDF string>:\d+: joint 'right_finger' <mimic> attribute 'multiplier' must be 1 finite numbers, got 'nan'$",
    ):
        kd.Robot.from_urdf(base.replace('multiplier="-1"', 'multiplier="nan"'))
    with pytest.raises(ValueError, match=r"<mimic> has no joint attribute"):
        kd.Robot.from_urdf(base.replace('mimic joint="left_finger"', "mimic"))
    fixed = base.replace('<joint name="left_finger" type="prismatic"', '<joint name="left_finger" type="fixed"')
    with pytest.raises(ValueError, match=r"joint 'right_finger' mimics joint 'left_finger', which is fixed"):
        kd.Robot.from_urdf(fixed)
    cycle = base.replace(
        '<axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/><dynamics damping="0.3"',
        '<axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/><mimic joint="right_finger"/><dynamics damping="0.3"',
    )
    with pytest.raises(
        ValueError,
        match=r"mimic joints form a cycle: (left_finger -> right_finger -> left_finger|right_finger -> left_finger -> right_finger)",
    ):
        kd.Robot.from_urdf(cycle)
    with pytest.raises(ValueError, match=r"mimic must be one of \['reduce', 'independent'\]"):
        kd.Robot.from_urdf(base, mimic="yes")
    with pytest.raises(ValueError, match=r"joint 'j': only a revolute or prismatic joint can mimic"):
        Joint("j", "fixed", mimic=Mimic("a"))
    with pytest.raises(ValueError, match="cannot mimic itself"):
        Joint("j", mimic="j")
    with pytest.raises(ValueError, match="offset"):
        Mimic("a", 1.0, float("inf"))
    # a multi-DOF joint leads nothing
    links = [
        Link("ball", None, Joint("ball_joint", "spherical")),
        Link("f", "ball", Joint("f_joint", mimic=Mimic("ball_joint"))),
    ]
    with pytest.raises(ValueError, match=r"joint 'f_joint' mimics joint 'ball_joint', which is spherical"):
        kd.Robot(links)


def test_coordinate_maps_use_index_ranges_for_multi_dof_blocks():
    """A floating base and a spherical joint (nq 7 and 4, nv 6 and 3) before and between the
    1-DOF leader and followers: q and v copied block by block."""
    joints = [
        Joint("root", "floating"),
        Joint("a"),
        Joint("ball", "spherical"),
        Joint("f", "prismatic", mimic=Mimic("a", -2.0, 0.5)),
        Joint("c"),
    ]
    m = mimic_map(joints, joints)
    assert (m.nq_full, m.nv_full, m.nq, m.nv) == (14, 12, 13, 11)
    q = np.arange(13.0) + 1
    full = m.expand_q(q)
    np.testing.assert_array_equal(full, np.r_[q[:12], -2.0 * q[7] + 0.5, q[12]])
    v = np.arange(11.0) + 1
    np.testing.assert_array_equal(m.expand_v(v), np.r_[v[:10], -2.0 * v[6], v[10]])
    np.testing.assert_array_equal(m.reduce_force(np.eye(12)), m.G)


# ------------------------------------------------------------------ against the hand-reduced model
def test_reduced_dynamics_equal_the_hand_reduced_model(pair):
    reduced, full, G, b = pair
    frames = reduced.frame_names
    for q, qd, qdd in states(reduced):
        qf, qdf, qddf = G @ q + b, G @ qd, G @ qdd
        M = full.mass_matrix(qf)
        np.testing.assert_allclose(reduced.mass_matrix(q), G.T @ M @ G, atol=1e-12)
        np.testing.assert_allclose(
            reduced.inverse_dynamics(q, qd, qdd), G.T @ full.inverse_dynamics(qf, qdf, qddf), atol=1e-12
        )
        np.testing.assert_allclose(reduced.gravity_torque(q), G.T @ full.gravity_torque(qf), atol=1e-12)
        np.testing.assert_allclose(reduced.bias_torque(q, qd), G.T @ full.bias_torque(qf, qdf), atol=1e-12)
        np.testing.assert_allclose(reduced.coriolis_matrix(q, qd), G.T @ full.coriolis_matrix(qf, qdf) @ G, atol=1e-12)
        np.testing.assert_allclose(reduced.friction_torque(qd), G.T @ full.friction_torque(qdf), atol=1e-12)
        np.testing.assert_allclose(reduced.regressor(q, qd, qdd), G.T @ full.regressor(qf, qdf, qddf), atol=1e-12)
        np.testing.assert_allclose(
            reduced.christoffel(q), np.einsum("ai,bj,ck,abc->ijk", G, G, G, full.christoffel(qf)), atol=1e-12
        )
        tau = G.T @ full.inverse_dynamics(qf, qdf, qddf)
        np.testing.assert_allclose(reduced.forward_dynamics(q, qd, tau), qdd, atol=1e-9)
        np.testing.assert_allclose(reduced.mass_matrix_inverse(q), np.linalg.inv(G.T @ M @ G), rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(reduced.frame_poses(q), full.frame_poses(qf), atol=1e-14)
        for frame in frames[1:]:
            for ref in ("world", "local", "spatial"):
                np.testing.assert_allclose(
                    reduced.jacobian(q, frame, ref), full.jacobian(qf, frame, ref) @ G, atol=1e-12
                )
            np.testing.assert_allclose(
                reduced.frame_velocity(q, qd, frame), full.frame_velocity(qf, qdf, frame), atol=1e-12
            )
            np.testing.assert_allclose(
                reduced.jacobian_dot_qd(q, qd, frame), full.jacobian_dot_qd(qf, qdf, frame), atol=1e-12
            )
        H = reduced.jacobian_hessian(q, "left")
        np.testing.assert_allclose(H, np.einsum("ik,irj,jl->krl", G, full.jacobian_hessian(qf, "left"), G), atol=1e-12)
        assert reduced.kinetic_energy(q, qd) == pytest.approx(full.kinetic_energy(qf, qdf), abs=1e-13)
        assert reduced.potential_energy(q) == pytest.approx(full.potential_energy(qf), abs=1e-13)
        np.testing.assert_allclose(reduced.center_of_mass(q), full.center_of_mass(qf), atol=1e-14)
        np.testing.assert_allclose(reduced.momentum(q, qd), full.momentum(qf, qdf), atol=1e-13)
        f_ext = np.random.default_rng(3).normal(size=(len(reduced.body_names), 6))
        np.testing.assert_allclose(
            reduced.inverse_dynamics(q, qd, qdd, f_ext), G.T @ full.inverse_dynamics(qf, qdf, qddf, f_ext), atol=1e-12
        )


def test_batches_and_out_arguments(pair):
    reduced, _, _, _ = pair
    rng = np.random.default_rng(5)
    Q, QD, QDD = (rng.uniform(-1, 1, (6, reduced.n)) for _ in range(3))
    for method, args in (
        ("mass_matrix", (Q,)),
        ("inverse_dynamics", (Q, QD, QDD)),
        ("forward_dynamics", (Q, QD, QDD)),
        ("gravity_torque", (Q,)),
        ("coriolis_matrix", (Q, QD)),
        ("bias_torque", (Q, QD)),
        ("jacobian", (Q,)),
        ("kinetic_energy", (Q, QD)),
        ("regressor", (Q, QD, QDD)),
        ("mass_matrix_inverse", (Q,)),
        ("christoffel", (Q,)),
    ):
        batch = getattr(reduced, method)(*args)
        one = np.array([getattr(reduced, method)(*(a[k] for a in args)) for k in range(len(Q))])
        np.testing.assert_allclose(batch, one, atol=1e-12, err_msg=method)
    out = np.empty((6, reduced.n, reduced.n))
    assert reduced.mass_matrix(Q, out=out) is out and np.array_equal(out, reduced.mass_matrix(Q))
    out = np.empty(reduced.n)
    assert reduced.inverse_dynamics(Q[0], QD[0], QDD[0], out=out) is out
    with pytest.raises(ValueError, match=r"q must have shape \(3,\) or a batch \(N, 3\), got \(5,\)"):
        reduced.mass_matrix(np.zeros(5))
    with pytest.raises(ValueError, match=r"qd contains a non-finite value"):
        reduced.inverse_dynamics(Q[0], [np.nan, 0, 0], QDD[0])
    with pytest.raises(ValueError, match=r"out must have shape \(3, 3\), got \(2, 2\)"):
        reduced.mass_matrix(Q[0], out=np.empty((2, 2)))


# ------------------------------------------------------------------ identities on the reduced robot
def test_identities_of_the_reduced_robot(pair):
    reduced = pair[0]
    worst = kd.testing.check_identities(reduced, states=4)
    bad = {k: v for k, v in worst.items() if v > (1e-6 if "finite" in k else 1e-10)}
    assert not bad, bad
    # dM/dt - 2C skew (Christoffel property kept) and the derivatives by central differences
    h = 1e-6
    for q, qd, qdd in states(reduced, 3):
        C = reduced.coriolis_matrix(q, qd)
        Mdot = (reduced.mass_matrix(q + h * qd) - reduced.mass_matrix(q - h * qd)) / (2 * h)
        np.testing.assert_allclose(Mdot, C + C.T, atol=1e-7)
        S = Mdot - 2 * C
        np.testing.assert_allclose(S, -S.T, atol=1e-7)
        dq, dqd, M = reduced.inverse_dynamics_derivatives(q, qd, qdd)
        tau = reduced.inverse_dynamics(q, qd, qdd)
        fd_q = np.column_stack(
            [
                (reduced.inverse_dynamics(q + h * e, qd, qdd) - reduced.inverse_dynamics(q - h * e, qd, qdd)) / (2 * h)
                for e in np.eye(reduced.n)
            ]
        )
        fd_qd = np.column_stack(
            [
                (reduced.inverse_dynamics(q, qd + h * e, qdd) - reduced.inverse_dynamics(q, qd - h * e, qdd)) / (2 * h)
                for e in np.eye(reduced.n)
            ]
        )
        np.testing.assert_allclose(dq, fd_q, atol=1e-6)
        np.testing.assert_allclose(dqd, fd_qd, atol=1e-6)
        np.testing.assert_allclose(M, reduced.mass_matrix(q), atol=1e-12)
        fq, fqd, Minv = reduced.forward_dynamics_derivatives(q, qd, tau)
        fd = np.column_stack(
            [
                (reduced.forward_dynamics(q + h * e, qd, tau) - reduced.forward_dynamics(q - h * e, qd, tau)) / (2 * h)
                for e in np.eye(reduced.n)
            ]
        )
        np.testing.assert_allclose(fq, fd, atol=1e-6)
        fd = np.column_stack(
            [
                (reduced.forward_dynamics(q, qd + h * e, tau) - reduced.forward_dynamics(q, qd - h * e, tau)) / (2 * h)
                for e in np.eye(reduced.n)
            ]
        )
        np.testing.assert_allclose(fqd, fd, atol=1e-6)
        np.testing.assert_allclose(Minv, np.linalg.inv(M), atol=1e-9)


# ------------------------------------------------------------------ Pinocchio's mimic models
pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is an optional test oracle")


def _pin_q(model, robot, q):
    """Pinocchio's q (continuous joints as (cos, sin)) from kinedyn's reduced q, by joint name."""
    out = pin.neutral(model)
    for name, value in zip(robot.joint_names, q):
        jm = model.joints[model.getJointId(name)]
        if jm.nq == 2:
            out[jm.idx_q : jm.idx_q + 2] = np.cos(value), np.sin(value)
        else:
            out[jm.idx_q] = value
    return out


def _pin_v_index(model, robot):
    return np.array([model.joints[model.getJointId(name)].idx_v for name in robot.joint_names])


def compare_with_pinocchio(path_or_xml, states_count=3, frames=None):
    robot = kd.Robot.from_urdf(path_or_xml)
    model = (
        pin.buildModelFromXML(path_or_xml, mimic=True)
        if path_or_xml.lstrip().startswith("<")
        else pin.buildModelFromUrdf(path_or_xml, mimic=True)
    )
    data = model.createData()
    assert model.nv == robot.n
    iv = _pin_v_index(model, robot)
    P = np.zeros((robot.n, robot.n))
    P[np.arange(robot.n), iv] = 1.0  # kinedyn's order <- Pinocchio's
    rng = np.random.default_rng(11)
    frames = frames or robot.frame_names[1:]
    for _ in range(states_count):
        q = robot.random_configuration(rng)
        qd, qdd = rng.uniform(-1, 1, robot.n), rng.uniform(-2, 2, robot.n)
        pq, pv, pa = _pin_q(model, robot, q), P.T @ qd, P.T @ qdd
        friction = robot.friction_torque(qd)
        tau = P @ pin.rnea(model, data, pq, pv, pa)
        np.testing.assert_allclose(robot.inverse_dynamics(q, qd, qdd) - friction, tau, atol=1e-9, rtol=1e-9)
        M = pin.crba(model, data, pq)
        M = P @ (np.triu(M) + np.triu(M, 1).T) @ P.T
        np.testing.assert_allclose(robot.mass_matrix(q), M, atol=1e-9, rtol=1e-9)
        np.testing.assert_allclose(
            robot.gravity_torque(q), P @ pin.computeGeneralizedGravity(model, data, pq), atol=1e-9, rtol=1e-9
        )
        # Pinocchio's ABA has no mimic joints: its qdd is M^-1 (tau - nle)
        u = rng.uniform(-1, 1, robot.n)
        qdd_pin = np.linalg.solve(M, u - P @ pin.nonLinearEffects(model, data, pq, pv))
        np.testing.assert_allclose(robot.forward_dynamics(q, qd, u + friction), qdd_pin, atol=1e-9, rtol=1e-9)
        pin.computeJointJacobians(model, data, pq)
        pin.updateFramePlacements(model, data)
        for name in frames:
            fid = model.getFrameId(name)
            np.testing.assert_allclose(robot.pose(q, name), data.oMf[fid].homogeneous, atol=1e-9, err_msg=name)
            J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED) @ P.T
            np.testing.assert_allclose(robot.jacobian(q, name), J, atol=1e-9, err_msg=name)
    return robot


def test_gripper_agrees_with_pinocchios_mimic_model():
    compare_with_pinocchio(gripper_urdf())


ERD_MIMIC = [
    "panda_description/urdf/panda.urdf",
    "baxter_description/urdf/baxter.urdf",
    "pr2_description/urdf/pr2.urdf",
    "tiago_pro_description/robots/tiago_pro.urdf",
]


def erd_path(rel):
    from kinedyn.testing import example_robot_data_dir

    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    return os.path.join(root, rel)


@pytest.mark.filterwarnings("ignore::kinedyn.description.inertia.PhysicalConsistencyWarning")
@pytest.mark.parametrize("rel", ERD_MIMIC)
def test_example_robot_data_mimic_urdfs_agree_with_pinocchio(rel):
    path = erd_path(rel)
    robot = kd.Robot.from_urdf(path, inertia="warn")
    assert robot.mimic_joints, "the file has <mimic> joints"
    compare_with_pinocchio(path, states_count=2, frames=[robot.tool] + robot.body_names[-3:])


@pytest.mark.filterwarnings("ignore::kinedyn.description.inertia.PhysicalConsistencyWarning")
@pytest.mark.parametrize("rel", ["talos_data/robots/talos_full_v2.urdf", "romeo_description/urdf/romeo.urdf"])
def test_urdfs_pinocchio_cannot_reduce_agree_with_the_hand_reduced_model(rel):
    """Pinocchio 4.1 refuses these ("the parent joint of the mimic joint is not in the kinematic
    tree": the leader comes later in its depth-first order); kinedyn reduces them."""
    path = erd_path(rel)
    reduced, full = kd.Robot.from_urdf(path), kd.Robot.from_urdf(path, mimic="independent")
    G, b = hand_G(path, full, reduced)
    assert reduced.n < full.n
    rng = np.random.default_rng(2)
    for _ in range(2):
        q = reduced.random_configuration(rng)
        qd, qdd = rng.uniform(-1, 1, reduced.n), rng.uniform(-1, 1, reduced.n)
        qf = G @ q + b
        np.testing.assert_allclose(reduced.mass_matrix(q), G.T @ full.mass_matrix(qf) @ G, atol=1e-9)
        np.testing.assert_allclose(
            reduced.inverse_dynamics(q, qd, qdd), G.T @ full.inverse_dynamics(qf, G @ qd, G @ qdd), atol=1e-9
        )
        for frame in reduced.body_names[-2:]:
            np.testing.assert_allclose(reduced.jacobian(q, frame), full.jacobian(qf, frame) @ G, atol=1e-9)


# ------------------------------------------------------------------ what the rest of kinedyn does with them
def test_lock_joints_locks_the_followers_with_their_leader():
    robot = kd.Robot.from_urdf(gripper_urdf())
    locked = robot.lock_joints({"left_finger": 0.015})
    assert locked.joint_names == ["shoulder", "wrist"] and locked.mimic_joints == {
        "knuckle_joint": Mimic("wrist", 0.5, 0.2)
    }
    q = np.array([0.3, -0.4])
    np.testing.assert_allclose(locked.frame_poses(q), robot.frame_poses(np.r_[q, 0.015]), atol=1e-14)
    np.testing.assert_allclose(locked.mass_matrix(q), robot.mass_matrix(np.r_[q, 0.015])[:2, :2], atol=1e-12)
    both = robot.lock_joints({"left_finger": 0.015, "right_finger": -0.005})  # as given
    np.testing.assert_allclose(both.frame_poses(q), robot.frame_poses(np.r_[q, 0.015]), atol=1e-14)
    with pytest.raises(
        ValueError, match=r"joint 'right_finger' follows joint 'left_finger' \(mimic\); lock 'left_finger' too"
    ):
        robot.lock_joints({"right_finger": 0.01})
    assert robot.lock_joints(["wrist"], at=[0.1, 0.2, 0.3]).joint_names == ["shoulder", "left_finger"]


def test_simulation_runs_on_the_reduced_dynamics():
    robot = kd.Robot.from_urdf(gripper_urdf())
    no_friction = robot.replace(
        links=[
            l
            if l.joint.kind == "fixed"
            else l.__class__(
                l.name,
                l.parent,
                Joint(l.joint.name, l.joint.kind, l.joint.axis, mimic=l.joint.mimic),
                l.placement,
                l.post,
                l.inertia,
            )
            for l in robot.links
        ]
    )
    x0 = np.r_[0.2, -0.3, 0.01, 0.5, -0.2, 0.1]
    traj = kd.simulate(no_friction, 0.5, x0, method="rk4", dt=1e-3)
    assert traj.q.shape[-1] == 3
    energy = [no_friction.kinetic_energy(q, qd) + no_friction.potential_energy(q) for q, qd in zip(traj.q, traj.qd)]
    assert np.ptp(energy) < 1e-6 * max(1.0, abs(energy[0]))
    np.testing.assert_allclose(traj.qdd[5], no_friction.forward_dynamics(traj.q[5], traj.qd[5], np.zeros(3)), atol=1e-9)


def test_symbolic_engine_takes_reduced_mimic_joints():
    robot = kd.Robot.from_urdf(gripper_urdf())
    # the symbolic engine handles them (tests/test_symbolic_mimic.py): in the reduced coordinates
    assert robot.equations_of_motion(simplify=False).M.shape == (3, 3)
    # (inverse kinematics solves in the reduced coordinates: tests/test_ik_manifold.py)
    # with the followers kept independent, both run
    full = kd.Robot.from_urdf(gripper_urdf(), mimic="independent")
    assert full.equations_of_motion(simplify=False).M.shape == (5, 5)


def test_report_on_a_mimic_robot(tmp_path):
    from kinedyn.report.html import collect

    robot = kd.Robot.from_urdf(gripper_urdf())
    data = collect(robot, name="gripper", t_end=0.2)
    assert data.eom is not None and data.eom.n == 3  # the symbolic engine reduces the follower too


def test_the_reports_viewer_moves_the_followers(browser, tmp_path):
    """viewer.js runs the forward kinematics itself: each follower at multiplier * q[leader] + offset,
    one slider per reduced coordinate."""
    from kinedyn.cli import main

    urdf = tmp_path / "gripper.urdf"
    urdf.write_text(gripper_urdf(chain=True))
    path = tmp_path / "gripper.html"
    assert main(["report", str(urdf), "-o", str(path), "--t", "0.2"]) == 0
    page = browser.new_page()
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(path.resolve().as_uri())
    page.wait_for_function("window.kinedyn && window.kinedyn.ready()", timeout=60000)
    robot = kd.Robot.from_urdf(str(urdf))
    for q in ([0.1, 0.2, 0.01], [-1.0, 0.7, 0.03]):
        for frame in ("right", "tip", "knuckle", "left"):
            T = np.array(page.evaluate(f"(q) => window.kinedyn.fk(q).frames['{frame}']", q)).reshape(4, 4)
            np.testing.assert_allclose(T, robot.pose(q, frame), atol=1e-12, err_msg=frame)
    assert page.locator("#kinedyn-sliders input").count() == 3
    assert errors == []
    page.close()


def test_robot_files_read_and_write_mimic(tmp_path):
    robot = kd.Robot.from_urdf(gripper_urdf(chain=True))
    for ext in ("yaml", "toml"):
        path = tmp_path / f"gripper.{ext}"
        robot.save(path)
        again = kd.load(path)
        assert again.joint_names == robot.joint_names and again.mimic_joints == robot.mimic_joints
        q = np.array([0.3, -0.2, 0.01])
        np.testing.assert_allclose(again.mass_matrix(q), robot.mass_matrix(q), atol=1e-12)
        assert kd.load(path, mimic="independent").n == 6
    text = (tmp_path / "gripper.yaml").read_text().replace("multiplier: -1.0", "multiplier: 0")
    (tmp_path / "bad.yaml").write_text(text)
    with pytest.raises(
        ValueError,
        match=r"bad.yaml, line \d+: links row 4 \('right'\).joint.mimic: mimic of joint 'left_finger': multiplier must be non-zero",
    ):
        kd.load(tmp_path / "bad.yaml")


def test_ik_of_a_frame_no_follower_moves():
    """Solved on the robot with independent joints, the followers' coordinates dropped."""
    robot = kd.Robot.from_urdf(gripper_urdf())
    q_goal = np.array([0.4, -0.3, 0.02])
    target = robot.pose(q_goal, "left")
    result = robot.inverse_kinematics(target, q0=[0.3, -0.2, 0.01], frame="left")
    assert result.success and result.q.shape == (3,)
    np.testing.assert_allclose(robot.pose(result.q, "left"), target, atol=1e-8)
    batch = robot.inverse_kinematics(
        np.stack([target, robot.pose(np.zeros(3), "left")]), q0=np.zeros((2, 3)), frame="left"
    )
    assert batch.q.shape == (2, 3) and batch.success.all()
    with pytest.raises(ValueError, match=r"q0 must have shape \(3,\) or a batch \(N, 3\), got \(5,\)"):
        robot.inverse_kinematics(target, q0=np.zeros(5), frame="left")
    panda = kd.Robot.from_urdf(erd_path(ERD_MIMIC[0]))
    q = np.array([0.3, -0.5, 0.2, -2.0, 0.1, 1.8, 0.4, 0.02])
    result = panda.inverse_kinematics(panda.pose(q), q0=np.r_[q[:7] + 0.1, 0.01])
    assert result.success and result.q.shape == (8,)
    np.testing.assert_allclose(panda.pose(result.q), panda.pose(q), atol=1e-6)
    assert result.q[7] == 0.01  # the finger does not move the tool


def test_an_unmapped_native_method_is_refused_by_name():
    model = kd.Robot.from_urdf(gripper_urdf())._model
    with pytest.raises((NotImplementedError, AttributeError), match=r"'no_such_method'"):
        model.no_such_method
    for name in [m for m in dir(model.native) if not m.startswith("_") and callable(getattr(model.native, m))]:
        mapped = any(name in cls.__dict__ for cls in type(model).__mro__ if cls is not object)  # its loops' mixin too
        assert mapped or name in model.refused, f"ReducedModel does not map the core's {name}"
    for name in model.refused:
        with pytest.raises(NotImplementedError, match=name):
            getattr(model, name)
