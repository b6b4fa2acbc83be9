"""Questions 1 and 2 of the seed tutorial (Jacobians of the 2R arm, tool velocity, J^T F), and
:func:`answer` / :func:`work`, which work any question."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
import sympy as sp

from .. import robots
from .. import symbolic as ks
from ..kinematics import singularity_report
from ..symbolic.render.text import inline
from .answers import (
    Answer,
    Comparison,
    arm_2r_symbolic,
    fmt_number,
    fmt_vector,
    half_unit,
    matrix_rows,
    same_function,
    symbolic_frame_pose,
    symbolic_jacobian,
)
from .elbow import challenge
from .lagrange import question_3
from .printed import PRINTED, QUESTION_DATA, QUESTIONS, l1, l2, printed, th1, th2


# ------------------------------------------------------------------ Q1: the Jacobian of the 2R arm
def _q1_jacobian():
    """(robot, p, J) with p the tool position (x, y) and J = dp/dtheta, in the tutorial's symbols."""
    robot = arm_2r_symbolic()
    rl1, rl2 = sp.Symbol("l1", positive=True), sp.Symbol("l2", positive=True)
    T = symbolic_frame_pose(robot, [th1, th2])
    p = T[:2, 3].xreplace({rl1: l1, rl2: l2})
    # rows 0-1 of kinedyn.symbolic.jacobian, = dp/dtheta (the derivative is the check)
    J = symbolic_jacobian(robot, [th1, th2])[:2, :].xreplace({rl1: l1, rl2: l2})
    if not same_function(J - p.jacobian([th1, th2]), sp.zeros(2, 2), [th1, th2, l1, l2]):
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
    agrees = same_function(J - Jp, sp.zeros(2, 2), [th1, th2, l1, l2])
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
    check_ok = same_function(J * Jinv, sp.eye(2), [th1, th2, l1, l2])
    check = f"J J^-1 = I at random (theta, l1, l2): {'yes' if check_ok else 'NO'}; symbolically J J^-1 = {inline(prod)}"
    a.text("Check: " + check + ".")
    # kinedyn's singularity report at a stretched arm
    rep = singularity_report(robots.planar_2r(), [0.4, 0.0], task="planar")
    a.text(
        f"At theta2 = 0 kinedyn's singularity report (kinedyn jacobian --q 0.4 0 --task planar) says: {rep.summary()}."
    )
    Jp = printed("1b", "J_inv")
    agrees = same_function(Jinv - Jp, sp.zeros(2, 2), [th1, th2, l1, l2])
    a.comparisons.append(Comparison("J^-1", str(Jp), str(Jinv), agrees, check, exprs=(Jp, Jinv)))
    a.result = {
        "det": str(det),
        "J_inv": [[str(e) for e in row] for row in Jinv.tolist()],
        "singular_at_theta2_zero": rep.singular,
    }
    return a


