"""``kinedyn ik ROBOT --xyz X Y Z [--rpy R P Y] [--all] [--json]``: inverse kinematics from the shell.

Exit status 0 when a solution was found, 2 when none exists (out of reach, or every solution
outside the joint limits).
"""

from __future__ import annotations

import math

import numpy as np
from rich.table import Table

from ..._math import rpy_to_matrix
from ...ik.redundancy import default_redundancy
from ...ik.solve import METHODS, inverse_kinematics
from .. import app
from ..app import console, emit, esc, parse_q, q_labels, warn_degrees
from ..options import EXIT_NO, EXIT_OK, finite_float, in_cli_terms

# the solver's messages name its Python arguments; on the command line they are these flags
FLAG_PHRASES = {
    "respect_limits=False": "--ignore-limits",
    "method='numeric'": "--method numeric",
    "method='analytic'": "--method analytic",
    "a 4x4 pose": "a pose (--rpy)",
    "q0": "--q0",
}


def add_arguments(p) -> None:
    p.description = (
        "Every joint vector that puts the tool (or --frame) at the target, nearest --q0 first: closed form when "
        "the robot's geometry has one (planar 2R/3R, elbow arms, spherical wrists, UR-type arms), else "
        "Levenberg-Marquardt. Without --rpy the target is the position only. Example (the tutorial's challenge): "
        "kinedyn ik elbow_3r --xyz 1.0 0.2 0.5 --all"
    )
    p.add_argument("robot", nargs="?", default=None, help="built-in name or robot file (default: planar_2r)")
    p.add_argument(
        "--xyz",
        nargs=3,
        type=finite_float,
        required=True,
        metavar=("X", "Y", "Z"),
        help="target position of the frame origin (m)",
    )
    p.add_argument(
        "--rpy",
        nargs=3,
        type=finite_float,
        metavar=("ROLL", "PITCH", "YAW"),
        help="target orientation, R = Rz(yaw) Ry(pitch) Rx(roll) (radians; degrees with --deg); omit for a position-only target",
    )
    p.add_argument(
        "--all",
        action="store_true",
        help="print every solution and the statement of completeness (default: only the one nearest q0); on a "
        "seven-joint arm with a pose target, every branch at the arm angle of --q0 (SRS arms) or with a joint "
        "held at its --q0 value, unless --arm-angle or --hold says which",
    )
    p.add_argument(
        "--hold",
        metavar="JOINT=VALUE",
        help="seven-joint arms: hold JOINT at VALUE (rad; degrees with --deg) and list every branch",
    )
    p.add_argument(
        "--arm-angle",
        type=finite_float,
        metavar="PSI",
        help="SRS seven-joint arms: the elbow's swivel angle about the shoulder-wrist line (rad; degrees with --deg)",
    )
    p.add_argument("--q0", nargs="+", type=float, metavar="Q", help="reference / start joint values (default zeros)")
    p.add_argument("--deg", action="store_true", help="--rpy and --q0 in degrees; angles printed in degrees")
    p.add_argument("--frame", help="frame to place (default: the tool)")
    p.add_argument("--method", default="auto", choices=METHODS, help="closed form, numeric, or auto (default)")
    p.add_argument("--ignore-limits", action="store_true", help="keep solutions outside the joint limits")
    p.add_argument("--json", action="store_true", help="print one JSON document instead of a table")
    p.set_defaults(_flag_phrases=FLAG_PHRASES)


def target_from_args(xyz, rpy=None, degrees: bool = False) -> np.ndarray:
    """A 3-vector (no rpy) or a 4x4 pose from command-line values."""
    p = np.array(xyz, dtype=float)
    if rpy is None:
        return p
    r, pi, y = (math.radians(v) if degrees else float(v) for v in rpy)
    T = np.array(rpy_to_matrix(r, pi, y), dtype=float)
    T[:3, 3] = p
    return T


