"""Issue 12 §3: every numbered equation of the seed (/work/shared/seed: METR4202 Tutorial 4 with its
worked solution, Spong ch. 9, LaValle §13.4) re-derived by an independent route, one test (or a
parametrised case) per equation group. docs/seed-notes.md §5 lists every equation with its verdict and
the test here that decides it.

Conventions: nothing printed in the seed is used as an expectation. Each test derives the quantity
here (SymPy differentiation of energies written from positions, the total time derivative
d/dt e = sum de/dq qd + de/dqd qdd, a particle cloud, numerical quadrature, finite differences), then
(a) compares the printed form with the derivation (a misprint: printed - derived != 0 at a random state
while corrected - derived == 0 exactly) and (b) where kinedyn computes the same thing (eom.M, C, g,
christoffel, tau, P, the numeric engine, LagrangianSystem), compares kinedyn's output with the
derivation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from trig_zero import all_zero, is_zero

import kinedyn as kd
from kinedyn.symbolic import LagrangianSystem

RNG = np.random.default_rng(20261201)
sin, cos = sp.sin, sp.cos

# ---------------------------------------------------------------------------------------------- helpers
q1, q2, q3 = sp.symbols("q1 q2 q3", real=True)
qd1, qd2, qd3 = sp.symbols("qd1 qd2 qd3", real=True)
qdd1, qdd2, qdd3 = sp.symbols("qdd1 qdd2 qdd3", real=True)
Q, QD, QDD = [q1, q2], [qd1, qd2], [qdd1, qdd2]
m1, m2, m3, m4, l1, l2, lc1, lc2, lc3, lc4, I1, I2, I3, I4, g = sp.symbols(
    "m1 m2 m3 m4 l1 l2 lc1 lc2 lc3 lc4 I1 I2 I3 I4 g", positive=True
)


def ddt(e, q=Q, qd=QD, qdd=QDD):
    """Total time derivative along a motion: sum de/dq_i qd_i + de/dqd_i qdd_i (chain rule)."""
    return sum(sp.diff(e, a) * b for a, b in zip(list(q) + list(qd), list(qd) + list(qdd)))


def euler_lagrange(L, q=Q, qd=QD, qdd=QDD):
    return [sp.expand(ddt(sp.diff(L, v), q, qd, qdd) - sp.diff(L, c)) for c, v in zip(q, qd)]


def at_random_state(e):
    """e at a random state: every free symbol in [0.3, 1.7] (parameters) or [-pi, pi] (state); an
    undefined function of the coordinates (d11(q1, q2), P(q1, q2)) becomes a random trigonometric
    polynomial of them first."""
    from sympy.core.function import AppliedUndef

    e = sp.sympify(e)
    concrete = {}
    for fn in e.atoms(AppliedUndef):
        a, b, c, d = RNG.uniform(0.3, 1.7, size=4)
        u, v = (fn.args + fn.args)[:2]
        concrete[fn] = a + b * sp.cos(u) + c * sp.sin(v) + d * sp.cos(u - 2 * v)
    if concrete:
        e = e.xreplace(concrete).doit()
    vals = {
        s: (
            RNG.uniform(-math.pi, math.pi)
            if s.name.startswith("q") or s.name.startswith("th")
            else RNG.uniform(0.3, 1.7)
        )
        for s in e.free_symbols
    }
    return complex(e.xreplace(vals).evalf())


def misprint(printed, derived, corrected):
    """The misprint pattern: the printed form differs from the derivation at a random state, the
    corrected form equals it exactly."""
    printed, derived, corrected = sp.Matrix([printed]), sp.Matrix([derived]), sp.Matrix([corrected])
    assert all_zero(corrected - derived), (corrected - derived).applyfunc(sp.simplify)
    assert max(abs(at_random_state(e)) for e in printed - derived for _ in range(3)) > 1e-6, (
        "the printed form is not wrong"
    )


def planar_elbow_by_particles():
    """Spong's planar elbow written from its centre-of-mass positions (Fig. 9.7 conventions, gravity -y):
    D from K = sum m |v_c|^2 / 2 + I w^2 / 2 differentiated twice in qd, P = sum m g y_c."""
    rc1 = sp.Matrix([lc1 * cos(q1), lc1 * sin(q1)])
    rc2 = sp.Matrix([l1 * cos(q1) + lc2 * cos(q1 + q2), l1 * sin(q1) + lc2 * sin(q1 + q2)])
    v1, v2 = rc1.jacobian(Q) * sp.Matrix(QD), rc2.jacobian(Q) * sp.Matrix(QD)
    K = m1 * (v1.T * v1)[0] / 2 + m2 * (v2.T * v2)[0] / 2 + I1 * qd1**2 / 2 + I2 * (qd1 + qd2) ** 2 / 2
    P = m1 * g * rc1[1] + m2 * g * rc2[1]
    D = sp.hessian(K, QD).applyfunc(lambda e: sp.simplify(sp.trigsimp(e)))
    return rc1, rc2, K, P, D


def christoffel_spong(D, q):
    """c[i][j][k] of Spong (9.58) written from its definition."""
    n = len(q)
    return [
        [
            [(sp.diff(D[k, j], q[i]) + sp.diff(D[k, i], q[j]) - sp.diff(D[i, j], q[k])) / 2 for k in range(n)]
            for j in range(n)
        ]
        for i in range(n)
    ]


def kinedyn_planar_elbow():
    """kinedyn's symbolic planar 2R in this file's symbols."""
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion()
    rename = {eom.q[0]: q1, eom.q[1]: q2, eom.qd[0]: qd1, eom.qd[1]: qd2, eom.qdd[0]: qdd1, eom.qdd[1]: qdd2}
    by_name = {s.name: s for s in (m1, m2, l1, lc1, lc2, I1, I2, g)}
    rename.update({s: by_name[s.name] for s in eom.parameters if s.name in by_name})
    return eom, rename


# ============================================================================================== tutorial
th1, th2 = sp.symbols("theta1 theta2", real=True)
thd1, thd2, thdd1, thdd2 = sp.symbols("thetadot1 thetadot2 thetaddot1 thetaddot2", real=True)
TH, THD, THDD = [th1, th2], [thd1, thd2], [thdd1, thdd2]


def tip_by_complex_numbers():
    """The 2R tip as l1 e^{i th1} + l2 e^{i (th1 + th2)} (a route that writes no cosine by hand)."""
    z = l1 * sp.exp(sp.I * th1) + l2 * sp.exp(sp.I * (th1 + th2))
    z = sp.expand_complex(z)
    return sp.Matrix([sp.re(z), sp.im(z)])


def test_tutorial_review_fk_and_q1a_jacobian_and_kinedyn():
    """Review FK (x, y) and Q1a's J: derived from the complex-number tip; kinedyn.symbolic.pose and
    kinedyn.symbolic.jacobian (rows x, y) agree."""
    tip = tip_by_complex_numbers()
    printed_fk = sp.Matrix([l1 * cos(th1) + l2 * cos(th1 + th2), l1 * sin(th1) + l2 * sin(th1 + th2)])
    assert all_zero(printed_fk - tip)
    J = tip.jacobian(TH)
    printed_J = sp.Matrix(
        [
            [-l1 * sin(th1) - l2 * sin(th1 + th2), -l2 * sin(th1 + th2)],
            [l1 * cos(th1) + l2 * cos(th1 + th2), l2 * cos(th1 + th2)],
        ]
    )
    assert all_zero(printed_J - J)
    robot = kd.robots.planar_2r(symbolic=True)
    qs = kd.symbolic.joint_symbols(robot)
    names = {s.name: s for s in (l1, l2)}
    rename = {qs[0]: th1, qs[1]: th2}
    pose = kd.symbolic.pose(robot)
    Jk = kd.symbolic.jacobian(robot)
    rename.update({s: names[s.name] for s in (pose.free_symbols | Jk.free_symbols) if s.name in names})
    assert all_zero(pose[:2, 3].xreplace(rename) - tip)
    assert all_zero(Jk[:2, :].xreplace(rename) - J)


def test_tutorial_q1b_inverse_jacobian():
    """Q1b: 1/(L1 L2 s2) [[L2 c12, L2 s12], [-L1 c1 - L2 c12, -L1 s1 - L2 s12]] is J^-1 (J^-1 J = I) and
    kinedyn.symbolic.jacobian_inverse gives the same matrix and determinant l1 l2 s2."""
    J = tip_by_complex_numbers().jacobian(TH)
    printed = sp.Matrix(
        [
            [l2 * cos(th1 + th2), l2 * sin(th1 + th2)],
            [-l1 * cos(th1) - l2 * cos(th1 + th2), -l1 * sin(th1) - l2 * sin(th1 + th2)],
        ]
    ) / (l1 * l2 * sin(th2))
    assert all_zero(printed * J - sp.eye(2))
    inv = kd.symbolic.jacobian_inverse(J, [th1, th2])
    assert all_zero(inv.inverse - printed) and is_zero(inv.determinant - l1 * l2 * sin(th2))


def _q2_state(exact: bool):
    a1, a2 = 2.0, 3.0
    if exact:  # the printed angles are the elbow-down IK solution of the tip (1, 1): derived here
        c2 = (1 + 1 - a1**2 - a2**2) / (2 * a1 * a2)
        t2 = -math.acos(c2)
        t1 = math.atan2(1, 1) - math.atan2(a2 * math.sin(t2), a1 + a2 * math.cos(t2))
    else:
        t1, t2 = math.radians(167.028), math.radians(-156.44)
    J = np.array(
        [
            [-a1 * math.sin(t1) - a2 * math.sin(t1 + t2), -a2 * math.sin(t1 + t2)],
            [a1 * math.cos(t1) + a2 * math.cos(t1 + t2), a2 * math.cos(t1 + t2)],
        ]
    )
    return (t1, t2), J


def test_tutorial_q2a_velocity_and_the_numeric_core():
    """Q2a: J at the printed angles, rounded to 4 decimals, is the printed [[-1.0000, -0.5512],
    [1.0000, 2.9489]], v = J (1, 3) = (-2.654, 9.847) m/s; the engine's Jacobian agrees."""
    (t1, t2), J = _q2_state(exact=False)
    np.testing.assert_allclose(J, [[-1.0000, -0.5512], [1.0000, 2.9489]], atol=6e-4)
    np.testing.assert_allclose(J @ [1, 3], [-2.654, 9.847], atol=1e-3)
    pytest.importorskip("kinedyn._core")
    robot = kd.robots.planar_2r(2.0, 3.0)
    np.testing.assert_allclose(robot.jacobian(np.array([t1, t2]))[:2], J, atol=1e-12)


def test_tutorial_q2b_torque_tau2_misprint():
    """Q2b: tau = J^T F with F = (30, -20): tau1 = -50.0 as printed, tau2 = -75.5 (printed -75.1, a
    misprint: -0.5512 * 30 + 2.9489 * (-20) = -75.52 with the printed J itself)."""
    for exact in (False, True):
        _, J = _q2_state(exact)
        tau = J.T @ [30.0, -20.0]
        assert tau[0] == pytest.approx(-50.0, abs=0.01)
        assert tau[1] == pytest.approx(-75.5, abs=0.02) and abs(tau[1] - (-75.1)) > 0.4
    printed_J = np.array([[-1.0000, -0.5512], [1.0000, 2.9489]])
    assert (printed_J.T @ [30, -20])[1] == pytest.approx(-75.514, abs=1e-3)


