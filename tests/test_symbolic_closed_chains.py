"""Closed chains (issue 12 §5 third bullet, §7): SymPy mechanics' own four-bar linkage through
``LagrangianSystem(..., holonomic=[...])`` in seconds, with the same q̈ and λ as SymPy's
LagrangesMethod and KanesMethod."""

from __future__ import annotations

import time

import numpy as np
import pytest
import scipy.linalg
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

from kinedyn.symbolic import LagrangianSystem, coordinates

# SymPy's test_four_bar_linkage_with_manual_constraints: links of lengths l1..l4 and density rho
# (mass rho l, inertia rho l^3 / 12 about the centre), link 1 fixed along x with its centre at the
# origin, relative joint angles q1, q2, q3, no gravity; its parameter values and one consistent state
PARAMS = dict(l1=0.13, l2=0.24, l3=0.21, l4=0.34, rho=997.0)
Q_REF = np.array([2.1, 0.6655470375077588, 2.527408138024188])


def _u(angle):
    return sp.Matrix([sp.cos(angle), sp.sin(angle)])


def four_bar() -> LagrangianSystem:
    """Derived here from the geometry: joint J1 at the right end of the ground link (l1/2, 0), each
    moving link's centre half-way along it, absolute angles q1, q1 + q2, q1 + q2 + q3; the loop
    closes when link 4's far end reaches the ground link's left end (-l1/2, 0)."""
    (q1, q2, q3), (u1, u2, u3) = coordinates("q1 q2 q3")
    l1, l2, l3, l4, rho = sp.symbols("l1:5 rho")
    j1 = sp.Matrix([l1 / 2, 0])
    j2 = j1 + l2 * _u(q1)
    j3 = j2 + l3 * _u(q1 + q2)
    end = j3 + l4 * _u(q1 + q2 + q3)
    bodies = [
        dict(mass=rho * l2, position=j1 + l2 / 2 * _u(q1), inertia=rho * l2**3 / 12, angular_velocity=u1),
        dict(mass=rho * l3, position=j2 + l3 / 2 * _u(q1 + q2), inertia=rho * l3**3 / 12, angular_velocity=u1 + u2),
        dict(
            mass=rho * l4,
            position=j3 + l4 / 2 * _u(q1 + q2 + q3),
            inertia=rho * l4**3 / 12,
            angular_velocity=u1 + u2 + u3,
        ),
    ]
    closure = end - sp.Matrix([-l1 / 2, 0])
    return LagrangianSystem.from_bodies(
        [q1, q2, q3], bodies, qd=[u1, u2, u3], holonomic=list(closure), forces=[0, 0, 0], name="four-bar"
    )


def _closure_numeric(q):
    l1, l2, l3, l4 = (PARAMS[k] for k in ("l1", "l2", "l3", "l4"))
    a = np.cumsum(q)
    return np.array(
        [
            l1 + l2 * np.cos(a[0]) + l3 * np.cos(a[1]) + l4 * np.cos(a[2]),
            l2 * np.sin(a[0]) + l3 * np.sin(a[1]) + l4 * np.sin(a[2]),
        ]
    )


