"""``kinedyn jacobian ROBOT [--q ...]``: the geometric Jacobian at q, its singular values, rank and
manipulability over the rows the arm spans; with --symbolic, as formulas."""

from __future__ import annotations

import numpy as np

from ... import kinematics as kin
from .. import app
from ..app import console, dof_labels, emit, esc, matrix_table, parse_q, q_labels, q_text
from ..options import robot_argument, state_arguments
from . import formulas


def add_arguments(p) -> None:
    robot_argument(p)
    state_arguments(p)
    p.add_argument("--frame", help="frame name (default: the tool)")
    p.add_argument("--reference", default="world", choices=["world", "local", "spatial"])
    p.add_argument(
        "--task",
        default=None,
        help="rows: full, position, orientation, planar, planar_pose (default full; the manipulability "
        "of an arm with fewer than six joints then uses the rows it spans, e.g. vx vy vz for elbow_3r)",
    )
    formulas.add_arguments(p)


def _basis(why: str, rows: list, n: int) -> str:
    """Why the rank and manipulability are measured over the rows they are (kinematics.analysis_rows)."""
    if why == "given":
        return "the --task rows" + (
            f"; {len(rows)} rows > {n} joints, so J J^T is singular by construction" if len(rows) > n else ""
        )
    if why == "all":
        return "all six rows"
    if why == "column_space":
        return "all six rows; sqrt(det J^T J), the volume in the Jacobian's column space"
    return f"the rows a {n}-joint arm spans; choose others with --task"


def run(args) -> int:
    if args.symbolic:
        return formulas.run(args, "jacobian")
    robot = app.robot(args)
    q = parse_q(args.q, robot, args.deg)
    explicit = args.task is not None
    rows = kin.task_rows(args.task if explicit else "full")
    J = kin.task_jacobian(robot, q, args.frame, rows, args.reference)
    names = [kin.ROW_NAMES[r] for r in rows]
    a_rows, why = kin.analysis_rows(robot, rows, explicit, args.frame, args.reference)
    basis = _basis(why, rows, robot.n)
    report = kin.singularity_report(robot, q, args.frame, a_rows, args.reference)
    if why == "column_space":
        w = float(np.prod(report.singular_values))  # sqrt(det J^T J): the column-space volume
    else:
        w = float(kin.manipulability(robot, q, args.frame, a_rows, args.reference))
    w_rows = report.row_names
    payload = {
        "robot": robot.name,
        "q": q,
        "frame": args.frame or robot.tool,
        "reference": args.reference,
        "rows": names,
        "coordinate_labels": q_labels(robot),
        "velocity_labels": dof_labels(robot),
        "jacobian": J,
        "singular_values": report.singular_values,
        "rank": report.rank,
        "singular": report.singular,
        "manipulability": w,
        "analysis_rows": w_rows,
        "analysis_rows_basis": basis,
        "condition_number": report.condition_number,
        "lost_directions": report.lost_directions,
    }

    def render():
        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold] at q = {q_text(robot, q)}; frame '{esc(payload['frame'])}', reference '{args.reference}'"
        )
        c.print(matrix_table("Jacobian", J, names, dof_labels(robot)))
        c.print(f"rank, singular values and manipulability over rows {', '.join(w_rows)} ({basis})")
        c.print(f"singular values: {np.array2string(report.singular_values, precision=6)}")
        c.print(f"manipulability sqrt(det J J^T): {w:.6g}")
        style = "bold red" if report.singular else "green"
        c.print(f"[{style}]{esc(report.summary())}[/{style}]")

    emit(args, payload, render)
    return 0
