"""``kinedyn derive ROBOT``: the symbolic equations of motion, as LaTeX, Markdown, MathML, text or code."""

from __future__ import annotations

import sys

from ... import robots
from ..._ui import progress
from ..._ui.files import write_text
from ...description.snap import SNAP_TOLERANCE
from .. import app
from ..app import console, emit, esc
from ..options import OutputPath

FORMATS = ("text", "latex", "markdown", "mathml", "python", "numpy", "c")


def add_arguments(p) -> None:
    p.add_argument("robot", nargs="?", default=None, help="built-in name or robot file (default: planar_2r)")
    p.add_argument(
        "--symbolic", action="store_true", help="use the built-in's symbolic parameters (l1, m1, I1, g, ...)"
    )
    p.add_argument("--general", action="store_true", help="replace every inertia by ten symbols (M1, MX1, ..., ZZ1)")
    p.add_argument("--method", default="lagrange", choices=["lagrange", "newton_euler"])
    p.add_argument("--format", default="text", choices=FORMATS)
    p.add_argument("--no-simplify", action="store_true", help="keep products of sines and cosines (faster)")
    p.add_argument(
        "--form",
        default="auto",
        choices=["auto", "cse", "expanded"],
        help="M, C, g with named intermediate variables (cse), written out (expanded), or cse for a large model (auto)",
    )
    p.add_argument(
        "--snap-angles",
        type=float,
        default=SNAP_TOLERANCE,
        metavar="TOL",
        help=f"make rotation angles within TOL rad of a multiple of pi/2 exact (default {SNAP_TOLERANCE:g}; 0: off)",
    )
    p.add_argument("-o", "--output", action=OutputPath, help="write to this file instead of the terminal")
    p.add_argument("--json", action="store_true", help="print M, C, g, tau and op counts as JSON")


def _robot(args):
    name = args.robot or robots.DEFAULT
    options = app.RobotOptions.from_args(args)
    if args.symbolic:
        factory = app.symbolic_builtin(name)
        if factory is None:
            symbolic = [n for n in robots.CATALOGUE if app.symbolic_builtin(n) is not None]
            raise ValueError(
                f"--symbolic needs a built-in with symbolic parameters ({', '.join(symbolic)}); got '{name}'"
            )
        return app.substitute(factory(symbolic=True), options.values, name)
    return app.load_robot(name, options)


def run(args) -> int:
    robot = _robot(args)
    with progress.busy(
        f"deriving the equations of motion of '{robot.name}' ({args.method})", progress=False if args.json else None
    ):
        eom = robot.equations_of_motion(
            method=args.method,
            simplify=not args.no_simplify,
            parameters="general" if args.general else None,
            form=args.form,
            snap_angles=args.snap_angles,
        )
        fmt = args.format
        if fmt == "latex":
            text = eom.to_latex_document()
        elif fmt == "markdown":
            text = eom.to_markdown()
        elif fmt == "mathml":
            text = eom.to_mathml()
        elif fmt == "text":
            text = str(eom)
        else:
            text = eom.to_code(fmt)
        payload = _payload(args, robot, eom, text) if args.json else {}
    if args.output:
        write_text(args.output, text)  # atomic: a failed run leaves the old file
    if not args.json:
        for note in eom.notes:  # on stderr: the equations on stdout stay clean for a pipe
            print(f"note: {note}", file=sys.stderr)

    def render():
        if args.output:
            console().print(f"wrote the {fmt} equations of motion of '{esc(robot.name)}' to {esc(args.output)}")
        else:
            print(text)

    emit(args, payload, render)
    return 0


def _payload(args, robot, eom, text) -> dict:
    """The --json document: M, C, g, tau as strings; in CSE form (a large model) each block's
    intermediate variables as [name, expression] pairs beside its entries, in terms of them."""
    payload = {
        "robot": robot.name,
        "method": args.method,
        "format": args.format,
        "q": [str(s) for s in eom.q],
        "notes": eom.notes,
    }
    if eom.closed_form is not None:
        cf = eom.closed_form()
        n = eom.n
        entries = {k: [str(e) for e in cf[k].entries] for k in ("M", "C", "g")}
        payload.update(
            form="cse",
            M=[entries["M"][r * n : (r + 1) * n] for r in range(n)],
            C=[entries["C"][r * n : (r + 1) * n] for r in range(n)],
            g=entries["g"],
            tau=[str(t + f) for t, f in zip(cf["tau"].entries, eom.friction)],
            intermediates={k: [[str(s), str(e)] for s, e in cf[k].assignments] for k in ("M", "C", "g", "tau")},
            op_count={k: cf[k].op_count() for k in ("M", "C", "g", "tau")},
        )
    else:
        payload.update(
            form="expanded",
            M=[[str(e) for e in row] for row in eom.M.tolist()],
            C=[[str(e) for e in row] for row in eom.C.tolist()],
            g=[str(e) for e in eom.g],
            tau=[str(e) for e in eom.tau],
            op_count=eom.op_count(),
        )
    payload.update(output=args.output, text=None if args.output else text)
    return payload
