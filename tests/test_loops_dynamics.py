"""The numbers of closed loops (kinedyn.closed_loops, the core's constraints/): self-checks
(J against finite differences, J qdd + gamma = 0, inverse then forward dynamics) and Pinocchio's
constraintDynamics as the oracle, on mechanisms read from the same URDF by both."""

from __future__ import annotations

import numpy as np
import pytest

import kinedyn as kd

pin = pytest.importorskip("pinocchio")


def _link(name, mass, com, inertia=(0.01, 0.02, 0.015)):
    ixx, iyy, izz = inertia
    return (
        f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0.001" ixz="0" iyz="0.002"/></inertial></link>'
    )


def _joint(name, parent, child, xyz, axis, kind="revolute"):
    limit = '<limit lower="-10" upper="10" effort="10" velocity="10"/>' if kind == "revolute" else ""
    axis_xml = f'<axis xyz="{axis}"/>' if kind == "revolute" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/>{axis_xml}{limit}</joint>'
    )


def _urdf(parts) -> str:
    return '<robot name="mech"><link name="base"/>' + "".join(parts) + "</robot>"


def four_bar() -> str:
    """A planar four-bar in the x-z plane (axes along y, gravity in the plane): crank a1 and coupler
    a2 from the base, rocker b1 from (0.6, 0, 0); tip_a (coupler end) meets tip_b (rocker end)."""
    return _urdf(
        [
            _link("crank", 1.0, "0.1 0 0"),
            _link("coupler", 0.8, "0.3 0 0.01"),
            _link("rocker", 1.2, "0.2 0.01 0"),
            _link("tip_a", 0.0, "0 0 0"),
            _link("tip_b", 0.0, "0 0 0"),
            _joint("a1", "base", "crank", "0 0 0", "0 1 0"),
            _joint("a2", "crank", "coupler", "0.2 0 0", "0 1 0"),
            _joint("b1", "base", "rocker", "0.6 0 0", "0 1 0"),
            _joint("ta", "coupler", "tip_a", "0.7 0 0", "", kind="fixed"),
            _joint("tb", "rocker", "tip_b", "0.5 0 0", "", kind="fixed"),
        ]
    )


def spatial_loop() -> str:
    """Two chains of three revolute joints with skew axes, their ends pinned together (a spatial
    point loop, 3 DOF): no row is redundant."""
    return _urdf(
        [
            _link("l1", 1.0, "0.1 0 0.05"),
            _link("l2", 0.9, "0.15 0.02 0"),
            _link("l3", 0.7, "0.1 0 0"),
            _link("r1", 1.1, "0 0.1 0.05"),
            _link("r2", 0.6, "0.1 0.1 0"),
            _link("r3", 0.5, "0.05 0 0.1"),
            _link("tip_a", 0.0, "0 0 0"),
            _link("tip_b", 0.0, "0 0 0"),
            _joint("j1", "base", "l1", "0 0 0", "0 0 1"),
            _joint("j2", "l1", "l2", "0.3 0 0.1", "0 1 0"),
            _joint("j3", "l2", "l3", "0.3 0 0", "1 0 1"),
            _joint("k1", "base", "r1", "0.5 0.3 0", "0 0 1"),
            _joint("k2", "r1", "r2", "0 0.3 0.1", "1 0 0"),
            _joint("k3", "r2", "r3", "0 0.3 0", "0 1 1"),
            _joint("ta", "l3", "tip_a", "0.25 0 0", "", kind="fixed"),
            _joint("tb", "r3", "tip_b", "0 0.2 0", "", kind="fixed"),
        ]
    )


