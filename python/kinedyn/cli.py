"""The ``kinedyn`` command line: ``kinedyn COMMAND ROBOT [options]``.

ROBOT is a built-in name (``kinedyn robots`` lists them) or a robot file (.urdf, .yaml, .toml).
Every command prints readable tables (colour on a terminal) or, with ``--json``, one JSON document.
Each capability module registers its commands with ``add_<name>_command(s)(subparsers)``.

A mistake of the user (a bad robot file, a bad argument, an output path that cannot be written) is
one line on stderr, ``kinedyn COMMAND: error: ...``, and exit status 1; ``--debug`` adds the
traceback. Exit statuses: 0 done; 1 the user's mistake; 2 the command ran and its answer is "no"
(``ik``: no solution, ``check``: a property fails); 70 an internal error (a bug in kinedyn);
130 interrupted (Ctrl-C).
"""

from __future__ import annotations

import argparse
import contextlib
import contextvars
import json
import math
import os
import re
import sys
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "main",
    "load_robot",
    "parse_q",
    "emit",
    "console",
    "check_output_path",
    "OutputPath",
    "ROBOT_FILE_EXTENSIONS",
    "EXIT_OK",
    "EXIT_ERROR",
    "EXIT_NO",
    "EXIT_INTERNAL",
    "EXIT_INTERRUPTED",
]

EXIT_OK = 0
EXIT_ERROR = 1  # the user's mistake: bad argument, bad robot file, unwritable output
EXIT_NO = 2  # the command ran and its answer is "no": ik found no solution, check found a failing property
EXIT_INTERNAL = 70  # a bug in kinedyn (BSD sysexits' EX_SOFTWARE)
EXIT_INTERRUPTED = 130  # Ctrl-C (128 + SIGINT, as shells report it)


# ------------------------------------------------------------------ shared helpers
# The robot file extensions kinedyn.load reads (kinedyn.description.files.load dispatches on these).
ROBOT_FILE_EXTENSIONS = (".urdf", ".yaml", ".yml", ".toml", ".xml", ".xacro")


@dataclass
class _Invocation:
    """What the running command was given beyond its own arguments: the ``--set`` values, and whether
    it needs a numeric robot (every command but ``derive`` and ``info``)."""

    command: str
    values: dict[str, float] = field(default_factory=dict)
    numeric: bool = True
    xacro_args: dict[str, str] = field(default_factory=dict)  # --xacro-arg NAME:=VALUE
    trust_xacro: bool = False  # --trust-xacro: expanding xacro runs the file's Python expressions
    floating_base: bool = False  # --floating-base: a URDF's root link on a free-flyer


_INVOCATION: contextvars.ContextVar[_Invocation | None] = contextvars.ContextVar("kinedyn_cli_invocation", default=None)

# commands that show a robot with symbolic parameters as it is (the others need numbers)
SYMBOLIC_COMMANDS = {"derive", "info"}


def load_robot(spec: str, *, values: dict[str, float] | None = None, numeric: bool | None = None):
    """A built-in robot by name, or a robot file by path, with parameter ``values`` substituted
    (``--set name=value``: a built-in's keyword parameters, or a robot file's symbols). ``numeric``:
    refuse a robot that still has symbolic parameters, naming them and the ``--set`` that gives them.
    Inside :func:`main` both default to the running command's ``--set`` values and needs."""
    from . import robots

    run = _INVOCATION.get()
    if values is None:
        values = run.values if run is not None else {}
    if numeric is None:
        numeric = run.numeric if run is not None else False
    if spec in robots.CATALOGUE:
        if run is not None and run.floating_base:
            raise ValueError(
                f"--floating-base applies to URDF (and xacro) files; '{spec}' is a built-in robot with a fixed base"
            )
        robot = _builtin(spec, values)
    else:
        robot = _substitute(_robot_file(spec), values, spec)
    if numeric and robot.is_symbolic:
        missing = sorted(str(s) for s in robot.symbols)
        needs = f"'kinedyn {run.command}'" if run is not None else "this computation"
        raise ValueError(
            f"robot '{robot.name}' ({spec}) has parameters without values: {', '.join(missing)}; {needs} needs numbers: "
            f"add {' '.join(f'--set {m}=...' for m in missing)}"
        )
    return robot


