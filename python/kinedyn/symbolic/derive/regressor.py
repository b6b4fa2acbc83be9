"""Linearity in the parameters (Spong §9.5.3, eq. 9.121; Khalil & Dombre ch. 9, base
parameters): tau = Y(q, qd, qdd) Theta + tau_known, exactly.

tau is expanded (in the exact trigonometric ring) into terms  (state monomial) x (known monomial) x
(parameter polynomial). "Known" symbols (gravity by default, plus any passed as ``known``) go into Y;
every other symbol is a parameter. The coefficient of each state-and-known monomial in each row is a
polynomial in the parameters; its parameter-free part (a number: the reflected rotor inertia
r^2 J_m of a robot whose drives are given as numbers, or any product of numbers) is *known*: it is
collected in ``tau_known`` and is not a parameter (the numeric ``robot.regressor`` leaves the rotor
out the same way, so both count the same base parameters). Theta is a basis of the span of the
remaining polynomials, chosen greedily in the order they appear (rows in order, inertial terms qdd
first, then velocity terms, then gravity), each scaled to a primitive form. Every coefficient is then
a combination of Theta, which gives Y. The basis is minimal for this expansion: its size is the rank
of the regressor, the number of base parameters.

Arithmetic of the elimination: exact rationals (Python ``Fraction``) when the description is exact;
with float parameters (a numeric robot, e.g. the PUMA's a3 = 0.0203) the ring's coefficients carry
round-off, so a reduced coefficient counts as zero below ``rtol`` times the largest coefficient it
was formed from (as the numeric base parameters use a relative rank tolerance).

For the planar elbow this yields Theta1 = m1 lc1^2 + m2 (l1^2 + lc2^2) + I1 + I2, Theta2 = m2 l1 lc2,
Theta3 = m2 lc2^2 + I2, Theta4 = m1 lc1 + m2 l1, Theta5 = m2 lc2 (derived, not copied: the seed's
printed Theta3 and Theta5 differ).
"""

from __future__ import annotations

from fractions import Fraction
from math import gcd
from typing import Any

import sympy as sp

__all__ = ["regressor", "base_parameters", "Regressor"]


class Regressor(tuple):
    """``(Y, Theta)`` (unpacks as a pair) with ``Y * Theta + tau_known == tau`` (friction left out).
    ``tau_known``: the part of tau with no unknown parameter (an n x 1 SymPy matrix, often zero)."""

    tau_known: Any

    def __new__(cls, Y, Theta, tau_known):
        obj = super().__new__(cls, (Y, Theta))
        obj.tau_known = tau_known
        return obj

    @property
    def Y(self):
        return self[0]

    @property
    def Theta(self):
        return self[1]


def _ring_tau(eom):
    if eom.model is not None:
        model, d = eom.model
        return model, d["tau"]
    derived = eom.derivation
    if derived is not None:
        c = derived()
        return c["model"], c["tau"]
    raise ValueError("regressor(): these equations carry no exact model (build them from a robot)")


class _Field:
    """Scalar arithmetic of the elimination: exact (Fraction / SymPy) or float with a tolerance."""

    def __init__(self, ring, rtol):
        self.inexact = ring.domain == sp.RR
        self.exact_q = ring.domain in (sp.QQ, sp.ZZ)
        self.rtol = rtol
        self._to_sym = ring.domain.to_sympy

    def num(self, c):
        if self.inexact:
            return float(c)
        if self.exact_q:
            return Fraction(int(c.numerator), int(c.denominator))
        return self._to_sym(c)

    def sym(self, v):
        if isinstance(v, float):
            return sp.Integer(int(v)) if v.is_integer() else sp.Float(v)
        if isinstance(v, Fraction):
            return sp.Rational(v.numerator, v.denominator)
        return v

    def zero_vec(self, vec, scale):
        """True when every entry is zero (exactly, or below rtol * scale for floats)."""
        if self.inexact:
            return all(abs(v) <= self.rtol * scale for v in vec.values())
        return all(v == 0 for v in vec.values())


def _split(ring, tau, known):
    """Coefficient vectors: key (row, state monomial, known monomial) -> {parameter monomial: number},
    in the greedy order, and the parameter-free part {key: number}."""
    npar = ring.nparams
    is_known = [any(s in known for s in sp.sympify(g).free_symbols) for g in ring.param_gens]
    coeffs: dict[tuple, dict[tuple, object]] = {}
    free: dict[tuple, object] = {}
    order: list[tuple] = []
    none_known = (0,) * npar
    for row, t in enumerate(tau):
        t = ring.chop(t)
        for m, c in sorted(t.items(), key=lambda mc: _state_rank(ring, mc[0])):
            if any(is_known):
                pm = tuple(e if not is_known[j] else 0 for j, e in enumerate(m[:npar]))
                km = tuple(e if is_known[j] else 0 for j, e in enumerate(m[:npar]))
            else:
                pm, km = m[:npar], none_known
            key = (row, m[npar:], km)
            if not any(pm):  # no unknown parameter: a known term, not part of Theta
                free[key] = free.get(key, 0) + c
                continue
            if key not in coeffs:
                coeffs[key] = {}
                order.append(key)
            coeffs[key][pm] = coeffs[key].get(pm, 0) + c
    return coeffs, order, free


