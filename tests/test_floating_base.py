"""Floating bases and multi-DOF joints (free-flyer, spherical, planar) against Pinocchio as the oracle:
every URDF of example-robot-data, fixed and floating, and random trees of every joint kind built joint
by joint in both libraries. Conventions (docs/conventions.md): q of size nq (a free-flyer's position,
then its unit quaternion (x, y, z, w)), v of size nv ([linear; angular] in the child's own frame).
"""

from __future__ import annotations

import glob
import os
import warnings
import zlib

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.testing import example_robot_data_dir, random_robot

pin = pytest.importorskip("pinocchio", reason="Pinocchio (the `pin` package, test extra 'peers') is not installed")
pytest.importorskip("kinedyn._core", reason="the native module is not built")

from pinocchio_pairs import PinPair, pinocchio_model  # noqa: E402

TOL = 1e-9


def _urdf_files() -> list:
    root = example_robot_data_dir()
    if root is None:
        return []
    return sorted(os.path.relpath(p, root) for p in glob.glob(os.path.join(root, "**", "*.urdf"), recursive=True))


URDFS = _urdf_files()
# example-robot-data's ur3.urdf is an empty <robot> (a placeholder its xacro overwrites): nothing to load
EMPTY = {os.path.join("ur_description", "urdf", "ur3.urdf")}


def _close(what, got, expected, scale=1.0):
    err = float(np.abs(np.asarray(got) - np.asarray(expected)).max(initial=0.0))
    assert err <= TOL * max(1.0, scale), f"{what}: max difference {err:.3e}"


