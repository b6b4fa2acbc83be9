"""``kinedyn robots``: the built-in robots, their joint counts and sources."""

from __future__ import annotations

from rich.table import Table

from ... import robots
from ..app import console, emit


def add_arguments(p) -> None:
    p.add_argument("--json", action="store_true")


def run(args) -> int:
    items = {name: (robots.get(name).source or "") for name in robots.names()}

    def render():
        t = Table(title="built-in robots", title_justify="left")
        t.add_column("name")
        t.add_column("n", justify="right")
        t.add_column("source")
        for name in robots.names():
            t.add_row(name, str(robots.get(name).n), items[name])
        console().print(t)

    emit(args, {"robots": items}, render)
    return 0
