"""Khatib's operational-space inertia Lambda = (J M^-1 J^T)^-1 and the dynamically consistent
inverse J_bar = M^-1 J^T Lambda (kinedyn.dynamics), checked by their defining identities and by
the physics they describe: a force F at the tool accelerates it by Lambda^-1 F (forward dynamics
with an external wrench), and null-space torques do not accelerate the tool."""

from __future__ import annotations

import numpy as np
import pytest
from reference import PANDA, erd

import kinedyn as kd
from kinedyn import dynamics as dyn
from kinedyn import kinematics as kin

pytest.importorskip("kinedyn._core", reason="the native module is not built")

RNG = np.random.default_rng(20261202)
CASES = [
    ("puma560", "full"),
    ("puma560", "position"),
    ("stanford", "full"),
    ("ur5", "orientation"),
    ("elbow_3r", "position"),
    ("planar_2r", "planar"),
    ("planar_3r", "planar_pose"),
    ("cartesian_2p", [1, 2]),
]


@pytest.mark.parametrize("name,task", CASES)
def test_lambda_inverts_j_minv_jt_and_j_bar_is_a_right_inverse(name, task):
    robot = kd.robots.get(name)
    for q in robot.random_configuration(RNG, size=3):
        J = kin.task_jacobian(robot, q, task=task)
        Minv = np.linalg.inv(robot.mass_matrix(q))  # an independent inverse of M
        L = dyn.operational_space_inertia(robot, q, task=task)
        m = J.shape[0]
        A = J @ Minv @ J.T
        tol = max(1e-10, 1e-13 * np.linalg.cond(A))  # rounding grows with A's condition number
        np.testing.assert_allclose(L @ A, np.eye(m), atol=tol)
        np.testing.assert_array_equal(L, L.T)
        assert np.all(np.linalg.eigvalsh(L) > 0)
        Jbar = dyn.dynamically_consistent_inverse(robot, q, task=task)
        assert Jbar.shape == (robot.n, m)
        np.testing.assert_allclose(J @ Jbar, np.eye(m), atol=tol)
        np.testing.assert_allclose(Jbar, Minv @ J.T @ L, atol=1e-8 * max(1.0, np.abs(Jbar).max()))
        # null-space torques (I - J^T J_bar^T) tau0 cause no tool acceleration: J M^-1 N tau0 = 0
        tau0 = RNG.normal(size=robot.n)
        np.testing.assert_allclose(J @ Minv @ (tau0 - J.T @ (Jbar.T @ tau0)), 0.0, atol=1e-8)


def test_a_force_at_the_tool_accelerates_it_by_lambda_inverse():
    """At rest without gravity, a wrench F at the tool's origin (f_ext on the last link; the PUMA's
    tool shares its origin) gives qdd = M^-1 J^T F, so the tool accelerates by J qdd = Lambda^-1 F."""
    robot = kd.robots.puma560(gravity=(0.0, 0.0, 0.0))
    q = robot.random_configuration(RNG)
    F = np.array([3.0, -1.0, 2.0, 0.5, 0.2, -0.4])
    f_ext = np.zeros((robot.n, 6))
    f_ext[-1] = F
    qdd = robot.forward_dynamics(q, np.zeros(6), np.zeros(6), f_ext=f_ext)
    a = robot.jacobian(q) @ qdd  # J qdd + dJ/dt qd, with qd = 0
    np.testing.assert_allclose(dyn.operational_space_inertia(robot, q) @ a, F, atol=1e-8)


def test_panda_urdf_redundant_arm():
    robot = kd.Robot.from_urdf(erd(*PANDA), mimic="independent")
    q = robot.random_configuration(RNG)
    J = robot.jacobian(q)
    Jbar = dyn.dynamically_consistent_inverse(robot, q)
    np.testing.assert_allclose(J @ Jbar, np.eye(6), atol=1e-8)
    L = dyn.operational_space_inertia(robot, q)
    np.testing.assert_allclose(L @ J @ robot.mass_matrix_inverse(q) @ J.T, np.eye(6), atol=1e-7)


def test_batches_equal_loops():
    robot = kd.robots.puma560()
    qs = robot.random_configuration(RNG, size=4)
    L = dyn.operational_space_inertia(robot, qs, task="position")
    Jbar = dyn.dynamically_consistent_inverse(robot, qs, task="position")
    assert L.shape == (4, 3, 3) and Jbar.shape == (4, 6, 3)
    for k in range(4):
        np.testing.assert_allclose(L[k], dyn.operational_space_inertia(robot, qs[k], task="position"), rtol=1e-12)
        np.testing.assert_allclose(
            Jbar[k], dyn.dynamically_consistent_inverse(robot, qs[k], task="position"), rtol=1e-12, atol=1e-15
        )


def test_singular_configurations_give_an_error_or_the_documented_pseudo_inverse():
    robot = kd.robots.planar_2r()
    stretched = np.array([0.4, 0.0])
    for f in (dyn.operational_space_inertia, dyn.dynamically_consistent_inverse):
        with pytest.raises(
            ValueError, match=r"the task Jacobian is singular at q = \[0\.4 0\. \].*the tool cannot move along"
        ):
            f(robot, stretched, task="planar")
        with pytest.raises(ValueError, match=r"configuration 1 of the batch"):
            f(robot, [[0.4, 1.0], stretched], task="planar")
        with pytest.raises(ValueError, match="the task has 6 rows but the robot only 2 joints"):
            f(robot, [0.4, 1.0])
        with pytest.raises(ValueError, match="method must be 'inverse' or 'pinv'"):
            f(robot, [0.4, 1.0], task="planar", method="solve")
    # pinv: finite, symmetric, the inertia along the direction the tool can still move, 0 along the lost one
    L = dyn.operational_space_inertia(robot, stretched, task="planar", method="pinv")
    assert np.all(np.isfinite(L))
    J = kin.task_jacobian(robot, stretched, task="planar")
    A = J @ robot.mass_matrix_inverse(stretched) @ J.T
    np.testing.assert_allclose(L, np.linalg.pinv(A, hermitian=True), atol=1e-10)
    T = robot.pose(stretched)
    radial = T[:2, 3] / np.linalg.norm(T[:2, 3])  # the stretched arm cannot move along itself
    np.testing.assert_allclose(L @ radial, 0.0, atol=1e-10)
    Jbar = dyn.dynamically_consistent_inverse(robot, stretched, task="planar", method="pinv")
    P = J @ Jbar  # the projector onto the directions the tool can move in, not I
    np.testing.assert_allclose(P @ P, P, atol=1e-10)
    np.testing.assert_allclose(P @ radial, 0.0, atol=1e-10)
    # away from the singularity pinv agrees with the inverse
    q = np.array([0.4, 1.2])
    np.testing.assert_allclose(
        dyn.operational_space_inertia(robot, q, task="planar", method="pinv"),
        dyn.operational_space_inertia(robot, q, task="planar"),
        rtol=1e-9,
    )
    # more task rows than joints with pinv: finite, rank n
    L6 = dyn.operational_space_inertia(robot, q, method="pinv")
    assert np.all(np.isfinite(L6)) and np.linalg.matrix_rank(L6) == 2
