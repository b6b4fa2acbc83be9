"""The properties of Spong §9.5 *proved* on symbolic equations of motion (``eom.check_properties()``):
identities decided by an exact trigonometric normal form, the inertia bounds by a global search.
The numeric checks of a robot are :func:`kinedyn.analysis.check_properties`."""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..._math import by_name
from ...property_checks import Check, PropertiesReport, global_inertia_bounds

__all__ = ["prove_properties"]


def _trig_normal_form(expr, coordinates):
    """The numerator of ``expr`` as a polynomial in s_i = sin q_i, c_i = cos q_i (after expanding sines
    and cosines of sums and multiples) and the other symbols, reduced modulo s_i^2 + c_i^2 - 1 (a
    Groebner basis: the leading monomials s_i^2 are pairwise coprime), so every s_i has degree <= 1.
    That remainder is unique, so it is 0 exactly when the polynomial identity holds: ``0`` proves
    ``expr == 0``. Returns the remainder (SymPy expression)."""
    e = sp.expand(expr)
    if e == 0:
        return e
    e = sp.expand(sp.expand_trig(e))
    if e == 0:
        return e
    rep = {}
    pyth = []
    for k, c in enumerate(coordinates):
        s_k, c_k = sp.Dummy(f"s{k}"), sp.Dummy(f"c{k}")
        rep[sp.sin(c)] = s_k
        rep[sp.cos(c)] = c_k
        pyth.append((s_k, c_k))
    e = e.xreplace(rep)
    num, _ = sp.fraction(sp.together(e))
    num = sp.expand(num)
    for s_k, c_k in pyth:
        num = num.replace(
            lambda x, s_k=s_k: x.is_Pow and x.base == s_k and x.exp.is_Integer and x.exp >= 2,
            lambda x, s_k=s_k, c_k=c_k: s_k ** (int(x.exp) % 2) * (1 - c_k**2) ** (int(x.exp) // 2),
        )
    return sp.expand(num)


def _decide_zero(entries, coordinates, variables, rng, tries: int = 12):
    """("proved", 0, None) when every entry reduces to 0 (:func:`_trig_normal_form`); otherwise the
    entries are evaluated at ``tries`` random points (coordinates and rates in [-pi, pi], other symbols
    in [0.5, 2]): ("failed", residual, point) when one is not zero there, ("sampled", residual, None)
    when none is (simplification could not decide, the numbers found no counterexample)."""
    pending = [e for e in entries if _trig_normal_form(e, coordinates) != 0]
    if not pending:
        return "proved", 0.0, None
    symbols = sorted(set().union(*(sp.sympify(e).free_symbols for e in pending)), key=str)
    fn = sp.lambdify(symbols, pending, "numpy")
    worst, witness = 0.0, None
    for _ in range(tries):
        point = {s: (rng.uniform(-np.pi, np.pi) if s in variables else rng.uniform(0.5, 2.0)) for s in symbols}
        vals = np.abs(np.asarray(fn(*[point[s] for s in symbols]), dtype=complex))
        if vals.max() > worst:
            worst, witness = float(vals.max()), {str(k): float(v) for k, v in point.items()}
    if worst > 1e-9:
        return "failed", worst, witness
    return "sampled", worst, None


def prove_properties(
    eom, params=None, limits=None, samples: int = 256, starts: int = 12, seed: int = 0
) -> PropertiesReport:
    """The properties of Spong §9.5 for a symbolic :class:`kinedyn.symbolic.EquationsOfMotion`
    (``eom.check_properties()``), each decided exactly where it can be:

    - D(q) symmetric, dD/dt - 2C skew-symmetric (Prop. 9.1), dD/dt = C + C^T (eq. 9.110), and
      D qdd + C qd + g = d/dt dL/dqd - dL/dq with L = K - P (eqs. 9.52-9.61: C is the Christoffel
      matrix of this D, g the gradient of this P; a transposed C passes the two identities before it,
      not this one): status "proved" when the difference reduces to 0 exactly (sines and cosines of
      sums expanded, then reduced modulo sin^2 + cos^2 = 1, a normal form), "failed" with the state
      of a counterexample, "sampled" when simplification cannot decide and random states show none.
    - Inertia bounds lambda_min I <= D(q) <= lambda_max I (eq. 9.120) by :func:`global_inertia_bounds`
      with dD/dq_k differentiated symbolically (status "searched"), after substituting ``params``
      ({symbol or name: value}); "skipped" (and saying which) while D has free parameters. A
      coordinate that appears only inside sines and cosines is periodic; any other needs a range in
      ``limits`` ({coordinate or name: (lower, upper)}), default [-1, 1].
    """
    rng = np.random.default_rng(seed)
    q = list(eom.q)
    qd = list(eom.qd)
    n = eom.n
    D, C, g = eom.M, eom.C, eom.g
    # d/dt along the motion: (q_k, qd_k), and for a closed chain's reduced equations in a velocity map
    # also the dependent coordinates at their rates G_d qd (eom.configuration_rates)
    rates = eom.configuration_rates() if hasattr(eom, "configuration_rates") else list(zip(q, qd))
    velocity_map = len(rates) > n
    coordinates = [c for c, _ in rates]
    variables = set(coordinates) | set(qd) | set(eom.qdd)
    checks = []

    floating = any(m.has(sp.Float) for m in (D, C, g)) or (eom.P is not None and sp.sympify(eom.P).has(sp.Float))

    def decided(name, entries, source, what):
        status, residual, witness = _decide_zero(entries, coordinates, variables, rng)
        how = {
            "proved": "reduces to 0 exactly (sin/cos of sums expanded, reduced modulo sin^2 + cos^2 = 1)",
            "sampled": f"not decided by simplification; zero to {residual:.2g} at random states (not proved)"
            + (
                "; the model holds floating-point numbers (e.g. cos of a DH twist of pi/2 rounded), whose rounding "
                "leaves a residue exact cancellation cannot remove: exact (rational or symbolic) parameters can be proved"
                if floating
                else ""
            ),
            "failed": f"not zero: |{what}| = {residual:.3g} at {witness}",
        }[status]
        checks.append(
            Check(
                name,
                status != "failed",
                residual,
                0.0 if status == "proved" else 1e-9,
                f"{what}: {how}",
                source,
                dict(witness=witness) if witness else {},
                status=status,
            )
        )

    decided("D symmetric", [D[i, j] - D[j, i] for i in range(n) for j in range(i + 1, n)], "Spong eq. 9.50", "D - D^T")
    Ddot = sp.zeros(n, n)
    for qi, vi in rates:
        Ddot += D.diff(qi) * vi
    N = Ddot - 2 * C
    decided(
        "dD/dt - 2C skew-symmetric",
        [N[i, j] + N[j, i] for i in range(n) for j in range(i, n)],
        "Spong Prop. 9.1, eqs. 9.109-9.111",
        "N + N^T",
    )
    decided(
        "dD/dt == C + C^T",
        [Ddot[i, j] - C[i, j] - C[j, i] for i in range(n) for j in range(i, n)],
        "Spong eq. 9.110",
        "dD/dt - C - C^T",
    )
    P = eom.P
    if velocity_map:
        checks.append(
            Check(
                "D qdd + C qd + g == d/dt dL/dqd - dL/dq",
                True,
                0.0,
                0.0,
                "the reduced equations G^T (M qdd + C qd + g) of a closed chain in a velocity map qd = G(q) qd_i are not "
                "the Euler-Lagrange equations of a Lagrangian in the independent coordinates alone (the closure ties "
                "the others to them implicitly); the tree's equations they come from satisfy it",
                "Spong eqs. 9.52-9.61",
                status="skipped",
            )
        )
    elif P is not None:
        L = eom.K - P
        lhs = []
        for k in range(n):
            p_k = sp.diff(L, qd[k])
            ddt = sum(sp.diff(p_k, a) * b for a, b in zip(q + qd, qd + list(eom.qdd)))
            lhs.append(ddt - sp.diff(L, q[k]))
        rigid = D * eom.qdd + C * sp.Matrix(qd) + g
        decided(
            "D qdd + C qd + g == d/dt dL/dqd - dL/dq",
            [rigid[k] - lhs[k] for k in range(n)],
            "Spong eqs. 9.52-9.61",
            "D qdd + C qd + g - (d/dt dL/dqd - dL/dq)",
        )
    else:
        checks.append(
            Check(
                "D qdd + C qd + g == d/dt dL/dqd - dL/dq",
                True,
                0.0,
                0.0,
                "no potential energy P in this model (not a natural system)",
                "Spong eqs. 9.52-9.61",
                status="skipped",
            )
        )

    # inertia bounds by a global search
    name = "inertia bounds lambda_min I <= D(q) <= lambda_max I"
    Dn = D.xreplace(by_name(params, eom.parameters)) if params else D
    free = sorted(Dn.free_symbols - set(q), key=str)
    if velocity_map:
        checks.append(
            Check(
                name,
                True,
                0.0,
                0.0,
                "D depends on the dependent coordinates of a closed chain, which its closure ties to the independent "
                "ones: the bounds need a search on the closed configurations (give an explicit branch, solution=, for "
                "D in the independent coordinates alone)",
                "Spong eqs. 9.119-9.120",
                status="skipped",
            )
        )
        return PropertiesReport(eom.name or "equations of motion", samples, checks)
    if free:
        checks.append(
            Check(
                name,
                True,
                0.0,
                0.0,
                f"D has free parameters {', '.join(map(str, free))}: give their values in params= to search the bounds",
                "Spong eqs. 9.119-9.120",
                status="skipped",
            )
        )
        return PropertiesReport(eom.name or "equations of motion", samples, checks)
    limits = by_name(limits, q) if limits else {}
    # 2 pi-periodic: only inside sines and cosines, with integer multiples (a mimic follower's cos(3 q/2) is not)
    angles = [sp.expand(f.args[0]) for f in Dn.atoms(sp.sin, sp.cos)]
    periodic = np.array(
        [
            not Dn.replace(lambda x: isinstance(x, (sp.sin, sp.cos)), lambda x: sp.Integer(1)).has(c)
            and all(a.coeff(c).is_integer for a in angles)
            for c in q
        ]
    )
    lower = np.array([-np.pi if p else float(limits.get(c, (-1.0, 1.0))[0]) for c, p in zip(q, periodic)])
    upper = np.array([np.pi if p else float(limits.get(c, (-1.0, 1.0))[1]) for c, p in zip(q, periodic)])
    f_D = sp.lambdify([q], Dn, "numpy")
    f_dD = sp.lambdify([q], [Dn.diff(c) for c in q], "numpy")

    def mass_matrix(x):
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:
            return np.array([np.asarray(f_D(row), dtype=float) for row in x])
        return np.asarray(f_D(x), dtype=float)

    b = global_inertia_bounds(
        mass_matrix,
        lambda x: np.asarray(f_dD(np.asarray(x, dtype=float)), dtype=float),
        lower,
        upper,
        periodic,
        samples=samples,
        starts=starts,
        seed=seed,
    )
    checks.append(
        Check(
            name,
            bool(b.lambda_min > 0),
            float(max(0.0, -b.lambda_min)),
            0.0,
            b.describe(),
            "Spong eqs. 9.119-9.120",
            dict(
                lambda_min=b.lambda_min,
                lambda_max=b.lambda_max,
                q_lambda_min=b.q_lambda_min,
                q_lambda_max=b.q_lambda_max,
                sampled_min=b.sampled_min,
                sampled_max=b.sampled_max,
            ),
            status="searched",
        )
    )
    return PropertiesReport(eom.name or "equations of motion", samples, checks)
