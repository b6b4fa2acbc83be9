"""LagrangianSystem results at textbook size (issue 12 §4): the multipliers, L, H and Hamilton's
equations go through kinedyn.symbolic.simplify.textbook_form. Each result is checked against the
unsimplified one (or a derivation written here) at random points, and its size against a bound well
under the size it had before (op counts, sympy.count_ops, measured before the change: sphere lambda
20, knife-edge lambda 23, remotely driven arm L 94, H 253, qdot 606)."""

from __future__ import annotations

import numpy as np
import sympy as sp

from kinedyn.symbolic import examples
from kinedyn.symbolic.system import LagrangianSystem, coordinates

RNG = np.random.default_rng(3)


def _ops(e) -> int:
    return int(sum(sp.count_ops(x) for x in e) if isinstance(e, sp.MatrixBase) else sp.count_ops(e))


def _same(a, b, symbols, trials=5):
    fa, fb = sp.lambdify(symbols, a, "numpy"), sp.lambdify(symbols, b, "numpy")
    for _ in range(trials):
        x = RNG.uniform(0.3, 1.5, len(symbols))
        np.testing.assert_allclose(
            np.asarray(fa(*x), dtype=float), np.asarray(fb(*x), dtype=float), rtol=1e-9, atol=1e-12
        )


def _raw_multipliers(s):
    """The multipliers as formed, before simplification (the path phase_space takes)."""
    M = sp.hessian(s.L, s.qd)
    bias = sp.Matrix([e.subs({a: 0 for a in s.qdd}) for e in s.euler_lagrange()])
    return s.multipliers(None, M, bias)


def test_sphere_multiplier_is_the_textbook_one():
    """Particle on the sphere |q|^2 = 1 with no force: differentiating the constraint twice gives
    q.qdd + |qd|^2 = 0, and m qdd = -A^T lambda = -2 lambda q, so lambda = m |qd|^2 / (2 |q|^2)."""
    m = sp.Symbol("m", positive=True)
    s = examples.sphere_particle(m=m)
    lam = s.multipliers()[0]
    q, qd = sp.Matrix(s.q), sp.Matrix(s.qd)
    assert sp.simplify(lam - m * (qd.T * qd)[0, 0] / (2 * (q.T * q)[0, 0])) == 0
    assert _ops(lam) <= 15  # printed (2 qd1^2 + ...)/(4 q1^2/m + ...) before: 20 ops


def test_knife_edge_multiplier_loses_its_denominator():
    (x, y, th), (xd, yd, thd) = coordinates("x y th")
    m, J = sp.symbols("m J", positive=True)
    s = LagrangianSystem(
        [x, y, th],
        K=m * (xd**2 + yd**2) / 2 + J * thd**2 / 2,
        P=0,
        qd=[xd, yd, thd],
        pfaffian=sp.Matrix([[sp.sin(th), -sp.cos(th), 0]]),
    )
    lam = s.multipliers()
    assert sp.fraction(sp.together(lam[0]))[1] == 1, lam  # no sin^2/m + cos^2/m denominator
    assert _ops(lam) <= 12
    _same(lam, _raw_multipliers(s), [x, y, th, xd, yd, thd, m, J, *s.u])


def test_remotely_driven_arm_lagrangian_and_hamiltonian_are_small_and_right():
    s = examples.remotely_driven_arm()
    assert _ops(s.L) <= 45  # 94 before (sin^2 + cos^2 pairs, products of sines and cosines of p1, p2)
    assert not s.L.has(sp.cos(s.q[0]) ** 2)
    _hamiltonian_is_right(s, H_ops=100, qdot_ops=100)  # 253 and 606 before; 83 and 97 as p^T adj(M) p / (2 det M)


def test_five_bar_hamiltonian_is_the_adjugate_over_the_determinant():
    """The five-bar's H (left unsimplified before: one fraction too large to simplify whole) as
    p^T adj(M) p / (2 det M) + P, and Hamilton's equations from it, equal the Lagrangian route."""
    _hamiltonian_is_right(examples.five_bar(), H_ops=240, qdot_ops=320)


def _hamiltonian_is_right(s, H_ops, qdot_ops):
    p, H, qdot, pdot = s.hamiltonian()
    assert _ops(H) <= H_ops and _ops(qdot) <= qdot_ops, (_ops(H), _ops(qdot))
    # H = K + P with p = M qd, and qdot = M^-1 p: at random states and parameters
    M = sp.hessian(s.L, s.qd)
    K = (sp.Matrix(s.qd).T * M * sp.Matrix(s.qd))[0, 0] / 2
    P = -s.L.subs({v: 0 for v in s.qd})
    momenta = dict(zip(p, M * sp.Matrix(s.qd)))
    params = sorted((s.L.free_symbols - set(s.q) - set(s.qd)), key=str)
    syms = [*s.q, *s.qd, *params]
    _same(H.xreplace(momenta), K + P, syms)
    _same(qdot.xreplace(momenta), sp.Matrix(s.qd), syms)
    # Hamilton's pdot = -dH/dq equals the Euler-Lagrange form d/dt(M qd) = dL/dq + u along the motion
    EL = sp.Matrix([sp.diff(s.L, c) for c in s.q]) + s.u
    _same(pdot.xreplace(momenta), EL, [*syms, *s.u])


def test_arc_length_euler_lagrange_is_the_textbook_one():
    """LaValle Ex 13.9, L = sqrt(1 + xd^2): the Euler-Lagrange expression is xdd/(1 + xd^2)^(3/2)."""
    (x,), (xd,) = coordinates("x")
    s = LagrangianSystem([x], L=sp.sqrt(1 + xd**2), qd=[xd])
    E = s.equations_of_motion().steps[1].equations[0][1]
    xdd = s.qdd[0]
    assert sp.simplify(E - xdd / (1 + xd**2) ** sp.Rational(3, 2)) == 0
    assert _ops(E) <= 8, E  # 20 before: -xdd xd^2/(xd^2 sqrt(xd^2 + 1) + sqrt(xd^2 + 1)) + xdd/sqrt(xd^2 + 1)
