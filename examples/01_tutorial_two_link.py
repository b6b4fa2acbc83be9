"""The tutorial's two-link planar arm (METR4202 Tutorial 4, Q1-Q2): Jacobian, tool velocity, J^T F.

Run: python examples/01_tutorial_two_link.py
"""

import numpy as np

import kinedyn as kd
from kinedyn import kinematics as kin

robot = kd.robots.planar_2r(l1=2.0, l2=3.0)  # a1 = 2 m, a2 = 3 m
q = np.radians([167.028, -156.44])  # the tutorial's joint angles
qd = np.array([1.0, 3.0])  # rad/s
F = np.array([30.0, -20.0])  # N, at the tool

J = kin.task_jacobian(robot, q, task="planar")  # rows x, y of the geometric Jacobian
v = kin.tool_velocity(robot, q, qd, task="planar")
tau = kin.joint_torques(robot, q, F, task="planar")
print("tool position [m]:", np.round(robot.pose(q)[:2, 3], 4))
print("J =\n", np.round(J, 4))
print("v = J qd [m/s]:", np.round(v, 4))
print("tau = J^T F [N m]:", np.round(tau, 4), "(the tutorial prints -75.1 for tau2: a misprint)")

# independent checks: the velocity by finite differences of the FK, the torques by virtual work
h = 1e-6
v_fd = (robot.pose(q + h * qd)[:2, 3] - robot.pose(q - h * qd)[:2, 3]) / (2 * h)
tau_fd = np.array([F @ (robot.pose(q + h * e)[:2, 3] - robot.pose(q - h * e)[:2, 3]) / (2 * h) for e in np.eye(2)])
assert np.allclose(v, v_fd, atol=1e-7) and np.allclose(tau, tau_fd, atol=1e-6)

# joint rates for a wanted tool velocity, and the singular pose
print(
    "qd for v = (0, 1) m/s:", np.round(kin.joint_velocities(robot, q, [0.0, 1.0], task="planar", method="inverse"), 4)
)
print("at theta2 = 0:", kin.singularity_report(robot, [0.4, 0.0], task="planar").summary())
