"""The properties of Spong §9.5 for a :class:`kinedyn.symbolic.LagrangianSystem` — proven by exact
simplification where they are identities, measured numerically where they are statements about
motion.

Exact (every entry brought to its unique trigonometric normal form, :func:`simplify_trig`, and
compared with zero; a proof for all q, qd and all parameter values):

- M = d2L/dqd2 symmetric (Spong eq. 9.42);
- natural systems (L = qd^T M(q) qd / 2 - P(q)), with C from the Christoffel symbols (Spong 9.58):
  N = dM/dt - 2C skew-symmetric (Prop. 9.1, eq. 9.109), dM/dt = C + C^T (eq. 9.110, which skew
  symmetry alone does not imply), and C qd + g equal to the Euler-Lagrange bias
  (d/dt dL/dqd - dL/dq)|qdd=0 (a transposed C fails this one).

Numeric (needs a value for every parameter, ``params`` by name):

- M positive definite at ``samples`` random configurations (smallest eigenvalue reported);
- passivity / energy balance (Spong eqs. 9.113-9.118): along a trajectory driven by smooth random
  forces u(t), integrated with the work and the friction's dissipation in the state,
  ``int qd . u dt = H(T) - H(0) + int qd . B dt`` (H = the energy function, :meth:`energy`).

Constrained systems (holonomic or Pfaffian, A(q) qd = 0): the exact checks are of the
unconstrained Lagrangian in all n coordinates (the ambient M, C, g; the constraint forces A^T lambda
are not part of C). Along the constrained motion (started on the constraint manifold, solved by the
KKT system) the numeric part checks the energy balance above — which holds because the constraint
forces do no work, qd . A^T lambda = (A qd) . lambda = 0 — that this work is indeed zero, and that
the motion stays on the manifold (|g_c(q)| and |A qd| along the trajectory).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import sympy as sp

from ...property_checks import Check, PropertiesReport

if TYPE_CHECKING:
    from .system import LagrangianSystem

__all__ = ["check_system_properties"]


def _nonzero(entries, simp) -> list:
    """The entries whose normal form is not zero (an empty list proves the identity)."""
    out = []
    for e in entries:
        e = sp.expand(e)
        if e == 0:
            continue
        s = simp(e)
        if s != 0 and sp.simplify(s) != 0:
            out.append(s)
    return out


def _exact_checks(system, eom) -> list:
    n = system.n
    simp = system._simp
    checks = []
    M = eom.M
    asym = _nonzero([M[i, j] - M[j, i] for i in range(n) for j in range(i + 1, n)], simp)
    checks.append(
        Check(
            "M symmetric (exact)",
            not asym,
            float(len(asym)),
            0.0,
            "M = d2L/dqd2; every M_ij - M_ji simplified to 0" if not asym else f"M_ij - M_ji not zero: {asym[:2]}",
            "Spong eq. 9.42",
        )
    )
    if not eom.extra.get("natural", True):
        return checks
    qd = list(eom.qd)
    Mdot = sp.Matrix(n, n, lambda i, j: sum(sp.diff(M[i, j], c) * v for c, v in zip(eom.q, qd)))
    N = Mdot - 2 * eom.C
    skew = _nonzero([N[i, j] + N[j, i] for i in range(n) for j in range(i, n)], simp)
    checks.append(
        Check(
            "dM/dt - 2C skew-symmetric (exact)",
            not skew,
            float(len(skew)),
            0.0,
            "N = dM/dt - 2C, every N_ij + N_ji simplified to 0" if not skew else f"N + N^T not zero: {skew[:2]}",
            "Spong Prop. 9.1, eq. 9.109",
        )
    )
    cct = _nonzero(list(Mdot - eom.C - eom.C.T), simp)
    checks.append(
        Check(
            "dM/dt == C + C^T (exact)",
            not cct,
            float(len(cct)),
            0.0,
            "every entry of dM/dt - C - C^T simplified to 0" if not cct else f"not zero: {cct[:2]}",
            "Spong eq. 9.110",
        )
    )
    bias = eom.extra.get("bias")
    if bias is None:
        bias = sp.Matrix([e.subs({a: 0 for a in system.qdd}) for e in system.euler_lagrange()])
    cq = _nonzero(list(eom.C * eom.qd + eom.g - bias), simp)
    checks.append(
        Check(
            "C qd + g == Euler-Lagrange bias (exact)",
            not cq,
            float(len(cq)),
            0.0,
            "C qd + g - (d/dt dL/dqd - dL/dq)|qdd=0 simplified to 0 (a transposed C fails here)"
            if not cq
            else f"not zero: {cq[:2]}",
            "Spong eqs. 9.58-9.62",
        )
    )
    return checks


def _on_manifold(q, qd, A_fn, phi_fn, k_h):
    """Project a state onto the constraint manifold: Gauss-Newton on the holonomic residuals, then
    qd onto the null space of A."""
    for _ in range(50):
        if not k_h:
            break
        r = np.atleast_1d(phi_fn(q))
        if np.abs(r).max() < 1e-13:
            break
        Ah = np.atleast_2d(A_fn(q))[:k_h]
        q = q - np.linalg.pinv(Ah) @ r
    A = np.atleast_2d(A_fn(q))
    qd = qd - np.linalg.pinv(A) @ (A @ qd)
    return q, qd


def check_system_properties(
    system: LagrangianSystem,
    params: dict | None = None,
    samples: int = 50,
    seed: int = 0,
    T: float = 2.0,
    exact_only: bool = False,
    tolerance: float = 1e-6,
) -> PropertiesReport:
    """Prove and measure the properties of a Lagrangian system (see the module docstring).

    ``params``: parameter values by name (needed for the numeric checks unless ``exact_only``);
    ``samples`` random configurations for positive definiteness; a trajectory of ``T`` seconds
    (solve_ivp, rtol 1e-10) from a seeded random state under forces ``a_k sin(w_k t + phi_k)`` for
    the energy balance, whose relative residual must be below ``tolerance``."""
    from scipy.integrate import solve_ivp  # scipy loads only when the motion is integrated

    eom = system.equations_of_motion()
    checks = _exact_checks(system, eom)
    if exact_only:
        return PropertiesReport(system.name or "Lagrangian system", 0, checks)
    values = {str(k): v for k, v in dict(params or {}).items()}
    state = set(system.q) | set(system.qd) | {system.t}
    exprs = [system.L, *system.B, *system.A, *system.holonomic]
    missing = sorted({str(s) for e in exprs for s in sp.sympify(e).free_symbols - state if str(s) not in values})
    if missing:
        raise ValueError(
            f"check_system_properties: give values for the parameters {missing} (params={{'name': value}}), or exact_only=True"
        )
    sub = lambda e: sp.sympify(e).xreplace({s: values[str(s)] for s in sp.sympify(e).free_symbols if str(s) in values})
    n = system.n
    q_sym, qd_sym = list(system.q), list(system.qd)
    rng = np.random.default_rng(seed)

    # M positive definite at sampled configurations
    M_fn = sp.lambdify([q_sym, qd_sym], sub(sp.hessian(system.L, system.qd)), "numpy")
    Q = rng.uniform(-np.pi, np.pi, size=(samples, n))
    QD = rng.normal(size=(samples, n))
    eig = np.array([np.linalg.eigvalsh(np.asarray(M_fn(q, v), dtype=float).reshape(n, n))[0] for q, v in zip(Q, QD)])
    worst = int(np.argmin(eig))
    checks.append(
        Check(
            "M positive definite (sampled)",
            bool(eig.min() > 0),
            float(max(0.0, -eig.min())),
            0.0,
            f"smallest eigenvalue {eig.min():.6g} over {samples} random states (at q = {np.array2string(Q[worst], precision=3)})",
            "Spong eq. 9.42",
            dict(min_eigenvalue=float(eig.min())),
        )
    )

    # passivity along a trajectory under smooth random forces
    t = system.t
    amplitude, omega, phase = rng.uniform(0.5, 2.0, n), rng.uniform(0.5, 3.0, n), rng.uniform(0, 2 * np.pi, n)
    u = [float(a) * sp.sin(float(w) * t + float(p)) for a, w, p in zip(amplitude, omega, phase)]
    accelerations = system.numeric_accelerations(values, u=u)
    u_fn = sp.lambdify([t], u, "numpy")
    B_fn = sp.lambdify([q_sym, qd_sym], list(sub(system.B)), "numpy")
    H_fn = sp.lambdify([q_sym, qd_sym], sub(system.energy()), "numpy")
    k = system.A.shape[0]
    k_h = len(system.holonomic)
    # constraint Jacobian A(q) (k x n; 0 x n without constraints) and holonomic residuals g_c(q)
    A_fn: Callable = sp.lambdify([q_sym], sub(system.A) if k else sp.zeros(1, n), "numpy")
    phi_fn: Callable = sp.lambdify([q_sym], [sub(e) for e in system.holonomic] or [0], "numpy")
    q0, qd0 = rng.uniform(-1.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
    if k:
        q0, qd0 = _on_manifold(q0, qd0, A_fn, phi_fn, k_h)

    def rhs(time, y):
        q, qd = y[:n], y[n : 2 * n]
        qdd, lam = accelerations(time, q, qd)
        work = float(qd @ np.asarray(u_fn(time), dtype=float))
        dissipated = float(qd @ np.asarray(B_fn(q, qd), dtype=float).reshape(n))
        constraint_work = float(qd @ (np.atleast_2d(A_fn(q)).T @ lam)) if k else 0.0
        return np.concatenate([qd, qdd, [work, dissipated, constraint_work]])

    name = "passivity: int qd . u dt == H(T) - H(0) + int qd . B dt"
    try:
        sol = solve_ivp(rhs, (0.0, T), np.concatenate([q0, qd0, [0.0, 0.0, 0.0]]), rtol=1e-10, atol=1e-12)
    except ValueError as err:  # a singular configuration met along the way
        checks.append(
            Check(name, False, float("inf"), tolerance, f"the simulation failed: {err}", "Spong eqs. 9.113-9.117")
        )
        return PropertiesReport(system.name or "Lagrangian system", samples, checks)
    if not sol.success:
        checks.append(
            Check(
                name, False, float("inf"), tolerance, f"the simulation failed: {sol.message}", "Spong eqs. 9.113-9.117"
            )
        )
        return PropertiesReport(system.name or "Lagrangian system", samples, checks)
    yT = sol.y[:, -1]
    H0, HT = float(H_fn(q0, qd0)), float(H_fn(yT[:n], yT[n : 2 * n]))
    work, dissipated, constraint_work = yT[2 * n :]
    scale = max(1.0, abs(work), abs(H0), abs(HT), abs(dissipated))
    residual = abs(work - (HT - H0) - dissipated) / scale
    checks.append(
        Check(
            name,
            bool(residual <= tolerance),
            float(residual),
            tolerance,
            f"{T:g} s under u = a sin(w t + phi): work {work:.6g}, dH {HT - H0:.6g}, dissipated {dissipated:.6g} (solve_ivp, rtol 1e-10)",
            "Spong eqs. 9.113-9.117",
            dict(work=float(work), dH=HT - H0, dissipated=float(dissipated)),
        )
    )
    if k:
        cw = abs(constraint_work) / scale
        checks.append(
            Check(
                "constraint forces do no work: int qd . A^T lambda dt == 0",
                bool(cw <= tolerance),
                float(cw),
                tolerance,
                f"|int qd . A^T lambda dt| = {abs(constraint_work):.3g} (A qd = 0 along the motion)",
                "LaValle §13.4.3 (d'Alembert)",
            )
        )
        drift = 0.0
        for y in sol.y.T:
            q, qd = y[:n], y[n : 2 * n]
            drift = max(drift, float(np.abs(np.atleast_2d(A_fn(q)) @ qd).max()))
            if k_h:
                drift = max(drift, float(np.abs(np.atleast_1d(phi_fn(q))).max()))
        checks.append(
            Check(
                "motion stays on the constraint manifold",
                bool(drift <= tolerance),
                drift,
                tolerance,
                "max over the trajectory of |g_c(q)| and |A(q) qd| (no Baumgarte stabilisation)",
                "LaValle eqs. 13.170-13.171",
            )
        )
    return PropertiesReport(system.name or "Lagrangian system", samples, checks)