# tutorial Q3: uniform rods, COM D of link 2 at l2/2, I_A = m1 l1^2 / 3 about joint A, I_D = m2 l2^2 / 12
def _q3():
    xD = l1 * cos(th1) + l2 / 2 * cos(th1 + th2)
    yD = l1 * sin(th1) + l2 / 2 * sin(th1 + th2)
    xDd, yDd = ddt(xD, TH, THD, THDD), ddt(yD, TH, THD, THDD)
    vD2 = sp.expand(xDd**2 + yDd**2)
    IA, ID = m1 * l1**2 / 3, m2 * l2**2 / 12
    K = IA * thd1**2 / 2 + ID * (thd1 + thd2) ** 2 / 2 + m2 * vD2 / 2
    P = m1 * g * l1 / 2 * sin(th1) + m2 * g * (l1 * sin(th1) + l2 / 2 * sin(th1 + th2))
    return xD, yD, xDd, yDd, vD2, K, P, K - P


C1, S1, C2, S2, C12, S12 = cos(th1), sin(th1), cos(th2), sin(th2), cos(th1 + th2), sin(th1 + th2)


def test_tutorial_q3_steps_1_to_3():
    """Step 1 (x_D, y_D and their rates, v_D^2), step 2 (K), step 3 (P) as printed equal the
    derivation; the rod inertias are integrals here (m/l int s^2 ds)."""
    s, m, L = sp.symbols("s m L", positive=True)
    assert sp.integrate(m / L * s**2, (s, 0, L)) == m * L**2 / 3
    assert sp.integrate(m / L * s**2, (s, -L / 2, L / 2)) == m * L**2 / 12
    xD, yD, xDd, yDd, vD2, K, P, _ = _q3()
    assert is_zero(xDd - (-l1 * S1 * thd1 - l2 / 2 * S12 * (thd1 + thd2)))
    assert is_zero(yDd - (l1 * C1 * thd1 + l2 / 2 * C12 * (thd1 + thd2)))
    assert is_zero(
        vD2
        - (
            thd1**2 * (l1**2 + l2**2 / 4 + l1 * l2 * C2)
            + thd2**2 * l2**2 / 4
            + thd1 * thd2 * (l2**2 / 2 + l1 * l2 * C2)
        )
    )
    K_pr = (
        thd1**2 * (m1 * l1**2 / 6 + m2 * l2**2 / 6 + m2 * l1**2 / 2 + m2 * l1 * l2 * C2 / 2)
        + thd2**2 * m2 * l2**2 / 6
        + thd1 * thd2 * (m2 * l2**2 / 3 + m2 * l1 * l2 * C2 / 2)
    )
    assert is_zero(K - K_pr)
    assert is_zero(P - (m1 * g * l1 / 2 * S1 + m2 * g * (l1 * S1 + l2 / 2 * S12)))


def test_tutorial_q3_lagrangian_first_term_typo():
    """The Lagrangian's first term is printed theta-dot^2 (no index): theta-dot_1^2 is meant."""
    *_, L = _q3()
    thd = sp.Symbol("thetadot", real=True)
    first = m1 * l1**2 / 6 + m2 * l2**2 / 6 + m2 * l1**2 / 2 + m2 * l1 * l2 * C2 / 2
    rest = (
        thd2**2 * m2 * l2**2 / 6
        + thd1 * thd2 * (m2 * l2**2 / 3 + m2 * l1 * l2 * C2 / 2)
        - m1 * g * l1 / 2 * S1
        - m2 * g * (l1 * S1 + l2 / 2 * S12)
    )
    misprint(thd**2 * first + rest, L, thd1**2 * first + rest)


def _operator(terms):
    """d/dt as a sum of printed chain-rule terms: [(variable, its rate)]."""
    return lambda f: sum(sp.diff(f, v) * r for v, r in terms)


def test_tutorial_chain_rule_lines_drop_a_term():
    """Step 4's chain rule. The recalled dz/dt = dz/dx x' + dz/dy y' (z of x, y only) is right. The
    operator before d/dt dL/dthd1 keeps d/dth2 and d/dthd1 but drops d/dthd2 thdd2, and the one
    before d/dt dL/dthd2 ("the second chain-rule line") keeps d/dth2 and d/dthd2 but drops
    d/dthd1 thdd1: dL/dthd2 = thd1 (m2 l2^2/3 + m2 l1 l2 C2/2) + m2 l2^2 thd2/3 depends on thd1, so
    the dropped term is (m2 l2^2/3 + m2 l1 l2 C2/2) thdd1, not zero. The full derivative (every
    variable, the route of ddt) is the deciding check; the printed results below each line keep the
    term the line drops."""
    x, y, xd, yd = sp.symbols("x y xd yd", real=True)
    z = sp.Function("z")(x, y)
    assert ddt(z, [x, y], [xd, yd], [0, 0]) == sp.diff(z, x) * xd + sp.diff(z, y) * yd
    *_, L = _q3()
    full = lambda f: ddt(f, TH, THD, THDD)
    for k, printed_terms, dropped in (
        (0, [(th2, thd2), (thd1, thdd1)], (thd2, thdd2)),
        (1, [(th2, thd2), (thd2, thdd2)], (thd1, thdd1)),
    ):
        f = sp.diff(L, THD[k])
        printed = _operator(printed_terms)(f)
        corrected = _operator(printed_terms + [dropped, (th1, thd1)])(f)
        misprint(printed, full(f), corrected)
        assert is_zero(full(f) - printed - sp.diff(f, dropped[0]) * dropped[1])
    dropped2 = sp.diff(sp.diff(L, thd2), thd1)
    assert is_zero(dropped2 - (m2 * l2**2 / 3 + m2 * l1 * l2 * C2 / 2))


def test_tutorial_q3_step_4_lines_and_kinedyn():
    """Step 4, line by line: d/dt dL/dthd1 OK; dL/dth1 printed with + (MISPRINT: -dP/dth1); tau1 OK;
    d/dt dL/dthd2 printed with -m2 l1 l2 S2 thd1^2/2 - m2 l1 l2 S2 thd1 thd2 (MISPRINT:
    -m2 l1 l2 S2 thd1 thd2 / 2 only); dL/dth2 printed m2 l1 l2 S2 thd1 thd2 + m2 g l2 C12/2 (MISPRINT:
    -m2 l1 l2 S2 (thd1^2 + thd1 thd2)/2 - m2 g l2 C12/2); tau2 printed with -m2 l1 l2 S2 thd1^2/2
    (MISPRINT: +). kinedyn's planar_2r with lc = l/2, I = m l^2/12 gives the derived tau."""
    *_, L = _q3()
    ddt1, ddt2 = [sp.expand(ddt(sp.diff(L, v), TH, THD, THDD)) for v in THD]
    dL1, dL2 = [sp.expand(sp.diff(L, c)) for c in TH]
    tau1, tau2 = sp.expand(ddt1 - dL1), sp.expand(ddt2 - dL2)
    a11 = m1 * l1**2 / 3 + m2 * l1**2 + m2 * l2**2 / 3 + m2 * l1 * l2 * C2
    a12 = m2 * l2**2 / 3 + m2 * l1 * l2 * C2 / 2
    h = m2 * l1 * l2 * S2
    grav1 = (m1 / 2 + m2) * g * l1 * C1 + m2 * g * l2 * C12 / 2
    assert is_zero(ddt1 - (a11 * thdd1 + a12 * thdd2 - h * thd1 * thd2 - h / 2 * thd2**2))
    misprint(grav1, dL1, -grav1)
    assert is_zero(tau1 - (a11 * thdd1 + a12 * thdd2 - h * thd1 * thd2 - h / 2 * thd2**2 + grav1))
    misprint(
        a12 * thdd1 + m2 * l2**2 / 3 * thdd2 - h / 2 * thd1**2 - h * thd1 * thd2,
        ddt2,
        a12 * thdd1 + m2 * l2**2 / 3 * thdd2 - h / 2 * thd1 * thd2,
    )
    misprint(h * thd1 * thd2 + m2 * g * l2 * C12 / 2, dL2, -h / 2 * (thd1**2 + thd1 * thd2) - m2 * g * l2 * C12 / 2)
    misprint(
        a12 * thdd1 + m2 * l2**2 / 3 * thdd2 - h / 2 * thd1**2 + m2 * g * l2 * C12 / 2,
        tau2,
        a12 * thdd1 + m2 * l2**2 / 3 * thdd2 + h / 2 * thd1**2 + m2 * g * l2 * C12 / 2,
    )
    # kinedyn: the same arm as Spong's planar elbow with lc = l/2, I = m l^2/12
    robot = kd.robots.planar_2r(symbolic=True, lc1=l1 / 2, lc2=l2 / 2, I1=m1 * l1**2 / 12, I2=m2 * l2**2 / 12)
    eom = robot.equations_of_motion(steps=False)
    rename = dict(zip(list(eom.q) + list(eom.qd) + list(eom.qdd), TH + THD + THDD))
    names = {s.name: s for s in (m1, m2, l1, l2, g)}
    rename.update({s: names[s.name] for s in eom.parameters if s.name in names})
    assert all_zero(eom.tau.xreplace(rename) - sp.Matrix([tau1, tau2]))
    assert is_zero(eom.P.xreplace(rename) - _q3()[6])


def test_tutorial_challenge_elbow_jacobian_and_ik():
    """Challenge (no printed solution): the elbow arm's FK from its DH rows (built here from rotation
    matrices), its Jacobian against kinedyn.symbolic.jacobian, and the IK of (1.0, 0.2, 0.5) by the
    numeric core on all four branches (FK round trip)."""
    L1, L2, L3 = 3.0, 2.0, 1.0
    robot = kd.robots.elbow_3r(L1=L1, L2=L2, L3=L3)
    qs = kd.symbolic.joint_symbols(robot)
    a, b, c = qs
    r = L2 * cos(b) + L3 * cos(b + c)
    tip = sp.Matrix([cos(a) * r, sin(a) * r, L1 + L2 * sin(b) + L3 * sin(b + c)])
    assert all_zero(kd.symbolic.pose(robot)[:3, 3] - tip)
    assert all_zero(kd.symbolic.jacobian(robot)[:3, :] - tip.jacobian(qs))
    pytest.importorskip("kinedyn._core")
    target = np.array([1.0, 0.2, 0.5])
    f = sp.lambdify([qs], tip, "numpy")
    s3 = math.sqrt(1 - 0.5725**2)
    for t1 in (math.atan2(0.2, 1.0), math.atan2(0.2, 1.0) + math.pi):
        rr = math.hypot(1.0, 0.2) * (1 if abs(t1) < 1 else -1)
        for t3 in (math.atan2(s3, 0.5725), math.atan2(-s3, 0.5725)):
            t2 = math.atan2(0.5 - L1, rr) - math.atan2(L3 * math.sin(t3), L2 + L3 * math.cos(t3))
            q = np.array([t1, t2, t3])
            np.testing.assert_allclose(np.ravel(f(q)), target, atol=1e-12)
            np.testing.assert_allclose(robot.pose(q)[:3, 3], target, atol=1e-12)


# ============================================================================================== Spong ch. 9
y, yd, ydd, m, f = sp.symbols("y yd ydd m f", real=True)


