"""Symbolic equations of motion of robots (issue 4).

Every symbolic quantity is checked against numbers computed by an independent route written here
(NumPy forward kinematics, finite-difference Jacobians, Spong eq. 9.46 for D, finite differences of D
for the Christoffel symbols and of P for g), and, when the native module is built, against the
numeric engine. Small arms are also compared symbolically with closed forms derived in this file.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.description.dh import DHRow
from kinedyn.description.inertia import Inertia
from kinedyn.symbolic import EquationsOfMotion

warnings.filterwarnings("ignore", message=".*triangle inequality.*")

RNG = np.random.default_rng(4)


# ----------------------------------------------------------------------------------------------
# an independent numeric Euler-Lagrange evaluation (NumPy FK, geometric Jacobians, finite differences)
def _rot(axis, angle):
    a = np.asarray(axis, float)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def _fk(robot, q):
    """World poses of the bodies: T_i = T_parent placement motion(q_i + offset)."""
    out = []
    for i, b in enumerate(robot.tree.bodies):
        P = np.asarray(b.placement, float)
        Jm = np.eye(4)
        x = q[i] + float(b.joint.offset)
        if b.joint.kind == "revolute":
            Jm[:3, :3] = _rot(b.joint.axis, x)
        else:
            Jm[:3, 3] = np.asarray(b.joint.axis, float) * x
        T = (out[b.parent] if b.parent >= 0 else np.eye(4)) @ P @ Jm
        out.append(T)
    return out


def _com_and_R(robot, q):
    Ts = _fk(robot, q)
    return [T[:3, :3] @ np.asarray(b.inertia.com, float) + T[:3, 3] for T, b in zip(Ts, robot.tree.bodies)], [
        T[:3, :3] for T in Ts
    ]


def numeric_M(robot, q):
    """D = sum m Jvc^T Jvc + Jw^T R I R^T Jw + diag(armature) (Spong 9.46) with the geometric Jacobians
    of the textbook: column j of an ancestor joint is z_j x (p_ci - o_j), z_j (revolute) or z_j, 0
    (prismatic), z_j and o_j the joint's world axis and origin."""
    n = robot.n
    bodies = robot.tree.bodies
    Ts = _fk(robot, q)
    z, o = [], []
    for b in bodies:
        F = (Ts[b.parent] if b.parent >= 0 else np.eye(4)) @ np.asarray(
            b.placement, float
        )  # joint frame, before motion
        z.append(F[:3, :3] @ np.asarray(b.joint.axis, float))
        o.append(F[:3, 3])
    D = np.diag([float(b.joint.armature) for b in bodies])
    for i, b in enumerate(bodies):
        pc = Ts[i][:3, :3] @ np.asarray(b.inertia.com, float) + Ts[i][:3, 3]
        Jv, Jw = np.zeros((3, n)), np.zeros((3, n))
        j = i
        while j >= 0:
            if bodies[j].joint.kind == "revolute":
                Jv[:, j] = np.cross(z[j], pc - o[j])
                Jw[:, j] = z[j]
            else:
                Jv[:, j] = z[j]
            j = bodies[j].parent
        R = Ts[i][:3, :3]
        Ic = np.asarray(b.inertia.inertia, float)
        D += float(b.inertia.mass) * Jv.T @ Jv + Jw.T @ R @ Ic @ R.T @ Jw
    return D


def numeric_P(robot, q):
    c, _ = _com_and_R(robot, q)
    g = np.asarray(robot.gravity, float)
    return -sum(float(b.inertia.mass) * g @ ci for b, ci in zip(robot.tree.bodies, c))


def numeric_g(robot, q, h=1e-6):
    n = robot.n
    out = np.zeros(n)
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        out[j] = (numeric_P(robot, q + e) - numeric_P(robot, q - e)) / (2 * h)
    return out


