"""LaTeX of a derivation that a TeX engine compiles and that fits the page.

Two outputs:

* :func:`fragment` — one amsmath ``align*`` block (what :meth:`EquationsOfMotion.to_latex` returns), to
  paste into a document that loads ``amsmath``; it is also valid KaTeX / MathJax input.
* :func:`document` — a complete ``article`` (``kinedyn derive --format latex``): a section per step,
  its prose as text, one ``align*`` per step.

Both are written for a text width of about 17 cm (A4, 2 cm margins, 10 pt): prose goes through
:func:`latex_text` (TeX's special characters escaped, ASCII math such as ``r_ci``, ``qd^T`` or ``tau_k``
set as inline math), long sums are broken between terms over several aligned lines, a long factor
``a (b + c + ...)`` is opened with ``\\Bigl(`` on one line and closed with ``\\Bigr)`` on a later one, and
a matrix too wide for the line is written entry by entry (``D_{12} = ...``; zero entries left out and
said so). The breaking uses only amsmath (no ``breqn``): the widths are estimated from the expression
tree (:func:`width`), in points of 10 pt Computer Modern.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import sympy as sp
from sympy.printing.conventions import split_super_sub

from .mathml import compound_latex_names

__all__ = [
    "escape",
    "sum_pieces",
    "latex_text",
    "width",
    "expression_lines",
    "equation_rows",
    "fragment",
    "document",
    "LINE_PT",
]

#: the text width in points (A4 less 2 cm margins) and the width given to a right-hand side when the
#: left-hand sides are short (the text width less the left-hand column, the relation and a margin)
TEXT_PT = 483.0
LINE_PT = 380.0

_SPECIAL = {
    "\\": r"\textbackslash{}",
    "{": r"\{",
    "}": r"\}",
    "$": r"\$",
    "&": r"\&",
    "#": r"\#",
    "%": r"\%",
    "_": r"\_",
    "^": r"\textasciicircum{}",
    "~": r"\textasciitilde{}",
    "<": r"\textless{}",
    ">": r"\textgreater{}",
}
_GREEK_WORDS = {
    "tau",
    "omega",
    "lambda",
    "theta",
    "alpha",
    "beta",
    "gamma",
    "delta",
    "mu",
    "nu",
    "phi",
    "psi",
    "sigma",
    "rho",
    "epsilon",
}
_RATE_WORDS = {"qd": r"\dot{q}", "qdd": r"\ddot{q}", "qdot": r"\dot{q}", "qddot": r"\ddot{q}", "pdot": r"\dot{p}"}
# a word of ASCII math: base, optional _subscript, optional ^superscript, optional (arguments)
_MATH_WORD = re.compile(
    r"(?<![\w\\])([A-Za-z]+)(?:_([A-Za-z0-9]+))?(?:\^(-?[A-Za-z0-9]+))?(\((?:[A-Za-z0-9_, ]*)\))?(?![\w])"
)


def escape(s: str) -> str:
    """``s`` for LaTeX text mode, TeX's special characters escaped and nothing else changed."""
    return "".join(_SPECIAL.get(c, c) for c in s)


_escape = escape


def _math_base(base: str) -> str:
    if base in _RATE_WORDS:
        return _RATE_WORDS[base]
    if base in _GREEK_WORDS:
        return "\\" + base
    if base == "sum":
        return r"\sum"
    return base if len(base) == 1 else r"\mathit{" + base + "}"


def _math_word(m: re.Match) -> str | None:
    """The inline math of one ASCII-math word, or None for an ordinary word."""
    base, sub, sup, args = m.group(1), m.group(2), m.group(3), m.group(4)
    is_math = (
        bool(sub or sup)
        or base in _RATE_WORDS
        or base in _GREEK_WORDS
        or (len(base) == 1 and base.isupper() and base != "A")
    )
    if args and len(base) == 1:
        is_math = True
    if not is_math:
        return None
    out = _math_base(base)
    if sub:
        out += "_{" + (_math_base(sub) if sub in _GREEK_WORDS else sub) + "}"
    if sup:
        out += "^{" + ("T" if sup == "T" else sup) + "}"
    if args:
        inner = ", ".join(
            _math_base(a.strip()) if a.strip() in _RATE_WORDS or a.strip() in _GREEK_WORDS else _escape(a.strip())
            for a in args[1:-1].split(",")
        )
        out += r"\left(" + inner + r"\right)" if inner else "()"
    return "$" + out + "$"


