"""The seed tutorial (METR4202 Tutorial 4: Jacobians, J^T F, Lagrangian dynamics, the elbow arm),
worked with kinedyn, every answer with its steps.

Each question gives an :class:`Answer`: a list of items (text, equations, tables) and comparisons of
kinedyn's result with the answer *printed in the tutorial*. Where they differ, the comparison carries
the independent check that decides it (finite differences of the forward kinematics or of the
Lagrangian written from the geometry, virtual work, the energy balance), evaluated numerically.

``PRINTED`` below is the one place that holds the tutorial's printed answers (transcribed as printed,
so misprints included); ``QUESTION_DATA`` holds the questions' inputs. Conventions: docs/seed-notes.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp

__all__ = [
    "QUESTIONS",
    "PRINTED",
    "QUESTION_DATA",
    "Answer",
    "Comparison",
    "answer",
    "work",
    "to_json",
    "render_markdown",
    "render_text",
]

QUESTIONS = ["1a", "1b", "2a", "2b", "3", "challenge"]

# ------------------------------------------------------------------ the tutorial's inputs
QUESTION_DATA: dict[str, dict[str, Any]] = {
    "2a": {"l1": 2.0, "l2": 3.0, "theta_deg": (167.028, -156.44), "theta_decimals": (3, 2), "qd": (1.0, 3.0)},
    "2b": {"F": (30.0, -20.0)},
    "challenge": {"L1": 3.0, "L2": 2.0, "L3": 1.0, "tool": (1.0, 0.2, 0.5)},
}

# ------------------------------------------------------------------ printed in the tutorial
# The answers as printed in the tutorial's solutions (misprints kept). Symbolic answers are SymPy
# strings in th1, th2 (joint angles), thd1, thd2 (rates), thdd1, thdd2, l1, l2, m1, m2, g; numbers are
# strings so that the printed number of digits is kept. Never used as a source of truth: each is
# compared with kinedyn and with an independent check.
PRINTED: dict[str, dict[str, Any]] = {
    "1a": {
        "J": "Matrix([[-l1*sin(th1) - l2*sin(th1 + th2), -l2*sin(th1 + th2)],"
        " [l1*cos(th1) + l2*cos(th1 + th2), l2*cos(th1 + th2)]])"
    },
    "1b": {
        "J_inv": "Matrix([[l2*cos(th1 + th2), l2*sin(th1 + th2)],"
        " [-l1*cos(th1) - l2*cos(th1 + th2), -l1*sin(th1) - l2*sin(th1 + th2)]])/(l1*l2*sin(th2))"
    },
    "2a": {"J": [["-1.0000", "-0.5512"], ["1.0000", "2.9489"]], "v": ["-2.654", "9.847"]},
    "2b": {"tau": ["-50.0", "-75.1"]},
    "3": {
        "v_D^2": "thd1**2*(l1**2 + l2**2/4 + l1*l2*cos(th2)) + thd2**2*(l2**2/4) + thd1*thd2*(l2**2/2 + l1*l2*cos(th2))",
        "K": "thd1**2*(m1*l1**2/6 + m2*l2**2/6 + m2*l1**2/2 + m2*l1*l2*cos(th2)/2) + thd2**2*(m2*l2**2/6)"
        " + thd1*thd2*(m2*l2**2/3 + m2*l1*l2*cos(th2)/2)",
        "P": "m1*g*l1/2*sin(th1) + m2*g*(l1*sin(th1) + l2/2*sin(th1 + th2))",
        # printed with "theta-dot squared" (no index) in the first term; read as thd1**2
        "L": "thd1**2*(m1*l1**2/6 + m2*l2**2/6 + m2*l1**2/2 + m2*l1*l2*cos(th2)/2) + thd2**2*(m2*l2**2/6)"
        " + thd1*thd2*(m2*l2**2/3 + m2*l1*l2*cos(th2)/2) - m1*g*l1/2*sin(th1) - m2*g*(l1*sin(th1) + l2/2*sin(th1 + th2))",
        "d/dt dL/dthd1": "(m1*l1**2/3 + m2*l1**2 + m2*l2**2/3 + m2*l1*l2*cos(th2))*thdd1 + (m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd2"
        " - m2*l1*l2*sin(th2)*thd1*thd2 - m2*l1*l2*sin(th2)*thd2**2/2",
        "dL/dth1": "(m1/2 + m2)*g*l1*cos(th1) + m2*g*l2*cos(th1 + th2)/2",
        "tau1": "(m1*l1**2/3 + m2*l1**2 + m2*l2**2/3 + m2*l1*l2*cos(th2))*thdd1 + (m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd2"
        " - m2*l1*l2*sin(th2)*thd1*thd2 - m2*l1*l2*sin(th2)*thd2**2/2 + (m1/2 + m2)*g*l1*cos(th1) + m2*g*l2*cos(th1 + th2)/2",
        "d/dt dL/dthd2": "(m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd1 + m2*l2**2/3*thdd2 - m2*l1*l2*sin(th2)*thd1**2/2"
        " - m2*l1*l2*sin(th2)*thd1*thd2",
        "dL/dth2": "m2*l1*l2*sin(th2)*thd1*thd2 + m2*g*l2*cos(th1 + th2)/2",
        "tau2": "(m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd1 + m2*l2**2/3*thdd2 - m2*l1*l2*sin(th2)*thd1**2/2 + m2*g*l2*cos(th1 + th2)/2",
    },
    # the challenge question comes with no printed solution
}

# the tutorial's symbols
th1, th2, thd1, thd2, thdd1, thdd2 = sp.symbols("th1 th2 thd1 thd2 thdd1 thdd2", real=True)
l1, l2, m1, m2, g = sp.symbols("l1 l2 m1 m2 g", positive=True)
_PRINTED_NS = {
    "th1": th1,
    "th2": th2,
    "thd1": thd1,
    "thd2": thd2,
    "thdd1": thdd1,
    "thdd2": thdd2,
    "l1": l1,
    "l2": l2,
    "m1": m1,
    "m2": m2,
    "g": g,
    "Matrix": sp.Matrix,
    "sin": sp.sin,
    "cos": sp.cos,
}


def printed(question: str, key: str):
    """A symbolic printed answer as a SymPy expression in the tutorial's symbols."""
    return sp.sympify(PRINTED[question][key], locals=_PRINTED_NS)