def run(args) -> int:
    robot = app.robot(args)
    if args.rpy is not None and not args.deg:
        warn_degrees("--rpy", [(name, v, None) for name, v in zip(("roll", "pitch", "yaw"), args.rpy)])
    target = target_from_args(args.xyz, args.rpy, args.deg)
    q0 = None
    if args.q0 is not None:
        q0 = parse_q(args.q0, robot, args.deg, "--q0")
    redundancy = _redundancy(args, robot, target, q0)
    if redundancy is not None:
        result = robot.inverse_kinematics(
            target, q0=q0, respect_limits=not args.ignore_limits, frame=args.frame, redundancy=redundancy
        )
    else:
        result = inverse_kinematics(
            robot, target, q0=q0, method=args.method, respect_limits=not args.ignore_limits, frame=args.frame
        )
    shown = result.solutions if args.all else result.solutions[:1]
    # per q coordinate: revolute angles (--deg) and the column names (a multi-DOF joint's block:
    # root.x, root.y, root.z, root.qx, ..., root.qw for a free-flyer; kinedyn.coordinates)
    revolute = np.array([j.kind == "revolute" for j in robot.joints for _ in range(j.nq)], dtype=bool)
    labels = q_labels(robot)

    def angles(q):
        return np.where(revolute, np.degrees(q), q) if args.deg else q

    payload = {
        "robot": robot.name,
        "frame": args.frame or robot.tool,
        "target": target,
        "units": "deg/m" if args.deg else "rad/m",
        "coordinate_labels": labels,
        **result.to_dict(),
        "solutions": [angles(q) for q in shown],
        "position_error": result.position_error[: len(shown)],
        "orientation_error": result.orientation_error[: len(shown)],
        "count": len(result.solutions),
        "redundancy": redundancy,
    }
    if "message" in payload:
        payload["message"] = in_cli_terms(payload["message"], FLAG_PHRASES)
    if payload["nearest_q"] is not None:
        payload["nearest_q"] = angles(result.nearest_q)

    def render():
        c = console()
        what = (
            f"position {np.array2string(target, precision=6)}"
            if target.shape == (3,)
            else f"pose at {np.array2string(target[:3, 3], precision=6)}, rpy {np.array2string(np.asarray(args.rpy), precision=6)}{' deg' if args.deg else ' rad'}"
        )
        c.print(f"[bold]{esc(robot.name)}[/bold]: '{esc(payload['frame'])}' to {what}; solver {result.solver}")
        if len(shown):
            unit = "deg" if args.deg else "rad"
            table = Table(
                title=f"{len(result.solutions)} solution(s) ({unit}, m), nearest q0 first"
                + ("" if args.all else " (--all lists every one)"),
                title_justify="left",
            )
            table.add_column("#", justify="right")
            for label in labels:
                table.add_column(esc(label), justify="right")
            table.add_column("|dp| m", justify="right")
            table.add_column("|dR| rad", justify="right")
            for k, q in enumerate(shown):
                table.add_row(
                    str(k + 1),
                    *(f"{v:.4f}" for v in angles(q)),
                    f"{result.position_error[k]:.0e}",
                    f"{result.orientation_error[k]:.0e}",
                )
            c.print(table)
        if redundancy is not None:
            c.print(f"redundancy: {esc(_describe(redundancy, args.deg))}")
        if args.all:
            c.print(esc(result.completeness))
        style = "green" if result.success else "bold red"
        c.print(f"[{style}]{esc(in_cli_terms(result.message, FLAG_PHRASES))}[/{style}]")

    emit(args, payload, render)
    return EXIT_OK if result.success else EXIT_NO


def _redundancy(args, robot, target, q0) -> dict | None:
    """The redundancy parameter from --hold / --arm-angle, or for --all on a seven-joint arm with
    a pose target the default one (kinedyn.ik.redundancy.default_redundancy); else None."""
    if args.hold is not None and args.arm_angle is not None:
        raise ValueError("give --hold or --arm-angle, not both")
    if args.arm_angle is not None:
        return {"arm_angle": math.radians(args.arm_angle) if args.deg else float(args.arm_angle)}
    if args.hold is not None:
        name, sep, value = args.hold.partition("=")
        try:
            v = float(value)
        except ValueError:
            v = math.nan
        if not sep or not math.isfinite(v):
            raise ValueError(f"--hold takes JOINT=VALUE (a finite number), got {args.hold!r}")
        joint = robot.joint_names.index(name) if name in robot.joint_names else name
        k = joint if isinstance(joint, int) else -1
        revolute = 0 <= k < len(robot.joints) and robot.joints[k].kind == "revolute"
        return {"joint": name, "value": math.radians(v) if args.deg and revolute else v}
    if args.all and robot.nq == 7 and target.shape == (4, 4) and args.method == "auto":
        return default_redundancy(robot, q0, args.frame)
    return None


def _describe(redundancy: dict, degrees: bool) -> str:
    if "arm_angle" in redundancy:
        psi = redundancy["arm_angle"]
        return f"arm angle {math.degrees(psi):.4f} deg" if degrees else f"arm angle {psi:.6f} rad"
    return f"{redundancy['joint']} held at {redundancy['value']:.6f}"