def planar_slider() -> str:
    """A planar joint (x, y, heading) carrying an arm whose tip is pinned to a rocker on the base
    (joint and link names in the order both readers lay the tree out)."""
    return _urdf(
        [
            _link("a_sled", 1.5, "0.05 0.02 0"),
            _link("arm", 0.8, "0.2 0 0"),
            _link("b_rocker", 1.0, "0.2 0.01 0"),
            _link("tip_a", 0.0, "0 0 0"),
            _link("tip_b", 0.0, "0 0 0"),
            '<joint name="a0" type="planar"><parent link="base"/><child link="a_sled"/><axis xyz="0 0 1"/></joint>',
            _joint("a", "a_sled", "arm", "0.1 0 0", "0 0 1"),
            _joint("b", "base", "b_rocker", "0.8 0.2 0", "0 0 1"),
            _joint("ta", "arm", "tip_a", "0.5 0 0", "", kind="fixed"),
            _joint("tb", "b_rocker", "tip_b", "0.4 0 0", "", kind="fixed"),
        ]
    )


def closed_state(robot, hold, seed):
    """A closed configuration near a random one (the ``hold`` joints kept) and a velocity and an
    acceleration-free torque that keep it closed."""
    rng = np.random.default_rng(seed)
    q = robot.project_configuration(robot.integrate(robot.neutral(), rng.uniform(-0.6, 0.6, robot.n)), hold=hold)
    qd = robot.project_velocity(q, rng.uniform(-1, 1, robot.n))
    tau = rng.uniform(-2, 2, robot.n)
    return q, qd, tau


def pinocchio_qdd(urdf, q, qd, tau, loops=(("point", "tip_a", "tip_b"),), floating=False):
    """Pinocchio's constraintDynamics on the same URDF and loops: qdd, and the loops' forces on
    frame a's link in base axes (Pinocchio gives them in frame a's axes, LOCAL)."""
    model = pin.buildModelFromXML(urdf, pin.JointModelFreeFlyer()) if floating else pin.buildModelFromXML(urdf)
    data = model.createData()
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    kinds = {"point": pin.ContactType.CONTACT_3D, "weld": pin.ContactType.CONTACT_6D}
    frames = []
    for kind, a, b in loops:
        frame_a, frame_b = model.frames[model.getFrameId(a)], model.frames[model.getFrameId(b)]
        constraint = pin.RigidConstraintModel(
            kinds[kind],
            model,
            frame_a.parentJoint,
            frame_a.placement,
            frame_b.parentJoint,
            frame_b.placement,
            pin.ReferenceFrame.LOCAL,
        )
        models.append(constraint)
        datas.append(constraint.createData())
        frames.append((kind, frame_a))
    pin.initConstraintDynamics(model, data, models, datas)
    settings = pin.ProximalSettings(1e-14, 1e-10, 100)
    qdd = pin.constraintDynamics(model, data, q, qd, tau, models, datas, settings)
    pin.framesForwardKinematics(model, data, q)
    forces, at = [], 0
    for kind, frame in frames:
        rot = (data.oMi[frame.parentJoint] * frame.placement).rotation
        rows = 3 if kind == "point" else 6
        lam = data.lambda_c[at : at + rows]
        forces.extend(rot @ lam[:3])
        if rows == 6:
            forces.extend(rot @ lam[3:])
        at += rows
    return qdd.copy(), np.array(forces)


@pytest.mark.parametrize(("make", "hold"), [(four_bar, ["a1"]), (spatial_loop, ["j1"]), (planar_slider, [])])
def test_constrained_forward_dynamics_matches_pinocchio(make, hold):
    urdf = make()
    robot = kd.Robot.from_urdf(urdf).add_loop("tip_a", "tip_b", kind="point")
    for seed in range(3):
        q, qd, tau = closed_state(robot, hold, seed)
        assert np.abs(robot.loop_residual(q)).max() < 1e-12
        qdd, lam = robot.constrained_forward_dynamics(q, qd, tau)
        qdd_pin, lam_pin = pinocchio_qdd(urdf, q, qd, tau)
        assert np.allclose(qdd, qdd_pin, rtol=0, atol=1e-9), (qdd, qdd_pin)
        # J^T lambda (the joint torques of the loop force) is unique even where lambda is not
        jac = robot.loop_jacobian(q)
        assert np.allclose(jac.T @ lam, jac.T @ lam_pin, atol=1e-8)
        if make is spatial_loop:  # no redundant row: lambda itself is unique
            assert np.allclose(lam, lam_pin, atol=1e-8)