def test_spong_9_1_to_9_5_one_dof():
    """(9.1) m y'' = f - m g; (9.2) d/dt dK/dyd = m y''; (9.3) dP/dy = m g; (9.4) L = K - P; (9.5)
    E-L = f reproduces (9.1). kinedyn's LagrangianSystem gives the same equation."""
    K, P = m * yd**2 / 2, m * g * y
    assert ddt(sp.diff(K, yd), [y], [yd], [ydd]) == m * ydd
    assert sp.diff(P, y) == m * g
    (el,) = euler_lagrange(K - P, [y], [yd], [ydd])
    assert sp.expand(el - f) == sp.expand(m * ydd - (f - m * g))
    system = LagrangianSystem([y], K=K, P=P, qd=[yd])
    eom = system.equations_of_motion()
    assert sp.expand(eom.tau[0] - el.xreplace({ydd: eom.qdd[0]})) == 0


def test_spong_9_6_to_9_10_geared_link_and_the_damping_misprint():
    """(9.6) K = (r^2 J_m + J_l) th'^2 / 2 with th_m = r th_l; (9.7)-(9.9) J th'' + M g l sin th = tau.
    (9.10): the motor's damping B_m th_m' reflected to the link is r^2 B_m th_l', by the power it
    dissipates (B_m th_m'^2 = r^2 B_m th_l'^2): B = r^2 B_m + B_l, not the printed r B_m + B_l."""
    r, Jm, Jl, M, ell, Bm, Bl = sp.symbols("r J_m J_l M ell B_m B_l", positive=True)
    th, thd, thdd = sp.symbols("theta thetadot thetaddot", real=True)
    K = Jm * (r * thd) ** 2 / 2 + Jl * thd**2 / 2
    assert sp.expand(K - (r**2 * Jm + Jl) * thd**2 / 2) == 0
    P = M * g * ell * (1 - cos(th))
    (el,) = euler_lagrange(K - P, [th], [thd], [thdd])
    assert sp.expand(el - ((r**2 * Jm + Jl) * thdd + M * g * ell * sin(th))) == 0
    dissipated = Bm * (r * thd) ** 2 + Bl * thd**2  # power lost in both dampers
    B_true = sp.expand(dissipated / thd**2)
    misprint(r * Bm + Bl, B_true, r**2 * Bm + Bl)


def test_spong_9_12_to_9_18_constraints_and_virtual_displacements():
    """(9.12) |r1 - r2| = l and its squared form; (9.16) -> (9.17): with (9.12) holding, the perturbed
    constraint is 2 (r1 - r2)^T (dr1 - dr2) + O(d^2); (9.18) dr = sum dr/dq dq (finite differences on
    the elbow's tip); (9.22)-(9.24): forces c (r1 - r2) and -c (r1 - r2) do c (r1-r2)^T (dr1 - dr2) of
    work, zero by (9.17)."""
    r1, r2, d1, d2 = [sp.Matrix(sp.symbols(f"{n}x {n}y {n}z", real=True)) for n in ("a", "b", "da", "db")]
    eps, ell, c = sp.symbols("epsilon ell c", positive=True)
    perturbed = ((r1 + eps * d1 - r2 - eps * d2).T * (r1 + eps * d1 - r2 - eps * d2))[0]
    series = sp.expand(perturbed - (r1 - r2).dot(r1 - r2))
    assert sp.expand(series.coeff(eps, 1) - 2 * (r1 - r2).dot(d1 - d2)) == 0
    work = (c * (r1 - r2)).dot(d1) + (-c * (r1 - r2)).dot(d2)
    assert sp.expand(work - c * (r1 - r2).dot(d1 - d2)) == 0
    tip = sp.lambdify([Q], sp.Matrix([cos(q1) + 0.7 * cos(q1 + q2), sin(q1) + 0.7 * sin(q1 + q2)]), "numpy")
    Jt = sp.lambdify([Q], sp.Matrix([cos(q1) + 0.7 * cos(q1 + q2), sin(q1) + 0.7 * sin(q1 + q2)]).jacobian(Q), "numpy")
    q0, dq = RNG.normal(size=2), 1e-7 * RNG.normal(size=2)
    np.testing.assert_allclose(np.ravel(tip(q0 + dq) - tip(q0)), np.asarray(Jt(q0)) @ dq, rtol=1e-5)


def test_spong_9_26_generalized_force_is_J_transpose_f():
    """(9.26)-(9.27): psi_j = sum_i f_i^T dr_i/dq_j; for a force F at the 2R tip that is J^T F, which
    kinedyn.symbolic.joint_torques computes."""
    Fx, Fy = sp.symbols("F_x F_y", real=True)
    tip = sp.Matrix([l1 * cos(q1) + l2 * cos(q1 + q2), l1 * sin(q1) + l2 * sin(q1 + q2)])
    psi = sp.Matrix([sp.Matrix([Fx, Fy]).dot(tip.diff(c)) for c in Q])
    assert all_zero(kd.symbolic.joint_torques(tip.jacobian(Q), sp.Matrix([Fx, Fy]), Q) - psi)


def test_spong_9_28_to_9_38_dalembert_to_euler_lagrange():
    """(9.29) product rule, (9.30) v = sum dr/dq qd, (9.31) dv/dqd_j = dr/dq_j (printed with the index
    i: a typo), (9.32) d/dt dr/dq_j = dv/dq_j, (9.33)-(9.35) sum m r''^T dr/dq_j = d/dt dK/dqd_j -
    dK/dq_j, for the two centres of mass of the planar elbow."""
    rc1, rc2, K, _, _ = planar_elbow_by_particles()
    for j in range(2):
        lhs = 0
        rhs_929 = 0
        for mass, r in ((m1, rc1), (m2, rc2)):
            v = r.jacobian(Q) * sp.Matrix(QD)  # (9.30)
            acc = v.applyfunc(ddt)
            lhs += mass * acc.dot(r.diff(Q[j]))
            assert all_zero(v.diff(QD[j]) - r.diff(Q[j]))  # (9.31) with the index j
            assert all_zero(r.diff(Q[j]).applyfunc(ddt) - v.diff(Q[j]))  # (9.32)
            rhs_929 += ddt(mass * v.dot(r.diff(Q[j]))) - mass * v.dot(r.diff(Q[j]).applyfunc(ddt))
        assert is_zero(lhs - rhs_929)  # (9.29)
        K_particles = sum(
            mass * (r.jacobian(Q) * sp.Matrix(QD)).dot(r.jacobian(Q) * sp.Matrix(QD)) / 2
            for mass, r in ((m1, rc1), (m2, rc2))
        )
        assert is_zero(lhs - (ddt(sp.diff(K_particles, QD[j])) - sp.diff(K_particles, Q[j])))  # (9.35)
    # (9.31) as printed (dv_i/dqd_i, the particle index on qd) is not dr/dq_j: for particle 2, j = 2
    v2 = rc2.jacobian(Q) * sp.Matrix(QD)
    assert not all_zero(v2.diff(QD[0]) - rc2.diff(Q[1]))


def test_spong_9_39_9_40_potential_forces():
    """(9.38) with psi = -dP/dq + tau (9.39) is E-L of L = K - P (9.40)."""
    _, _, K, P, _ = planar_elbow_by_particles()
    tau = sp.symbols("tau1 tau2", real=True)
    for k in range(2):
        lhs_938 = ddt(sp.diff(K, QD[k])) - sp.diff(K, Q[k]) - (-sp.diff(P, Q[k]) + tau[k])
        lhs_940 = ddt(sp.diff(K - P, QD[k])) - sp.diff(K - P, Q[k]) - tau[k]
        assert is_zero(lhs_938 - lhs_940)


def _particle_body(n=40):
    pts = RNG.normal(size=(n, 3)) * [0.5, 0.2, 0.1]
    masses = RNG.uniform(0.1, 1.0, size=n)
    com = masses @ pts / masses.sum()
    rel = pts - com
    I_body = sum(mi * (np.dot(p, p) * np.eye(3) - np.outer(p, p)) for mi, p in zip(masses, rel))
    return pts, masses, com, I_body


def _rot(axis, a):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(a) * Kx + (1 - math.cos(a)) * Kx @ Kx


def test_spong_9_41_to_9_44_rigid_body_kinetic_energy_and_inertia_tensor():
    """(9.41) K = m v^T v/2 + w^T I w/2 about the centre of mass equals the particles' sum; (9.42)
    S(w) = R' R^T (finite differences); (9.43) the world tensor is R I R^T; (9.44) with the
    products of inertia -sum m x y (the particles' own sums)."""
    pts, masses, com, I_body = _particle_body()
    # (9.44) entries by their definitions
    rel = pts - com
    Ixx = sum(mi * (p[1] ** 2 + p[2] ** 2) for mi, p in zip(masses, rel))
    Ixy = -sum(mi * p[0] * p[1] for mi, p in zip(masses, rel))
    assert I_body[0, 0] == pytest.approx(Ixx) and I_body[0, 1] == pytest.approx(Ixy)
    R = lambda t: _rot([0.3, -0.5, 0.8], 0.7 * t) @ _rot([1, 0, 0], 0.2 + 0.4 * t)
    t0, h = 0.37, 1e-6
    Rd = (R(t0 + h) - R(t0 - h)) / (2 * h)
    S = Rd @ R(t0).T
    np.testing.assert_allclose(S, -S.T, atol=1e-8)  # (9.42): skew
    w = np.array([S[2, 1], S[0, 2], S[1, 0]])
    v = np.array([0.3, -1.1, 0.4])
    # particle velocities of the moving body x(t) = c(t) + R(t) R(t0)^T (x0 - c0)
    vel = v + (Rd @ R(t0).T @ (pts - com).T).T
    K_particles = 0.5 * sum(mi * vi @ vi for mi, vi in zip(masses, vel))
    I_world = I_body  # the cloud's tensor in world axes at t0 (the cloud is at pts then)
    # the tensor of the rotated cloud computed directly in world axes equals R I R^T
    Rw = _rot([0.2, 0.9, -0.4], 1.1)
    rel_w = (Rw @ rel.T).T
    I_direct = sum(mi * (np.dot(p, p) * np.eye(3) - np.outer(p, p)) for mi, p in zip(masses, rel_w))
    np.testing.assert_allclose(I_direct, Rw @ I_body @ Rw.T, atol=1e-12)
    assert K_particles == pytest.approx(0.5 * masses.sum() * v @ v + 0.5 * w @ I_world @ w, rel=1e-9)


def test_spong_example_9_2_box_and_kinedyn_inertia_box():
    """Ex 9.2: I_xx = rho abc (b^2 + c^2)/12, I_yy, I_zz, products 0 (triple integrals); kinedyn's
    Inertia.box(m, (a, b, c)) gives the same with m = rho a b c."""
    x, yy, z, a, b, c, rho = sp.symbols("x y z a b c rho", positive=True)
    box = lambda e: sp.integrate(e * rho, (x, -a / 2, a / 2), (yy, -b / 2, b / 2), (z, -c / 2, c / 2))
    I = [sp.factor(box(e)) for e in (yy**2 + z**2, x**2 + z**2, x**2 + yy**2)]
    printed = [
        rho * a * b * c / 12 * (b**2 + c**2),
        rho * a * b * c / 12 * (a**2 + c**2),
        rho * a * b * c / 12 * (a**2 + b**2),
    ]
    assert all(sp.simplify(u - w) == 0 for u, w in zip(I, printed))
    assert box(-x * yy) == 0 and box(-x * z) == 0 and box(-yy * z) == 0
    from kinedyn.description.inertia import Inertia

    vals = dict(rho=1.3, a=0.4, b=0.7, c=0.2)
    inertia = Inertia.box(1.3 * 0.4 * 0.7 * 0.2, (0.4, 0.7, 0.2))
    np.testing.assert_allclose(
        np.diag(np.asarray(inertia.inertia, float)),
        [float(e.subs({sp.Symbol(k, positive=True): v for k, v in vals.items()})) for e in I],
        rtol=1e-12,
    )