def _consistent_states(count, seed):
    """States on the constraint manifold near SymPy's: q1 drawn, q2, q3 solved; qd in the null space of A."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        q1 = Q_REF[0] + rng.uniform(-0.3, 0.3)
        q = np.r_[q1, fsolve(lambda x: _closure_numeric(np.r_[q1, x]), Q_REF[1:])]
        for _ in range(3):  # Newton steps to round-off
            J = np.column_stack(
                [(_closure_numeric(q + 1e-7 * e) - _closure_numeric(q - 1e-7 * e)) / 2e-7 for e in np.eye(3)[1:]]
            )
            q[1:] -= np.linalg.solve(J, _closure_numeric(q))
        assert np.abs(_closure_numeric(q)).max() < 1e-12
        h = 1e-7
        A = np.column_stack([(_closure_numeric(q + h * e) - _closure_numeric(q - h * e)) / (2 * h) for e in np.eye(3)])
        qd = scipy.linalg.null_space(A)[:, 0] * rng.uniform(-2, 2)
        out.append((q, qd))
    return out


@pytest.fixture(scope="module")
def sympy_four_bar():
    """The same mechanism in SymPy mechanics (frames and points), solved by LagrangesMethod (with
    multipliers) and KanesMethod (dependent speeds): functions (q, qd) -> (qdd, lambda) and -> qdd."""
    from sympy.physics.mechanics import (
        KanesMethod,
        LagrangesMethod,
        Lagrangian,
        Point,
        ReferenceFrame,
        RigidBody,
        dynamicsymbols,
        inertia,
    )

    q = dynamicsymbols("q1:4")
    u = dynamicsymbols("u1:4")
    t = dynamicsymbols._t
    l1, l2, l3, l4, rho = sp.symbols("l1:5 rho")
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    F2 = N.orientnew("F2", "Axis", [q[0], N.z])
    F3 = F2.orientnew("F3", "Axis", [q[1], F2.z])
    F4 = F3.orientnew("F4", "Axis", [q[2], F3.z])
    J1 = O.locatenew("J1", l1 / 2 * N.x)
    C2, J2 = J1.locatenew("C2", l2 / 2 * F2.x), J1.locatenew("J2", l2 * F2.x)
    C3, J3 = J2.locatenew("C3", l3 / 2 * F3.x), J2.locatenew("J3", l3 * F3.x)
    C4, E = J3.locatenew("C4", l4 / 2 * F4.x), J3.locatenew("E", l4 * F4.x)
    loop = E.pos_from(O) + l1 / 2 * N.x
    fh = sp.Matrix([loop.dot(N.x), loop.dot(N.y)])
    p_syms = [l1, l2, l3, l4, rho]
    p_vals = [PARAMS[str(s)] for s in p_syms]
    qdot = [qi.diff(t) for qi in q]

    def rigid(name, C, F, length):
        return RigidBody(name, C, F, rho * length, (inertia(F, 0, 0, rho * length**3 / 12), C))

    # LagrangesMethod: velocities in q'
    for C in (C2, C3, C4):
        C.set_vel(N, C.pos_from(O).dt(N))
    bodies = [rigid("B2", C2, F2, l2), rigid("B3", C3, F3, l3), rigid("B4", C4, F4, l4)]
    lm = LagrangesMethod(Lagrangian(N, *bodies), q, hol_coneqs=fh, frame=N)
    lm.form_lagranges_equations()
    lm_M = sp.lambdify([q, qdot, p_syms], lm.mass_matrix_full)
    lm_f = sp.lambdify([q, qdot, p_syms], lm.forcing_full)

    def lagranges(qv, qdv):
        x = np.linalg.solve(np.asarray(lm_M(qv, qdv, p_vals), float), np.asarray(lm_f(qv, qdv, p_vals), float).ravel())
        return x[3:6], x[6:]  # (q', q'', lambda)

    # KanesMethod: speeds u = q', q1 independent
    to_u = dict(zip(qdot, u))
    F2.set_ang_vel(N, u[0] * N.z)
    F3.set_ang_vel(F2, u[1] * F2.z)
    F4.set_ang_vel(F3, u[2] * F3.z)
    for C in (C2, C3, C4):
        C.set_vel(N, C.pos_from(O).dt(N).subs(to_u))
    fhd = fh.diff(t).subs(to_u)
    kane = KanesMethod(
        N,
        q_ind=[q[0]],
        u_ind=[u[0]],
        q_dependent=q[1:],
        u_dependent=u[1:],
        kd_eqs=[qd - ui for qd, ui in zip(qdot, u)],
        configuration_constraints=fh,
        velocity_constraints=fhd,
    )
    kane.kanes_equations([rigid("B2", C2, F2, l2), rigid("B3", C3, F3, l3), rigid("B4", C4, F4, l4)], [])
    k_M = sp.lambdify([q, u, p_syms], kane.mass_matrix)
    k_f = sp.lambdify([q, u, p_syms], kane.forcing)

    def kanes(qv, qdv):
        return np.linalg.solve(np.asarray(k_M(qv, qdv, p_vals), float), np.asarray(k_f(qv, qdv, p_vals), float).ravel())

    return lagranges, kanes


def test_four_bar_numeric_is_fast_and_matches_sympy_mechanics(sympy_four_bar):
    lagranges, kanes = sympy_four_bar
    start = time.perf_counter()
    system = four_bar()
    accelerations = system.numeric_accelerations(PARAMS)
    f = system.numeric(PARAMS)
    setup = time.perf_counter() - start
    assert setup < 60.0  # it did not finish in 600 s when the constrained system was inverted symbolically
    for q, qd in _consistent_states(8, seed=3):
        qdd, lam = accelerations(0.0, q, qd)
        qdd_lm, lam_lm = lagranges(q, qd)
        np.testing.assert_allclose(qdd, qdd_lm, rtol=1e-9, atol=1e-12)
        # SymPy's LagrangesMethod puts A^T lambda on the right-hand side; kinedyn on the left
        np.testing.assert_allclose(lam, -lam_lm, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(qdd, kanes(q, qd), rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(f(0.0, np.r_[q, qd]), np.r_[qd, qdd], rtol=1e-12)
    assert np.abs(lam).max() > 1e-3  # the constraint forces are not trivially zero


def test_four_bar_solution_satisfies_the_constrained_equations_derived_here():
    """An independent derivation: the constraint holds to second order, A qdd + d/dt(A) qd = 0 with
    d/dt(A) by finite differences of the closure, and the motion conserves energy and stays closed."""
    system = four_bar()
    accelerations = system.numeric_accelerations(PARAMS)
    for q, qd in _consistent_states(4, seed=5):
        qdd, _ = accelerations(0.0, q, qd)
        # d2/dt2 closure(q(t)) = 0, by a central difference of the closure along the motion
        h = 1e-4
        second = (
            _closure_numeric(q + h * qd + h * h / 2 * qdd)
            - 2 * _closure_numeric(q)
            + _closure_numeric(q - h * qd + h * h / 2 * qdd)
        ) / h**2
        assert np.abs(second).max() < 1e-5
    q0, qd0 = _consistent_states(1, seed=7)[0]
    sol = solve_ivp(system.numeric(PARAMS), (0, 2.0), np.r_[q0, 20 * qd0], rtol=1e-10, atol=1e-12)
    assert sol.success
    H = sp.lambdify([system.q + system.qd], system.energy().subs({sp.Symbol(k): v for k, v in PARAMS.items()}))
    E = np.array([H(x) for x in sol.y.T])
    assert np.ptp(E) < 1e-6 * abs(E[0])
    assert max(np.abs(_closure_numeric(x[:3])).max() for x in sol.y.T) < 1e-6
    assert np.ptp(sol.y[0]) > 0.5  # it really moved


def test_baumgarte_pulls_a_drifted_state_back():
    system = four_bar()
    plain = system.numeric(PARAMS)
    stabilised = system.numeric(PARAMS, baumgarte=(20.0, 20.0))
    q0, qd0 = _consistent_states(1, seed=11)[0]
    x0 = np.r_[q0 + np.array([0.0, 2e-3, -1e-3]), qd0]  # off the manifold
    drift = [
        np.abs(_closure_numeric(solve_ivp(f, (0, 1.0), x0, rtol=1e-10, atol=1e-12).y[:3, -1])).max()
        for f in (plain, stabilised)
    ]
    assert drift[1] < 1e-2 * drift[0]


def test_singular_configuration_is_named():
    (x, y), (xd, yd) = coordinates("x y")
    # two copies of one constraint: A has rank 1, the KKT matrix is singular
    system = LagrangianSystem(
        [x, y], K=(xd**2 + yd**2) / 2, qd=[xd, yd], holonomic=[x - y, 2 * x - 2 * y], forces=[0, 0]
    )
    with pytest.raises(ValueError, match="singular"):
        system.numeric_accelerations()(0.0, [0.1, 0.1], [0.0, 0.0])


def test_four_bar_symbolic_phase_space_and_multipliers_finish_and_agree():
    """phase_space() (one LU elimination of the KKT system) and multipliers() (LU solves, no M^-1)
    finish in seconds for the four-bar and give the numeric solution's q̈ and λ."""
    system = four_bar()
    start = time.perf_counter()
    _, f = system.phase_space()
    lam = system.multipliers()
    assert time.perf_counter() - start < 60.0
    q, qd = _consistent_states(1, seed=3)[0]
    values = {sp.Symbol(k): v for k, v in PARAMS.items()} | dict(zip(system.q, q)) | dict(zip(system.qd, qd))
    evaluate = sp.lambdify([list(values)], list(f[3:]) + list(lam), cse=True)
    got = np.array(evaluate(list(values.values())), dtype=float)
    qdd, multipliers = system.numeric_accelerations(PARAMS)(0.0, q, qd)
    np.testing.assert_allclose(got, np.r_[qdd, multipliers], rtol=1e-8, atol=1e-12)