def _robot_file(spec: str):
    from . import robots
    from .robot_files import load

    path = Path(spec)
    ext = path.suffix.lower()
    if ext not in ROBOT_FILE_EXTENSIONS:
        why = f"robot files end in {', '.join(ROBOT_FILE_EXTENSIONS)}" + (f", not '{ext}'" if ext else "")
        raise ValueError(f"'{spec}' is neither a built-in robot ({', '.join(robots.names())}) nor a robot file ({why})")
    if not path.exists():
        raise ValueError(f"robot file '{spec}' does not exist")
    if path.is_dir():
        raise ValueError(f"robot file '{spec}' is a folder")
    run = _INVOCATION.get()
    options: dict[str, Any] = {}
    if ext == ".xacro" and run is not None:
        options = {"xacro_args": run.xacro_args, "trust_xacro": run.trust_xacro}
    if run is not None and run.floating_base:
        if ext not in (".urdf", ".xacro"):
            raise ValueError(
                f"--floating-base applies to URDF (and xacro) files, not '{spec}' (a robot file or MJCF says its own joints)"
            )
        options["floating_base"] = True
    try:
        try:
            return load(path, **options)
        except ValueError as e:
            if ext == ".xacro" and "trust_xacro=True" in str(e):
                raise ValueError(
                    str(e).replace("pass trust_xacro=True (command line: --trust-xacro)", "add --trust-xacro")
                ) from None
            raise
    except ValueError as e:  # the loader's own message; make sure it says which file
        if spec in str(e) or str(path) in str(e):
            raise
        raise ValueError(f"robot file '{spec}': {e}") from e
    except (OSError, MemoryError, KeyboardInterrupt):
        raise
    except Exception as e:  # a loader should raise only ValueError: say which file it was reading
        e.kinedyn_context = f"while loading robot file '{spec}'"  # read by the error handler
        raise


def _builtin(name: str, values: dict[str, float]):
    """A built-in with ``values`` for its numeric keyword parameters (``planar_2r --set l1=2``)."""
    import inspect

    from . import robots

    if not values:
        return robots.get(name)
    params = inspect.signature(robots.CATALOGUE[name]).parameters

    def is_number(
        v: inspect.Parameter,
    ) -> bool:  # a number, or None standing for a computed number (planar_2r's lc1 = l1/2)
        if v.default is None:
            return v.annotation in (inspect.Parameter.empty, "float", "Optional[float]", float)
        return isinstance(v.default, (int, float)) and not isinstance(v.default, bool)

    numeric = [p for p, v in params.items() if is_number(v)]
    unknown = [k for k in values if k not in numeric]
    if unknown:
        raise ValueError(
            f"--set {unknown[0]}: the built-in robot '{name}' has no parameter '{unknown[0]}' (its parameters: {', '.join(numeric)})"
        )
    return robots.get(name, **values)


def set_values() -> dict[str, float]:
    """The running command's ``--set`` values (empty outside :func:`main`)."""
    run = _INVOCATION.get()
    return dict(run.values) if run is not None else {}


def _substitute(robot, values: dict[str, float], spec: str):
    """The file's robot with its symbols replaced by ``values`` (names checked first)."""
    if not values:
        return robot
    known = sorted(str(s) for s in robot.symbols)
    unknown = [k for k in values if k not in known]
    if unknown:
        has = (
            f"its parameters: {', '.join(known)}" if known else "it has no symbolic parameters: every value is a number"
        )
        raise ValueError(f"--set {unknown[0]}: robot '{spec}' has no parameter '{unknown[0]}' ({has})")
    return robot.subs(values)


def _parse_set_value(text: str) -> float:
    """The value of ``--set name=VALUE``: a finite number, written as a number or as arithmetic on
    numbers (``0.5``, ``pi/2``, ``sqrt(2)/2``), read by kinedyn's expression parser (never eval)."""
    from .description.expressions import parse_number

    return parse_number(text)


def _parse_set(text: str):
    """``--set name=value`` as (name, value); argparse reports the error with the flag."""
    name, eq, value = text.partition("=")
    name = name.strip()
    if not eq or not name.isidentifier():
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE (e.g. --set l1=0.5), got '{text}'")
    try:
        return name, _parse_set_value(value.strip())
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"{name}: the value must be a number, got '{value.strip()}' ({e})") from None


def _parse_xacro_arg(text: str):
    """``--xacro-arg name:=value`` as (name, value), as xacro's own command line writes it."""
    name, eq, value = text.partition(":=")
    if not eq or not name.strip() or any(c.isspace() for c in name.strip()):
        raise argparse.ArgumentTypeError(f"expected NAME:=VALUE (e.g. --xacro-arg prefix:=left_), got '{text}'")
    return name.strip(), value


def _set_values(pairs) -> dict[str, float]:
    values: dict[str, float] = {}
    for name, value in pairs or []:
        if name in values:
            raise ValueError(f"--set {name} is given twice")
        values[name] = value
    return values


