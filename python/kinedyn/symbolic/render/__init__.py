"""Rendering: names of the quantities in three notations and the MathML of equations
(:mod:`.mathml`), LaTeX that fits the page (:mod:`.latex`), Markdown and plain text (:mod:`.text`).

``kinedyn.symbolic.render`` names the MathML module's public names, as it always has."""

from .mathml import (
    MATHML_NS,
    Name,
    ddt_dL_dqd,
    dL_dq,
    dL_dqd,
    equation_mathml,
    lagrangian,
    latex_to_mathml,
    legacy_rate_names,
    mathml_of,
    name,
    of_q,
    rate_names,
    rate_symbols,
    symbol_name,
    text_of,
    value_mathml,
    vector_name,
)

__all__ = [
    "MATHML_NS",
    "Name",
    "ddt_dL_dqd",
    "dL_dq",
    "dL_dqd",
    "equation_mathml",
    "lagrangian",
    "latex_to_mathml",
    "legacy_rate_names",
    "mathml_of",
    "name",
    "of_q",
    "rate_names",
    "rate_symbols",
    "symbol_name",
    "text_of",
    "value_mathml",
    "vector_name",
]