def numeric_C(robot, q, qd, h=1e-5):
    """C[k, j] = sum_i c_ijk qd_i with c_ijk from central differences of D (Spong 9.58, 9.62)."""
    n = robot.n
    dD = np.zeros((n, n, n))  # dD[:, :, i] = dD/dq_i
    for i in range(n):
        e = np.zeros(n)
        e[i] = h
        dD[:, :, i] = (numeric_M(robot, q + e) - numeric_M(robot, q - e)) / (2 * h)
    C = np.zeros((n, n))
    for k in range(n):
        for j in range(n):
            C[k, j] = sum(0.5 * (dD[k, j, i] + dD[k, i, j] - dD[i, j, k]) * qd[i] for i in range(n))
    return C


def evaluate(eom: EquationsOfMotion, expr, q, qd=None, qdd=None, values=None):
    values = dict(values or {})
    sub = {s: values[str(s)] for s in eom.parameters if str(s) in values}
    sub.update(dict(zip(eom.q, q)))
    if qd is not None:
        sub.update(dict(zip(eom.qd, qd)))
    if qdd is not None:
        sub.update(dict(zip(eom.qdd, qdd)))
    out = sp.sympify(expr).xreplace(sub) if not isinstance(expr, sp.MatrixBase) else expr.xreplace(sub)
    return np.array(sp.N(out, 17).tolist() if isinstance(out, sp.MatrixBase) else float(out), dtype=float)


def symbolic_elbow():
    """The elbow arm of the tutorial with symbolic lengths and masses (uniform rods), built from DH
    rows with a numeric +90 deg twist (sin(pi/2) = 1.0 exactly in floats; cos is round-off)."""
    L1, L2, L3, m1, m2, m3, g = sp.symbols("L1 L2 L3 m1 m2 m3 g", positive=True)
    rod = lambda m, L: Inertia(m, (L / 2 - L, 0, 0), ((0, 0, 0), (0, m * L**2 / 12, 0), (0, 0, m * L**2 / 12)))
    link1 = Inertia(m1, (0, -L1 / 2, 0), ((m1 * L1**2 / 12, 0, 0), (0, 0, 0), (0, 0, m1 * L1**2 / 12)))
    rows = [
        DHRow(d=L1, alpha=math.pi / 2, inertia=link1),
        DHRow(a=L2, inertia=rod(m2, L2)),
        DHRow(a=L3, inertia=rod(m3, L3)),
    ]
    return kd.Robot.from_dh(rows, gravity=(0, 0, -g), name="elbow_sym")


PLANAR_VALUES = dict(l1=1.3, l2=0.9, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13, g=9.81)
ELBOW_VALUES = dict(L1=0.7, L2=1.1, L3=0.8, m1=2.0, m2=1.5, m3=1.2, g=9.81)
PLANAR3_VALUES = dict(l1=1.0, l2=0.8, l3=0.5, m1=1.0, m2=1.2, m3=0.7, g=9.81)


def _numeric_cases():
    cases = [
        ("planar_2r", kd.robots.planar_2r(symbolic=True), PLANAR_VALUES),
        ("planar_3r", kd.robots.planar_3r(symbolic=True), PLANAR3_VALUES),
        ("elbow_sym", symbolic_elbow(), ELBOW_VALUES),
        ("planar_2r_num", kd.robots.planar_2r(), {}),
        ("cartesian_2p", kd.robots.cartesian_2p(), {}),
    ]
    return cases


@pytest.mark.parametrize("name,robot,values", _numeric_cases(), ids=[c[0] for c in _numeric_cases()])
def test_matches_independent_numeric_euler_lagrange(name, robot, values):
    eom = robot.equations_of_motion()
    numeric = robot.subs({s: values[s.name] for s in robot.symbols}) if values else robot
    for _ in range(3):
        q = RNG.uniform(-np.pi, np.pi, robot.n)
        qd = RNG.normal(size=robot.n)
        qdd = RNG.normal(size=robot.n)
        M = evaluate(eom, eom.M, q, values=values)
        np.testing.assert_allclose(M, numeric_M(numeric, q), rtol=1e-7, atol=1e-8)
        np.testing.assert_allclose(
            evaluate(eom, eom.g, q, values=values).ravel(), numeric_g(numeric, q), rtol=1e-7, atol=1e-7
        )
        C = evaluate(eom, eom.C, q, qd, values=values)
        np.testing.assert_allclose(C, numeric_C(numeric, q, qd), rtol=1e-5, atol=1e-6)
        tau = evaluate(eom, eom.tau, q, qd, qdd, values=values).ravel()
        np.testing.assert_allclose(tau, M @ qdd + C @ qd + numeric_g(numeric, q), rtol=1e-5, atol=1e-6)
        np.testing.assert_allclose(evaluate(eom, eom.K, q, qd, values=values), 0.5 * qd @ M @ qd, rtol=1e-9)
        np.testing.assert_allclose(evaluate(eom, eom.P, q, values=values), numeric_P(numeric, q), rtol=1e-9, atol=1e-9)


