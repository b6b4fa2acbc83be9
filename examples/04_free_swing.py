"""The tutorial arm swinging freely under gravity: forward dynamics of the Rust core integrated with
SciPy, and the energy balance that checks it (no torque, no friction: K + P is constant).

Run: python examples/04_free_swing.py
"""

import numpy as np
from scipy.integrate import solve_ivp

import kinedyn as kd

robot = kd.robots.planar_2r()
n = robot.n
x0 = np.array([0.5, -0.7, 0.0, 0.0])  # q, qd
rhs = lambda t, x: np.concatenate([x[n:], robot.forward_dynamics(x[:n], x[n:], np.zeros(n))])
sol = solve_ivp(rhs, (0.0, 3.0), x0, method="DOP853", rtol=1e-10, atol=1e-10, t_eval=np.linspace(0, 3, 7))
q, qd = sol.y[:n].T, sol.y[n:].T
H = robot.kinetic_energy(q, qd) + robot.potential_energy(q)
for t, qi, h in zip(sol.t, q, H):
    print(f"t = {t:3.1f} s  q = {np.round(qi, 4)}  K + P = {h:.9f} J")
assert np.max(np.abs(H - H[0])) < 1e-6