def compare(pair: PinPair, rng, states: int = 2, frames: int = 3, derivatives: bool = False):
    """Every quantity of ``pair.robot`` against Pinocchio at ``states`` random states."""
    robot, model, data, P = pair.robot, pair.model, pair.data, pair.perm
    B = np.ix_(P, P)
    # frames compared: Pinocchio's BODY frames (URDF links) that kinedyn has, or, for a model built
    # joint by joint (no frames), the joints' own frames, which are kinedyn's link frames there
    links = set(robot.frame_names)
    bodies = [f.name for f in model.frames if f.type == pin.BODY and f.name in links]
    if bodies:
        chosen = list(rng.choice(bodies, size=min(frames, len(bodies)), replace=False))
        picked = [
            (name, model.getFrameId(name, pin.BODY), True)
            for name in dict.fromkeys([robot.tool, *chosen])
            if name in bodies
        ]
    else:
        picked = [
            (robot.body_names[robot.joint_names.index(model.names[j])], j, False) for j in range(1, model.njoints)
        ]
    for _ in range(states):
        q, v, a = pair.random_state(rng)
        qp, vp, ap = pair.to_pin_q(q), v[P], a[P]
        friction = robot.friction_torque(v)
        M = pin.crba(model, data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        scale = float(np.abs(M).max())
        _close("M", robot.mass_matrix(q)[B], M, scale)
        tau = pin.rnea(model, data, qp, vp, ap)
        _close("tau", (robot.inverse_dynamics(q, v, a) - friction)[P], tau, float(np.abs(tau).max()))
        _close("g", robot.gravity_torque(q)[P], pin.computeGeneralizedGravity(model, data, qp), scale)
        _close("C", robot.coriolis_matrix(q, v)[B], pin.computeCoriolisMatrix(model, data, qp, vp), scale)
        # qdd: an ill-conditioned M (fingers of a few grams beside a 50 kg trunk) magnifies rounding in
        # either library, so the two accelerations are compared through M: both solve M qdd = tau - b,
        # each to a backward error of order eps (|M| |qdd| + |tau|) (Higham, Accuracy and Stability of
        # Numerical Algorithms, 2nd ed., §7.1), hence the scale
        try:
            qdd = robot.forward_dynamics(q, v, a + friction)[P]
        except RuntimeError as e:  # kinedyn refuses a numerically singular M; so must the condition say
            assert "singular mass matrix" in str(e) and np.linalg.cond(M) > 1e12, e
        else:
            residual_scale = max(float(np.abs(tau).max()), scale * float(np.abs(qdd).max()))
            _close("M (qdd - qdd_pin)", M @ (qdd - pin.aba(model, data, qp, vp, ap)), 0.0, residual_scale)
        pin.forwardKinematics(model, data, qp)
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, qp)
        for name, index, is_frame in picked:
            pose = data.oMf[index] if is_frame else data.oMi[index]
            _close(f"pose of {name}", robot.pose(q, name), pose.homogeneous)
            J = (pin.getFrameJacobian if is_frame else pin.getJointJacobian)(
                model, data, index, pin.LOCAL_WORLD_ALIGNED
            )
            _close(f"Jacobian of {name}", robot.jacobian(q, name)[:, P], J)
        # K = v M v / 2 with Pinocchio's M (armature included; its computeKineticEnergy treats the
        # rotors differently, so it is compared where there are none)
        _close("kinetic energy", robot.kinetic_energy(q, v), vp @ M @ vp / 2, scale)
        if not robot.armature.any():
            _close(
                "kinetic energy (Pinocchio)",
                robot.kinetic_energy(q, v),
                pin.computeKineticEnergy(model, data, qp, vp),
                scale,
            )
        _close("centre of mass", robot.center_of_mass(q), pin.centerOfMass(model, data, qp))
        A = pin.ccrba(model, data, qp, vp)
        _close("centroidal momentum matrix", robot.centroidal_momentum_matrix(q)[:, P], A, scale)
        _close("centroidal momentum", robot.centroidal_momentum_matrix(q) @ v, data.hg.vector, scale)
        _close(
            "centre-of-mass Jacobian", robot.center_of_mass_jacobian(q)[:, P], pin.jacobianCenterOfMass(model, data, qp)
        )
        # the acceleration drift J_dot v of each compared frame (a = 0): Pinocchio's classical acceleration
        pin.forwardKinematics(model, data, qp, vp, 0 * vp)
        for name, index, is_frame in picked[:2]:
            if is_frame:
                drift = pin.getFrameClassicalAcceleration(model, data, index, pin.LOCAL_WORLD_ALIGNED)
            else:
                placement = pin.SE3(data.oMi[index].rotation, np.zeros(3))
                drift = placement.act(data.a[index]).vector
                drift[:3] += np.cross(placement.act(data.v[index]).angular, placement.act(data.v[index]).linear)
            _close(f"J_dot v of {name}", robot.jacobian_dot_qd(q, v, name), drift, scale)
        _close("potential energy", robot.potential_energy(q), pin.computePotentialEnergy(model, data, qp), scale)
        Y = pin.computeJointTorqueRegressor(model, data, qp, vp, ap)
        pi = np.concatenate([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])
        _close("Y pi == tau (Pinocchio's regressor)", Y @ pi, tau - model.armature * ap, float(np.abs(tau).max()))
        _close(
            "Y pi == tau (kinedyn's regressor)",
            (robot.regressor(q, v, a) @ robot.inertial_parameters())[P],
            tau - model.armature * ap,
            float(np.abs(tau).max()),
        )
        if derivatives:
            dq, dv, _ = pin.computeRNEADerivatives(model, data, qp, vp, ap)
            Dq, Dv, Dqdd = robot.inverse_dynamics_derivatives(q, v, a)
            _close("dtau/dq", Dq[B], dq, scale)
            _close("dtau/dv", Dv[B], dv + np.diag(robot.viscous[P]), scale)
            _close("dtau/dqdd", Dqdd[B], M, scale)
            # at the torque that gives qdd = a in both (kinedyn's includes the joints' friction)
            fq, fv, ftau = pin.computeABADerivatives(model, data, qp, vp, tau)
            Fq, Fv, Ftau = robot.forward_dynamics_derivatives(q, v, robot.inverse_dynamics(q, v, a))
            _close("dqdd/dq", Fq[B], fq, float(np.abs(fq).max()))
            _close("dqdd/dtau", Ftau[B], ftau, float(np.abs(ftau).max()))