def _catalogue():
    return [n for n in kd.robots.names() if n != "elbow_3r" or _elbow_numeric_ok()]


def _elbow_numeric_ok():
    try:
        kd.robots.elbow_3r()
        return True
    except Exception:
        return False


@pytest.mark.parametrize("name", _catalogue())
def test_catalogue_matches_numeric_engine(name):
    """Every built-in robot: M, C, g, tau, K, P equal the numeric engine's to 1e-10 relative."""
    pytest.importorskip("kinedyn._core", reason="the native module is not built")
    robot = kd.robots.get(name)
    eom = robot.equations_of_motion(steps=False)
    f = eom.compile(what=("M", "C", "g", "friction"), backend="numpy")
    K = sp.lambdify([list(eom.q), list(eom.qd)], eom.K, "numpy")
    P = sp.lambdify([list(eom.q)], eom.P, "numpy")
    q = robot.random_configuration(RNG, size=4)
    qd = RNG.normal(size=q.shape)
    qdd = RNG.normal(size=q.shape)
    rel = lambda a, b: np.abs(a - b).max() / max(1.0, np.abs(b).max())
    M, C, g = f.M(q), f.C(q, qd), f.g(q)
    assert rel(M, robot.mass_matrix(q)) < 1e-10
    assert rel(g, robot.gravity_torque(q)) < 1e-10
    assert rel(C, robot.coriolis_matrix(q, qd)) < 1e-10
    tau = np.einsum("nij,nj->ni", M, qdd) + np.einsum("nij,nj->ni", C, qd) + g + f.friction(qd)
    assert rel(tau, robot.inverse_dynamics(q, qd, qdd)) < 1e-10
    for k in range(len(q)):
        assert abs(K(q[k], qd[k]) - robot.kinetic_energy(q[k], qd[k])) < 1e-10 * max(
            1.0, abs(robot.kinetic_energy(q[k], qd[k]))
        )
        assert abs(P(q[k]) - robot.potential_energy(q[k])) < 1e-10 * max(1.0, abs(robot.potential_energy(q[k])))
    if robot.n <= 3:  # the symbolic tau itself, including friction
        ft = sp.lambdify([list(eom.q), list(eom.qd), list(eom.qdd)], eom.tau, "numpy")
        assert (
            rel(np.array(ft(q[0], qd[0], qdd[0]), dtype=float).ravel(), robot.inverse_dynamics(q[0], qd[0], qdd[0]))
            < 1e-10
        )


def test_puma_matches_independent_numeric_lagrange():
    robot = kd.robots.puma560()
    eom = robot.equations_of_motion(steps=False)
    f = eom.compile(what=("M", "g"), backend="numpy")
    for _ in range(2):
        q = RNG.uniform(-np.pi, np.pi, 6)
        np.testing.assert_allclose(f.M(q), numeric_M(robot, q), rtol=1e-7, atol=1e-8)
        np.testing.assert_allclose(f.g(q), numeric_g(robot, q), rtol=1e-6, atol=1e-7)


