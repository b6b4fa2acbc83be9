"""The seed's Euler-Lagrange examples, derived symbolically (Spong ch. 9, LaValle §13.4).

Prints the planar elbow's equations with the derivation's steps, the remotely driven arm's missing
Coriolis terms, the five-bar's decoupling condition, and simulates a particle on a sphere.
Run: PYTHONPATH=python python examples/06_symbolic_mechanisms.py
"""

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

import kinedyn as kd
from kinedyn.symbolic import examples

# 1. the planar elbow (tutorial Q3, Spong §9.4): every step, then D, C, g
eom = kd.robots.planar_2r(symbolic=True).equations_of_motion()
for k, step in enumerate(eom.steps, start=1):
    print(f"step {k}: {step.title}")
print("D =", eom.M)
print("C =", eom.C)
print("g =", eom.g.T)
Y, Theta = eom.regressor()
print("grouped parameters:", list(Theta))
assert Theta.shape == (5, 1)

# 2. the remotely driven arm: centrifugal but no Coriolis terms
remote = examples.remotely_driven_arm().equations_of_motion()
pd1, pd2 = remote.qd
h = sp.expand(remote.C * remote.qd)
print("remotely driven arm, C qd =", h.T)
assert all(sp.Poly(e, pd1, pd2).coeff_monomial(pd1 * pd2) == 0 for e in h)

# 3. the five-bar linkage: D12 = (m3 l2 lc3 - m4 l1 lc4) cos(q1 - q2)
five = examples.five_bar().equations_of_motion()
print("five-bar D12 =", sp.factor(five.M[0, 1]))
m3, m4, l1, l2, lc3, lc4 = sp.symbols("m3 m4 l1 l2 lc3 lc4", positive=True)
assert sp.simplify(five.M[0, 1].subs(m3, m4 * l1 * lc4 / (l2 * lc3))) == 0

# 4. a particle on the unit sphere follows a great circle
sphere = examples.sphere_particle()
sol = solve_ivp(sphere.numeric(), (0, 6), [1, 0, 0, 0, 0.8, 0.6], rtol=1e-10, atol=1e-12)
radius_error = np.abs(np.linalg.norm(sol.y[:3], axis=0) - 1).max()
plane_error = np.abs(np.cross([1, 0, 0], [0, 0.8, 0.6]) @ sol.y[:3]).max()
print(f"sphere: |q| - 1 <= {radius_error:.1e}, distance from the great circle's plane <= {plane_error:.1e}")
assert radius_error < 1e-7 and plane_error < 1e-7
