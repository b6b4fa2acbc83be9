"""Question 3 of the seed tutorial: the Lagrangian dynamics of the two-link arm of uniform rods,
derived by kinedyn and checked against a Lagrangian written from the geometry of the rods."""

from __future__ import annotations

import math
import re

import numpy as np
import sympy as sp

from .answers import Answer, Comparison, arm_2r_symbolic, fmt_number, tutorial_display
from .printed import g, l1, l2, m1, m2, printed, th1, th2, thd1, thd2, thdd1, thdd2


# ------------------------------------------------------------------ Q3: Lagrangian dynamics of the rod arm
class _RodArm:
    """The tutorial's arm of two uniform rods written from its geometry alone (not from kinedyn):
    link 1 pivots at A (I_A = m1 l1^2/3), link 2's centre D is at l1 (C1, S1) + l2/2 (C12, S12) with
    I_D = m2 l2^2/12; gravity -g along y. Every derivative is a central finite difference."""

    def __init__(self, m1, m2, l1, l2, g):
        self.m1, self.m2, self.l1, self.l2, self.g = m1, m2, l1, l2, g

    def D(self, q):
        return np.array(
            [
                self.l1 * math.cos(q[0]) + self.l2 / 2 * math.cos(q[0] + q[1]),
                self.l1 * math.sin(q[0]) + self.l2 / 2 * math.sin(q[0] + q[1]),
            ]
        )

    def vD(self, q, qd, h=1e-4):
        """v_D = (dD/dq) qd, dD/dq by central differences (so v_D is exactly linear in qd)."""
        J = np.column_stack([(self.D(q + h * e) - self.D(q - h * e)) / (2 * h) for e in np.eye(2)])
        return J @ qd

    def vD2(self, q, qd):
        v = self.vD(q, qd)
        return float(v @ v)

    def K(self, q, qd):
        IA, ID = self.m1 * self.l1**2 / 3, self.m2 * self.l2**2 / 12
        return 0.5 * IA * qd[0] ** 2 + 0.5 * ID * (qd[0] + qd[1]) ** 2 + 0.5 * self.m2 * self.vD2(q, qd)

    def P(self, q):
        return self.m1 * self.g * self.l1 / 2 * math.sin(q[0]) + self.m2 * self.g * self.D(q)[1]

    def L(self, q, qd):
        return self.K(q, qd) - self.P(q)

    @staticmethod
    def _d(f, h):
        """Fourth-order central difference f'(0)."""
        return (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)

    def dL_dq(self, q, qd, k, h=1e-3):
        e = np.eye(2)[k]
        return self._d(lambda t: self.L(q + t * e, qd), h)

    def dL_dqd(self, q, qd, k, h=0.5):
        e = np.eye(2)[k]  # L is quadratic in qd: the difference is exact for any h
        return (self.L(q, qd + h * e) - self.L(q, qd - h * e)) / (2 * h)

    def ddt_dL_dqd(self, q, qd, qdd, k, h=1e-3):
        """d/dt of dL/dqd_k along q(t) = q + qd t + qdd t^2/2."""
        return self._d(lambda t: self.dL_dqd(q + qd * t + qdd * t * t / 2, qd + qdd * t, k), h)

    def tau(self, q, qd, qdd, k):
        return self.ddt_dL_dqd(q, qd, qdd, k) - self.dL_dq(q, qd, k)

    def power_balance(self, q, qd, qdd, tau, h=1e-3):
        """qd . tau - dH/dt along the motion (zero for the true torques; H = K + P)."""
        H = lambda t: self.K(q + qd * t + qdd * t * t / 2, qd + qdd * t) + self.P(q + qd * t + qdd * t * t / 2)
        return float(qd @ tau - self._d(H, h))


def _q3_robot():
    """The tutorial's arm in kinedyn: planar_2r with symbols, uniform rods (lc = l/2, I = m l^2/12)."""
    robot = arm_2r_symbolic()
    s = {n: sp.Symbol(n, positive=True) for n in ("l1", "l2", "lc1", "lc2", "m1", "m2", "I1", "I2")}
    return robot.subs(
        {
            s["lc1"]: s["l1"] / 2,
            s["lc2"]: s["l2"] / 2,
            s["I1"]: s["m1"] * s["l1"] ** 2 / 12,
            s["I2"]: s["m2"] * s["l2"] ** 2 / 12,
        }
    )


def _to_tutorial(eom):
    """Substitution from kinedyn's state symbols (q_i, qd_i, qdd_i) and parameters to the tutorial's."""
    rep = dict(zip(list(eom.q) + list(eom.qd) + list(eom.qdd), [th1, th2, thd1, thd2, thdd1, thdd2]))
    for s in eom.parameters if hasattr(eom, "parameters") else []:
        t = {"l1": l1, "l2": l2, "m1": m1, "m2": m2, "g": g}.get(str(s))
        if t is not None:
            rep[s] = t
    return lambda e: sp.sympify(e).xreplace(rep)