def test_a_floating_base_with_a_weld_to_the_ground_matches_pinocchio():
    """The spatial mechanism on a free-flyer, its chain A welded to the ground (6 rows) and pinned to
    chain B (3 rows): 12 velocities, 9 rows."""
    urdf = spatial_loop()
    robot = (
        kd.Robot.from_urdf(urdf, floating_base=True)
        .add_loop("tip_a", "universe", kind="weld")
        .add_loop("tip_a", "tip_b", kind="point")
    )
    for seed in range(3):
        q, qd, tau = closed_state(robot, [], seed)
        assert np.abs(robot.loop_residual(q)).max() < 1e-12
        qdd, lam = robot.constrained_forward_dynamics(q, qd, tau)
        loops = (("weld", "tip_a", "universe"), ("point", "tip_a", "tip_b"))
        qdd_pin, lam_pin = pinocchio_qdd(urdf, q, qd, tau, loops, floating=True)
        assert np.allclose(qdd, qdd_pin, rtol=0, atol=1e-9), (qdd, qdd_pin)
        jac = robot.loop_jacobian(q)
        assert np.allclose(jac.T @ lam, jac.T @ lam_pin, atol=1e-8)


def test_the_four_bar_out_of_plane_row_is_zero_and_gets_no_force():
    robot = kd.Robot.from_urdf(four_bar()).add_loop("tip_a", "tip_b")
    q, qd, tau = closed_state(robot, ["a1"], 4)
    jac = robot.loop_jacobian(q)
    assert np.abs(jac[1]).max() == 0.0  # the y row: every axis is along y
    qdd, lam = robot.constrained_forward_dynamics(q, qd, tau)
    assert abs(lam[1]) < 1e-9  # least-norm multipliers
    assert np.abs(jac @ qdd + robot.loop_gamma(q, qd)).max() < 1e-10


def test_jacobian_is_the_derivative_of_the_residual_and_gamma_of_j_qd():
    robot = kd.Robot.from_urdf(spatial_loop()).add_loop("tip_a", "tip_b")
    rng = np.random.default_rng(1)
    q, qd = rng.uniform(-1, 1, robot.n), rng.uniform(-1, 1, robot.n)
    h = 1e-6
    fd = np.column_stack(
        [(robot.loop_residual(q + h * e) - robot.loop_residual(q - h * e)) / (2 * h) for e in np.eye(robot.n)]
    )
    assert np.allclose(robot.loop_jacobian(q), fd, atol=1e-8)
    jdot_qd = (robot.loop_jacobian(q + h * qd) @ qd - robot.loop_jacobian(q - h * qd) @ qd) / (2 * h)
    assert np.allclose(robot.loop_gamma(q, qd), jdot_qd, atol=1e-7)


def test_a_batch_gives_the_single_calls():
    robot = kd.Robot.from_urdf(spatial_loop()).add_loop("tip_a", "tip_b")
    states = [closed_state(robot, ["j1"], s) for s in range(9)]
    q, qd, tau = (np.array(x) for x in zip(*states))
    qdd, lam = robot.constrained_forward_dynamics(q, qd, tau)
    assert qdd.shape == (9, robot.n) and lam.shape == (9, 3)
    for k in range(9):
        one = robot.constrained_forward_dynamics(q[k], qd[k], tau[k])
        assert np.allclose(qdd[k], one[0], atol=1e-10) and np.allclose(lam[k], one[1], atol=1e-9)