_DERIVATIVE = re.compile(r"(?<![\w\\])d/dt\b|(?<![\w\\])d([A-Za-z])/d([A-Za-z]+)(?:_([A-Za-z0-9]+))?(?![\w])")


def _derivative(m: re.Match) -> str:
    if m.group(0) == "d/dt":
        return r"$\frac{d}{dt}$"
    top, bottom, sub = m.group(1), m.group(2), m.group(3)
    return (
        r"$\partial " + _math_base(top) + r"/\partial " + _math_base(bottom) + ("_{" + sub + "}" if sub else "") + "$"
    )


def latex_text(s: str) -> str:
    """Prose for LaTeX text mode (and KaTeX's ``\\text{}``): TeX's special characters escaped; words of
    ASCII math (``r_ci(q)``, ``qd^T``, ``tau_k``, ``J_vci``, ``K``, ``omega``, ``dL/dqd_k``) set as inline
    math, neighbouring pieces of math joined into one (``$K = \\dot{q}^{T} D(q) \\dot{q}$``)."""
    out, pos = [], 0
    spans = []
    for m in _DERIVATIVE.finditer(s):
        spans.append((m.start(), m.end(), _derivative(m)))
    for m in _MATH_WORD.finditer(s):
        if any(a < m.end() and m.start() < b for a, b, _ in spans):
            continue
        math = _math_word(m)
        if math is not None:
            spans.append((m.start(), m.end(), math))
    for a, b, math in sorted(spans):
        out.append(_escape(s[pos:a]))
        out.append(math)
        pos = b
    out.append(_escape(s[pos:]))
    text = "".join(out)
    # $a$ = $b$ -> $a = b$ (operators and spaces between two pieces of math belong to the math)
    return re.sub(r"\$((?:\s*[=+*/-]\s*)|\s+|\s*,\s*)\$", lambda g: g.group(1) if g.group(1).strip() else " ", text)


# ------------------------------------------------------------------ widths (points, 10 pt CM)
_CHAR, _SUB, _OP, _FUN = 5.5, 3.8, 7.8, 14.0


def _symbol_width(sym) -> float:
    name, sups, subs = split_super_sub(sym.name)
    base = re.sub(r"(ddot|dot|hat|bar|vec|tilde|prime)$", "", name)
    base_w = _CHAR if base.lower() in _GREEK_WORDS else _CHAR * max(1, len(base))
    return base_w + _SUB * sum(len(x) for x in subs + sups)


def width(expr) -> float:
    """Estimated printed width of ``sp.latex(expr)`` in points (display style, 10 pt)."""
    if isinstance(expr, sp.MatrixBase):
        cols = [max((width(e) for e in expr.col(j)), default=0.0) for j in range(expr.cols)]
        return sum(cols) + 2 * _CHAR * max(expr.cols - 1, 0) + 2 * _CHAR
    if expr.is_Symbol:
        return _symbol_width(expr)
    if expr.is_Number:
        if expr.is_Rational and not expr.is_Integer:
            return _CHAR * max(len(str(abs(expr.p))), len(str(expr.q))) + 2
        return _CHAR * len(str(expr if not expr.is_Float else sp.Float(expr, 15)))
    if expr.is_Add:
        return sum(width(a) for a in expr.args) + _OP * (len(expr.args) - 1)
    if expr.is_Mul:
        num, den = sp.fraction(expr)
        if den != 1:
            return max(width(num), width(den)) + 4
        total = 0.0
        for f in expr.args:
            total += width(f) + (2 * _CHAR if f.is_Add else 1.5)
        return total
    if expr.is_Pow:
        if expr.exp.is_Rational and expr.exp.is_negative:
            return width(1 / expr) + 4
        return width(expr.base) + (2 * _CHAR if expr.base.is_Add or expr.base.is_Mul else 0) + 0.7 * width(expr.exp)
    if isinstance(expr, sp.Function) or expr.is_Function:
        return _FUN + sum(width(a) for a in expr.args) + 2 * _CHAR
    return _CHAR * len(sp.latex(expr)) * 0.5