# ------------------------------------------------------------------ results
@dataclass
class Comparison:
    """kinedyn's value of one quantity beside the tutorial's printed one."""

    quantity: str
    printed: str
    kinedyn: str
    agrees: bool
    #: the independent check that decides (always run; essential where they disagree)
    check: str = ""
    #: the correct value where the printed one is wrong
    correction: str = ""
    #: (printed, kinedyn) as SymPy expressions for symbolic answers (rendering only)
    exprs: tuple | None = None

    def to_dict(self) -> dict:
        return {
            "quantity": self.quantity,
            "printed": self.printed,
            "kinedyn": self.kinedyn,
            "agrees": self.agrees,
            "check": self.check,
            "correction": self.correction,
        }


@dataclass
class Answer:
    key: str
    title: str
    question: str
    #: ("text", str) | ("eq", name, value) | ("table", title, headers, rows)
    items: list[tuple] = field(default_factory=list)
    comparisons: list[Comparison] = field(default_factory=list)
    #: machine-readable results (numbers as floats/lists, expressions as strings)
    result: dict[str, Any] = field(default_factory=dict)

    def text(self, s: str):
        self.items.append(("text", s))

    def eq(self, name: str, value):
        self.items.append(("eq", name, value))

    def table(self, title: str, headers: Sequence[str], rows: Sequence[Sequence[Any]]):
        self.items.append(("table", title, list(headers), [list(r) for r in rows]))

    @property
    def misprints(self) -> list[Comparison]:
        return [c for c in self.comparisons if not c.agrees]


# ------------------------------------------------------------------ helpers
def _fmt(x: float, digits: int = 6) -> str:
    x = float(x)
    if abs(x) < 1e-12:
        x = 0.0
    return f"{x:.{digits}g}"


def _vec(v, digits: int = 6) -> str:
    return "(" + ", ".join(_fmt(x, digits) for x in np.ravel(v)) + ")"


def _mat_rows(M, digits: int = 6) -> list[list[str]]:
    return [[_fmt(x, digits) for x in row] for row in np.atleast_2d(M)]


def _decimals(s: str) -> int:
    return len(s.split(".")[1]) if "." in s else 0


def _half_unit(s: str) -> float:
    return 0.5 * 10.0 ** (-_decimals(s))


def symbolic_frame_pose(robot, q: Sequence[sp.Symbol], frame: str | None = None) -> sp.Matrix:
    """The pose of a frame as a SymPy matrix in the joint symbols ``q``: kinedyn.symbolic.pose with the
    robot's joint symbols renamed to ``q``."""
    from .. import symbolic as ks

    return ks.pose(robot, frame).xreplace(dict(zip(ks.joint_symbols(robot), q)))


def symbolic_jacobian(robot, q: Sequence[sp.Symbol], frame: str | None = None) -> sp.Matrix:
    """kinedyn.symbolic.jacobian (rows [v; w], base axes) in the joint symbols ``q``."""
    from .. import symbolic as ks

    return ks.jacobian(robot, frame).xreplace(dict(zip(ks.joint_symbols(robot), q)))


def _abbreviate(expr, q: Sequence[sp.Symbol], prefix=("C", "S")):
    """cos(th1 + th2) -> C12, sin(th2) -> S2: the tutorial's shorthand, for display only."""
    reps = {}
    for f in expr.atoms(sp.cos, sp.sin):
        arg = sp.expand(f.args[0])
        idx = []
        ok = True
        for term in sp.Add.make_args(arg):
            if term in q:
                idx.append(str(list(q).index(term) + 1))
            else:
                ok = False
        if ok and idx:
            name = (prefix[0] if isinstance(f, sp.cos) else prefix[1]) + "".join(sorted(idx))
            reps[f] = sp.Symbol(name)
    return expr.xreplace(reps)


def _display(expr, tutorial_symbols: bool = True):
    """A SymPy value in the tutorial's notation (theta, dots, C/S shorthand) for rendering."""
    if not isinstance(expr, (sp.Basic, sp.MatrixBase)):
        return expr
    names = {
        th1: "theta1",
        th2: "theta2",
        thd1: "thetadot1",
        thd2: "thetadot2",
        thdd1: "thetaddot1",
        thdd2: "thetaddot2",
    }
    reps = {s: sp.Symbol(n, real=True) for s, n in names.items()}
    e = _abbreviate(expr, [th1, th2, sp.Symbol("th3", real=True)]) if tutorial_symbols else expr
    return e.xreplace(reps) if isinstance(e, sp.Basic) else e.applyfunc(lambda x: x.xreplace(reps))


def _same(a, b, symbols: Sequence[sp.Symbol], trials: int = 4, seed: int = 7) -> bool:
    """Numeric equality of two expressions at random values of ``symbols`` (relative 1e-9)."""
    rng = np.random.default_rng(seed)
    fa = sp.lambdify(symbols, a, "numpy")
    fb = sp.lambdify(symbols, b, "numpy")
    for _ in range(trials):
        x = rng.uniform(0.3, 1.7, len(symbols)) * rng.choice([-1, 1], len(symbols))
        va, vb = np.asarray(fa(*x), dtype=float), np.asarray(fb(*x), dtype=float)
        if not np.allclose(va, vb, rtol=1e-9, atol=1e-9 * max(1.0, float(np.max(np.abs(va))))):
            return False
    return True


# ------------------------------------------------------------------ Q1: the Jacobian of the 2R arm
def _arm_2r_symbolic():
    from .. import robots

    return robots.planar_2r(symbolic=True)


def _q1_jacobian():
    """(robot, p, J) with p the tool position (x, y) and J = dp/dtheta, in the tutorial's symbols."""
    robot = _arm_2r_symbolic()
    rl1, rl2 = sp.Symbol("l1", positive=True), sp.Symbol("l2", positive=True)
    T = symbolic_frame_pose(robot, [th1, th2])
    p = T[:2, 3].xreplace({rl1: l1, rl2: l2})
    # rows 0-1 of kinedyn.symbolic.jacobian, = dp/dtheta (the derivative is the check)
    J = symbolic_jacobian(robot, [th1, th2])[:2, :].xreplace({rl1: l1, rl2: l2})
    if not _same(J - p.jacobian([th1, th2]), sp.zeros(2, 2), [th1, th2, l1, l2]):
        raise RuntimeError("internal error: the symbolic Jacobian is not dp/dtheta")
    return robot, p, J


