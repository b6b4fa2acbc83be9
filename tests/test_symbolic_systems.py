"""General Lagrangian systems (kd.LagrangianSystem) and the seed's example mechanisms (issue 4)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import kinedyn as kd
from kinedyn.robots import examples as rex
from kinedyn.symbolic import LagrangianSystem, coordinates
from kinedyn.symbolic import examples as ex

RNG = np.random.default_rng(13)


def _values(system, **given):
    """Random positive values for every parameter symbol of a system (by name), some fixed."""
    names = sorted(
        {s.name for s in system.L.free_symbols} - {c.name for c in system.q + system.qd}
        | {s.name for e in system.B for s in e.free_symbols} - {c.name for c in system.q + system.qd}
    )
    out = {n: float(RNG.uniform(0.5, 2.0)) for n in names}
    out.update(given)
    return out


# ----------------------------------------------------------------------------------------------
def test_remotely_driven_arm_has_no_coriolis_but_centrifugal_terms():
    s = ex.remotely_driven_arm()
    eom = s.equations_of_motion()
    pd1, pd2 = eom.qd
    h = (eom.C * eom.qd).applyfunc(sp.expand)
    for e in h:
        assert sp.Poly(e, pd1, pd2).coeff_monomial(pd1 * pd2) == 0  # no Coriolis term
    assert sp.Poly(h[0], pd1, pd2).coeff_monomial(pd2**2) != 0  # centrifugal coupling remains
    assert sp.Poly(h[1], pd1, pd2).coeff_monomial(pd1**2) != 0
    # an independent route: the planar elbow's D in joint angles, changed to absolute angles
    # (q1 = p1, q2 = p2 - p1, so qd = T pd with T = [[1, 0], [-1, 1]]): D_p = T^T D_q T
    arm = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    p1, p2 = eom.q
    T = sp.Matrix([[1, 0], [-1, 1]])
    Dq = arm.M.xreplace({arm.q[0]: p1, arm.q[1]: p2 - p1})
    Dp = T.T * Dq * T
    assert (Dp - eom.M).applyfunc(lambda e: sp.expand(sp.expand_trig(e))) == sp.zeros(2, 2)


def test_five_bar_decoupling_condition():
    s = ex.five_bar()
    eom = s.equations_of_motion()
    m3, m4, l1, l2, lc3, lc4 = sp.symbols("m3 m4 l1 l2 lc3 lc4", positive=True)
    q1, q2 = eom.q
    # D12 vanishes identically exactly when m3 l2 lc3 = m4 l1 lc4
    decoupled = {m3: m4 * l1 * lc4 / (l2 * lc3)}
    assert sp.simplify(eom.M[0, 1].subs(decoupled)) == 0
    assert not (eom.M.subs(decoupled).applyfunc(sp.simplify)).free_symbols & {q1, q2}  # constant D
    assert (eom.C.subs(decoupled)).applyfunc(sp.simplify) == sp.zeros(2, 2)  # no Coriolis/centrifugal
    # and not otherwise: at a random parameter set violating the condition D12 != 0
    vals = _values(s)
    assert (
        abs(float(eom.M[0, 1].subs({sp.Symbol(k, positive=True): v for k, v in vals.items()}).subs({q1: 0.3, q2: 1.1})))
        > 1e-6
    )
    # gravity of each coordinate depends on that coordinate only (Spong's phi_1(q1), phi_2(q2))
    assert not eom.g[0].has(q2) and not eom.g[1].has(q1)


def test_five_bar_inertia_matrix_from_positions_written_here():
    """D from the centres of mass written out component by component (an independent route)."""
    s = ex.five_bar()
    eom = s.equations_of_motion()
    l1, l2, lc1, lc2, lc3, lc4 = sp.symbols("l1 l2 lc1 lc2 lc3 lc4", positive=True)
    m = sp.symbols("m1:5", positive=True)
    I = sp.symbols("I1:5", positive=True)
    q1, q2 = eom.q
    x = [lc1 * sp.cos(q1), lc2 * sp.cos(q2), l2 * sp.cos(q2) + lc3 * sp.cos(q1), l1 * sp.cos(q1) - lc4 * sp.cos(q2)]
    y = [lc1 * sp.sin(q1), lc2 * sp.sin(q2), l2 * sp.sin(q2) + lc3 * sp.sin(q1), l1 * sp.sin(q1) - lc4 * sp.sin(q2)]
    D = sp.diag(I[0] + I[2], I[1] + I[3])
    for i in range(4):
        J = sp.Matrix([[sp.diff(x[i], q1), sp.diff(x[i], q2)], [sp.diff(y[i], q1), sp.diff(y[i], q2)]])
        D += m[i] * J.T * J
    assert (D - eom.M).applyfunc(lambda e: sp.simplify(e)) == sp.zeros(2, 2)


def test_sphere_particle_moves_on_a_great_circle():
    s = ex.sphere_particle()
    f = s.numeric()
    q0 = np.array([1.0, 0.0, 0.0])
    v0 = np.array([0.0, 0.6, 0.8]) * 1.7  # tangent: q0 . v0 = 0
    sol = solve_ivp(f, (0, 6.0), np.r_[q0, v0], rtol=1e-10, atol=1e-12, dense_output=True)
    assert sol.success
    Q = sol.y[:3].T
    normal = np.cross(q0, v0) / np.linalg.norm(np.cross(q0, v0))
    np.testing.assert_allclose(np.linalg.norm(Q, axis=1), 1.0, atol=1e-7)  # stays on the sphere
    np.testing.assert_allclose(Q @ normal, 0.0, atol=1e-7)  # in the plane through the centre
    speed = np.linalg.norm(sol.y[3:].T, axis=1)
    np.testing.assert_allclose(speed, speed[0], rtol=1e-7)  # no gravity: constant speed
    assert np.ptp(Q[:, 1]) > 1.0  # it really travelled


def test_multipliers_keep_the_constraint_which_the_printed_formula_does_not():
    """lambda with the (dA/dt) qd term keeps |q| = 1; LaValle's printed 13.180 (without it) drifts."""
    s = ex.sphere_particle()
    lam = s.multipliers(u=[0, 0, 0])
    q, qd = s.q, s.qd
    # at |q| = 1, m = 2: lambda = |qd|^2 / 2 . Derived here: A = 2 q^T, A qdd + 2 |qd|^2 = 0 and
    # 2 qdd = -2 q lambda  ->  qdd = -lambda q  ->  -2 lambda + 2 |qd|^2 = 0
    state = {q[0]: 0.6, q[1]: 0.0, q[2]: 0.8, qd[0]: 0.3, qd[1]: 1.2, qd[2]: -0.225}
    np.testing.assert_allclose(float(lam[0].subs(state)), 0.3**2 + 1.2**2 + 0.225**2, rtol=1e-12)