def latex_width(tex: str) -> float:
    """Estimated width in points of a small piece of LaTeX (a left-hand side such as
    ``\\frac{\\partial \\mathcal{L}}{\\partial \\dot{q}_{1}}``): a fraction as its wider part,
    subscripts smaller, each command one character."""
    t = re.sub(r"\\(left|right|mathcal|mathit|mathrm|operatorname|dot|ddot|bigl|bigr|Bigl|Bigr)\b", "", str(tex))
    frac = re.compile(r"\\frac\{([^{}]*)\}\{([^{}]*)\}")
    while True:
        t2 = re.sub(r"\{([^{}]*)\}", lambda m: "{" + m.group(1) + "}", t)
        m = frac.search(t2)
        if not m:
            break
        a, b = m.group(1), m.group(2)
        t = t2[: m.start()] + (a if latex_width(a) >= latex_width(b) else b) + t2[m.end() :]
    subs = sum(len(re.sub(r"\\[A-Za-z]+", "x", x)) for x in re.findall(r"[_^]\{([^{}]*)\}", t))
    t = re.sub(r"[_^]\{[^{}]*\}", "", t)
    t = re.sub(r"\\[A-Za-z]+", "x", t)
    t = re.sub(r"[{}\s]", "", t)
    return _CHAR * len(t) + _SUB * subs


def rhs_limit(lhs_names: Sequence[str]) -> float:
    """The width left for right-hand sides in an ``align*`` whose widest left-hand side is among
    ``lhs_names`` (the columns line up, so the widest one counts for every row)."""
    widest = max((latex_width(str.__str__(n) if isinstance(n, str) else str(n)) for n in lhs_names), default=0.0)
    return min(LINE_PT, TEXT_PT - widest - 40.0)


# ------------------------------------------------------------------ breaking
Line = tuple[str, float]


def _tex(expr, names) -> str:
    compound = compound_latex_names(expr)  # lc2 -> l_{c2}
    return sp.latex(expr, symbol_names={**compound, **names} if compound else names)


