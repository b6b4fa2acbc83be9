"""Pinocchio as an oracle (an optional test extra): the UR5 and Panda URDFs of the
``example-robot-data`` package and the KUKA iiwa URDF (example-robot-data has none; pybullet's
``pybullet_data`` does) give the same tau, M, C, g, qdd, centre of mass and momentum.

URDF ``<dynamics damping friction>`` become kinedyn's joint friction, which Pinocchio's algorithms
leave out; it is removed from kinedyn's results before comparing.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

import kinedyn as kd

pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is an optional test oracle")
pytest.importorskip("kinedyn._core", reason="the native module is not built")

TOL = 1e-9


def robots_dir() -> str:
    from kinedyn.testing import example_robot_data_dir

    folder = example_robot_data_dir()
    if folder is None:
        pytest.skip("example-robot-data (pip install example-robot-data) is not installed")
    return folder


def iiwa_urdf() -> str:
    """The KUKA LBR iiwa 14 URDF: example-robot-data's if a version ships it, else pybullet_data's."""
    path = os.path.join(robots_dir(), "iiwa_description/urdf/iiwa.urdf")
    if os.path.exists(path):
        return path
    try:
        import pybullet_data
    except ImportError:
        pytest.skip("no KUKA iiwa URDF: example-robot-data has none and pybullet (pybullet_data) is not installed")
    return os.path.join(pybullet_data.getDataPath(), "kuka_iiwa", "model.urdf")


PANDA_FINGERS = {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02}
CASES = {
    "ur5": (lambda: os.path.join(robots_dir(), "ur_description/urdf/ur5_robot.urdf"), {}),
    "panda": (lambda: os.path.join(robots_dir(), "panda_description/urdf/panda.urdf"), PANDA_FINGERS),
    "iiwa": (iiwa_urdf, {}),
}


@pytest.fixture(params=list(CASES), scope="module")
def pair(request):
    where, locked = CASES[request.param]
    path = where()
    assert os.path.exists(path), path
    robot = kd.Robot.from_urdf(path)
    model = pin.buildModelFromUrdf(path)
    if locked:
        robot = robot.lock_joints(locked)
        q_ref = pin.neutral(model)
        ids = []
        for name, value in locked.items():
            jid = model.getJointId(name)
            q_ref[model.joints[jid].idx_q] = value
            ids.append(jid)
        model = pin.buildReducedModel(model, ids, q_ref)
    assert model.nq == model.nv == robot.n, "only 1-dof joints with nq == nv are compared"
    names = [model.names[j] for j in range(1, model.njoints)]
    assert names == robot.joint_names, f"joint order differs: {names} vs {robot.joint_names}"
    return robot, model, model.createData()


def friction(robot, qd):
    v = np.array([float(j.viscous) for j in robot.joints])
    c = np.array([float(j.coulomb) for j in robot.joints])
    return v * qd + c * np.sign(qd)


def states(robot, count=5, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield robot.random_configuration(rng), rng.uniform(-2, 2, robot.n), rng.uniform(-3, 3, robot.n)


def close(got, want, what):
    scale = max(1.0, np.abs(want).max())
    err = np.abs(np.asarray(got) - np.asarray(want)).max()
    assert err <= TOL * scale, f"{what}: max |diff| {err:.3g}"


def test_same_dynamics_as_pinocchio(pair):
    robot, model, data = pair
    for q, qd, qdd in states(robot):
        tau = pin.rnea(model, data, q, qd, qdd)
        close(robot.inverse_dynamics(q, qd, qdd) - friction(robot, qd), tau, "tau")
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T  # Pinocchio fills the upper triangle
        close(robot.mass_matrix(q), M, "M")
        close(robot.coriolis_matrix(q, qd), pin.computeCoriolisMatrix(model, data, q, qd), "C")
        close(robot.gravity_torque(q), pin.computeGeneralizedGravity(model, data, q), "g")
        close(robot.forward_dynamics(q, qd, tau + friction(robot, qd)), pin.aba(model, data, q, qd, tau), "qdd")
        Minv = pin.computeMinverse(model, data, q)
        close(robot.mass_matrix_inverse(q), np.triu(Minv) + np.triu(Minv, 1).T, "M^-1")
        close(robot.kinetic_energy(q, qd), pin.computeKineticEnergy(model, data, q, qd), "K")
        close(robot.potential_energy(q), pin.computePotentialEnergy(model, data, q), "P")


def test_same_centre_of_mass_and_momentum_as_pinocchio(pair):
    robot, model, data = pair
    for q, qd, _ in states(robot, 3):
        # both count the moving bodies only (Pinocchio's data.mass[0] leaves the universe out)
        com = pin.centerOfMass(model, data, q)
        close(robot.center_of_mass(q), com, "centre of mass")
        pin.computeCentroidalMomentum(model, data, q, qd)
        p, L_com = data.hg.linear, data.hg.angular
        h = robot.momentum(q, qd)
        close(h[:3], p, "linear momentum")
        close(h[3:], L_com + np.cross(com, p), "angular momentum about the base origin")