def _energy_drift(system, values, x0, T=3.0):
    f = system.numeric(values)
    H = sp.lambdify(
        [system.q + system.qd],
        system.energy().subs({sp.Symbol(k, positive=True): v for k, v in values.items()}),
        "numpy",
    )
    sol = solve_ivp(f, (0, T), x0, rtol=1e-10, atol=1e-12)
    assert sol.success
    E = np.array([H(x) for x in sol.y.T])
    return np.abs(E - E[0]).max() / max(1.0, abs(E[0]))


@pytest.mark.parametrize(
    "factory", [ex.remotely_driven_arm, ex.five_bar, ex.falling_particle], ids=["remote", "five_bar", "falling"]
)
def test_energy_is_conserved(factory):
    s = factory()
    vals = _values(s)
    n = s.n
    x0 = np.r_[RNG.uniform(-1, 1, n), RNG.normal(size=n)]
    assert _energy_drift(s, vals, x0) < 1e-7


def test_geared_link_energy_conserved_without_damping_and_dissipated_with_it():
    s = ex.geared_link()
    vals = dict(J_l=0.4, J_m=0.01, M=1.5, g=9.81, ell=0.3, r=10.0, B_m=0.0, tau_m=0.0)
    assert _energy_drift(s, vals, np.array([1.0, 0.0])) < 1e-8
    vals["B_m"] = 0.02
    assert _energy_drift(s, vals, np.array([1.0, 0.0])) > 1e-2


