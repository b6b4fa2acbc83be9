"""Floating bases and multi-DOF joints (free-flyer, spherical, planar) against Pinocchio as the oracle:
every URDF of example-robot-data, fixed and floating, and random trees of every joint kind built joint
by joint in both libraries. Conventions (docs/conventions.md): q of size nq (a free-flyer's position,
then its unit quaternion (x, y, z, w)), v of size nv ([linear; angular] in the child's own frame).
"""

from __future__ import annotations

import glob
import os
import warnings

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
        picked = [(name, model.getFrameId(name, pin.BODY), True) for name in dict.fromkeys([robot.tool, *chosen]) if name in bodies]
    else:
        picked = [(robot.body_names[robot.joint_names.index(model.names[j])], j, False) for j in range(1, model.njoints)]
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
        # either library, so the two accelerations are compared through M: both solve M qdd = tau - b
        try:
            qdd = robot.forward_dynamics(q, v, a + friction)[P]
        except RuntimeError as e:  # kinedyn refuses a numerically singular M; so must the condition say
            assert "singular mass matrix" in str(e) and np.linalg.cond(M) > 1e12, e
        else:
            _close("M (qdd - qdd_pin)", M @ (qdd - pin.aba(model, data, qp, vp, ap)), 0.0, float(np.abs(tau).max()))
        pin.forwardKinematics(model, data, qp)
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, qp)
        for name, index, is_frame in picked:
            pose = data.oMf[index] if is_frame else data.oMi[index]
            _close(f"pose of {name}", robot.pose(q, name), pose.homogeneous)
            J = (pin.getFrameJacobian if is_frame else pin.getJointJacobian)(model, data, index, pin.LOCAL_WORLD_ALIGNED)
            _close(f"Jacobian of {name}", robot.jacobian(q, name)[:, P], J)
        # K = v M v / 2 with Pinocchio's M (armature included; its computeKineticEnergy treats the
        # rotors differently, so it is compared where there are none)
        _close("kinetic energy", robot.kinetic_energy(q, v), vp @ M @ vp / 2, scale)
        if not robot.armature.any():
            _close("kinetic energy (Pinocchio)", robot.kinetic_energy(q, v), pin.computeKineticEnergy(model, data, qp, vp), scale)
        _close("centre of mass", robot.center_of_mass(q), pin.centerOfMass(model, data, qp))
        if derivatives:
            dq, dv, _ = pin.computeRNEADerivatives(model, data, qp, vp, ap)
            Dq, Dv, Dqdd = robot.inverse_dynamics_derivatives(q, v, a)
            _close("dtau/dq", Dq[B], dq, scale)
            _close("dtau/dv", Dv[B], dv + np.diag(robot.viscous[P]), scale)
            _close("dtau/dqdd", Dqdd[B], M, scale)


@pytest.mark.skipif(not URDFS, reason="example-robot-data is not installed")
@pytest.mark.parametrize("rel", URDFS)
def test_every_example_robot_data_urdf_agrees_with_pinocchio(rel):
    path = os.path.join(example_robot_data_dir(), rel)
    rng = np.random.default_rng(abs(hash(rel)) % 2**32)
    if rel in EMPTY:
        with pytest.raises(ValueError, match="has no <link>"):
            kd.Robot.from_urdf(path)
        with pytest.raises(ValueError):
            pin.buildModelFromUrdf(path)
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # some files' inertias are not physical (kinedyn warns)
        floating = kd.Robot.from_urdf(path, floating_base=True)
        try:
            fixed = kd.Robot.from_urdf(path)
        except ValueError as e:  # a drone: the root link is the only body
            assert "no moving joint" in str(e)
            fixed = None
    assert floating.nq == floating.nv + 1 and floating.joints[0].kind == "floating" and floating.joint_names[0] == "root_joint"
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
    with pytest.raises(ValueError, match=r"q\[3\.\.7\], the quaternion .* FreeFlyer joint .* has norm 1\.0\d*.* normalise"):
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


def test_drones_load_with_a_floating_base_only():
    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    path = os.path.join(root, "iris_description", "robots", "iris_simple.urdf")
    with pytest.raises(ValueError, match="no moving joint"):
        kd.Robot.from_urdf(path)
    drone = kd.Robot.from_urdf(path, floating_base=True)
    assert (drone.nq, drone.nv) == (7, 6)
    q = np.array([0, 0, 1.0, 0, 0, 0, 1.0])
    mass = drone.mass_matrix(q)[0, 0]
    # hovering: the free-flyer's gravity force is m g straight down, in the body frame (level)
    np.testing.assert_allclose(drone.gravity_torque(q)[:3], [0, 0, mass * 9.81], rtol=1e-12)