def test_inverse_then_forward_gives_the_motion_back():
    robot = kd.Robot.from_urdf(four_bar()).add_loop("tip_a", "tip_b")
    q, qd, tau = closed_state(robot, ["a1"], 2)
    qdd, _ = robot.constrained_forward_dynamics(q, qd, tau)
    tau_a = robot.constrained_inverse_dynamics(q, qd, qdd, actuated=["a1"])
    assert tau_a[1] == 0.0 and tau_a[2] == 0.0
    again, _ = robot.constrained_forward_dynamics(q, qd, tau_a)
    assert np.allclose(again, qdd, atol=1e-9)


def test_inverse_dynamics_names_what_is_wrong():
    robot = kd.Robot.from_urdf(four_bar()).add_loop("tip_a", "tip_b", name="pin")
    q, qd, _ = closed_state(robot, ["a1"], 3)
    with pytest.raises(ValueError, match="does not keep loop 'pin' closed"):
        robot.constrained_inverse_dynamics(q, qd, np.ones(3), actuated=["a1"])
    with pytest.raises(ValueError, match="unknown joint 'a9'"):
        robot.constrained_inverse_dynamics(q, qd, np.zeros(3), actuated=["a9"])
    qdd, _ = robot.constrained_forward_dynamics(q, qd, np.zeros(3))
    with pytest.raises(ValueError, match="do not determine their torques"):
        robot.constrained_inverse_dynamics(q, qd, qdd, actuated=["a1", "a2", "b1"])


def test_forward_kinematics_of_the_parallel_mechanism_from_its_actuated_joint():
    robot = kd.Robot.from_urdf(four_bar()).add_loop("tip_a", "tip_b")
    start = np.array([0.3, -0.2, 0.4])
    q = robot.project_configuration(start, hold=["a1"])
    assert q[0] == start[0]
    assert np.abs(robot.loop_residual(q)).max() < 1e-12
    tips = robot.pose(q, frame="tip_a")[:3, 3], robot.pose(q, frame="tip_b")[:3, 3]
    assert np.allclose(*tips, atol=1e-12)
    qd = robot.project_velocity(q, np.array([1.0, 0.0, 0.0]))
    assert np.abs(robot.loop_jacobian(q) @ qd).max() < 1e-12
    with pytest.raises(ValueError, match="do not close"):
        robot.project_configuration(np.array([3.0, 0.0, 0.0]), hold=["a1", "a2"])


def test_reduced_mimic_joints_compose_with_the_loops():
    """The coupler a2 following the crank a1 (a2 = a1): the loop's Jacobian in the reduced coordinates
    is the full one times the mimic map (tests/test_loops_mimic.py has the dynamics), and with the crank
    held the rocker alone cannot close the loop: refused by name."""
    urdf = four_bar().replace(
        '<axis xyz="0 1 0"/><limit lower="-10" upper="10" effort="10" velocity="10"/></joint><joint name="b1"',
        '<axis xyz="0 1 0"/><limit lower="-10" upper="10" effort="10" velocity="10"/><mimic joint="a1"/></joint>'
        '<joint name="b1"',
    )
    robot = kd.Robot.from_urdf(urdf).add_loop("tip_a", "tip_b")
    assert robot.mimic_joints and robot.n == 2
    independent = kd.Robot.from_urdf(urdf, mimic="independent").add_loop("tip_a", "tip_b")
    q = np.array([0.3, 0.4])
    full = independent.loop_jacobian(np.array([0.3, 0.3, 0.4]))
    assert np.allclose(robot.loop_jacobian(q), np.c_[full[:, 0] + full[:, 1], full[:, 2]], atol=1e-14)
    assert np.allclose(robot.loop_residual(q), independent.loop_residual(np.array([0.3, 0.3, 0.4])), atol=1e-15)
    with pytest.raises(ValueError, match="loops do not close.*held joints"):
        robot.project_configuration(q, hold=["a1"])
    q = independent.project_configuration(np.array([0.3, -0.2, 0.4]), hold=["a1"])
    assert np.abs(independent.loop_residual(q)).max() < 1e-12