def expression_lines(expr, limit: float = LINE_PT, names: dict | None = None) -> list[Line]:
    """``expr`` as LaTeX lines of at most ``limit`` points each where it can be broken (between the
    terms of a sum; inside a long factor of a product, between ``\\Bigl(`` and ``\\Bigr)``); a line
    after the first starts with its sign. Returns ``[(latex, estimated width)]``."""
    names = names or {}
    expr = sp.sympify(expr)
    w = width(expr)
    if w <= limit:
        return [(_tex(expr, names), w)]
    if expr.is_Add:
        out: list[Line] = []
        cur, curw = "", 0.0
        for i, term in enumerate(expr.as_ordered_terms()):
            neg = term.could_extract_minus_sign()
            body = -term if neg else term
            op = "-" if neg else ("+" if i else "")
            sub = expression_lines(body, limit - _OP, names)
            if len(sub) == 1:
                piece, pw = (f"{op} {sub[0][0]}" if op else sub[0][0]), sub[0][1] + (_OP if op else 0)
                if cur and curw + pw > limit:
                    out.append((cur, curw))
                    cur, curw = piece, pw
                else:
                    cur, curw = (f"{cur} {piece}" if cur else piece), curw + pw
            else:
                if cur:
                    out.append((cur, curw))
                out.append(((f"{op} " if op else "") + sub[0][0], sub[0][1] + _OP))
                out.extend(sub[1:-1])
                cur, curw = sub[-1]
        if cur:
            out.append((cur, curw))
        return out
    if expr.is_Mul:
        num, den = sp.fraction(expr)
        adds = [f for f in sp.Mul.make_args(num) if f.is_Add] + [
            f.base for f in sp.Mul.make_args(num) if f.is_Pow and f.base.is_Add and f.exp == 1
        ]
        if adds:
            big = max(adds, key=width)
            rest = sp.Mul(*[f for f in sp.Mul.make_args(num) if f != big]) / den
            neg = rest.could_extract_minus_sign()
            if neg:
                rest = -rest
            head = ("- " if neg else "") + ("" if rest == 1 else _tex(rest, names) + " ")
            inner = expression_lines(big, limit - width(rest) - 10, names)
            if len(inner) > 1:
                first = (head + r"\Bigl(" + inner[0][0], width(rest) + inner[0][1] + 10)
                last = (inner[-1][0] + r"\Bigr)", inner[-1][1] + 5)
                return [first, *inner[1:-1], last]
    if expr.is_Mul and len(expr.args) > 1:  # a long product of short factors: split between factors
        num, den = sp.fraction(expr)
        if den == 1:
            coeff, factors = expr.as_coeff_mul()
            neg = coeff < 0
            coeff = -coeff if neg else coeff
            groups: list[list[Line]] = [] if coeff == 1 else [[(_tex(coeff, names), width(coeff))]]
            for f in factors:
                sub = expression_lines(f, limit - 10, names)
                if len(sub) == 1 and f.is_Add:
                    sub = [(r"\left(" + sub[0][0] + r"\right)", sub[0][1] + 2 * _CHAR)]
                groups.append(sub)
            lines: list[Line] = []
            cur, curw = "", 0.0
            for group in groups:
                first_tex, first_w = group[0]
                if curw and curw + first_w > limit:
                    lines.append((cur, curw))
                    cur, curw = r"\cdot " + first_tex, first_w + 5
                else:
                    cur, curw = (cur + " " + first_tex) if cur else first_tex, curw + first_w + 1.5
                if len(group) > 1:
                    lines.append((cur, curw))
                    lines.extend(group[1:-1])
                    cur, curw = group[-1]
            lines.append((cur, curw))
            if neg:
                lines[0] = ("- " + lines[0][0], lines[0][1] + _OP)
            if len(lines) > 1:
                return lines
    if isinstance(expr, (sp.sin, sp.cos)) and expr.args[0].is_Add:  # a long argument: \sin\Bigl( ... \Bigr)
        inner = expression_lines(expr.args[0], limit - 30, names)
        if len(inner) > 1:
            head = "\\" + type(expr).__name__
            return [
                (head + r"\Bigl(" + inner[0][0], inner[0][1] + 25),
                *inner[1:-1],
                (inner[-1][0] + r"\Bigr)", inner[-1][1] + 5),
            ]
    if expr.is_Pow and expr.base.is_Add and expr.exp.is_Integer and expr.exp > 0:
        inner = expression_lines(expr.base, limit - 20, names)
        if len(inner) > 1:
            return [
                (r"\Bigl(" + inner[0][0], inner[0][1] + 5),
                *inner[1:-1],
                (inner[-1][0] + r"\Bigr)^{" + str(expr.exp) + "}", inner[-1][1] + 10),
            ]
    return [(_tex(expr, names), w)]


def sum_pieces(expr, limit: float = LINE_PT) -> list:
    """A sum wider than ``limit`` points cut between its terms into consecutive partial sums each at
    most ``limit`` wide (a single wider term stands alone); ``sum(pieces) == expr``. Anything else:
    ``[expr]``."""
    if not expr.is_Add or width(expr) <= limit:
        return [expr]
    pieces: list = []
    current: list = []
    used = 0.0
    for term in expr.as_ordered_terms():
        w = width(term) + _OP
        if current and used + w > limit:
            pieces.append(sp.Add(*current))
            current, used = [], 0.0
        current.append(term)
        used += w
    pieces.append(sp.Add(*current))
    return pieces


def _entry_name(lhs: str, i: int, j: int | None) -> str:
    """``D(q)`` -> ``D_{12}``; ``\\tau`` -> ``\\tau_{1}``; anything else -> ``\\left[lhs\\right]_{12}``."""
    idx = f"{i + 1}" if j is None else f"{i + 1}{j + 1}"
    m = re.fullmatch(r"(\\?[A-Za-z]+)(\(.*\))?", lhs.strip())
    if m:
        return f"{m.group(1)}_{{{idx}}}{m.group(2) or ''}"
    return r"\left[" + lhs + r"\right]_{" + idx + "}"


def _scalar_rows(lhs: str, value, limit: float, names) -> list[str]:
    lines = expression_lines(value, limit, names)
    rows = [f"{lhs} &= {lines[0][0]} \\\\"]
    rows += [f"&\\quad {tex} \\\\" for tex, _ in lines[1:]]
    return rows


