"""``kinedyn fk ROBOT [--q ...]``: the pose of a frame (or of every frame) at q; with --symbolic,
as formulas."""

from __future__ import annotations

import numpy as np

from ..._math import rpy_from_matrix
from .. import app
from ..app import console, emit, esc, fixed, matrix_table, parse_q, q_labels, q_text
from ..options import robot_argument, state_arguments
from . import formulas

# the rows and columns of a homogeneous transform: the frame's axes and origin in base coordinates
POSE_ROWS = ["x", "y", "z", "(homogeneous)"]
POSE_COLUMNS = ["x axis", "y axis", "z axis", "origin"]


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
        "coordinate_labels": q_labels(robot),
        "frames": {
            f: {"pose": T, "position": T[:3, 3], "rpy": list(rpy_from_matrix(T))} for f, T in zip(frames, poses)
        },
    }

    def render():
        c = console()
        c.print(f"[bold]{esc(robot.name)}[/bold] at q = {q_text(robot, q)}")
        for f, T in zip(frames, poses):
            c.print(
                matrix_table(
                    f"pose of '{f}' in '{robot.base}' (4x4: rotation, position in m)", T, POSE_ROWS, POSE_COLUMNS
                )
            )
            rpy = list(rpy_from_matrix(T))
            c.print(f"  position {fixed(T[:3, 3], 6)} m, rpy {fixed(np.degrees(rpy), 4)} deg")

    emit(args, payload, render)
    return 0
