"""Linearity in the parameters (Spong §9.5.3, eq. 9.121): tau = Y(q, qd, qdd) Theta, exactly.

tau is expanded (in the exact trigonometric ring) into terms  (state monomial) x (known monomial) x
(parameter polynomial). "Known" symbols (gravity by default, plus any passed as ``known``) go into Y;
every other symbol is a parameter. The coefficient of each state-and-known monomial in each row is a
polynomial in the parameters; Theta is a basis of the rational span of these polynomials, chosen
greedily in the order they appear (rows in order, inertial terms qdd first, then velocity terms,
then gravity), each scaled to a primitive form. Every coefficient is then an exact rational
combination of Theta, which gives Y. The basis is minimal for this expansion: its size is the rank.

For the planar elbow this yields Theta1 = m1 lc1^2 + m2 (l1^2 + lc2^2) + I1 + I2, Theta2 = m2 l1 lc2,
Theta3 = m2 lc2^2 + I2, Theta4 = m1 lc1 + m2 l1, Theta5 = m2 lc2 (derived, not copied: the seed's
printed Theta3 and Theta5 differ).
"""

from __future__ import annotations

from typing import Dict, List

import sympy as sp

__all__ = ["regressor"]


def _ring_tau(eom):
    if eom.model is not None:
        model, d = eom.model
        return model.ring, d["tau"]
    derived = getattr(eom, "_derived", None)
    if derived is not None:
        c = derived()
        return c["model"].ring, c["tau"]
    raise ValueError("regressor(): these equations carry no exact model (build them from a robot)")


def regressor(eom, known=None):
    """(Y, Theta): sp.Matrix (n x p) and sp.Matrix (p x 1) with Y * Theta == tau (friction excluded)."""
    ring, tau = _ring_tau(eom)
    known = set(known or [])
    robot_gravity = set()
    if eom.model is not None:
        for v in eom.model[0].gravity:
            robot_gravity |= sp.sympify(v).free_symbols
    elif getattr(eom, "_derived", None) is not None:
        for v in eom._derived()["model"].gravity:
            robot_gravity |= sp.sympify(v).free_symbols
    known |= robot_gravity
    npar = ring.nparams
    pgens = ring.param_gens
    is_known = [any(s in known for s in sp.sympify(g).free_symbols) for g in pgens]
    to_sym = ring.domain.to_sympy
    # coefficient polynomials: key (row, state monomial, known monomial) -> {param monomial: number}
    coeffs: Dict[tuple, Dict[tuple, object]] = {}
    order: List[tuple] = []
    for row, t in enumerate(tau):
        t = ring.chop(t)
        items = sorted(t.items(), key=lambda mc: _state_rank(ring, mc[0]))
        for m, c in items:
            pm = tuple(e if not is_known[j] else 0 for j, e in enumerate(m[:npar]))
            km = tuple(e if is_known[j] else 0 for j, e in enumerate(m[:npar]))
            key = (row, m[npar:], km)
            if key not in coeffs:
                coeffs[key] = {}
                order.append(key)
            coeffs[key][pm] = coeffs[key].get(pm, 0) + to_sym(c)
    # greedy basis over the numbers (Gaussian elimination on coefficient vectors)
    basis: List[Dict[tuple, object]] = []
    echelon: List[tuple] = []  # (pivot monomial, reduced vector, combination over basis)
    combos: Dict[tuple, list] = {}
    for key in order:
        vec = {k: v for k, v in coeffs[key].items() if v != 0}
        if not vec:
            continue
        comb = _express(vec, echelon, len(basis))
        if comb is None:
            # new basis element, scaled to primitive form (content 1, positive leading coefficient)
            scale = _content(vec)
            prim = {k: v / scale for k, v in vec.items()}
            basis.append(prim)
            idx = len(basis) - 1
            red = dict(prim)
            cmb = [sp.Integer(0)] * (idx + 1)
            cmb[idx] = sp.Integer(1)
            for piv, rvec, rcomb in echelon:  # reduce against earlier pivots
                if piv in red and red[piv] != 0:
                    f = red[piv] / rvec[piv]
                    red = _axpy(red, rvec, -f)
                    cmb = [a - f * (rcomb[i] if i < len(rcomb) else 0) for i, a in enumerate(cmb)]
            piv = max(red, key=lambda k: (k, 0))
            echelon.append((piv, red, cmb))
            comb = [sp.Integer(0)] * idx + [scale]
        combos[key] = comb
    p = len(basis)
    tidy = lambda v: sp.Integer(int(v)) if isinstance(v, sp.Float) and float(v).is_integer() else v
    Theta = sp.Matrix([sp.Add(*[tidy(v) * _mono(pgens, k) for k, v in b.items()]) for b in basis])
    Yr = [[ring.zero] * p for _ in tau]
    for key, comb in combos.items():
        row, sm, km = key
        mono = ring.R.from_dict({tuple(km) + tuple(sm): ring.domain.one})
        for j, w in enumerate(comb):
            if w != 0:
                Yr[row][j] += mono * ring.const(w)
    Y = ring.matrix_to_sympy([[ring.reduce(e) for e in r] for r in Yr])
    return Y, Theta


def _state_rank(ring, m):
    """Order: acceleration terms, then velocity terms, then the rest (gravity)."""
    acc = [m[j] for j in ring.qdd_idx]
    vel = [m[j] for j in ring.qd_idx]
    trig = sum(m[j] for j in list(ring.c_idx.values()) + list(ring.s_idx.values()))
    group = 0 if any(acc) else (1 if any(vel) else 2)
    return (group, [-e for e in acc], [-e for e in vel], trig, m[ring.nparams:])


def _mono(gens, exps):
    return sp.Mul(*[sp.sympify(g.as_expr() if hasattr(g, "as_expr") else g) ** e for g, e in zip(gens, exps) if e])


def _content(vec):
    vals = list(vec.values())
    if all(v.is_Rational for v in vals):
        from math import gcd

        nums = [abs(int(v.p)) for v in vals]
        dens = [int(v.q) for v in vals]
        g = 0
        for x in nums:
            g = gcd(g, x)
        l = 1
        for d in dens:
            l = l * d // gcd(l, d)
        c = sp.Rational(g, l)
    else:
        c = vals[0]
    lead = vec[max(vec)]
    return c if (lead / c) > 0 else -c


def _axpy(a, b, f):
    out = dict(a)
    for k, v in b.items():
        out[k] = out.get(k, 0) + f * v
        if out[k] == 0 or (isinstance(out[k], sp.Float) and abs(out[k]) < 1e-14):
            del out[k]
    return out


def _express(vec, echelon, nb):
    """Coefficients of vec over the basis (via the echelon form), or None if independent."""
    red = dict(vec)
    comb = [sp.Integer(0)] * nb
    for piv, rvec, rcomb in echelon:
        if piv in red and red[piv] != 0:
            f = red[piv] / rvec[piv]
            red = _axpy(red, rvec, -f)
            for i, a in enumerate(rcomb):
                comb[i] += f * a
    if any(v != 0 for v in red.values()):
        return None
    return comb
