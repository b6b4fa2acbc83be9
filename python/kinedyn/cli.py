"""The ``kinedyn`` command line: ``kinedyn COMMAND ROBOT [options]``.

ROBOT is a built-in name (``kinedyn robots`` lists them) or a robot file (.urdf, .yaml, .toml).
Every command prints readable tables (colour on a terminal) or, with ``--json``, one JSON document.
Each capability module registers its commands with ``add_<name>_command(s)(subparsers)``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

__all__ = ["main", "load_robot", "parse_q", "emit", "console"]


# ------------------------------------------------------------------ shared helpers
def load_robot(spec: str):
    """A built-in robot by name, or a robot file by path."""
    from . import robots
    from .description.files import load

    if spec in robots.CATALOGUE:
        return robots.get(spec)
    path = Path(spec)
    if path.suffix.lower() in (".urdf", ".yaml", ".yml", ".toml", ".xml"):
        if not path.exists():
            raise ValueError(f"robot file '{spec}' does not exist")
        return load(path)
    raise ValueError(f"'{spec}' is neither a built-in robot ({', '.join(robots.names())}) nor a robot file (.urdf, .yaml, .toml)")


def parse_q(values: Optional[Sequence[float]], robot, degrees: bool = False, flag: str = "--q") -> np.ndarray:
    """Joint values (or rates) from the command line (zeros when omitted); degrees convert revolute
    joints only. ``flag`` names the option in the error message."""
    if values is None:
        return np.zeros(robot.n)
    q = np.array(values, dtype=float)
    if q.shape != (robot.n,):
        raise ValueError(f"{flag} needs {robot.n} values for robot '{robot.name}' (joints {', '.join(robot.joint_names)}), got {q.size}")
    if degrees:
        q = np.array([math.radians(v) if j.kind == "revolute" else v for v, j in zip(q, robot.joints)])
    return q


def console():
    from rich.console import Console

    return Console(highlight=False, soft_wrap=True)


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    return x


def emit(args, payload: dict, render: Callable[[], None]) -> None:
    """Print ``payload`` as JSON with --json, else call ``render`` for the human view."""
    if getattr(args, "json", False):
        print(json.dumps(_jsonable(payload), indent=2))
    else:
        render()


def matrix_table(title: str, M: np.ndarray, rows: Sequence[str], cols: Sequence[str], digits: int = 6):
    from rich.table import Table

    table = Table(title=title, title_justify="left")
    table.add_column("")
    for c in cols:
        table.add_column(c, justify="right")
    for name, row in zip(rows, np.atleast_2d(M)):
        table.add_row(name, *(f"{v: .{digits}g}" for v in row))
    return table


def _fmt(v) -> str:
    if isinstance(v, float):
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:.6g}"
    return str(v)


def _robot_arg(p):
    p.add_argument("robot", nargs="?", default=None, help="built-in name or robot file (default: planar_2r, the tutorial's arm)")
    p.add_argument("--json", action="store_true", help="print one JSON document instead of tables")


def _robot(args):
    from . import robots

    return load_robot(args.robot or robots.DEFAULT)


def _state_args(p, with_qd: bool = False):
    p.add_argument("--q", nargs="+", type=float, metavar="Q", help="joint values (default zeros)")
    if with_qd:
        p.add_argument("--qd", nargs="+", type=float, metavar="QD", help="joint velocities (default zeros)")
    p.add_argument("--deg", action="store_true", help="revolute joint values are in degrees")


# ------------------------------------------------------------------ commands
def cmd_robots(args) -> int:
    from . import robots

    items = {name: (robots.get(name).source or "") for name in robots.names()}

    def render():
        from rich.table import Table

        t = Table(title="built-in robots", title_justify="left")
        t.add_column("name")
        t.add_column("n", justify="right")
        t.add_column("source")
        for name in robots.names():
            t.add_row(name, str(robots.get(name).n), items[name])
        console().print(t)

    emit(args, {"robots": items}, render)
    return 0


def cmd_info(args) -> int:
    robot = _robot(args)
    joints = []
    for b in robot.tree.bodies:
        j = b.joint
        joints.append(
            {
                "name": j.name,
                "link": b.name,
                "type": j.kind,
                "parent": robot.tree.bodies[b.parent].name if b.parent >= 0 else robot.base,
                "axis": [float(a) for a in j.axis],
                "offset": float(j.offset),
                "lower": j.lower,
                "upper": j.upper,
                "velocity_limit": j.velocity_limit,
                "effort_limit": j.effort_limit,
                "gear_ratio": float(j.gear_ratio),
                "rotor_inertia": float(j.rotor_inertia),
                "viscous": float(j.viscous),
                "coulomb": float(j.coulomb),
            }
        )
    bodies = [
        {"link": b.name, "mass": float(b.inertia.mass), "com": [float(c) for c in b.inertia.com], "inertia_about_com": np.array(b.inertia.inertia, dtype=float)}
        for b in robot.tree.bodies
    ]
    dh = None
    if robot.dh is not None:
        dh = [{"theta": float(r.theta), "d": float(r.d), "a": float(r.a), "alpha": float(r.alpha), "type": r.kind} for r in robot.dh]
    payload = {
        "name": robot.name,
        "n": robot.n,
        "source": robot.source,
        "gravity": [float(g) for g in robot.gravity],
        "tool": robot.tool,
        "frames": robot.frame_names,
        "joints": joints,
        "dh_convention": robot.dh_convention,
        "dh": dh,
        "bodies": bodies,
        "total_mass": float(sum(b["mass"] for b in bodies)),
    }

    def render():
        from rich.table import Table

        c = console()
        c.print(f"[bold]{robot.name}[/bold]: {robot.n} joints, tool frame '{robot.tool}', gravity {payload['gravity']} m/s^2")
        if robot.source:
            c.print(f"source: {robot.source}")
        t = Table(title="joints", title_justify="left")
        for col in ("#", "joint", "type", "parent -> link", "axis", "offset", "limits", "vel / effort"):
            t.add_column(col)
        for i, j in enumerate(joints, 1):
            unit = "rad" if j["type"] == "revolute" else "m"
            t.add_row(
                str(i), j["name"], j["type"], f"{j['parent']} -> {j['link']}", " ".join(_fmt(a) for a in j["axis"]), _fmt(j["offset"]),
                f"[{_fmt(j['lower'])}, {_fmt(j['upper'])}] {unit}", f"{_fmt(j['velocity_limit'])} / {_fmt(j['effort_limit'])}",
            )
        c.print(t)
        if dh is not None:
            t = Table(title=f"DH table ({robot.dh_convention})", title_justify="left")
            for col in ("link", "theta", "d", "a", "alpha", "type"):
                t.add_column(col, justify="right")
            for i, r in enumerate(dh, 1):
                var = "q" if r["type"] == "revolute" else "d"
                t.add_row(
                    str(i),
                    f"q{i} + {_fmt(r['theta'])}" if var == "q" else _fmt(r["theta"]),
                    f"q{i} + {_fmt(r['d'])}" if var == "d" else _fmt(r["d"]),
                    _fmt(r["a"]), f"{_fmt(math.degrees(r['alpha']))} deg", r["type"],
                )
            c.print(t)
        t = Table(title="mass properties (body frames = joint frames)", title_justify="left")
        for col in ("link", "mass [kg]", "centre of mass [m]", "Ixx Iyy Izz about COM [kg m^2]"):
            t.add_column(col)
        for b in bodies:
            I = b["inertia_about_com"]
            t.add_row(b["link"], _fmt(b["mass"]), " ".join(_fmt(x) for x in b["com"]), " ".join(_fmt(I[k][k]) for k in range(3)))
        c.print(t)
        c.print(f"total moving mass: {_fmt(payload['total_mass'])} kg")

    emit(args, payload, render)
    return 0


def _rpy(R: np.ndarray) -> list:
    """Fixed-axis roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll)."""
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    roll = math.atan2(R[2, 1], R[2, 2])
    yaw = math.atan2(R[1, 0], R[0, 0])
    return [roll, pitch, yaw]


def cmd_fk(args) -> int:
    robot = _robot(args)
    q = parse_q(args.q, robot, args.deg)
    frames = robot.frame_names if args.all else [args.frame or robot.tool]
    poses = robot.frame_poses(q, frames)
    payload = {"robot": robot.name, "q": q, "frames": {f: {"pose": T, "position": T[:3, 3], "rpy": _rpy(T[:3, :3])} for f, T in zip(frames, poses)}}

    def render():
        c = console()
        c.print(f"[bold]{robot.name}[/bold] at q = {np.array2string(q, precision=6)} rad/m")
        for f, T in zip(frames, poses):
            c.print(matrix_table(f"pose of '{f}' in '{robot.base}'", T, ["", "", "", ""], ["", "", "", ""]))
            rpy = _rpy(T[:3, :3])
            c.print(f"  position {np.array2string(T[:3, 3], precision=6)} m, rpy {np.array2string(np.degrees(rpy), precision=4)} deg")

    emit(args, payload, render)
    return 0


def cmd_jacobian(args) -> int:
    from . import kinematics as kin

    robot = _robot(args)
    q = parse_q(args.q, robot, args.deg)
    rows = kin.task_rows(args.task)
    J = kin.task_jacobian(robot, q, args.frame, rows, args.reference)
    report = kin.singularity_report(robot, q, args.frame, rows, args.reference)
    names = report.row_names
    payload = {
        "robot": robot.name,
        "q": q,
        "frame": args.frame or robot.tool,
        "reference": args.reference,
        "rows": names,
        "jacobian": J,
        "singular_values": report.singular_values,
        "rank": report.rank,
        "singular": report.singular,
        "manipulability": float(np.prod(report.singular_values)) if len(rows) <= robot.n else 0.0,
        "condition_number": report.condition_number,
        "lost_directions": report.lost_directions,
    }

    def render():
        c = console()
        c.print(f"[bold]{robot.name}[/bold] at q = {np.array2string(q, precision=6)}; frame '{payload['frame']}', reference '{args.reference}'")
        c.print(matrix_table("Jacobian", J, names, robot.joint_names))
        c.print(f"singular values: {np.array2string(report.singular_values, precision=6)}")
        c.print(f"manipulability sqrt(det J J^T): {payload['manipulability']:.6g}")
        style = "bold red" if report.singular else "green"
        c.print(f"[{style}]{report.summary()}[/{style}]")

    emit(args, payload, render)
    return 0


def cmd_dynamics(args) -> int:
    robot = _robot(args)
    q = parse_q(args.q, robot, args.deg)
    qd = parse_q(args.qd, robot, args.deg, "--qd")
    qdd = parse_q(args.qdd, robot, args.deg, "--qdd")
    M, C, g = robot.mass_matrix(q), robot.coriolis_matrix(q, qd), robot.gravity_torque(q)
    payload = {
        "robot": robot.name,
        "q": q,
        "qd": qd,
        "qdd": qdd,
        "mass_matrix": M,
        "coriolis_matrix": C,
        "gravity_torque": g,
        "tau": robot.inverse_dynamics(q, qd, qdd),
        "kinetic_energy": robot.kinetic_energy(q, qd),
        "potential_energy": robot.potential_energy(q),
    }
    if args.tau is not None:
        tau = parse_q(args.tau, robot, False, "--tau")
        payload["applied_tau"] = tau
        payload["forward_dynamics_qdd"] = robot.forward_dynamics(q, qd, tau)
    if args.derivatives:
        payload["dtau_dq"], payload["dtau_dqd"], _ = robot.inverse_dynamics_derivatives(q, qd, qdd)

    def render():
        c = console()
        names = robot.joint_names
        c.print(f"[bold]{robot.name}[/bold] at q = {np.array2string(q, precision=6)}, qd = {np.array2string(qd, precision=6)}, qdd = {np.array2string(qdd, precision=6)}")
        c.print(matrix_table("M(q), mass matrix", M, names, names))
        c.print(matrix_table("C(q, qd), Coriolis matrix (Christoffel symbols)", C, names, names))
        c.print(matrix_table("g(q), gravity torque and tau = M qdd + C qd + g + friction", np.column_stack([g, payload["tau"]]), names, ["g", "tau"]))
        c.print(f"kinetic energy {payload['kinetic_energy']:.6g} J, potential energy {payload['potential_energy']:.6g} J")
        if args.tau is not None:
            c.print(f"forward dynamics: tau = {np.array2string(payload['applied_tau'], precision=6)} gives qdd = {np.array2string(payload['forward_dynamics_qdd'], precision=6)}")
        if args.derivatives:
            c.print(matrix_table("dtau/dq", payload["dtau_dq"], names, names))
            c.print(matrix_table("dtau/dqd", payload["dtau_dqd"], names, names))

    emit(args, payload, render)
    return 0


def _command_modules() -> list:
    """Commands contributed by the capability modules: (module, registration function)."""
    return [
        ("kinedyn.ik.cli", "add_ik_command"),
        ("kinedyn.symbolic.cli", "add_derive_command"),
        ("kinedyn.simulate.cli", "add_simulate_commands"),
        ("kinedyn.analysis.cli", "add_analysis_commands"),
        ("kinedyn.report.cli", "add_report_commands"),
    ]


def build_parser() -> argparse.ArgumentParser:
    import importlib

    parser = argparse.ArgumentParser(prog="kinedyn", description="Robot kinematics and dynamics, symbolic and numeric.")
    parser.add_argument("--version", action="version", version=f"kinedyn {__import__('kinedyn').__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("robots", help="list the built-in robots")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_robots)

    p = sub.add_parser("info", help="joint table, DH table and mass properties of a robot")
    _robot_arg(p)
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("fk", help="forward kinematics: pose of a frame at q")
    _robot_arg(p)
    _state_args(p)
    p.add_argument("--frame", help="frame name (default: the tool)")
    p.add_argument("--all", action="store_true", help="every frame of the robot")
    p.set_defaults(func=cmd_fk)

    p = sub.add_parser("jacobian", help="geometric Jacobian at q, its singular values and singularities")
    _robot_arg(p)
    _state_args(p)
    p.add_argument("--frame", help="frame name (default: the tool)")
    p.add_argument("--reference", default="world", choices=["world", "local", "spatial"])
    p.add_argument("--task", default="full", help="rows: full, position, orientation, planar, planar_pose (default full)")
    p.set_defaults(func=cmd_jacobian)

    p = sub.add_parser("dynamics", help="M, C, g and tau at a state (Rust core); forward dynamics with --tau; derivatives")
    _robot_arg(p)
    _state_args(p, with_qd=True)
    p.add_argument("--qdd", nargs="+", type=float, metavar="QDD", help="joint accelerations for tau (default zeros)")
    p.add_argument("--tau", nargs="+", type=float, metavar="TAU", help="joint torques/forces: also print the forward dynamics qdd")
    p.add_argument("--derivatives", action="store_true", help="also print dtau/dq and dtau/dqd (analytical)")
    p.set_defaults(func=cmd_dynamics)

    for module, function in _command_modules():
        getattr(importlib.import_module(module), function)(sub)
    return parser


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        return int(args.func(args) or 0)
    except BrokenPipeError:  # e.g. `kinedyn derive | head`: the reader left, nothing to report
        sys.stderr.close()
        return 0
    except (ValueError, KeyError, FileNotFoundError, RuntimeError) as e:
        message = e.args[0] if isinstance(e, KeyError) and e.args else e
        print(f"kinedyn {args.command}: error: {message}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
