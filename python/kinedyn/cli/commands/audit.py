"""``kinedyn audit FILE``: what is wrong with a robot file (docs/audit.md): per link and joint, the
severity, the file and line, the problem and the fix. ``--strict`` exits with status 2 when there
is an error (for pipelines that check robot descriptions); ``--json`` prints the findings as JSON."""

from __future__ import annotations

import os

from rich.table import Table

from ...description.audit import audit
from ..app import console, emit, esc
from ..options import EXIT_NO, EXIT_OK

_STYLE = {"error": "bold red", "warning": "yellow", "info": "dim"}


def add_arguments(p) -> None:
    p.add_argument("file", metavar="FILE", help="a robot file: URDF (.urdf) or MJCF (.xml, .mjcf)")
    p.add_argument("--json", action="store_true", help="print one JSON document instead of a table")
    p.add_argument("--strict", action="store_true", help="exit with status 2 when the audit finds an error")
    p.add_argument(
        "--no-geometry",
        dest="geometry",
        action="store_false",
        help="skip the checks against the links' shapes (no mesh is read)",
    )


def run(args) -> int:
    if not os.path.isfile(args.file):
        raise ValueError(f"{args.file}: no such robot file")
    result = audit(args.file, geometry=args.geometry)

    def render():
        c = console()
        counts = result.counts()
        t = Table(
            title=f"audit of {esc(result.source)}: {counts['error']} errors, {counts['warning']} warnings, {counts['info']} notes",
            title_justify="left",
        )
        for col in ("severity", "where", "element", "finding", "fix"):
            t.add_column(col)
        for f in result.findings:
            where = f.where if f.file != result.source else (f"line {f.line}" if f.line else "")
            style = _STYLE[f.severity]
            t.add_row(f"[{style}]{f.severity}[/{style}]", esc(where), esc(f.element), esc(f.message), esc(f.fix))
        c.print(t)
        if not result.findings:
            c.print("no findings")

    emit(args, result.to_dict(), render)
    return EXIT_NO if args.strict and not result.ok else EXIT_OK