def equation_rows(lhs, value, limit: float = LINE_PT, names: dict | None = None) -> list[str]:
    """``align*`` rows (each ending in ``\\\\``) for ``lhs = value``: a matrix that fits the line as a
    matrix, a wider one entry by entry (zero entries left out, said in a ``\\text`` row)."""
    names = names or {}
    lhs = str.__str__(lhs) if isinstance(lhs, str) else str(lhs)
    if isinstance(value, sp.MatrixBase):
        fits = all(width(e) <= limit for e in value) and width(value) <= limit
        if fits:
            return [f"{lhs} &= {_tex(value, names)} \\\\"]
        rows: list[str] = []
        zeros = 0
        column = value.cols == 1
        for i in range(value.rows):
            for j in range(value.cols):
                e = value[i, j]
                if e == 0:
                    zeros += 1
                    continue
                rows += _scalar_rows(_entry_name(lhs, i, None if column else j), e, limit, names)
        if zeros:
            rows.append(r"&\text{(the other entries of $" + lhs + r"$ are zero)} \\")
        return rows
    return _scalar_rows(lhs, value, limit, names)


# ------------------------------------------------------------------ the two outputs
RESULT_TITLE = r"M(q)\ddot{q} + C(q,\dot{q})\dot{q} + g(q) = \tau"


def fragment(
    steps: Sequence,
    final: Sequence[tuple],
    names: dict | None = None,
    limit: float | None = None,
    title: str = RESULT_TITLE,
) -> str:
    """One ``align*`` block: each step's title as a ``\\text`` row, its equations, then the result
    (``title``: its equation, LaTeX)."""
    if limit is None:
        limit = rhs_limit([lhs for step in steps for lhs, _ in step.equations] + [lhs for lhs, _ in final])
    body: list[str] = []
    for step in steps:
        body.append(r"&\text{" + latex_text(step.title) + r"} \\")
        for lhs, value in step.equations:
            body += equation_rows(lhs, value, limit, names)
    body.append(r"&\text{Equations of motion: } " + title + r" \\")
    for lhs, value in final:
        body += equation_rows(lhs, value, limit, names)
    if body:
        body[-1] = body[-1][: -len(r" \\")]
    return "\\begin{align*}\n" + "\n".join(body) + "\n\\end{align*}"


PREAMBLE = r"""\documentclass[10pt]{article}
\usepackage[a4paper,margin=2cm]{geometry}
\usepackage{amsmath,amssymb}
\setcounter{MaxMatrixCols}{20}
\allowdisplaybreaks
"""


def align(rows: list[str]) -> str:
    if not rows:
        return ""
    rows = list(rows)
    rows[-1] = rows[-1][: -len(r" \\")] if rows[-1].endswith(r" \\") else rows[-1]
    return "\\begin{align*}\n" + "\n".join(rows) + "\n\\end{align*}"


def document(
    title: str,
    steps: Sequence,
    final: Sequence[tuple],
    names: dict | None = None,
    intro: str = "",
    limit: float | None = None,
    legend: str = "",
    result_title: str = RESULT_TITLE,
) -> str:
    """A complete LaTeX document (``pdflatex`` compiles it): a section per step with its prose and its
    equations, and the result (``result_title``: its equation, LaTeX); ``intro`` is prose (through
    :func:`latex_text`), ``legend`` LaTeX."""
    parts = [PREAMBLE, r"\title{" + _escape(title) + "}", r"\date{}", r"\begin{document}", r"\maketitle"]
    if intro:
        parts.append(latex_text(intro) + "\n")
    if legend:  # already LaTeX
        parts.append(legend + "\n")
    for k, step in enumerate(steps, start=1):
        parts.append(r"\section*{Step " + str(k) + ": " + latex_text(step.title) + "}")
        if getattr(step, "text", ""):
            parts.append(latex_text(step.text) + "\n")
        rows: list[str] = []
        step_limit = limit if limit is not None else rhs_limit([lhs for lhs, _ in step.equations])
        for lhs, value in step.equations:
            rows += equation_rows(lhs, value, step_limit, names)
        parts.append(align(rows))
    parts.append(r"\section*{Result: $" + result_title + "$}")
    rows = []
    final_limit = limit if limit is not None else rhs_limit([lhs for lhs, _ in final])
    for lhs, value in final:
        rows += equation_rows(lhs, value, final_limit, names)
    parts.append(align(rows))
    parts.append(r"\end{document}")
    return "\n".join(p for p in parts if p) + "\n"