def _q1a() -> Answer:
    a = Answer(
        "1a",
        "Jacobian of the two-link planar arm",
        "Calculate the Jacobian relating joint velocities to tool-point velocities.",
    )
    robot, p, J = _q1_jacobian()
    a.text(
        "kinedyn builds the arm from its DH table (kd.robots.planar_2r(symbolic=True)) and multiplies out the forward kinematics:"
    )
    a.eq("p(theta) = (x, y)", sp.Matrix(p))
    a.text(
        "The Jacobian is the derivative of the tool position with respect to the joint angles, J = dp/dtheta (rows x, y; these are rows 0-1 of kinedyn's 6 x n geometric Jacobian):"
    )
    a.eq("J", J)
    # independent check: the numeric engine's geometric Jacobian (a different code path) at random states
    from .. import robots

    rng = np.random.default_rng(11)
    worst = 0.0
    fJ = sp.lambdify([th1, th2, l1, l2], J, "numpy")
    for _ in range(5):
        q = rng.uniform(-math.pi, math.pi, 2)
        L = rng.uniform(0.5, 3.0, 2)
        num = robots.planar_2r(l1=L[0], l2=L[1]).jacobian(q)[:2]
        worst = max(worst, float(np.max(np.abs(np.asarray(fJ(*q, *L), dtype=float) - num))))
    check = f"the numeric engine's geometric Jacobian (robot.jacobian(q)[:2]) equals it at 5 random (q, l1, l2): max difference {worst:.1e}"
    a.text("Check: " + check + ".")
    Jp = printed("1a", "J")
    agrees = _same(J - Jp, sp.zeros(2, 2), [th1, th2, l1, l2])
    a.comparisons.append(Comparison("J", str(Jp), str(J), agrees, check, exprs=(Jp, J)))
    a.result = {
        "p": [str(e) for e in p],
        "J": [[str(e) for e in row] for row in J.tolist()],
        "numeric_engine_max_difference": worst,
    }
    return a


def _q1b() -> Answer:
    a = Answer(
        "1b", "Inverse Jacobian", "Calculate the inverse Jacobian relating tool-point velocities to joint velocities."
    )
    from .. import symbolic as ks

    _, _, J = _q1_jacobian()
    inverse = ks.jacobian_inverse(J, coordinates=[th1, th2])
    det = inverse.determinant
    a.text("The determinant of the 2 x 2 Jacobian:")
    a.eq("det J", det)
    a.text(
        "so J is invertible except where sin(theta2) = 0 (arm stretched out or folded back). "
        "The inverse is the adjugate divided by the determinant, θ̇ = J⁻¹ (ẋ, ẏ):"
    )
    adj = inverse.adjugate
    Jinv = adj / det
    a.eq("J^-1", sp.MatMul(1 / det, adj, evaluate=False))
    prod = (J * Jinv).applyfunc(lambda e: sp.simplify(sp.expand_trig(e)))
    check_ok = _same(J * Jinv, sp.eye(2), [th1, th2, l1, l2])
    check = (
        f"J J^-1 = I at random (theta, l1, l2): {'yes' if check_ok else 'NO'}; symbolically J J^-1 = {sp.sstr(prod)}"
    )
    a.text("Check: " + check + ".")
    # kinedyn's singularity report at a stretched arm
    from .. import robots
    from ..kinematics import singularity_report

    rep = singularity_report(robots.planar_2r(), [0.4, 0.0], task="planar")
    a.text(
        f"At theta2 = 0 kinedyn's singularity report (kinedyn jacobian --q 0.4 0 --task planar) says: {rep.summary()}."
    )
    Jp = printed("1b", "J_inv")
    agrees = _same(Jinv - Jp, sp.zeros(2, 2), [th1, th2, l1, l2])
    a.comparisons.append(Comparison("J^-1", str(Jp), str(Jinv), agrees, check, exprs=(Jp, Jinv)))
    a.result = {
        "det": str(det),
        "J_inv": [[str(e) for e in row] for row in Jinv.tolist()],
        "singular_at_theta2_zero": rep.singular,
    }
    return a


# ------------------------------------------------------------------ Q2: velocity and torque at a pose
def _q2_state():
    from .. import robots

    d = QUESTION_DATA["2a"]
    robot = robots.planar_2r(l1=d["l1"], l2=d["l2"])
    q = np.radians(d["theta_deg"])
    return robot, q, np.array(d["qd"])


def _q_box(q_deg: Sequence[float], decimals: Sequence[int]) -> list[np.ndarray]:
    """The corners of the rounding box of angles printed with the given decimals (degrees -> rad)."""
    corners = []
    for s1 in (-1, 1):
        for s2 in (-1, 1):
            corners.append(
                np.radians([q_deg[0] + s1 * 0.5 * 10.0 ** -decimals[0], q_deg[1] + s2 * 0.5 * 10.0 ** -decimals[1]])
            )
    return corners


def _agrees_within_rounding(printed_str: str, f: Callable[..., float], q_deg, decimals) -> bool:
    """True when the printed number lies within kinedyn's value over the rounding of the tutorial's
    input angles, widened by half a unit in the printed number's last digit."""
    values = [f(q) for q in _q_box(q_deg, decimals)]
    lo, hi = min(values), max(values)
    x = float(printed_str)
    return lo - _half_unit(printed_str) <= x <= hi + _half_unit(printed_str)


def _fd_tool_velocity(robot, q, qd, h=1e-6):
    """Independent: the tool's velocity by central differences of the forward kinematics along qd."""
    return (robot.pose(q + h * qd)[:2, 3] - robot.pose(q - h * qd)[:2, 3]) / (2 * h)


def _fd_virtual_work(robot, q, F, h=1e-6):
    """Independent: tau_i = d(F . p)/dq_i (virtual work), by central differences of the forward kinematics."""
    tau = np.zeros(robot.n)
    for i in range(robot.n):
        e = np.zeros(robot.n)
        e[i] = h
        tau[i] = F @ (robot.pose(q + e)[:2, 3] - robot.pose(q - e)[:2, 3]) / (2 * h)
    return tau