# ----------------------------------------------------------------------------------------------
# Lagrange vs Newton-Euler
@pytest.mark.parametrize(
    "robot",
    [kd.robots.planar_2r(symbolic=True), kd.robots.planar_3r(symbolic=True), symbolic_elbow()],
    ids=["2r", "3r", "elbow"],
)
def test_lagrange_and_newton_euler_agree_symbolically(robot):
    lag = robot.equations_of_motion(method="lagrange")
    ne = robot.equations_of_motion(method="newton_euler")
    # both sides are in the canonical (Fourier) form, so equal expressions expand to the same sum
    assert (lag.tau - ne.tau).applyfunc(sp.expand) == sp.zeros(robot.n, 1)
    assert (lag.M - ne.M).applyfunc(sp.expand) == sp.zeros(robot.n, robot.n)
    # and the Newton-Euler program, substituted back, equals them too (an independent path)
    expanded = sp.Matrix(ne.program.expanded("tau"))
    vals = {s: v for s, v in zip(sorted(robot.symbols, key=str), RNG.uniform(0.5, 2.0, len(robot.symbols)))}
    state = dict(zip(list(ne.q) + list(ne.qd) + list(ne.qdd), RNG.normal(size=3 * robot.n)))
    a = np.array(expanded.xreplace(vals).xreplace(state).evalf(), dtype=float)
    b = np.array(lag.tau.xreplace(vals).xreplace(state).evalf(), dtype=float)
    np.testing.assert_allclose(a, b, rtol=1e-12)


def test_lagrange_and_newton_euler_agree_numerically_puma():
    robot = kd.robots.puma560()
    lag = robot.equations_of_motion(steps=False)
    ne = robot.equations_of_motion(method="newton_euler")
    f_lag = lag.compile(what=("M", "C", "g"), backend="numpy")
    f_ne = ne.compile(what=("tau",))
    q = robot.random_configuration(RNG, size=5)
    qd = RNG.normal(size=q.shape)
    qdd = RNG.normal(size=q.shape)
    tau_lag = np.einsum("nij,nj->ni", f_lag.M(q), qdd) + np.einsum("nij,nj->ni", f_lag.C(q, qd), qd) + f_lag.g(q)
    np.testing.assert_allclose(f_ne.tau(q, qd, qdd), tau_lag, rtol=1e-10, atol=1e-10)


def test_newton_euler_general_inertias_operation_count():
    """The customised model of the PUMA 560 with 60 symbolic inertial parameters stays small."""
    from kinedyn.symbolic.robot_eom import general_parameters, newton_euler_eom

    robot = kd.robots.puma560()
    ne = newton_euler_eom(robot, parameters=general_parameters(robot))
    ops = ne.op_count()
    assert ops["total"] < 600, ops  # a plain symbolic RNEA takes about 850, ungrouped 655 (issue 4)
    numeric = robot.equations_of_motion(method="newton_euler").op_count()
    assert numeric["total"] < ops["total"]


# ----------------------------------------------------------------------------------------------
# planar elbow: closed forms derived here from the kinetic energy written by hand
def _planar_elbow_by_hand():
    l1, lc1, lc2, m1, m2, I1, I2, g = sp.symbols("l1 lc1 lc2 m1 m2 I1 I2 g", positive=True)
    q1, q2, qd1, qd2 = sp.symbols("q1 q2 qd1 qd2", real=True)
    t = sp.Symbol("t")
    # centres of mass as functions of time, differentiated by SymPy (no Jacobian formula used)
    a1, a2 = sp.Function("a1")(t), sp.Function("a2")(t)
    r1 = sp.Matrix([lc1 * sp.cos(a1), lc1 * sp.sin(a1)])
    r2 = sp.Matrix([l1 * sp.cos(a1) + lc2 * sp.cos(a1 + a2), l1 * sp.sin(a1) + lc2 * sp.sin(a1 + a2)])
    v1, v2 = r1.diff(t), r2.diff(t)
    K = m1 * v1.dot(v1) / 2 + m2 * v2.dot(v2) / 2 + I1 * a1.diff(t) ** 2 / 2 + I2 * (a1.diff(t) + a2.diff(t)) ** 2 / 2
    K = K.subs({a1.diff(t): qd1, a2.diff(t): qd2}).subs({a1: q1, a2: q2})
    D = sp.hessian(K, [qd1, qd2]).applyfunc(sp.trigsimp)
    P = m1 * g * r1[1] + m2 * g * r2[1]
    P = P.subs({a1: q1, a2: q2})
    return D, P, (q1, q2, qd1, qd2), (l1, lc1, lc2, m1, m2, I1, I2, g)


