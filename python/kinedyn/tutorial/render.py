"""The worked answers written out: JSON, Markdown, the report's HTML section (presentation MathML)
and the terminal (rich)."""

from __future__ import annotations

import html
import re
from collections.abc import Sequence

import sympy as sp
from rich.console import Console
from rich.markup import escape
from rich.table import Table
from rich.text import Text

from ..symbolic.render import MATHML_NS, latex_to_mathml, rate_symbols, value_mathml
from .answers import Answer, tutorial_display


# ------------------------------------------------------------------ rendering
def _jsonable_value(v):
    if isinstance(v, (sp.Basic, sp.MatrixBase)):
        return str(v)
    return v


def to_json(answers: Sequence[Answer]) -> dict:
    out = {}
    for a in answers:
        out[a.key] = {
            "title": a.title,
            "question": a.question,
            "steps": [
                {
                    "kind": it[0],
                    **(
                        {"text": it[1]}
                        if it[0] == "text"
                        else {"name": it[1], "value": _jsonable_value(it[2])}
                        if it[0] == "eq"
                        else {"title": it[1], "headers": it[2], "rows": it[3]}
                    ),
                }
                for it in a.items
            ],
            "result": a.result,
            "comparisons": [c.to_dict() for c in a.comparisons],
            "misprints": [c.quantity for c in a.misprints],
        }
    return out


def _latex(value) -> str:
    if isinstance(value, str):
        return r"\text{" + value.replace("_", r"\_") + "}"
    return sp.latex(tutorial_display(value))


def name_latex(name: str) -> str:
    """The LaTeX of an equation's name as the tutorial writes it in ASCII: ``J^-1`` -> ``J^{-1}``,
    ``dL/dthetadot1`` -> ``\\frac{\\partial L}{\\partial \\dot{\\theta}_{1}}``, ``J_w_1`` -> ``J_{\\omega_{1}}``,
    ``det J_v`` -> ``\\det J_{v}``; the same names the Markdown and the report's MathML show."""

    def coord(m: re.Match) -> str:
        dots = {"": "", "d": "dot", "dd": "ddot", "dot": "dot", "ddot": "ddot"}[m.group(2) or ""]
        base = r"\theta"
        return (f"\\{dots}{{{base}}}" if dots else base) + (f"_{{{m.group(3)}}}" if m.group(3) else "")

    t = name.strip()
    t = re.sub(r"^d/dt\s+", r"\\frac{d}{dt}", t)
    t = re.sub(r"\bdL/d(theta|th)(ddot|dot|dd|d)?(\d?)\b", lambda m: r"\frac{\partial L}{\partial " + coord(m) + "}", t)
    t = re.sub(r"(?<!\\)\b(theta|th)(ddot|dot|dd|d)?(\d?)\b", coord, t)
    t = re.sub(r"\b([a-z])_([A-Z])\^(\d)\b", r"\1_{\2}^{\3}", t)
    t = re.sub(r"\bJ_w_(\d)\b", r"J_{\\omega_{\1}}", t)
    t = re.sub(r"\bJ_v_c(\d)\b", r"J_{v_{c\1}}", t)
    t = re.sub(r"\b([rJ])_([a-z]?\d|[a-z])\b", r"\1_{\2}", t)
    t = re.sub(r"\btau_?(\d)\b", r"\\tau_{\1}", t)
    t = re.sub(r"\b([ov])(\d)\b", r"\1_{\2}", t)
    t = re.sub(r"\^-1\b", "^{-1}", t)
    t = re.sub(r"\bdet\s+", r"\\det ", t)
    t = re.sub(r"\b(cos|sin)\(", r"\\\1(", t)
    t = re.sub(r"\(", r"\\left(", t)
    t = re.sub(r"\)", r"\\right)", t)
    return t


