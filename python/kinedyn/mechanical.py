"""Numeric mechanical systems for simulation, constrained ones included.

:class:`MechanicalSystem` is the numeric interface the integrators need from anything that is not
a :class:`kinedyn.Robot`: callables for ``M(q)``, the bias ``h(q, qd)`` (everything on the left of
``M qdd + h = u`` except ``M qdd``: Coriolis, gravity, friction), and optionally constraints
``A(q) qd = 0`` with their drift term ``dA/dt qd`` and the holonomic residuals ``phi(q)`` (the first
rows of ``A`` are ``d phi / dq``). :meth:`MechanicalSystem.from_lagrangian` compiles a symbolic
:class:`kinedyn.symbolic.LagrangianSystem` into one (SymPy ``lambdify`` with common subexpressions).

Constrained accelerations (LaValle §13.4.3 with the ``dA/dt qd`` term that eqs. 13.180/13.184 omit,
see docs/seed-notes.md §2.12) and Baumgarte stabilisation (J. Baumgarte, "Stabilization of
constraints and integrals of motion in dynamical systems", Comput. Methods Appl. Mech. Eng. 1,
1972, 1-16): instead of ``A qdd + dA/dt qd = 0`` impose

    A qdd + dA/dt qd + 2 alpha (A qd) + beta^2 phi = 0,

so that the constraint error obeys ``e'' + 2 alpha e' + beta^2 e = 0`` and decays instead of
drifting (``phi`` only for the holonomic rows). With the multipliers ``lambda`` this is one linear
system (the KKT matrix of the constrained Euler-Lagrange equations ``M qdd + h + A^T lambda = u``)::

    [ M   A^T ] [ qdd    ]   [ u - h                                   ]
    [ A   0   ] [ lambda ] = [ -dA/dt qd - 2 alpha A qd - beta^2 phi    ]
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["MechanicalSystem"]


@dataclass
class MechanicalSystem:
    """A mechanical system given numerically (one state at a time).

    ``mass_matrix(q) -> (n, n)``; ``bias(q, qd) -> (n,)``; optional ``constraint_jacobian(q) ->
    (k, n)``, ``constraint_drift(q, qd) -> (k,)`` (= dA/dt qd), ``constraint(q) -> (k_h,)`` (holonomic
    residuals, rows 0..k_h-1 of A), ``energy(q, qd)`` (H), ``kinetic_energy``, ``potential_energy``,
    ``points(q) -> (m, 2 or 3)`` (positions to draw in an animation). ``baumgarte = (alpha, beta)``.
    """

    n: int
    mass_matrix: Callable
    bias: Callable
    constraint_jacobian: Callable | None = None
    constraint_drift: Callable | None = None
    constraint: Callable | None = None
    energy: Callable | None = None
    kinetic_energy: Callable | None = None
    potential_energy: Callable | None = None
    points: Callable | None = None
    names: Sequence[str] = field(default_factory=tuple)
    name: str = "system"
    baumgarte: tuple = (10.0, 10.0)
    #: optional fast path: ``terms(q, qd) -> (M, h, A, dA/dt qd, phi)`` in one call
    terms: Callable | None = None

    def __post_init__(self):
        if not self.names:
            self.names = tuple(f"q{i + 1}" for i in range(self.n))
        if (self.constraint_jacobian is None) != (self.constraint_drift is None):
            raise ValueError("give both constraint_jacobian (A(q)) and constraint_drift (dA/dt qd), or neither")

    @property
    def constrained(self) -> bool:
        return self.constraint_jacobian is not None

    def accelerations(self, q, qd, u, baumgarte: tuple | None = None):
        """(qdd, lambda) solving the (Baumgarte-stabilised) constrained equations of motion."""
        if self.terms is not None:
            M, h, A, drift, phi = self.terms(q, qd)
        else:
            M, h = self.mass_matrix(q), self.bias(q, qd)
            A = drift = phi = None
            if self.constraint_jacobian is not None and self.constraint_drift is not None:  # both or neither
                A, drift = self.constraint_jacobian(q), self.constraint_drift(q, qd)
                phi = self.constraint(q) if self.constraint is not None else None
        M = np.asarray(M, dtype=float).reshape(self.n, self.n)
        rhs = np.asarray(u, dtype=float) - np.asarray(h, dtype=float).reshape(self.n)
        if not self.constrained:
            return np.linalg.solve(M, rhs), np.zeros(0)
        alpha, beta = self.baumgarte if baumgarte is None else baumgarte
        A = np.atleast_2d(np.asarray(A, dtype=float))
        k = A.shape[0]
        # A qdd = -dA/dt qd - 2 alpha A qd - beta^2 phi
        c = -np.asarray(drift, dtype=float).reshape(k) - 2.0 * alpha * (A @ qd)
        if phi is not None and beta:
            phi = np.atleast_1d(np.asarray(phi, dtype=float))
            c[: phi.size] -= beta**2 * phi
        K = np.zeros((self.n + k, self.n + k))
        K[: self.n, : self.n] = M
        K[: self.n, self.n :] = A.T
        K[self.n :, : self.n] = A
        sol = np.linalg.solve(K, np.concatenate([rhs, c]))
        return sol[: self.n], sol[self.n :]

    def constraint_residuals(self, q, qd) -> tuple:
        """(position residual |phi(q)|_inf or 0, velocity residual |A(q) qd|_inf) at one state."""
        pos = float(np.abs(np.atleast_1d(self.constraint(q))).max(initial=0.0)) if self.constraint is not None else 0.0
        vel = (
            float(np.abs(np.atleast_2d(self.constraint_jacobian(q)) @ qd).max(initial=0.0))
            if self.constraint_jacobian is not None
            else 0.0
        )
        return pos, vel

    # ------------------------------------------------------------------ from a LagrangianSystem
    @classmethod
    def from_lagrangian(cls, system, params=None, points=None, baumgarte=(10.0, 10.0)) -> MechanicalSystem:
        """Compile a :class:`kinedyn.symbolic.LagrangianSystem` (parameters given by name in
        ``params``; the generalised forces come from the simulation, not from ``system.u``).
        ``points``: optional SymPy expressions (a list of 2- or 3-vectors of q) drawn by animate()."""
        import sympy as sp  # loaded only when a symbolic system is compiled

        q, qd, qdd = list(system.q), list(system.qd), list(system.qdd)
        values = {str(k): v for k, v in dict(params or {}).items()}
        EL = system.euler_lagrange()
        zero_acc = {a: 0 for a in qdd}
        M = sp.hessian(system.L, qd)
        h = sp.Matrix([sp.expand(e.subs(zero_acc)) for e in EL]) + system.B
        A = system.A
        k = A.shape[0]
        drift = (A * sp.Matrix(qd)).jacobian(q) * sp.Matrix(qd) if k else sp.zeros(0, 1)
        phi = sp.Matrix(system.holonomic) if system.holonomic else sp.zeros(0, 1)
        H = system.energy()
        exprs = {"M": M, "h": h, "A": A, "drift": drift, "phi": phi, "H": H}
        if system.K is not None:
            exprs["K"] = system.K
            exprs["P"] = system.P
        if points is not None:
            exprs["points"] = sp.Matrix([list(p) for p in points])
        state = set(q) | set(qd) | {system.t}
        subs = {}
        for e in exprs.values():
            for s in sp.sympify(e).free_symbols - state:
                if str(s) in values:
                    subs[s] = values[str(s)]
        exprs = {key: sp.sympify(e).subs(subs) for key, e in exprs.items()}
        missing = set()
        for e in exprs.values():
            missing |= {str(s) for s in e.free_symbols - state}
        if exprs["M"].free_symbols & set(qd):
            raise ValueError("simulate needs a mass matrix d2L/dqd2 that does not depend on the velocities")
        if any(e.has(system.t) for e in exprs.values()):
            raise ValueError("simulate handles time-invariant Lagrangians; give time-dependent forcing as u(t, q, qd)")
        if missing:
            raise ValueError(
                f"{system.name or 'the Lagrangian system'}: give values for the parameters {sorted(missing)} (params={{'name': value}})"
            )

        kwargs: dict[str, Any] = {}

        def compile_(expr, shape):
            fn = sp.lambdify([q, qd], expr, modules="numpy", cse=True)

            def f(qv, qdv):
                return np.asarray(fn(qv, qdv), dtype=float).reshape(shape)

            return f

        n = len(q)
        # one call per stage for everything the accelerations need (common subexpressions shared)
        k_h = exprs["phi"].shape[0]
        together = sp.lambdify(
            [q, qd], [exprs["M"], exprs["h"], exprs["A"], exprs["drift"], exprs["phi"]], modules="numpy", cse=True
        )

        def terms(qv, qdv):
            M_, h_, A_, d_, p_ = together(qv, qdv)
            return (
                np.asarray(M_, dtype=float).reshape(n, n),
                np.asarray(h_, dtype=float).reshape(n),
                np.asarray(A_, dtype=float).reshape(k, n),
                np.asarray(d_, dtype=float).reshape(k),
                np.asarray(p_, dtype=float).reshape(k_h) if k_h else None,
            )

        kwargs["terms"] = terms
        Mf = compile_(exprs["M"], (n, n))
        hf = compile_(exprs["h"], (n,))
        Hf = compile_(exprs["H"], ())
        if k:
            Af = compile_(exprs["A"], (k, n))
            df = compile_(exprs["drift"], (k,))
            kwargs.update(constraint_jacobian=lambda x: Af(x, np.zeros(n)), constraint_drift=df)
            if phi.shape[0]:
                pf = compile_(exprs["phi"], (phi.shape[0],))
                kwargs["constraint"] = lambda x: pf(x, np.zeros(n))
        if "K" in exprs:
            Kf, Pf = compile_(exprs["K"], ()), compile_(exprs["P"], ())
            kwargs.update(
                kinetic_energy=lambda x, v: float(Kf(x, v)), potential_energy=lambda x: float(Pf(x, np.zeros(n)))
            )
        if "points" in exprs:
            m = exprs["points"]
            pts = compile_(m, tuple(m.shape))
            kwargs["points"] = lambda x: pts(x, np.zeros(n))
        return cls(
            n=n,
            mass_matrix=lambda x: Mf(x, np.zeros(n)),
            bias=hf,
            energy=lambda x, v: float(Hf(x, v)),
            names=tuple(str(c) for c in q),
            name=system.name or "Lagrangian system",
            baumgarte=baumgarte,
            **kwargs,
        )