def _pretty_collect(e):
    e = sp.expand(e)
    return sp.collect(e, [thdd1, thdd2, thd1 * thd2, thd1**2, thd2**2], func=sp.factor)


_Q3_SAMPLES = [
    # (m1, m2, l1, l2, g, q, qd, qdd): generic values, so that no term vanishes
    (1.3, 2.1, 1.7, 2.3, 9.81, (0.4, -1.1), (0.9, 1.6), (0.7, -0.5)),
    (0.8, 1.5, 2.0, 3.0, 9.81, (-2.2, 0.7), (-1.3, 0.6), (-0.4, 1.2)),
]


def question_3() -> Answer:
    a = Answer(
        "3",
        "Equations of motion of the two-link arm by Lagrange's method",
        "Derive the equations of motion of the two-link arm of uniform rods (m1, l1; m2, l2; gravity -g along y).",
    )
    robot = _q3_robot()
    a.text(
        "kinedyn: robot = kd.robots.planar_2r(symbolic=True) with uniform rods (lc_i = l_i/2, I_i = m_i l_i^2/12 about the centre), "
        "eom = robot.equations_of_motion(). The steps of kinedyn's derivation (eom.steps), in the tutorial's notation "
        "(theta_i = q_i, C12 = cos(theta1 + theta2), ...):"
    )
    eom = robot.equations_of_motion()
    T = _to_tutorial(eom)
    for k, step in enumerate(eom.steps, start=1):
        if step.title.startswith("Christoffel"):
            continue
        a.text(f"Step {k}: {step.title}")  # its sentence on a line of its own: " - " would read as a minus
        if step.text:
            a.text(step.text)
        for lhs, value in step.equations:
            v = value.applyfunc(T) if isinstance(value, sp.MatrixBase) else _pretty_collect(T(value))
            a.eq(_plain_lhs(lhs), v)
    # kinedyn's values of the tutorial's intermediate quantities, by the chain rule applied to eom.L
    K, P = T(eom.K), T(eom.P)
    L = K - P
    qs, qds, qdds = [th1, th2], [thd1, thd2], [thdd1, thdd2]

    def ddt(e):
        return sum(sp.diff(e, qs[j]) * qds[j] + sp.diff(e, qds[j]) * qdds[j] for j in range(2))

    vD2 = None
    for step in eom.steps:  # kinedyn's centre of mass of link 2 (the tutorial's point D), differentiated in time
        for lhs, value in step.equations:
            if lhs == "r_{c2}":
                rD = sp.Matrix(value).applyfunc(T)
                vD = rD.applyfunc(lambda e: sum(sp.diff(e, qq) * w for qq, w in zip([th1, th2], [thd1, thd2])))
                vD2 = sp.expand(sp.trigsimp(sp.expand((vD.T * vD)[0, 0])))
    ours = {
        **({"v_D^2": vD2} if vD2 is not None else {}),
        "K": K,
        "P": P,
        "L": L,
        "d/dt dL/dthd1": ddt(sp.diff(L, thd1)),
        "dL/dth1": sp.diff(L, th1),
        "tau1": T(eom.tau[0]),
        "d/dt dL/dthd2": ddt(sp.diff(L, thd2)),
        "dL/dth2": sp.diff(L, th2),
        "tau2": T(eom.tau[1]),
    }
    a.text("Step 7 is the answer: the equations of motion τᵢ = d/dt ∂L/∂θ̇ᵢ − ∂L/∂θᵢ.")
    a.text(
        "Independent check of every step: the arm written from its geometry alone (rod about its end, rod about its centre, "
        "the centre D of link 2), with every velocity and derivative taken by central finite differences; and the energy "
        "balance qd . tau = dH/dt (H = K + P) along the motion."
    )
    arms = [(_RodArm(*s[:5]), np.array(s[5]), np.array(s[6]), np.array(s[7]), s) for s in _Q3_SAMPLES]
    refs = {
        "v_D^2": lambda A, q, qd, qdd: A.vD2(q, qd),
        "K": lambda A, q, qd, qdd: A.K(q, qd),
        "P": lambda A, q, qd, qdd: A.P(q),
        "L": lambda A, q, qd, qdd: A.L(q, qd),
        "d/dt dL/dthd1": lambda A, q, qd, qdd: A.ddt_dL_dqd(q, qd, qdd, 0),
        "dL/dth1": lambda A, q, qd, qdd: A.dL_dq(q, qd, 0),
        "tau1": lambda A, q, qd, qdd: A.tau(q, qd, qdd, 0),
        "d/dt dL/dthd2": lambda A, q, qd, qdd: A.ddt_dL_dqd(q, qd, qdd, 1),
        "dL/dth2": lambda A, q, qd, qdd: A.dL_dq(q, qd, 1),
        "tau2": lambda A, q, qd, qdd: A.tau(q, qd, qdd, 1),
    }
    syms = [m1, m2, l1, l2, g, th1, th2, thd1, thd2, thdd1, thdd2]
    rows = []
    checks = {}
    for name, ref in refs.items():
        if name not in ours:
            continue
        pr = printed("3", name)
        kd_expr = ours[name]
        f_pr, f_kd = sp.lambdify(syms, pr, "math"), sp.lambdify(syms, kd_expr, "math")
        ok_pr = ok_kd = True
        shown = None
        for A, q, qd, qdd, s in arms:
            args = [s[0], s[1], s[2], s[3], s[4], *q, *qd, *qdd]
            r, vp, vk = ref(A, q, qd, qdd), f_pr(*args), f_kd(*args)
            tol = 1e-6 * max(1.0, abs(r))
            ok_pr &= abs(vp - r) <= tol
            ok_kd &= abs(vk - r) <= tol
            shown = shown or (vp, vk, r)
        assert shown is not None  # arms is a fixed, non-empty list of test arms
        diff = sp.simplify(sp.expand_trig(sp.expand(kd_expr - pr)))
        check = (
            f"finite differences of the geometric model at m1=1.3, m2=2.1, l1=1.7, l2=2.3, theta=(0.4, -1.1), thetadot=(0.9, 1.6), "
            f"thetaddot=(0.7, -0.5): {fmt_number(shown[2])}; printed expression: {fmt_number(shown[0])}; kinedyn: {fmt_number(shown[1])}"
        )
        if name.startswith("tau"):
            A, q, qd, qdd, s = arms[0]
            k = int(name[-1]) - 1
            tp = np.array([refs["tau1"](A, q, qd, qdd), refs["tau2"](A, q, qd, qdd)])
            args = [s[0], s[1], s[2], s[3], s[4], *q, *qd, *qdd]
            alt = tp.copy()
            alt[k] = sp.lambdify(syms, pr, "math")(*args)
            check += (
                f"; energy balance qd . tau - dH/dt: {fmt_number(A.power_balance(q, qd, qdd, tp), 2)} with kinedyn's torques, "
                f"{fmt_number(A.power_balance(q, qd, qdd, alt), 4)} with the printed {name}"
            )
        checks[name] = check
        a.comparisons.append(
            Comparison(
                name,
                str(tutorial_display(pr)),
                str(tutorial_display(_pretty_collect(kd_expr))),
                ok_pr,
                check,
                ""
                if ok_pr
                else f"{tutorial_display(_pretty_collect(kd_expr))}   (kinedyn - printed = {tutorial_display(diff)})",
                exprs=(_pretty_collect(pr), _pretty_collect(kd_expr), diff),
            )
        )
        rows.append([name, "yes" if ok_pr else "NO", "yes" if ok_kd else "NO"])
    a.text(
        "kinedyn's value agrees with the finite-difference model for every quantity: "
        + ("yes" if all(r[2] == "yes" for r in rows) else "NO")
        + "."
    )
    a.text(
        "Remarks on the printed text: the first term of L is printed with an unindexed thetadot^2 (read as thetadot1^2); the chain-rule "
        "line 'd/dt = d/dtheta2 thetadot2 + d/dthetadot1 thetaddot1' leaves out the d/dthetadot2 thetaddot2 term (and d/dtheta1 thetadot1, "
        "which is zero here); tau1 is right although dL/dtheta1 above it has the wrong sign."
    )
    a.result = {name: str(ours[name]) for name in ours} | {
        "kinedyn_agrees_with_finite_differences": all(r[2] == "yes" for r in rows)
    }
    return a


def _plain_lhs(lhs: str) -> str:
    s = lhs.replace(r"\mathcal{L}", "L").replace(r"\tau", "tau").replace(r"\omega", "w")
    s = re.sub(r"\\frac\{d\}\{dt\}", "d/dt ", s)
    s = re.sub(r"\\frac\{\\partial ([^}]*)\}\{\\partial ([^}]*\}?)\}", r"d\1/d\2", s)
    s = re.sub(r"\\dot\{(q_\{?\d+\}?)\}", r"\1dot", s)
    s = s.replace("\\", "").replace("{", "").replace("}", "")
    s = re.sub(r"q_(\d)dot", r"thetadot\1", s)
    return re.sub(r"q_(\d)", r"theta\1", s)
