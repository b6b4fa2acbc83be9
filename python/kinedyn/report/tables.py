"""The report pages' numbers and tables as HTML (the robot report's templates and the identification
page call them): numbers to 6 significant digits, tables in a box that scrolls."""

from __future__ import annotations

import html
import math
from collections.abc import Sequence

import numpy as np
from markupsafe import Markup

__all__ = ["fmt", "table", "matrix_table"]


def fmt(v, digits: int = 6) -> str:
    """A number as the report writes it: ``digits`` significant digits, ±∞, and 0 for |v| < 1e-13
    (round-off of an exact zero)."""
    v = float(v)
    if math.isinf(v):
        return "∞" if v > 0 else "-∞"
    if abs(v) < 1e-13:
        v = 0.0
    return f"{v:.{digits}g}"


def table(headers: Sequence[str], rows: Sequence[Sequence], numeric_from: int = 1, cls: str = "") -> str:
    """A table as HTML text: every cell escaped unless it is :class:`markupsafe.Markup`; the cells from column
    ``numeric_from`` on are numbers (right-aligned, class ``num``)."""
    h = "".join(f"<th>{html.escape(str(c))}</th>" for c in headers)
    body = []
    for r in rows:
        cells = []
        for k, c in enumerate(r):
            css = ' class="num"' if k >= numeric_from else ""
            cells.append(f"<td{css}>{c if isinstance(c, Markup) else html.escape(str(c))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    # a box that scrolls when the table is wider than its card (a 44-joint Jacobian), and taller than
    # about a screen for a long one (the Talos joint table); its first column and header stay in view
    tall = " tall" if len(rows) > 16 else ""
    return f'<div class="table-box{tall}"><table class="{cls}"><thead><tr>{h}</tr></thead><tbody>{"".join(body)}</tbody></table></div>'


def matrix_table(M, rows: Sequence[str], cols: Sequence[str], cls: str) -> str:
    """A matrix with its rows and columns named; with no names (the tool pose), the bare numbers."""
    values = np.atleast_2d(M)
    if not any(rows) and not any(cols):  # a bare matrix: no label column or header row to take room
        body = "".join("<tr>" + "".join(f'<td class="num">{fmt(v)}</td>' for v in row) + "</tr>" for row in values)
        return f'<div class="table-box"><table class="{cls} bare"><tbody>{body}</tbody></table></div>'
    return table(["", *cols], [[r, *(fmt(v) for v in row)] for r, row in zip(rows, values)], cls=cls)