# ------------------------------------------------------------------ output paths
class OutputPath(argparse.Action):
    """argparse action for an option that names a file to write: :func:`main` checks every such
    path with :func:`check_output_path` before the command starts its work."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)


def check_output_path(path, flag: str = "output") -> Path:
    """``path`` if a file can be written there, else ValueError naming ``flag`` and the reason:
    the name is empty, the path lies in /proc or /sys (the kernel's virtual files), it is a folder,
    its folder is missing or is not a folder, or there is no permission to write it. An existing
    file or device (``/dev/null``, ``/dev/stdout``) needs only write permission."""
    text = os.fspath(path)
    if not text.strip():
        raise ValueError(f"{flag}: the file name is empty")
    where = f"{flag}: cannot write '{text}'"
    full = Path(os.path.abspath(text))  # as written (not through symbolic links: /dev/stdout is a link into /proc)
    for virtual in (Path("/proc"), Path("/sys")):
        if full == virtual or virtual in full.parents:
            raise ValueError(f"{where}: it is in {virtual}, the kernel's virtual files, not a place for output")
    if full.is_dir():
        raise ValueError(f"{where}: it is a folder; give a file name, e.g. '{Path(text) / 'out'}'")
    if full.exists():
        if not os.access(full, os.W_OK):
            raise ValueError(f"{where}: no permission to write the file")
        return Path(text)
    parent = full.parent
    if not parent.exists():
        raise ValueError(f"{where}: the folder '{parent}' does not exist")
    if not parent.is_dir():
        raise ValueError(f"{where}: '{parent}' is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"{where}: no permission to create a file in '{parent}'")
    return Path(text)


def _check_outputs(args) -> None:
    """Every OutputPath option of the command, checked before the work starts; an output that would
    overwrite the robot file it reads is refused too."""
    parser = getattr(args, "_command_parser", None)
    if parser is None:
        return
    robot = getattr(args, "robot", None)
    robot_file = (
        Path(robot).resolve()
        if robot and Path(robot).suffix.lower() in ROBOT_FILE_EXTENSIONS and Path(robot).exists()
        else None
    )
    seen: dict[Path, str] = {}
    for action in parser._actions:
        if not isinstance(action, OutputPath):
            continue
        value = getattr(args, action.dest, None)
        if value is None:
            continue
        flag = "/".join(action.option_strings) or str(action.metavar or action.dest)  # a positional OUT names itself
        path = check_output_path(value, flag).resolve()
        if robot_file is not None and path == robot_file:
            raise ValueError(f"{flag}: '{value}' is the robot file this command reads; write somewhere else")
        if path in seen:
            raise ValueError(f"{flag}: '{value}' is also the file of {seen[path]}; give each output its own file")
        seen[path] = flag


# ------------------------------------------------------------------ argument values
def _number_type(kind, test, what: str):
    """An argparse type: ``kind(text)`` (float or int) that passes ``test``, else the error
    '<what>, got TEXT', which argparse prefixes with the flag."""

    def convert(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{what}, got '{text}'") from None
        if not (math.isfinite(value) and test(value)):
            raise argparse.ArgumentTypeError(f"{what}, got '{text}'")
        return value

    convert.__name__ = what  # argparse's fallback message names the type by this
    return convert


positive_float = _number_type(float, lambda v: v > 0, "must be a positive number")
nonnegative_float = _number_type(float, lambda v: v >= 0, "must be a number >= 0")
finite_float = _number_type(float, lambda v: True, "must be a finite number (not NaN or inf)")
positive_int = _number_type(int, lambda v: v >= 1, "must be a whole number >= 1")
nonnegative_int = _number_type(int, lambda v: v >= 0, "must be a whole number >= 0")


def in_cli_terms(text: str, phrases: dict[str, str] | None) -> str:
    """``text`` (a library message) with the Python argument names in ``phrases`` replaced by the
    command line flags that set them (``respect_limits=False`` -> ``--ignore-limits``)."""
    for python, flag in (phrases or {}).items():
        text = re.sub(rf"(?<![\w-]){re.escape(python)}(?![\w=])", flag, text)
    return text


def parse_q(
    values: Sequence[float] | None, robot, degrees: bool = False, flag: str = "--q", rates: bool | None = None
) -> np.ndarray:
    """Joint values (``--q``, ``--q0``, ``--goal``: a configuration of ``robot.nq`` numbers, the
    neutral one when omitted) or rates, accelerations, torques (the other flags, or ``rates=True``:
    ``robot.nv`` numbers, zeros when omitted); degrees convert revolute joints only. ``flag`` names
    the option in the error message."""
    rates = flag not in ("--q", "--q0", "--goal") if rates is None else rates
    size = robot.nv if rates else robot.nq
    if values is None:
        return np.zeros(size) if rates else robot.neutral()
    q = np.array(values, dtype=float)
    # the 1-DOF joint each number belongs to (None inside a multi-DOF joint's block)
    owners: list = []
    for j in robot.joints:
        k = j.nv if rates else j.nq
        owners.extend([None] * k if j.is_multi_dof else [j])
    if q.shape != (size,):
        what = "rates" if rates else "coordinates"
        extra = (
            f" {what}: nq = {robot.nq} with its multi-DOF joints" if robot.has_multi_dof_joints and not rates else ""
        )
        raise ValueError(
            f"{flag} needs {size} values for robot '{robot.name}' (joints {', '.join(robot.joint_names)}{extra}), got {q.size}"
        )
    bad = np.flatnonzero(~np.isfinite(q))
    if bad.size:
        owner = owners[bad[0]]
        raise ValueError(
            f"{flag}: value {bad[0] + 1} ({owner.name if owner is not None else 'a multi-DOF joint'}) is {q[bad[0]]}, not a finite number"
        )
    if degrees:
        q = np.array([math.radians(v) if j is not None and j.kind == "revolute" else v for v, j in zip(q, owners)])
    return q


def esc(text) -> str:
    """``text`` (a name from a robot file, a path, a library message) safe inside rich markup: a
    ``[`` that would open a tag (``[/bold]``, ``[red]``) is escaped, so the terminal shows it as it
    is. Everything printed with console().print that is not kinedyn's own markup goes through this."""
    from rich.markup import escape

    return escape(str(text))


def console():
    """The console every command prints with: tables keep their numbers whole (kinedyn.terminal)."""
    from .terminal import console as terminal_console

    return terminal_console()


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, np.generic):
        # every NumPy scalar (np.bool_, integers, floats, complex): its Python value, converted in turn
        # (a non-finite float, a complex) -- json knows none of NumPy's scalar types
        return _jsonable(x.item())
    if isinstance(x, complex):
        return [_jsonable(x.real), _jsonable(x.imag)]
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

    table = Table(title=esc(title), title_justify="left")
    table.add_column("")
    for c in cols:
        table.add_column(esc(c), justify="right")
    for name, row in zip(rows, np.atleast_2d(M)):
        table.add_row(esc(name), *(f"{v: .{digits}g}" for v in row))
    return table


def _fmt(v) -> str:
    if isinstance(v, float):
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:.6g}"
    return str(v)


