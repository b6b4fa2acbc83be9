"""Names of the quantities in a derivation, in three notations at once, and the MathML of equations.

A :class:`Name` is the LaTeX of a left-hand side (it *is* a ``str``, so code that reads the LaTeX keeps
working) that also carries its plain-text form (``.text``: ``dL/dqdot1``, ``d/dt dL/dqdot1``, ``J_vc1``) and
its presentation MathML (``.mathml``: ``<mfrac><mrow><mo>∂</mo>...``, ``<mover>`` for the dots of
q̇ and q̈). Right-hand sides are SymPy expressions, printed by SymPy's presentation MathML printer
with the velocity and acceleration symbols drawn with their dots.

Plain strings are still accepted as names (steps written by hand): their MathML comes from
:func:`latex_to_mathml`, a converter for the small LaTeX of equation names.
"""

from __future__ import annotations

import html
import re
from html.entities import html5
from xml.dom.minidom import parseString

import sympy as sp
from sympy.printing.conventions import split_super_sub
from sympy.printing.mathml import MathMLPresentationPrinter

__all__ = [
    "rate_names",
    "legacy_rate_names",
    "Name",
    "name",
    "of_q",
    "dL_dqd",
    "ddt_dL_dqd",
    "dL_dq",
    "lagrangian",
    "symbol_name",
    "vector_name",
    "latex_to_mathml",
    "value_mathml",
    "equation_mathml",
    "text_of",
    "mathml_of",
]

MATHML_NS = "http://www.w3.org/1998/Math/MathML"
_GREEK = {
    "tau": "τ",
    "omega": "ω",
    "theta": "θ",
    "alpha": "α",
    "partial": "∂",
    "lambda": "λ",
    "pi": "π",
    "mu": "μ",
    "nu": "ν",
}


class Name(str):
    """LaTeX of a left-hand side, with ``.text`` and ``.mathml`` (see the module docstring)."""

    text: str
    mathml: str

    def __new__(cls, latex: str, text: str, mathml: str):
        obj = super().__new__(cls, latex)
        obj.text = text
        obj.mathml = mathml
        return obj

    @property
    def latex(self) -> str:
        return str.__str__(self)


# ------------------------------------------------------------------ velocity and acceleration symbols
def rate_names(name: str) -> tuple:
    """Names of the velocity and acceleration symbols of the coordinate ``name``, in SymPy's own
    accent convention (a base ending in ``dot``/``ddot``): ``q1`` -> ``("qdot1", "qddot1")``,
    ``theta_2`` -> ``("thetadot_2", "thetaddot_2")``, ``x`` -> ``("xdot", "xddot")``. SymPy's printers
    draw them with the accent — ``sp.pretty`` q̇₁, ``sp.latex`` ``\\dot{q}_{1}`` (kinedyn's MathML via
    :func:`rate_symbols`) — while ``str`` stays the plain identifier ``qdot1`` that code generation, ``sympify``
    and JSON need."""
    base = split_super_sub(name)[0]
    if not base or not name.startswith(base):
        return f"{name}dot", f"{name}ddot"
    rest = name[len(base) :]
    return f"{base}dot{rest}", f"{base}ddot{rest}"


def legacy_rate_names(name: str) -> tuple:
    """The names kinedyn gave the velocity and acceleration symbols before :func:`rate_names`
    (``q1`` -> ``qd1``, ``qdd1``; ``x`` -> ``x_d``, ``x_dd``): still read in energies written as strings."""
    m = re.fullmatch(r"([A-Za-z]+)(\d+)", name)
    return (f"{m.group(1)}d{m.group(2)}", f"{m.group(1)}dd{m.group(2)}") if m else (f"{name}_d", f"{name}_dd")


# ------------------------------------------------------------------ MathML pieces
def mi(x: str, script: bool = False) -> str:
    return f'<mi mathvariant="script">{html.escape(x)}</mi>' if script else f"<mi>{html.escape(x)}</mi>"


def tokens(s: str) -> str:
    """A subscript such as ``c1`` or ``121``: letters as identifiers, digits as one number each run."""
    parts = re.findall(r"[A-Za-z]+|\d+|.", s)
    out = "".join(
        f"<mn>{p}</mn>"
        if p.isdigit()
        else (f"<mi>{html.escape(_GREEK.get(p, p))}</mi>" if p.isalpha() else f"<mo>{html.escape(p)}</mo>")
        for p in parts
    )
    return out if len(parts) == 1 else f"<mrow>{out}</mrow>"