def test_spong_9_45_to_9_49_kinetic_and_potential_energy_of_an_arm():
    """(9.46)-(9.47): D = sum m Jv^T Jv + Jw^T R I R^T Jw from the geometric Jacobians of the centres
    of mass equals the engine's mass matrix (CRBA) and K = qd^T D qd / 2 its kinetic energy; (9.48)-
    (9.49) P = sum m g^T r_c holds with g pointing *up* (against gravity): kinedyn's
    potential_energy is -sum m gravity . r_c."""
    pytest.importorskip("kinedyn._core")
    robot = kd.robots.elbow_3r(L1=0.7, L2=1.1, L3=0.8, m1=2.0, m2=1.5, m3=1.2)
    q, qd = RNG.uniform(-math.pi, math.pi, 3), RNG.normal(size=3)
    # body poses from the tree (T_i = T_parent placement motion(q_i)), Jacobian columns z_j x (p_c - o_j), z_j
    poses = []
    for i, body in enumerate(robot.tree.bodies):
        motion = np.eye(4)
        motion[:3, :3] = _rot(body.joint.axis, q[i] + float(body.joint.offset))
        poses.append(
            (poses[body.parent] if body.parent >= 0 else np.eye(4)) @ np.asarray(body.placement, float) @ motion
        )
    D = np.zeros((3, 3))
    P = 0.0
    for i, body in enumerate(robot.tree.bodies):
        R, p_c = poses[i][:3, :3], poses[i][:3, :3] @ np.asarray(body.inertia.com, float) + poses[i][:3, 3]
        Jv, Jw = np.zeros((3, 3)), np.zeros((3, 3))
        j = i
        while j >= 0:
            z = poses[j][:3, :3] @ np.asarray(robot.tree.bodies[j].joint.axis, float)
            Jv[:, j], Jw[:, j] = np.cross(z, p_c - poses[j][:3, 3]), z
            j = robot.tree.bodies[j].parent
        Ic = np.asarray(body.inertia.inertia, float)
        D += body.inertia.mass * Jv.T @ Jv + Jw.T @ R @ Ic @ R.T @ Jw
        P += body.inertia.mass * (-np.asarray(robot.gravity, float)) @ p_c
    np.testing.assert_allclose(D, robot.mass_matrix(q), atol=1e-12)
    assert robot.kinetic_energy(q, qd) == pytest.approx(qd @ D @ qd / 2, rel=1e-12)
    assert robot.potential_energy(q) == pytest.approx(P, rel=1e-12)


# a generic 2-DOF system: D(q) symmetric with arbitrary entries, P(q) arbitrary
d11, d12, d22, Pf = [sp.Function(n)(q1, q2) for n in ("d11", "d12", "d22", "P")]
DG = sp.Matrix([[d11, d12], [d12, d22]])
LG = (sp.Matrix(QD).T * DG * sp.Matrix(QD))[0] / 2 - Pf
ELG = euler_lagrange(LG)


def test_spong_9_50_to_9_54_derivatives_of_the_lagrangian():
    """(9.50)-(9.51) K and L; (9.52) dL/dqd_k = sum_j d_kj qd_j; (9.53) d/dt dL/dqd_k = sum_j d_kj
    qdd_j + sum_ij dd_kj/dq_i qd_i qd_j (printed first sum over i: an index typo); (9.54)."""
    K = sum(DG[i, j] * QD[i] * QD[j] for i in range(2) for j in range(2)) / 2
    assert sp.expand(K - (sp.Matrix(QD).T * DG * sp.Matrix(QD))[0] / 2) == 0
    for k in range(2):
        assert sp.expand(sp.diff(LG, QD[k]) - sum(DG[k, j] * QD[j] for j in range(2))) == 0
        rhs = sum(DG[k, j] * QDD[j] for j in range(2)) + sum(
            sp.diff(DG[k, j], Q[i]) * QD[i] * QD[j] for i in range(2) for j in range(2)
        )
        assert sp.expand(ddt(sp.diff(LG, QD[k])) - rhs) == 0
        rhs54 = sum(sp.diff(DG[i, j], Q[k]) * QD[i] * QD[j] for i in range(2) for j in range(2)) / 2 - sp.diff(Pf, Q[k])
        assert sp.expand(sp.diff(LG, Q[k]) - rhs54) == 0


def test_spong_9_55_sign_of_the_potential_term_misprint():
    """(9.55) prints sum d_kj qdd_j + sum {dd_kj/dq_i - dd_ij/dq_k / 2} qd_i qd_j - dP/dq_k = tau_k.
    d/dt dL/dqd_k - dL/dq_k has -(-dP/dq_k) = +dP/dq_k: the printed minus is a sign misprint (9.59)-
    (9.61) then carry +phi_k, as they should)."""
    for k in range(2):
        quad = sum(
            (sp.diff(DG[k, j], Q[i]) - sp.diff(DG[i, j], Q[k]) / 2) * QD[i] * QD[j] for i in range(2) for j in range(2)
        )
        inertial = sum(DG[k, j] * QDD[j] for j in range(2))
        misprint(inertial + quad - sp.diff(Pf, Q[k]), ELG[k], inertial + quad + sp.diff(Pf, Q[k]))
        assert sp.expand(inertial + quad - sp.diff(Pf, Q[k]) - ELG[k]) == sp.expand(-2 * sp.diff(Pf, Q[k]))


def test_spong_9_56_to_9_63_christoffel_symbols_and_C():
    """(9.56) symmetrisation, (9.57), (9.58) c_ijk, (9.59) phi = dP/dq, (9.60)-(9.61) D qdd + C qd + g
    = E-L (9.60 printed with sum_i over d_kj qdd_j: an index typo), (9.62) C_kj = sum_i c_ijk qd_i;
    (9.63) prints dd_kj/dq_j in place of dd_kj/dq_i: a misprint (it differs from 9.62)."""
    c = christoffel_spong(DG, Q)
    for k in range(2):
        s1 = sum(sp.diff(DG[k, j], Q[i]) * QD[i] * QD[j] for i in range(2) for j in range(2))
        s2 = (
            sum((sp.diff(DG[k, j], Q[i]) + sp.diff(DG[k, i], Q[j])) * QD[i] * QD[j] for i in range(2) for j in range(2))
            / 2
        )
        assert sp.expand(s1 - s2) == 0  # (9.56)
        lhs57 = sum(
            (sp.diff(DG[k, j], Q[i]) - sp.diff(DG[i, j], Q[k]) / 2) * QD[i] * QD[j] for i in range(2) for j in range(2)
        )
        assert sp.expand(lhs57 - sum(c[i][j][k] * QD[i] * QD[j] for i in range(2) for j in range(2))) == 0  # (9.57)
        for i in range(2):
            for j in range(2):
                assert sp.expand(c[i][j][k] - c[j][i][k]) == 0  # c_ijk = c_jik
    C = sp.Matrix(2, 2, lambda k, j: sum(c[i][j][k] * QD[i] for i in range(2)))  # (9.62)
    phi = sp.Matrix([sp.diff(Pf, x) for x in Q])
    assert all_zero(DG * sp.Matrix(QDD) + C * sp.Matrix(QD) + phi - sp.Matrix(ELG))  # (9.60)-(9.61)
    C_963 = sp.Matrix(
        2,
        2,
        lambda k, j: sum(
            (sp.diff(DG[k, j], Q[j]) + sp.diff(DG[k, i], Q[j]) - sp.diff(DG[i, j], Q[k])) / 2 * QD[i] for i in range(2)
        ),
    )
    assert not all_zero(C_963 - C)
    # the index-typo check of (9.60): summing d_kj qdd_j over i (j free) is not the inertial term
    assert sp.expand(sum(DG[0, 1] * QDD[1] for _ in range(2)) - sum(DG[0, j] * QDD[j] for j in range(2))) != 0


def test_spong_9_64_constant_diagonal_inertia_sign_misprint():
    """(9.64) prints d_kk qdd_k - phi_k = tau_k for a constant diagonal D; E-L gives + phi_k."""
    a, b = sp.symbols("a b", positive=True)
    el = euler_lagrange(a * qd1**2 / 2 + b * qd2**2 / 2 - Pf)
    for k, dkk in enumerate((a, b)):
        misprint(dkk * QDD[k] - sp.diff(Pf, Q[k]), el[k], dkk * QDD[k] + sp.diff(Pf, Q[k]))


def test_spong_9_65_to_9_73_two_link_cartesian():
    """(9.65)-(9.68) J_vc1 = [[0,0],[0,0],[1,0]], J_vc2 = [[0,0],[0,1],[1,0]] from r_c1 = (0, 0, q1),
    r_c2 = (0, q2, q1); (9.69)-(9.70) D = diag(m1 + m2, m2); (9.71)-(9.72) P, phi; (9.73) the equations.
    kinedyn: a PP arm from its DH rows gives the same D and g numerically."""
    rc1, rc2 = sp.Matrix([0, 0, q1]), sp.Matrix([0, q2, q1])
    J1, J2 = rc1.jacobian(Q), rc2.jacobian(Q)
    assert J1 == sp.Matrix([[0, 0], [0, 0], [1, 0]]) and J2 == sp.Matrix([[0, 0], [0, 1], [1, 0]])
    D = m1 * J1.T * J1 + m2 * J2.T * J2
    assert D == sp.diag(m1 + m2, m2)
    P = g * (m1 * rc1[2] + m2 * rc2[2])
    assert sp.expand(P - g * (m1 + m2) * q1) == 0
    el = euler_lagrange((sp.Matrix(QD).T * D * sp.Matrix(QD))[0] / 2 - P)
    f1, f2 = sp.symbols("f1 f2", real=True)
    assert sp.expand(el[0] - f1 - ((m1 + m2) * qdd1 + g * (m1 + m2) - f1)) == 0 and sp.expand(el[1] - m2 * qdd2) == 0
    pytest.importorskip("kinedyn._core")
    from kinedyn.description.inertia import Inertia

    rows = [
        dict(theta=0, d=0, a=0, alpha=-math.pi / 2, kind="prismatic", inertia=Inertia(2.0, (0.1, 0.2, -0.3))),
        dict(theta=0, d=0, a=0, alpha=0, kind="prismatic", inertia=Inertia(0.7, (0.05, -0.1, 0.2))),
    ]
    robot = kd.Robot.from_dh(rows, gravity=(0, 0, -9.81))
    qn = RNG.normal(size=2)
    np.testing.assert_allclose(robot.mass_matrix(qn), np.diag([2.7, 0.7]), atol=1e-12)
    np.testing.assert_allclose(robot.gravity_torque(qn), [9.81 * 2.7, 0.0], atol=1e-12)