@pytest.mark.skipif(not URDFS, reason="example-robot-data is not installed")
@pytest.mark.parametrize("rel", URDFS)
def test_every_example_robot_data_urdf_agrees_with_pinocchio(rel):
    path = os.path.join(example_robot_data_dir(), rel)
    rng = np.random.default_rng(zlib.crc32(rel.encode()))  # not hash(): salted per process
    if rel in EMPTY:
        with pytest.raises(ValueError, match="has no <link>"):
            kd.Robot.from_urdf(path)
        with pytest.raises(ValueError):
            pin.buildModelFromUrdf(path)
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # some files' inertias are not physical (kinedyn warns)
        floating = kd.Robot.from_urdf(
            path, floating_base=True, mimic="independent"
        )  # as Pinocchio's model below (tests/test_mimic.py reduces them)
        fixed = kd.Robot.from_urdf(path, mimic="independent")
        if fixed.nv == 0:  # a drone: the root link is the only body, no degree of freedom (as Pinocchio)
            assert pin.buildModelFromUrdf(path).nq == 0
            fixed = None
    assert (
        floating.nq == floating.nv + 1
        and floating.joints[0].kind == "floating"
        and floating.joint_names[0] == "root_joint"
    )
    compare(PinPair(floating, pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())), rng)
    if fixed is not None:
        assert floating.nv == fixed.nv + 6
        compare(PinPair(fixed, pin.buildModelFromUrdf(path)), rng)


@pytest.mark.parametrize("seed", range(6))
def test_random_trees_of_every_joint_kind_agree_with_pinocchio(seed):
    robot = random_robot(seed, n=7, branching=True, floating=seed % 2 == 0, spherical=0.3, planar=0.2, prismatic=0.3)
    kinds = {j.kind for j in robot.joints}
    assert kinds & {"spherical", "planar", "floating"}, kinds
    compare(PinPair(robot, pinocchio_model(robot)), np.random.default_rng(seed), states=3, derivatives=True)


def test_the_floating_root_is_pinocchios_free_flyer():
    """q = (position, quaternion x y z w, joints), v = (linear and angular velocity of the root in its
    own frame, joint rates): the root link's pose and twist follow Pinocchio's convention exactly."""
    robot = random_robot(3, n=3, floating=True, friction=False)
    p = [0.3, -0.2, 0.5]
    angle, axis = 0.7, np.array([1.0, 2.0, 2.0]) / 3.0
    quat = [*(np.sin(angle / 2) * axis), np.cos(angle / 2)]
    q = np.array([*p, *quat, 0.1, -0.4])
    root = robot.body_names[0]
    # the root link's pose is its joint frame's placement in the base times (R(quaternion), position)
    T = np.linalg.solve(np.asarray(robot.tree.bodies[0].placement, dtype=float), robot.pose(q, root))
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    np.testing.assert_allclose(T[:3, :3], R, atol=1e-14)
    np.testing.assert_allclose(T[:3, 3], p, atol=1e-14)
    v = np.array([1.0, 2.0, 3.0, 0.4, 0.5, 0.6, 0.0, 0.0])
    twist = robot.frame_velocity(q, v, root, reference="local")
    np.testing.assert_allclose(twist, v[:6], atol=1e-13)


def test_non_unit_quaternion_and_wrong_lengths_are_named_errors():
    robot = random_robot(1, n=4, floating=True, spherical=1.0, friction=False)
    assert robot.nq == 7 + 4 * 3 and robot.nv == 6 + 3 * 3
    q = np.zeros(robot.nq)
    q[6] = 1.0
    with pytest.raises(
        ValueError, match=r"q\[3\.\.7\], the quaternion .* FreeFlyer joint .* has norm 1\.0\d*.* normalise"
    ):
        robot.mass_matrix(np.where(np.arange(robot.nq) == 6, 1.01, q))
    for k in range(7, robot.nq, 4):
        q[k + 3] = 1.0
    assert robot.mass_matrix(q).shape == (robot.nv, robot.nv)
    bad = q.copy()
    bad[10] = 0.5  # the first spherical joint's w
    with pytest.raises(ValueError, match=r"q\[7\.\.11\], the quaternion .* Spherical joint"):
        robot.gravity_torque(bad)
    with pytest.raises(ValueError, match=rf"q must have shape \({robot.nq},\)"):
        robot.mass_matrix(q[:-1])
    with pytest.raises(ValueError, match=rf"qd must have shape \({robot.nv},\)"):
        robot.inverse_dynamics(q, np.zeros(robot.nq), np.zeros(robot.nv))