def _dot(base: str, n: int) -> str:
    return f'<mover accent="true">{base}<mo>{"˙" if n == 1 else "¨"}</mo></mover>'


def _split_symbol(sym) -> tuple:
    """(base, subscript) of a coordinate's name as SymPy prints it: q1 -> (q, 1), theta_2 -> (theta, 2)."""
    nm = sym.name if hasattr(sym, "name") else str(sym)
    m = re.fullmatch(r"([A-Za-z]+?)_?(\d+)", nm) or re.fullmatch(r"(.+?)_(.+)", nm)
    return (m.group(1), m.group(2)) if m else (nm, "")


def _rate_mathml(q, n: int) -> str:
    """q̇_k (n = 1) or q̈_k (n = 2) as MathML: the dot over the base, the index below."""
    base, sub = _split_symbol(q)
    b = _dot(mi(_GREEK.get(base, base)), n)
    return f"<msub>{b}{tokens(sub)}</msub>" if sub else b


def _coord_mathml(q) -> str:
    base, sub = _split_symbol(q)
    b = mi(_GREEK.get(base, base))
    return f"<msub>{b}{tokens(sub)}</msub>" if sub else b


# ------------------------------------------------------------------ names
def name(latex: str, text: str, base: str, sub: str = "", script: bool = False) -> Name:
    """A plain name ``base_sub``: ``name("r_{c1}", "r_c1", "r", "c1")``; Greek bases by name."""
    b = mi(_GREEK.get(base, base), script)
    return Name(latex, text, f"<msub>{b}{tokens(sub)}</msub>" if sub else b)


def of_q(f: str, rates: bool = False) -> Name:
    """``D(q)``, ``g(q)``, ``A(q)``; ``rates=True``: ``C(q, q̇)``."""
    if rates:
        return Name(
            f"{f}(q, \\dot{{q}})",
            f"{f}(q, qd)",
            f"<mrow><mi>{f}</mi><mo>(</mo><mi>q</mi><mo>,</mo>{_dot('<mi>q</mi>', 1)}<mo>)</mo></mrow>",
        )
    return Name(f"{f}(q)", f"{f}(q)", f"<mrow><mi>{f}</mi><mo>(</mo><mi>q</mi><mo>)</mo></mrow>")


def lagrangian() -> Name:
    return Name(r"\mathcal{L}", "L", mi("L", script=True))


def _partial_frac(num: str, den: str) -> str:
    return f"<mfrac><mrow><mo>∂</mo>{num}</mrow><mrow><mo>∂</mo>{den}</mrow></mfrac>"


def _rate_latex(q, n: int = 1) -> str:
    """\\dot{q}_{1} (the dot over the base, as the textbooks and ``latex_names`` write it)."""
    base = sp.latex(q)
    m = re.fullmatch(r"(.+?)_\{(.+)\}", base)
    head, tail = (m.group(1), "_{" + m.group(2) + "}") if m else (base, "")
    return ("\\dot{" if n == 1 else "\\ddot{") + head + "}" + tail


def dL_dqd(q, qd) -> Name:
    """∂L/∂q̇_k."""
    return Name(
        f"\\frac{{\\partial \\mathcal{{L}}}}{{\\partial {_rate_latex(q)}}}",
        f"dL/d{qd}",
        _partial_frac(mi("L", script=True), _rate_mathml(q, 1)),
    )


def ddt_dL_dqd(q, qd) -> Name:
    """d/dt ∂L/∂q̇_k."""
    return Name(
        f"\\frac{{d}}{{dt}}\\frac{{\\partial \\mathcal{{L}}}}{{\\partial {_rate_latex(q)}}}",
        f"d/dt dL/d{qd}",
        f"<mrow><mfrac><mi>d</mi><mrow><mi>d</mi><mi>t</mi></mrow></mfrac>{_partial_frac(mi('L', script=True), _rate_mathml(q, 1))}</mrow>",
    )


def dL_dq(q) -> Name:
    """∂L/∂q_k."""
    return Name(
        f"\\frac{{\\partial \\mathcal{{L}}}}{{\\partial {sp.latex(q)}}}",
        f"dL/d{q}",
        _partial_frac(mi("L", script=True), _coord_mathml(q)),
    )


