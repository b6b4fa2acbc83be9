"""The challenge question of the seed tutorial: the elbow arm's forward kinematics, its closed-form
inverse kinematics (:func:`elbow_ik`) and its Jacobian."""

from __future__ import annotations

import math
import warnings

import numpy as np
import sympy as sp

from .. import robots
from ..description.dh import MasslessRobotWarning
from ..robot import Robot
from .answers import Answer, fmt_number, matrix_rows, same_function, symbolic_frame_pose, symbolic_jacobian
from .printed import QUESTION_DATA


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


def challenge() -> Answer:
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
        rows.append(
            [str(i), f"theta{i}*", fmt_number(r.d), fmt_number(r.a), f"{fmt_number(math.degrees(r.alpha))} deg"]
        )
    a.table(
        "DH table (standard: Rz(theta) Tz(d) Tx(a) Rx(alpha); * = joint variable)",
        ["link", "theta", "d [m]", "a [m]", "alpha"],
        rows,
    )
    # symbolic FK and Jacobian from the symbolic robot
    # the same DH table with the lengths as symbols
    Ls = sp.symbols("L1 L2 L3", positive=True)
    with warnings.catch_warnings():  # kinematics only: the symbolic table needs no masses
        warnings.simplefilter("ignore", MasslessRobotWarning)
        sym = Robot.from_dh(
            [(r.theta, Ls[0] if i == 0 else r.d, Ls[i] if i else r.a, r.alpha) for i, r in enumerate(dh)]
        )
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
        f"{fmt_number(rn)}, {fmt_number(sn)}, {fmt_number(math.hypot(rn, sn))}, {fmt_number(Dn)}",
    )
    sols = elbow_ik(X, Y, Z, d["L1"], d["L2"], d["L3"])
    target = np.array(d["tool"])
    names = [elbow_branch_name(robot, qv) for qv in sols]  # labelled by where the elbow is, not by list order
    tab_deg, tab_rad = [], []
    residuals = []
    for name, qv in zip(names, sols):
        err = float(np.linalg.norm(robot.pose(qv)[:3, 3] - target))
        residuals.append(err)
        tab_deg.append([name, *(fmt_number(math.degrees(v), 9) for v in qv), f"{err:.1e}"])
        tab_rad.append([name, *(fmt_number(v, 9) for v in qv)])
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
    if not same_function(Jv - o3.jacobian(q), sp.zeros(3, 3), [t1, t2, t3, L1s, L2s, L3s]):
        raise RuntimeError("internal error: the symbolic Jacobian is not d o3 / d theta")
    a.text("Jacobian [J_v; J_w] in base axes: J_v = d o3 / d theta, column i of J_w = the joint axis z_(i-1):")
    a.eq("J", J)
    detJ = -L2s * L3s * sp.sin(t3) * (L2s * sp.cos(t2) + L3s * sp.cos(t2 + t3))
    if not same_function(Jv.det(), detJ, [t1, t2, t3, L1s, L2s, L3s]):  # a factored form, checked before it is shown
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
        [[rn_, *row] for rn_, row in zip(["vx", "vy", "vz", "wx", "wy", "wz"], matrix_rows(jac[0], 7))],
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
