"""What a person reads: the self-contained HTML report of a robot (:mod:`kinedyn.report.html`: its numbers
gathered into :class:`ReportData` by :func:`collect`, rendered by Jinja2 templates), the identification
report (:func:`identification_html`), and the worked tutorial (:mod:`kinedyn.tutorial`, importable here as
``kinedyn.report.tutorial``). Command line: ``kinedyn report``, ``kinedyn tutorial``."""

from . import tutorial
from .data import ReportData, collect
from .html import build_report, render_report, write_report
from .identification import identification_html, write_identification_html
from .tutorial import QUESTIONS, answer, work

__all__ = [
    "QUESTIONS",
    "answer",
    "work",
    "tutorial",
    "ReportData",
    "build_report",
    "collect",
    "render_report",
    "write_report",
    "identification_html",
    "write_identification_html",
]
