"""What every ``kinedyn`` command shares: loading the robot (a built-in name or a robot file, with
``--set`` values, xacro arguments and a floating base, all passed explicitly as :class:`RobotOptions`
built from the parsed command line), reading joint values, and printing tables or JSON
(docs/architecture.md, "Add a CLI command"). Argument values and output paths are in
:mod:`kinedyn.cli.options`, which ``kinedyn --help`` loads without this module."""

from __future__ import annotations

import argparse
import inspect
import json
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from rich.markup import escape
from rich.table import Table

from .. import robots
from .._ui import terminal
from .._ui.json import jsonable
from .._ui.names import did_you_mean
from ..coordinates import coordinate_labels, coordinate_units, velocity_labels
from .options import ROBOT_FILE_EXTENSIONS, SYMBOLIC_COMMANDS, set_values


# ------------------------------------------------------------------ the robot
@dataclass(frozen=True)
class RobotOptions:
    """How a command loads its robot, beyond the robot's name: the ``--set`` values, whether the
    command needs a numeric robot (every command but ``derive`` and ``info``), and the robot-file
    options ``--xacro-arg``, ``--trust-xacro`` and ``--floating-base``. ``command`` names the
    command in messages (empty outside the command line)."""

    command: str = ""
    values: dict[str, float] = field(default_factory=dict)
    numeric: bool = False
    xacro_args: dict[str, str] = field(default_factory=dict)  # --xacro-arg NAME:=VALUE
    trust_xacro: bool = False  # --trust-xacro: expanding xacro runs the file's Python expressions
    floating_base: bool = False  # --floating-base: a URDF's root link on a free-flyer

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> RobotOptions:
        """The options a parsed command line gives (global and per-command ``--set`` together)."""
        command = getattr(args, "command", None) or ""
        return cls(
            command,
            set_values((getattr(args, "set_global", None) or []) + (getattr(args, "set", None) or [])),
            bool(command) and command not in SYMBOLIC_COMMANDS,
            dict(getattr(args, "xacro_args", None) or []),
            bool(getattr(args, "trust_xacro", False)),
            bool(getattr(args, "floating_base", False)),
        )


def load_robot(spec: str, options: RobotOptions | None = None, *, numeric: bool | None = None):
    """A built-in robot by name, or a robot file by path, with ``options.values`` substituted
    (``--set name=value``: a built-in's keyword parameters, or a robot file's symbols). ``numeric``
    (default ``options.numeric``): refuse a robot that still has symbolic parameters, naming them and
    the ``--set`` that gives them."""
    options = options if options is not None else RobotOptions()
    numeric = options.numeric if numeric is None else numeric
    if spec in robots.CATALOGUE:
        if options.floating_base:
            raise ValueError(
                f"--floating-base applies to URDF (and xacro) files; '{spec}' is a built-in robot with a fixed base"
            )
        robot = builtin_robot(spec, options.values)
    else:
        robot = substitute(robot_file(spec, options), options.values, spec)
    if numeric and robot.is_symbolic:
        missing = sorted(str(s) for s in robot.symbols)
        needs = f"'kinedyn {options.command}'" if options.command else "this computation"
        raise ValueError(
            f"robot '{robot.name}' ({spec}) has parameters without values: {', '.join(missing)}; {needs} needs numbers: "
            f"add {' '.join(f'--set {m}=...' for m in missing)}"
        )
    return robot


def robot(args: argparse.Namespace):
    """The command's robot: its ROBOT argument (default: planar_2r, the tutorial's arm), loaded with
    the options of its command line."""
    return load_robot(args.robot or robots.DEFAULT, RobotOptions.from_args(args))


def symbolic_builtin(name: str):
    """The factory of a built-in robot that has a symbolic form (``factory(symbolic=True)``), else None."""
    factory = robots.CATALOGUE.get(name)
    return factory if factory is not None and "symbolic" in inspect.signature(factory).parameters else None


def robot_file(spec: str, options: RobotOptions):
    """The robot of a robot file, loaded with ``options``' xacro arguments and floating base; every
    error names the file."""
    path = Path(spec)
    ext = path.suffix.lower()
    if ext not in ROBOT_FILE_EXTENSIONS:
        why = f"robot files end in {', '.join(ROBOT_FILE_EXTENSIONS)}" + (f", not '{ext}'" if ext else "")
        raise ValueError(
            f"'{spec}' is neither a built-in robot ({', '.join(robots.names())}) nor a robot file ({why}){did_you_mean(spec, robots.names())}"
        )
    if not path.exists():
        raise ValueError(f"robot file '{spec}' does not exist")
    if path.is_dir():
        raise ValueError(f"robot file '{spec}' is a folder")
    loader_options: dict[str, Any] = {}
    if ext == ".xacro":
        loader_options = {"xacro_args": dict(options.xacro_args), "trust_xacro": options.trust_xacro}
    if options.floating_base:
        if ext not in (".urdf", ".xacro"):
            raise ValueError(
                f"--floating-base applies to URDF (and xacro) files, not '{spec}' (a robot file or MJCF says its own joints)"
            )
        loader_options["floating_base"] = True
    try:
        try:
            from .. import robot_files  # the file readers load only for a robot file

            return robot_files.load(path, **loader_options)
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
        e.kinedyn_context = f"while loading robot file '{spec}'"  # type: ignore[attr-defined]  # read by the error handler
        raise


def builtin_robot(name: str, values: dict[str, float]):
    """A built-in with ``values`` for its numeric keyword parameters (``planar_2r --set l1=2``)."""
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
            f"--set {unknown[0]}: the built-in robot '{name}' has no parameter '{unknown[0]}'{did_you_mean(unknown[0], numeric)} (its parameters: {', '.join(numeric)})"
        )
    return robots.get(name, **values)