def symbol_name(sym) -> Name:
    """The name of an intermediate variable (``WP3x``): SymPy's LaTeX and MathML of the symbol."""
    return Name(sp.latex(sym), str(sym), sp.mathml(sym, printer="presentation"))


def vector_name(latex_base: str, text_base: str, mathml_base: str, index, accent: int = 0) -> Name:
    """A per-link vector such as ω̇_3: ``vector_name(r"\\omega", "w", "ω", 3, accent=1)``."""
    b = mi(mathml_base)
    if accent:
        b = _dot(b, accent)
        latex_base = ("\\dot{" if accent == 1 else "\\ddot{") + latex_base + "}"
    return Name(f"{latex_base}_{{{index}}}", f"{text_base}{index}", f"<msub>{b}{tokens(str(index))}</msub>")


def text_of(lhs) -> str:
    """The plain-text form of a name (a :class:`Name`, or LaTeX written by hand)."""
    if isinstance(lhs, Name):
        return lhs.text
    s = str(lhs).replace(r"\dot{q}", "qd").replace(r"\ddot{q}", "qdd").replace(r"\tau", "tau").replace(r"\omega", "w")
    s = re.sub(r"\\(frac|partial|mathcal|operatorname|left|right|text)", "", s)
    return s.replace("{", "").replace("}", "").replace("\\", "")


def mathml_of(lhs) -> str:
    """The MathML of a name (a :class:`Name`, or LaTeX written by hand)."""
    return lhs.mathml if isinstance(lhs, Name) else latex_to_mathml(str(lhs))


# ------------------------------------------------------------------ expressions
_COM_NAME = re.compile(r"([A-Za-z])(c)_?(\d+)")


def compound_name(sym) -> tuple[str, str] | None:
    """(LaTeX, MathML) of a parameter named for a centre of mass, ``lc2`` or ``lc_2`` (Spong's l_c2, the
    distance to link 2's centre of mass): one symbol l with the subscript c2, where SymPy would print
    the product-looking ``lc_{2}``; None for any other name."""
    m = _COM_NAME.fullmatch(getattr(sym, "name", ""))
    if m is None:
        return None
    base, c, k = m.groups()
    return f"{base}_{{{c}{k}}}", f"<msub>{mi(base)}<mrow>{mi(c)}<mn>{k}</mn></mrow></msub>"


def compound_latex_names(expr) -> dict:
    """``{symbol: LaTeX}`` for the symbols of ``expr`` that :func:`compound_name` renames (for
    ``sympy.latex(..., symbol_names=...)``)."""
    free = expr.free_symbols if hasattr(expr, "free_symbols") else set()
    return {s: n[0] for s in free if (n := compound_name(s)) is not None}


class _Printer(MathMLPresentationPrinter):
    """SymPy's presentation printer, drawing chosen symbols (the rates q̇_k, q̈_k) with given MathML."""

    def __init__(self, symbols: dict[sp.Symbol, str], settings=None):
        super().__init__(settings or {})
        self._given = symbols

    def _print_Symbol(self, sym, style="plain"):
        if sym in self._given:
            root = parseString(f'<wrap xmlns="{MATHML_NS}">{self._given[sym]}</wrap>').documentElement
            assert root is not None  # a parsed document always has its root element
            return root.firstChild
        compound = compound_name(sym)
        if compound is not None:
            self._given[sym] = compound[1]
            return self._print_Symbol(sym, style)
        return super()._print_Symbol(sym, style)


def rate_symbols(q, qd, qdd) -> dict[sp.Symbol, str]:
    """MathML for the coordinates q_k and their velocity and acceleration symbols (dots over the base)."""
    out = {}
    for a, b, c in zip(q, qd, qdd):
        out[a] = _coord_mathml(a)
        out[b] = _rate_mathml(a, 1)
        out[c] = _rate_mathml(a, 2)
    return out


def _xml_entities(m: str) -> str:
    """HTML named entities (SymPy writes &InvisibleTimes;, &ApplyFunction;) as characters, so the MathML
    is well-formed XML as well as HTML."""
    keep = {"amp", "lt", "gt", "quot", "apos"}
    return re.sub(
        r"&([A-Za-z]+);", lambda g: g.group(0) if g.group(1) in keep else html5.get(g.group(1) + ";", g.group(0)), m
    )