def test_drones_have_no_degree_of_freedom_on_a_fixed_base_and_six_on_a_floating_one():
    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    path = os.path.join(root, "iris_description", "robots", "iris_simple.urdf")
    still = kd.Robot.from_urdf(path)
    assert (still.nq, still.nv) == (0, 0) and still.mass_matrix(np.zeros(0)).shape == (0, 0)
    drone = kd.Robot.from_urdf(path, floating_base=True)
    assert (drone.nq, drone.nv) == (7, 6)
    q = np.array([0, 0, 1.0, 0, 0, 0, 1.0])
    mass = drone.mass_matrix(q)[0, 0]
    # hovering: the free-flyer's gravity force is m g straight down, in the body frame (level)
    np.testing.assert_allclose(drone.gravity_torque(q)[:3], [0, 0, mass * 9.81], rtol=1e-12)


# ------------------------------------------------------------------ minimal coordinates (symbolic engine)
def test_euler_parametrisation_has_the_same_dynamics_as_the_native_joints():
    """The symbolic engine's coordinates (position + ZYX Euler angles) against the quaternion model:
    with v = T(q_e) qd_e, M_e = T^T M T, g_e = T^T g, tau_e = T^T tau(q, v, T qdd_e + dT/dt qd_e)."""
    from kinedyn.description.parametrise import euler_parametrised, euler_to_native, euler_velocity_map

    robot = random_robot(
        0, n=7, branching=True, floating=True, spherical=0.3, planar=0.2, prismatic=0.3, friction=False
    )
    assert {"floating", "spherical", "planar"} <= {j.kind for j in robot.joints}
    euler = euler_parametrised(robot)
    assert euler.nq == euler.nv == robot.nv and not euler.has_multi_dof_joints
    rng = np.random.default_rng(4)
    for _ in range(3):
        qe, qde, qdde = rng.uniform(-1.2, 1.2, robot.nv), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        q, v = euler_to_native(robot, qe, qde)
        T = euler_velocity_map(robot, qe)
        h = 1e-6
        Tdot = (euler_velocity_map(robot, qe + h * qde) - euler_velocity_map(robot, qe - h * qde)) / (2 * h)
        for name in robot.frame_names:
            _close(f"pose of {name}", euler.pose(qe, name), robot.pose(q, name))
        _close("M", euler.mass_matrix(qe), T.T @ robot.mass_matrix(q) @ T, 10.0)
        _close("g", euler.gravity_torque(qe), T.T @ robot.gravity_torque(q), 10.0)
        _close("K", euler.kinetic_energy(qe, qde), robot.kinetic_energy(q, v), 10.0)
        tau = T.T @ robot.inverse_dynamics(q, v, T @ qdde + Tdot @ qde)
        assert np.abs(euler.inverse_dynamics(qe, qde, qdde) - tau).max() < 1e-6 * max(1.0, np.abs(tau).max())


def test_symbolic_equations_of_a_floating_robot_match_the_core():
    """eom of a floating two-link robot (derived in Euler coordinates) evaluated at random states equals
    the core's M and g mapped through T (two engines, two parametrisations)."""
    from kinedyn.description.parametrise import euler_to_native, euler_velocity_map

    robot = random_robot(2, n=2, floating=True, friction=False, fixed=0)
    eom = robot.equations_of_motion(simplify=False)
    assert [str(s) for s in eom.q] == ["j1_x", "j1_y", "j1_z", "j1_yaw", "j1_pitch", "j1_roll", "j2"]
    rng = np.random.default_rng(5)
    for _ in range(2):
        qe = rng.uniform(-1.2, 1.2, robot.nv)
        q, _v = euler_to_native(robot, qe)
        T = euler_velocity_map(robot, qe)
        values = dict(zip(eom.q, qe))
        M = np.array(eom.M.subs(values).evalf(), dtype=float)
        g = np.array(eom.g.subs(values).evalf(), dtype=float).ravel()
        _close("symbolic M", M, T.T @ robot.mass_matrix(q) @ T, 10.0)
        _close("symbolic g", g, T.T @ robot.gravity_torque(q), 10.0)