def _rates_mathml() -> dict[sp.Symbol, str]:
    """MathML of the displayed tutorial symbols theta_k, thetadot_k, thetaddot_k: θ with dots above."""
    q = [sp.Symbol(f"theta{k}", real=True) for k in (1, 2)]
    return rate_symbols(
        q,
        [sp.Symbol(f"thetadot{k}", real=True) for k in (1, 2)],
        [sp.Symbol(f"thetaddot{k}", real=True) for k in (1, 2)],
    )


def render_markdown(answers: Sequence[Answer]) -> str:
    out = ["# The METR4202 Tutorial 4, worked with kinedyn", ""]
    for a in answers:
        out += [
            f"## Q{a.key}: {a.title}" if a.key != "challenge" else f"## Challenge: {a.title}",
            "",
            f"*{a.question}*",
            "",
        ]
        for it in a.items:
            if it[0] == "text":
                out += [it[1], ""]
            elif it[0] == "eq":
                name, value = it[1], it[2]
                if isinstance(value, str):
                    out += [f"- **{name}** = {value}", ""]
                else:
                    out += ["$$", f"{name_latex(name)} = {_latex(value)}", "$$", ""]
            else:
                _, title, headers, rows = it
                out += [f"**{title}**", "", "| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
                out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
                out.append("")
        if a.comparisons:
            out += [
                "**Against the tutorial's printed answer**",
                "",
                "| quantity | printed | kinedyn | verdict |",
                "|---|---|---|---|",
            ]
            for c in a.comparisons:
                out.append(
                    f"| {c.quantity} | `{c.printed}` | `{c.kinedyn}` | {'agrees' if c.agrees else '**differs: misprint**'} |"
                )
            out.append("")
            for c in a.misprints:
                out += [
                    f"- **{c.quantity}: the printed value is wrong.** Correct: `{c.correction or c.kinedyn}`. Deciding check: {c.check}.",
                    "",
                ]
    return "\n".join(out)


def render_html(answers: Sequence[Answer]) -> str:
    """The worked answers as one HTML ``<section>`` for the report: each question's steps, its
    equations in presentation MathML (the tutorial's notation), its tables, and the verdict on each
    printed answer with the deciding check and, for a misprint, the correct value."""
    rates = _rates_mathml()

    def equation(name: str, value) -> str:
        if isinstance(value, str):
            return f"<p><b>{html.escape(name)}</b> = {html.escape(value)}</p>"
        lhs = latex_to_mathml(name_latex(name))
        return f'<div class="eq"><math xmlns="{MATHML_NS}" display="block"><mrow>{lhs}<mo>=</mo>{value_mathml(tutorial_display(value), rates)}</mrow></math></div>'

    def table(headers, rows) -> str:
        head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
        body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows)
        return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"

    def value(text: str, expr) -> str:
        if expr is not None:
            return f'<math xmlns="{MATHML_NS}">{value_mathml(tutorial_display(expr), rates)}</math>'
        return f"<code>{html.escape(text)}</code>"

    out = [
        "<section id='tutorial'><h2>The tutorial, worked</h2>",
        "<p class='note'>The seed tutorial's questions on this arm, worked by kinedyn step by step (<code>kinedyn tutorial</code> "
        "prints the same in a terminal). Every printed answer is compared with kinedyn's and decided by an independent check.</p>",
    ]
    for a in answers:
        title = f"Q{a.key}: {a.title}" if a.key != "challenge" else f"Challenge: {a.title}"
        out += [f"<h3>{html.escape(title)}</h3>", f"<p><i>{html.escape(a.question)}</i></p>"]
        for item in a.items:
            if item[0] == "text":
                out.append(f"<p>{html.escape(item[1])}</p>")
            elif item[0] == "eq":
                out.append(equation(item[1], item[2]))
            else:
                _, caption, headers, rows = item
                out += [f"<p><b>{html.escape(caption)}</b></p>", table(headers, rows)]
        if a.comparisons:
            rows = []
            for c in a.comparisons:
                printed, mine = c.exprs[:2] if c.exprs else (None, None)
                verdict = "<span class='ok'>agrees</span>" if c.agrees else "<span class='bad'>differs: misprint</span>"
                quantity = f'<math xmlns="{MATHML_NS}">{latex_to_mathml(name_latex(c.quantity))}</math>'
                rows.append(
                    f"<tr><td>{quantity}</td><td>{value(c.printed, printed)}</td><td>{value(c.kinedyn, mine)}</td><td>{verdict}</td></tr>"
                )
            out.append(
                "<table class='comparisons'><thead><tr><th>quantity</th><th>printed</th><th>kinedyn</th><th>verdict</th></tr></thead>"
                f"<tbody>{''.join(rows)}</tbody></table>"
            )
            for c in a.misprints:
                out.append(
                    f"<p><b class='bad'>{html.escape(c.quantity)}: the printed value is wrong.</b> Correct: "
                    f"{value(c.correction or c.kinedyn, c.exprs[1] if c.exprs else None)}. Deciding check: {html.escape(c.check)}.</p>"
                )
    out.append("</section>")
    return "\n".join(out)