def test_planar_elbow_closed_forms():
    robot = kd.robots.planar_2r(symbolic=True)
    eom = robot.equations_of_motion()
    D, P, (q1, q2, qd1, qd2), (l1, lc1, lc2, m1, m2, I1, I2, g) = _planar_elbow_by_hand()
    rename = {q1: eom.q[0], q2: eom.q[1], qd1: eom.qd[0], qd2: eom.qd[1]}
    D = D.xreplace(rename)
    assert (eom.M - D).applyfunc(lambda e: sp.simplify(e)) == sp.zeros(2, 2)
    # textbook form: the entries are as short as the hand-simplified ones (cos q2, no sin^2)
    d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * sp.cos(eom.q[1])) + I1 + I2
    assert sp.expand(eom.M[0, 0] - d11) == 0
    assert not eom.M[0, 0].has(sp.sin) and sp.count_ops(eom.M[0, 0]) <= sp.count_ops(sp.expand(d11))
    # Christoffel symbols by their definition from the hand-derived D
    q = list(eom.q)
    for i in range(2):
        for j in range(2):
            for k in range(2):
                c = (sp.diff(D[k, j], q[i]) + sp.diff(D[k, i], q[j]) - sp.diff(D[i, j], q[k])) / 2
                assert sp.simplify(eom.christoffel[i][j][k] - c) == 0, (i, j, k)
    # C[k, j] = sum_i c_ijk qd_i ; the only non-zero symbol family is h = -m2 l1 lc2 sin q2
    h = -m2 * l1 * lc2 * sp.sin(q[1])
    qd = list(eom.qd)
    C_expected = sp.Matrix([[h * qd[1], h * (qd[0] + qd[1])], [-h * qd[0], 0]])
    assert (eom.C - C_expected).applyfunc(sp.expand) == sp.zeros(2, 2)
    # g = dP/dq of the hand-written potential energy
    Ph = P.xreplace(rename)
    assert (eom.g - sp.Matrix([sp.diff(Ph, x) for x in q])).applyfunc(
        lambda e: sp.expand(sp.expand_trig(e))
    ) == sp.zeros(2, 1)


@pytest.mark.parametrize(
    "robot",
    [kd.robots.planar_2r(symbolic=True), kd.robots.planar_3r(symbolic=True), symbolic_elbow()],
    ids=["2r", "3r", "elbow"],
)
def test_skew_symmetry_symbolic(robot):
    """N = dD/dt - 2C is skew-symmetric, and dD/dt = C + C^T (which a transposed C would fail)."""
    eom = robot.equations_of_motion(steps=False)
    Ddot = sp.zeros(robot.n, robot.n)
    for qi, vi in zip(eom.q, eom.qd):
        Ddot += eom.M.diff(qi) * vi
    N = Ddot - 2 * eom.C
    assert (N + N.T).applyfunc(lambda e: sp.expand(sp.expand_trig(e))) == sp.zeros(robot.n, robot.n)
    assert (Ddot - eom.C - eom.C.T).applyfunc(lambda e: sp.expand(sp.expand_trig(e))) == sp.zeros(robot.n, robot.n)


# ----------------------------------------------------------------------------------------------
# regressor
@pytest.mark.parametrize(
    "robot",
    [kd.robots.planar_2r(symbolic=True), kd.robots.planar_3r(symbolic=True), symbolic_elbow()],
    ids=["2r", "3r", "elbow"],
)
def test_regressor_reproduces_tau_exactly(robot):
    eom = robot.equations_of_motion(steps=False)
    Y, Theta = eom.regressor()
    assert (Y * Theta - (eom.tau - eom.friction)).applyfunc(lambda e: sp.expand(sp.expand_trig(e))) == sp.zeros(
        robot.n, 1
    )
    # minimal: Y sampled at many states has full column rank
    syms = list(eom.q) + list(eom.qd) + list(eom.qdd)
    known = {s: 9.81 for s in Y.free_symbols if s.name == "g"}
    Yf = sp.lambdify([syms], Y.xreplace(known), "numpy")
    stack = np.vstack([np.array(Yf(RNG.normal(size=len(syms))), dtype=float) for _ in range(20)])
    assert np.linalg.matrix_rank(stack, tol=1e-9) == Theta.shape[0]