def _eliminate(coeffs, order, F):
    """Greedy basis of the coefficient vectors (Gaussian elimination) and each vector's combination."""
    basis: list[dict[tuple, object]] = []
    echelon: list[tuple] = []  # (pivot monomial, reduced vector, combination over the basis)
    combos: dict[tuple, list] = {}
    for key in order:
        vec = {k: F.num(v) for k, v in coeffs[key].items()}
        vec = {k: v for k, v in vec.items() if v != 0}
        if not vec:
            continue
        scale = max(abs(v) for v in vec.values()) if F.inexact else 1
        red, comb = _reduce(vec, echelon, len(basis))
        if not F.zero_vec(red, scale):
            # new basis element, scaled to primitive form (content 1, positive leading coefficient)
            c = _content(vec)
            prim = {k: v / c for k, v in vec.items()}
            basis.append(prim)
            idx = len(basis) - 1
            red, cmb = _reduce(prim, echelon, idx + 1)
            cmb = [-x for x in cmb]
            cmb[idx] = 1
            if F.inexact:  # round-off entries are not pivots: keep those above rtol of the largest
                big = max(abs(v) for v in red.values())
                red = {k: v for k, v in red.items() if abs(v) > F.rtol * big}
                piv = max(red, key=lambda k: abs(red[k]))
            else:
                piv = max(red)
            echelon.append((piv, red, cmb))
            comb = [0] * idx + [c]
        combos[key] = comb
    return basis, combos


def _reduce(vec, echelon, nb):
    """vec minus its components along the echelon rows, and those components over the basis."""
    red = dict(vec)
    comb = [0] * nb
    for piv, rvec, rcomb in echelon:
        f = red.get(piv, 0)
        if f != 0:
            f = f / rvec[piv]
            for k, v in rvec.items():
                red[k] = red.get(k, 0) - f * v
            del red[piv]  # exactly zero by construction
            for i, a in enumerate(rcomb):
                comb[i] += f * a
    return {k: v for k, v in red.items() if v != 0}, comb


def _content(vec):
    vals = list(vec.values())
    if all(isinstance(v, Fraction) for v in vals):
        g, l = 0, 1
        for v in vals:
            g = gcd(g, abs(v.numerator))
            l = l * v.denominator // gcd(l, v.denominator)
        c = Fraction(g, l)
    else:
        c = vals[0]
    lead = vec[max(vec)]
    return c if (lead / c) > 0 else -c


def base_parameters(eom, known=None) -> sp.Matrix:
    """Theta alone (the grouped base parameters), without forming Y."""
    model, tau = _ring_tau(eom)
    known = _known(eom, model, known)
    coeffs, order, _ = _split(model.ring, tau, known)
    F = _Field(model.ring, rtol=1e-10)
    basis, _ = _eliminate(coeffs, order, F)
    return _theta(model.ring, basis, F)


def _known(eom, model, known):
    known = set(known or [])
    for v in model.gravity:
        known |= sp.sympify(v).free_symbols
    return known


def _theta(ring, basis, F):
    pgens = ring.param_gens
    return sp.Matrix([sp.Add(*[F.sym(v) * _mono(pgens, k) for k, v in b.items()]) for b in basis])


def regressor(eom, known=None) -> Regressor:
    """(Y, Theta) with Y * Theta + tau_known == tau (friction excluded); see the module docstring."""
    model, tau = _ring_tau(eom)
    ring = model.ring
    known = _known(eom, model, known)
    coeffs, order, free = _split(ring, tau, known)
    F = _Field(ring, rtol=1e-10)
    basis, combos = _eliminate(coeffs, order, F)
    p = len(basis)
    Theta = _theta(ring, basis, F)
    Yr = [[ring.zero] * p for _ in tau]
    for key, comb in combos.items():
        row, sm, km = key
        mono = ring.R.from_dict({tuple(km) + tuple(sm): ring.domain.one})
        for j, w in enumerate(comb):
            if w != 0:
                Yr[row][j] += mono * ring.const(F.sym(w))
    Y = ring.matrix_to_sympy([[ring.reduce(e) for e in r] for r in Yr]) if p else sp.zeros(len(tau), 0)
    tk = [ring.zero for _ in tau]
    for (row, sm, km), c in free.items():
        if c:
            tk[row] += ring.R.from_dict({tuple(km) + tuple(sm): c})
    tau_known = ring.matrix_to_sympy([[ring.reduce(e)] for e in tk])
    return Regressor(Y, Theta, tau_known)


def _state_rank(ring, m):
    """Order: acceleration terms, then velocity terms, then the rest (gravity)."""
    acc = [m[j] for j in ring.qdd_idx]
    vel = [m[j] for j in ring.qd_idx]
    trig = sum(m[j] for j in list(ring.c_idx.values()) + list(ring.s_idx.values()))
    group = 0 if any(acc) else (1 if any(vel) else 2)
    return (group, [-e for e in acc], [-e for e in vel], trig, m[ring.nparams :])


def _mono(gens, exps):
    return sp.Mul(*[sp.sympify(g.as_expr() if hasattr(g, "as_expr") else g) ** e for g, e in zip(gens, exps) if e])
