"""The equations of a robot with closed loops (issue 27 §3; docs/closed-loops.md, "The equations"):
the multiplier form M qdd + C qd + g = tau + A^T lambda with phi(q) = 0, and the reduced form, for
the five-bar and the four-bar built as one Robot each with a loop (kinedyn.robots.examples), each
checked by another route: the hand-written closed chain and a Lagrangian written here from the link
energies (five-bar, Spong §9.4), SymPy mechanics' LagrangesMethod and KanesMethod (four-bar), the
numeric core's Jacobians (a weld)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
import sympy as sp
from trig_zero import all_zero

import kinedyn as kd
from kinedyn.description import Frame, Joint, Link
from kinedyn.description.inertia import Inertia
from kinedyn.robots import examples as rex
from kinedyn.symbolic.mechanisms import decoupling_condition

RNG = np.random.default_rng(27)

# SymPy's four-bar test values (tests/test_symbolic_closed_chains.py), with gravity added here
FOUR_BAR = dict(l1=0.13, l2=0.24, l3=0.21, l4=0.34, rho=997.0, g=9.81)
Q_REF = np.array([2.1, 0.6655470375077588, 2.527408138024188])
FIVE_BAR = "l1 l2 lc1 lc2 lc3 lc4 m1 m2 m3 m4 I1 I2 I3 I4 g"


def _values(expr_or_matrix, values: dict):
    """The expression with its parameters (matched by name) replaced by numbers."""
    e = sp.sympify(expr_or_matrix)
    return e.xreplace({s: values[s.name] for s in e.free_symbols if s.name in values})


def _numeric(matrix, args, values):
    return sp.lambdify(args, _values(matrix, values), "numpy")


def _same(a: sp.Matrix, b: sp.Matrix) -> bool:
    return all_zero(a - b)


# ----------------------------------------------------------------------------- four-bar
def _closure_numeric(q):
    """The four-bar's loop written here: link 4's far end minus the ground link's left end."""
    l1, l2, l3, l4 = (FOUR_BAR[k] for k in ("l1", "l2", "l3", "l4"))
    a = np.cumsum(q)
    return np.array(
        [
            l1 + l2 * np.cos(a[0]) + l3 * np.cos(a[1]) + l4 * np.cos(a[2]),
            l2 * np.sin(a[0]) + l3 * np.sin(a[1]) + l4 * np.sin(a[2]),
        ]
    )


def _closed_states(count, seed):
    """(q, qd) on the four-bar's manifold: q1 drawn, q2, q3 by Newton; qd in the null space of the
    closure's finite-difference Jacobian."""
    rng = np.random.default_rng(seed)
    out = []
    h = 1e-7
    for _ in range(count):
        q = Q_REF.copy()
        q[0] += rng.uniform(-0.3, 0.3)
        for _ in range(30):
            J = np.column_stack(
                [(_closure_numeric(q + h * e) - _closure_numeric(q - h * e)) / (2 * h) for e in np.eye(3)[1:]]
            )
            q[1:] -= np.linalg.solve(J, _closure_numeric(q))
        assert np.abs(_closure_numeric(q)).max() < 1e-12
        A = np.column_stack([(_closure_numeric(q + h * e) - _closure_numeric(q - h * e)) / (2 * h) for e in np.eye(3)])
        out.append((q, scipy.linalg.null_space(A)[:, 0] * rng.uniform(-2, 2)))
    return out


@pytest.fixture(scope="module")
def four_bar():
    return rex.four_bar_robot(gravity=True).equations_of_motion()