def test_planar_elbow_five_parameters():
    """The grouping derived by hand: tau is linear in these five combinations (the seed prints
    Theta3 = m2 l1 lc2 and Theta5 = m2 l2, which do not reproduce tau)."""
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    Y, Theta = eom.regressor()
    l1, lc1, lc2, m1, m2, I1, I2 = sp.symbols("l1 lc1 lc2 m1 m2 I1 I2", positive=True)
    expected = [
        m1 * lc1**2 + m2 * (l1**2 + lc2**2) + I1 + I2,
        m2 * l1 * lc2,
        m2 * lc2**2 + I2,
        m1 * lc1 + m2 * l1,
        m2 * lc2,
    ]
    assert Theta.shape == (5, 1)
    assert [sp.expand(t) for t in Theta] == [sp.expand(e) for e in expected]
    # the printed (wrong) third and fifth parameters cannot reproduce tau with this Y
    l2 = sp.Symbol("l2", positive=True)
    wrong = sp.Matrix([expected[0], expected[1], m2 * l1 * lc2, expected[3], m2 * l2])
    assert sp.expand((Y * wrong - eom.tau)[1]) != 0


# ----------------------------------------------------------------------------------------------
# presentation
def test_steps_and_renderings():
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion()
    titles = [s.title for s in eom.steps]
    assert titles[0].startswith("Centre-of-mass positions") and any("Kinetic energy" in t for t in titles)
    assert any("Christoffel" in t for t in titles)
    tex = eom.to_latex()
    assert tex.startswith("\\begin{align*}") and "\\dot{q}_{1}" in tex and "\\frac{\\partial \\mathcal{L}}" in tex
    md = eom.to_markdown()
    assert md.count("$$") % 2 == 0 and "## Step 1" in md
    ml = eom.to_mathml()
    assert ml.count("<math") == ml.count("</math>") > 5
    text = str(eom)
    assert "tau" in text and "cos(q2)" in text
    # the steps' torque equals the final tau (friction-free arm)
    torques = [v for s in eom.steps for (lhs, v) in s.equations if lhs.startswith("\\tau_")]
    assert (sp.Matrix(torques) - eom.tau).applyfunc(sp.expand) == sp.zeros(2, 1)


def test_simplify_false_gives_equal_product_form():
    robot = kd.robots.planar_2r(symbolic=True)
    a = robot.equations_of_motion(simplify=False, steps=False)
    b = robot.equations_of_motion(steps=False)
    assert (a.M - b.M).applyfunc(lambda e: sp.expand(sp.expand_trig(e))) == sp.zeros(2, 2)
    assert any(e.has(sp.cos(a.q[0] + a.q[1])) for e in b.g) and not any(e.has(sp.cos(a.q[0] + a.q[1])) for e in a.g)


def test_rotor_inertia_and_friction_enter_as_documented():
    from kinedyn.robots.examples import geared_link_robot

    eom = geared_link_robot().equations_of_motion()
    J_l, J_m, r, B_m, M, g, ell = sp.symbols("J_l J_m r B_m M g ell", positive=True)
    assert sp.expand(eom.M[0, 0] - (J_l + r**2 * J_m)) == 0
    assert sp.expand(eom.friction[0] - r**2 * B_m * eom.qd[0]) == 0
    assert (
        sp.expand(eom.tau[0] - (eom.M[0, 0] * eom.qdd[0] + M * g * ell * sp.cos(eom.q[0]) + r**2 * B_m * eom.qd[0]))
        == 0
    )


