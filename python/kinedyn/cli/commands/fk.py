"""``kinedyn fk ROBOT [--q ...]``: the pose of a frame (or of every frame) at q; with --symbolic,
as formulas."""

from __future__ import annotations

import numpy as np

from ..._math import rpy_from_matrix
from .. import app
from ..app import console, emit, esc, matrix_table, parse_q
from ..options import robot_argument, state_arguments
from . import formulas


def add_arguments(p) -> None:
    robot_argument(p)
    state_arguments(p)
    p.add_argument("--frame", help="frame name (default: the tool)")
    p.add_argument("--all", action="store_true", help="every frame of the robot")
    formulas.add_arguments(p)


def run(args) -> int:
    if args.symbolic:
        return formulas.run(args, "fk")
    robot = app.robot(args)
    q = parse_q(args.q, robot, args.deg)
    frames = robot.frame_names if args.all else [args.frame or robot.tool]
    poses = robot.frame_poses(q, frames)
    payload = {
        "robot": robot.name,
        "q": q,
        "frames": {
            f: {"pose": T, "position": T[:3, 3], "rpy": list(rpy_from_matrix(T))} for f, T in zip(frames, poses)
        },
    }

    def render():
        c = console()
        c.print(f"[bold]{esc(robot.name)}[/bold] at q = {np.array2string(q, precision=6)} rad/m")
        for f, T in zip(frames, poses):
            c.print(matrix_table(f"pose of '{f}' in '{robot.base}'", T, ["", "", "", ""], ["", "", "", ""]))
            rpy = list(rpy_from_matrix(T))
            c.print(
                f"  position {np.array2string(T[:3, 3], precision=6)} m, rpy {np.array2string(np.degrees(rpy), precision=4)} deg"
            )

    emit(args, payload, render)
    return 0
