"""Tutorial Q3: the equations of motion of the two-link arm of uniform rods, by Lagrange's method,
symbolically (with every step) and checked against the numeric Newton-Euler of the Rust core.

Run: python examples/02_lagrange_two_link.py
"""

import numpy as np
import sympy as sp

import kinedyn as kd

l1, l2, m1, m2, lc1, lc2, I1, I2 = sp.symbols("l1 l2 m1 m2 lc1 lc2 I1 I2", positive=True)
robot = kd.robots.planar_2r(symbolic=True).subs({lc1: l1 / 2, lc2: l2 / 2, I1: m1 * l1**2 / 12, I2: m2 * l2**2 / 12})
eom = robot.equations_of_motion()
for k, step in enumerate(eom.steps, 1):
    print(f"step {k}: {step.title}")
print("tau1 =", eom.tau[0])
print("tau2 =", eom.tau[1])  # + (1/2) m2 l1 l2 sin(q2) qd1^2: the tutorial prints a minus sign

# the same arm with numbers, against the Rust core's recursive Newton-Euler
values = {"l1": 2.0, "l2": 3.0, "m1": 1.0, "m2": 2.0, "g": 9.81}
numeric = kd.robots.planar_2r(l1=2.0, l2=3.0, m1=1.0, m2=2.0)
q, qd, qdd = np.array([0.3, -0.7]), np.array([1.0, 3.0]), np.array([0.5, -1.0])
state = dict(zip(list(eom.q) + list(eom.qd) + list(eom.qdd), [*q, *qd, *qdd]))
state.update({s: values[str(s)] for s in eom.parameters})  # the symbols l1, l2, m1, m2, g
tau_symbolic = np.array([float(e.subs(state)) for e in eom.tau])
tau_numeric = numeric.inverse_dynamics(q, qd, qdd)
print("tau (symbolic) =", tau_symbolic, " tau (RNEA) =", tau_numeric)
assert np.allclose(tau_symbolic, tau_numeric, rtol=1e-12)