def test_locking_the_floating_joint_gives_the_fixed_base_robot_at_that_pose():
    robot = random_robot(3, n=5, branching=True, floating=True, spherical=0.5, friction=False)
    pair = PinPair(robot, pinocchio_model(robot))
    q, v, _ = pair.random_state(np.random.default_rng(8))
    fixed = robot.lock_joints([robot.joint_names[0]], at=q)
    assert fixed.joints[0].kind != "floating" and (fixed.nq, fixed.nv) == (robot.nq - 7, robot.nv - 6)
    _close("tool pose", fixed.pose(q[7:], fixed.tool), robot.pose(q, robot.tool))
    _close("M of the joints", fixed.mass_matrix(q[7:]), robot.mass_matrix(q)[6:, 6:], 10.0)
    spherical = robot.joint_names[[j.kind for j in robot.joints].index("spherical")]
    with pytest.raises(ValueError, match=f"joint '{spherical}'.* not unit"):
        robot.lock_joints({spherical: [0.0, 0.0, 0.0, 2.0]})


def test_floating_robots_convert_to_urdf_and_back():
    """robot.to_urdf of a floating robot (the trunk becomes the URDF root) read back with
    floating_base=True, and a planar joint written as URDF's planar type: the same dynamics."""
    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    solo = kd.Robot.from_urdf(os.path.join(root, "solo_description", "robots", "solo12.urdf"), floating_base=True)
    planar = random_robot(4, n=4, planar=1.0, friction=False)
    assert "planar" in {j.kind for j in planar.joints}
    for robot, floating in ((solo, True), (planar, False)):
        back = kd.Robot.from_urdf(robot.to_urdf(), floating_base=floating)
        assert back.joint_names == robot.joint_names and (back.nq, back.nv) == (robot.nq, robot.nv)
        pair = PinPair(robot, pinocchio_model(robot))
        rng = np.random.default_rng(2)
        for _ in range(2):
            q, v, a = pair.random_state(rng)
            _close("M", back.mass_matrix(q), robot.mass_matrix(q), 10.0)
            _close("tau", back.inverse_dynamics(q, v, a), robot.inverse_dynamics(q, v, a), 10.0)
            for name in robot.body_names:
                _close(f"pose of {name}", back.pose(q, name), robot.pose(q, name))


def test_identities_and_base_parameters_hold_on_a_floating_tree():
    """kinedyn.testing.check_identities (finite differences along q ⊕ t qd) and the base parameters
    (Y[:, base] pi_base == Y pi) on a tree with every multi-DOF kind."""
    from kinedyn.testing import check_identities

    robot = random_robot(0, n=7, branching=True, floating=True, spherical=0.3, planar=0.2)
    worst = check_identities(robot, states=3)
    assert len(worst) >= 10
    for name, residual in worst.items():
        assert residual < (1e-7 if "finite differences" in name else 1e-10), (name, residual)
    base = robot.base_parameters(samples=40)
    rng = np.random.default_rng(6)
    q, v, a = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    Y = robot.regressor(q, v, a)
    assert Y.shape == (robot.nv, 10 * len(robot.body_names))
    _close("Y_base pi_base", Y[:, base.indices] @ base.values, Y @ robot.inertial_parameters(), 10.0)


# ------------------------------------------------------------------ simulation on the manifold
def test_a_tumbling_floating_tree_keeps_its_energy_and_momentum():
    """No gravity, no torque, no friction: the core's RK4 on the manifold (Runge-Kutta-Munthe-Kaas:
    stages q ⊕ c k, k = dexp⁻¹(v)) keeps the energy and the spatial momentum, and is fourth order:
    the momentum's drift falls at least 10x when dt halves (16x in theory)."""
    robot = random_robot(4, n=4, branching=True, floating=True, spherical=0.4, friction=False, fixed=0).replace(
        gravity=(0, 0, 0)
    )
    assert {"floating", "spherical"} <= {j.kind for j in robot.joints}
    q0 = robot.random_configuration(1)
    v0 = np.random.default_rng(2).normal(size=robot.nv)
    drift = []
    for dt in (2e-3, 1e-3):
        traj = kd.simulate(robot, (0.0, 1.0), np.concatenate([q0, v0]), dt=dt, method="rk4")
        assert traj.q.shape == (int(round(1 / dt)) + 1, robot.nq) and traj.qd.shape[-1] == robot.nv
        H = traj.H
        assert np.abs(H - H[0]).max() < 1e-8 * max(1.0, abs(H[0]))
        h = robot.momentum(traj.q, traj.qd)
        drift.append(np.abs(h - h[0]).max())
        quaternions = traj.q[:, 3:7]
        assert np.abs(np.linalg.norm(quaternions, axis=1) - 1).max() < 1e-12
    assert drift[1] < 1e-8 and drift[0] > 10 * drift[1], drift


