"""The tutorial's challenge: the elbow manipulator (L1 = 3 m, L2 = 2 m, L3 = 1 m): DH table, every
inverse-kinematics solution for the tool at (1.0, 0.2, 0.5) m, and the Jacobian there.

Run: python examples/03_elbow_ik.py
"""

import numpy as np

import kinedyn as kd
from kinedyn.tutorial import elbow_ik

robot = kd.robots.elbow_3r(L1=3.0, L2=2.0, L3=1.0)
for i, row in enumerate(robot.dh, 1):
    print(f"link {i}: theta = q{i}, d = {row.d:g}, a = {row.a:g}, alpha = {np.degrees(row.alpha):g} deg")

target = np.array([1.0, 0.2, 0.5])
solutions = elbow_ik(*target, 3.0, 2.0, 1.0)  # the textbook's closed form (Spong §3.3)
if hasattr(robot, "inverse_kinematics"):  # kinedyn's own solver, where this version has it
    solutions = np.atleast_2d(robot.inverse_kinematics(target).solutions)
for q in solutions:
    error = np.linalg.norm(robot.pose(q)[:3, 3] - target)
    print("q [deg] =", np.round(np.degrees(q), 4), f" FK error {error:.1e} m")
    assert error < 1e-9
print(f"{len(solutions)} solutions")
assert len(solutions) == 4

J = robot.jacobian(solutions[0])
print("J at the first solution =\n", np.round(J, 6))
print("singular values:", np.round(np.linalg.svd(J[:3], compute_uv=False), 6))
