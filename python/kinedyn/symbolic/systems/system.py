"""``LagrangianSystem``: equations of motion of any mechanism from its Lagrangian (LaValle §13.4,
Spong §9.1-9.3), not only joint-coordinate robots.

    L(q, qd, t) = K - P, or given directly
    d/dt dL/dqd - dL/dq = u - B(q, qd) - A(q)^T lambda                  (LaValle 13.136, 13.181, 13.173)
    natural systems (K = qd^T M(q) qd / 2, P = P(q)):
        M(q) qdd + C(q, qd) qd + g(q) + B(q, qd) + A(q)^T lambda = u     (LaValle 13.183; C by Spong 9.58)
    constraints: holonomic g_c(q) = 0 (A = d g_c / dq, LaValle 13.171) and Pfaffian A(q) qd = 0 (13.170).
    Multipliers, from A qdd + (dA/dt) qd = 0:
        lambda = (A M^-1 A^T)^-1 (A M^-1 (u - C qd - g - B) + (dA/dt) qd)
    (LaValle's eqs. 13.180 / 13.184 leave out the (dA/dt) qd term, which is not zero when A depends
    on q — for the particle on a sphere it is 2 |qd|^2 — and 13.180 also drops g; both kept here.)
    Hamiltonian form: p = dL/dqd (= M qd), H = p.qd - L, qdot = dH/dp, pdot = -dH/dq + u - B.
Numerically (``numeric``, ``numeric_accelerations``) the multipliers are never formed symbolically:
M, h, A and (dA/dt) qd are compiled entry by entry and the KKT system
    [M A^T; A 0] [qdd; lambda] = [u - h - B; -(dA/dt) qd]
is solved per evaluation (closed chains such as SymPy's four-bar in seconds, not hours).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

import numpy as np
import sympy as sp
from sympy.core.function import AppliedUndef

from ...expressions import parse_expression
from ...mechanical import MechanicalSystem
from ..derive.lagrange import latex_names
from ..derive.simplify import simplify_trig, textbook_form
from ..eom import EquationsOfMotion
from ..render.mathml import lagrangian, legacy_rate_names, name, of_q, rate_names  # q1 -> qdot1, qddot1
from ..steps import Step
from .system_properties import check_system_properties

__all__ = ["LagrangianSystem", "coordinates"]


def coordinates(names):
    """(q, qd): real symbols for generalised coordinates and their velocities, e.g.
    ``coordinates("p1 p2")`` -> ([p1, p2], [pdot1, pdot2]); ``coordinates("x")`` -> ([x], [xdot]) (SymPy
    prints them ṗ₁, ẋ)."""
    if isinstance(names, str):
        names = names.replace(",", " ").split()
    q = [sp.Symbol(n, real=True) for n in names]
    qd = [sp.Symbol(rate_names(n)[0], real=True) for n in names]
    return q, qd


def _as_list(value, what):
    if value is None:
        return []
    if isinstance(value, sp.MatrixBase):
        if value.shape[1] != 1 and value.shape[0] != 1:
            raise ValueError(
                f"{what} must be a vector (a list or a column), got a {value.shape[0]}x{value.shape[1]} matrix"
            )
        return list(value)
    if isinstance(value, sp.Basic):
        return [value]
    out = []
    for v in value:
        if isinstance(v, (list, tuple, sp.MatrixBase)):
            raise ValueError(f"{what} must be a flat list of scalar expressions, got a nested entry {v!r}")
        out.append(sp.sympify(v))
    return out


def _scalar(value, what: str, names: dict) -> sp.Expr:
    """One scalar SymPy expression from an expression, a number or a string, or a ValueError naming
    ``what``; in a string the coordinate and velocity names are the system's own symbols (``names``)."""
    try:
        e = parse_expression(value, names) if isinstance(value, str) else sp.sympify(value)
    except (sp.SympifyError, TypeError, ValueError) as err:
        raise ValueError(f"{what} could not be read as an expression: {value!r} ({err})") from None
    e = sp.sympify(e)
    if isinstance(e, sp.MatrixBase) and e.shape == (1, 1):
        e = e[0, 0]
    if not isinstance(e, sp.Expr):
        raise ValueError(f"{what} must be one scalar expression, got {type(e).__name__} {value!r}")
    if e.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        raise ValueError(f"{what} contains NaN or infinity: {e}")
    return e