@pytest.fixture(scope="module")
def sympy_four_bar():
    """The four-bar in SymPy mechanics (frames and points, gravity -g along y): functions
    (q, qd) -> (qdd, lambda) by LagrangesMethod, -> qdd by KanesMethod (q1 independent), and the
    kinetic energy."""
    from sympy.physics.mechanics import (
        KanesMethod,
        LagrangesMethod,
        Lagrangian,
        Point,
        ReferenceFrame,
        RigidBody,
        dynamicsymbols,
        inertia,
        kinetic_energy,
    )

    q = dynamicsymbols("q1:4")
    u = dynamicsymbols("u1:4")
    t = dynamicsymbols._t
    l1, l2, l3, l4, rho, g = sp.symbols("l1:5 rho g")
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
    p_syms = [l1, l2, l3, l4, rho, g]
    p_vals = [FOUR_BAR[str(s)] for s in p_syms]
    qdot = [qi.diff(t) for qi in q]

    def bodies():
        out = []
        for name, C, F, length in (("B2", C2, F2, l2), ("B3", C3, F3, l3), ("B4", C4, F4, l4)):
            b = RigidBody(name, C, F, rho * length, (inertia(F, 0, 0, rho * length**3 / 12), C))
            b.potential_energy = rho * length * g * C.pos_from(O).dot(N.y)
            out.append(b)
        return out

    for C in (C2, C3, C4):
        C.set_vel(N, C.pos_from(O).dt(N))
    lm = LagrangesMethod(Lagrangian(N, *bodies()), q, hol_coneqs=fh, frame=N)
    lm.form_lagranges_equations()
    lm_M = sp.lambdify([q, qdot, p_syms], lm.mass_matrix_full)
    lm_f = sp.lambdify([q, qdot, p_syms], lm.forcing_full)
    energy = sp.lambdify([q, qdot, p_syms], kinetic_energy(N, *bodies()))

    def lagranges(qv, qdv):
        x = np.linalg.solve(np.asarray(lm_M(qv, qdv, p_vals), float), np.asarray(lm_f(qv, qdv, p_vals), float).ravel())
        return x[3:6], x[6:]  # (q', q'', lambda): A^T lambda on the right-hand side, as kinedyn's

    to_u = dict(zip(qdot, u))
    F2.set_ang_vel(N, u[0] * N.z)
    F3.set_ang_vel(F2, u[1] * F2.z)
    F4.set_ang_vel(F3, u[2] * F3.z)
    for C in (C2, C3, C4):
        C.set_vel(N, C.pos_from(O).dt(N).subs(to_u))
    kane = KanesMethod(
        N,
        q_ind=[q[0]],
        u_ind=[u[0]],
        q_dependent=q[1:],
        u_dependent=u[1:],
        kd_eqs=[qd - ui for qd, ui in zip(qdot, u)],
        configuration_constraints=fh,
        velocity_constraints=fh.diff(t).subs(to_u),
    )
    weights = [(C, -rho * length * g * N.y) for C, length in ((C2, l2), (C3, l3), (C4, l4))]
    kane.kanes_equations(bodies(), weights)
    k_M = sp.lambdify([q, u, p_syms], kane.mass_matrix)
    k_f = sp.lambdify([q, u, p_syms], kane.forcing)

    def kanes(qv, qdv):
        return np.linalg.solve(np.asarray(k_M(qv, qdv, p_vals), float), np.asarray(k_f(qv, qdv, p_vals), float).ravel())

    return lagranges, kanes, lambda qv, qdv: float(energy(qv, qdv, p_vals))


def _kkt(eom, values):
    """(q, qd, tau) -> (qdd, lambda) of M qdd + C qd + g = tau + A^T lambda, A qdd + dA/dt qd = 0,
    from the symbolic M, C, g, A (dA/dt qd = d(A qd)/dq qd, formed here)."""
    q, qd = list(eom.q), list(eom.qd)
    drift = (eom.A * eom.qd).jacobian(q) * eom.qd
    M = _numeric(eom.M, [q], values)
    h = _numeric(eom.C * eom.qd + eom.g, [q, qd], values)
    A = _numeric(eom.A, [q], values)
    d = _numeric(drift, [q, qd], values)
    n, k = eom.n, len(eom.phi)

    def solve(qv, qdv, tau):
        Av = np.asarray(A(qv), float)
        K = np.block([[np.asarray(M(qv), float), -Av.T], [Av, np.zeros((k, k))]])
        rhs = np.r_[tau - np.ravel(h(qv, qdv)), -np.ravel(d(qv, qdv))]
        x = np.linalg.solve(K, rhs)
        return x[:n], x[n:]

    return solve


