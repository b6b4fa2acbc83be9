"""``kinedyn check ROBOT``: the properties of the equations of motion (Spong §9.5), each with its
residual; with --prove, also proved on the symbolic model. Exit status 2 when a property fails."""

from __future__ import annotations

from dataclasses import replace

from rich.table import Table

from ...analysis.properties import check_properties, prove_properties
from .. import app
from ..app import console, emit, esc
from ..options import EXIT_NO, EXIT_OK, nonnegative_int, positive_float, positive_int, robot_argument

SEARCH_BUDGET = 30.0  # seconds: the inertia-bound search of a 32-joint humanoid took 3.5 minutes unbounded


def add_arguments(p) -> None:
    robot_argument(p)
    p.add_argument("--samples", type=positive_int, default=200, help="random states (default 200)")
    p.add_argument(
        "--t", type=positive_float, default=2.0, help="length of the passivity trajectory in seconds (default 2)"
    )
    p.add_argument("--seed", type=nonnegative_int, default=0)
    p.add_argument(
        "--budget",
        type=positive_float,
        default=SEARCH_BUDGET,
        metavar="SECONDS",
        help=f"time for the global search of the inertia bounds (default {SEARCH_BUDGET:g} s); when it runs out, "
        "the bounds found so far are reported as sampled, not searched",
    )
    p.add_argument(
        "--prove",
        action="store_true",
        help="also prove the identities on the symbolic model (exact simplification) and search its inertia bounds",
    )


def run(args) -> int:
    robot = app.robot(args)
    if getattr(args, "prove", False) and robot.has_multi_dof_joints:
        joint = next(j for j in robot.joints if j.is_multi_dof)
        raise ValueError(
            f"kinedyn check --prove handles revolute and prismatic joints only; robot '{robot.name}' has the {joint.kind} joint "
            f"'{joint.name}': the symbolic engine writes it in ZYX Euler angles, whose D(q) is singular at pitch = ±pi/2, so no inertia "
            f"bounds exist in them, and a floating base's derivation is large. Run 'kinedyn check' without --prove (the numeric "
            f"checks handle multi-DOF joints), or call robot.equations_of_motion().check_properties() in Python for the identities"
        )
    if robot.loops and getattr(args, "prove", False):
        # a closed chain's properties are its reduced equations': proved on the symbolic ones; without
        # --prove, check_properties measures the numeric reduced equations at sampled closed states
        report = robot.equations_of_motion(steps=False).check_properties(samples=args.samples, seed=args.seed)
        report.checks = [replace(c, name="reduced model: " + c.name) for c in report.checks]
        emit(args, report.to_dict(), lambda: _table(report, robot, args))
        return EXIT_OK if report.passed else EXIT_NO
    report = check_properties(
        robot,
        samples=args.samples,
        seed=args.seed,
        T=args.t,
        time_budget=args.budget,
        progress=None if not getattr(args, "json", False) else False,
    )
    if getattr(args, "prove", False):
        proof = prove_properties(robot.equations_of_motion(steps=False), samples=args.samples, seed=args.seed)
        report.checks += [replace(c, name="symbolic model: " + c.name) for c in proof.checks]

    emit(args, report.to_dict(), lambda: _table(report, robot, args))
    return EXIT_OK if report.passed else EXIT_NO


def _table(report, robot, args) -> None:
    c = console()
    t = Table(
        title=f"properties of {esc(robot.name)} ({args.samples} sampled states, "
        + ("closed ones, the reduced equations)" if robot.loops else f"{args.t:g} s trajectory)"),
        title_justify="left",
    )
    for col in ("", "property", "how", "residual", "tolerance", "measured"):
        t.add_column(col)
    for chk in report.checks:
        mark = "[green]ok[/green]" if chk.passed else "[bold red]FAIL[/bold red]"
        t.add_row(mark, esc(chk.name), chk.status, f"{chk.residual:.3g}", f"{chk.tolerance:.3g}", esc(chk.detail))
    c.print(t)