def test_geared_link_system_equals_robot_description():
    """The Lagrangian system and the Robot (gear ratio, rotor inertia, viscous friction) agree:
    theta_sys = theta_robot + pi/2 (hanging down vs. along x)."""
    s = ex.geared_link()
    es = s.equations_of_motion()
    er = rex.geared_link_robot().equations_of_motion()
    th_r, thd, thdd = er.q[0], er.qd[0], er.qdd[0]
    lhs_sys = (es.M * sp.Matrix(es.qdd) + es.C * sp.Matrix(es.qd) + es.g + s.B)[0]
    lhs_sys = lhs_sys.subs({es.q[0]: th_r + sp.pi / 2, es.qd[0]: thd, es.qdd[0]: thdd})
    assert sp.simplify(lhs_sys - er.tau[0]) == 0
    r, tau_m = sp.symbols("r tau_m", positive=True)
    assert s.u[0] == r * tau_m  # the motor torque reaches the link multiplied by the gear ratio


def test_falling_particle_and_simple_variational_problem():
    s = ex.falling_particle()
    x, f = s.phase_space(u=[0, 0, 0])
    m, g = sp.symbols("m g", positive=True)
    assert list(f[3:]) == [0, 0, -g]
    v = ex.simple_variational()
    (x,), (xdd,) = v.q, v.qdd
    assert sp.expand(v.euler_lagrange()[0] - (2 * xdd - 3 * x**2)) == 0


def test_hamiltonian_form_matches_lagrange():
    s = ex.remotely_driven_arm()
    vals = _values(s)
    p, H, qdot, pdot = s.hamiltonian()
    num = {sp.Symbol(k, positive=True): v for k, v in vals.items()}
    q = RNG.uniform(-1, 1, 2)
    qd = RNG.normal(size=2)
    M = sp.hessian(s.L, s.qd).subs(num).subs(dict(zip(s.q, q)))
    pv = np.array(M, dtype=float) @ qd
    state = {**dict(zip(s.q, q)), **dict(zip(p, pv)), **num, **{u: 0 for u in s.u}}
    np.testing.assert_allclose(np.array(qdot.subs(state), dtype=float).ravel(), qd, rtol=1e-10)
    # pdot = dL/dq at the same state (Euler-Lagrange with u = 0)
    dLdq = [sp.diff(s.L, c).subs(num).subs({**dict(zip(s.q, q)), **dict(zip(s.qd, qd))}) for c in s.q]
    np.testing.assert_allclose(np.array(pdot.subs(state), dtype=float).ravel(), np.array(dLdq, dtype=float), rtol=1e-9)


def test_lagrangian_given_directly_and_dynamicsymbols():
    from sympy.physics.mechanics import dynamicsymbols

    th = dynamicsymbols("th")
    t = sp.Symbol("t")
    m, l, g = sp.symbols("m l g", positive=True)
    L = m * l**2 * sp.diff(th, t) ** 2 / 2 + m * g * l * sp.cos(th)
    s = LagrangianSystem([th], L=L)
    eom = s.equations_of_motion()
    assert sp.expand(eom.M[0, 0] - m * l**2) == 0
    assert sp.expand(eom.g[0] - m * g * l * sp.sin(s.q[0])) == 0


def test_pfaffian_constraint_rolling_disk_keeps_velocity_constraint():
    """A Pfaffian (non-holonomic) constraint: a knife edge on a plane, x' sin(th) - y' cos(th) = 0."""
    (x, y, th), (xd, yd, thd) = coordinates("x y th")
    s = LagrangianSystem(
        [x, y, th],
        K=(xd**2 + yd**2) / 2 + thd**2 / 10,
        P=0,
        qd=[xd, yd, thd],
        pfaffian=sp.Matrix([[sp.sin(th), -sp.cos(th), 0]]),
        forces=[0, 0, 0],
    )
    f = s.numeric()
    sol = solve_ivp(f, (0, 3), [0, 0, 0.3, np.cos(0.3), np.sin(0.3), 1.0], rtol=1e-10, atol=1e-12)
    X = sol.y
    resid = X[3] * np.sin(X[2]) - X[4] * np.cos(X[2])
    assert np.abs(resid).max() < 1e-7


