"""The ``kinedyn`` command line: ``kinedyn COMMAND ROBOT [options]``.

ROBOT is a built-in name (``kinedyn robots`` lists them) or a robot file (.urdf, .yaml, .toml).
Every command prints readable tables (colour on a terminal) or, with ``--json``, one JSON document.
Each command is a module of :mod:`kinedyn.cli.commands` with ``add_arguments(parser)`` and
``run(args) -> int``, named in :data:`COMMANDS`; a command's module is imported only when that
command runs, so ``kinedyn --help`` does not load the capabilities (docs/architecture.md).

A mistake of the user (a bad robot file, a bad argument, an output path that cannot be written) is
one line on stderr, ``kinedyn COMMAND: error: ...``, and exit status 1; ``--debug`` adds the
traceback. Exit statuses: 0 done; 1 the user's mistake; 2 the command ran and its answer is "no"
(``ik``: no solution, ``check``: a property fails); 70 an internal error (a bug in kinedyn);
130 interrupted (Ctrl-C).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import sys
import traceback
import warnings
from collections.abc import Iterable, Sequence

from .._ui import interrupts
from .._version import __version__
from .options import (
    EXIT_ERROR,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_NO,
    EXIT_OK,
    ROBOT_FILE_EXTENSIONS,
    SYMBOLIC_COMMANDS,
    OutputPath,
    check_output_path,
    check_outputs,
    in_cli_terms,
    one_line,
    parse_set,
    parse_set_value,
    parse_xacro_arg,
    set_values,
)

__all__ = [
    "main",
    "build_parser",
    "COMMANDS",
    "check_output_path",
    "OutputPath",
    "ROBOT_FILE_EXTENSIONS",
    "SYMBOLIC_COMMANDS",
    "EXIT_OK",
    "EXIT_ERROR",
    "EXIT_NO",
    "EXIT_INTERNAL",
    "EXIT_INTERRUPTED",
    "in_cli_terms",
    "parse_set_value",
]

#: command -> (its module in kinedyn.cli.commands, the one line ``kinedyn --help`` shows), in the
#: order of the help
COMMANDS = {
    "robots": ("robots", "list the built-in robots"),
    "info": ("info", "joint table, DH table and mass properties of a robot"),
    "fk": ("fk", "forward kinematics: pose of a frame at q"),
    "jacobian": ("jacobian", "geometric Jacobian at q, its singular values and singularities"),
    "dynamics": ("dynamics", "M, C, g and tau at a state (Rust core); forward dynamics with --tau; derivatives"),
    "convert": ("convert", "write a robot as URDF, MJCF, a robot file or a DH table, and check the result"),
    "ik": ("ik", "inverse kinematics: the joint values that put the tool at a target"),
    "derive": ("derive", "symbolic equations of motion (LaTeX, Markdown, MathML, text, Python, NumPy, C)"),
    "codegen": ("codegen", "the robot's dynamics (RNEA, CRBA, M^-1, ABA, derivatives) as straight-line C or Rust"),
    "simulate": ("simulate", "simulate a robot under a controller (RK4 in the native core by default)"),
    "check": ("check", "properties of the equations of motion, each with its residual (Spong §9.5)"),
    "identify": (
        "identify",
        "identify base inertial parameters and friction from a log (--data) or a simulated Fourier excitation",
    ),
    "tutorial": (
        "tutorial",
        "work the seed tutorial (METR4202 Tutorial 4) with kinedyn, step by step, against its printed answers",
    ),
    "report": (
        "report",
        "one self-contained HTML report of a robot: 3-D view, Jacobian, equations of motion, properties, simulation",
    ),
    "view": ("view", "open a live 3-D view of a robot in the browser (meshes, joint sliders); Ctrl-C stops it"),
    "audit": (
        "audit",
        "what is wrong with a robot file: inertias, masses for their shapes, limits, mimics, names, tree",
    ),
}


class _UsageError(Exception):
    """A command line that argparse rejects (raised instead of argparse's print-usage-and-exit)."""

    def __init__(self, prog: str, message: str):
        super().__init__(message)
        self.prog = prog


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``kinedyn fk: error: argument --q: ...``, through main()."""

    def error(self, message):
        raise _UsageError(self.prog, f"{message} (see '{self.prog} --help')")


class _CommandParser(_Parser):
    """A command's parser, whose arguments its module adds the first time they are needed: when
    the command line names the command, or when :func:`build_parser` is asked for it."""

    command: str = ""
    loaded: bool = False

    def load(self) -> _CommandParser:
        if not self.loaded:
            self.loaded = True
            module = importlib.import_module(f"{__name__}.commands.{COMMANDS[self.command][0]}")
            module.add_arguments(self)
            _common_options(self)
            if self.get_default("func") is None:  # a test may have put its own function here
                self.set_defaults(func=module.run)
            self.set_defaults(_command_parser=self)
        return self

    def parse_known_args(self, args=None, namespace=None):
        self.load()
        return super().parse_known_args(args, namespace)


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
            type=parse_set,
            default=None if global_ else argparse.SUPPRESS,
            metavar="NAME=VALUE",
            help="give a robot parameter a value (repeatable): a symbol of a robot file, or a keyword of a built-in (e.g. --set l1=0.5)",
        )
    if not global_ and any(a.dest == "robot" for a in p._actions):
        p.add_argument(
            "--xacro-arg",
            dest="xacro_args",
            action="append",
            type=parse_xacro_arg,
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


def build_parser(load: Iterable[str] | None = None) -> argparse.ArgumentParser:
    """The ``kinedyn`` parser. ``load``: the commands whose arguments are added now (None: every
    command, for tools and tests that read the whole parser); the others add theirs when the
    command line names them, which keeps ``kinedyn --help`` from importing every capability."""
    parser = _Parser(prog="kinedyn", description="Robot kinematics and dynamics, symbolic and numeric.")
    parser.add_argument("--version", action="version", version=f"kinedyn {__version__}")
    _common_options(parser, global_=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_CommandParser)
    for command, (_, summary) in COMMANDS.items():
        p = sub.add_parser(command, help=summary)
        p.command = command
    for command in COMMANDS if load is None else load:
        sub.choices[command].load()
    return parser


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
    if debug:
        traceback.print_exception(type(e), e, e.__traceback__, file=sys.stderr)
    head = f"kinedyn {command}" if command else "kinedyn"
    if isinstance(e, MemoryError):
        detail = _message(e) if str(e) else "the work needs more memory than this machine has"
        print(
            one_line(
                f"{head}: error: out of memory: {detail} (ask for less: fewer samples or states, a larger step, a shorter time)"
            ),
            file=sys.stderr,
        )
        return EXIT_ERROR
    if isinstance(e, _USER_ERRORS) and not isinstance(e, _BUGS):
        print(one_line(f"{head}: error: {in_cli_terms(_message(e), phrases)}"), file=sys.stderr)
        return EXIT_ERROR
    context = getattr(e, "kinedyn_context", None)
    print(
        one_line(
            f"{head}: internal error{' ' + context if context else ''}: {type(e).__name__}: {_message(e)}. "
            f"This is a bug in kinedyn: rerun with --debug to see the traceback, and please report it"
        ),
        file=sys.stderr,
    )
    return EXIT_INTERNAL


def _warning_line(command: str):
    """warnings.showwarning that prints one line per warning: ``kinedyn fk: warning: ...``."""

    def show(message, category, filename, lineno, file=None, line=None):
        print(one_line(f"kinedyn {command}: warning: {message}"), file=file or sys.stderr)

    return show


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line ``argv`` (default ``sys.argv[1:]``); returns the exit status (see the
    module docstring). Never lets an exception out, but SystemExit from --help and --version."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv[: argv.index("--")] if "--" in argv else "--debug" in argv
    command, phrases = "", None
    try:
        with interrupts.sticky():  # Ctrl-C stops the command even where a library swallows it
            parser = build_parser(load=())
            try:
                args = parser.parse_args(argv)
            except _UsageError as e:
                print(one_line(f"{e.prog}: error: {e}"), file=sys.stderr)
                return EXIT_ERROR
            if not getattr(args, "func", None):
                parser.print_help()
                return EXIT_OK
            command = args.command
            debug = bool(args.debug)
            phrases = getattr(args, "_flag_phrases", None)
            # a --set given twice is refused before the work starts, as an unwritable output is
            set_values((getattr(args, "set_global", None) or []) + (getattr(args, "set", None) or []))
            with warnings.catch_warnings():
                if not debug:
                    warnings.showwarning = _warning_line(command)
                check_outputs(args)
                return int(args.func(args) or 0)
    except BrokenPipeError:  # e.g. `kinedyn derive | head`: the reader left, nothing to report
        # the interpreter's flush at exit must not fail again (Python docs, signal: SIGPIPE)
        with contextlib.suppress(Exception):
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
