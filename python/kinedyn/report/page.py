"""The Jinja2 environment of the report's pages (templates/*.html.j2): autoescaped, so every name
from a robot file or a log is text, never markup; the numbers' format (``fmt``) and the tables
(:mod:`kinedyn.report.tables`) are at hand in every template."""

from __future__ import annotations

from importlib import resources

from jinja2 import Environment, PackageLoader, select_autoescape
from markupsafe import Markup

from .tables import fmt, matrix_table, table

__all__ = ["TEMPLATES", "report_asset"]

#: the templates of the report's pages (report/templates/*.html.j2), escaping every value put in them
TEMPLATES = Environment(
    loader=PackageLoader("kinedyn.report", "templates"),
    autoescape=select_autoescape(["html", "j2"], default_for_string=True),
    trim_blocks=True,
    lstrip_blocks=True,
    keep_trailing_newline=True,
)
TEMPLATES.filters["fmt"] = fmt
# the tables are HTML text (callers outside a template use them too); in a template they are markup
TEMPLATES.globals.update(
    table=lambda *args, **kwargs: Markup(table(*args, **kwargs)),
    matrix_table=lambda *args, **kwargs: Markup(matrix_table(*args, **kwargs)),
)


def report_asset(name: str) -> str:
    """A file of the report's own assets (report/assets/), as text to inline in a page."""
    return resources.files("kinedyn.report").joinpath("assets").joinpath(name).read_text(encoding="utf-8")
