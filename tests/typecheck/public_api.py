"""User code as the docs write it, checked by mypy (``[tool.mypy] files`` in pyproject.toml; never
run): the public API must type-check the way it is used, e.g. ``kd.simulate(...)`` calls the
function although ``kinedyn.simulate`` is a package, and lazily loaded submodules are typed."""

from __future__ import annotations

import numpy as np

import kinedyn as kd
from kinedyn.ik import IKResult
from kinedyn.simulate import MechanicalSystem, Trajectory

robot: kd.Robot = kd.robots.planar_2r()
q, qd = np.zeros(2), np.ones(2)
M: np.ndarray = robot.mass_matrix(q)
tau: np.ndarray = robot.inverse_dynamics(q, qd, [0.0, 0.0])
energy: float | np.ndarray = robot.kinetic_energy(q, qd)
J: np.ndarray = kd.kinematics.task_jacobian(robot, q, task="planar")
A, B = kd.dynamics.linearize(robot, q)
controller = kd.simulate.PD(100.0, 20.0, kd.simulate.Constant(np.ones(2)))
traj: Trajectory = kd.simulate(robot, 1.0, np.zeros(4), controller=controller)
path: Trajectory = kd.simulate(robot, (0.0, 1.0), np.zeros(4), dt=1e-3, record_every=10)
system: MechanicalSystem = kd.simulate.MechanicalSystem(1, lambda q: np.eye(1), lambda q, qd: np.zeros(1))
ik: IKResult = kd.ik.inverse_kinematics(robot, robot.pose(q))
loaded: kd.Robot = kd.load("robot.yaml")
