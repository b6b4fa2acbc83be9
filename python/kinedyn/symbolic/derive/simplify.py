"""Exact, fast simplification of robot dynamics expressions to the textbook form.

Every quantity of a rigid-body model (positions, D(q), P(q), C(q, qd), tau) is a polynomial in the
sines and cosines of the revolute coordinates, the prismatic coordinates, the velocities and
accelerations, with coefficients that are polynomials in the parameters. :class:`TrigRing` does all
arithmetic in a sparse polynomial ring (SymPy's ``PolyRing``) with generators

    parameters ...,  c_i = cos q_i, s_i = sin q_i  (revolute),  q_i (prismatic),  qd_i,  qdd_i

and keeps every element in the normal form modulo the ideal (s_i^2 + c_i^2 - 1): no s_i appears
with a power above one (s_i^2 is rewritten 1 - c_i^2 as soon as it is formed). Two expressions are
equal exactly when their normal forms are equal, so "simplifies to zero" is a dictionary comparison.

Mimic joints (a joint whose coordinate is ``m q_i + o``) need more: cos(m q_i) for an integer m is a
polynomial in c_i, s_i (angle addition), but for a fractional m (or a prismatic q_i) it is not, so
such a multiple gets generators of its own, ``cos(m q_i)`` and ``sin(m q_i)`` (``multiples``), and a
prismatic follower of a revolute q_i needs q_i itself (``angles``). They are functions of q_i, not
new coordinates: :meth:`TrigRing.diff_q` differentiates them by the chain rule,
``d cos(m q_i)/dq_i = -m sin(m q_i)``, a derivation of the ring (it maps cos^2 + sin^2 - 1 to 0), so
every identity of the derivation (Lagrange's equations, Christoffel symbols) holds exactly; only the
normal form is no longer unique across such generators (cos(q_i) and cos(3 q_i / 2) are not
independent functions), which the printed output leaves to SymPy's term collection.

Output (:meth:`TrigRing.to_sympy`) linearises each trigonometric monomial by the product-to-sum
formulas into the unique Fourier form  sum_k a_k cos(k.q) + b_k sin(k.q)  (k an integer vector with its
first non-zero entry positive). This is the textbook form: cos(q1 + q2) rather than c1 c2 - s1 s2,
m2 (l1^2 + 2 l1 lc2 cos q2 ...) with cos^2 + sin^2 = 1 applied. Coefficients of each term are
collected and factored when short. Nothing here calls ``sympy.simplify``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from fractions import Fraction
from functools import lru_cache
from typing import Any

import sympy as sp
from sympy.polys.rings import PolyRing, sring

__all__ = ["TrigRing", "trig_normal_form", "simplify_trig", "chop"]


def chop(value: float, tol: float = 1e-13) -> float:
    """A float with round-off zeros removed (cos(pi/2) = 6e-17 -> 0.0): keeps expressions short."""
    return 0.0 if abs(value) < tol else value


class TrigRing:
    """The polynomial ring of one model; see the module docstring.

    ``coordinates``: list of (symbol, kind) with kind ``"revolute"`` or ``"prismatic"``;
    ``velocities``, ``accelerations``: symbol lists of the same length; ``leaves``: SymPy expressions
    of the parameters that will be converted into the ring (used to find the parameter generators
    and the coefficient domain). ``multiples``: pairs (i, m), exact non-zero constants m, whose
    cos(m q_i), sin(m q_i) get generators of their own (needed for a fractional m of a revolute q_i,
    any m of a prismatic one); ``angles``: revolute coordinates i whose q_i itself is a generator
    (see the module docstring: mimic joints).
    """

    def __init__(
        self, coordinates, velocities, accelerations, leaves: Iterable = (), extra_symbols=(), multiples=(), angles=()
    ):
        self.q = [c for c, _ in coordinates]
        self.kinds = [k for _, k in coordinates]
        self.qd = list(velocities)
        self.qdd = list(accelerations)
        self.n = len(self.q)
        leaves = [sp.sympify(e) for e in leaves]
        state = set(self.q) | set(self.qd) | set(self.qdd)
        for e in leaves:
            bad = e.free_symbols & state
            if bad:
                raise ValueError(f"parameter expression {e} depends on the coordinates {sorted(map(str, bad))}")
        params = [e for e in leaves if not e.is_number] + [sp.sympify(s) for s in extra_symbols]
        if params:
            R0, _ = sring(params + [sp.Integer(1)])
            domain = R0.domain
            pgens = list(R0.symbols)
        else:
            domain = sp.QQ
            pgens = []
        if any(isinstance(e, sp.Float) or (e.is_number and e.has(sp.Float)) for e in leaves):
            domain = sp.RR if domain in (sp.ZZ, sp.QQ) else domain
        for e in leaves:  # irrational numbers (sqrt(2), pi) need the EX domain
            if e.is_number and not e.is_Rational and not isinstance(e, sp.Float):
                domain = sp.EX
        if domain == sp.ZZ:
            domain = sp.QQ
        elif not domain.is_Field and domain != sp.EX:
            domain = domain.get_field()
        self.domain = domain
        self.param_gens = pgens
        # generator layout: params | c_i, s_i (revolute) or q_i (prismatic) | qd | qdd
        self.c_sym, self.s_sym = {}, {}
        gens = list(pgens)
        self.c_idx, self.s_idx, self.p_idx = {}, {}, {}
        for i, (qi, kind) in enumerate(coordinates):
            if kind == "revolute":
                self.c_sym[i] = sp.Dummy(f"c{i + 1}")
                self.s_sym[i] = sp.Dummy(f"s{i + 1}")
                self.c_idx[i] = len(gens)
                gens.append(self.c_sym[i])
                self.s_idx[i] = len(gens)
                gens.append(self.s_sym[i])
            elif kind == "prismatic":
                self.p_idx[i] = len(gens)
                gens.append(qi)
            else:
                raise ValueError(f"coordinate kind must be 'revolute' or 'prismatic', got {kind!r}")
        # trigonometric pairs (c, s generator indices, angle): each coordinate's own, then the multiples
        self._pairs = [(self.c_idx[i], self.s_idx[i], self.q[i]) for i in sorted(self.c_idx)]
        self.m_idx: dict = {}  # (i, m) -> (c index, s index) of cos(m q_i), sin(m q_i)
        for i, m in multiples:
            m = sp.sympify(m)
            if (i, m) in self.m_idx:
                continue
            if m == 0 or (i in self.c_idx and m.is_Integer):
                raise ValueError(
                    f"multiple {m} of coordinate {self.q[i]}: an integer multiple of a revolute coordinate needs no generator"
                )
            c_m, s_m = sp.Dummy(f"c{i + 1}m"), sp.Dummy(f"s{i + 1}m")
            self.m_idx[i, m] = (len(gens), len(gens) + 1)
            gens += [c_m, s_m]
            self._pairs.append((len(gens) - 2, len(gens) - 1, m * self.q[i]))
        self.a_idx: dict = {}  # revolute i -> index of the generator q_i
        for i in angles:
            if i not in self.c_idx:
                raise ValueError(f"coordinate {self.q[i]} is not revolute: it is a generator already")
            if i not in self.a_idx:
                self.a_idx[i] = len(gens)
                gens.append(self.q[i])
        self.qd_idx = list(range(len(gens), len(gens) + self.n))
        gens += self.qd
        self.qdd_idx = list(range(len(gens), len(gens) + self.n))
        gens += self.qdd
        self.R = PolyRing(gens, domain)
        self.gens = self.R.gens
        self.nparams = len(pgens)
        self.zero, self.one = self.R.zero, self.R.one
        self._param_ring = PolyRing(pgens, domain) if pgens else None
        # s^2 -> 1 - c^2 for every trigonometric pair: (s index, 1 - c^2)
        self._s_rules = [(j_s, self.one - self.gens[j_c] ** 2) for j_c, j_s, _ in self._pairs]
        self._cache: dict = {}

    # ------------------------------------------------------------------ conversion in
    def const(self, value):
        """A parameter expression (number or SymPy expression free of the state) as a ring element."""
        if isinstance(value, float):
            value = chop(value)
            return self.R(self.domain.convert(value)) if value else self.zero
        e = sp.sympify(value)
        if e.is_number:
            if e == 0:
                return self.zero
            if self.domain == sp.EX:
                return self.R(self.domain.from_sympy(e))
            return self.R(self.domain.from_sympy(sp.Float(chop(float(e))) if isinstance(e, sp.Float) else e))
        key = ("const", e)
        if key not in self._cache:
            self._cache[key] = self._from_param_expr(e)
        return self._cache[key]

    def _from_param_expr(self, e):
        try:
            return self.R.from_expr(e)
        except Exception:
            pass
        # generators that are not plain symbols (sin(alpha), 1/m): map through sring's own split
        R0, (p,) = sring([e], *self.param_gens, domain=self.domain)
        width = len(self.gens) - len(self.param_gens)
        return self.R.from_dict({m + (0,) * width: c for m, c in p.items()})

    def cos(self, i, offset=0):
        """cos(q_i + offset) for a revolute coordinate."""
        return self._trig(i, offset, "cos")

    def sin(self, i, offset=0):
        return self._trig(i, offset, "sin")

    def _trig(self, i, offset, which):
        c, s = self.gens[self.c_idx[i]], self.gens[self.s_idx[i]]
        return self._shifted(c, s, offset, which)

    def _shifted(self, c, s, offset, which):
        """cos or sin of (x + offset) from c = cos x, s = sin x."""
        if isinstance(offset, float) or (isinstance(offset, sp.Basic) and offset.is_number and offset.has(sp.Float)):
            co, so = self.const(math.cos(float(offset))), self.const(math.sin(float(offset)))
        else:
            co, so = self.const(sp.cos(offset)), self.const(sp.sin(offset))
        # cos(q + o) = c cos o - s sin o ; sin(q + o) = s cos o + c sin o
        return c * co - s * so if which == "cos" else s * co + c * so

    def cos_multiple(self, i, m, offset=0):
        """cos(m q_i + offset): by angle addition for an integer m of a revolute q_i, else through the
        generators of the multiple (i, m) given to the constructor."""
        return self._multiple(i, m, offset, "cos")

    def sin_multiple(self, i, m, offset=0):
        return self._multiple(i, m, offset, "sin")

    def _multiple(self, i, m, offset, which):
        m = sp.sympify(m)
        if i in self.c_idx and m == 1:
            return self._trig(i, offset, which)
        if i in self.c_idx and m.is_Integer:
            c, s = self._integer_multiple(i, int(m))
        elif (i, m) in self.m_idx:
            j_c, j_s = self.m_idx[i, m]
            c, s = self.gens[j_c], self.gens[j_s]
        elif (i, -m) in self.m_idx:  # cos(-x) = cos x, sin(-x) = -sin x (SymPy writes cos(3 q/2 - o))
            j_c, j_s = self.m_idx[i, -m]
            c, s = self.gens[j_c], -self.gens[j_s]
        else:
            raise ValueError(f"cos({m} {self.q[i]}) is not in this ring (pass ({i}, {m}) in multiples)")
        return self.reduce(self._shifted(c, s, offset, which))

    def _integer_multiple(self, i, k):
        """(cos(k q_i), sin(k q_i)) by repeated angle addition."""
        ci, si = self.gens[self.c_idx[i]], self.gens[self.s_idx[i]]
        if k < 0:
            si = -si
        C, S = self.one, self.zero
        for _ in range(abs(k)):
            C, S = self.reduce(C * ci - S * si), self.reduce(S * ci + C * si)
        return C, S

    def angle(self, i):
        """q_i as a polynomial: the generator of a prismatic coordinate, or of a revolute one given in
        ``angles``."""
        if i in self.p_idx:
            return self.gens[self.p_idx[i]]
        if i in self.a_idx:
            return self.gens[self.a_idx[i]]
        raise ValueError(f"the revolute coordinate {self.q[i]} itself is not in this ring (pass {i} in angles)")

    def coordinate(self, i):
        return self.gens[self.p_idx[i]]

    def velocity(self, i):
        return self.gens[self.qd_idx[i]]

    def acceleration(self, i):
        return self.gens[self.qdd_idx[i]]

    def from_sympy(self, expr):
        """Any SymPy expression polynomial in the sines and cosines of integer combinations of the
        revolute coordinates (and polynomial in the rest) -> normal form. Raises ValueError otherwise."""
        expr = sp.sympify(expr)
        rep = {}
        for f in expr.atoms(sp.sin, sp.cos):
            if f.args[0].free_symbols & set(self.q):
                rep[f] = self._trig_of_argument(f)
        try:
            out = self._convert(expr, rep)
        except (ValueError, sp.PolynomialError, sp.CoercionFailed) as exc:
            raise ValueError(
                f"expression is not a polynomial in the trigonometric functions of the coordinates: {exc}"
            ) from None
        return self.reduce(out)

    def _trig_of_argument(self, f):
        arg = sp.expand(f.args[0])
        qs = [self.q[i] for i in range(self.n)]
        coeffs = {}
        rest = arg
        for i, qi in enumerate(qs):
            k = arg.coeff(qi)
            if k != 0:
                if not ((i in self.c_idx and k.is_Integer) or (i, k) in self.m_idx):
                    raise ValueError(f"{f}: argument must be an integer combination of revolute coordinates")
                coeffs[i] = k
                rest -= k * qi
        rest = sp.expand(rest)
        if rest.free_symbols & (set(self.q) | set(self.qd) | set(self.qdd)):
            raise ValueError(f"{f}: argument is not linear in the coordinates")
        # cos/sin of sum k_i q_i via repeated angle addition, then the constant phase
        C, S = self.one, self.zero
        for i, k in coeffs.items():
            ci, si = self.cos_multiple(i, k), self.sin_multiple(i, k)
            C, S = self.reduce(C * ci - S * si), self.reduce(S * ci + C * si)
        co, so = self.const(sp.cos(rest)), self.const(sp.sin(rest))
        if isinstance(f, sp.cos):
            return self.reduce(C * co - S * so)
        return self.reduce(S * co + C * so)

    def _convert(self, e, rep):
        if e in rep:
            return rep[e]
        state = set(self.q) | set(self.qd) | set(self.qdd)
        if not (e.free_symbols & state):
            return self.const(e)
        if e.is_Symbol:
            if e in self.qd:
                return self.velocity(self.qd.index(e))
            if e in self.qdd:
                return self.acceleration(self.qdd.index(e))
            i = self.q.index(e)
            if i in self.p_idx or i in self.a_idx:
                return self.angle(i)
            raise ValueError(f"revolute coordinate {e} appears outside sin/cos")
        if e.is_Add:
            out = self.zero
            for a in e.args:
                out += self._convert(a, rep)
            return out
        if e.is_Mul:
            out = self.one
            for a in e.args:
                out = self.reduce(out * self._convert(a, rep))
            return out
        if e.is_Pow and e.exp.is_Integer and e.exp >= 0:
            base = self._convert(e.base, rep)
            out = self.one
            for _ in range(int(e.exp)):
                out = self.reduce(out * base)
            return out
        raise ValueError(f"cannot convert {e}")

    # ------------------------------------------------------------------ arithmetic
    def reduce(self, p):
        """Normal form modulo s_i^2 + c_i^2 - 1 (every s_i to a power of at most one)."""
        rules = self._s_rules
        if not rules:
            return p
        if all(m[j] < 2 for m in p.keys() for j, _ in rules):
            return p
        clean: dict = {}
        dirty = self.zero
        for m, c in p.items():
            if all(m[j] < 2 for j, _ in rules):
                clean[m] = clean.get(m, 0) + c
                continue
            mm = list(m)
            factor = self.one
            for j, one_minus_c2 in rules:
                e = mm[j]
                if e >= 2:
                    mm[j] = e % 2
                    factor = factor * one_minus_c2 ** (e // 2)
            dirty += self.R.from_dict({tuple(mm): c}) * factor
        return self.R.from_dict(clean) + dirty if clean else dirty

    def is_zero(self, p, reference=None, rtol: float = 1e-10) -> bool:
        """Exactly zero; for a float domain, zero up to round-off relative to ``reference``."""
        if not p:
            return True
        if self.domain != sp.RR:
            return False
        scale = max([abs(float(c)) for c in reference.values()] + [1.0]) if reference else 1.0
        return all(abs(float(c)) <= rtol * scale for c in p.values())

    def chop(self, p, rtol: float = 1e-12):
        """Drop round-off terms of a float-domain element (|c| below rtol times the largest)."""
        if self.domain != sp.RR or not p:
            return p
        big = max(abs(float(c)) for c in p.values())
        return self.R.from_dict({m: c for m, c in p.items() if abs(float(c)) > rtol * big})

    def mul(self, a, b):
        return self.reduce(a * b)

    def dot(self, xs, ys):
        out = self.zero
        for x, y in zip(xs, ys):
            if x and y:
                out += x * y
        return self.reduce(out)

    def diff_q(self, p, i):
        """d p / d q_i (chain rule through c_i, s_i for a revolute coordinate, and through the
        generators of its multiples, d cos(m q_i)/dq_i = -m sin(m q_i), and its angle generator)."""
        if i in self.p_idx:
            out = p.diff(self.gens[self.p_idx[i]])
        else:
            c, s = self.gens[self.c_idx[i]], self.gens[self.s_idx[i]]
            out = -p.diff(c) * s + p.diff(s) * c
            if i in self.a_idx:
                out += p.diff(self.gens[self.a_idx[i]])
        for (k, m), (j_c, j_s) in self.m_idx.items():
            if k == i:
                c, s = self.gens[j_c], self.gens[j_s]
                out += (-p.diff(c) * s + p.diff(s) * c) * self.const(m)
        return self.reduce(out)

    def diff_qd(self, p, i):
        return p.diff(self.gens[self.qd_idx[i]])

    def diff_qdd(self, p, i):
        return p.diff(self.gens[self.qdd_idx[i]])

    def time_derivative(self, p):
        """d p / dt = sum_i dp/dq_i qd_i + dp/dqd_i qdd_i (no explicit time dependence)."""
        out = self.zero
        for i in range(self.n):
            dq = self.diff_q(p, i)
            if dq:
                out += dq * self.velocity(i)
            dqd = self.diff_qd(p, i)
            if dqd:
                out += dqd * self.acceleration(i)
        return self.reduce(out)

    def substitute_state(self, p, qd_zero=False, qdd_zero=False):
        """p with the velocities and/or accelerations set to zero."""
        idx = (self.qd_idx if qd_zero else []) + (self.qdd_idx if qdd_zero else [])
        return self.R.from_dict({m: c for m, c in p.items() if all(m[j] == 0 for j in idx)})

    # ------------------------------------------------------------------ conversion out
    def _symbol_map(self):
        return {self.R.symbols[j_c]: sp.cos(angle) for j_c, _, angle in self._pairs} | {
            self.R.symbols[j_s]: sp.sin(angle) for _, j_s, angle in self._pairs
        }

    def to_product_form(self, p):
        """SymPy expression with sin(q_i), cos(q_i) products (no angle sums)."""
        return p.as_expr().xreplace(self._symbol_map())

    def to_sympy(self, p, factor: bool = True):
        """The Fourier (textbook) form of a normal-form element as a SymPy expression."""
        p = self.chop(p)
        if not p:
            return sp.Integer(0)
        trig_js = sorted([j for j_c, j_s, _ in self._pairs for j in (j_c, j_s)])
        angles = [angle for _, _, angle in self._pairs]
        nparam = self.nparams
        groups: dict[tuple, dict[tuple, Any]] = {}
        to_sym = self.domain.to_sympy
        for m, c in p.items():
            pm = m[:nparam]
            trig = tuple((m[j_c], m[j_s]) for j_c, j_s, _ in self._pairs)
            other = tuple(e if j not in trig_js else 0 for j, e in enumerate(m) if j >= nparam)
            for (k, kind), w in _linearise(trig).items():
                key = (other, k, kind)
                g = groups.setdefault(key, {})
                g[pm] = g.get(pm, 0) + to_sym(c) * sp.Rational(w.numerator, w.denominator)
        terms = []
        other_gens = self.gens[nparam:]
        big = max([abs(float(v)) for g in groups.values() for v in g.values()] + [0.0]) if self.domain == sp.RR else 0.0
        for (other, k, kind), coeffs in groups.items():
            if self.domain == sp.RR:
                coeffs = {pm: v for pm, v in coeffs.items() if abs(float(v)) > 1e-12 * big}
            coeff = sp.Add(
                *[
                    v * sp.Mul(*[g.as_expr() ** e for g, e in zip(self.param_gens, pm) if e])
                    for pm, v in coeffs.items()
                    if v != 0
                ]
            )
            if coeff == 0:
                continue
            if factor and self.domain != sp.RR and len(sp.Add.make_args(coeff)) <= 8:
                coeff = sp.factor_terms(sp.factor(coeff))
            state = sp.Mul(*[g.as_expr() ** e for g, e in zip(other_gens, other) if e])
            angle = sum((kk * a for kk, a in zip(k, angles)), sp.Integer(0))
            trig = sp.Integer(1) if all(kk == 0 for kk in k) else (sp.cos(angle) if kind == "cos" else sp.sin(angle))
            terms.append(coeff * trig * state)
        return sp.Add(*terms)

    def matrix_to_sympy(self, rows, factor: bool = True) -> sp.Matrix:
        return sp.Matrix([[self.to_sympy(e, factor) for e in row] for row in rows])


@lru_cache(maxsize=4096)
def _linearise(trig: tuple) -> dict:
    """prod_i cos(q_i)^a_i sin(q_i)^b_i  ->  {(k, 'cos'|'sin'): weight} by product-to-sum.

    Uses exponentials: cos x = (z + 1/z)/2, sin x = (z - 1/z)/(2i); a Laurent polynomial in the z_i
    with complex rational coefficients, then the pairs k, -k recombined into cos(k.q), sin(k.q)."""
    n = len(trig)
    poly = {(0,) * n: (Fraction(1), Fraction(0))}  # exponent vector -> (re, im)
    for i, (a, b) in enumerate(trig):
        for _ in range(a):
            poly = _mul_exp(poly, i, n, ((Fraction(1, 2), Fraction(0)), (Fraction(1, 2), Fraction(0))))
        for _ in range(b):
            # (z - 1/z)/(2i) = -i/2 z + i/2 z^-1
            poly = _mul_exp(poly, i, n, ((Fraction(0), Fraction(-1, 2)), (Fraction(0), Fraction(1, 2))))
    out: dict = {}
    for k, (re, im) in poly.items():
        if re == 0 and im == 0:
            continue
        first = next((x for x in k if x != 0), 0)
        if first < 0:
            continue  # handled with its positive partner
        if first == 0:
            out[(k, "cos")] = out.get((k, "cos"), 0) + re
            continue
        neg = tuple(-x for x in k)
        re2, im2 = poly.get(neg, (Fraction(0), Fraction(0)))
        # a e^{ix} + b e^{-ix} = (a + b) cos x + i (a - b) sin x ; real part taken
        cos_w = re + re2
        sin_w = -(im - im2)
        if cos_w:
            out[(k, "cos")] = cos_w
        if sin_w:
            out[(k, "sin")] = sin_w
    return {key: w for key, w in out.items() if w}


def _mul_exp(poly, i, n, factor):
    (pr, pi_), (mr, mi) = factor  # coefficient of z_i^{+1} and z_i^{-1}
    out: dict = {}
    for k, (re, im) in poly.items():
        for shift, (fr, fi) in ((1, (pr, pi_)), (-1, (mr, mi))):
            shifted = list(k)
            shifted[i] += shift
            kk = tuple(shifted)
            r0, i0 = out.get(kk, (Fraction(0), Fraction(0)))
            out[kk] = (r0 + re * fr - im * fi, i0 + re * fi + im * fr)
    return out


def trig_normal_form(expr, coordinates: Sequence, prismatic: Sequence = ()) -> tuple[TrigRing, object]:
    """(ring, element): the normal form of ``expr`` in the sines and cosines of ``coordinates``."""
    coords = [(q, "prismatic" if q in set(prismatic) else "revolute") for q in coordinates]
    expr = sp.sympify(expr)
    state = set(coordinates)
    leaves = [a for a in _parameter_atoms(expr, state)]
    ring = TrigRing(coords, [], [], leaves)
    return ring, ring.from_sympy(expr)


def _parameter_atoms(expr, state):
    """Maximal sub-expressions free of the state that are not products/sums/powers (for generator discovery)."""
    out = set()

    def walk(e):
        if not (e.free_symbols & state):
            if not e.is_number:
                out.add(e)
            return
        if isinstance(e, (sp.sin, sp.cos)):
            arg = sp.expand(e.args[0])
            rest = arg.subs({s: 0 for s in state})
            if rest != 0:
                out.add(sp.cos(rest))
                out.add(sp.sin(rest))
            return
        for a in e.args:
            walk(a)

    walk(expr)
    return sorted(out, key=sp.default_sort_key)


def simplify_trig(expr, coordinates: Sequence, prismatic: Sequence = (), factor: bool = True):
    """Textbook form of one scalar expression in the coordinates (falls back to ``sympy.trigsimp``
    when the expression is not a trigonometric polynomial, e.g. has sqrt or a denominator in q)."""
    expr = sp.sympify(expr)
    if not expr.free_symbols & set(coordinates):
        return sp.expand(expr) if expr.is_polynomial() else expr
    try:
        ring, p = trig_normal_form(expr, coordinates, prismatic)
    except ValueError:
        return sp.trigsimp(sp.cancel(expr))
    return ring.to_sympy(p, factor)


def textbook_form(expr, coordinates: Sequence = (), prismatic: Sequence = ()):
    """A result of a Lagrangian system (L, multipliers, H and Hamilton's equations, an Euler-Lagrange
    expression) in the size a textbook prints it; a matrix entry by entry.

    The expression is brought over one denominator (``sympy.together``); numerator and denominator
    are each put in the trigonometric normal form of :func:`simplify_trig` (so ``sin^2 + cos^2``
    collapses and products of sines and cosines become sines and cosines of sums), common factors
    are cancelled, and constants pulled out (``sympy.factor_terms``). The smallest of the candidates
    by ``sympy.count_ops`` is returned — never a larger expression than the input. Examples: the
    sphere particle's multiplier ``(2 qd1^2 + ...)/(4 q1^2/m + ...)`` -> ``m (qd1^2 + ...)/(2 (q1^2 + ...))``;
    the knife edge's ``.../(sin^2/m + cos^2/m)`` loses its denominator."""
    if isinstance(expr, sp.MatrixBase):
        return expr.applyfunc(lambda e: textbook_form(e, coordinates, prismatic))
    expr = sp.sympify(expr)
    if expr.is_Atom:
        return expr
    coordinates, prismatic = list(coordinates), list(prismatic)

    def ring(x):
        x = sp.expand(x)
        if coordinates and x.free_symbols & set(coordinates):
            return simplify_trig(x, coordinates, prismatic=prismatic)
        return sp.factor_terms(x)

    candidates = [expr]
    if sp.count_ops(expr) > 300:  # cancel/together on larger fractions takes minutes (the five-bar's H): keep it
        return expr
    together = sp.together(expr)
    num, den = sp.fraction(together)
    try:
        num, den = ring(num), ring(den)
    except (ValueError, TypeError, NotImplementedError):  # not a trigonometric polynomial (sqrt, ...)
        pass
    candidates.append(sp.factor_terms(num) / sp.factor_terms(den))
    try:
        cancelled = sp.cancel(num / den)
        n2, d2 = sp.fraction(cancelled)
        candidates.append(sp.factor_terms(ring(n2)) / sp.factor_terms(ring(d2)))
    except (sp.PolynomialError, ValueError, TypeError, NotImplementedError):
        pass
    if expr.is_Add:  # terms over different denominators (H = p^T M^-1 p / 2 + P): one fraction per denominator
        groups: dict[Any, list] = {}
        try:
            for term in sp.Add.make_args(expr):
                n, d = sp.fraction(sp.cancel(sp.together(term)))
                groups.setdefault(sp.factor_terms(ring(d)), []).append(n)
            parts = []
            for d, ns in groups.items():
                n = ring(sp.Add(*ns))
                n2, d2 = sp.fraction(sp.cancel(n / d))
                parts.append(sp.factor_terms(ring(n2)) / sp.factor_terms(ring(d2)))
            candidates.append(sp.Add(*parts))
        except (sp.PolynomialError, ValueError, TypeError, NotImplementedError):
            pass
    if sp.count_ops(expr) < 60:  # small enough for SymPy's general heuristics (seconds on larger ones)
        candidates.append(sp.factor_terms(sp.simplify(expr)))
    return min(candidates, key=lambda e: (sp.count_ops(e), len(str(e))))