def test_four_bar_multiplier_form_matches_sympy_lagranges_method(four_bar, sympy_four_bar):
    lagranges, kanes, _ = sympy_four_bar
    eom = four_bar
    assert [s.name for s in eom.q] == ["q1", "q2", "q3"] and eom.constraint_rows == ["closure.x", "closure.y"]
    solve = _kkt(eom, FOUR_BAR)
    for q, qd in _closed_states(5, seed=1):
        qdd, lam = solve(q, qd, np.zeros(3))
        qdd_lm, lam_lm = lagranges(q, qd)
        np.testing.assert_allclose(qdd, qdd_lm, rtol=1e-9, atol=1e-10)
        np.testing.assert_allclose(lam, lam_lm, rtol=1e-9, atol=1e-10)  # the same sign: tau + A^T lambda
        np.testing.assert_allclose(qdd, kanes(q, qd), rtol=1e-9, atol=1e-10)
    assert np.abs(lam).max() > 1.0  # the loop carries the links' weight


def test_four_bar_as_a_lagrangian_system_has_the_opposite_multipliers(four_bar):
    """eom.system() is the closed chain as LagrangianSystem (A^T lambda on the left): the same q̈,
    multipliers of the opposite sign."""
    accelerations = four_bar.system().numeric_accelerations(FOUR_BAR)
    solve = _kkt(four_bar, FOUR_BAR)
    q, qd = _closed_states(1, seed=4)[0]
    qdd, lam = solve(q, qd, np.zeros(3))
    qdd_s, lam_s = accelerations(0.0, q, qd)
    np.testing.assert_allclose(qdd_s, qdd, rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(lam_s, -lam, rtol=1e-9, atol=1e-10)


def test_four_bar_reduced_form_matches_kanes_method_and_the_kinetic_energy(four_bar, sympy_four_bar):
    """The velocity map's reduced equations in q1 (q2, q3 dependent): M_r v^2 / 2 is SymPy's kinetic
    energy, and q1's acceleration from M_r, C_r, g_r is KanesMethod's (tau = 0); with a torque tau at
    the three joints, G^T tau drives the same q̈1 as the multiplier form."""
    _, kanes, energy = sympy_four_bar
    red = four_bar.reduced
    assert [s.name for s in red.q] == ["q1"] and [s.name for s in red.dependent] == ["q2", "q3"]
    args = [list(four_bar.q), list(red.qd)]
    M_r = _numeric(red.M, [list(four_bar.q)], FOUR_BAR)
    h_r = _numeric(red.C * red.qd + red.g, args, FOUR_BAR)
    G = _numeric(red.G, [list(four_bar.q)], FOUR_BAR)
    solve = _kkt(four_bar, FOUR_BAR)
    for q, qd in _closed_states(5, seed=2):
        v = qd[:1]
        np.testing.assert_allclose(np.asarray(G(q), float) @ v, qd, rtol=1e-7)  # qd by finite differences
        qd = np.asarray(G(q), float) @ v
        Mr = float(np.asarray(M_r(q), float)[0, 0])
        np.testing.assert_allclose(Mr * v[0] ** 2 / 2, energy(q, qd), rtol=1e-10)
        qdd1 = -float(np.ravel(h_r(q, v))[0]) / Mr
        np.testing.assert_allclose(qdd1, kanes(q, qd)[0], rtol=1e-9)
        tau = RNG.normal(size=3)
        forced = (float(np.ravel(np.asarray(G(q), float).T @ tau)[0]) - float(np.ravel(h_r(q, v))[0])) / Mr
        np.testing.assert_allclose(forced, solve(q, qd, tau)[0][0], rtol=1e-9)


# ----------------------------------------------------------------------------- five-bar
BRANCH = {"phi4": "q2 - q1", "phi3": "q1 - q2"}  # the parallelogram: links 4, 3 parallel to links 2, 1


FILE_BRANCH = {"q4": "q2 - q1", "q3": "q1 - q2"}  # examples/robots/five_bar_symbolic.yaml names link 4's joint q4
FIVE_BAR_FILE = Path(__file__).resolve().parents[1] / "examples" / "robots" / "five_bar_symbolic.yaml"


@pytest.fixture(scope="module", params=["python", "file"])
def five_bar(request):
    """The five-bar built in Python (kinedyn.robots.examples.five_bar_robot) and read from its robot
    file, reduced on the parallelogram branch; the file's symbols renamed to the Python ones (which
    carry positive=True) so that both compare with the same expressions."""
    if request.param == "python":
        return rex.five_bar_robot().equations_of_motion(independent=["q1", "q2"], solution=BRANCH)
    robot = kd.load(FIVE_BAR_FILE)
    same = {s: sp.Symbol(s.name, positive=True) for s in robot.symbols}
    return robot.subs(same).equations_of_motion(independent=["q1", "q2"], solution=FILE_BRANCH)


def _u(angle):
    return sp.Matrix([sp.cos(angle), sp.sin(angle)])


def _direct_five_bar():
    """D, C, g of the five-bar in q1, q2 written here from the link energies: each link's centre of
    mass from the parallelogram's geometry and its angular velocity; K = sum m |v|^2 / 2 + I w^2 / 2,
    P = sum m g y, D = d2K/dqd2, g = dP/dq, C from D's Christoffel symbols (Spong eq. 9.58)."""
    l1, l2, lc1, lc2, lc3, lc4, g = sp.symbols("l1 l2 lc1 lc2 lc3 lc4 g", positive=True)
    m = sp.symbols("m1:5", positive=True)
    I = sp.symbols("I1:5", positive=True)
    q1, q2, qd1, qd2 = sp.symbols("q1 q2 qdot1 qdot2", real=True)
    q, qd = [q1, q2], sp.Matrix([qd1, qd2])
    A, B = l1 * _u(q1), l2 * _u(q2)  # the tips of links 1 and 2
    centres = [lc1 * _u(q1), lc2 * _u(q2), B + lc3 * _u(q1), A - lc4 * _u(q2)]
    turns = [qd1, qd2, qd1, qd2]  # links 1 and 3 stay parallel, as do links 2 and 4
    K = sum(
        (
            m[i] * (r.jacobian(q) * qd).dot(r.jacobian(q) * qd) / 2 + I[i] * w**2 / 2
            for i, (r, w) in enumerate(zip(centres, turns))
        ),
        sp.Integer(0),
    )
    P = sum((m[i] * g * r[1] for i, r in enumerate(centres)), sp.Integer(0))
    D = sp.hessian(K, list(qd)).applyfunc(sp.simplify)
    G = sp.Matrix([sp.diff(P, c) for c in q])
    C = sp.zeros(2, 2)
    for k in range(2):
        for j in range(2):
            C[k, j] = sum(
                (sp.diff(D[k, j], q[i]) + sp.diff(D[k, i], q[j]) - sp.diff(D[i, j], q[k])) / 2 * qd[i] for i in range(2)
            )
    return D, C, G, (q1, q2, qd1, qd2)


def test_five_bar_reduced_equations_match_the_closed_chain_and_a_direct_lagrangian(five_bar):
    red = five_bar.reduced
    assert [s.name for s in red.q] == ["q1", "q2"] and len(five_bar.q) == 4
    assert [r[-2:] for r in five_bar.constraint_rows] == [".x", ".y"]  # z vanishes identically: planar
    chains = rex.five_bar_from_chains()  # two DH chains and their closure (kinedyn.symbolic.mechanisms)
    D, C, g, (q1, q2, qd1, qd2) = _direct_five_bar()
    rename = {q1: red.q[0], q2: red.q[1], qd1: red.qd[0], qd2: red.qd[1]}
    for mine, theirs, direct in ((red.M, chains.M, D), (red.C, chains.C, C), (red.g, chains.g, g)):
        assert _same(mine, theirs.xreplace({a: b for a, b in zip(chains.q, red.q)} | dict(zip(chains.qd, red.qd))))
        assert _same(mine, direct.xreplace(rename))


def test_five_bar_decoupling_condition(five_bar):
    """D is diagonal (and constant) exactly when m3 l2 lc3 = m4 l1 lc4: the condition found on the
    robot's reduced D equals the coefficient of cos(q1 - q2) in the direct Lagrangian's D12, and under
    it D is constant and C vanishes."""
    red = five_bar.reduced
    D, _, _, (q1, q2, _, _) = _direct_five_bar()
    coefficient = sp.expand(sp.expand_trig(D[0, 1])).coeff(sp.cos(q1) * sp.cos(q2))  # D12 = k cos(q1 - q2)
    assert sp.expand(sp.expand_trig(D[0, 1] - coefficient * sp.cos(q1 - q2))) == 0 and coefficient != 0
    conditions, solution = decoupling_condition(red, solve_for="m3")
    assert len(conditions) == 1
    assert sp.expand((conditions[0].lhs - conditions[0].rhs) ** 2 - coefficient**2) == 0
    m3 = next(s for s in red.parameters if s.name == "m3")
    assert sp.simplify(coefficient.xreplace({sp.Symbol("m3", positive=True): solution[m3]})) == 0
    decoupled = red.subs({m3: solution[m3]})
    assert sp.simplify(decoupled.M[0, 1]) == 0 and not decoupled.M.free_symbols & set(red.q)
    assert decoupled.C.applyfunc(sp.simplify) == sp.zeros(2, 2)
    assert decoupling_condition(red, solve_for="m3", constant=True)[1] == solution


def test_five_bar_velocity_map_agrees_with_the_explicit_branch():
    """Without the branch, the velocity map in q1, q2 (G from A at each configuration) gives on the
    parallelogram the explicit reduction's D, C, g (numbers for the parameters: the symbolic map of
    15 parameters is large)."""
    values = {n: float(RNG.uniform(0.5, 2.0)) for n in FIVE_BAR.split()}
    robot = rex.five_bar_robot().subs(values)
    eom = robot.equations_of_motion(independent=["q1", "q2"], steps=False)
    red = eom.reduced
    explicit = rex.five_bar_robot().equations_of_motion(independent=["q1", "q2"], solution=BRANCH, steps=False).reduced
    q_all = list(eom.q)
    parts = [_numeric(m, [q_all, list(red.qd)], {}) for m in (red.M, red.C, red.g)]
    expected = [
        _numeric(m, [list(explicit.q), list(explicit.qd)], values) for m in (explicit.M, explicit.C, explicit.g)
    ]
    for _ in range(4):
        q, v = RNG.uniform(-np.pi, np.pi, 2), RNG.normal(size=2)
        on_branch = np.array([q[0], q[1] - q[0], q[1], q[0] - q[1]])
        for got, want in zip(parts, expected):
            np.testing.assert_allclose(np.asarray(got(on_branch, v), float), np.asarray(want(q, v), float), atol=1e-10)


# ----------------------------------------------------------------------------- properties
def test_skew_symmetry_is_proved_on_both_reduced_forms(four_bar, five_bar):
    for eom, lagrange in ((four_bar, "skipped"), (five_bar, "proved")):
        report = eom.check_properties()
        status = {c.name: c.status for c in report.checks}
        assert status["dD/dt - 2C skew-symmetric"] == "proved", report
        assert status["dD/dt == C + C^T"] == "proved", report
        assert status["D qdd + C qd + g == d/dt dL/dqd - dL/dq"] == lagrange
        assert report.passed


def test_a_wrong_reduced_coriolis_matrix_fails_the_proof(four_bar):
    """The proof runs along the dependent coordinates' rates too: C_r without its dG/dt part is caught."""
    from kinedyn.analysis import prove_properties
    from kinedyn.symbolic.systems.closed_loops import ReducedEquations

    red = four_bar.reduced
    G = red.G
    wrong = G.T * four_bar.C.xreplace(dict(zip(four_bar.qd, G * red.qd))) * G  # G^T C G alone
    broken = ReducedEquations(
        red.q, red.qd, red.qdd, red.M, wrong, red.g, dependent=red.dependent, dependent_rates=red.dependent_rates, G=G
    )
    status = {c.name: c.status for c in prove_properties(broken).checks}
    assert status["dD/dt - 2C skew-symmetric"] == "failed"


def test_properties_refuse_a_robot_whose_loop_cannot_close():
    """A point loop out of reach for every length drawn: no closed configuration, no reduced form, and
    check_properties says why; the numeric checks refuse any robot with loops."""
    arm = kd.robots.planar_2r(symbolic=True)
    l1 = next(s for s in arm.symbols if s.name == "l1")
    T = sp.eye(4)
    T[0, 3] = 10 * l1 + 10
    arm = arm.replace(frames=(*arm.frames, Frame("far", None, T))).add_loop("tool", "far")
    eom = arm.equations_of_motion(steps=False)
    assert eom.reduced is None and "no closed configuration" in eom.reduced_note
    with pytest.raises(ValueError, match="reduced equations of a robot with loops.*no closed configuration"):
        eom.check_properties()
    with pytest.raises(ValueError, match="loops"):
        kd.analysis.check_properties(kd.robots.planar_2r().add_loop("tool", "base"))


# ----------------------------------------------------------------------------- a weld, the numeric core
def _translation(x, y=0.0):
    T = np.eye(4)
    T[:2, 3] = x, y
    return T


def _planar_4r():
    """Links of lengths 1, 0.8, 0.7, 0.6 about z; a frame ``dock`` on the base at (1.5, 0.3)."""
    links, parent = [], None
    for k, length in enumerate((0.0, 1.0, 0.8, 0.7)):  # each joint at the previous link's length
        inertia = Inertia(1.0, (0.3, 0, 0), np.diag([0.0, 0.1, 0.1]))
        links.append(
            Link(
                f"link{k + 1}", parent, Joint(f"q{k + 1}", "revolute", (0, 0, 1)), _translation(length), inertia=inertia
            )
        )
        parent = f"link{k + 1}"
    frames = [Frame("tip", "link4", _translation(0.6)), Frame("dock", None, _translation(1.5, 0.3))]
    return kd.Robot(links, frames, gravity=(0, -9.81, 0), name="planar 4R")


def test_weld_rows_are_the_relative_twist_of_the_numeric_core():
    """A planar 4R arm welded at its tip to a base frame: rows x, y and rz (the others vanish
    identically); A = dphi/dq equals the core's J_tip - J_dock (world) on the linear rows everywhere
    and on the rotation row at a closed configuration; one degree of freedom is left, and the
    velocity map keeps the weld closed."""
    robot = _planar_4r().add_loop("tip", "dock", kind="weld", name="dock")
    eom = robot.equations_of_motion(steps=False)
    assert eom.constraint_rows == ["dock.x", "dock.y", "dock.rz"]
    q = list(eom.q)
    A = _numeric(eom.A, [q], {})
    phi = _numeric(eom.phi, [q], {})
    x = RNG.uniform(-np.pi, np.pi, 4)
    J = robot.jacobian(x, "tip") - robot.jacobian(x, "dock")
    np.testing.assert_allclose(np.asarray(A(x), float)[:2], J[:2], atol=1e-12)
    closed = False
    while not closed:  # Gauss-Newton onto the weld, from random starts until the frames coincide
        x = RNG.uniform(-np.pi, np.pi, 4)
        for _ in range(50):
            x -= np.linalg.lstsq(np.asarray(A(x), float), np.ravel(phi(x)), rcond=None)[0]
        closed = np.allclose(robot.pose(x, "tip"), robot.pose(x, "dock"), atol=1e-10)  # not the half-turn
    assert np.abs(np.ravel(phi(x))).max() < 1e-12
    J = robot.jacobian(x, "tip") - robot.jacobian(x, "dock")
    np.testing.assert_allclose(np.asarray(A(x), float), J[[0, 1, 5]], atol=1e-10)
    red = eom.reduced
    assert len(red.q) == 1 and len(red.dependent) == 3
    G = _numeric(red.G, [q], {})
    np.testing.assert_allclose(J[[0, 1, 5]] @ np.asarray(G(x), float), 0.0, atol=1e-10)  # the map keeps it welded


# ----------------------------------------------------------------------------- steps, LaTeX, errors
def test_steps_and_latex_of_a_closed_chain(tmp_path, four_bar):
    titles = [s.title for s in four_bar.steps]
    assert any(t.startswith("Loop closure") for t in titles)
    assert any(t.startswith("Constraint Jacobian") for t in titles)
    assert any(t.startswith("Independent coordinates") for t in titles)
    assert any(t.startswith("Reduced equations") for t in titles)
    text = str(four_bar)
    assert "tau + A(q)^T lambda" in text and "M_r(q)" in text
    doc = four_bar.to_latex_document()
    assert r"A(q)^{T}\lambda" in doc and r"\phi" in doc
    assert r"A(q)^{T}\lambda" in four_bar.to_markdown() and "A(q)^T lambda" in four_bar.to_mathml()
    if shutil.which("pdflatex") is None:
        pytest.skip("pdflatex is not installed")
    (tmp_path / "doc.tex").write_text(doc)
    run = subprocess.run(
        ["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stdout[-2000:]


def test_bad_reduction_requests_are_named():
    robot = rex.five_bar_robot()
    with pytest.raises(ValueError, match="give 2 independent coordinates, got 1"):
        _ = robot.equations_of_motion(independent=["q1"], steps=False).reduced
    with pytest.raises(ValueError, match="'q9' is not a joint coordinate"):
        _ = robot.equations_of_motion(independent=["q1", "q9"], steps=False).reduced
    with pytest.raises(ValueError, match="does not close the loop"):
        _ = robot.equations_of_motion(solution={"phi4": "q2 - q1", "phi3": "q2 - q1"}, steps=False).reduced
    with pytest.raises(ValueError, match="has none"):
        kd.robots.planar_2r().equations_of_motion(independent=["q1"])


def test_cli_check_proves_on_the_reduced_model_and_measures_it_without_prove(tmp_path, capsys):
    from kinedyn.cli import main

    path = tmp_path / "four_bar.yaml"
    rex.four_bar_robot().subs(dict(l1=2, l2=3, l3=4, l4=5, rho=1)).save(path)
    # the file's numbers load as floats: the identities are sampled there, not proved exactly
    assert main(["check", str(path), "--prove", "--samples", "8", "--json"]) in (0, 2)
    checks = {c["name"]: c for c in json.loads(capsys.readouterr().out)["checks"]}
    assert checks["reduced model: D symmetric"]["status"] == "proved"
    assert checks["reduced model: dD/dt - 2C skew-symmetric"]["status"] in ("proved", "sampled", "failed")
    # without --prove: the numeric reduced equations at sampled closed states (kinedyn.analysis.closed_properties)
    assert main(["check", str(path), "--samples", "8", "--json"]) == 0
    checks = {c["name"]: c for c in json.loads(capsys.readouterr().out)["checks"]}
    assert checks["dM_r/dt - 2C_r skew-symmetric"]["passed"] and checks["M_r symmetric positive definite"]["passed"]


def test_newton_euler_tree_gives_the_same_closed_chain(four_bar):
    """The tree's equations by the customised Newton-Euler model: the same closure, A and reduced M_r."""
    eom = rex.four_bar_robot(gravity=True).equations_of_motion(method="newton_euler", steps=False)
    assert eom.method == "newton_euler" and eom.phi == four_bar.phi and eom.A == four_bar.A
    assert sp.simplify(eom.reduced.M[0, 0] - four_bar.reduced.M[0, 0]) == 0
    assert sp.simplify(eom.reduced.g[0] - four_bar.reduced.g[0]) == 0