class LagrangianSystem:
    """A mechanical system described by generalised coordinates and its Lagrangian.

    ``LagrangianSystem(q, K=..., P=...)``, ``LagrangianSystem(q, L=...)``, or
    :meth:`from_bodies`. ``q``: symbols (or names, or ``dynamicsymbols`` functions of time);
    ``qd``: their velocity symbols (default from :func:`coordinates`' naming); ``forces``: generalised
    forces u (default symbols u1..un); ``B``: non-conservative forces B(q, qd) (on the left side, as
    friction); ``holonomic``: expressions g_c(q) = 0; ``pfaffian``: a k x n matrix A(q), A qd = 0.
    """

    def __init__(
        self,
        q,
        K=None,
        P=0,
        *,
        L=None,
        qd=None,
        t=None,
        forces=None,
        B=None,
        holonomic=None,
        pfaffian=None,
        name: str = "",
    ):
        q = list(q) if not isinstance(q, (str, sp.Basic)) else [q]
        if not q:
            raise ValueError("a Lagrangian system needs at least one generalised coordinate")
        self.t = t if t is not None else sp.Symbol("t", real=True)
        fun_rep = {}
        coords = []
        for c in q:
            if isinstance(c, str):
                if not re.fullmatch(r"[A-Za-z_]\w*", c):
                    raise ValueError(f"coordinate name {c!r} is not a valid symbol name")
                c = sp.Symbol(c, real=True)
            if isinstance(c, AppliedUndef):  # q(t) from dynamicsymbols
                self.t = c.args[0]
                sym = sp.Symbol(c.func.__name__, real=True)
                fun_rep[c] = sym
                c = sym
            if not isinstance(c, sp.Symbol):
                raise ValueError(
                    f"generalised coordinate {c!r} is not a symbol: give plain SymPy symbols (or names), e.g. sympy.symbols('q1 q2')"
                )
            coords.append(c)
        if len(set(coords)) != len(coords):
            raise ValueError(f"generalised coordinates repeat: {coords}")
        self.q = coords
        self.n = n = len(coords)
        if qd is None:
            qd = [sp.Symbol(rate_names(c.name)[0], real=True) for c in coords]
        qd = list(qd)
        if len(qd) != n or not all(isinstance(v, sp.Symbol) for v in qd):
            raise ValueError(f"qd must be {n} symbols, one velocity per coordinate, got {qd!r}")
        self.qd = qd
        self.qdd = [sp.Symbol(rate_names(c.name)[1], real=True) for c in coords]
        # replace q(t), q'(t), q''(t) by symbols
        rep = {}
        for f, sym in fun_rep.items():
            i = coords.index(sym)
            rep[sp.Derivative(f, self.t, 2)] = self.qdd[i]
            rep[sp.Derivative(f, self.t)] = qd[i]
        self._rep = (rep, fun_rep)
        sub = self._sub
        if L is None and K is None:
            raise ValueError("give the kinetic energy K (and potential energy P) or the Lagrangian L")
        if L is not None and K is not None:
            raise ValueError("give either K and P or L, not both")
        # in expressions given as strings, coordinate and velocity names are these symbols
        self._names = names = {v.name: v for v in [*coords, *qd, *self.qdd, self.t] if isinstance(v, sp.Symbol)}
        for c, v, a in zip(coords, qd, self.qdd):
            for old_name, sym in zip(legacy_rate_names(c.name), (v, a)):
                names.setdefault(old_name, sym)
        # SymPy expressions; K and P None when the Lagrangian was given
        self.K: Any = None
        self.P: Any = None
        if K is not None:
            self.K = sub(_scalar(K, "the kinetic energy K", names))
            self.P = sub(_scalar(P, "the potential energy P", names))
            self.L: Any = self.K - self.P
        else:
            self.L = sub(_scalar(L, "the Lagrangian L", names))
        for c, v in zip(coords, qd):
            if not self.L.has(v):
                src = "kinetic energy K" if K is not None else "Lagrangian L"
                raise ValueError(
                    f"coordinate {c}: its velocity {v} does not appear in the {src}, so the mass matrix is "
                    f"singular (free symbols of {src}: {sorted(map(str, (self.K if K is not None else self.L).free_symbols))}); "
                    "was the coordinate misspelt, or is the energy written with other velocity symbols?"
                )
        self.u = (
            sp.Matrix(sp.symbols(f"u1:{n + 1}", real=True))
            if forces is None
            else sp.Matrix(_as_list(sub(forces), "forces"))
        )
        if len(self.u) != n:
            raise ValueError(f"forces must have {n} entries (one per coordinate), got {len(self.u)}")
        self.B = sp.zeros(n, 1) if B is None else sp.Matrix(_as_list(sub(B), "B"))
        if len(self.B) != n:
            raise ValueError(f"non-conservative forces B must have {n} entries, got {len(self.B)}")
        self.holonomic = _as_list(sub(holonomic), "holonomic constraints")
        state = set(qd) | set(self.qdd)
        for e in self.holonomic:
            if e.free_symbols & state:
                raise ValueError(
                    f"holonomic constraint {e} = 0 depends on velocities; write it as a Pfaffian constraint A(q) qd = 0"
                )
        rows = []
        if self.holonomic:
            rows.append(sp.Matrix([[sp.diff(e, c) for c in coords] for e in self.holonomic]))
        if pfaffian is not None:
            A = sp.Matrix(sub(sp.Matrix(pfaffian))) if not isinstance(pfaffian, sp.MatrixBase) else sub(pfaffian)
            if A.shape[1] != n:
                raise ValueError(
                    f"Pfaffian constraint matrix A must have shape (k, {n}) for A(q) qd = 0, got {A.shape}"
                )
            if A.free_symbols & state:
                raise ValueError("Pfaffian constraint matrix A(q) must not depend on velocities")
            rows.append(A)
        self.A = sp.Matrix.vstack(*rows) if rows else sp.zeros(0, n)
        self.lam = (
            sp.Matrix(sp.symbols(f"lambda1:{self.A.shape[0] + 1}", real=True)) if self.A.shape[0] else sp.zeros(0, 1)
        )
        self.name = name

    def _sub(self, e):
        if e is None:
            return None
        rep, fun_rep = self._rep
        if isinstance(e, (list, tuple)):
            return [self._sub(x) for x in e]
        e = sp.sympify(parse_expression(e, self._names)) if isinstance(e, str) else sp.sympify(e)
        if rep:
            e = (
                e.xreplace(rep).xreplace(fun_rep)
                if not isinstance(e, sp.MatrixBase)
                else e.xreplace(rep).xreplace(fun_rep)
            )
        return e

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_bodies(cls, q, bodies: Sequence[dict], gravity=None, qd=None, **kwargs) -> LagrangianSystem:
        """Bodies given by expressions of the coordinates (Spong eqs. 9.41, 9.48):

        each body is a dict with ``mass``, ``position`` (centre of mass, 2 or 3 coordinates),
        optionally ``inertia`` (a scalar for planar motion or a 3x3 matrix, about the centre of mass
        in the axes of ``angular_velocity``) and ``angular_velocity`` (a scalar or a 3-vector,
        expressed in those axes, as an expression of qd). ``gravity``: the gravity vector (same
        dimension as the positions), e.g. (0, -g). K = sum m |v_c|^2 / 2 + w^T I w / 2, P = -sum m gravity . r_c.
        """
        q_syms, qd_syms = (list(q), list(qd)) if qd is not None else (list(q), None)
        qs = [sp.Symbol(c, real=True) if isinstance(c, str) else c for c in q_syms]
        vs = qd_syms or [sp.Symbol(rate_names(c.name)[0], real=True) for c in qs]
        K = sp.Integer(0)
        P = sp.Integer(0)
        for k, body in enumerate(bodies):
            unknown = set(body) - {"mass", "position", "inertia", "angular_velocity", "name"}
            if unknown:
                raise ValueError(f"body {k + 1}: unknown keys {sorted(unknown)}")
            m = sp.sympify(body["mass"])
            r = sp.Matrix(body["position"])
            v = r.jacobian(qs) * sp.Matrix(vs)
            K += m * (v.T * v)[0, 0] / 2
            if gravity is not None:
                gv = sp.Matrix(gravity)
                if gv.shape != r.shape:
                    raise ValueError(f"body {k + 1}: gravity has {len(gv)} components but the position has {len(r)}")
                P -= m * (gv.T * r)[0, 0]
            if "angular_velocity" in body:
                w = body["angular_velocity"]
                I = body.get("inertia", 0)
                if isinstance(w, (list, tuple, sp.MatrixBase)):
                    w = sp.Matrix(w)
                    K += (w.T * sp.Matrix(I) * w)[0, 0] / 2
                else:
                    K += sp.sympify(I) * sp.sympify(w) ** 2 / 2
        return cls(qs, K=textbook_form(K, qs), P=textbook_form(P, qs), qd=vs, **kwargs)

    # ------------------------------------------------------------------ derivation
    def _dt(self, e):
        """Total time derivative: sum de/dq qd + de/dqd qdd + de/dt."""
        out = sp.diff(e, self.t)
        for c, v, a in zip(self.q, self.qd, self.qdd):
            out += sp.diff(e, c) * v + sp.diff(e, v) * a
        return out

    def _simp(self, e):
        return simplify_trig(sp.expand(e), self._trig_coords(), prismatic=self._poly_coords())

    def _poly_coords(self):
        """Coordinates that appear outside sin/cos somewhere (treated as polynomial variables)."""
        out = []
        exprs = [self.L] + list(self.B) + list(self.A) + self.holonomic
        for c in self.q:
            for e in exprs:
                stripped = e.replace(lambda x: isinstance(x, (sp.sin, sp.cos)), lambda x: sp.Integer(1))
                if stripped.has(c):
                    out.append(c)
                    break
        return out

    def _trig_coords(self):
        return list(self.q)

    def euler_lagrange(self):
        """[d/dt dL/dqd_k - dL/dq_k for k] (LaValle eq. 13.118 / 13.124), unsimplified."""
        return [self._dt(sp.diff(self.L, v)) - sp.diff(self.L, c) for c, v in zip(self.q, self.qd)]

    def is_natural(self) -> bool:
        """True when L = qd^T M(q) qd / 2 - P(q) (kinetic energy quadratic in qd, no time)."""
        M = sp.hessian(self.L, self.qd)
        if M.free_symbols & (set(self.qd) | {self.t}):
            return False
        zero = {v: 0 for v in self.qd}
        rest = sp.expand(self.L - (sp.Matrix(self.qd).T * M * sp.Matrix(self.qd))[0, 0] / 2 - self.L.subs(zero))
        return rest == 0 and not self.L.subs(zero).has(self.t)

    def equations_of_motion(self, simplify: bool = True) -> EquationsOfMotion:
        """M, C, g (natural systems; otherwise C = 0 and g holds the whole bias h(q, qd)), with the
        steps of the derivation; ``extra`` holds the constraint Jacobian A, multipliers and forces."""
        n = self.n
        simp = self._simp if simplify else sp.expand
        EL = self.euler_lagrange()
        M = sp.hessian(self.L, self.qd).applyfunc(simp)
        zero_acc = {a: 0 for a in self.qdd}
        h = sp.Matrix([sp.expand(e.subs(zero_acc)) for e in EL])
        natural = self.is_natural()
        if natural:
            P = -self.L.subs({v: 0 for v in self.qd})
            g = sp.Matrix([simp(sp.diff(P, c)) for c in self.q])
            dM = [[[sp.diff(M[a, b], c) for c in self.q] for b in range(n)] for a in range(n)]
            chris = [
                [[simp((dM[k][j][i] + dM[k][i][j] - dM[i][j][k]) / 2) for k in range(n)] for j in range(n)]
                for i in range(n)
            ]
            C = sp.Matrix(n, n, lambda k, j: simp(sum(chris[i][j][k] * self.qd[i] for i in range(n))))
            K = simp((sp.Matrix(self.qd).T * M * sp.Matrix(self.qd))[0, 0] / 2)
            P = simp(P)
        else:
            g = h.applyfunc(simp)
            C = sp.zeros(n, n)
            chris = None
            K, P = None, None
        steps = [
            Step("Lagrangian", "L = K - P" if self.K is not None else "given directly", [(lagrangian(), self.L)]),
            Step(
                "Euler-Lagrange equations d/dt dL/dqd_k - dL/dq_k = u_k - B_k - (A^T lambda)_k",
                "(LaValle eqs. 13.118, 13.181, 13.173)",
                [
                    (name(f"E_{{{k + 1}}}", f"E_{k + 1}", "E", f"{k + 1}"), self._textbook(simp(e)))
                    for k, e in enumerate(EL)
                ],
            ),
        ]
        if self.A.shape[0]:
            steps.append(
                Step(
                    "Constraints A(q) qd = 0",
                    "holonomic constraints differentiated (LaValle 13.171) and Pfaffian rows",
                    [(of_q("A"), self.A)],
                )
            )
        eom = EquationsOfMotion(
            self.q,
            self.qd,
            self.qdd,
            M,
            C,
            g,
            K=K if natural else None,  # no potential: K is qd^T M qd / 2 from M, P undefined
            P=P if natural else None,
            friction=self.B,
            christoffel=chris,
            steps=steps,
            name=self.name,
            method="lagrange",
            latex_names=latex_names(self.q, self.qd, self.qdd),
            extra=dict(A=self.A, multipliers=self.lam, forces=self.u, natural=natural, bias=h),
        )
        return eom

    def _textbook(self, e):
        return textbook_form(e, self._trig_coords(), self._poly_coords())

    def multipliers(self, u=None, M=None, bias=None):
        """lambda = (A M^-1 A^T)^-1 (A M^-1 (u - h - B) + (dA/dt) qd), h = C qd + g (see module doc);
        simplified to textbook size (:func:`kinedyn.symbolic.simplify.textbook_form`) when called
        without ``M`` and ``bias`` (phase_space passes them and skips that)."""
        if M is None and bias is None:
            return self._textbook(
                self.multipliers(
                    u,
                    sp.hessian(self.L, self.qd),
                    sp.Matrix([e.subs({a: 0 for a in self.qdd}) for e in self.euler_lagrange()]),
                )
            )
        if not self.A.shape[0]:
            return sp.zeros(0, 1)
        u = self.u if u is None else sp.Matrix(u)
        if M is None:
            M = sp.hessian(self.L, self.qd)
        if bias is None:
            bias = sp.Matrix([e.subs({a: 0 for a in self.qdd}) for e in self.euler_lagrange()])
        Ad = self.A.applyfunc(self._dt)
        # M^-1 applied by LU solves, never by forming the inverse (M.inv() of a closed chain's M hangs)
        Minv_AT = M.LUsolve(self.A.T)
        S = self.A * Minv_AT
        rhs = Minv_AT.T * (u - bias - self.B) + Ad * sp.Matrix(self.qd)
        return S.LUsolve(rhs)

    def phase_space(self, u=None, simplify: bool = False):
        """(x, f): x = (q, qd), x' = f(x) = (qd, M^-1 (u - h - B - A^T lambda)) with the multipliers
        eliminated (LaValle 13.148 generalised). Constrained systems: f is the qdd part of the KKT
        system's symbolic solution, correct but large for closed chains (SymPy's four-bar: ~4e5
        operations per entry); to simulate, use :meth:`numeric`, which solves it per evaluation."""
        u = self.u if u is None else sp.Matrix(u)
        M = sp.hessian(self.L, self.qd)
        bias = sp.Matrix([e.subs({a: 0 for a in self.qdd}) for e in self.euler_lagrange()])
        rhs = u - bias - self.B
        k = self.A.shape[0]
        if k:
            # the KKT system [M A^T; A 0] [qdd; lambda] = [u - h - B; -(dA/dt) qd] solved by one LU
            # elimination (unsimplified; ~3 s for SymPy's four-bar, where inverting M did not finish)
            drift = self.A.applyfunc(self._dt) * sp.Matrix(self.qd)
            kkt = sp.Matrix.vstack(sp.Matrix.hstack(M, self.A.T), sp.Matrix.hstack(self.A, sp.zeros(k, k)))
            qdd = kkt.LUsolve(sp.Matrix.vstack(rhs, -drift))[: self.n, :]
        else:
            qdd = M.LUsolve(rhs)
        if simplify:
            qdd = qdd.applyfunc(sp.simplify)
        return sp.Matrix.vstack(sp.Matrix(self.q), sp.Matrix(self.qd)), sp.Matrix.vstack(sp.Matrix(self.qd), qdd)

    def energy(self):
        """The energy function H = sum qd_k dL/dqd_k - L (= K + P for natural systems)."""
        return sp.expand(sum(v * sp.diff(self.L, v) for v in self.qd) - self.L)

    def hamiltonian(self):
        """(p, H(q, p), qdot, pdot): p = dL/dqd, Hamilton's equations qdot = dH/dp, pdot = -dH/dq + u - B
        (natural systems; p = M qd)."""
        if not self.is_natural():
            raise ValueError(
                "hamiltonian(): the Legendre transform is formed here for natural systems (L = qd^T M qd / 2 - P)"
            )
        p = sp.Matrix([sp.Symbol(f"p_{c.name}", real=True) for c in self.q])  # momentum conjugate to each q
        # M^-1 = adj(M) / det(M), each entry and the determinant simplified on their own: the quotient
        # p^T adj(M) p / (2 det M) is the textbook's form, and simplifying it whole (one fraction of
        # a few hundred operations, the five-bar's) takes minutes
        M = sp.hessian(self.L, self.qd).applyfunc(self._textbook)
        det = self._textbook(M.det())
        if det == 0:
            raise ValueError(
                "hamiltonian(): the inertia matrix d2L/dqd2 is singular (det = 0), so p = M qd cannot be inverted"
            )
        adj = M.adjugate().applyfunc(self._textbook)
        P = self._textbook(-self.L.subs({v: 0 for v in self.qd}))
        H = self._textbook(sp.expand((p.T * adj * p)[0, 0])) / (2 * det) + P  # H = p^T M^-1 p / 2 + P
        qdot = sp.Matrix(
            [self._textbook(sp.expand((adj[i, :] * p)[0, 0])) / det for i in range(self.n)]
        )  # dH/dp = M^-1 p
        B = self.B.subs(dict(zip(self.qd, qdot)))
        pdot = sp.Matrix([-sp.diff(H, c) for c in self.q]) + self.u - B  # from the simplified H
        return p, H, qdot, pdot

    def _has_time(self) -> bool:
        return any(sp.sympify(e).has(self.t) for e in [self.L, *self.B, *self.A, *self.holonomic])

    def _kkt_system(self, values: dict, baumgarte: tuple):
        """The numeric pieces of the KKT system in one compiled function (shared subexpressions):
        M = d2L/dqd2 (evaluated at the state: it may depend on qd for a Lagrangian that is not
        quadratic), h = sum_j d2L/dqd dq_j qd_j - dL/dq + B (the Euler-Lagrange bias of a
        time-invariant L, without forming its qdd terms), A, (dA/dt) qd = d(A qd)/dq qd, g_c."""
        q, qd = list(self.q), list(self.qd)
        n, k, k_h = self.n, self.A.shape[0], len(self.holonomic)
        dL_dqd = sp.Matrix([sp.diff(self.L, v) for v in qd])
        M = dL_dqd.jacobian(qd)
        h = dL_dqd.jacobian(q) * sp.Matrix(qd) - sp.Matrix([sp.diff(self.L, c) for c in q]) + self.B
        drift = (self.A * sp.Matrix(qd)).jacobian(q) * sp.Matrix(qd) if k else sp.zeros(0, 1)
        phi = sp.Matrix(self.holonomic) if k_h else sp.zeros(0, 1)
        parts = [M, h, self.A, drift, phi]
        state = set(q) | set(qd)
        free = set().union(*(m.free_symbols for m in parts)) - state
        missing = sorted(str(s) for s in free if str(s) not in values)
        if missing:
            raise ValueError(
                f"{self.name or 'the Lagrangian system'}: give values for the parameters {missing} (params={{'name': value}})"
            )
        numbers = {s: values[str(s)] for s in free}
        parts = [m.xreplace(numbers) for m in parts]
        together = sp.lambdify([q, qd], parts, modules="numpy", cse=True)

        def terms(qv, qdv):
            M_, h_, A_, d_, p_ = together(qv, qdv)
            return (
                np.asarray(M_, dtype=float).reshape(n, n),
                np.asarray(h_, dtype=float).reshape(n),
                np.asarray(A_, dtype=float).reshape(k, n),
                np.asarray(d_, dtype=float).reshape(k),
                np.asarray(p_, dtype=float).reshape(k_h) if k_h else None,
            )

        zero = np.zeros(n)
        constraint: dict = {}
        if k:
            constraint = dict(
                constraint_jacobian=lambda x: terms(x, zero)[2], constraint_drift=lambda x, v: terms(x, v)[3]
            )
            if k_h:
                constraint["constraint"] = lambda x: terms(x, zero)[4]
        return MechanicalSystem(
            n=n,
            mass_matrix=lambda x: terms(x, zero)[0],
            bias=lambda x, v: terms(x, v)[1],
            terms=terms,
            names=tuple(c.name for c in q),
            name=self.name or "Lagrangian system",
            baumgarte=baumgarte,
            **constraint,
        )

    def numeric_accelerations(self, params=None, u=None, baumgarte=None):
        """``accelerations(t, q, qd) -> (qdd, lambda)``: the constrained equations of motion solved
        numerically at each call, never inverted symbolically (so closed chains such as SymPy's
        four-bar take milliseconds to set up). The symbolic parts are formed entry by entry and
        compiled with ``lambdify`` (common subexpressions shared): M = d2L/dqd2, the bias
        h = (d/dt dL/dqd - dL/dq)|qdd=0 + B, the constraint Jacobian A and its drift (dA/dt) qd; then
        NumPy solves the KKT system of ``M qdd + h + A^T lambda = u`` with ``A qdd + (dA/dt) qd = 0``::

            [ M  A^T ] [ qdd    ]   [ u - h                                    ]
            [ A  0   ] [ lambda ] = [ -(dA/dt) qd - 2 alpha A qd - beta^2 g_c  ]

        ``baumgarte = (alpha, beta)`` adds Baumgarte's stabilisation (constraint errors decay as
        e'' + 2 alpha e' + beta^2 e = 0 instead of drifting; g_c only for the holonomic rows); the
        default ``None`` is (0, 0): the exact constrained dynamics, the same q̈ and λ as
        :meth:`phase_space` and :meth:`multipliers`. ``u``: generalised forces, expressions of t, q,
        qd (default zero). Parameters are matched by name from ``params``. Time-dependent
        Lagrangians or constraints are not handled here (a ValueError says so)."""
        if self._has_time():
            raise ValueError(
                "numeric_accelerations() handles time-invariant Lagrangians and constraints; this system's L, B or constraints depend on t"
            )
        values = {str(k): v for k, v in dict(params or {}).items()}
        alpha, beta = (0.0, 0.0) if baumgarte is None else baumgarte
        mech = self._kkt_system(values, (float(alpha), float(beta)))
        forces = sp.zeros(self.n, 1) if u is None else sp.Matrix(_as_list(self._sub(u), "forces"))
        if len(forces) != self.n:
            raise ValueError(f"forces u must have {self.n} entries (one per coordinate), got {len(forces)}")
        forces = forces.xreplace({s: values[str(s)] for s in forces.free_symbols if str(s) in values})
        left = forces.free_symbols - set(self.q) - set(self.qd) - {self.t}
        if left:
            raise ValueError(f"give values for the parameters {sorted(map(str, left))} of the forces u")
        u_fn = sp.lambdify([self.t, list(self.q), list(self.qd)], list(forces), "numpy")
        n = self.n

        def accelerations(t, q, qd):
            q = np.asarray(q, dtype=float).reshape(n)
            qd = np.asarray(qd, dtype=float).reshape(n)
            try:
                return mech.accelerations(q, qd, np.asarray(u_fn(t, q, qd), dtype=float).reshape(n))
            except np.linalg.LinAlgError:
                raise ValueError(
                    f"{self.name or 'the Lagrangian system'}: the constrained equations are singular at q = {q.tolist()} "
                    "(M singular, or the constraint Jacobian A loses rank: a singular configuration of the mechanism)"
                ) from None

        return accelerations

    def numeric(self, params=None, u=None, baumgarte=None):
        """A NumPy right-hand side f(t, x) for scipy.integrate.solve_ivp (x = (q, qd)), with the
        parameters and forces substituted from ``params`` / ``u`` (default forces zero).

        Time-invariant systems (constrained ones included) are solved numerically per call through
        :meth:`numeric_accelerations` (KKT system, optional Baumgarte stabilisation); systems whose
        Lagrangian depends on t use the symbolic :meth:`phase_space`."""
        if not self._has_time():
            accelerations = self.numeric_accelerations(params, u, baumgarte)
            n = self.n

            def rhs(t, y):
                y = np.asarray(y, dtype=float)
                return np.concatenate([y[n:], accelerations(t, y[:n], y[n:])[0]])

            return rhs
        if baumgarte is not None:
            raise ValueError("Baumgarte stabilisation needs a time-invariant system (see numeric_accelerations)")
        params = {sp.Symbol(k, real=True) if isinstance(k, str) else k: v for k, v in dict(params or {}).items()}
        # match parameter symbols by name (users may create them without assumptions)
        free = {}
        x, f = self.phase_space(u=sp.zeros(self.n, 1) if u is None else u)
        names = {str(k): v for k, v in params.items()}
        for s in f.free_symbols - set(self.q) - set(self.qd):
            if str(s) in names:
                free[s] = names[str(s)]
        f = f.subs(free)
        left = f.free_symbols - set(self.q) - set(self.qd) - {self.t}
        if left:
            raise ValueError(f"give values for the parameters {sorted(map(str, left))}")
        fn = sp.lambdify([self.t, list(x)], list(f), "numpy")
        return lambda t, y: np.array(fn(t, y), dtype=float)

    def change_coordinates(self, A, coordinates=None, name: str = "") -> LagrangianSystem:
        """The same system in coordinates p with q = A p (A constant, n x n, invertible; qd = A pd):
        L_p(p, pd) = L(A p, A pd); generalised forces and B map by A^T (virtual work:
        u . dq = (A^T u) . dp); holonomic constraints g_c(A p) and Pfaffian rows A_c(A p) A.
        ``coordinates``: names of p (default p1..pn). See also
        :func:`kinedyn.symbolic.mechanisms.change_coordinates` for a robot's equations of motion."""
        n = self.n
        A = sp.Matrix(A)
        if A.shape != (n, n):
            raise ValueError(f"the map q = A p needs a square A of shape ({n}, {n}) for {n} coordinates, got {A.shape}")
        if A.free_symbols & (set(self.q) | set(self.qd) | {self.t}):
            raise ValueError("A must be constant (no coordinates, velocities or time in it)")
        if sp.simplify(A.det()) == 0:
            raise ValueError(f"A = {A.tolist()} is singular: the new coordinates would not determine q")
        if coordinates is None:
            coordinates = [f"p{i + 1}" for i in range(n)]
        elif isinstance(coordinates, str):
            coordinates = coordinates.replace(",", " ").split()
        p = [sp.Symbol(c, real=True) if isinstance(c, str) else c for c in coordinates]
        pd = [sp.Symbol(rate_names(c.name)[0], real=True) for c in p]
        if len(p) != n:
            raise ValueError(f"coordinates must name {n} coordinates, got {len(p)}")
        taken = {s.name for e in [self.L, *self.u, *self.B, *self.A] for s in sp.sympify(e).free_symbols} - {
            c.name for c in self.q + self.qd
        }
        clash = sorted({s.name for s in p + pd} & taken)
        if clash:
            raise ValueError(
                f"the new coordinates' names {clash} are already symbols of the system: choose other names"
            )
        rep = {**dict(zip(self.q, A * sp.Matrix(p))), **dict(zip(self.qd, A * sp.Matrix(pd)))}
        pfaffian = None
        if self.A.shape[0] > len(self.holonomic):
            pfaffian = self.A[len(self.holonomic) :, :].xreplace(rep) * A
        return LagrangianSystem(
            p,
            L=sp.expand(self.L.xreplace(rep)),
            qd=pd,
            t=self.t,
            forces=list(A.T * self.u.xreplace(rep)),
            B=list(A.T * self.B.xreplace(rep)),
            holonomic=[sp.expand(e.xreplace(rep)) for e in self.holonomic] or None,
            pfaffian=pfaffian,
            name=name or f"{self.name} in coordinates {', '.join(c.name for c in p)}",
        )

    def check_properties(self, params=None, **kwargs):
        """M symmetric and dM/dt - 2C skew-symmetric proven by exact simplification, M positive
        definite and passivity measured: :func:`kinedyn.analysis.check_system_properties`."""
        return check_system_properties(self, params, **kwargs)

    def __repr__(self) -> str:
        return f"LagrangianSystem(q={self.q}, constraints={self.A.shape[0]})"