def test_spong_9_74_to_9_88_planar_elbow_and_kinedyn():
    """(9.75) J_vc1 (printed l_c in row 1: an l_c1 typo), (9.77) J_vc2, (9.78)-(9.81) D from the
    Jacobians, (9.82) D, (9.83) Christoffel symbols (h = -m2 l1 lc2 sin q2), (9.84) P, (9.85)-(9.86)
    phi, (9.87) the equations, (9.88) C -- all derived from the centres of mass here; kinedyn's eom.M,
    eom.christoffel, eom.P, eom.g, eom.C and eom.tau equal the derivation, and the numeric engine agrees
    at a random state."""
    rc1, rc2, K, P, D = planar_elbow_by_particles()
    J1, J2 = rc1.jacobian(Q), rc2.jacobian(Q)
    assert all_zero(J1 - sp.Matrix([[-lc1 * sin(q1), 0], [lc1 * cos(q1), 0]]))
    assert all_zero(
        J2
        - sp.Matrix(
            [
                [-l1 * sin(q1) - lc2 * sin(q1 + q2), -lc2 * sin(q1 + q2)],
                [l1 * cos(q1) + lc2 * cos(q1 + q2), lc2 * cos(q1 + q2)],
            ]
        )
    )
    assert all_zero(m1 * J1.T * J1 + m2 * J2.T * J2 + sp.Matrix([[I1 + I2, I2], [I2, I2]]) - D)  # (9.81)
    D_pr = sp.Matrix(
        [
            [
                m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * cos(q2)) + I1 + I2,
                m2 * (lc2**2 + l1 * lc2 * cos(q2)) + I2,
            ],
            [m2 * (lc2**2 + l1 * lc2 * cos(q2)) + I2, m2 * lc2**2 + I2],
        ]
    )
    assert all_zero(D - D_pr)
    c = christoffel_spong(D, Q)
    h = -m2 * l1 * lc2 * sin(q2)
    printed_c = {
        (0, 0, 0): 0,
        (0, 1, 0): h,
        (1, 0, 0): h,
        (1, 1, 0): h,
        (0, 0, 1): -h,
        (0, 1, 1): 0,
        (1, 0, 1): 0,
        (1, 1, 1): 0,
    }
    assert all(is_zero(c[i][j][k] - v) for (i, j, k), v in printed_c.items())
    phi = sp.Matrix([sp.diff(P, x) for x in Q])
    assert all_zero(
        phi - sp.Matrix([(m1 * lc1 + m2 * l1) * g * cos(q1) + m2 * lc2 * g * cos(q1 + q2), m2 * lc2 * g * cos(q1 + q2)])
    )
    C = sp.Matrix(2, 2, lambda k, j: sum(c[i][j][k] * QD[i] for i in range(2)))
    assert all_zero(C - sp.Matrix([[h * qd2, h * qd2 + h * qd1], [-h * qd1, 0]]))  # (9.88)
    tau = sp.Matrix(euler_lagrange(K - P))
    eq87 = sp.Matrix(
        [
            D_pr[0, 0] * qdd1 + D_pr[0, 1] * qdd2 + 2 * h * qd1 * qd2 + h * qd2**2 + phi[0],
            D_pr[1, 0] * qdd1 + D_pr[1, 1] * qdd2 - h * qd1**2 + phi[1],
        ]
    )
    assert all_zero(tau - eq87)
    eom, rename = kinedyn_planar_elbow()
    assert all_zero(eom.M.xreplace(rename) - D)
    assert all_zero(eom.C.xreplace(rename) - C)
    assert all_zero(eom.g.xreplace(rename) - phi)
    assert is_zero(eom.P.xreplace(rename) - P)
    assert all_zero(eom.tau.xreplace(rename) - tau)
    for i in range(2):
        for j in range(2):
            for k in range(2):
                assert is_zero(eom.christoffel[i][j][k].xreplace(rename) - c[i][j][k])
    pytest.importorskip("kinedyn._core")
    vals = dict(l1=1.3, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13)
    robot = kd.robots.planar_2r(l1=1.3, l2=0.9, **{k: v for k, v in vals.items() if k != "l1"})
    state = RNG.normal(size=6)
    sub = {**{s: vals[s.name] for s in (m1, m2, l1, lc1, lc2, I1, I2)}, g: 9.81, **dict(zip(Q + QD + QDD, state))}
    np.testing.assert_allclose(
        robot.inverse_dynamics(state[:2], state[2:4], state[4:]), np.array(tau.xreplace(sub), float).ravel(), rtol=1e-10
    )
    np.testing.assert_allclose(
        robot.christoffel(state[:2]),
        np.array([[[float(c[i][j][k].xreplace(sub)) for k in range(2)] for j in range(2)] for i in range(2)]),
        atol=1e-12,
    )


p1, p2, pd1, pd2, pdd1, pdd2 = sp.symbols("p1 p2 pd1 pd2 pdd1 pdd2", real=True)
PP, PD, PDD = [p1, p2], [pd1, pd2], [pdd1, pdd2]


def test_spong_9_89_to_9_95_remotely_driven_link():
    """Absolute angles p1 = q1, p2 = q1 + q2. (9.89) v_c2's first column is printed (l1 sin p1,
    l1 cos p1): MISPRINT, the derivative of r_c2 is (-l1 sin p1, l1 cos p1); (9.90)-(9.92) D(p);
    (9.93) Christoffel symbols; (9.94) P and phi; (9.95) the equations. kinedyn's LagrangianSystem
    (from the bodies) and the change of coordinates D_p = A^T D_q A of kinedyn's planar_2r agree."""
    rc1 = sp.Matrix([lc1 * cos(p1), lc1 * sin(p1)])
    rc2 = sp.Matrix([l1 * cos(p1) + lc2 * cos(p2), l1 * sin(p1) + lc2 * sin(p2)])
    J2 = rc2.jacobian(PP)
    J2_printed = sp.Matrix([[l1 * sin(p1), -lc2 * sin(p2)], [l1 * cos(p1), lc2 * cos(p2)]])
    J2_corrected = sp.Matrix([[-l1 * sin(p1), -lc2 * sin(p2)], [l1 * cos(p1), lc2 * cos(p2)]])
    misprint(list(J2_printed), list(J2), list(J2_corrected))
    v1, v2 = rc1.jacobian(PP) * sp.Matrix(PD), J2 * sp.Matrix(PD)
    K = m1 * v1.dot(v1) / 2 + m2 * v2.dot(v2) / 2 + I1 * pd1**2 / 2 + I2 * pd2**2 / 2  # (9.90): w1 = pd1, w2 = pd2
    D = sp.hessian(K, PD)
    D_pr = sp.Matrix(
        [
            [m1 * lc1**2 + m2 * l1**2 + I1, m2 * l1 * lc2 * cos(p2 - p1)],
            [m2 * l1 * lc2 * cos(p2 - p1), m2 * lc2**2 + I2],
        ]
    )
    assert all_zero(D - D_pr)
    c = christoffel_spong(D, PP)
    s_ = m2 * l1 * lc2 * sin(p2 - p1)
    printed = {
        (0, 0, 0): 0,
        (0, 1, 0): 0,
        (1, 0, 0): 0,
        (1, 1, 0): -s_,
        (0, 0, 1): s_,
        (1, 1, 1): 0,
        (0, 1, 1): 0,
        (1, 0, 1): 0,
    }
    assert all(is_zero(c[i][j][k] - v) for (i, j, k), v in printed.items())
    P = m1 * g * rc1[1] + m2 * g * rc2[1]
    assert is_zero(P - (m1 * g * lc1 * sin(p1) + m2 * g * (l1 * sin(p1) + lc2 * sin(p2))))
    phi = [sp.diff(P, x) for x in PP]
    assert is_zero(phi[0] - (m1 * lc1 + m2 * l1) * g * cos(p1)) and is_zero(phi[1] - m2 * lc2 * g * cos(p2))
    tau = euler_lagrange(K - P, PP, PD, PDD)
    eq95 = [
        D_pr[0, 0] * pdd1 + D_pr[0, 1] * pdd2 + c[1][1][0] * pd2**2 + phi[0],
        D_pr[1, 0] * pdd1 + D_pr[1, 1] * pdd2 + c[0][0][1] * pd1**2 + phi[1],
    ]
    assert all(is_zero(a - b) for a, b in zip(tau, eq95))
    system = LagrangianSystem.from_bodies(
        PP,
        [
            dict(mass=m1, position=list(rc1), inertia=I1, angular_velocity=pd1),
            dict(mass=m2, position=list(rc2), inertia=I2, angular_velocity=pd2),
        ],
        gravity=[0, -g],
        qd=PD,
    )
    eom = system.equations_of_motion()
    assert all_zero(eom.M - D) and all_zero(eom.tau.xreplace(dict(zip(eom.qdd, PDD))) - sp.Matrix(tau))
    planar, rename = kinedyn_planar_elbow()
    A = sp.Matrix([[1, 0], [-1, 1]])  # q = A p
    Dq = planar.M.xreplace(rename).xreplace({q1: p1, q2: p2 - p1})
    assert all_zero(A.T * Dq * A - D)


def test_spong_9_96_to_9_108_five_bar_linkage():
    """Parallelogram five-bar, q1, q2 absolute angles. (9.96), (9.97), (9.99) OK; (9.98) prints
    r_c3 = (lc2 cos q1, lc2 sin q2) + lc3 u1: MISPRINT, link 3 hangs at the tip of link 2 (l2 u2), as
    (9.100)'s v_c3 uses; (9.100) OK; (9.101) v_c4 entry (2,2) printed +lc4 cos q2: MISPRINT (-lc4 cos q2);
    (9.102)/(9.103) index typos; (9.104) D OK; (9.105) makes D constant diagonal, C = 0; (9.106) prints
    P = g sum y_ci = g s1 (...) = g s2 (...): MISPRINT, P = g sum m_i y_ci = g s1 (...) + g s2 (...);
    (9.107)-(9.108) OK. kinedyn's LagrangianSystem gives the same D and decoupled equations."""
    u1, u2 = sp.Matrix([cos(q1), sin(q1)]), sp.Matrix([cos(q2), sin(q2)])
    r = [lc1 * u1, lc2 * u2, l2 * u2 + lc3 * u1, l1 * u1 - lc4 * u2]
    r3_printed = sp.Matrix([lc2 * cos(q1), lc2 * sin(q2)]) + lc3 * u1
    misprint(list(r3_printed), list(r[2]), list(l2 * u2 + lc3 * u1))
    J = [ri.jacobian(Q) for ri in r]
    assert all_zero(J[2] - sp.Matrix([[-lc3 * sin(q1), -l2 * sin(q2)], [lc3 * cos(q1), l2 * cos(q2)]]))
    misprint(
        list(sp.Matrix([[-l1 * sin(q1), lc4 * sin(q2)], [l1 * cos(q1), lc4 * cos(q2)]])),
        list(J[3]),
        list(sp.Matrix([[-l1 * sin(q1), lc4 * sin(q2)], [l1 * cos(q1), -lc4 * cos(q2)]])),
    )
    masses, inertias, omegas = [m1, m2, m3, m4], [I1, I2, I3, I4], [qd1, qd2, qd1, qd2]
    K = sum(
        mi * (Ji * sp.Matrix(QD)).dot(Ji * sp.Matrix(QD)) / 2 + Ii * w**2 / 2
        for mi, Ji, Ii, w in zip(masses, J, inertias, omegas)
    )
    D = sp.hessian(K, QD)
    D_pr = sp.Matrix(
        [
            [m1 * lc1**2 + m3 * lc3**2 + m4 * l1**2 + I1 + I3, (m3 * l2 * lc3 - m4 * l1 * lc4) * cos(q2 - q1)],
            [(m3 * l2 * lc3 - m4 * l1 * lc4) * cos(q2 - q1), m2 * lc2**2 + m3 * l2**2 + m4 * lc4**2 + I2 + I4],
        ]
    )
    assert all_zero(D - D_pr)
    decoupled = {m4: m3 * l2 * lc3 / (l1 * lc4)}  # (9.105)
    Dd = D.xreplace(decoupled)
    assert is_zero(Dd[0, 1]) and all(sp.diff(Dd[i, i], x) == 0 for i in range(2) for x in Q)
    P = g * sum(mi * ri[1] for mi, ri in zip(masses, r))
    s1_part, s2_part = g * sin(q1) * (m1 * lc1 + m3 * lc3 + m4 * l1), g * sin(q2) * (m2 * lc2 + m3 * l2 - m4 * lc4)
    assert is_zero(P - (s1_part + s2_part))
    assert not is_zero(g * sum(ri[1] for ri in r) - P)  # "g sum y_ci" leaves out the masses
    phi = [sp.diff(P, x) for x in Q]
    assert is_zero(phi[0] - g * cos(q1) * (m1 * lc1 + m3 * lc3 + m4 * l1)) and is_zero(
        phi[1] - g * cos(q2) * (m2 * lc2 + m3 * l2 - m4 * lc4)
    )
    tau = [e.xreplace(decoupled) for e in euler_lagrange(K - P)]
    assert is_zero(tau[0] - (Dd[0, 0] * qdd1 + phi[0].xreplace(decoupled))) and is_zero(
        tau[1] - (Dd[1, 1] * qdd2 + phi[1].xreplace(decoupled))
    )
    bodies = [
        dict(mass=mi, position=list(ri), inertia=Ii, angular_velocity=w)
        for mi, ri, Ii, w in zip(masses, r, inertias, omegas)
    ]
    eom = LagrangianSystem.from_bodies(Q, bodies, gravity=[0, -g], qd=QD).equations_of_motion()
    assert all_zero(eom.M - D)
    assert all_zero(eom.C.xreplace(decoupled))


