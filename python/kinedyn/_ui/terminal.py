"""Tables on a terminal that keep every number whole, at any width and when piped.

rich shrinks a table that is wider than the terminal (80 columns when piped) by cutting cells with an
ellipsis, so ``2.44929e-21`` printed as ``2.44929…``, which reads as 2.45. Here every column that
holds only numbers never wraps, every other column folds instead of being cut, and a table still
wider than the terminal is split into several tables of whole columns, each repeating the row labels
(as NumPy prints a wide array in blocks of columns).

:func:`console` is the console every ``kinedyn`` command prints with; :func:`fit_table` is the rule.
"""

from __future__ import annotations

import copy
import re

from rich.cells import cell_len
from rich.console import Console
from rich.measure import Measurement
from rich.table import Table
from rich.text import Text

__all__ = ["console", "fit_table", "NUMBER"]

#: A cell that is one number as kinedyn prints them (``-1.5``, `` 2.44929e-21``, ``inf``, ``nan``,
#: ``3.1 m``, ``28.6°``).
NUMBER = re.compile(
    r"\s*[-+]?(\d+(\.\d*)?|\.\d+)([eE][-+]?\d+)?\s*(°|m|rad|%)?\s*|\s*[-+]?(inf|nan|∞)\s*", re.IGNORECASE
)


def _plain(cell) -> str:
    if isinstance(cell, Text):
        return cell.plain
    if isinstance(cell, str):
        return Text.from_markup(cell).plain
    return ""  # another renderable: not a number


def fit_table(table, width: int, console) -> list:
    """``table`` (a rich Table) as a list of tables no wider than ``width`` columns of ``console``:
    numeric columns (every cell a :data:`NUMBER`) do not wrap, other columns fold rather than cut;
    if the table is still too wide, its columns go into several tables, each keeping the first column
    (the row labels) and titled with the columns it shows."""
    for k, column in enumerate(table.columns):
        cells = [_plain(c) for c in column._cells]
        column.overflow = "fold"
        longest = max((cell_len(c.strip()) for c in cells), default=0)
        if cells and all(NUMBER.fullmatch(c) for c in cells):
            # at least as wide as its longest number (rich would otherwise squeeze it); a long header folds
            column.no_wrap = True
            column.min_width = max(column.min_width or 0, longest)
        elif k == 0:  # the row labels: whole up to 24 characters, folded beyond
            column.min_width = max(column.min_width or 0, min(longest, 24))
    unbounded = console.options.update_width(1 << 16)  # a table's measurement is clamped to the width it is given

    def too_wide(t) -> bool:
        return Measurement.get(console, unbounded, t).minimum > width

    if len(table.columns) < 3 or not too_wide(table):
        return [table]
    key, rest = table.columns[0], table.columns[1:]

    def part(columns):
        t = copy.copy(table)
        t.columns = [copy.copy(c) for c in [key, *columns]]
        return t

    groups: list[list] = [[]]
    for column in rest:
        if groups[-1] and too_wide(part(groups[-1] + [column])):
            groups.append([])
        groups[-1].append(column)
    if len(groups) == 1:
        return [table]
    out, start = [], 1
    title = table.title or ""
    for group in groups:
        t = part(group)
        end = start + len(group) - 1
        which = f"column {start} of {len(rest)}" if start == end else f"columns {start}-{end} of {len(rest)}"
        t.title = f"{title} ({which})" if title else which
        out.append(t)
        start = end + 1
    return out


def console():
    """The console kinedyn's commands print with: no highlighting, long lines not broken, and every
    rich Table printed through :func:`fit_table` at the console's width."""
    return _Console(highlight=False, soft_wrap=True)


class _Console(Console):
    """A rich Console whose tables are printed through :func:`fit_table`."""

    def print(self, *objects, **kwargs):
        parts: list = []
        for obj in objects:
            parts.extend(fit_table(obj, self.width, self) if isinstance(obj, Table) else [obj])
        super().print(*parts, **kwargs)
