"""``kinedyn fk|jacobian ROBOT --symbolic``: the pose or the Jacobian as formulas in the joint
symbols (kinedyn.symbolic), as text, LaTeX, Markdown or JSON."""

from __future__ import annotations

import json

from ... import robots
from .. import app


def symbolic_robot(args):
    """The robot for ``--symbolic``: a built-in with symbolic parameters in its symbolic form (l1, l2,
    ...; other built-ins keep their numbers), a robot file with its symbols; --set values substituted."""
    name = args.robot or robots.DEFAULT
    options = app.RobotOptions.from_args(args)
    factory = app.symbolic_builtin(name)
    if factory is not None:
        return app.substitute(factory(symbolic=True), options.values, name)
    return app.load_robot(name, options, numeric=False)


def add_arguments(p) -> None:
    """--symbolic, --format and --abbreviate."""
    p.add_argument(
        "--symbolic",
        action="store_true",
        help="the result as formulas in the joint symbols (kinedyn.symbolic), with the robot's parameter symbols",
    )
    p.add_argument(
        "--format",
        default="text",
        choices=["text", "latex", "markdown", "json"],
        help="with --symbolic: output format (default text)",
    )
    p.add_argument(
        "--abbreviate", action="store_true", help="with --symbolic: cos(q1 + q2) shown as c12, sin(q2) as s2"
    )


def run(args, what: str) -> int:
    """``kinedyn fk|jacobian ROBOT --symbolic``: the pose or the Jacobian as formulas (kinedyn.symbolic)."""
    # the symbolic engine and SymPy load only when --symbolic asks for formulas (kinedyn._lazy)
    import sympy as sp

    from ... import symbolic as ks

    robot = symbolic_robot(args)
    frame = args.frame or robot.tool
    q = ks.joint_symbols(robot)
    if what == "fk":
        M = ks.pose(robot, frame)
        label, latex_label = f"T_{frame}(q)", rf"T_{{\mathrm{{{frame}}}}}(q)"
    else:
        M = ks.jacobian(robot, frame, reference=args.reference)
        label, latex_label = f"J_{frame}(q) [{args.reference}]", rf"J_{{\mathrm{{{frame}}}}}(q)"
    shown = ks.abbreviate(M, q) if args.abbreviate else M
    fmt = "json" if args.json else args.format
    title = f"{'pose' if what == 'fk' else 'geometric Jacobian (rows [v; w], ' + args.reference + ')'} of '{frame}' of {robot.name} in q = ({', '.join(map(str, q))})"
    if fmt == "json":
        payload = {
            "robot": robot.name,
            "frame": frame,
            "q": [str(s) for s in q],
            "parameters": sorted(str(s) for s in robot.symbols),
            ("pose" if what == "fk" else "jacobian"): [[str(e) for e in row] for row in M.tolist()],
        }
        if what == "jacobian":
            payload["reference"] = args.reference
        print(json.dumps(payload, indent=2))
        return 0
    if fmt == "latex":
        print(f"% {title}\n{latex_label} = {sp.latex(shown)}")
    elif fmt == "markdown":
        print(f"{title}:\n\n$$\n{latex_label} = {sp.latex(shown)}\n$$")
    else:
        print(f"{title}:\n{label} =")
        print("\n".join("  [" + ", ".join(str(e) for e in row) + "]" for row in shown.tolist()))
    return 0