def test_spong_9_109_to_9_118_skew_symmetry_and_passivity():
    """(9.109) dd_kj/dt; (9.110) n_kj = sum_i (dd_ij/dq_k - dd_ki/dq_j) qd_i (printed 'd_j': a typo);
    (9.111) n_jk = -n_kj, for a generic symmetric D; (9.113)-(9.117) dH/dt = qd^T tau along the
    motion for kinedyn's planar elbow ((9.115) prints C for C qd: a typo); (9.118) integrates it."""
    c = christoffel_spong(DG, Q)
    C = sp.Matrix(2, 2, lambda k, j: sum(c[i][j][k] * QD[i] for i in range(2)))
    Ddot = DG.applyfunc(ddt)
    N = Ddot - 2 * C
    N_pr = sp.Matrix(
        2, 2, lambda k, j: sum((sp.diff(DG[i, j], Q[k]) - sp.diff(DG[k, i], Q[j])) * QD[i] for i in range(2))
    )
    assert all_zero(N - N_pr) and all_zero(N + N.T)
    eom, rename = kinedyn_planar_elbow()
    M, Ck, gk = (x.xreplace(rename) for x in (eom.M, eom.C, eom.g))
    H = (sp.Matrix(QD).T * M * sp.Matrix(QD))[0] / 2 + eom.P.xreplace(rename)
    tau = M * sp.Matrix(QDD) + Ck * sp.Matrix(QD) + gk
    assert is_zero(ddt(H) - sp.Matrix(QD).dot(tau))
    Nk = M.applyfunc(ddt) - 2 * Ck
    assert is_zero((sp.Matrix(QD).T * Nk * sp.Matrix(QD))[0])
    assert all_zero(Nk + Nk.T)
    # kinedyn's property check agrees with this derivation: proved, not sampled
    report = eom.check_properties()
    assert report["dD/dt - 2C skew"].status == "proved" and report["dD/dt == C + C^T"].status == "proved"


def test_spong_9_121_to_9_133_regressor_misprints():
    """(9.122)-(9.133) for the planar elbow. tau derived here equals Y Theta only with Theta3 =
    m2 lc2^2 + I2 (printed m2 l1 lc2: MISPRINT), Theta5 = m2 lc2 (printed m2 l2: MISPRINT), (9.131)
    phi2 = Theta5 g cos(q1 + q2) (printed without g: MISPRINT), and the Y derived here: the printed Y
    (9.132) has s2 (qd1^2 - 2 qd1 qd2) in row 1 (MISPRINT: -s2 (qd2^2 + 2 qd1 qd2)) and qdd2 in row 2,
    column 3 (MISPRINT: qdd1 + qdd2). (9.125)-(9.127), (9.130) hold. (9.121) prints D(q) for D(q) qdd:
    a typo. kinedyn's eom.regressor() reproduces the same tau."""
    rc1, rc2, K, P, D = planar_elbow_by_particles()
    tau = sp.Matrix(euler_lagrange(K - P))
    Th_pr = [m1 * lc1**2 + m2 * (l1**2 + lc2**2) + I1 + I2, m2 * l1 * lc2, m2 * l1 * lc2, m1 * lc1 + m2 * l1, m2 * l2]
    Th = [Th_pr[0], Th_pr[1], m2 * lc2**2 + I2, Th_pr[3], m2 * lc2]
    assert (
        is_zero(D[0, 0] - (Th[0] + 2 * Th[1] * cos(q2)))
        and is_zero(D[0, 1] - (Th[2] + Th[1] * cos(q2)))
        and is_zero(D[1, 1] - Th[2])
    )
    misprint(Th_pr[2], D[1, 1], Th[2])
    phi = [sp.diff(P, x) for x in Q]
    assert is_zero(phi[0] - (Th[3] * g * cos(q1) + Th[4] * g * cos(q1 + q2)))
    misprint(Th_pr[4] * cos(q1 + q2), phi[1], Th[4] * g * cos(q1 + q2))
    Y_pr = sp.Matrix(
        [
            [
                qdd1,
                cos(q2) * (2 * qdd1 + qdd2) + sin(q2) * (qd1**2 - 2 * qd1 * qd2),
                qdd2,
                g * cos(q1),
                g * cos(q1 + q2),
            ],
            [0, cos(q2) * qdd1 + sin(q2) * qd1**2, qdd2, 0, g * cos(q1 + q2)],
        ]
    )
    Y = sp.Matrix(
        [
            [
                qdd1,
                cos(q2) * (2 * qdd1 + qdd2) - sin(q2) * (qd2**2 + 2 * qd1 * qd2),
                qdd2,
                g * cos(q1),
                g * cos(q1 + q2),
            ],
            [0, cos(q2) * qdd1 + sin(q2) * qd1**2, qdd1 + qdd2, 0, g * cos(q1 + q2)],
        ]
    )
    misprint(list(Y_pr * sp.Matrix(Th)), list(tau), list(Y * sp.Matrix(Th)))
    assert max(abs(at_random_state(e)) for e in Y_pr * sp.Matrix(Th_pr) - tau) > 1e-6
    eom, rename = kinedyn_planar_elbow()
    Yk, Thk = eom.regressor()
    assert all_zero((Yk * Thk).xreplace(rename) - tau)


def test_spong_9_119_9_120_eigenvalue_bounds_at_a_configuration():
    """(9.119) lambda_1(q) I <= D(q) <= lambda_n(q) I: D - lambda_1 I and lambda_n I - D are positive
    semidefinite (eigenvalues >= 0) for kinedyn's planar elbow at random q. The uniform bounds (9.120)
    by a global search: tests/test_properties_proved.py (closed form for the 2R)."""
    eom, rename = kinedyn_planar_elbow()
    vals = {m1: 2.0, m2: 1.5, l1: 1.3, lc1: 0.6, lc2: 0.35, I1: 0.21, I2: 0.13}
    f = sp.lambdify([Q], eom.M.xreplace(rename).xreplace(vals), "numpy")
    for qq in RNG.uniform(-math.pi, math.pi, size=(20, 2)):
        D = np.array(f(qq), float)
        lam = np.linalg.eigvalsh(D)
        assert lam[0] > 0
        assert (
            np.linalg.eigvalsh(D - lam[0] * np.eye(2)).min() > -1e-12
            and np.linalg.eigvalsh(lam[-1] * np.eye(2) - D).min() > -1e-12
        )


# ============================================================================================== LaValle §13.4
tt = sp.Symbol("t", real=True)
x_, xd_, xdd_ = sp.symbols("x xd xdd", real=True)


def test_lavalle_13_114_to_13_118_first_variation_and_integration_by_parts():
    """(13.116): Phi(x + g) - Phi(x) = int (dL/dx g + dL/dxd g') dt + O(g^2), checked with L = x^3 +
    xd^2 (13.119), x = t^2, h = sin(pi t), g = eps h on [0, 1] (exact integrals); its last line
    (integration by parts) equals the second; (13.117) prints the last integral with h for g: with
    g = eps h it is off by the factor eps (a typo); (13.118) then follows: the boundary term vanishes."""
    eps = sp.Symbol("epsilon", positive=True)
    X = tt**2
    h = sin(sp.pi * tt)
    G = eps * h
    Lf = lambda x, xd: x**3 + xd**2
    Phi = lambda x: sp.integrate(Lf(x, sp.diff(x, tt)), (tt, 0, 1))
    dLdx = 3 * X**2
    dLdxd = 2 * sp.diff(X, tt)
    first = sp.integrate(dLdx * G + dLdxd * sp.diff(G, tt), (tt, 0, 1))
    change = sp.expand(Phi(X + G) - Phi(X))
    assert sp.simplify(change.coeff(eps, 1) - first.coeff(eps, 1)) == 0
    by_parts = (
        sp.integrate(dLdx * G - sp.diff(dLdxd, tt) * G, (tt, 0, 1)) + (dLdxd * G).subs(tt, 1) - (dLdxd * G).subs(tt, 0)
    )
    assert sp.simplify(by_parts - first) == 0
    boundary = (dLdxd * G).subs(tt, 1) - (dLdxd * G).subs(tt, 0)
    right = sp.integrate(dLdxd * sp.diff(G, tt), (tt, 0, 1)) + sp.integrate(sp.diff(dLdxd, tt) * G, (tt, 0, 1))
    printed = sp.integrate(dLdxd * sp.diff(G, tt), (tt, 0, 1)) + sp.integrate(sp.diff(dLdxd, tt) * h, (tt, 0, 1))
    assert sp.simplify(boundary - right) == 0
    assert sp.simplify((printed - boundary).subs(eps, sp.Rational(1, 2))) != 0


def test_lavalle_examples_13_9_and_13_10_and_kinedyn():
    """Ex 13.9 (13.115): E-L of sqrt(1 + xd^2) is -xdd / (1 + xd^2)^(3/2) = 0 (straight lines; nothing
    printed to compare). Ex 13.10 (13.119)-(13.123): dL/dx = 3x^2, dL/dxd = 2xd, d/dt = 2xdd,
    2xdd - 3x^2 = 0, xdd = 3x^2/2. kinedyn's LagrangianSystem(L=...) gives the same E-L expressions."""
    (el9,) = euler_lagrange(sp.sqrt(1 + xd_**2), [x_], [xd_], [xdd_])
    assert sp.simplify(el9 - xdd_ / (1 + xd_**2) ** sp.Rational(3, 2)) == 0
    L10 = x_**3 + xd_**2
    assert sp.diff(L10, x_) == 3 * x_**2 and sp.diff(L10, xd_) == 2 * xd_
    (el10,) = euler_lagrange(L10, [x_], [xd_], [xdd_])
    assert sp.expand(el10 - (2 * xdd_ - 3 * x_**2)) == 0
    assert sp.solve(el10, xdd_) == [3 * x_**2 / 2]
    for L, el in ((sp.sqrt(1 + xd_**2), el9), (L10, el10)):
        system = LagrangianSystem([x_], L=L, qd=[xd_])
        (k,) = system.euler_lagrange()
        assert sp.simplify(k.xreplace({system.qdd[0]: xdd_}) - el) == 0