def _exact_pose_note(a: Answer, robot, q):
    """The tutorial's angles are the IK solution for a tool at (1, 1): show it, and solve it exactly with
    kinedyn's inverse kinematics where that exists."""
    p = robot.pose(q)[:3, 3]
    a.text(
        f"Where is the tool? kinedyn's FK at these angles gives (x, y) = {_vec(p[:2])} m: the angles are the inverse "
        "kinematics of a tool at (1, 1) m, rounded."
    )
    if not hasattr(robot, "inverse_kinematics"):
        return None
    try:
        res = robot.inverse_kinematics(np.array([1.0, 1.0, 0.0]))
        sols = np.atleast_2d(np.asarray(res.solutions, dtype=float))
    except (ValueError, TypeError, NotImplementedError, AttributeError):
        return None
    if sols.size == 0:
        return None
    wrapped = (sols - q + math.pi) % (2 * math.pi) - math.pi
    exact = q + wrapped[np.argmin(np.linalg.norm(wrapped, axis=1))]
    a.text(f"kinedyn's inverse kinematics for (1, 1): theta = {_vec(np.degrees(exact), 10)} deg on this branch.")
    return exact


def _q2a() -> Answer:
    d = QUESTION_DATA["2a"]
    a = Answer(
        "2a",
        "Tool velocity v = J qd",
        f"Tool-point linear velocity for joint rates (1, 3) rad/s, a1 = 2, a2 = 3, theta = ({d['theta_deg'][0]} deg, {d['theta_deg'][1]} deg).",
    )
    robot, q, qd = _q2_state()
    J = robot.jacobian(q)[:2]
    v = J @ qd
    a.text(
        "kinedyn: J = robot.jacobian(q)[:2] (rows x, y), v = J qd (kinedyn.kinematics.tool_velocity(robot, q, qd, task='planar'))."
    )
    a.table("J at the tutorial's angles", ["", "theta1", "theta2"], [["x", *_mat_rows(J)[0]], ["y", *_mat_rows(J)[1]]])
    a.eq("v = J qd [m/s]", _vec(v))
    v_fd = _fd_tool_velocity(robot, q, qd)
    check = f"central differences of the forward kinematics along qd give v = {_vec(v_fd)} m/s (difference {np.max(np.abs(v_fd - v)):.1e})"
    a.text("Check: " + check + ".")
    exact = _exact_pose_note(a, robot, q)
    if exact is not None:
        a.text(f"At the exact angles v = {_vec(robot.jacobian(exact)[:2] @ qd)} m/s.")
    dec = d["theta_decimals"]
    for (i, j), s in np.ndenumerate(np.array(PRINTED["2a"]["J"])):
        ok = _agrees_within_rounding(s, lambda qq, i=i, j=j: robot.jacobian(qq)[i, j], d["theta_deg"], dec)
        a.comparisons.append(
            Comparison(
                f"J[{i + 1},{j + 1}]",
                s,
                _fmt(J[i, j], 7),
                ok,
                "within the rounding of the printed angles" if ok else check,
            )
        )
    for i, s in enumerate(PRINTED["2a"]["v"]):
        ok = _agrees_within_rounding(s, lambda qq, i=i: (robot.jacobian(qq)[:2] @ qd)[i], d["theta_deg"], dec)
        a.comparisons.append(Comparison(f"v[{i + 1}] [m/s]", s, _fmt(v[i], 7), ok, check, "" if ok else _fmt(v[i], 4)))
    a.result = {"q_rad": q.tolist(), "J": J.tolist(), "v": v.tolist(), "v_finite_differences": v_fd.tolist()}
    if exact is not None:
        a.result["q_exact_rad"] = exact.tolist()
    return a


def _q2b() -> Answer:
    d = QUESTION_DATA["2a"]
    F = np.array(QUESTION_DATA["2b"]["F"])
    a = Answer("2b", "Joint torques tau = J^T F", "Joint torques for a force F = (30, -20) N at the tool, same pose.")
    robot, q, _ = _q2_state()
    J = robot.jacobian(q)[:2]
    tau = J.T @ F
    a.text("kinedyn: tau = J^T F (kinedyn.kinematics.joint_torques(robot, q, F, task='planar')).")
    a.table("J^T", ["", "Fx", "Fy"], [["theta1", *_mat_rows(J.T)[0]], ["theta2", *_mat_rows(J.T)[1]]])
    for i in range(2):
        a.eq(
            f"tau{i + 1} [N m]",
            f"{_fmt(J[0, i], 5)} * {_fmt(F[0])} + {_fmt(J[1, i], 5)} * {_fmt(F[1])} = {_fmt(tau[i])}",
        )
    tau_fd = _fd_virtual_work(robot, q, F)
    Jp = np.array(PRINTED["2a"]["J"], dtype=float)
    by_hand = Jp.T @ F
    check = (
        f"virtual work, tau_i = d(F . p)/dq_i by central differences of the forward kinematics, gives tau = {_vec(tau_fd)} N m; "
        f"and the tutorial's own printed J^T times F gives {_vec(by_hand, 5)} N m "
        f"({_fmt(Jp[0, 1], 4)} * 30 + {_fmt(Jp[1, 1], 5)} * (-20) = {_fmt(by_hand[1], 5)})"
    )
    a.text("Check: " + check + ".")
    exact = _exact_pose_note(a, robot, q)
    if exact is not None:
        a.text(f"At the exact angles tau = {_vec(robot.jacobian(exact)[:2].T @ F)} N m.")
    for i, s in enumerate(PRINTED["2b"]["tau"]):
        ok = _agrees_within_rounding(
            s, lambda qq, i=i: (robot.jacobian(qq)[:2].T @ F)[i], d["theta_deg"], d["theta_decimals"]
        )
        a.comparisons.append(
            Comparison(f"tau{i + 1} [N m]", s, _fmt(tau[i], 7), ok, check, "" if ok else f"{tau[i]:.1f}")
        )
    a.result = {"tau": tau.tolist(), "tau_virtual_work": tau_fd.tolist(), "tau_from_printed_J": by_hand.tolist()}
    if exact is not None:
        a.result["tau_exact_pose"] = (robot.jacobian(exact)[:2].T @ F).tolist()
    return a


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
    robot = _arm_2r_symbolic()
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


