"""The command line's argument values and output paths, light enough for ``kinedyn --help``: the
exit statuses, ``--set`` and ``--xacro-arg`` values, number types, output-path checks and the
options several commands share. Loading robots and printing are in :mod:`kinedyn.cli.app`."""

from __future__ import annotations

import argparse
import math
import os
import re
from pathlib import Path

from .._ui.files import same_file
from ..expressions import parse_number

EXIT_OK = 0
EXIT_ERROR = 1  # the user's mistake: bad argument, bad robot file, unwritable output
EXIT_NO = 2  # the command ran and its answer is "no": ik found no solution, check found a failing property
EXIT_INTERNAL = 70  # a bug in kinedyn (BSD sysexits' EX_SOFTWARE)
EXIT_INTERRUPTED = 130  # Ctrl-C (128 + SIGINT, as shells report it)

# The robot file extensions kinedyn.load reads (kinedyn.description.files.load dispatches on these).
ROBOT_FILE_EXTENSIONS = (".urdf", ".yaml", ".yml", ".toml", ".xml", ".xacro")

# commands that show a robot with symbolic parameters as it is (the others need numbers)
SYMBOLIC_COMMANDS = {"derive", "info"}


# ------------------------------------------------------------------ --set and --xacro-arg
def parse_set_value(text: str) -> float:
    """The value of ``--set name=VALUE``: a finite number, written as a number or as arithmetic on
    numbers (``0.5``, ``pi/2``, ``sqrt(2)/2``), read by kinedyn's expression parser (never eval)."""
    return parse_number(text)


def parse_set(text: str):
    """``--set name=value`` as (name, value); argparse reports the error with the flag."""
    name, eq, value = text.partition("=")
    name = name.strip()
    if not eq or not name.isidentifier():
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE (e.g. --set l1=0.5), got '{text}'")
    try:
        return name, parse_set_value(value.strip())
    except ValueError as e:
        raise argparse.ArgumentTypeError(f"{name}: the value must be a number, got '{value.strip()}' ({e})") from None


def parse_xacro_arg(text: str):
    """``--xacro-arg name:=value`` as (name, value), as xacro's own command line writes it."""
    name, eq, value = text.partition(":=")
    if not eq or not name.strip() or any(c.isspace() for c in name.strip()):
        raise argparse.ArgumentTypeError(f"expected NAME:=VALUE (e.g. --xacro-arg prefix:=left_), got '{text}'")
    return name.strip(), value


def set_values(pairs) -> dict[str, float]:
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


class InputPath(argparse.Action):
    """argparse action for an option that names a file the command reads (a log): no output of the
    command may be that file (:func:`check_outputs`)."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)


def _flag(action) -> str:
    return "/".join(action.option_strings) or str(action.metavar or action.dest)  # a positional names itself


def check_outputs(args) -> None:
    """Every OutputPath option of the command, checked before the work starts. An output that is a
    file the command reads (the robot file, an InputPath option's file) is refused, and so are two
    outputs that are one file: files are compared by device and inode, so a hard link or a symbolic
    link to the robot file is the robot file (kinedyn._ui.files.same_file)."""
    parser = getattr(args, "_command_parser", None)
    if parser is None:
        return
    inputs: list[tuple[str, str]] = []
    robot = getattr(args, "robot", None)
    if isinstance(robot, str) and robot and os.path.exists(robot):
        inputs.append((robot, "the robot file this command reads"))
    for action in parser._actions:
        value = getattr(args, action.dest, None)
        if isinstance(action, InputPath) and isinstance(value, str) and value:
            inputs.append((value, f"the file {_flag(action)} reads"))
    seen: list[tuple[Path, str]] = []
    for action in parser._actions:
        if not isinstance(action, OutputPath):
            continue
        value = getattr(args, action.dest, None)
        if value is None:
            continue
        flag = _flag(action)
        path = check_output_path(value, flag)
        for source, what in inputs:
            if Path(os.path.abspath(value)) == Path(os.path.abspath(source)) or same_file(value, source):
                raise ValueError(f"{flag}: '{value}' is {what} ('{source}'); write somewhere else")
        for other, other_flag in seen:
            if path.resolve() == other.resolve() or same_file(path, other):
                raise ValueError(f"{flag}: '{value}' is also the file of {other_flag}; give each output its own file")
        seen.append((path, flag))


# ------------------------------------------------------------------ argument values
def number_type(kind, test, what: str):
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


positive_float = number_type(float, lambda v: v > 0, "must be a positive number")
nonnegative_float = number_type(float, lambda v: v >= 0, "must be a number >= 0")
finite_float = number_type(float, lambda v: True, "must be a finite number (not NaN or inf)")
positive_int = number_type(int, lambda v: v >= 1, "must be a whole number >= 1")
nonnegative_int = number_type(int, lambda v: v >= 0, "must be a whole number >= 0")


def in_cli_terms(text: str, phrases: dict[str, str] | None) -> str:
    """``text`` (a library message) with the Python argument names in ``phrases`` replaced by the
    command line flags that set them (``respect_limits=False`` -> ``--ignore-limits``)."""
    for python, flag in (phrases or {}).items():
        text = re.sub(rf"(?<![\w-]){re.escape(python)}(?![\w=])", flag, text)
    return text


def one_line(text: str) -> str:
    """``text`` with its line breaks and runs of spaces made single spaces: one line on stderr."""
    return " ".join(str(text).split())


# ------------------------------------------------------------------ shared options
def robot_argument(p: argparse.ArgumentParser) -> None:
    """The optional ROBOT positional and --json."""
    p.add_argument(
        "robot", nargs="?", default=None, help="built-in name or robot file (default: planar_2r, the tutorial's arm)"
    )
    p.add_argument("--json", action="store_true", help="print one JSON document instead of tables")


def state_arguments(p: argparse.ArgumentParser, with_qd: bool = False) -> None:
    """--q (and --qd) and --deg."""
    p.add_argument("--q", nargs="+", type=float, metavar="Q", help="joint values (default zeros)")
    if with_qd:
        p.add_argument("--qd", nargs="+", type=float, metavar="QD", help="joint velocities (default zeros)")
    p.add_argument("--deg", action="store_true", help="revolute joint values are in degrees")
