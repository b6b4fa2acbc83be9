"""What a person reads: the worked tutorial (:mod:`kinedyn.report.tutorial`) and the self-contained HTML
report of a robot (:mod:`kinedyn.report.html`). Command line: ``kinedyn tutorial``, ``kinedyn report``."""

from .html import build_report, collect, write_report
from .tutorial import QUESTIONS, answer, work

__all__ = ["QUESTIONS", "answer", "work", "build_report", "collect", "write_report"]