def test_bad_method_is_refused():
    with pytest.raises(ValueError, match="method"):
        kd.robots.planar_2r().equations_of_motion(method="hamilton")


def test_hamiltons_equations_reproduce_the_lagrangian_equations():
    """With p = M qd, Hamilton's qdot is qd and pdot is d(M qd)/dt = dM/dt qd + M qdd along the
    Lagrangian equations of motion (qdd from phase_space), friction and applied torques included."""
    import dataclasses

    robot = kd.robots.planar_2r()
    links = [
        dataclasses.replace(l, joint=dataclasses.replace(l.joint, viscous=0.3, coulomb=0.2)) if l.joint.is_moving else l
        for l in robot.links
    ]
    eom = robot.replace(links=links, dh=None).equations_of_motion()
    p, H, qdot, pdot = eom.hamiltonian()
    x, f, u = eom.phase_space()
    rng = np.random.default_rng(4)
    values = dict(zip(list(eom.q) + list(eom.qd) + list(u), rng.uniform(-1.5, 1.5, 3 * eom.n)))
    M = eom.M.subs(values)
    at_p = {**values, **dict(zip(p, M * sp.Matrix(eom.qd).subs(values)))}
    qd = np.array(sp.Matrix(eom.qd).subs(values), dtype=float).ravel()
    np.testing.assert_allclose(np.array(qdot.subs(at_p), dtype=float).ravel(), qd, atol=1e-12)
    qdd = np.array(f[eom.n :, :].subs(values), dtype=float).ravel()
    Mdot = sum((sp.diff(eom.M, qi) * vi for qi, vi in zip(eom.q, qd)), sp.zeros(eom.n, eom.n)).subs(values)
    expected = np.array(Mdot, dtype=float) @ qd + np.array(M, dtype=float) @ qdd
    np.testing.assert_allclose(np.array(pdot.subs(at_p), dtype=float).ravel(), expected, atol=1e-10)


# ------------------------------------------------------------------ symbolic=True keeps the values given
def _numeric_M_g(eom, subs, q):
    values = {**subs, **dict(zip(eom.q, q))}
    M = np.array(eom.M.subs(values).evalf(), dtype=float)
    g = np.array(sp.Matrix(eom.g).subs(values).evalf(), dtype=float).ravel()
    return M, g


@pytest.mark.parametrize(
    "build, given, rest",
    [
        (
            kd.robots.planar_2r,
            {"lc1": 0.7, "I1": 0.4, "m2": 2.5},
            {"l1": 2.0, "l2": 3.0, "m1": 1.0, "lc2": 1.2, "I2": 0.9, "g": 9.81},
        ),
        (
            kd.robots.elbow_3r,
            {"L2": 1.5, "m3": 0.8},
            {"L1": 3.0, "L3": 1.0, "m1": 1.0, "m2": 1.2, "g": 9.81, "radius": 0.07},
        ),
    ],
)
def test_symbolic_builtin_keeps_the_values_given(build, given, rest):
    """planar_2r(symbolic=True, lc1=..., I1=...) once ignored the values (every parameter became a symbol):
    the given ones must not appear as symbols, the rest must, and M, g with the rest substituted equal
    the numeric robot built with all the values, at random states."""
    robot = build(symbolic=True, **given)
    eom = robot.equations_of_motion()
    names = {str(s) for s in (eom.M.free_symbols | sp.Matrix(eom.g).free_symbols)} - {str(q) for q in eom.q}
    assert not names & set(given) and names <= set(rest) and names
    numeric = build(**given, **rest)
    rng = np.random.default_rng(3)
    subs = {s: rest[str(s)] for s in (eom.M.free_symbols | sp.Matrix(eom.g).free_symbols) if str(s) in rest}
    for q in rng.uniform(-np.pi, np.pi, (3, numeric.n)):
        M, g = _numeric_M_g(eom, subs, q)
        np.testing.assert_allclose(M, numeric.mass_matrix(q), atol=1e-12)
        np.testing.assert_allclose(g, numeric.gravity_torque(q), atol=1e-12)