def substitute(robot, values: dict[str, float], spec: str):
    """The file's robot with its symbols replaced by ``values`` (names checked first)."""
    if not values:
        return robot
    known = sorted(str(s) for s in robot.symbols)
    unknown = [k for k in values if k not in known]
    if unknown:
        has = (
            f"its parameters: {', '.join(known)}" if known else "it has no symbolic parameters: every value is a number"
        )
        raise ValueError(
            f"--set {unknown[0]}: robot '{spec}' has no parameter '{unknown[0]}'{did_you_mean(unknown[0], known)} ({has})"
        )
    return robot.subs(values)


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
    elif not rates:
        warn_degrees(flag, [(f"value {k + 1} ({j.name})", v, j) for k, (v, j) in enumerate(zip(q, owners)) if j])
    return q


def looks_like_degrees(value: float, joint=None) -> bool:
    """An angle in radians that is more likely degrees: beyond 2 pi, or (a revolute joint with finite
    limits) further outside its limits than their span (90 where the limits are [-2.9, 2.9])."""
    if abs(value) > 2 * math.pi:
        return True
    if joint is None or not (math.isfinite(joint.lower) and math.isfinite(joint.upper)):
        return False
    span = max(joint.upper - joint.lower, 1e-9)
    return value < joint.lower - span or value > joint.upper + span


def warn_degrees(flag: str, entries) -> None:
    """Warn (one line on stderr, kinedyn.cli's warning format) when revolute angles given in radians
    look like degrees; ``entries``: (what, value, joint or None) with the joint None for an angle
    that is not a joint's (``--rpy``)."""
    slips = [(what, v, j) for what, v, j in entries if (j is None or j.kind == "revolute") and looks_like_degrees(v, j)]
    if not slips:
        return
    what, v, j = slips[0]
    limits = (
        f", outside its limits [{j.lower:.4g}, {j.upper:.4g}] rad" if j is not None and math.isfinite(j.lower) else ""
    )
    more = f" (and {len(slips) - 1} more)" if len(slips) > 1 else ""
    warnings.warn(
        f"{flag} {what} is {v:g} rad = {math.degrees(v):.4g} deg{limits}{more}: angles are radians unless you add --deg; "
        "did you mean degrees?",
        UserWarning,
        stacklevel=3,
    )


# ------------------------------------------------------------------ labels of q and qd
def dof_labels(robot) -> list[str]:
    """One label per degree of freedom (nv): rows of M, C, g, tau, columns of a Jacobian; a
    free-flyer's six are ``root.vx`` ... ``root.ωz`` (kinedyn.coordinates, the report's names)."""
    return velocity_labels(robot)


def q_labels(robot) -> list[str]:
    """One label per entry of q (nq): a free-flyer's seven are ``root.x`` ... ``root.qw``."""
    return coordinate_labels(robot)


def q_units(robot, degrees: bool = False) -> str:
    """The units of a configuration's entries in words: "rad", "m", "rad/m", or for a robot with
    multi-DOF joints what each kind of entry is (a quaternion's entries have no unit)."""
    units = set(coordinate_units(robot))
    angle = "deg" if degrees else "rad"
    plain = "/".join(angle if u == "rad" else u for u in ("rad", "m") if u in units) or angle
    if "" not in units:
        return plain
    kinds = {j.kind for j in robot.joints}
    parts = [f"{plain} but"]
    if kinds & {"floating", "spherical"}:
        parts.append("quaternions (qx qy qz qw) unitless")
    if "planar" in kinds:
        parts.append("(cos θ, sin θ) unitless")
    return parts[0] + " " + ", ".join(parts[1:])


def q_text(robot, q, degrees: bool = False, precision: int = 6) -> str:
    """``q`` for a one-line header, with its units (``[0.1 0.2] rad``)."""
    return f"{np.array2string(np.asarray(q), precision=precision)} ({q_units(robot, degrees)})"


def esc(text) -> str:
    """``text`` (a name from a robot file, a path, a library message) safe inside rich markup: a
    ``[`` that would open a tag (``[/bold]``, ``[red]``) is escaped, so the terminal shows it as it
    is. Everything printed with console().print that is not kinedyn's own markup goes through this."""
    return escape(str(text))


def console():
    """The console every command prints with: tables keep their numbers whole (kinedyn._ui.terminal)."""
    return terminal.console()


def emit(args, payload: dict, render: Callable[[], None]) -> None:
    """Print ``payload`` as JSON with --json, else call ``render`` for the human view."""
    if getattr(args, "json", False):
        print(json.dumps(jsonable(payload), indent=2))
    else:
        render()


def matrix_table(title: str, M: np.ndarray, rows: Sequence[str], cols: Sequence[str], digits: int = 6):
    table = Table(title=esc(title), title_justify="left")
    table.add_column("")
    for c in cols:
        table.add_column(esc(c), justify="right")
    for name, row in zip(rows, np.atleast_2d(M)):
        table.add_row(esc(name), *(f"{v + 0.0: .{digits}g}" for v in row))  # + 0.0: no "-0"
    return table


def fixed(values, digits: int = 4) -> str:
    """Numbers in fixed notation with ``digits`` decimals, rounding-level values shown as 0
    (``[180.0000 0.0000 1.3071]``, never ``-9.0101e-15`` or ``-0.0000``)."""
    out = []
    for v in np.atleast_1d(np.asarray(values, dtype=float)):
        r = round(float(v), digits)
        out.append(f"{(0.0 if r == 0 else r):.{digits}f}")
    return "[" + " ".join(out) + "]"


def fmt(v) -> str:
    if isinstance(v, float):
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:.6g}"
    return str(v)
