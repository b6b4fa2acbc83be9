"""The rigid-body part of identification checked by an independent route (issue 29, Tests):
Pinocchio's joint-torque regressor. kinedyn's regressor columns are Pinocchio's (the same parameter
order, [m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about each joint frame) on example-robot-data's UR5
and Panda; the base-parameter estimate of ``identify`` equals least squares on Pinocchio's columns
(the same base columns); and the armature column is what Pinocchio's ``model.armature`` adds to its
RNEA."""

from __future__ import annotations

import numpy as np
import pytest
from reference import PANDA, UR5, erd

import kinedyn as kd
import kinedyn.analysis as an

pin = pytest.importorskip("pinocchio")


@pytest.mark.parametrize("files", [UR5, PANDA], ids=["ur5", "panda"])
def test_regressor_columns_are_pinocchios(files):
    path = erd(*files)
    robot = kd.load(path)
    model = pin.buildModelFromUrdf(path)
    fingers = [j for j in robot.joint_names if "finger" in j]
    if fingers:  # the Panda's gripper locked at 0 in both: its bodies join the last link's
        robot = robot.lock_joints(fingers)
        ids = [model.getJointId(nm) for nm in model.names if "finger" in nm]
        model = pin.buildReducedModel(model, ids, pin.neutral(model))
    data = model.createData()
    assert model.nv == robot.n
    rng = np.random.default_rng(4)
    Q, V, A = rng.normal(size=(3, 5, robot.n))
    Y = robot.regressor(Q, V, A)
    for k in range(5):
        Yp = pin.computeJointTorqueRegressor(model, data, Q[k], V[k], A[k])
        assert np.allclose(Y[k], Yp, rtol=1e-12, atol=1e-12 * np.abs(Yp).max())
    pi = np.concatenate([model.inertias[i].toDynamicParameters() for i in range(1, model.njoints)])
    assert np.allclose(robot.inertial_parameters(), pi, atol=1e-12)


def test_identified_base_parameters_equal_least_squares_on_pinocchios_columns():
    path = erd(*UR5)
    robot = kd.load(path)
    model = pin.buildModelFromUrdf(path)
    data = model.createData()
    ref = an.excitation(robot, harmonics=4, period=5.0, amplitude=0.6, seed=2)
    meas = an.simulate_measurements(robot, ref, T=5.0, rate=50.0, noise=0.05, seed=3)
    result = an.identify(robot, meas)
    base = robot.base_parameters()
    Yp = np.concatenate(
        [
            pin.computeJointTorqueRegressor(model, data, q, v, a)
            for q, v, a in zip(np.asarray(meas.q), np.asarray(meas.qd), np.asarray(meas.qdd))
        ]
    )
    # Pinocchio's columns of the base parameters (kinedyn's regressor keeps those columns, the others
    # grouped into them), fitted to the same noisy torques
    theta = np.linalg.lstsq(Yp[:, base.indices], np.asarray(meas.tau).reshape(-1), rcond=None)[0]
    assert np.allclose(result.estimates, theta, rtol=1e-8, atol=1e-10 * np.abs(theta).max())
    assert np.abs(result.estimates - result.true_values).max() > 1e-6  # noisy data: a real fit, not the truth


def test_the_armature_column_is_pinocchios_armature():
    path = erd(*UR5)
    robot = kd.load(path)
    model = pin.buildModelFromUrdf(path)
    armature = np.array([0.4, 0.5, 0.3, 0.1, 0.1, 0.05])
    model.armature = armature
    data = model.createData()
    from kinedyn.analysis.parameters import rotor_regressor

    rng = np.random.default_rng(5)
    Q, V, A = rng.normal(size=(3, 4, robot.n))
    columns = np.concatenate([robot.regressor(Q, V, A), rotor_regressor(A, tuple(range(robot.n)), robot.n)], axis=2)
    x = np.concatenate([robot.inertial_parameters(), armature])
    for k in range(4):
        assert np.allclose(columns[k] @ x, pin.rnea(model, data, Q[k], V[k], A[k]), atol=1e-10)