def test_an_external_wrench_acts_as_its_joint_torques():
    robot = kd.Robot.from_urdf(spatial_loop()).add_loop("tip_a", "tip_b")
    q, qd, tau = closed_state(robot, ["j1"], 6)
    f_ext = np.zeros((len(robot.body_names), 6))
    link = robot.body_names.index("l2")
    f_ext[link] = [1.0, -2.0, 0.5, 0.3, 0.1, -0.2]
    jac = robot.jacobian(q, frame="l2", reference="world")
    with_wrench, lam = robot.constrained_forward_dynamics(q, qd, tau, f_ext=f_ext)
    as_torque, lam_torque = robot.constrained_forward_dynamics(q, qd, tau + jac.T @ f_ext[link])
    assert np.allclose(with_wrench, as_torque, atol=1e-10) and np.allclose(lam, lam_torque, atol=1e-9)
    assert not np.allclose(with_wrench, robot.constrained_forward_dynamics(q, qd, tau)[0])


@pytest.mark.parametrize(("make", "independent"), [(four_bar, None), (four_bar, ["a1"]), (spatial_loop, None)])
def test_reduced_dynamics_gives_the_constrained_motion(make, independent):
    robot = kd.Robot.from_urdf(make()).add_loop("tip_a", "tip_b")
    q, _, tau = closed_state(robot, [robot.joint_names[0]], 7)
    k = robot.n - np.linalg.matrix_rank(robot.loop_jacobian(q))
    reduced = robot.reduced_dynamics(q, np.linspace(-0.7, 0.9, k), independent=independent)
    qd = reduced["qd"]
    assert np.abs(robot.loop_jacobian(q) @ qd).max() < 1e-12
    qdd_i = np.linalg.solve(reduced["M"], reduced["G"].T @ tau - reduced["bias"] - reduced["g"])
    qdd, _ = robot.constrained_forward_dynamics(q, qd, tau)
    assert np.allclose(reduced["G"] @ qdd_i + reduced["a0"], qdd, atol=1e-9)
    if independent:
        assert reduced["independent"] == [robot.joint_names.index(independent[0])]


def test_reduced_dynamics_refuses_coordinates_that_are_not_independent():
    robot = kd.Robot.from_urdf(spatial_loop()).add_loop("tip_a", "tip_b")
    q, _, _ = closed_state(robot, ["j1"], 8)
    with pytest.raises(ValueError, match="not independent coordinates"):
        robot.reduced_dynamics(q, np.zeros(2), independent=["j1", "j2"])


def test_a_robot_with_loops_pickles_with_them():
    import pickle

    robot = kd.Robot.from_urdf(four_bar()).add_loop("tip_a", "tip_b")
    q, qd, tau = closed_state(robot, ["a1"], 9)
    again = pickle.loads(pickle.dumps(robot))
    assert np.array_equal(
        again.constrained_forward_dynamics(q, qd, tau)[0], robot.constrained_forward_dynamics(q, qd, tau)[0]
    )
    assert again.loop_jacobian(q).shape == (3, 3)


def test_projections_and_inverse_dynamics_take_a_batch():
    robot = kd.Robot.from_urdf(four_bar()).add_loop("tip_a", "tip_b")
    starts = np.array([[0.3, -0.2, 0.4], [0.5, -0.4, 0.6], [0.1, 0.0, 0.3]])
    q = robot.project_configuration(starts, hold=["a1"])
    assert q.shape == (3, 3) and np.array_equal(q[:, 0], starts[:, 0])
    assert np.abs(robot.loop_residual(q)).max() < 1e-12
    qd = robot.project_velocity(q, np.ones((3, 3)))
    qdd, _ = robot.constrained_forward_dynamics(q, qd, np.zeros((3, 3)))
    tau = robot.constrained_inverse_dynamics(q, qd, qdd, actuated=["a1"])
    assert tau.shape == (3, 3)
    for k in range(3):
        assert np.allclose(tau[k], robot.constrained_inverse_dynamics(q[k], qd[k], qdd[k], actuated=["a1"]))
        assert np.allclose(robot.project_configuration(starts[k], hold=["a1"]), q[k])