def _robot_arg(p):
    p.add_argument(
        "robot", nargs="?", default=None, help="built-in name or robot file (default: planar_2r, the tutorial's arm)"
    )
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


def _value(v):
    """A parameter for display: a float, or the text of a symbolic expression (``info`` shows a
    robot file with symbols as it is)."""
    try:
        return float(v)
    except TypeError:
        return str(v)


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
                "axis": [_value(a) for a in j.axis],
                "offset": _value(j.offset),
                "lower": j.lower,
                "upper": j.upper,
                "velocity_limit": j.velocity_limit,
                "effort_limit": j.effort_limit,
                "gear_ratio": _value(j.gear_ratio),
                "rotor_inertia": _value(j.rotor_inertia),
                "viscous": _value(j.viscous),
                "coulomb": _value(j.coulomb),
                "coulomb_negative": _value(j.coulomb_levels[1]),  # the level for qd < 0 (= coulomb if symmetric)
            }
        )
    bodies = [
        {
            "link": b.name,
            "mass": _value(b.inertia.mass),
            "com": [_value(c) for c in b.inertia.com],
            "inertia_about_com": [
                [_value(x) for x in row] for row in np.asarray(b.inertia.inertia, dtype=object).tolist()
            ],
        }
        for b in robot.tree.bodies
    ]
    dh = None
    if robot.dh is not None:
        dh = [
            {"theta": _value(r.theta), "d": _value(r.d), "a": _value(r.a), "alpha": _value(r.alpha), "type": r.kind}
            for r in robot.dh
        ]
    payload = {
        "name": robot.name,
        "n": robot.n,
        "source": robot.source,
        "gravity": [_value(g) for g in robot.gravity],
        "tool": robot.tool,
        "frames": robot.frame_names,
        "joints": joints,
        "dh_convention": robot.dh_convention,
        "dh": dh,
        "bodies": bodies,
        "total_mass": _value(sum(b.inertia.mass for b in robot.tree.bodies)),
        "symbols": sorted(str(s) for s in robot.symbols),
    }

    def render():
        from rich.table import Table

        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold]: {robot.n} joints, tool frame '{esc(robot.tool)}', gravity {esc(payload['gravity'])} m/s^2"
        )
        if robot.source:
            c.print(f"source: {esc(robot.source)}")
        t = Table(title="joints", title_justify="left")
        for col in ("#", "joint", "type", "parent -> link", "axis", "offset", "limits", "vel / effort"):
            t.add_column(col)
        for i, j in enumerate(joints, 1):
            unit = "rad" if j["type"] == "revolute" else "m"
            t.add_row(
                str(i),
                esc(j["name"]),
                j["type"],
                esc(f"{j['parent']} -> {j['link']}"),
                esc(" ".join(_fmt(a) for a in j["axis"])),
                esc(_fmt(j["offset"])),
                f"[{_fmt(j['lower'])}, {_fmt(j['upper'])}] {unit}",
                f"{_fmt(j['velocity_limit'])} / {_fmt(j['effort_limit'])}",
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
                    esc(f"q{i} + {_fmt(r['theta'])}" if var == "q" else _fmt(r["theta"])),
                    esc(f"q{i} + {_fmt(r['d'])}" if var == "d" else _fmt(r["d"])),
                    esc(_fmt(r["a"])),
                    f"{_fmt(math.degrees(r['alpha']))} deg"
                    if isinstance(r["alpha"], float)
                    else esc(f"{r['alpha']} rad"),
                    r["type"],
                )
            c.print(t)
        t = Table(title="mass properties (body frames = joint frames)", title_justify="left")
        for col in ("link", "mass [kg]", "centre of mass [m]", "Ixx Iyy Izz about COM [kg m^2]"):
            t.add_column(col)
        for b in bodies:
            I = b["inertia_about_com"]
            t.add_row(
                esc(b["link"]),
                esc(_fmt(b["mass"])),
                esc(" ".join(_fmt(x) for x in b["com"])),
                esc(" ".join(_fmt(I[k][k]) for k in range(3))),
            )
        c.print(t)
        c.print(f"total moving mass: {esc(_fmt(payload['total_mass']))} kg")
        if payload["symbols"]:
            c.print(
                f"symbolic parameters: {', '.join(payload['symbols'])} (numeric commands take their values: --set NAME=VALUE)"
            )

    emit(args, payload, render)
    return 0


