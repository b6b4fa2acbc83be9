"""``kinedyn tutorial``: the seed tutorial (METR4202 Tutorial 4) worked with kinedyn, step by step,
against its printed answers."""

from __future__ import annotations

from ...report import tutorial
from ..app import console, emit


def add_arguments(p) -> None:
    p.add_argument("--question", "-q", choices=tutorial.QUESTIONS, help="one question (default: all)")
    p.add_argument(
        "--format",
        choices=["text", "markdown"],
        default="text",
        help="text (tables, colour on a terminal) or markdown with LaTeX",
    )
    p.add_argument("--json", action="store_true", help="print one JSON document instead")


def run(args) -> int:
    questions = [args.question] if args.question else None
    answers = tutorial.work(questions)
    payload = {
        "questions": tutorial.to_json(answers),
        "misprints": {a.key: [c.quantity for c in a.misprints] for a in answers},
    }

    def render():
        if args.format == "markdown":
            print(tutorial.render_markdown(answers))
        else:
            tutorial.render_text(answers, console())

    emit(args, payload, render)
    return 0
