"""``kinedyn codegen ROBOT --algorithms rnea,aba --lang c|rust [-o FILE]``: the robot's dynamics as
straight-line C or Rust (:mod:`kinedyn.codegen`, docs/codegen.md)."""

from __future__ import annotations

import sys

from ... import codegen
from ..._ui.files import write_text
from .. import app
from ..app import console, emit, esc
from ..options import OutputPath, robot_argument


def add_arguments(p) -> None:
    robot_argument(p)
    p.add_argument(
        "--algorithms",
        default="rnea,crba,minv,aba",
        metavar="NAMES",
        help=f"comma-separated, from {', '.join(codegen.ALGORITHMS)}, or all (default: rnea,crba,minv,aba)",
    )
    p.add_argument("--lang", default="c", choices=codegen.LANGUAGES, help="the language of the source (default c)")
    p.add_argument("--name", help="the robot's part of the function names kinedyn_NAME_ALGORITHM (default: its name)")
    p.add_argument("-o", "--output", action=OutputPath, help="write the source to this file instead of the terminal")


def run(args) -> int:
    algorithms = codegen.parse_algorithms(args.algorithms)
    robot = app.robot(args)
    text = codegen.generate(robot, algorithms, args.lang, name=args.name)
    counts = {a: codegen.operation_counts(robot, a)["optimized"] for a in algorithms} if args.json else {}
    if args.output:
        write_text(args.output, text)  # atomic: a failed run leaves the old file
    payload = {
        "robot": robot.name,
        "language": args.lang,
        "algorithms": algorithms,
        "operations": counts,
        "output": args.output,
        "source": None if args.output else text,
    }

    def render():
        if args.output:
            console().print(
                f"wrote {', '.join(algorithms)} of '{esc(robot.name)}' as {args.lang} to {esc(args.output)}"
            )
        else:
            sys.stdout.write(text)

    emit(args, payload, render)
    return 0
