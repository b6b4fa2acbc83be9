"""``kinedyn convert ROBOT OUT``: write a robot as URDF, MJCF, a robot file or a DH table, then read
OUT back and compare it with ROBOT (docs/model-files.md, "Converting robots")."""

from __future__ import annotations

import sys

from ...convert import ConversionError, convert
from .. import app
from ..options import EXIT_ERROR, EXIT_OK, OutputPath, one_line

CONVERT_TOLERANCE = 1e-8  # largest difference `kinedyn convert` accepts between a written file and its source


def add_arguments(p) -> None:
    p.description = (
        "Write ROBOT (a built-in or any robot file kinedyn reads) to OUT in the format of OUT's extension "
        "(.urdf, .xml/.mjcf, .yaml/.yml, .toml) or --to; then read OUT back and compare frame poses, M and "
        "inverse dynamics with ROBOT at random states (docs/model-files.md, 'Converting robots')."
    )
    p.add_argument("robot", help="built-in name or robot file")
    p.add_argument("output", metavar="OUT", action=OutputPath, help="the file to write")
    p.add_argument(
        "--to",
        choices=["dh", "urdf", "mjcf", "yaml", "toml"],
        help="output format (default: from OUT's extension); "
        "dh: the DH table of a serial chain, written as a .yaml/.toml robot file",
    )
    p.add_argument(
        "--convention", choices=["standard", "modified"], default="standard", help="DH convention for --to dh"
    )
    p.add_argument(
        "--inertia",
        choices=["warn", "repair", "strict"],
        default=None,
        help="inertia policy for tensors no rigid body has (repair: project them onto physical ones, as MJCF needs)",
    )
    p.add_argument(
        "--lock",
        action="append",
        default=[],
        metavar="JOINT",
        help="fix a joint at 0 before converting (repeatable; e.g. a gripper's fingers, for --to dh)",
    )
    p.add_argument("--states", type=int, default=5, help="random states of the check (default 5)")
    p.add_argument("--no-check", action="store_true", help="skip the check (reading the result back)")


def run(args) -> int:
    robot = app.load_robot(args.robot, app.RobotOptions.from_args(args))
    if args.inertia is not None:
        robot = robot.replace(inertia=args.inertia)
    if args.lock:
        robot = robot.lock_joints(args.lock)
    if args.states < 1:
        raise ValueError(f"--states must be at least 1, got {args.states}")
    try:
        result = convert(
            robot,
            args.output,
            args.to,
            convention=args.convention,
            check=not args.no_check,
            states=args.states,
            tolerance=CONVERT_TOLERANCE,
        )
    except ConversionError as e:  # the check found a difference: nothing written; show what it found
        print(e.result.summary().replace("wrote ", "did not write ", 1))
        print(
            one_line(
                f"kinedyn convert: error: the written file differs from {args.robot} by {e.result.max_error:.3g} "
                f"(more than {CONVERT_TOLERANCE:g}); nothing was written to {args.output}; "
                "this is a bug in kinedyn's writer, please report it"
            ),
            file=sys.stderr,
        )
        return EXIT_ERROR
    print(result.summary())
    for note in result.notes:
        if note.startswith("not checked"):  # said on stderr too: the conversion is unverified
            print(f"kinedyn convert: warning: {one_line(note)}", file=sys.stderr)
    return EXIT_OK
