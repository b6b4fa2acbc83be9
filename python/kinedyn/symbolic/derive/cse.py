"""Closed-form M(q), C(q, qd) and g(q) of a robot in common-subexpression form, fast at any size.

The customised Newton-Euler model (:mod:`kinedyn.symbolic.newton_euler`, Khalil & Dombre §9.5) is a
straight-line program tau(q, qd, qdd) with named intermediate variables. Its parts follow by forward-mode
differentiation of that program, one assignment at a time (each right-hand side is small, so
``sympy.diff`` on it is cheap), never by expanding tau:

* ``M[:, j] = d tau / d qdd_j`` (tau is linear in qdd; taken at qd = qdd = 0, Khalil & Dombre §9.7's
  use of the inverse dynamic model for the inertia matrix);
* ``g = tau(q, 0, 0)``;
* ``C[:, j] = 1/2 d tau / d qd_j`` at qdd = 0: the velocity terms h(q, qd) = sum_ij c_ijk qd_i qd_j are a
  quadratic form with the Christoffel symbols c_ijk = c_jik (Spong eq. 9.58) as coefficients, so
  d h_k / d qd_j = 2 sum_i c_ijk qd_i = 2 C_kj (Spong eq. 9.62): the Christoffel C, not just any C
  with C qd = h.

Each block is then passed through ``sympy.cse`` (new variables ``x1, x2, ...`` for subexpressions used
more than once), and printed as Khalil & Dombre print their models: the intermediate variables in order,
then each matrix entry in terms of them. Derivative variables are named after the variable they
differentiate: ``WP3x_a2`` = d WP3x / d qdd_2, ``W3x_v2`` = d W3x / d qd_2.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import sympy as sp
from sympy.simplify.cse_main import tree_cse

from ..render.mathml import Name, name, of_q
from ..steps import Step, op_counts
from .newton_euler import newton_euler_program

__all__ = ["Block", "ClosedForm", "closed_form", "closed_form_of_program", "evaluate_block"]

Assignment = tuple[sp.Symbol, sp.Expr]


class Block:
    """One result in CSE form: ``assignments`` (symbol, expression) in order, then ``entries`` (row-major,
    ``shape``) in terms of them. ``title``/``text`` describe it for the step-by-step display."""

    def __init__(
        self,
        name: str,
        shape: tuple,
        assignments: list[Assignment],
        entries: list[sp.Expr],
        title: str = "",
        text: str = "",
    ):
        self.name = name
        self.shape = shape
        self.assignments = assignments
        self.entries = entries
        self.title = title
        self.text = text

    def entry_symbols(self) -> list[sp.Symbol]:
        """Names of the entries (M11, M12, ..., g1, ...), 1-based like the book."""
        if len(self.shape) == 2:
            return [
                sp.Symbol(f"{self.name}{r + 1}{c + 1}", real=True)
                for r in range(self.shape[0])
                for c in range(self.shape[1])
            ]
        return [sp.Symbol(f"{self.name}{r + 1}", real=True) for r in range(self.shape[0])]

    def symbol_matrix(self) -> sp.Matrix:
        """The result as a matrix of entry names (zero entries stay 0)."""
        syms = [s if e != 0 else sp.Integer(0) for s, e in zip(self.entry_symbols(), self.entries)]
        rows = self.shape[0]
        cols = self.shape[1] if len(self.shape) == 2 else 1
        return sp.Matrix(rows, cols, syms)

    def equations(self) -> list[Assignment]:
        """Intermediate variables, then the non-zero entries: [(lhs symbol, rhs)]."""
        out = list(self.assignments)
        out += [(s, e) for s, e in zip(self.entry_symbols(), self.entries) if e != 0]
        return out

    def parameters(self) -> set:
        """Free symbols of the block other than its own intermediate variables (state included)."""
        defined = {s for s, _ in self.assignments}
        free: set = set()
        for e in [e for _, e in self.assignments] + list(self.entries):
            free |= sp.sympify(e).free_symbols
        return free - defined

    def op_count(self) -> dict[str, int]:
        return op_counts([e for _, e in self.assignments] + list(self.entries))

    def __str__(self) -> str:
        return "\n".join(f"{s} = {e}" for s, e in self.equations())


class ClosedForm:
    """The blocks ``M``, ``C``, ``g`` (and ``tau``, the customised model itself) of one robot."""

    def __init__(self, blocks: dict[str, Block], q, qd, qdd):
        self.blocks = blocks
        self.q, self.qd, self.qdd = list(q), list(qd), list(qdd)

    def __getitem__(self, name: str) -> Block:
        return self.blocks[name]

    def __str__(self) -> str:
        return "\n\n".join(f"# {b.title}\n{b}" for b in self.blocks.values())


# ---------------------------------------------------------------------------- program transformations
def _is_trivial(e) -> bool:
    return e.is_Atom or (e.is_Mul and len(e.args) == 2 and e.args[0].is_Number and e.args[1].is_Atom)


def _specialise(assignments: Sequence[Assignment], values: dict) -> tuple[list[Assignment], dict]:
    """The program with some inputs fixed (``values``); variables that become numbers or plain symbols are
    propagated instead of assigned. Returns (assignments, env) where env maps every program variable
    that vanished to its value."""
    env = dict(values)
    out = []
    for s, e in assignments:
        v = e.xreplace(env)
        if _is_trivial(v):
            env[s] = v
        else:
            out.append((s, v))
    return out, env


def _tangent(
    assignments: Sequence[Assignment], outputs: Sequence[sp.Expr], seed: dict, env: dict, suffix: str, names: set
):
    """Forward-mode derivative of a straight-line program along ``seed`` (input symbol -> derivative),
    with the partial derivatives taken on the original right-hand sides and evaluated at the point
    ``env`` (the specialised primal values). Returns (new assignments, derivatives of the outputs)."""
    t = dict(seed)
    new: list[Assignment] = []

    def derivative(e):
        return _directional(e, t).xreplace(env)

    for s, e in assignments:
        d = derivative(e)
        if d == 0:
            continue
        if _is_trivial(d):
            t[s] = d
            continue
        name = f"{s.name}{suffix}"
        while name in names:
            name += "_"
        names.add(name)
        sym = sp.Symbol(name, real=True)
        new.append((sym, d))
        t[s] = sym
    return new, [derivative(sp.sympify(o)) for o in outputs]


def _directional(e, t: dict):
    """d e along the tangents ``t`` (symbol -> derivative) for sums, products and integer powers of symbols
    (what the Newton-Euler program's right-hand sides are made of); anything else through ``sympy.diff``.
    Much faster than ``sympy.diff`` once per variable: no Derivative objects, one pass over the tree."""
    if e.is_Symbol:
        return t.get(e, _ZERO)
    if e.is_Number or not (e.free_symbols & t.keys()):
        return _ZERO
    if e.is_Add:
        return sp.Add(*[_directional(a, t) for a in e.args])
    if e.is_Mul:
        args = e.args
        terms = []
        for i, a in enumerate(args):
            da = _directional(a, t)
            if da != 0:
                terms.append(sp.Mul(*(args[:i] + (da,) + args[i + 1 :])))
        return sp.Add(*terms)
    if e.is_Pow and e.exp.is_Integer:
        db = _directional(e.base, t)
        return e.exp * e.base ** (e.exp - 1) * db if db != 0 else _ZERO
    return sp.Add(*[sp.diff(e, x) * t[x] for x in e.free_symbols if x in t])


_ZERO = sp.Integer(0)


def _prune(assignments: Sequence[Assignment], outputs: Sequence[sp.Expr]) -> list[Assignment]:
    needed = set()
    for e in outputs:
        needed |= sp.sympify(e).free_symbols
    keep = []
    for s, e in reversed(assignments):
        if s in needed:
            keep.append((s, e))
            needed |= e.free_symbols
    return keep[::-1]


def _cse(assignments: list[Assignment], entries: list[sp.Expr], names: set) -> tuple[list[Assignment], list[sp.Expr]]:
    """``sympy.cse`` over the right-hand sides; each new variable ``x<k>`` is placed just before its first use
    (its own ingredients are defined by then, since it is a subexpression of that use)."""
    exprs = [e for _, e in assignments] + list(entries)
    start = 1
    while f"x{start}" in names:
        start += 1000
    symbols = sp.numbered_symbols("x", start=start, real=True)
    try:  # the tree pass of sympy.cse without its costly search for common sub-sums/products (opt_cse)
        repl, reduced = tree_cse(exprs, symbols, opt_subs={}, order="none")
    except ImportError:  # pragma: no cover - a SymPy without the helper
        repl, reduced = sp.cse(exprs, symbols=symbols, order="none")
    if not repl:
        return list(assignments), list(entries)
    defs = dict(repl)
    done: set = set()
    out: list[Assignment] = []

    def emit_deps(e):
        for x in sorted(e.free_symbols & defs.keys() - done, key=lambda s: int(s.name[1:])):
            if x in done:
                continue
            done.add(x)
            emit_deps(defs[x])
            out.append((x, defs[x]))

    k = len(assignments)
    for (s, _), e in zip(assignments, reduced[:k]):
        emit_deps(e)
        out.append((s, e))
    ent = list(reduced[k:])
    for e in ent:
        emit_deps(e)
    return out, ent


# ---------------------------------------------------------------------------- public
def closed_form(robot, q, qd, qdd, parameters=None, cse: bool = True) -> ClosedForm:
    """M, C, g (and tau) of ``robot`` in CSE form from its customised Newton-Euler model (see the module
    docstring); symbols ``q``, ``qd``, ``qdd`` as in ``robot.equations_of_motion()``."""
    prog = newton_euler_program(robot, q, qd, qdd, parameters=parameters, friction=False)
    return closed_form_of_program(prog, q, qd, qdd, cse=cse)


def closed_form_of_program(prog, q, qd, qdd, cse: bool = True) -> ClosedForm:
    """:func:`closed_form` of an already built customised model (a
    :class:`~kinedyn.symbolic.newton_euler.Program` with output ``tau``, friction left out)."""
    n = len(q)
    base = list(prog.assignments)
    tau = [sp.sympify(e) for e in prog.outputs["tau"]]
    names = {str(s) for s, _ in base} | {str(s) for s in list(q) + list(qd) + list(qdd)}
    zero = sp.Integer(0)
    blocks: dict[str, Block] = {}

    # M: d tau / d qdd_j at qd = qdd = 0
    primal, env = _specialise(base, {**{v: zero for v in qd}, **{a: zero for a in qdd}})
    m_assign: list[Assignment] = []
    columns = []
    for j in range(n):
        new, col = _tangent(base, tau, {qdd[j]: sp.Integer(1)}, env, f"_a{j + 1}", names)
        m_assign += new
        columns.append(col)
    m_entries = [
        sp.expand(columns[c][r]) if _small(columns[c][r]) else columns[c][r] for r in range(n) for c in range(n)
    ]
    blocks["M"] = _finish(
        "M",
        (n, n),
        primal + m_assign,
        m_entries,
        cse,
        names,
        "Inertia matrix M(q) = d tau / d qdd (customised Newton-Euler model, CSE form)",
        "Column j is the derivative of the Newton-Euler program along qdd_j at qd = qdd = 0; "
        "X_aj denotes d X / d qdd_j; x1, x2, ... are common subexpressions.",
    )

    # g: tau(q, 0, 0)
    g_entries = [t.xreplace(env) for t in tau]
    blocks["g"] = _finish(
        "g",
        (n,),
        primal,
        g_entries,
        cse,
        names,
        "Gravity vector g(q) = tau(q, 0, 0) (CSE form)",
        "The Newton-Euler program with qd = qdd = 0.",
    )

    # C: 1/2 d tau / d qd_j at qdd = 0 (Christoffel C, Spong eqs. 9.58, 9.62)
    c_primal, env_c = _specialise(base, {a: zero for a in qdd})
    c_assign: list[Assignment] = []
    columns = []
    for j in range(n):
        new, col = _tangent(base, tau, {qd[j]: sp.Integer(1)}, env_c, f"_v{j + 1}", names)
        c_assign += new
        columns.append(col)
    half = sp.Rational(1, 2)
    c_entries = [
        sp.expand(half * columns[c][r]) if _small(columns[c][r]) else half * columns[c][r]
        for r in range(n)
        for c in range(n)
    ]
    blocks["C"] = _finish(
        "C",
        (n, n),
        c_primal + c_assign,
        c_entries,
        cse,
        names,
        "Coriolis matrix C(q, qd) = (1/2) d tau / d qd (Christoffel form, CSE)",
        "tau's velocity terms are sum_ij c_ijk qd_i qd_j, so their derivative along qd_j is 2 C_kj "
        "(Spong eqs. 9.58, 9.62); taken at qdd = 0; X_vj denotes d X / d qd_j.",
    )

    # tau: the customised model itself
    blocks["tau"] = Block(
        "tau",
        (n,),
        base,
        tau,
        "Joint torques tau (customised Newton-Euler model, Khalil & Dombre)",
        "The recursion's intermediate variables, then tau; friction is added separately.",
    )
    return ClosedForm(blocks, q, qd, qdd)


def _small(e) -> bool:
    return sp.count_ops(e) <= 40 if not e.is_Atom else True


def _finish(name, shape, assignments, entries, cse, names, title, text) -> Block:
    assignments = _prune(assignments, entries)
    if cse:
        assignments, entries = _cse(assignments, entries, names)
    return Block(name, shape, assignments, entries, title, text)


def evaluate_block(block: Block, values: dict) -> list:
    """Numbers of a block at ``values`` ({symbol: float}), evaluating its assignments in order (for tests)."""
    env = dict(values)
    for s, e in block.assignments:
        env[s] = sp.sympify(e).xreplace(env)
    return [sp.sympify(e).xreplace(env) for e in block.entries]


# ---------------------------------------------------------------------------- display
#: the customised model is shown in CSE form above this many operations (tau of the PUMA 560 with its
#: numeric inertias has 354 and stays expanded; with general inertias 577)
CSE_THRESHOLD = 400
#: ... and for any model of more coordinates than this (the PUMA 560 with numeric inertias: expanded,
#: its Lagrange steps filled 800 kB of LaTeX; in CSE form about 50 kB, like its general-inertia model)
CSE_JOINTS = 3


def _lhs(sym):
    """The name of an intermediate variable, written the way SymPy's printers write the symbol in the
    right-hand sides (C2 -> C_{2}, WP3x_a2 -> WP3x_{a2}) without calling them once per variable."""
    text = sym.name
    digits = re.fullmatch(r"([A-Za-z]+)(\d+)", text)
    base, sub = (digits.group(1), digits.group(2)) if digits else (text.split("_", 1) + [""])[:2]
    if not sub:
        return Name(text, text, f"<mi>{text}</mi>")
    return Name(f"{base}_{{{sub}}}", text, f"<msub><mi>{base}</mi><mi>{sub}</mi></msub>")


def _entry_name(block: Block, sym):
    idx = sym.name[len(block.name) :]
    base = r"\tau" if block.name == "tau" else block.name
    return name(f"{base}_{{{idx}}}", sym.name, block.name, idx)


def block_equations(block: Block) -> tuple[list, list]:
    """(entries, intermediates) of a block as [(name, value)] for display: the non-zero entries
    (M11 = ...) and the intermediate variables they use, in order."""
    entries = [(_entry_name(block, s), e) for s, e in zip(block.entry_symbols(), block.entries) if e != 0]
    return entries, [(_lhs(s), e) for s, e in block.assignments]


def closed_form_steps(cf: ClosedForm, which: Sequence[str] = ("M", "C", "g")) -> list:
    """One :class:`~kinedyn.symbolic.eom.Step` per block: its intermediate variables, then its entries."""
    steps = []
    for key in which:
        b = cf[key]
        entries = set(b.entry_symbols())
        eqs = [(_entry_name(b, s) if s in entries else _lhs(s), e) for s, e in b.equations()]
        steps.append(Step(b.title, b.text, eqs))
    return steps


def final_equations(cf: ClosedForm, friction) -> list:
    """The result as matrices of entry names (M11, ..., C11, ..., g1, ...) defined by the steps, and
    tau = M qdd + C qd + g + friction in those names."""
    M, C, g = cf["M"].symbol_matrix(), cf["C"].symbol_matrix(), cf["g"].symbol_matrix()
    tau = M * sp.Matrix(cf.qdd) + C * sp.Matrix(cf.qd) + g + sp.Matrix(friction)
    return [(of_q("M"), M), (of_q("C", rates=True), C), (of_q("g"), g), (name(r"\tau", "tau", "tau"), tau)]