V = sp.Function("V")


def test_lavalle_13_128_newton_in_euler_lagrange_form_sign_misprint():
    """(13.128) prints d/dt (m qd) - dV/dq = 0. With V the potential energy (force -dV/dq, as
    13.130 and Ex 13.11 use) Newton's law m qdd = -dV/dq is d/dt (m qd) + dV/dq = 0: the E-L equation of
    L = m qd^2/2 - V(q) (13.129) derived here."""
    (el,) = euler_lagrange(m * xd_**2 / 2 - V(x_), [x_], [xd_], [xdd_])
    misprint(m * xdd_ - sp.diff(V(x_), x_), el, m * xdd_ + sp.diff(V(x_), x_))
    # (13.130): d/dt dK/dqd - dK/dq + dV/dq for K = qd^T M qd / 2 (the generic 2-DOF system above)
    K = (sp.Matrix(QD).T * DG * sp.Matrix(QD))[0] / 2
    for k in range(2):
        assert sp.expand(ddt(sp.diff(K, QD[k])) - sp.diff(K, Q[k]) + sp.diff(Pf, Q[k]) - ELG[k]) == 0


def test_lavalle_13_131_to_13_135_falling_particle_and_13_136_13_137():
    """Ex 13.11: (13.131) K, (13.132) L (printed '= 0' at its end: a typo), (13.133) d/dt dL/dqd_i =
    m qdd_i, (13.134) dV/dq = (0, 0, mg), (13.135) m qdd1 = m qdd2 = 0, m qdd3 + mg = 0; kinedyn's
    LagrangianSystem agrees. (13.137): the double sum equals the quadratic form."""
    qs, vs, acc = sp.symbols("q1:4", real=True), sp.symbols("qd1:4", real=True), sp.symbols("qdd1:4", real=True)
    K = m * sum(v**2 for v in vs) / 2
    Vp = m * g * qs[2]
    el = euler_lagrange(K - Vp, qs, vs, acc)
    assert [ddt(sp.diff(K - Vp, v), qs, vs, acc) for v in vs] == [m * a for a in acc]
    assert [sp.diff(Vp, c) for c in qs] == [0, 0, m * g]
    assert [sp.expand(e) for e in el] == [m * acc[0], m * acc[1], m * acc[2] + m * g]
    eom = LagrangianSystem(list(qs), K=K, P=Vp, qd=list(vs)).equations_of_motion()
    assert all_zero(eom.tau.xreplace(dict(zip(eom.qdd, acc))) - sp.Matrix(el))
    Mg = sp.Matrix(3, 3, lambda i, j: sp.Function(f"m{i}{j}")(*qs) if i <= j else sp.Function(f"m{j}{i}")(*qs))
    assert (
        sp.expand(
            (sp.Matrix(vs).T * Mg * sp.Matrix(vs))[0] / 2
            - sum(Mg[i, j] * vs[i] * vs[j] for i in range(3) for j in range(3)) / 2
        )
        == 0
    )


def test_lavalle_example_13_12_planar_body_kinetic_energy_misprint():
    """Ex 13.12: (13.138) K = m qd . qd / 2 + I qd3^2 / 2 with qd = (qd1, qd2, qd3) counts the
    rotation twice (the third E-L equation becomes (m + I) qdd3 = u3, not the printed I qdd3 = u3 of
    13.139): the dot product is over the translation (qd1, qd2) only; with it (13.139) holds."""
    qs, vs, acc = sp.symbols("q1:4", real=True), sp.symbols("qd1:4", real=True), sp.symbols("qdd1:4", real=True)
    Ib = sp.Symbol("I", positive=True)
    printed = m * sum(v**2 for v in vs) / 2 + Ib * vs[2] ** 2 / 2
    corrected = m * (vs[0] ** 2 + vs[1] ** 2) / 2 + Ib * vs[2] ** 2 / 2
    # a planar body of particles moving with centre velocity (vx, vy) and rate w: its kinetic energy is
    # the corrected K with m = total mass, I = the moment about the centre (the printed K is larger)
    vx, vy, w = 0.3, -0.8, 1.7
    pts = RNG.normal(size=(30, 2))
    mp = RNG.uniform(0.1, 1.0, size=30)
    c = mp @ pts / mp.sum()
    K_particles = 0.5 * sum(
        mi * ((vx - w * (p_[1] - c[1])) ** 2 + (vy + w * (p_[0] - c[0])) ** 2) for mi, p_ in zip(mp, pts)
    )
    Izz = sum(mi * ((p_ - c) @ (p_ - c)) for mi, p_ in zip(mp, pts))
    num = {m: mp.sum(), Ib: Izz, vs[0]: vx, vs[1]: vy, vs[2]: w}
    assert float(corrected.xreplace(num)) == pytest.approx(K_particles, rel=1e-12)
    assert abs(float(printed.xreplace(num)) - K_particles) > 0.1
    assert sp.expand(printed - corrected) == m * vs[2] ** 2 / 2
    el_pr = euler_lagrange(printed, qs, vs, acc)
    el = euler_lagrange(corrected, qs, vs, acc)
    assert [sp.expand(e) for e in el] == [m * acc[0], m * acc[1], Ib * acc[2]]
    assert sp.expand(el_pr[2] - (m + Ib) * acc[2]) == 0


def test_lavalle_13_140_to_13_147_general_form_and_christoffel_index_order():
    """(13.140)-(13.141) E-L = sum m_ij qdd_j + sum h_ijk qd_j qd_k + g_i with h_ijk = dm_ij/dq_k -
    dm_jk/dq_i / 2; (13.142)-(13.144) C qd = sum h qd qd; (13.145) the rewriting; (13.146)-(13.147)
    c_ij = sum_k c_ijk qd_k, c_ijk = (dm_ij/dq_k + dm_ik/dq_j - dm_jk/dq_i)/2 (row index first:
    LaValle's c_ijk is Spong's c_kji), for the generic 2-DOF system; kinedyn's eom.christoffel (Spong's
    order) maps onto it for the planar elbow."""
    M = DG
    h = lambda i, j, k: sp.diff(M[i, j], Q[k]) - sp.diff(M[j, k], Q[i]) / 2
    cL = lambda i, j, k: (sp.diff(M[i, j], Q[k]) + sp.diff(M[i, k], Q[j]) - sp.diff(M[j, k], Q[i])) / 2
    C = sp.Matrix(2, 2, lambda i, j: sum(cL(i, j, k) * QD[k] for k in range(2)))
    for i in range(2):
        form = (
            sum(M[i, j] * QDD[j] for j in range(2))
            + sum(h(i, j, k) * QD[j] * QD[k] for j in range(2) for k in range(2))
            + sp.diff(Pf, Q[i])
        )
        assert sp.expand(form - ELG[i]) == 0
        hsum = sum(h(i, j, k) * QD[j] * QD[k] for j in range(2) for k in range(2))
        rewritten = (
            sum(sp.diff(M[i, j], Q[k]) * QD[j] * QD[k] for j in range(2) for k in range(2)) / 2
            + sum((sp.diff(M[i, j], Q[k]) - sp.diff(M[j, k], Q[i])) * QD[j] * QD[k] for j in range(2) for k in range(2))
            / 2
        )
        assert sp.expand(hsum - rewritten) == 0  # (13.145)
        assert sp.expand((C * sp.Matrix(QD))[i] - hsum) == 0  # (13.143), (13.146)
    cS = christoffel_spong(M, Q)
    assert all(sp.expand(cL(i, j, k) - cS[k][j][i]) == 0 for i in range(2) for j in range(2) for k in range(2))
    eom, rename = kinedyn_planar_elbow()
    Mk = eom.M.xreplace(rename)
    cLk = lambda i, j, k: (sp.diff(Mk[i, j], Q[k]) + sp.diff(Mk[i, k], Q[j]) - sp.diff(Mk[j, k], Q[i])) / 2
    assert all(
        is_zero(eom.christoffel[k][j][i].xreplace(rename) - cLk(i, j, k))
        for i in range(2)
        for j in range(2)
        for k in range(2)
    )


def test_lavalle_13_148_phase_form_and_the_numeric_core():
    """(13.148) qdd = M^-1 (u - C qd - g): the engine's forward dynamics (ABA) equals it with its own
    M, C, g, and solves M qdd + C qd + g = u."""
    pytest.importorskip("kinedyn._core")
    robot = kd.robots.puma560()
    q, qd, u = RNG.uniform(-1, 1, 6), RNG.normal(size=6), RNG.normal(size=6)
    M, C, gv = robot.mass_matrix(q), robot.coriolis_matrix(q, qd), robot.gravity_torque(q)
    qdd = robot.forward_dynamics(q, qd, u)
    np.testing.assert_allclose(
        qdd, np.linalg.solve(M, u - C @ qd - gv - robot.friction_torque(qd)), rtol=1e-9, atol=1e-9
    )


d1s, ell1, ell2 = sp.symbols("d1 ell1 ell2", positive=True)


