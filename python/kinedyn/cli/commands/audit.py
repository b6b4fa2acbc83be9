"""``kinedyn audit FILE``: what is wrong with a robot file (docs/audit.md): per link and joint, the
severity, the file and line, the problem and the fix; with ``--compare``, what Pinocchio and MuJoCo
make of the same URDF (:mod:`kinedyn.analysis.loaders`). ``--strict`` exits with status 2 when there
is an error (for pipelines that check robot descriptions); ``--json`` prints the findings as JSON."""

from __future__ import annotations

import os

from rich.table import Table

from ...description.audit import audit
from ..app import console, emit, esc
from ..options import EXIT_NO, EXIT_OK, positive_int

_STYLE = {"error": "bold red", "warning": "yellow", "info": "dim"}


def add_arguments(p) -> None:
    p.add_argument("file", metavar="FILE", help="a robot file: URDF (.urdf) or MJCF (.xml, .mjcf)")
    p.add_argument("--json", action="store_true", help="print one JSON document instead of a table")
    p.add_argument("--strict", action="store_true", help="exit with status 2 when the audit finds an error")
    p.add_argument(
        "--compare",
        action="store_true",
        help="also load the URDF with Pinocchio and MuJoCo and compare M(q), g(q) and the frames (the peers extra)",
    )
    p.add_argument("--samples", type=positive_int, default=4, help="configurations compared with --compare (default 4)")
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
    loaders = None
    if args.compare:
        if not args.file.lower().endswith((".urdf", ".xml", ".mjcf")):
            raise ValueError(f"{args.file}: --compare reads a URDF (.urdf) or MJCF (.xml, .mjcf) file")
        from ...analysis.loaders import compare_loaders  # builds robots and loads the peers: only when asked

        loaders = compare_loaders(args.file, samples=args.samples)

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
        if loaders is not None:
            t = Table(
                title=f"what each tool makes of the file ({loaders.samples} sampled configurations)",
                title_justify="left",
            )
            for col in ("tool", "quantity", "relative difference", "where", "cause"):
                t.add_column(col)
            for r in loaders.rows:
                mark = "[green]agrees[/green]" if r.agrees else f"[yellow]{r.difference:.3g}[/yellow]"
                t.add_row(r.tool, r.quantity, mark, esc(r.where), esc(r.cause))
            for tool, why in loaders.skipped.items():
                t.add_row(tool, "", "[red]not compared[/red]", "", esc(why))
            c.print(t)

    payload = result.to_dict()
    if loaders is not None:
        payload["loaders"] = loaders.to_dict()
    emit(args, payload, render)
    failed = not result.ok or (loaders is not None and (not loaders.agree or bool(loaders.skipped)))
    return EXIT_NO if args.strict and failed else EXIT_OK