def render_text(answers: Sequence[Answer], console=None) -> None:
    """Readable terminal output (rich: aligned tables, colour on a TTY)."""
    c = console or Console(highlight=False, soft_wrap=False)
    for a in answers:
        head = f"Q{a.key}" if a.key != "challenge" else "Challenge"
        c.rule(f"[bold]{head}: {escape(a.title)}[/bold]", align="left")
        c.print(Text(a.question, style="italic"))
        for it in a.items:
            if it[0] == "text":
                c.print(Text(it[1]))
            elif it[0] == "eq":
                name, value = it[1], it[2]
                if isinstance(value, str):
                    c.print(Text.assemble((f"  {name} = ", "bold cyan"), value))
                else:
                    _pretty_eq(c, name, value)
            else:
                _, title, headers, rows = it
                t = Table(title=escape(title), title_justify="left")
                for h in headers:
                    t.add_column(escape(h), justify="right")
                for r in rows:
                    t.add_row(*(escape(str(x)) for x in r))
                c.print(t)
        if a.comparisons:
            t = Table(title="against the tutorial's printed answer", title_justify="left")
            for h in ("quantity", "printed", "kinedyn", "verdict"):
                t.add_column(h)
            for cmp in a.comparisons:
                sym = cmp.exprs is not None
                t.add_row(
                    escape(cmp.quantity),
                    "(expression)" if sym else escape(cmp.printed),
                    "(expression)" if sym else escape(cmp.kinedyn),
                    "[green]agrees[/green]" if cmp.agrees else "[bold red]differs: misprint[/bold red]",
                )
            c.print(t)
            for cmp in a.misprints:
                c.print(Text.assemble(("MISPRINT ", "bold red"), (f"{cmp.quantity}", "bold")))
                if cmp.exprs is not None:
                    _pretty_eq(c, "printed", cmp.exprs[0])
                    _pretty_eq(c, "correct", cmp.exprs[1])
                    if len(cmp.exprs) > 2:
                        _pretty_eq(c, "correct - printed", cmp.exprs[2])
                else:
                    c.print(Text(f"  printed {cmp.printed}; correct {cmp.correction or cmp.kinedyn}"))
                c.print(Text.assemble(("  deciding check: ", "bold"), cmp.check))
        c.print()


def _pretty_eq(c, name: str, value) -> None:
    """``name = value`` with the value pretty-printed (multi-line), the name on the middle line."""
    lines = sp.pretty(tutorial_display(value), use_unicode=True, wrap_line=False).split("\n")
    label = f"  {name} = "
    mid = len(lines) // 2
    for k, line in enumerate(lines):
        c.print(
            Text.assemble((label if k == mid else " " * len(label), "bold cyan"), line), overflow="ignore", crop=False
        )


def _short(s: str, width: int = 70) -> str:
    return s if len(s) <= width else s[: width - 3] + "..."