def _rpy(R: np.ndarray) -> list:
    """Fixed-axis roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll)."""
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    roll = math.atan2(R[2, 1], R[2, 2])
    yaw = math.atan2(R[1, 0], R[0, 0])
    return [roll, pitch, yaw]


def _symbolic_robot(args):
    """The robot for ``--symbolic``: a built-in with symbolic parameters in its symbolic form (l1, l2,
    ...; other built-ins keep their numbers), a robot file with its symbols; --set values substituted."""
    import inspect

    from . import robots

    name = args.robot or robots.DEFAULT
    factory = robots.CATALOGUE.get(name)
    if factory is not None and "symbolic" in inspect.signature(factory).parameters:
        return _substitute(factory(symbolic=True), set_values(), name)
    return load_robot(name, numeric=False)


def cmd_symbolic_kinematics(args, what: str) -> int:
    """``kinedyn fk|jacobian ROBOT --symbolic``: the pose or the Jacobian as formulas (kinedyn.symbolic)."""
    import sympy as sp

    from . import symbolic as ks

    robot = _symbolic_robot(args)
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


def _symbolic_args(p) -> None:
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


def cmd_fk(args) -> int:
    if args.symbolic:
        return cmd_symbolic_kinematics(args, "fk")
    robot = _robot(args)
    q = parse_q(args.q, robot, args.deg)
    frames = robot.frame_names if args.all else [args.frame or robot.tool]
    poses = robot.frame_poses(q, frames)
    payload = {
        "robot": robot.name,
        "q": q,
        "frames": {f: {"pose": T, "position": T[:3, 3], "rpy": _rpy(T[:3, :3])} for f, T in zip(frames, poses)},
    }

    def render():
        c = console()
        c.print(f"[bold]{esc(robot.name)}[/bold] at q = {np.array2string(q, precision=6)} rad/m")
        for f, T in zip(frames, poses):
            c.print(matrix_table(f"pose of '{f}' in '{robot.base}'", T, ["", "", "", ""], ["", "", "", ""]))
            rpy = _rpy(T[:3, :3])
            c.print(
                f"  position {np.array2string(T[:3, 3], precision=6)} m, rpy {np.array2string(np.degrees(rpy), precision=4)} deg"
            )

    emit(args, payload, render)
    return 0


ROW_NAMES = ["vx", "vy", "vz", "wx", "wy", "wz"]