def test_four_bar_example_is_the_mechanism_derived_here():
    from kinedyn.symbolic import examples

    example, here = examples.four_bar_linkage(), four_bar()
    rename = {sp.Symbol(k, positive=True): sp.Symbol(k) for k in PARAMS} | dict(zip(example.qd, here.qd))
    assert sp.expand(example.L.xreplace(rename) - here.L) == 0
    assert [sp.expand(a.xreplace(rename) - b) for a, b in zip(example.holonomic, here.holonomic)] == [0, 0]
    q, qd = _consistent_states(1, seed=2)[0]
    np.testing.assert_allclose(
        example.numeric_accelerations(PARAMS)(0.0, q, qd)[0],
        here.numeric_accelerations(PARAMS)(0.0, q, qd)[0],
        rtol=1e-12,
    )


def test_numeric_handles_a_lagrangian_not_quadratic_in_the_velocities():
    """L = xd^4 / 12 - x^2 / 2: M = xd^2 depends on the velocity; the Euler-Lagrange equation
    xd^2 xdd + x = 0 (derived here) gives xdd = -x / xd^2."""
    (x,), (xd,) = coordinates("x")
    system = LagrangianSystem([x], L=xd**4 / 12 - x**2 / 2, qd=[xd], forces=[0])
    f = system.numeric()
    np.testing.assert_allclose(f(0.0, [0.3, 1.5]), [1.5, -0.3 / 1.5**2], rtol=1e-12)