# ----------------------------------------------------------------------------------------------
# bad input
def test_coordinate_missing_from_kinetic_energy():
    (x, y), (xd, yd) = coordinates("x y")
    with pytest.raises(ValueError, match="does not appear in the kinetic energy"):
        LagrangianSystem([x, y], K=xd**2 / 2, P=0, qd=[xd, yd])


def test_constraint_with_wrong_shape():
    (x, y), (xd, yd) = coordinates("x y")
    with pytest.raises(ValueError, match=r"shape \(k, 2\)"):
        LagrangianSystem([x, y], K=(xd**2 + yd**2) / 2, qd=[xd, yd], pfaffian=sp.Matrix([[1, 0, 0]]))
    with pytest.raises(ValueError, match="must be a vector"):
        LagrangianSystem([x, y], K=(xd**2 + yd**2) / 2, qd=[xd, yd], holonomic=sp.Matrix([[x, y], [y, x]]))
    with pytest.raises(ValueError, match="depends on velocities"):
        LagrangianSystem([x, y], K=(xd**2 + yd**2) / 2, qd=[xd, yd], holonomic=[x * xd])


def test_energies_as_strings_use_the_systems_own_symbols():
    """Names in a string are the coordinates' real symbols: "x_d" in K used to be another, plain
    symbol, and the check then said x_d does not appear in K while listing it."""
    (x,), (xd,) = coordinates("x")
    written = LagrangianSystem([x], K="m*x_d**2/2", P="k*x**2/2", B=["c*x_d"])
    made = LagrangianSystem([x], K=sp.Symbol("m") * xd**2 / 2, P=sp.Symbol("k") * x**2 / 2, B=[sp.Symbol("c") * xd])
    assert written.equations_of_motion().tau == made.equations_of_motion().tau
    (p, r), _ = coordinates("p r")
    sphere = LagrangianSystem(["p", "r"], L="(p_d**2 + r_d**2)/2", holonomic=["p**2 + r**2 - 1"])
    assert sphere.holonomic == [p**2 + r**2 - 1]


def test_energies_that_are_not_one_expression_are_named():
    (x,), (xd,) = coordinates("x")
    with pytest.raises(ValueError, match="kinetic energy K could not be read as an expression"):
        LagrangianSystem([x], K="m*x_d**2*(", P=0)
    with pytest.raises(ValueError, match="kinetic energy K must be one scalar expression"):
        LagrangianSystem([x], K=[xd**2, xd], P=0)
    with pytest.raises(ValueError, match="potential energy P contains NaN"):
        LagrangianSystem([x], K=xd**2 / 2, P=float("nan"))


def test_non_symbol_coordinate():
    x, y = sp.symbols("x y")
    with pytest.raises(ValueError, match="is not a symbol"):
        LagrangianSystem([x + y], K=x**2)
    with pytest.raises(ValueError, match="is not a symbol"):
        LagrangianSystem([sp.Integer(3)], K=x**2)
    with pytest.raises(ValueError, match="not a valid symbol name"):
        LagrangianSystem(["2x"], K=x**2)


def test_robot_phase_space():
    eom = kd.robots.planar_2r().equations_of_motion(steps=False)
    x, f, u = eom.phase_space()
    q = np.array([0.3, -0.4])
    qd = np.array([0.5, 1.0])
    tau = np.array([1.0, -2.0])
    F = sp.lambdify([list(x), list(u)], f, "numpy")
    M = np.array(eom.M.subs(dict(zip(eom.q, q))), dtype=float)
    bias = np.array(
        (eom.C * eom.qd + eom.g).subs({**dict(zip(eom.q, q)), **dict(zip(eom.qd, qd))}), dtype=float
    ).ravel()
    np.testing.assert_allclose(
        np.array(F(np.r_[q, qd], tau), dtype=float).ravel()[2:], np.linalg.solve(M, tau - bias), rtol=1e-10
    )