def spanned_rows(robot, frame=None, reference: str = "world", samples: int = 8, seed: int = 0):
    """The task rows an arm with fewer than six joints can span, for its manipulability: the linear rows
    that move at some configuration, then the angular ones, kept when there are at most n of them and
    they have rank min(rows, n) at a generic configuration; None when no such subset exists (then the
    measure is taken in the Jacobian's column space, sqrt(det J^T J)).

    Rows are tested at ``samples`` seeded random configurations inside the finite joint limits, so
    the choice is deterministic (elbow_3r: vx, vy, vz; planar_2r: vx, vy; a SCARA: vx, vy, vz, wz)."""
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(robot.lower_limits), robot.lower_limits, -np.pi)
    hi = np.where(np.isfinite(robot.upper_limits), robot.upper_limits, np.pi)
    Js = np.array([robot.jacobian(lo + (hi - lo) * rng.random(robot.n), frame, reference) for _ in range(samples)])
    scale = max(1.0, float(np.abs(Js).max(initial=0.0)))
    moving = [r for r in range(6) if np.abs(Js[:, r, :]).max() > 1e-9 * scale]
    linear, angular = [r for r in moving if r < 3], [r for r in moving if r >= 3]
    rows = linear if len(linear) >= robot.n else linear + angular
    if not rows or len(rows) > robot.n:
        return None
    if max(np.linalg.matrix_rank(J[rows], tol=1e-9 * scale) for J in Js) < len(rows):
        return None
    return rows


def _analysis_rows(robot, rows, explicit: bool, frame, reference):
    """(rows, basis) on which ``jacobian`` measures rank and manipulability: the --task rows when given;
    otherwise all six for n >= 6, or the rows an arm with fewer joints spans (``spanned_rows``)."""
    if explicit:
        return rows, "the --task rows" + (
            f"; {len(rows)} rows > {robot.n} joints, so J J^T is singular by construction"
            if len(rows) > robot.n
            else ""
        )
    if len(rows) <= robot.n:
        return rows, "all six rows"
    chosen = spanned_rows(robot, frame, reference)
    if chosen is None:
        return rows, "all six rows; sqrt(det J^T J), the volume in the Jacobian's column space"
    return chosen, f"the rows a {robot.n}-joint arm spans; choose others with --task"


def cmd_jacobian(args) -> int:
    from . import kinematics as kin

    if args.symbolic:
        return cmd_symbolic_kinematics(args, "jacobian")
    robot = _robot(args)
    q = parse_q(args.q, robot, args.deg)
    explicit = args.task is not None
    rows = kin.task_rows(args.task if explicit else "full")
    J = kin.task_jacobian(robot, q, args.frame, rows, args.reference)
    names = [ROW_NAMES[r] for r in rows]
    a_rows, basis = _analysis_rows(robot, rows, explicit, args.frame, args.reference)
    report = kin.singularity_report(robot, q, args.frame, a_rows, args.reference)
    if len(a_rows) > robot.n and a_rows is rows and not explicit:
        w = float(np.prod(report.singular_values))  # sqrt(det J^T J): the column-space volume
    else:
        w = float(kin.manipulability(robot, q, args.frame, a_rows, args.reference))
    w_rows = report.row_names
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
        "manipulability": w,
        "analysis_rows": w_rows,
        "analysis_rows_basis": basis,
        "condition_number": report.condition_number,
        "lost_directions": report.lost_directions,
    }

    def render():
        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold] at q = {np.array2string(q, precision=6)}; frame '{esc(payload['frame'])}', reference '{args.reference}'"
        )
        c.print(matrix_table("Jacobian", J, names, robot.joint_names))
        c.print(f"rank, singular values and manipulability over rows {', '.join(w_rows)} ({basis})")
        c.print(f"singular values: {np.array2string(report.singular_values, precision=6)}")
        c.print(f"manipulability sqrt(det J J^T): {w:.6g}")
        style = "bold red" if report.singular else "green"
        c.print(f"[{style}]{esc(report.summary())}[/{style}]")

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
        c.print(
            f"[bold]{esc(robot.name)}[/bold] at q = {np.array2string(q, precision=6)}, qd = {np.array2string(qd, precision=6)}, qdd = {np.array2string(qdd, precision=6)}"
        )
        c.print(matrix_table("M(q), mass matrix", M, names, names))
        c.print(matrix_table("C(q, qd), Coriolis matrix (Christoffel symbols)", C, names, names))
        c.print(
            matrix_table(
                "g(q), gravity torque and tau = M qdd + C qd + g + friction",
                np.column_stack([g, payload["tau"]]),
                names,
                ["g", "tau"],
            )
        )
        c.print(
            f"kinetic energy {payload['kinetic_energy']:.6g} J, potential energy {payload['potential_energy']:.6g} J"
        )
        if args.tau is not None:
            c.print(
                f"forward dynamics: tau = {np.array2string(payload['applied_tau'], precision=6)} gives qdd = {np.array2string(payload['forward_dynamics_qdd'], precision=6)}"
            )
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
        ("kinedyn.visual.cli", "add_view_command"),
    ]


