"""Line plots as inline SVG (the report's plots, a trajectory's notebook display): no plotting library,
the page stays self-contained."""

from __future__ import annotations

import html
import math
from collections.abc import Sequence

import numpy as np

__all__ = ["svg_plot"]

_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"]


def _ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    if hi - lo <= 0:
        return [lo]
    raw = (hi - lo) / n
    mag = 10 ** math.floor(math.log10(raw))
    step = min((m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw), default=raw)
    start = math.ceil(lo / step) * step
    return [start + k * step for k in range(int((hi - start) / step + 1e-9) + 1)]


_DASHES = ["", "6 3", "2 2", "8 3 2 3"]  # after the colours run out: the same colours dashed


def _legend_rows(labels: Sequence[str], width: float, left: float, right: float) -> list[list[tuple]]:
    """Legend entries laid out in rows that fit between ``left`` and ``width - right``: each entry is
    (x, label), 26 px of line sample and gap plus ~6.6 px per character of 11-px text, 14 px apart."""
    rows: list[list[tuple]] = [[]]
    x = left + 4
    for label in labels:
        w = 26 + 6.6 * len(label)
        if rows[-1] and x + w > width - right:
            rows.append([])
            x = left + 4
        rows[-1].append((x, label))
        x += w + 14
    return rows


def svg_plot(
    x, series: Sequence[tuple], title: str, xlabel: str, ylabel: str, width: int = 520, height: int = 270
) -> str:
    """A line plot as inline SVG: ``series`` = [(label, y), ...]. The legend names every series, in as
    many rows as it needs (the plot grows taller to keep its area); colours repeat dashed after seven."""
    x = np.asarray(x, dtype=float)
    ys = [np.asarray(y, dtype=float) for _, y in series]
    # no series (a robot with no moving joint has no coordinate to plot): an empty plot on [-1, 1]
    ylo = min((float(np.min(y)) for y in ys), default=0.0)
    yhi = max((float(np.max(y)) for y in ys), default=0.0)
    if yhi - ylo < 1e-9 * max(1.0, abs(yhi)):
        ylo, yhi = ylo - 1.0, yhi + 1.0
    pad = 0.06 * (yhi - ylo)
    ylo, yhi = ylo - pad, yhi + pad
    L, R, B = 62, 14, 44
    legend = _legend_rows([str(label) for label, _ in series], width, L, R)
    Tp = 32 + 14 * len(legend)
    height += Tp - 46
    W, H = width - L - R, height - Tp - B
    px = lambda v: L + W * (v - x[0]) / (x[-1] - x[0] if x[-1] > x[0] else 1.0)
    py = lambda v: Tp + H * (1 - (v - ylo) / (yhi - ylo))
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" role="img" aria-label="{html.escape(title)}">',
        f'<text x="{width / 2}" y="18" text-anchor="middle" font-size="13" font-weight="600" fill="#243238">{html.escape(title)}</text>',
    ]
    for v in _ticks(ylo, yhi):
        out.append(f'<line x1="{L}" x2="{L + W}" y1="{py(v):.1f}" y2="{py(v):.1f}" stroke="#eceee9"/>')
        out.append(
            f'<text x="{L - 6}" y="{py(v) + 4:.1f}" text-anchor="end" font-size="11" fill="#5f6b73">{v:.4g}</text>'
        )
    for v in _ticks(float(x[0]), float(x[-1])):
        out.append(f'<line y1="{Tp}" y2="{Tp + H}" x1="{px(v):.1f}" x2="{px(v):.1f}" stroke="#f1f2ee"/>')
        out.append(
            f'<text y="{Tp + H + 16}" x="{px(v):.1f}" text-anchor="middle" font-size="11" fill="#5f6b73">{v:.4g}</text>'
        )
    out.append(f'<rect x="{L}" y="{Tp}" width="{W}" height="{H}" fill="none" stroke="#9aa5aa"/>')
    places = [(32 + 14 * r, x0) for r, row in enumerate(legend) for x0, _ in row]
    for k, ((label, _), y, (ly, lx)) in enumerate(zip(series, ys, places)):
        pts = " ".join(f"{px(a):.1f},{py(b):.1f}" for a, b in zip(x, y))
        c = _COLOURS[k % len(_COLOURS)]
        dash = _DASHES[(k // len(_COLOURS)) % len(_DASHES)]
        dash_attr = f' stroke-dasharray="{dash}"' if dash else ""
        out.append(f'<polyline points="{pts}" fill="none" stroke="{c}" stroke-width="1.8"{dash_attr}/>')
        out.append(
            f'<line x1="{lx:.1f}" x2="{lx + 18:.1f}" y1="{ly - 4}" y2="{ly - 4}" stroke="{c}" stroke-width="2.5"{dash_attr}/>'
            f'<text x="{lx + 22:.1f}" y="{ly}" font-size="11" fill="#243238">{html.escape(label)}</text>'
        )
    out.append(
        f'<text x="{L + W / 2}" y="{height - 8}" text-anchor="middle" font-size="12" fill="#36454c">{html.escape(xlabel)}</text>'
    )
    out.append(
        f'<text transform="translate(14 {Tp + H / 2}) rotate(-90)" text-anchor="middle" font-size="12" fill="#36454c">{html.escape(ylabel)}</text>'
    )
    out.append("</svg>")
    return "".join(out)