def _q3() -> Answer:
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
        a.text(f"Step {k}: {step.title}" + (f" - {step.text}" if step.text else ""))
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
            f"thetaddot=(0.7, -0.5): {_fmt(shown[2])}; printed expression: {_fmt(shown[0])}; kinedyn: {_fmt(shown[1])}"
        )
        if name.startswith("tau"):
            A, q, qd, qdd, s = arms[0]
            k = int(name[-1]) - 1
            tp = np.array([refs["tau1"](A, q, qd, qdd), refs["tau2"](A, q, qd, qdd)])
            args = [s[0], s[1], s[2], s[3], s[4], *q, *qd, *qdd]
            alt = tp.copy()
            alt[k] = sp.lambdify(syms, pr, "math")(*args)
            check += (
                f"; energy balance qd . tau - dH/dt: {_fmt(A.power_balance(q, qd, qdd, tp), 2)} with kinedyn's torques, "
                f"{_fmt(A.power_balance(q, qd, qdd, alt), 4)} with the printed {name}"
            )
        checks[name] = check
        a.comparisons.append(
            Comparison(
                name,
                str(_display(pr)),
                str(_display(_pretty_collect(kd_expr))),
                ok_pr,
                check,
                "" if ok_pr else f"{_display(_pretty_collect(kd_expr))}   (kinedyn - printed = {_display(diff)})",
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
    import re

    s = lhs.replace(r"\mathcal{L}", "L").replace(r"\tau", "tau").replace(r"\omega", "w")
    s = re.sub(r"\\frac\{d\}\{dt\}", "d/dt ", s)
    s = re.sub(r"\\frac\{\\partial ([^}]*)\}\{\\partial ([^}]*\}?)\}", r"d\1/d\2", s)
    s = re.sub(r"\\dot\{(q_\{?\d+\}?)\}", r"\1dot", s)
    s = s.replace("\\", "").replace("{", "").replace("}", "")
    s = re.sub(r"q_(\d)dot", r"thetadot\1", s)
    return re.sub(r"q_(\d)", r"theta\1", s)


# ------------------------------------------------------------------ challenge: the elbow manipulator
def elbow_ik(x: float, y: float, z: float, L1: float, L2: float, L3: float) -> np.ndarray:
    """All joint solutions (up to 4) of Spong's elbow arm for a tool point (x, y, z) (Spong §3.3):
    theta1 = atan2(y, x) [or + pi with r -> -r]; cos theta3 = D = (r^2 + s^2 - L2^2 - L3^2)/(2 L2 L3),
    theta3 = atan2(+-sqrt(1 - D^2), D); theta2 = atan2(s, r) - atan2(L3 sin theta3, L2 + L3 cos theta3),
    with r = sqrt(x^2 + y^2), s = z - L1."""
    r0 = math.hypot(x, y)
    s = z - L1
    D = (r0**2 + s**2 - L2**2 - L3**2) / (2 * L2 * L3)
    if abs(D) > 1 + 1e-12:
        return np.zeros((0, 3))
    D = max(-1.0, min(1.0, D))
    out = []
    for shoulder in (+1, -1):
        t1 = math.atan2(y, x) + (0.0 if shoulder > 0 else math.pi)
        r = shoulder * r0
        for elbow in (+1, -1):
            t3 = math.atan2(elbow * math.sqrt(1 - D * D), D)
            t2 = math.atan2(s, r) - math.atan2(L3 * math.sin(t3), L2 + L3 * math.cos(t3))
            out.append([t1, t2, t3])
    return np.array(out)


def elbow_branch_name(robot, q) -> str:
    """The IK branch of the elbow arm at ``q``, decided geometrically (not by the order in which
    ``elbow_ik`` lists its solutions): the shoulder is in "front" when the arm's vertical plane faces the
    tool (the upper arm's horizontal direction (cos theta1, sin theta1) points towards the tool's
    horizontal position), and the elbow is "up" when it lies above the shoulder-tool line, i.e. on the
    side of that line that the upward vertical points to, in the arm's plane."""
    shoulder, elbow, tool = (
        T[:3, 3]
        for T in robot.frame_poses(np.asarray(q, dtype=float), [robot.frame_names[1], robot.frame_names[2], robot.tool])
    )
    front = math.cos(q[0]) * tool[0] + math.sin(q[0]) * tool[1] > 0
    line = (tool - shoulder) / np.linalg.norm(tool - shoulder)
    up_normal = np.array([0.0, 0.0, 1.0]) - line[2] * line  # the vertical, less its part along the line
    up = float(np.dot(elbow - shoulder, up_normal)) > 0
    return f"{'front' if front else 'back'}, elbow {'up' if up else 'down'}"


def _challenge() -> Answer:
    from .. import robots

    d = QUESTION_DATA["challenge"]
    a = Answer(
        "challenge",
        "The elbow manipulator",
        "DH table, inverse kinematic equations, the joint values for the tool at (1.0, 0.2, 0.5) m, the Jacobian (L1 = 3 m, L2 = 2 m, L3 = 1 m).",
    )
    a.text(
        "The tutorial's figure is missing from the seed; kinedyn follows Spong's elbow (articulated) arm: z0 up along joint 1, "
        "shoulder at height L1, joints 2 and 3 horizontal, zero pose with both arms along x0 (docs/seed-notes.md §3). "
        "The tutorial prints no solution, so nothing is compared; every result is checked instead."
    )
    robot = robots.elbow_3r(L1=d["L1"], L2=d["L2"], L3=d["L3"])
    dh = robot.dh
    assert dh is not None  # elbow_3r is built from its DH table
    rows = []
    for i, r in enumerate(dh, start=1):
        rows.append([str(i), f"theta{i}*", _fmt(r.d), _fmt(r.a), f"{_fmt(math.degrees(r.alpha))} deg"])
    a.table(
        "DH table (standard: Rz(theta) Tz(d) Tx(a) Rx(alpha); * = joint variable)",
        ["link", "theta", "d [m]", "a [m]", "alpha"],
        rows,
    )
    # symbolic FK and Jacobian from the symbolic robot
    from ..robot import Robot

    # the same DH table with the lengths as symbols
    Ls = sp.symbols("L1 L2 L3", positive=True)
    sym = Robot.from_dh([(r.theta, Ls[0] if i == 0 else r.d, Ls[i] if i else r.a, r.alpha) for i, r in enumerate(dh)])
    t1, t2, t3 = sp.symbols("theta1 theta2 theta3", real=True)
    q = [t1, t2, t3]
    T = symbolic_frame_pose(sym, q)
    o3 = T[:3, 3]
    a.text("Forward kinematics (kinedyn: the DH products of this table multiplied out, with the lengths as symbols):")
    a.eq("o3 = (x, y, z)", o3)
    x, y, z = sp.symbols("x y z", real=True)
    L1s, L2s, L3s = sp.symbols("L1 L2 L3", positive=True)
    a.text(
        "Inverse kinematics (geometric, Spong §3.3): project onto the base plane and the vertical plane through the arm."
    )
    r_ = sp.sqrt(x**2 + y**2)
    s_ = z - L1s
    Dexpr = (r_**2 + s_**2 - L2s**2 - L3s**2) / (2 * L2s * L3s)
    a.eq("theta1", "atan2(y, x)   or   atan2(y, x) + pi")
    a.eq("D = cos(theta3)", Dexpr)
    a.eq("theta3", "atan2(±sqrt(1 - D²), D)")
    a.eq("theta2", "atan2(z - L1, ±sqrt(x² + y²)) - atan2(L3 sin(theta3), L2 + L3 cos(theta3))")
    a.text(
        "reachable when |L2 - L3| <= sqrt(r^2 + s^2) <= L2 + L3 (r = sqrt(x^2 + y^2), s = z - L1); the sign of r picks the shoulder "
        "(front / back), the sign of the square root the elbow (down / up)."
    )
    X, Y, Z = d["tool"]
    rn, sn = math.hypot(X, Y), Z - d["L1"]
    Dn = (rn**2 + sn**2 - d["L2"] ** 2 - d["L3"] ** 2) / (2 * d["L2"] * d["L3"])
    a.eq(
        "at (1.0, 0.2, 0.5) m: r, s, sqrt(r^2 + s^2), D",
        f"{_fmt(rn)}, {_fmt(sn)}, {_fmt(math.hypot(rn, sn))}, {_fmt(Dn)}",
    )
    sols = elbow_ik(X, Y, Z, d["L1"], d["L2"], d["L3"])
    target = np.array(d["tool"])
    names = [elbow_branch_name(robot, qv) for qv in sols]  # labelled by where the elbow is, not by list order
    tab_deg, tab_rad = [], []
    residuals = []
    for name, qv in zip(names, sols):
        err = float(np.linalg.norm(robot.pose(qv)[:3, 3] - target))
        residuals.append(err)
        tab_deg.append([name, *(_fmt(math.degrees(v), 9) for v in qv), f"{err:.1e}"])
        tab_rad.append([name, *(_fmt(v, 9) for v in qv)])
    a.table(
        "joint values for the tool at (1.0, 0.2, 0.5) m, in degrees",
        ["branch", "theta1", "theta2", "theta3", "FK error [m]"],
        tab_deg,
    )
    a.table("the same in radians", ["branch", "theta1", "theta2", "theta3"], tab_rad)
    a.text(
        "Check: kinedyn's forward kinematics (robot.pose) puts the tool back on the target for each solution (FK error column)."
    )
    kd_solutions = None
    if hasattr(robot, "inverse_kinematics"):
        try:
            res = robot.inverse_kinematics(target)
            kd_solutions = np.atleast_2d(np.asarray(res.solutions, dtype=float))
        except (ValueError, TypeError, NotImplementedError, AttributeError):
            kd_solutions = None
    if kd_solutions is not None and kd_solutions.size:
        wrap = lambda A: (A + math.pi) % (2 * math.pi) - math.pi
        matched = sum(any(np.allclose(wrap(s - k), 0, atol=1e-8) for k in kd_solutions) for s in sols)
        a.text(
            f"kinedyn's inverse kinematics (robot.inverse_kinematics) returns {len(kd_solutions)} solutions; {matched} of the 4 above are among them."
        )
    # Jacobian
    J = symbolic_jacobian(sym, q)
    Jv = J[:3, :]
    if not _same(Jv - o3.jacobian(q), sp.zeros(3, 3), [t1, t2, t3, L1s, L2s, L3s]):
        raise RuntimeError("internal error: the symbolic Jacobian is not d o3 / d theta")
    a.text("Jacobian [J_v; J_w] in base axes: J_v = d o3 / d theta, column i of J_w = the joint axis z_(i-1):")
    a.eq("J", J)
    detJ = -L2s * L3s * sp.sin(t3) * (L2s * sp.cos(t2) + L3s * sp.cos(t2 + t3))
    if not _same(Jv.det(), detJ, [t1, t2, t3, L1s, L2s, L3s]):  # a factored form, checked before it is shown
        detJ = sp.factor(sp.trigsimp(Jv.det()))
    a.eq("det J_v", detJ)
    a.text(
        "The arm is singular where det J_v = 0: sin(theta3) = 0 (elbow straight or folded) or L2 cos(theta2) + L3 cos(theta2 + theta3) = 0 "
        "(the tool on the z0 axis)."
    )
    subs_num = {
        sp.Symbol("L1", positive=True): d["L1"],
        sp.Symbol("L2", positive=True): d["L2"],
        sp.Symbol("L3", positive=True): d["L3"],
    }
    fJ = sp.lambdify(q, J.xreplace(subs_num), "numpy")
    jac = []
    worst = 0.0
    for qv in sols:
        Jn = robot.jacobian(qv)
        worst = max(worst, float(np.max(np.abs(np.asarray(fJ(*qv), dtype=float) - Jn))))
        jac.append(Jn)
    a.table(
        f"J at the first solution ({names[0]}), kinedyn robot.jacobian(q)",
        ["", "theta1", "theta2", "theta3"],
        [[rn_, *row] for rn_, row in zip(["vx", "vy", "vz", "wx", "wy", "wz"], _mat_rows(jac[0], 7))],
    )
    a.text(
        f"Check: the symbolic J evaluated at the four solutions equals the numeric engine's robot.jacobian(q): max difference {worst:.1e}."
    )
    a.result = {
        "dh": [
            {"theta": f"theta{i}", "d": float(r.d), "a": float(r.a), "alpha": float(r.alpha)}
            for i, r in enumerate(dh, 1)
        ],
        "solutions_rad": sols.tolist(),
        "branches": names,
        "fk_residuals": residuals,
        "jacobians": [Jn.tolist() for Jn in jac],
        "jacobian_symbolic": [[str(e) for e in row] for row in J.tolist()],
        "symbolic_vs_numeric_max_difference": worst,
    }
    if kd_solutions is not None:
        a.result["kinedyn_ik_solutions_rad"] = kd_solutions.tolist()
    return a


# ------------------------------------------------------------------ entry points
_SOLVERS = {"1a": _q1a, "1b": _q1b, "2a": _q2a, "2b": _q2b, "3": _q3, "challenge": _challenge}


def answer(question: str) -> Answer:
    """Work one question: "1a", "1b", "2a", "2b", "3" or "challenge"."""
    key = str(question).lower().lstrip("q")
    if key not in _SOLVERS:
        raise ValueError(f"unknown question '{question}' (questions: {', '.join(QUESTIONS)})")
    return _SOLVERS[key]()


def work(questions: Sequence[str] | None = None) -> list[Answer]:
    """Work the questions in order (all of them by default)."""
    return [answer(q) for q in (questions or QUESTIONS)]


# ------------------------------------------------------------------ rendering
def _jsonable_value(v):
    if isinstance(v, (sp.Basic, sp.MatrixBase)):
        return str(v)
    return v


def to_json(answers: Sequence[Answer]) -> dict:
    out = {}
    for a in answers:
        out[a.key] = {
            "title": a.title,
            "question": a.question,
            "steps": [
                {
                    "kind": it[0],
                    **(
                        {"text": it[1]}
                        if it[0] == "text"
                        else {"name": it[1], "value": _jsonable_value(it[2])}
                        if it[0] == "eq"
                        else {"title": it[1], "headers": it[2], "rows": it[3]}
                    ),
                }
                for it in a.items
            ],
            "result": a.result,
            "comparisons": [c.to_dict() for c in a.comparisons],
            "misprints": [c.quantity for c in a.misprints],
        }
    return out


def _latex(value) -> str:
    if isinstance(value, str):
        return r"\text{" + value.replace("_", r"\_") + "}"
    return sp.latex(_display(value))


def name_latex(name: str) -> str:
    """The LaTeX of an equation's name as the tutorial writes it in ASCII: ``J^-1`` -> ``J^{-1}``,
    ``dL/dthetadot1`` -> ``\\frac{\\partial L}{\\partial \\dot{\\theta}_{1}}``, ``J_w_1`` -> ``J_{\\omega_{1}}``,
    ``det J_v`` -> ``\\det J_{v}``; the same names the Markdown and the report's MathML show."""
    import re

    def coord(m: re.Match) -> str:
        dots = {"": "", "d": "dot", "dd": "ddot", "dot": "dot", "ddot": "ddot"}[m.group(2) or ""]
        base = r"\theta"
        return (f"\\{dots}{{{base}}}" if dots else base) + (f"_{{{m.group(3)}}}" if m.group(3) else "")

    t = name.strip()
    t = re.sub(r"^d/dt\s+", r"\\frac{d}{dt}", t)
    t = re.sub(r"\bdL/d(theta|th)(ddot|dot|dd|d)?(\d?)\b", lambda m: r"\frac{\partial L}{\partial " + coord(m) + "}", t)
    t = re.sub(r"(?<!\\)\b(theta|th)(ddot|dot|dd|d)?(\d?)\b", coord, t)
    t = re.sub(r"\b([a-z])_([A-Z])\^(\d)\b", r"\1_{\2}^{\3}", t)
    t = re.sub(r"\bJ_w_(\d)\b", r"J_{\\omega_{\1}}", t)
    t = re.sub(r"\bJ_v_c(\d)\b", r"J_{v_{c\1}}", t)
    t = re.sub(r"\b([rJ])_([a-z]?\d|[a-z])\b", r"\1_{\2}", t)
    t = re.sub(r"\btau_?(\d)\b", r"\\tau_{\1}", t)
    t = re.sub(r"\b([ov])(\d)\b", r"\1_{\2}", t)
    t = re.sub(r"\^-1\b", "^{-1}", t)
    t = re.sub(r"\bdet\s+", r"\\det ", t)
    t = re.sub(r"\b(cos|sin)\(", r"\\\1(", t)
    t = re.sub(r"\(", r"\\left(", t)
    t = re.sub(r"\)", r"\\right)", t)
    return t


def _rates_mathml() -> dict[sp.Symbol, str]:
    """MathML of the displayed tutorial symbols theta_k, thetadot_k, thetaddot_k: θ with dots above."""
    from ..symbolic.render import rate_symbols

    q = [sp.Symbol(f"theta{k}", real=True) for k in (1, 2)]
    return rate_symbols(
        q,
        [sp.Symbol(f"thetadot{k}", real=True) for k in (1, 2)],
        [sp.Symbol(f"thetaddot{k}", real=True) for k in (1, 2)],
    )


def render_markdown(answers: Sequence[Answer]) -> str:
    out = ["# The METR4202 Tutorial 4, worked with kinedyn", ""]
    for a in answers:
        out += [
            f"## Q{a.key}: {a.title}" if a.key != "challenge" else f"## Challenge: {a.title}",
            "",
            f"*{a.question}*",
            "",
        ]
        for it in a.items:
            if it[0] == "text":
                out += [it[1], ""]
            elif it[0] == "eq":
                name, value = it[1], it[2]
                if isinstance(value, str):
                    out += [f"- **{name}** = {value}", ""]
                else:
                    out += ["$$", f"{name_latex(name)} = {_latex(value)}", "$$", ""]
            else:
                _, title, headers, rows = it
                out += [f"**{title}**", "", "| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
                out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
                out.append("")
        if a.comparisons:
            out += [
                "**Against the tutorial's printed answer**",
                "",
                "| quantity | printed | kinedyn | verdict |",
                "|---|---|---|---|",
            ]
            for c in a.comparisons:
                out.append(
                    f"| {c.quantity} | `{c.printed}` | `{c.kinedyn}` | {'agrees' if c.agrees else '**differs: misprint**'} |"
                )
            out.append("")
            for c in a.misprints:
                out += [
                    f"- **{c.quantity}: the printed value is wrong.** Correct: `{c.correction or c.kinedyn}`. Deciding check: {c.check}.",
                    "",
                ]
    return "\n".join(out)


def render_html(answers: Sequence[Answer]) -> str:
    """The worked answers as one HTML ``<section>`` for the report: each question's steps, its
    equations in presentation MathML (the tutorial's notation), its tables, and the verdict on each
    printed answer with the deciding check and, for a misprint, the correct value."""
    from html import escape

    from ..symbolic.render import MATHML_NS, latex_to_mathml, value_mathml

    rates = _rates_mathml()

    def equation(name: str, value) -> str:
        if isinstance(value, str):
            return f"<p><b>{escape(name)}</b> = {escape(value)}</p>"
        lhs = latex_to_mathml(name_latex(name))
        return f'<div class="eq"><math xmlns="{MATHML_NS}" display="block"><mrow>{lhs}<mo>=</mo>{value_mathml(_display(value), rates)}</mrow></math></div>'

    def table(headers, rows) -> str:
        head = "".join(f"<th>{escape(str(h))}</th>" for h in headers)
        body = "".join("<tr>" + "".join(f"<td>{escape(str(c))}</td>" for c in r) + "</tr>" for r in rows)
        return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"

    def value(text: str, expr) -> str:
        if expr is not None:
            return f'<math xmlns="{MATHML_NS}">{value_mathml(_display(expr), rates)}</math>'
        return f"<code>{escape(text)}</code>"

    out = [
        "<section id='tutorial'><h2>The tutorial, worked</h2>",
        "<p class='note'>The seed tutorial's questions on this arm, worked by kinedyn step by step (<code>kinedyn tutorial</code> "
        "prints the same in a terminal). Every printed answer is compared with kinedyn's and decided by an independent check.</p>",
    ]
    for a in answers:
        title = f"Q{a.key}: {a.title}" if a.key != "challenge" else f"Challenge: {a.title}"
        out += [f"<h3>{escape(title)}</h3>", f"<p><i>{escape(a.question)}</i></p>"]
        for item in a.items:
            if item[0] == "text":
                out.append(f"<p>{escape(item[1])}</p>")
            elif item[0] == "eq":
                out.append(equation(item[1], item[2]))
            else:
                _, caption, headers, rows = item
                out += [f"<p><b>{escape(caption)}</b></p>", table(headers, rows)]
        if a.comparisons:
            rows = []
            for c in a.comparisons:
                printed, mine = c.exprs[:2] if c.exprs else (None, None)
                verdict = "<span class='ok'>agrees</span>" if c.agrees else "<span class='bad'>differs: misprint</span>"
                quantity = f'<math xmlns="{MATHML_NS}">{latex_to_mathml(name_latex(c.quantity))}</math>'
                rows.append(
                    f"<tr><td>{quantity}</td><td>{value(c.printed, printed)}</td><td>{value(c.kinedyn, mine)}</td><td>{verdict}</td></tr>"
                )
            out.append(
                "<table class='comparisons'><thead><tr><th>quantity</th><th>printed</th><th>kinedyn</th><th>verdict</th></tr></thead>"
                f"<tbody>{''.join(rows)}</tbody></table>"
            )
            for c in a.misprints:
                out.append(
                    f"<p><b class='bad'>{escape(c.quantity)}: the printed value is wrong.</b> Correct: "
                    f"{value(c.correction or c.kinedyn, c.exprs[1] if c.exprs else None)}. Deciding check: {escape(c.check)}.</p>"
                )
    out.append("</section>")
    return "\n".join(out)


def render_text(answers: Sequence[Answer], console=None) -> None:
    """Readable terminal output (rich: aligned tables, colour on a TTY)."""
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table
    from rich.text import Text

    c = console or Console(highlight=False, soft_wrap=False)
    for a in answers:
        head = f"Q{a.key}" if a.key != "challenge" else "Challenge"
        c.rule(f"[bold]{head}: {escape(a.title)}[/bold]", align="left")
        c.print(Text(a.question, style="italic"))
        for it in a.items:
            if it[0] == "text":
                c.print(Text(it[1]))
            elif it[0] == "eq":
                name, value = it[1], it[2]
                if isinstance(value, str):
                    c.print(Text.assemble((f"  {name} = ", "bold cyan"), value))
                else:
                    _pretty_eq(c, name, value)
            else:
                _, title, headers, rows = it
                t = Table(title=escape(title), title_justify="left")
                for h in headers:
                    t.add_column(escape(h), justify="right")
                for r in rows:
                    t.add_row(*(escape(str(x)) for x in r))
                c.print(t)
        if a.comparisons:
            t = Table(title="against the tutorial's printed answer", title_justify="left")
            for h in ("quantity", "printed", "kinedyn", "verdict"):
                t.add_column(h)
            for cmp in a.comparisons:
                sym = cmp.exprs is not None
                t.add_row(
                    escape(cmp.quantity),
                    "(expression)" if sym else escape(cmp.printed),
                    "(expression)" if sym else escape(cmp.kinedyn),
                    "[green]agrees[/green]" if cmp.agrees else "[bold red]differs: misprint[/bold red]",
                )
            c.print(t)
            for cmp in a.misprints:
                c.print(Text.assemble(("MISPRINT ", "bold red"), (f"{cmp.quantity}", "bold")))
                if cmp.exprs is not None:
                    _pretty_eq(c, "printed", cmp.exprs[0])
                    _pretty_eq(c, "correct", cmp.exprs[1])
                    if len(cmp.exprs) > 2:
                        _pretty_eq(c, "correct - printed", cmp.exprs[2])
                else:
                    c.print(Text(f"  printed {cmp.printed}; correct {cmp.correction or cmp.kinedyn}"))
                c.print(Text.assemble(("  deciding check: ", "bold"), cmp.check))
        c.print()


def _pretty_eq(c, name: str, value) -> None:
    """``name = value`` with the value pretty-printed (multi-line), the name on the middle line."""
    from rich.text import Text

    lines = sp.pretty(_display(value), use_unicode=True, wrap_line=False).split("\n")
    label = f"  {name} = "
    mid = len(lines) // 2
    for k, line in enumerate(lines):
        c.print(
            Text.assemble((label if k == mid else " " * len(label), "bold cyan"), line), overflow="ignore", crop=False
        )


def _short(s: str, width: int = 70) -> str:
    return s if len(s) <= width else s[: width - 3] + "..."