class _UsageError(Exception):
    """A command line that argparse rejects (raised instead of argparse's print-usage-and-exit)."""

    def __init__(self, prog: str, message: str):
        super().__init__(message)
        self.prog = prog


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``kinedyn fk: error: argument --q: ...``, through main()."""

    def error(self, message):
        raise _UsageError(self.prog, f"{message} (see '{self.prog} --help')")


def _common_options(p: argparse.ArgumentParser, global_: bool = False) -> None:
    """--debug on every command, --set on those that read a robot; given to the main parser too, so
    that ``kinedyn --debug fk ...`` and ``kinedyn fk ... --debug`` both work."""
    default = False if global_ else argparse.SUPPRESS
    p.add_argument("--debug", action="store_true", default=default, help="on an error, show the Python traceback")
    if global_ or any(a.dest == "robot" for a in p._actions):
        p.add_argument(
            "--set",
            dest="set_global" if global_ else "set",
            action="append",
            type=_parse_set,
            default=None if global_ else argparse.SUPPRESS,
            metavar="NAME=VALUE",
            help="give a robot parameter a value (repeatable): a symbol of a robot file, or a keyword of a built-in (e.g. --set l1=0.5)",
        )
    if not global_ and any(a.dest == "robot" for a in p._actions):
        p.add_argument(
            "--xacro-arg",
            dest="xacro_args",
            action="append",
            type=_parse_xacro_arg,
            default=argparse.SUPPRESS,
            metavar="NAME:=VALUE",
            help="an argument of a .xacro robot file (repeatable)",
        )
        p.add_argument(
            "--trust-xacro",
            action="store_true",
            default=argparse.SUPPRESS,
            help="expand a .xacro robot file: xacro runs Python expressions from the file, so only for files you trust",
        )
        p.add_argument(
            "--floating-base",
            action="store_true",
            default=argparse.SUPPRESS,
            help="a URDF's root link moves freely on a free-flyer joint 'root_joint' (q: position, quaternion x y z w, joints)",
        )


def build_parser() -> argparse.ArgumentParser:
    import importlib

    parser = _Parser(prog="kinedyn", description="Robot kinematics and dynamics, symbolic and numeric.")
    parser.add_argument("--version", action="version", version=f"kinedyn {__import__('kinedyn').__version__}")
    _common_options(parser, global_=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

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
    _symbolic_args(p)
    p.set_defaults(func=cmd_fk)

    p = sub.add_parser("jacobian", help="geometric Jacobian at q, its singular values and singularities")
    _robot_arg(p)
    _state_args(p)
    p.add_argument("--frame", help="frame name (default: the tool)")
    p.add_argument("--reference", default="world", choices=["world", "local", "spatial"])
    p.add_argument(
        "--task",
        default=None,
        help="rows: full, position, orientation, planar, planar_pose (default full; the manipulability "
        "of an arm with fewer than six joints then uses the rows it spans, e.g. vx vy vz for elbow_3r)",
    )
    _symbolic_args(p)
    p.set_defaults(func=cmd_jacobian)

    p = sub.add_parser(
        "dynamics", help="M, C, g and tau at a state (Rust core); forward dynamics with --tau; derivatives"
    )
    _robot_arg(p)
    _state_args(p, with_qd=True)
    p.add_argument("--qdd", nargs="+", type=float, metavar="QDD", help="joint accelerations for tau (default zeros)")
    p.add_argument(
        "--tau", nargs="+", type=float, metavar="TAU", help="joint torques/forces: also print the forward dynamics qdd"
    )
    p.add_argument("--derivatives", action="store_true", help="also print dtau/dq and dtau/dqd (analytical)")
    p.set_defaults(func=cmd_dynamics)

    p = sub.add_parser(
        "convert",
        help="write a robot as URDF, MJCF, a robot file or a DH table, and check the result",
        description="Write ROBOT (a built-in or any robot file kinedyn reads) to OUT in the format of OUT's extension "
        "(.urdf, .xml/.mjcf, .yaml/.yml, .toml) or --to; then read OUT back and compare frame poses, M and "
        "inverse dynamics with ROBOT at random states (docs/model-files.md, 'Converting robots').",
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
    p.set_defaults(func=cmd_convert)

    for module, function in _command_modules():
        getattr(importlib.import_module(module), function)(sub)
    for p in sub.choices.values():
        _common_options(p)
        p.set_defaults(_command_parser=p)
    return parser


def cmd_convert(args) -> int:
    from .convert import convert

    robot = load_robot(args.robot)
    if args.inertia is not None:
        robot = robot.replace(inertia=args.inertia)
    if args.lock:
        robot = robot.lock_joints(args.lock)
    if args.states < 1:
        raise ValueError(f"--states must be at least 1, got {args.states}")
    result = convert(
        robot, args.output, args.to, convention=args.convention, check=not args.no_check, states=args.states
    )
    print(result.summary())
    if result.checked and not result.max_error < CONVERT_TOLERANCE:
        print(
            _one_line(
                f"kinedyn convert: error: the written file differs from {args.robot} by {result.max_error:.3g} "
                f"(more than {CONVERT_TOLERANCE:g}); this is a bug in kinedyn's writer, please report it"
            ),
            file=sys.stderr,
        )
        return EXIT_ERROR
    return EXIT_OK


CONVERT_TOLERANCE = 1e-8  # largest difference `kinedyn convert` accepts between a written file and its source


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _message(e: BaseException) -> str:
    """The text of an exception for the user: a KeyError's key message without quotes, an OSError's
    file and reason."""
    if isinstance(e, KeyError) and e.args:
        text = str(e.args[0])
    elif isinstance(e, OSError) and e.strerror:
        text = f"'{e.filename}': {e.strerror}" if e.filename else e.strerror
    else:
        text = str(e)
    return text or type(e).__name__


# exceptions that mean "the input was wrong" (or the environment: a missing file, a missing program);
# anything else reaching main() is a bug in kinedyn. RecursionError is a RuntimeError but always a bug
# (a description nested too deep for a parser that should have bounded it).
_USER_ERRORS = (ValueError, KeyError, OSError, RuntimeError)
_BUGS = (RecursionError,)


def _report(command: str, e: BaseException, debug: bool, phrases: dict[str, str] | None) -> int:
    """Print ``e`` as one line (and its traceback with --debug); return the exit status."""
    import traceback

    if debug:
        traceback.print_exception(type(e), e, e.__traceback__, file=sys.stderr)
    head = f"kinedyn {command}" if command else "kinedyn"
    if isinstance(e, MemoryError):
        detail = _message(e) if str(e) else "the work needs more memory than this machine has"
        print(
            _one_line(
                f"{head}: error: out of memory: {detail} (ask for less: fewer samples or states, a larger step, a shorter time)"
            ),
            file=sys.stderr,
        )
        return EXIT_ERROR
    if isinstance(e, _USER_ERRORS) and not isinstance(e, _BUGS):
        print(_one_line(f"{head}: error: {in_cli_terms(_message(e), phrases)}"), file=sys.stderr)
        return EXIT_ERROR
    context = getattr(e, "kinedyn_context", None)
    print(
        _one_line(
            f"{head}: internal error{' ' + context if context else ''}: {type(e).__name__}: {_message(e)}. "
            f"This is a bug in kinedyn: rerun with --debug to see the traceback, and please report it"
        ),
        file=sys.stderr,
    )
    return EXIT_INTERNAL


def _warning_line(command: str):
    """warnings.showwarning that prints one line per warning: ``kinedyn fk: warning: ...``."""

    def show(message, category, filename, lineno, file=None, line=None):
        print(_one_line(f"kinedyn {command}: warning: {message}"), file=file or sys.stderr)

    return show


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line ``argv`` (default ``sys.argv[1:]``); returns the exit status (see the
    module docstring). Never lets an exception out, but SystemExit from --help and --version."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv[: argv.index("--")] if "--" in argv else "--debug" in argv
    command, phrases = "", None
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except _UsageError as e:
            print(_one_line(f"{e.prog}: error: {e}"), file=sys.stderr)
            return EXIT_ERROR
        if not getattr(args, "func", None):
            parser.print_help()
            return EXIT_OK
        command = args.command
        debug = bool(args.debug)
        phrases = getattr(args, "_flag_phrases", None)
        run = _Invocation(
            command,
            _set_values((args.set_global or []) + (getattr(args, "set", None) or [])),
            command not in SYMBOLIC_COMMANDS,
            dict(getattr(args, "xacro_args", None) or []),
            bool(getattr(args, "trust_xacro", False)),
            bool(getattr(args, "floating_base", False)),
        )
        token = _INVOCATION.set(run)
        try:
            with warnings.catch_warnings():
                if not debug:
                    warnings.showwarning = _warning_line(command)
                _check_outputs(args)
                return int(args.func(args) or 0)
        finally:
            _INVOCATION.reset(token)
    except BrokenPipeError:  # e.g. `kinedyn derive | head`: the reader left, nothing to report
        with contextlib.suppress(
            Exception
        ):  # the interpreter's flush at exit must not fail again (Python docs, signal: SIGPIPE)
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except SystemExit:
        raise
    except BaseException as e:  # noqa: B036 - the boundary: PanicException from the core is a BaseException
        return _report(command, e, debug, phrases)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
