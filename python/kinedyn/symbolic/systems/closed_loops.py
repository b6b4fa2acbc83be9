"""Equations of motion of a robot with closed loops (``robot.equations_of_motion()`` when
``robot.loops`` is not empty; docs/closed-loops.md, "The equations").

The tree's equations (Lagrange or Newton-Euler, :mod:`kinedyn.symbolic.systems.robot_eom`) in all its
n joint coordinates, and each loop's closure from the tree's forward kinematics
(:func:`kinedyn.symbolic.pose`), both frames in the base:

    point loop:  phi = p_a(q) - p_b(q)                                    (3 rows)
    weld loop:   phi = [p_a - p_b;  vee(R_a R_b^T - R_b R_a^T) / 2]       (6 rows)

Rows that vanish identically (z of a planar mechanism) are left out. On a closed configuration the
rotation rows' derivative is the relative angular velocity w_a - w_b, so A^T lambda applies the
multiplier lambda as a force (and moment) on frame a's body and its opposite on frame b's.

Multiplier form (LaValle, Planning Algorithms, §13.4.3; the sign of Pinocchio's constraint forces)::

    M(q) qdd + C(q, qd) qd + g(q) + friction = tau + A(q)^T lambda,   phi(q) = 0,   A = dphi/dq

(:class:`LagrangianSystem` writes the same system with ``+ A^T lambda`` on the left: its multipliers
are the negatives of these.)

Reduced form in m independent coordinates q_i (the others, q_d, dependent), premultiplying by G^T
(A G = 0 removes lambda):

- with an explicit branch q_d = s(q_i) (``solution``): :func:`kinedyn.symbolic.mechanisms.closed_chain`,
  D(q_i) = J^T D J with J = dTheta/dq_i and C from D's Christoffel symbols (Spong §9.4.4);
- otherwise the velocity map of coordinate partitioning (Wehage & Haug 1982): with r independent rows
  of A and A_d, A_i their columns of q_d and q_i, qd = G(q) qd_i with G = [I; -A_d^-1 A_i] (rows in
  the order of q), and

      M_r = G^T M G,   C_r = G^T (M dG/dt + C G),   g_r = G^T g,   tau_r = G^T tau

  functions of all n coordinates (the closure ties q_d to q_i), q on the loop's manifold. dM_r/dt -
  2 C_r is skew-symmetric (dM_r/dt = Gd^T M G + G^T Md G + G^T M Gd, so dM_r/dt - 2 C_r =
  (X^T - X) + G^T (Md - 2C) G with X = G^T M Gd). A_d^-1 = adj(A_d) / det(A_d) keeps every entry a
  fraction of trigonometric polynomials.

The independent coordinates are given (``independent``) or chosen at a closed configuration found
numerically (random parameter values, Gauss-Newton on phi): the dependent ones are taken from the
last coordinate backwards while their columns of A raise its rank, as many as the rank of A.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import sympy as sp

from ...expressions import parse_expression
from ..derive import proofs
from ..derive.kinematics import pose
from ..derive.simplify import simplify_trig
from ..eom import EquationsOfMotion
from ..render.mathml import Name, name, of_q
from ..steps import Step
from .mechanisms import closed_chain, closed_chain_system

__all__ = ["closed_loop_equations", "ClosedLoopEquations", "ReducedEquations", "loop_closure_rows"]

_AXES = ("x", "y", "z")


def _simp(e, q):
    return simplify_trig(sp.expand(e), list(q))


def loop_closure_rows(robot, q) -> tuple[list, list[str], list]:
    """(rows, labels, turns): the closure phi(q) of every loop of ``robot`` in the joint symbols ``q``
    (see the module docstring), rows that vanish identically left out; labels ``"loop.x"``,
    ``"loop.rz"``; for each weld, trace(R_a R_b^T) (3 when closed; its rotation rows vanish at a
    half-turn too, where the trace is -1)."""
    rows, labels, turns = [], [], []
    for loop in robot.loops:
        Ta, Tb = pose(robot, loop.frame_a), pose(robot, loop.frame_b)
        candidates = [(f"{loop.name}.{a}", Ta[k, 3] - Tb[k, 3]) for k, a in enumerate(_AXES)]
        if loop.kind == "weld":
            S = Ta[:3, :3] * Tb[:3, :3].T
            turns.append(_simp(S.trace(), q))
            S = (S - S.T) / 2  # vee of the skew part: the relative rotation's axis times its sine
            candidates += [(f"{loop.name}.r{a}", S[i, j]) for a, (i, j) in zip(_AXES, ((2, 1), (0, 2), (1, 0)))]
        for label, row in candidates:
            row = _simp(row, q)
            if row != 0:
                rows.append(row)
                labels.append(label)
    if not rows:
        raise ValueError(
            f"robot '{robot.name}': its loops {[lp.name for lp in robot.loops]} close identically (every closure row is "
            "zero for all q): the two frames of each are the same point of one body"
        )
    return rows, labels, turns


def _closed_configuration(phi, A, turns, q, parameters, seed: int = 0, tries: int = 24):
    """(q, values): a configuration where phi = 0 to 1e-11 and every weld's trace(R_a R_b^T) is
    positive (not a half-turn), for random parameter values in [0.5, 2] (Gauss-Newton from random
    starts); None when none is found."""
    rng = np.random.default_rng(seed)
    for _ in range(tries):
        values = {s: float(rng.uniform(0.5, 2.0)) for s in parameters}
        f = sp.lambdify([q], list(phi.xreplace(values)), "numpy")
        J = sp.lambdify([q], A.xreplace(values), "numpy")
        trace = sp.lambdify([q], [t.xreplace(values) for t in turns] or [1.0], "numpy")
        x = rng.uniform(-np.pi, np.pi, len(q))
        for _ in range(60):
            r = np.asarray(f(x), dtype=float)
            if np.abs(r).max() < 1e-11:
                if min(np.ravel(np.asarray(trace(x), dtype=float))) > 0:
                    return x, values
                break
            step = np.linalg.lstsq(np.asarray(J(x), dtype=float), r, rcond=None)[0]
            x = x - step
            if not np.all(np.isfinite(x)):
                break
    return None


def _readable(q, terms: int = 64):
    """Expanded, and in Fourier form (:func:`simplify_trig`) when at most ``terms`` terms long and
    exact (with floating-point coefficients the normal form costs far more than it shortens)."""

    def simplify(e):
        e = sp.expand(e)
        return simplify_trig(e, q) if len(sp.Add.make_args(e)) <= terms and not e.has(sp.Float) else e

    return simplify


def _rank(a) -> int:
    if a.size == 0:
        return 0
    s = np.linalg.svd(a, compute_uv=False)
    return int((s > 1e-8 * max(1.0, s[0])).sum())


class ReducedEquations(EquationsOfMotion):
    """The reduced equations of a closed chain in its independent coordinates ``q`` (``qd``, ``qdd``)
    through a velocity map qd_all = G(q_all) qd: M, C, g are functions of all the tree's coordinates,
    the dependent ones (``dependent``) on the loop's manifold, their rates ``G_d qd``
    (:meth:`configuration_rates`). Built by :func:`closed_loop_equations`."""

    def __init__(self, *args, dependent=(), dependent_rates=(), G=None, **kwargs):
        super().__init__(*args, **kwargs)
        self.dependent = list(dependent)
        self.dependent_rates = list(dependent_rates)
        self.G = G

    def configuration_rates(self) -> list[tuple]:
        return [*zip(self.q, self.qd), *zip(self.dependent, self.dependent_rates)]

    @property
    def parameters(self) -> list:
        return [s for s in super().parameters if s not in set(self.dependent)]


_RESULT_LATEX = r"M(q)\ddot{q} + C(q,\dot{q})\dot{q} + g(q) = \tau + A(q)^{T}\lambda,\ \phi(q) = 0"
_RESULT_TEXT = "M(q) qdd + C(q, qd) qd + g(q) = tau + A(q)^T lambda, phi(q) = 0"


class ClosedLoopEquations(EquationsOfMotion):
    """The equations of motion of a robot with closed loops (module docstring): the tree's M, C, g,
    friction in all n coordinates (``q``), the closure ``phi`` (k rows, labelled ``constraint_rows``),
    its Jacobian ``A``, the multipliers ``multipliers`` (lambda1..lambdak), and :attr:`reduced`, the
    equations in the independent coordinates (an :class:`EquationsOfMotion`), or None with
    :attr:`reduced_note` saying why. ``tau`` is the tree's M qdd + C qd + g + friction, which equals
    tau + A^T lambda on the closed chain."""

    result_latex = _RESULT_LATEX
    result_text = _RESULT_TEXT

    def __init__(
        self, tree: EquationsOfMotion, robot, phi, labels, turns=(), independent=None, solution=None, steps=True
    ):
        self.tree = tree
        self.turns = list(turns)
        super().__init__(
            tree.q,
            tree.qd,
            tree.qdd,
            lambda: tree.M,
            lambda: tree.C,
            lambda: tree.g,
            K=lambda: tree.K,
            P=lambda: tree.P,
            friction=lambda: tree.friction,
            christoffel=lambda: tree.christoffel,
            tau=lambda: tree.tau,
            steps=(lambda: self._all_steps()) if steps else None,
            name=tree.name,
            method=tree.method,
            latex_names=tree.latex_names,
            program=tree.program,
            model=tree.model,
            closed_form=None,
            derivation=tree.derivation,
            robot=robot,
            notes=tree.notes,
        )
        self.phi = sp.Matrix(phi)
        self.constraint_rows = list(labels)
        q = list(self.q)
        self.A = self.phi.jacobian(q).applyfunc(lambda e: _simp(e, q))
        k = len(self.phi)
        self.multipliers = sp.Matrix(sp.symbols(f"lambda1:{k + 1}", real=True))
        self._independent = independent
        self._solution = solution
        self.reduced_note = ""

    # ------------------------------------------------------------------ the reduced form
    def _symbol(self, c, what):
        by_name = {s.name: s for s in self.q}
        key = c if isinstance(c, str) else getattr(c, "name", None)
        if key not in by_name:
            raise ValueError(f"{what} {c!r} is not a joint coordinate of '{self.name}' (coordinates: {list(by_name)})")
        return by_name[key]

    @cached_property
    def reduced(self) -> EquationsOfMotion | None:
        """The equations in the independent coordinates (module docstring), built on first use; None
        when none exists here (:attr:`reduced_note` says why)."""
        if self._solution is not None:
            return self._explicit()
        try:
            return self._velocity_map()
        except _NoReduction as why:
            self.reduced_note = str(why)
            return None

    def _explicit(self) -> EquationsOfMotion:
        names = {s.name: s for s in [*self.q, *self.parameters]}
        solution = {
            self._symbol(k, "solution: key"): parse_expression(v, names) if isinstance(v, str) else sp.sympify(v)
            for k, v in dict(self._solution).items()
        }
        if self._independent is None:
            independent = [c for c in self.q if c not in solution]
        else:
            independent = [self._symbol(c, "independent coordinate") for c in self._independent]
        rank = self._closure_rank()
        if rank is not None and len(solution) != rank:
            raise ValueError(
                f"the loops of '{self.name}' fix {rank} coordinates (the rank of A on the closed chain): give {rank} "
                f"dependent coordinates in solution=, got {len(solution)} ({[c.name for c in solution]})"
            )
        tree = EquationsOfMotion(
            self.q, self.qd, self.qdd, self.M, self.C, self.g, P=self.P, friction=self.friction,
            christoffel=self.christoffel, name=self.name, latex_names=self.latex_names,
        )  # fmt: skip
        rows = self._independent_rows(independent, list(solution))
        closure = [self.phi[r] for r in rows]
        eom = closed_chain(
            tree, closure, independent, solution, name=f"{self.name} in {', '.join(map(str, independent))}"
        )
        eom.extra.update(independent=independent, dependent=list(solution), rows=rows)
        return eom

    def _closure_rank(self):
        found = self._closed
        return None if found is None else _rank(found[2])

    @cached_property
    def _closed(self):
        q = list(self.q)
        params = sorted(
            set().union(self.phi.free_symbols, *(sp.sympify(t).free_symbols for t in self.turns)) - set(q), key=str
        )
        found = _closed_configuration(self.phi, self.A, self.turns, q, params)
        if found is None:
            return None
        x, values = found
        return x, values, np.asarray(sp.lambdify([q], self.A.xreplace(values), "numpy")(x), dtype=float)

    def _independent_rows(self, independent, dependent) -> list[int]:
        """r rows of A whose columns of the dependent coordinates are independent at the closed
        configuration found (all rows when none was found)."""
        if self._closed is None:
            return list(range(len(self.phi)))
        A = self._closed[2]
        cols = [list(self.q).index(c) for c in dependent]
        rows: list[int] = []
        for r in range(A.shape[0]):
            if _rank(A[rows + [r]][:, cols]) > len(rows):
                rows.append(r)
        return rows

    def _partition(self):
        """(independent, dependent, rows) at a closed configuration (module docstring)."""
        if self._closed is None:
            raise _NoReduction(
                "no closed configuration was found (Gauss-Newton on phi from random starts, random parameter values "
                "in [0.5, 2]): the loops may not close for such values; give solution= with an explicit branch"
            )
        q = list(self.q)
        A = self._closed[2]
        rank = _rank(A)
        if self._independent is not None:
            independent = [self._symbol(c, "independent coordinate") for c in self._independent]
            dependent = [c for c in q if c not in independent]
            if len(dependent) != rank:
                raise ValueError(
                    f"the loops of '{self.name}' leave {len(q) - rank} degrees of freedom (n = {len(q)}, rank of A = "
                    f"{rank}): give {len(q) - rank} independent coordinates, got {len(independent)}"
                )
            if _rank(A[:, [q.index(c) for c in dependent]]) < rank:
                raise ValueError(
                    f"the closure cannot be solved for {[c.name for c in dependent]} at a closed configuration (their "
                    f"columns of A have rank below {rank}): choose other independent coordinates"
                )
        else:
            cols: list[int] = []
            for j in reversed(range(len(q))):
                if len(cols) < rank and _rank(A[:, cols + [j]]) > len(cols):
                    cols.append(j)
            dependent = [q[j] for j in sorted(cols)]
            independent = [c for c in q if c not in dependent]
        if not independent:
            raise _NoReduction(f"the loops of '{self.name}' leave no degree of freedom (rank of A = n = {len(q)})")
        return independent, dependent, self._independent_rows(independent, dependent)

    def _velocity_map(self) -> ReducedEquations:
        independent, dependent, rows = self._partition()
        q, qd = list(self.q), list(self.qd)
        simp = lambda e: _simp(e, q)
        idx = {c: k for k, c in enumerate(q)}
        ind, dep = [idx[c] for c in independent], [idx[c] for c in dependent]
        A_d = self.A.extract(rows, dep)
        A_i = self.A.extract(rows, ind)
        det = simp(A_d.det(method="berkowitz"))
        if det == 0:
            raise _NoReduction(f"det A_d = 0 identically for the dependent coordinates {[c.name for c in dependent]}")
        m = len(ind)
        # G = G_n / det: the independent rows det * I, the dependent ones -adj(A_d) A_i
        dep_rows = (-A_d.adjugate() * A_i).applyfunc(simp)
        G_n = sp.zeros(len(q), m)
        for a, k in enumerate(ind):
            G_n[k, a] = det
        for a, k in enumerate(dep):
            G_n[k, :] = dep_rows[a, :]
        v = sp.Matrix([qd[k] for k in ind])  # the independent rates
        rates_n = G_n * v  # qd_all * det
        on_map = {qd[k]: rates_n[k] / det for k in range(len(q))}

        Gt = G_n.T
        # each formed on first use: C_r's numerators are the large ones
        M_r = lambda: (Gt * self.M * G_n).applyfunc(simp) / det**2

        def C_r():
            # A G = 0 identically on the chosen rows, so dA/dt G + A dG/dt = 0: dG_i/dt = 0 and
            # dG_d/dt = -A_d^-1 (dA/dt G) = -adj(A_d) (Ad_n G_n) / det^3, Ad_n = det dA/dt along G v;
            # C(q, G v) = C(q, G_n v) / det (C is linear in qd)
            Ad_n = sp.zeros(len(rows), len(q))
            for k, c in enumerate(q):
                Ad_n += self.A.extract(rows, list(range(len(q)))).diff(c) * rates_n[k]
            Gd_n = -A_d.adjugate() * Ad_n * G_n
            Gdot_n = sp.zeros(len(q), m)
            for a, k in enumerate(dep):
                Gdot_n[k, :] = Gd_n[a, :]
            C_n = self.C.xreplace({qd[k]: rates_n[k] for k in range(len(q))})
            # the numerators expanded; their Fourier form only while small (simplify_trig of a
            # 4-coordinate weld's 300-term numerator takes minutes, of the numeric five-bar's 30 s)
            return (Gt * self.M * Gdot_n + det * Gt * C_n * G_n).applyfunc(_readable(q)) / det**4

        g_r = lambda: (Gt * self.g).applyfunc(simp) / det

        def friction_r():
            friction = self.friction.xreplace(on_map)
            return (Gt * friction).applyfunc(sp.expand) / det if any(friction) else sp.zeros(m, 1)

        G = G_n / det
        qdd = list(self.qdd)
        partition = [
            Step(
                "Independent coordinates and the velocity map qd = G(q) qd_i",
                f"Independent coordinates {', '.join(map(str, independent))}; from A qd = 0 (rows "
                f"{', '.join(self.constraint_rows[r] for r in rows)}), qd_d = -A_d^-1 A_i qd_i, so G stacks I and "
                "-A_d^-1 A_i = -adj(A_d) A_i / det(A_d) (coordinate partitioning, Wehage & Haug 1982).",
                [(name(r"\det A_d", "det A_d", "det A_d"), det), (of_q("G"), G)],
            ),
        ]
        reduced = ReducedEquations(
            independent,
            [qd[k] for k in ind],
            [qdd[k] for k in ind],
            M_r,
            C_r,
            g_r,
            P=self.P,
            friction=friction_r,
            steps=lambda: [*partition, result()],
            name=f"{self.name} in {', '.join(map(str, independent))}",
            method=self.method,
            latex_names=self.latex_names,
            dependent=dependent,
            dependent_rates=[rates_n[k] / det for k in dep],
            G=G,
            extra=dict(independent=independent, dependent=dependent, rows=rows, G=G, det=det),
        )

        def result():
            return Step(
                "Reduced equations G^T (M qdd + C qd + g) = G^T tau (A G = 0 removes lambda)",
                "qdd = G qdd_i + dG/dt qd_i: M_r = G^T M G, C_r = G^T (M dG/dt + C G), g_r = G^T g, tau_r = G^T tau, "
                "functions of all the coordinates on the closed chain.",
                [(_sub("M", "r"), reduced.M), (_sub("C", "r"), reduced.C), (_sub("g", "r"), reduced.g)],
            )

        return reduced

    # ------------------------------------------------------------------ steps, result, properties
    def _all_steps(self) -> list[Step]:
        steps = list(self.tree.steps)
        steps.append(
            Step(
                "Loop closure phi(q) = 0",
                "Each loop's two frames from the tree's forward kinematics, in the base: a point loop makes their "
                "origins coincide, a weld their axes too (rotation rows vee(R_a R_b^T - R_b R_a^T) / 2); rows that "
                f"vanish identically are left out. Rows: {', '.join(self.constraint_rows)}.",
                [(name(r"\phi", "phi", "phi"), self.phi)],
            )
        )
        steps.append(
            Step(
                "Constraint Jacobian A = dphi/dq and the multiplier form",
                "M qdd + C qd + g = tau + A^T lambda with A qdd + dA/dt qd = 0 (LaValle §13.4.3): lambda is the force "
                "(and moment) the loop applies to frame a's body, its opposite to frame b's.",
                [(of_q("A"), self.A), (name(r"\lambda", "lambda", "lambda"), self.multipliers)],
            )
        )
        if self.reduced is not None:
            steps += self.reduced.steps[-2:] if self._solution is None else self.reduced.steps[-1:]
        elif self.reduced_note:
            steps.append(Step("No reduced form", self.reduced_note))
        return steps

    def result_equations(self) -> list[tuple]:
        out = [
            (of_q("M"), self.M),
            (of_q("C", rates=True), self.C),
            (of_q("g"), self.g),
            (of_q("A"), self.A),
            (name(r"\phi(q)", "phi(q)", "phi"), self.phi),
        ]
        if self.reduced is not None:
            r = self.reduced
            out += [(_sub("M", "r"), r.M), (_sub("C", "r"), r.C), (_sub("g", "r"), r.g)]
        return out

    def system(self):
        """The same closed chain as a constrained :class:`LagrangianSystem` (the tree's K and P, the
        closure as holonomic constraints), solved numerically per evaluation; its multipliers are the
        negatives of :attr:`multipliers` (it writes A^T lambda on the left)."""
        tree = EquationsOfMotion(
            self.q, self.qd, self.qdd, self.M, self.C, self.g, P=self.P, friction=self.friction, name=self.name
        )
        return closed_chain_system(tree, list(self.phi), name=self.name)

    def check_properties(self, params=None, limits=None, samples: int = 256, starts: int = 12, seed: int = 0):
        """The properties of Spong §9.5 on :attr:`reduced` (:func:`kinedyn.analysis.prove_properties`),
        or a ValueError saying why there is no reduced model."""
        if self.reduced is None:
            raise ValueError(
                f"check_properties() runs on the reduced equations of a robot with loops, and '{self.name}' has none here: "
                f"{self.reduced_note}"
            )
        return proofs.prove_properties(
            self.reduced, params=params, limits=limits, samples=samples, starts=starts, seed=seed
        )

    def __repr__(self) -> str:
        return f"ClosedLoopEquations(name={self.name!r}, n={self.n}, constraints={len(self.phi)})"


class _NoReduction(Exception):
    """Why a closed chain has no reduced form here (kept in ``reduced_note``)."""


def _sub(f: str, sub: str) -> Name:
    """M_r(q) and the like."""
    return Name(
        f"{f}_{{{sub}}}(q)",
        f"{f}_{sub}(q)",
        f"<mrow><msub><mi>{f}</mi><mi>{sub}</mi></msub><mo>(</mo><mi>q</mi><mo>)</mo></mrow>",
    )


def closed_loop_equations(tree: EquationsOfMotion, robot, independent=None, solution=None, steps: bool = True):
    """:class:`ClosedLoopEquations` of ``robot`` (with loops) from its tree's equations ``tree``."""
    phi, labels, turns = loop_closure_rows(robot, list(tree.q))
    if solution is not None and not isinstance(solution, dict):
        raise ValueError(f"solution must be a dict {{dependent coordinate: expression}}, got {type(solution).__name__}")
    return ClosedLoopEquations(tree, robot, phi, labels, turns, independent=independent, solution=solution, steps=steps)
