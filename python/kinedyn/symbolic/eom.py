"""``EquationsOfMotion``: the symbolic equations of one robot or Lagrangian system, with the steps that
led to them, renderings (LaTeX, Markdown, MathML, text), the regressor, and generated code.

    M(q) qdd + C(q, qd) qd + g(q) + friction(qd) = tau           (Spong eq. 9.61; docs/architecture.md)

``eom.christoffel[i][j][k]`` is c_ijk of Spong eq. 9.58 (0-based indices), ``C[k, j] = sum_i c_ijk qd_i``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from html import escape
from typing import Any

import sympy as sp

from .. import display
from .._math import by_name
from .backends import c_numpy, casadi
from .derive import cse, proofs, regressor
from .render import latex
from .render.mathml import broken_equation_mathml, equation_mathml, name, of_q, rate_symbols, text_of
from .render.text import equation_text
from .steps import Step, op_counts

__all__ = ["EquationsOfMotion", "Step"]


class EquationsOfMotion:
    """Symbolic equations of motion (see the module docstring). Built by
    :func:`equations_of_motion` (robots) or :meth:`kinedyn.LagrangianSystem.equations_of_motion`."""

    #: the equation the renderings print above the result (LaTeX, text); a closed chain's adds A^T lambda
    result_latex = latex.RESULT_TITLE
    result_text = "M(q) qdd + C(q, qd) qd + g(q) = tau"

    def __init__(
        self,
        q,
        qd,
        qdd,
        M,
        C,
        g,
        *,
        K=None,
        P=None,
        friction=None,
        christoffel=None,
        tau=None,
        steps=None,
        name: str = "",
        method: str = "lagrange",
        latex_names: dict | None = None,
        program=None,
        model=None,
        extra: dict | None = None,
        closed_form: Callable[[], Any] | None = None,
        derivation: Callable[[], dict[str, Any]] | None = None,
        robot: Any = None,
        notes: Sequence[str] = (),
    ):
        self.q = sp.Matrix(q)
        self.qd = sp.Matrix(qd)
        self.qdd = sp.Matrix(qdd)
        self.n = len(self.q)
        self.name = name
        self.method = method
        self._M, self._C, self._g = M, C, g
        self._K, self._P = K, P
        self._friction = friction
        self._christoffel = christoffel
        self._tau = tau
        self._steps = steps
        self.latex_names = dict(latex_names or {})
        self.program = program  # Newton-Euler customised model (kinedyn.symbolic.newton_euler.Program)
        self.model = model  # (RingModel, derivation dict) for robots
        self.extra = dict(extra or {})
        #: robot equations by Newton-Euler: the exact derivation (ring model, M, C, g, tau), computed
        #: on first call (see robot_eom); the regressor reads it
        self.derivation = derivation
        #: large robot models: M, C, g in CSE form (kinedyn.symbolic.cse.ClosedForm), and the rendered
        #: result as matrices of the entry names it defines (see robot_eom's ``form``)
        self.closed_form = closed_form
        self.final_equations: Callable[[], list] | None = (
            (lambda: cse.final_equations(closed_form(), self.friction)) if closed_form is not None else None
        )
        #: the kinedyn.Robot these equations were derived from (None for a LagrangianSystem); to_casadi
        #: takes the tool pose and Jacobian from it
        self.robot = robot
        #: sentences every rendering prints before the equations (e.g. the angles made exact, see
        #: :func:`kinedyn.description.snap.snap_right_angles`)
        self.notes = list(notes)

    # ------------------------------------------------------------------ lazily computed parts
    @staticmethod
    def _get(value):
        return value() if callable(value) else value

    @property
    def M(self) -> sp.Matrix:
        """The inertia matrix M(q) (Spong's D(q), eq. 9.47), reflected rotor inertia on the diagonal."""
        self._M = self._get(self._M)
        return self._M

    D = M

    @property
    def C(self) -> sp.Matrix:
        self._C = self._get(self._C)
        return self._C

    @property
    def g(self) -> sp.Matrix:
        self._g = self._get(self._g)
        return self._g

    @property
    def K(self):
        self._K = self._get(self._K)
        if self._K is None:
            self._K = sp.expand((self.qd.T * self.M * self.qd)[0, 0] / 2)
        return self._K

    @property
    def P(self):
        self._P = self._get(self._P)
        return self._P

    @property
    def L(self):
        """The Lagrangian L = K - P."""
        return self.K - self.P

    @property
    def H(self):
        """The Hamiltonian (total energy) H = K + P, as a function of q and qd (see :meth:`hamiltonian`)."""
        return self.K + self.P

    @property
    def friction(self) -> sp.Matrix:
        """Joint friction viscous * qd + coulomb * sign(qd) (zero when the description has none)."""
        self._friction = self._get(self._friction)
        if self._friction is None:
            self._friction = sp.zeros(self.n, 1)
        return self._friction

    @property
    def christoffel(self):
        """``c[i][j][k]`` (Spong eq. 9.58), nested lists of SymPy expressions."""
        self._christoffel = self._get(self._christoffel)
        return self._christoffel

    @property
    def tau(self) -> sp.Matrix:
        """tau = M qdd + C qd + g + friction."""
        self._tau = self._get(self._tau)
        if self._tau is None:
            self._tau = (self.M * self.qdd + self.C * self.qd + self.g).applyfunc(sp.expand) + self.friction
        return self._tau

    @property
    def steps(self) -> list[Step]:
        self._steps = self._get(self._steps)
        for step in self._steps or []:
            step.owner = self  # its notebook display prints q̇, q̈ by self's names
        return self._steps or []

    def configuration_rates(self) -> list[tuple]:
        """(coordinate, rate) pairs along which d/dt of a function of the configuration is taken:
        (q_k, qd_k); a closed chain's reduced equations add the dependent coordinates."""
        return list(zip(self.q, self.qd))

    # ------------------------------------------------------------------ derived forms
    def hamiltonian(self, u=None):
        """(p, H(q, p), qdot(q, p), pdot(q, p)): the momenta p = M qd, H = p^T M^-1 p / 2 + P and
        Hamilton's equations with the generalised forces, qdot = dH/dp and
        pdot = -dH/dq + u - friction(qdot). ``u`` defaults to symbols tau1..taun (as in
        :meth:`phase_space`)."""
        if u is None:
            u = sp.Matrix(sp.symbols(f"tau1:{self.n + 1}", real=True))
        p = sp.Matrix([sp.Symbol(f"p_{c.name}", real=True) for c in self.q])  # momentum conjugate to each q
        Minv = self.M.inv() if self.n <= 3 else self.M.inv(method="LU")
        H = sp.expand((p.T * Minv * p)[0, 0] / 2) + self.P
        qdot = sp.Matrix([sp.diff(H, pi) for pi in p])
        friction = self.friction.subs(dict(zip(self.qd, qdot)), simultaneous=True)
        pdot = sp.Matrix([-sp.diff(H, qi) for qi in self.q]) + sp.Matrix(u) - friction
        return p, H, qdot, pdot

    def phase_space(self, u=None):
        """(x, f, u): the state x = (q, qd) and x' = f(x, u) = (qd, M^-1 (u - C qd - g - friction))
        (LaValle eq. 13.148). ``u`` defaults to symbols tau1..taun."""
        if u is None:
            u = sp.Matrix(sp.symbols(f"tau1:{self.n + 1}", real=True))
        u = sp.Matrix(u)
        rhs = u - self.C * self.qd - self.g - self.friction
        qdd = self.M.LUsolve(rhs) if self.n > 2 else self.M.inv() * rhs
        x = sp.Matrix.vstack(self.q, self.qd)
        return x, sp.Matrix.vstack(self.qd, qdd), u

    def regressor(self, known=None):
        """(Y, Theta): tau (without friction) == Y(q, qd, qdd) Theta + tau_known exactly, Theta a
        minimal vector of grouped parameters; the result also has ``.tau_known``, the part of tau free
        of unknown parameters (numeric rotor inertia; usually zero). See
        :mod:`kinedyn.symbolic.regressor`."""
        return regressor.regressor(self, known=known)

    def base_parameters(self, known=None) -> sp.Matrix:
        """Theta of :meth:`regressor` without forming Y (much faster for a 6-DOF arm): the grouped base
        parameters; ``len`` equals the numeric ``robot.base_parameters()`` count."""
        return regressor.base_parameters(self, known=known)

    def check_properties(self, params=None, limits=None, samples: int = 256, starts: int = 12, seed: int = 0):
        """The properties of Spong §9.5 decided on these symbolic equations: D symmetric, dD/dt - 2C
        skew-symmetric, dD/dt = C + C^T and tau = d/dt dL/dqd - dL/dq *proved* by exact simplification
        (status "proved", or "failed" with a counterexample, or "sampled" where simplification cannot
        decide), and the inertia bounds of eq. 9.120 by a global search with the configurations that
        attain them (``params`` gives values to free parameters). A
        :class:`kinedyn.analysis.PropertiesReport`; see :func:`kinedyn.analysis.prove_properties`."""
        return proofs.prove_properties(self, params=params, limits=limits, samples=samples, starts=starts, seed=seed)

    def subs(self, mapping) -> EquationsOfMotion:
        """The same equations with parameters replaced (numbers or other expressions); keys are
        symbols or their names."""
        mapping = by_name(mapping, self.parameters)
        f = lambda m: m.subs(mapping) if m is not None else None
        return EquationsOfMotion(
            self.q,
            self.qd,
            self.qdd,
            f(self.M),
            f(self.C),
            f(self.g),
            K=f(self.K),
            P=f(self.P),
            friction=f(self.friction),
            christoffel=[[[c.subs(mapping) for c in row] for row in plane] for plane in self.christoffel]
            if self.christoffel
            else None,
            name=self.name,
            method=self.method,
            latex_names=self.latex_names,
        )

    @property
    def parameters(self) -> list:
        """Free symbols of the equations other than the state, sorted by name."""
        state = set(self.q) | set(self.qd) | set(self.qdd)
        free = set()
        if self.closed_form is not None:  # the same symbols, without expanding M, C, g
            for key in ("M", "C", "g"):
                free |= self.closed_form()[key].parameters()
            free |= self.friction.free_symbols
        else:
            for m in (self.M, self.C, self.g, self.friction):
                free |= m.free_symbols
        free |= sp.sympify(self.P).free_symbols if self.P is not None else set()
        return sorted(free - state, key=str)

    # ------------------------------------------------------------------ code
    def to_code(
        self, language: str = "numpy", what: Sequence[str] = ("M", "C", "g", "tau"), name: str | None = None
    ) -> str:
        """Source code (``"python"``, ``"numpy"`` or ``"c"``) computing the requested matrices, with
        common subexpressions eliminated; see :mod:`kinedyn.symbolic.codegen`."""
        return c_numpy.generate(self, language, what, name=name)

    def compile(self, what: Sequence[str] = ("M", "C", "g", "tau"), backend: str = "auto", params=None, p=None):
        """Fast callables for the requested matrices: C compiled with the system compiler when
        available (``backend="c"``), NumPy otherwise; each accepts one state or a batch (N, n).
        ``backend="jax"``: jit-able, vmap-able, differentiable JAX functions in float64 (this turns on
        ``jax_enable_x64``; see :mod:`kinedyn.symbolic.jax_backend`).
        ``params``: {symbol or name: value} substituted before generation; ``p``: values of the
        parameters left symbolic, in ``eom.parameters`` order, passed to every call."""
        return c_numpy.compile_eom(self, what, backend=backend, params=params, p=p)

    def to_casadi(self, params=None, robot=None, frame: str | None = None):
        """CasADi Functions (SX, common subexpressions shared) ``M``, ``C``, ``g``, ``tau``,
        ``forward_dynamics`` and, for a robot, the tool ``pose`` and ``jacobian``; inputs named
        ``q``, ``qd``, ``qdd``/``tau`` and ``p`` (parameters left symbolic, in the order of the
        result's ``parameters``). See :mod:`kinedyn.symbolic.casadi_export`."""
        return casadi.to_casadi(self, params=params, robot=robot, frame=frame)

    def op_count(self, what: str = "tau", cse: bool = False) -> dict[str, int]:
        """Operation counts of ``tau`` (or ``M``, ``g``...) as formed; for the Newton-Euler method the
        customised model with its intermediate variables; ``cse=True`` after common-subexpression
        elimination."""
        if what == "tau" and self.program is not None:
            return self.program.op_count(cse=cse)
        exprs = list(getattr(self, what))
        if cse:
            repl, red = sp.cse(exprs, order="none")
            exprs = [e for _, e in repl] + list(red)
        return op_counts(exprs)

    # ------------------------------------------------------------------ rendering
    def legend(self, style: str = "text") -> str:
        """Which joint each printed q_k is, where the joints' names are printed as q_1..q_n because they
        do not read well as symbols (``shoulder_pan_joint``; "" otherwise). ``style``: "text"
        (``q_1: shoulder_pan_joint``), "markdown" or "latex" (the names as code, the q_k as math)."""
        renamed = [(k, s) for k, s in enumerate(self.q, start=1) if self.latex_names.get(s) == f"q_{{{k}}}"]
        if not renamed or all(s.name == f"q{k}" for k, s in renamed):
            return ""
        if style == "latex":
            pairs = [f"$q_{{{k}}}$: \\texttt{{{latex.escape(s.name)}}}" for k, s in renamed]
        elif style == "markdown":
            pairs = [f"$q_{{{k}}}$: `{s.name}`" for k, s in renamed]
        else:
            pairs = [f"q_{k}: {s.name}" for k, s in renamed]
        return "Joint variables: " + ", ".join(pairs) + "."

    def result_equations(self) -> list[tuple]:
        """The result as (left-hand side, value) pairs: D, C, g, tau, or in CSE form the entry names
        (defined in the last steps)."""
        if self.final_equations is not None:  # CSE form: entry names, defined in the last steps
            return self.final_equations()
        return [
            (of_q("M"), self.M),
            (of_q("C", rates=True), self.C),
            (of_q("g"), self.g),
            (name(r"\tau", "tau", "tau"), self.tau),
        ]

    def to_latex(self, steps: bool = True) -> str:
        """A LaTeX fragment: one amsmath ``align*`` block with the steps of the derivation (if any, each
        title a ``\\text`` row) and the final matrices, to paste into a document that loads ``amsmath``
        (also valid KaTeX/MathJax input). Long sums are broken over lines and wide matrices written
        entry by entry so that every line fits a 17 cm text width. :meth:`to_latex_document` gives a
        complete document (``kinedyn derive --format latex``)."""
        return latex.fragment(
            self.steps if steps else [], self.result_equations(), self.latex_names, title=self.result_latex
        )

    def to_latex_document(self, steps: bool = True) -> str:
        """A complete LaTeX document (article, amsmath only) that ``pdflatex`` compiles: a section per
        step with its prose and equations, then the result; see :mod:`kinedyn.symbolic.latex`."""
        title = f"Equations of motion{' of ' + self.name if self.name else ''} ({self.method.replace('_', '-')})"
        return latex.document(
            title,
            self.steps if steps else [],
            self.result_equations(),
            self.latex_names,
            intro="\n\n".join(self.notes),
            legend=self.legend("latex"),
            result_title=self.result_latex,
        )

    def to_markdown(self) -> str:
        """Markdown with LaTeX math (``$$ ... $$``, long equations as ``aligned`` blocks broken over
        lines), one section per step."""
        names = self.latex_names

        def block(lhs, value) -> list[str]:
            rows = latex.equation_rows(lhs, value, names=names)
            if len(rows) == 1:
                return ["$$", rows[0].replace(" &= ", " = ", 1)[: -len(r" \\")], "$$", ""]
            rows[-1] = rows[-1][: -len(r" \\")]
            return ["$$", r"\begin{aligned}", *rows, r"\end{aligned}", "$$", ""]

        out = [f"# Equations of motion{': ' + self.name if self.name else ''} ({self.method})", ""]
        for sentence in [*self.notes, self.legend("markdown")]:
            out += [sentence, ""] if sentence else []
        for k, step in enumerate(self.steps, start=1):
            out += [f"## Step {k}: {step.title}", ""]
            if step.text:
                out += [step.text, ""]
            for lhs, value in step.equations:
                out += block(lhs, value)
        out += [f"## Result: ${self.result_latex}$", ""]
        for lhs, value in self.result_equations():
            out += block(lhs, value)
        return "\n".join(out)

    def equation_mathml(self, lhs, value, display: str = "block", width: float | None = None) -> str:
        """One ``<math>`` element ``lhs = value`` in presentation MathML (SymPy's printer; q̇, q̈ with
        dots); ``lhs`` a :class:`kinedyn.symbolic.render.Name` or a small LaTeX string. ``width``
        (points of 10 pt type, as :func:`kinedyn.symbolic.render.latex.width` estimates them): a sum
        wider than this is laid out over several lines, broken between its terms."""
        rates = self.__dict__.get("_rate_symbols")
        if rates is None:  # once per model, not per equation (a CSE-form model has a thousand)
            if self.legend():  # joints printed as q_1..q_n (see legend): their MathML too
                proxies = [sp.Symbol(f"q{k}") for k in range(1, self.n + 1)]
                rates = rate_symbols(proxies, self.qd, self.qdd)
                rates.update({q: rates.pop(p) for q, p in zip(self.q, proxies)})
            else:
                rates = rate_symbols(self.q, self.qd, self.qdd)
            self.__dict__["_rate_symbols"] = rates
        if width is not None and not isinstance(value, sp.MatrixBase):
            pieces = latex.sum_pieces(sp.sympify(value), width)
            if len(pieces) > 1:
                return broken_equation_mathml(lhs, pieces, rates, display=display)
        return equation_mathml(lhs, value, rates, display=display)

    def to_mathml(self, steps: bool = True) -> str:
        """Presentation MathML: one ``<section>`` per step (title, sentence, one ``<math>`` element per
        equation) and the result, inside one ``<div>`` (well-formed XML, embeddable in HTML)."""
        parts = ['<div class="kinedyn-eom">']
        parts += [f"<p>{escape(sentence)}</p>" for sentence in [*self.notes, self.legend()] if sentence]
        for k, step in enumerate(self.steps if steps else [], start=1):
            parts.append(f"<section><h3>Step {k}: {escape(step.title)}</h3>")
            if step.text:
                parts.append(f"<p>{escape(step.text)}</p>")
            parts += [self.equation_mathml(lhs, value) for lhs, value in step.equations]
            parts.append("</section>")
        parts.append(f"<section><h3>Result: {escape(self.result_text)}</h3>")
        parts += [self.equation_mathml(lhs, value) for lhs, value in self.result_equations()]
        parts.append("</section></div>")
        return "\n".join(parts)

    def __str__(self) -> str:
        out = [f"Equations of motion{' of ' + self.name if self.name else ''} ({self.method}): {self.result_text}"]
        out += self.notes  # no legend: plain text writes the joints' own names
        rates = [*self.qdd, *self.qd]
        for k, step in enumerate(self.steps, start=1):
            out.append(f"\nStep {k}: {step.title}")
            for lhs, value in step.equations:
                out += ["  " + line for line in equation_text(text_of(lhs), value, rates)]
        out.append("\nResult:")
        for lhs, value in self.result_equations():
            out += equation_text(text_of(lhs), value, rates)
        return "\n".join(out)

    def __repr__(self) -> str:
        return f"EquationsOfMotion(name={self.name!r}, n={self.n}, method={self.method!r})"

    # notebooks (kinedyn.display): the result typeset, the steps under a fold
    def _repr_html_(self) -> str:
        return display.eom_html(self)

    def _repr_latex_(self) -> str:
        return display.eom_latex(self)

    def _repr_markdown_(self) -> str:
        return display.eom_markdown(self)