# ------------------------------------------------------------------ Q2: velocity and torque at a pose
def _q2_state():
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
    return lo - half_unit(printed_str) <= x <= hi + half_unit(printed_str)


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
        f"Where is the tool? kinedyn's FK at these angles gives (x, y) = {fmt_vector(p[:2])} m: the angles are the inverse "
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
    a.text(f"kinedyn's inverse kinematics for (1, 1): theta = {fmt_vector(np.degrees(exact), 10)} deg on this branch.")
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
    a.table(
        "J at the tutorial's angles", ["", "theta1", "theta2"], [["x", *matrix_rows(J)[0]], ["y", *matrix_rows(J)[1]]]
    )
    a.eq("v = J qd [m/s]", fmt_vector(v))
    v_fd = _fd_tool_velocity(robot, q, qd)
    check = f"central differences of the forward kinematics along qd give v = {fmt_vector(v_fd)} m/s (difference {np.max(np.abs(v_fd - v)):.1e})"
    a.text("Check: " + check + ".")
    exact = _exact_pose_note(a, robot, q)
    if exact is not None:
        a.text(f"At the exact angles v = {fmt_vector(robot.jacobian(exact)[:2] @ qd)} m/s.")
    dec = d["theta_decimals"]
    for (i, j), s in np.ndenumerate(np.array(PRINTED["2a"]["J"])):
        ok = _agrees_within_rounding(s, lambda qq, i=i, j=j: robot.jacobian(qq)[i, j], d["theta_deg"], dec)
        a.comparisons.append(
            Comparison(
                f"J[{i + 1},{j + 1}]",
                s,
                fmt_number(J[i, j], 7),
                ok,
                "within the rounding of the printed angles" if ok else check,
            )
        )
    for i, s in enumerate(PRINTED["2a"]["v"]):
        ok = _agrees_within_rounding(s, lambda qq, i=i: (robot.jacobian(qq)[:2] @ qd)[i], d["theta_deg"], dec)
        a.comparisons.append(
            Comparison(f"v[{i + 1}] [m/s]", s, fmt_number(v[i], 7), ok, check, "" if ok else fmt_number(v[i], 4))
        )
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
    a.table("J^T", ["", "Fx", "Fy"], [["theta1", *matrix_rows(J.T)[0]], ["theta2", *matrix_rows(J.T)[1]]])
    for i in range(2):
        a.eq(
            f"tau{i + 1} [N m]",
            f"{fmt_number(J[0, i], 5)} * {fmt_number(F[0])} + {fmt_number(J[1, i], 5)} * {fmt_number(F[1])} = {fmt_number(tau[i])}",
        )
    tau_fd = _fd_virtual_work(robot, q, F)
    Jp = np.array(PRINTED["2a"]["J"], dtype=float)
    by_hand = Jp.T @ F
    check = (
        f"virtual work, tau_i = d(F . p)/dq_i by central differences of the forward kinematics, gives tau = {fmt_vector(tau_fd)} N m; "
        f"and the tutorial's own printed J^T times F gives {fmt_vector(by_hand, 5)} N m "
        f"({fmt_number(Jp[0, 1], 4)} * 30 + {fmt_number(Jp[1, 1], 5)} * (-20) = {fmt_number(by_hand[1], 5)})"
    )
    a.text("Check: " + check + ".")
    exact = _exact_pose_note(a, robot, q)
    if exact is not None:
        a.text(f"At the exact angles tau = {fmt_vector(robot.jacobian(exact)[:2].T @ F)} N m.")
    for i, s in enumerate(PRINTED["2b"]["tau"]):
        ok = _agrees_within_rounding(
            s, lambda qq, i=i: (robot.jacobian(qq)[:2].T @ F)[i], d["theta_deg"], d["theta_decimals"]
        )
        a.comparisons.append(
            Comparison(f"tau{i + 1} [N m]", s, fmt_number(tau[i], 7), ok, check, "" if ok else f"{tau[i]:.1f}")
        )
    a.result = {"tau": tau.tolist(), "tau_virtual_work": tau_fd.tolist(), "tau_from_printed_J": by_hand.tolist()}
    if exact is not None:
        a.result["tau_exact_pose"] = (robot.jacobian(exact)[:2].T @ F).tolist()
    return a


# ------------------------------------------------------------------ entry points
_SOLVERS = {"1a": _q1a, "1b": _q1b, "2a": _q2a, "2b": _q2b, "3": question_3, "challenge": challenge}


def answer(question: str) -> Answer:
    """Work one question: "1a", "1b", "2a", "2b", "3" or "challenge"."""
    key = str(question).lower().lstrip("q")
    if key not in _SOLVERS:
        raise ValueError(f"unknown question '{question}' (questions: {', '.join(QUESTIONS)})")
    return _SOLVERS[key]()


def work(questions: Sequence[str] | None = None) -> list[Answer]:
    """Work the questions in order (all of them by default)."""
    return [answer(q) for q in (questions or QUESTIONS)]