def test_lavalle_example_13_13_two_link_manipulator():
    """Ex 13.13, theta2 relative (m11's cos theta2 term says so), d1 = link 1's length, ell_i = joint i
    to COM i. Derived here from the centres of mass: (13.149) K1 = m1 ell1 thd1^2/2 + ... MISPRINT
    (ell1^2); (13.150) V1 OK; (13.151) K2 = p.p/2 + ... MISPRINT (m2 pdot.pdot/2); (13.152) p with
    ell2 cos theta2: MISPRINT (cos(theta1 + theta2)); (13.153) V2 likewise MISPRINT; (13.155)-(13.156)
    M OK; (13.157) c112 = c121 = c122 = -c211 = -m2 ell1 ell2 p2: MISPRINT (-m2 d1 ell2 sin theta2);
    (13.158) g1 = (m1 ell1 + m2 d1) g p1 + m1 ell2 p2, g2 = m2 ell2 g p2: MISPRINT; (13.159) C with
    +thd1 at (2,1): MISPRINT (-thd1); (13.160) r likewise; (13.161) row 1 OK with the corrected r, row 2
    m22 thdd1 + m21 thdd2: MISPRINT (m21 thdd1 + m22 thdd2). kinedyn's planar_2r (lc1 = ell1, lc2 =
    ell2, l1 = d1) gives the derived M, C, g."""
    rc1 = sp.Matrix([ell1 * cos(th1), ell1 * sin(th1)])
    pc2 = sp.Matrix([d1s * cos(th1) + ell2 * cos(th1 + th2), d1s * sin(th1) + ell2 * sin(th1 + th2)])
    v1, v2 = rc1.jacobian(TH) * sp.Matrix(THD), pc2.jacobian(TH) * sp.Matrix(THD)
    K1 = m1 * v1.dot(v1) / 2 + I1 * thd1**2 / 2
    misprint(m1 * ell1 * thd1**2 / 2 + I1 * thd1**2 / 2, K1, m1 * ell1**2 * thd1**2 / 2 + I1 * thd1**2 / 2)
    assert is_zero(m1 * g * rc1[1] - m1 * g * ell1 * sin(th1))
    K2 = m2 * v2.dot(v2) / 2 + I2 * (thd1 + thd2) ** 2 / 2
    misprint(v2.dot(v2) / 2 + I2 * (thd1 + thd2) ** 2 / 2, K2, m2 * v2.dot(v2) / 2 + I2 * (thd1 + thd2) ** 2 / 2)
    p_pr = sp.Matrix([d1s * cos(th1) + ell2 * cos(th2), d1s * sin(th1) + ell2 * sin(th2)])
    misprint(list(p_pr), list(pc2), list(pc2))
    V2 = m2 * g * pc2[1]
    misprint(m2 * g * (d1s * sin(th1) + ell2 * sin(th2)), V2, m2 * g * (d1s * sin(th1) + ell2 * sin(th1 + th2)))
    L = K1 + K2 - m1 * g * rc1[1] - V2
    M = sp.hessian(K1 + K2, THD)
    M_pr = sp.Matrix(
        [
            [
                I1 + m1 * ell1**2 + I2 + m2 * (d1s**2 + ell2**2 + 2 * d1s * ell2 * cos(th2)),
                I2 + m2 * (ell2**2 + d1s * ell2 * cos(th2)),
            ],
            [I2 + m2 * (ell2**2 + d1s * ell2 * cos(th2)), I2 + m2 * ell2**2],
        ]
    )
    assert all_zero(M - M_pr)
    cL = lambda i, j, k: (sp.diff(M[i, j], TH[k]) + sp.diff(M[i, k], TH[j]) - sp.diff(M[j, k], TH[i])) / 2
    r = m2 * d1s * ell2 * sin(th2)
    p2_printed = p_pr[1]
    for (i, j, k), sign in {(0, 0, 1): -1, (0, 1, 0): -1, (0, 1, 1): -1, (1, 0, 0): 1}.items():
        misprint(sign * m2 * ell1 * ell2 * p2_printed, cL(i, j, k), sign * r)
    for i, j, k in ((0, 0, 0), (1, 0, 1), (1, 1, 0), (1, 1, 1)):
        assert is_zero(cL(i, j, k))
    gv = sp.Matrix([sp.diff(m1 * g * rc1[1] + V2, c) for c in TH])
    g_pr = [(m1 * ell1 + m2 * d1s) * g * p_pr[0] + m1 * ell2 * p_pr[1], m2 * ell2 * g * p_pr[1]]
    g_ok = [(m1 * ell1 + m2 * d1s) * g * cos(th1) + m2 * ell2 * g * cos(th1 + th2), m2 * ell2 * g * cos(th1 + th2)]
    misprint(g_pr, list(gv), g_ok)
    C = sp.Matrix(2, 2, lambda i, j: sum(cL(i, j, k) * THD[k] for k in range(2)))
    misprint(
        list(-m2 * ell1 * ell2 * p2_printed * sp.Matrix([[thd2, thd1 + thd2], [thd1, 0]])),
        list(C),
        list(-r * sp.Matrix([[thd2, thd1 + thd2], [-thd1, 0]])),
    )
    tau = euler_lagrange(L, TH, THD, THDD)
    assert is_zero(tau[0] - (M[0, 0] * thdd1 + M[0, 1] * thdd2 - 2 * r * thd1 * thd2 - r * thd2**2 + gv[0]))
    misprint(
        M[1, 1] * thdd1 + M[1, 0] * thdd2 + r * thd1**2 + gv[1],
        tau[1],
        M[1, 0] * thdd1 + M[1, 1] * thdd2 + r * thd1**2 + gv[1],
    )
    eom, rename = kinedyn_planar_elbow()
    to_lavalle = {q1: th1, q2: th2, qd1: thd1, qd2: thd2, lc1: ell1, lc2: ell2, l1: d1s}
    assert all_zero(eom.M.xreplace(rename).xreplace(to_lavalle) - M)
    assert all_zero(eom.C.xreplace(rename).xreplace(to_lavalle) - C)
    assert all_zero(eom.g.xreplace(rename).xreplace(to_lavalle) - gv)


def test_lavalle_13_162_to_13_171_multipliers_and_pfaffian_constraints():
    """(13.162)-(13.164): extremes of h = x + y on x^2 + y^2 = 1 satisfy grad h + lambda grad g = 0
    (solved here: (1, 1)/sqrt 2 with lambda = -1/sqrt 2); (13.165) a parametric constraint as an implicit
    one; (13.166)-(13.169): L_c has no lambda-dot, so the multiplier equations reduce to dL_c/dlambda_i =
    g_i = 0; (13.170)-(13.171): d/dt g(q) = sum dg/dq_j qd_j (the sphere's 13.176)."""
    xx, yy, lam = sp.symbols("x y lambda", real=True)
    sols = sp.solve([1 + lam * 2 * xx, 1 + lam * 2 * yy, xx**2 + yy**2 - 1], [xx, yy, lam], dict=True)
    assert {(s[xx], s[yy], s[lam]) for s in sols} == {
        (sp.sqrt(2) / 2, sp.sqrt(2) / 2, -sp.sqrt(2) / 2),
        (-sp.sqrt(2) / 2, -sp.sqrt(2) / 2, sp.sqrt(2) / 2),
    }
    qs, vs = sp.symbols("q1:4", real=True), sp.symbols("qd1:4", real=True)
    gsph = sum(c**2 for c in qs) - 1
    Lc = sum(v**2 for v in vs) + lam * gsph
    lamd = sp.Symbol("lambdadot", real=True)
    assert sp.diff(Lc, lamd) == 0 and sp.diff(Lc, lam) == gsph
    gdot = ddt(gsph, qs, vs, [0, 0, 0])
    assert sp.expand(gdot - (2 * qs[0] * vs[0] + 2 * qs[1] * vs[1] + 2 * qs[2] * vs[2])) == 0


def test_lavalle_example_13_14_sphere_and_13_172_13_173():
    """Ex 13.14, m = 2: (13.174) L, (13.175) g1, (13.176) its Pfaffian form; (13.172) gives
    2 qdd_i + 2 lambda1 q_i = 0; the printed (13.177) qdd_i - 2 q_i lambda1 = 0 is not what (13.172)
    gives (sign and factor: MISPRINT; it matches only with lambda1 renamed -lambda1/2, harmless for the
    conclusion). (13.178): qdd parallel to q keeps q x qd constant, so c . q = 0 with c = q0 x qd0 (a
    great circle): checked on an RK4 run with lambda eliminated (lambda = |qd|^2 on the unit sphere).
    (13.173) differs from (13.172) by the multiplier's sign only. kinedyn's LagrangianSystem gives the
    same multiplier."""
    qs, vs, acc = (
        list(sp.symbols("q1:4", real=True)),
        list(sp.symbols("qd1:4", real=True)),
        list(sp.symbols("qdd1:4", real=True)),
    )
    lam = sp.Symbol("lambda1", real=True)
    L = sum(v**2 for v in vs)  # m/2 |qd|^2 with m = 2
    G = [2 * c for c in qs]
    el = euler_lagrange(L, qs, vs, acc)
    derived = [el[i] + lam * G[i] for i in range(3)]
    assert [sp.expand(e) for e in derived] == [2 * acc[i] + 2 * lam * qs[i] for i in range(3)]
    for i in range(3):
        misprint(acc[i] - 2 * qs[i] * lam, derived[i] / 2, acc[i] + lam * qs[i])
    # eliminate lambda with the constraint twice differentiated: q . qdd + |qd|^2 = 0
    lam_solved = sp.solve(sum(qs[i] * (-lam * qs[i]) for i in range(3)) + sum(v**2 for v in vs), lam)[0]
    assert sp.simplify(lam_solved.subs(qs[0] ** 2, 1 - qs[1] ** 2 - qs[2] ** 2) - sum(v**2 for v in vs)) == 0
    system = LagrangianSystem(qs, K=L, qd=vs, holonomic=[sum(c**2 for c in qs) - 1], forces=[0, 0, 0])
    (lam_k,) = system.multipliers()
    assert (
        sp.simplify(
            (lam_k - sum(v**2 for v in vs) / sum(c**2 for c in qs)).subs(qs[0] ** 2, 1 - qs[1] ** 2 - qs[2] ** 2)
        )
        == 0
    )

    def f(s):
        x, v = s[:3], s[3:]
        return np.concatenate([v, -(v @ v) / (x @ x) * x])

    s = np.concatenate([np.ones(3) / math.sqrt(3), [0.3, -0.1, -0.2]])
    c = np.cross(s[:3], s[3:])
    h_ = 1e-3
    for _ in range(3000):
        k1 = f(s)
        k2 = f(s + h_ / 2 * k1)
        k3 = f(s + h_ / 2 * k2)
        k4 = f(s + h_ * k3)
        s = s + h_ / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    assert abs(c @ s[:3]) < 1e-12 and abs(np.linalg.norm(s[:3]) - 1) < 1e-9


def test_lavalle_13_179_to_13_184_constrained_dynamics():
    """(13.179) M qdd + C qd + g + G^T lambda = u with G k x n (printed n x k: MISPRINT, G^T lambda must be
    n x 1 for lambda in R^k). (13.180) lambda = (G M^-1 G^T)^-1 G M^-1 (u - C qd): with (13.179) and
    G qdd + Gdot qd = 0 the multiplier is (G M^-1 G^T)^-1 (G M^-1 (u - C qd - g) + Gdot qd): (13.180)
    leaves out g and Gdot qd, (13.184) leaves out Gdot qd (MISPRINTs: "G time-invariant" is false for
    any q-dependent constraint). For the sphere (13.180) gives lambda = 0 while the derivation (and
    kinedyn's LagrangianSystem.multipliers) give |qd|^2. (13.181)-(13.183) add B and N: OK."""
    qs, vs = list(sp.symbols("q1:4", real=True)), list(sp.symbols("qd1:4", real=True))
    M = 2 * sp.eye(3)
    G = sp.Matrix([[2 * c for c in qs]])  # k x n = 1 x 3
    lam = sp.Matrix([sp.Symbol("lambda1", real=True)])
    assert (G.T * lam).shape == (3, 1)
    G_printed_shape = G.T  # n x k as printed: its transpose times lambda in R^k is not defined
    with pytest.raises(sp.ShapeError):
        _ = G_printed_shape.T * lam
    Gdot = G.applyfunc(lambda e: ddt(e, qs, vs, [0, 0, 0]))
    u = sp.zeros(3, 1)
    derived = (G * M.inv() * G.T).inv() * (G * M.inv() * u + Gdot * sp.Matrix(vs))
    printed_180 = (G * M.inv() * G.T).inv() * G * M.inv() * u
    on_sphere = {qs[0] ** 2: 1 - qs[1] ** 2 - qs[2] ** 2}
    assert sp.simplify(derived[0].subs(on_sphere) - sum(v**2 for v in vs)) == 0
    assert printed_180[0] == 0
    system = LagrangianSystem(
        qs, K=sum(v**2 for v in vs), qd=vs, holonomic=[sum(c**2 for c in qs) - 1], forces=[0, 0, 0]
    )
    assert sp.simplify((system.multipliers()[0] - derived[0]).subs(on_sphere)) == 0
    # the general formula: qdd from (13.179) with this lambda keeps G qdd + Gdot qd = 0 (gravity g and B = N included)
    gv = sp.Matrix([0, 0, 2 * g])
    N = sp.Matrix([sp.Symbol(f"b{i}", real=True) * vs[i] for i in range(3)])
    lam_full = (G * M.inv() * G.T).inv() * (G * M.inv() * (u - gv - N) + Gdot * sp.Matrix(vs))
    qdd = M.inv() * (u - gv - N - G.T * lam_full)
    assert sp.simplify((G * qdd + Gdot * sp.Matrix(vs))[0]) == 0
    lam_184 = (G * M.inv() * G.T).inv() * G * M.inv() * (u - gv - N)
    qdd_184 = M.inv() * (u - gv - N - G.T * lam_184)
    assert sp.simplify((G * qdd_184 + Gdot * sp.Matrix(vs))[0]) != 0