def value_mathml(value, rates: dict[sp.Symbol, str] | None = None) -> str:
    """Presentation MathML of a SymPy expression or matrix (``rates`` from :func:`rate_symbols`);
    brackets and parentheses marked stretchy, so they grow around matrices and fractions."""
    printer = _Printer(rates or {})
    m = _xml_entities(printer.doprint(sp.sympify(value)))
    return re.sub(r"<mo>([()\[\]])</mo>", r'<mo stretchy="true">\1</mo>', m)


def broken_equation_mathml(lhs, pieces, rates=None, display: str = "block") -> str:
    """``lhs = pieces[0] + pieces[1] + ...`` as one ``<math>`` element laid out on several lines (an
    ``<mtable>``, one row per piece, the later rows starting with their sign), so that a long sum wraps
    on the page instead of scrolling sideways (browsers' MathML does not break lines itself)."""
    rows = []
    for k, piece in enumerate(pieces):
        neg = k > 0 and piece.could_extract_minus_sign()
        body = value_mathml(-piece if neg else piece, rates)
        sign = "" if k == 0 else f"<mo>{'−' if neg else '+'}</mo>"
        left = mathml_of(lhs) if k == 0 else ""
        rows.append(f"<mtr><mtd>{left}</mtd><mtd><mo>{'=' if k == 0 else ''}</mo></mtd><mtd>{sign}{body}</mtd></mtr>")
    return (
        f'<math xmlns="{MATHML_NS}" display="{display}"><mtable columnalign="right center left">'
        + "".join(rows)
        + "</mtable></math>"
    )


def equation_mathml(lhs, value, rates=None, display: str = "block") -> str:
    """One ``<math>`` element: ``lhs = value``."""
    return (
        f'<math xmlns="{MATHML_NS}" display="{display}"><mrow>{mathml_of(lhs)}<mo>=</mo>'
        f"{value_mathml(value, rates)}</mrow></math>"
    )


def latex_to_mathml(s: str) -> str:
    """Presentation MathML for the small LaTeX of equation names (subscripts, \\frac, \\dot, \\ddot,
    \\partial, \\mathcal, Greek letters)."""
    pos = 0

    def group() -> str:
        nonlocal pos
        if pos < len(s) and s[pos] == "{":
            pos += 1
            out = seq("}")
            pos += 1
            return f"<mrow>{out}</mrow>"
        return atom()

    def atom() -> str:
        nonlocal pos
        c = s[pos]
        if c == "\\":
            m = re.match(r"\\([A-Za-z]+)", s[pos:])
            if not m:
                pos += 2
                return f"<mo>{html.escape(s[pos - 1])}</mo>"
            cmd = m.group(1)
            pos += len(m.group(0))
            if cmd == "frac":
                a = group()
                b = group()
                return f"<mfrac>{a}{b}</mfrac>"
            if cmd in ("dot", "ddot"):
                return _dot(group(), 1 if cmd == "dot" else 2)
            if cmd == "mathcal":
                inner = re.sub(r"<[^>]+>", "", group())
                return f'<mi mathvariant="script">{inner}</mi>'
            if cmd in ("left", "right"):
                return ""
            if cmd == "text":
                inner = re.sub(r"<[^>]+>", "", group())
                return f"<mtext>{inner}</mtext>"
            if cmd == "partial":
                return "<mo>∂</mo>"
            if cmd in _GREEK:
                return f"<mi>{_GREEK[cmd]}</mi>"
            return f"<mi>{html.escape(cmd)}</mi>"
        pos += 1
        if c.isdigit():
            return f"<mn>{c}</mn>"
        if c.isalpha():
            return f"<mi>{c}</mi>"
        if c == " ":
            return ""
        return f"<mo>{html.escape(c)}</mo>"

    def seq(stop: str | None) -> str:
        nonlocal pos
        parts: list[str] = []
        while pos < len(s) and (stop is None or s[pos] != stop):
            if s[pos] in "_^" and parts:
                op = s[pos]
                pos += 1
                sub = group()
                base = parts.pop()
                parts.append(f"<msub>{base}{sub}</msub>" if op == "_" else f"<msup>{base}{sub}</msup>")
            else:
                parts.append(group() if s[pos] == "{" else atom())
        return "".join(parts)

    return f"<mrow>{seq(None)}</mrow>"