def test_a_free_body_falls_on_its_parabola():
    """One rigid body on a free-flyer, spinning, under gravity: its centre of mass follows
    c0 + c_dot0 t + g t^2 / 2 whatever the rotation (every fixed-step method; RK4 closely)."""
    robot = random_robot(7, n=1, floating=True, friction=False, fixed=0)
    q0 = robot.random_configuration(3)
    v0 = np.array([0.3, -0.2, 1.0, 2.0, -1.0, 3.0])
    c0, cdot0 = robot.center_of_mass(q0), robot.center_of_mass_jacobian(q0) @ v0
    for method, tol in (("rk4", 1e-9), ("semi_implicit_euler", 5e-2), ("implicit", 5e-2)):
        traj = kd.simulate(robot, (0.0, 0.5), np.concatenate([q0, v0]), dt=1e-3, method=method)
        expected = c0 + np.outer(traj.t, cdot0) + 0.5 * np.outer(traj.t**2, robot.gravity)
        assert np.abs(robot.center_of_mass(traj.q) - expected).max() < tol, method


def test_simulation_of_multi_dof_joints_needs_the_native_integrators():
    robot = random_robot(1, n=3, floating=True, friction=False)
    x0 = np.concatenate([robot.neutral(), np.zeros(robot.nv)])
    with pytest.raises(ValueError, match="x0 must be .* nq \\+ nv"):
        kd.simulate(robot, 0.1, np.zeros(2 * robot.nv))
    with pytest.raises(ValueError, match="native fixed-step integrators only"):
        kd.simulate(robot, 0.1, x0, method="rk45")
    bad = x0.copy()
    bad[6] = 2.0
    with pytest.raises(ValueError, match="quaternion .* normalise"):
        kd.simulate(robot, 0.1, bad)


def test_the_command_line_takes_a_floating_base(capsys):
    """--floating-base on the commands that read a robot: fk, dynamics and simulate run on the
    configuration (nq numbers, the neutral one by default); what does not handle it yet says so."""
    from kinedyn.cli import main

    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    path = os.path.join(root, "solo_description", "robots", "solo12.urdf")
    robot = kd.Robot.from_urdf(path, floating_base=True)
    q = robot.random_configuration(3)
    assert main(["fk", path, "--floating-base", "--json", "--q", *map(str, q)]) == 0
    import json

    out = json.loads(capsys.readouterr().out)
    _close("tool pose", np.array(out["frames"][robot.tool]["pose"]), robot.pose(q))
    assert main(["simulate", path, "--floating-base", "--t", "0.02"]) == 0
    capsys.readouterr()
    assert main(["fk", path, "--floating-base", "--q", *map(str, q[:-1])]) != 0
    assert "--q needs 19 values" in capsys.readouterr().err
    assert main(["check", path, "--floating-base", "--prove"]) != 0
    assert "kinedyn check --prove handles revolute and prismatic joints only" in capsys.readouterr().err
    assert main(["info", "planar_2r", "--floating-base"]) != 0


def test_identification_from_joint_logs_refuses_multi_dof_joints_naming_them():
    from kinedyn.analysis import identification

    robot = random_robot(1, n=3, floating=True, friction=False)
    with pytest.raises(ValueError, match="excitation trajectory .*floating joint 'j1'"):
        identification.excitation(robot)
    with pytest.raises(
        ValueError,
        match="identification from joint logs handles revolute and prismatic joints only.*floating joint 'j1'",
    ):
        identification.identify(robot, None)
