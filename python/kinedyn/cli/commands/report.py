"""``kinedyn report ROBOT -o report.html``: one self-contained HTML report of a robot (3-D view,
Jacobian, equations of motion, properties, simulation; the worked tutorial for the tutorial's arm)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import robots
from ..._ui.files import write_text
from ...report.html import SIMULATION_BUDGET, build_report, collect, default_configuration
from .. import app
from ..app import console, emit, esc, parse_q
from ..options import OutputPath, nonnegative_int, positive_float


def add_arguments(p) -> None:
    p.add_argument(
        "robot", nargs="?", default=None, help="built-in name or robot file (default: planar_2r, the tutorial's arm)"
    )
    p.add_argument(
        "-o", "--output", default="report.html", action=OutputPath, help="the HTML file to write (default: report.html)"
    )
    p.add_argument(
        "--q", nargs="+", type=float, metavar="Q", help="joint values (default: a generic, non-singular configuration)"
    )
    p.add_argument(
        "--frame",
        help="the tool frame whose pose and Jacobian the report shows (default: the robot's tool, e.g. a URDF's "
        "tool0/*_tcp link, else the end of its longest chain)",
    )
    p.add_argument(
        "--qd",
        nargs="+",
        type=float,
        metavar="QD",
        help="joint velocities at the start of the simulation (default zeros)",
    )
    p.add_argument("--deg", action="store_true", help="revolute joint values are in degrees")
    p.add_argument("--t", type=positive_float, default=3.0, help="simulated seconds of free motion (default 3)")
    p.add_argument(
        "--eom-joints",
        type=nonnegative_int,
        default=3,
        help="typeset the symbolic equations of motion for arms with up to this many joints (default 3)",
    )
    p.add_argument(
        "--time-budget",
        dest="time_budget",
        type=positive_float,
        default=None,
        metavar="S",
        help="wall-clock seconds the free-motion simulation may take; a run cut short says so in the report (default 30)",
    )
    p.add_argument(
        "--collision",
        action="store_true",
        help="the 3-D view draws the description's collision shapes instead of its visual ones",
    )
    p.add_argument(
        "--no-tutorial",
        action="store_true",
        help="leave out the worked tutorial (included for the default robot, the tutorial's arm)",
    )
    p.add_argument("--json", action="store_true", help="print the report's numbers as one JSON document")


def run(args) -> int:
    spec = args.robot or robots.DEFAULT
    options = app.RobotOptions.from_args(args)
    robot = app.load_robot(spec, options)
    if args.frame is not None and args.frame != robot.tool:
        robot = robot.replace(tool=args.frame)  # a ValueError naming the robot's frames if it has none such
    q = parse_q(args.q, robot, args.deg) if args.q is not None else default_configuration(robot)
    qd = parse_q(args.qd, robot, args.deg, "--qd") if args.qd is not None else None
    out = Path(args.output)  # checked (with --t, --time-budget) before the command started: options.check_outputs

    # the tutorial's arm (the default robot, as the tutorial sets it: no --set changes) gets the tutorial
    # worked step by step; the tutorial's numbers are those of the standard arm, not of a changed one
    tutorial = spec == robots.DEFAULT and not options.values and not args.no_tutorial
    progress = False if args.json else None  # a bar on stderr on a terminal; never with --json
    budget = SIMULATION_BUDGET if args.time_budget is None else args.time_budget
    data = collect(
        robot, q, qd, name=spec, t_end=args.t, eom_joints=args.eom_joints, time_budget=budget, progress=progress
    )
    public = {k: v for k, v in data.items() if not k.startswith("_")}
    page = build_report(
        robot,
        q,
        qd,
        name=spec,
        t_end=args.t,
        eom_joints=args.eom_joints,
        data=data,
        tutorial=tutorial,
        progress=progress,
        time_budget=budget,
        geometry="collision" if args.collision else "visual",
    )
    write_text(out, page)  # atomic: a failed run leaves the old file
    payload = {"path": str(out.resolve()), **public}
    payload.pop("simulation", None)
    if "simulation" in data:
        payload["simulation_energy_drift"] = data["simulation"]["energy_drift"]
        payload["simulation_method"] = data["simulation"]["method"]
        payload["simulation_note"] = data["simulation"]["note"]

    def render():
        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold]: report written to [cyan]{esc(out)}[/cyan] ({out.stat().st_size / 1024:.0f} KiB, self-contained; open it in a browser)"
        )
        c.print(
            f"  q = {np.array2string(np.asarray(q), precision=4)}, Jacobian rank {data['rank']} ({esc(data['singularity'])})"
        )
        if data.get("properties"):
            bad = [p["property"] for p in data["properties"] if not p["ok"]]
            c.print(
                "  properties: "
                + ("[green]all hold[/green]" if not bad else f"[bold red]failing: {', '.join(bad)}[/bold red]")
            )
        if data.get("simulation", {}).get("note"):
            c.print(f"  [bold yellow]simulation[/bold yellow]: {data['simulation']['note']}")

    emit(args, payload, render)
    return 0
