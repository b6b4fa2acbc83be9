"""The seed tutorial (METR4202 Tutorial 4: Jacobians, J^T F, Lagrangian dynamics, the elbow arm),
worked with kinedyn, every answer with its steps.

Each question gives an :class:`Answer`: a list of items (text, equations, tables) and comparisons of
kinedyn's result with the answer *printed in the tutorial*. Where they differ, the comparison carries
the independent check that decides it (finite differences of the forward kinematics or of the
Lagrangian written from the geometry, virtual work, the energy balance), evaluated numerically.

The rooms: :mod:`.printed` (the printed answers and the questions' inputs, as data), :mod:`.answers`
(what a question returns, shared helpers), :mod:`.questions` (Q1, Q2, and :func:`answer`),
:mod:`.lagrange` (Q3), :mod:`.elbow` (the challenge), :mod:`.render` (JSON, Markdown, HTML, terminal).
Command line: ``kinedyn tutorial``. Conventions: docs/seed-notes.md.
"""

from .answers import Answer, Comparison, symbolic_frame_pose, symbolic_jacobian
from .elbow import elbow_branch_name, elbow_ik
from .printed import PRINTED, QUESTION_DATA, QUESTIONS, printed
from .questions import answer, work
from .render import name_latex, render_html, render_markdown, render_text, to_json

__all__ = [
    "QUESTIONS",
    "PRINTED",
    "QUESTION_DATA",
    "Answer",
    "Comparison",
    "answer",
    "work",
    "printed",
    "to_json",
    "render_markdown",
    "render_html",
    "render_text",
    "name_latex",
    "elbow_ik",
    "elbow_branch_name",
    "symbolic_frame_pose",
    "symbolic_jacobian",
]
