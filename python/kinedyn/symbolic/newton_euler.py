"""Customised symbolic recursive Newton-Euler model (Khalil & Dombre, *Modeling, Identification and
Control of Robots*, §9.4-9.5 "customized symbolic model"; Khalil & Kleinfinger 1987).

The recursion is the textbook one (Spong §9.6, Craig eqs. 6.45-6.53) written in body frames, with the
10 standard inertial parameters about each body origin (first moments h = m c, inertia I_o), so no
centre-of-mass position is ever formed. Symbols: ``E`` = parent_from_body rotation, ``ET`` its
transpose, ``r`` = body origin in parent axes, ``a`` = joint axis in body axes::

    w_j   = ET w_i + qd_j a                                   (angular velocity; revolute)
    wd_j  = ET wd_i + qdd_j a + (ET w_i) x (qd_j a)           (angular acceleration; revolute)
    U_i   = [wd_i]x + [w_i]x [w_i]x                           (Khalil's U matrix)
    vd_j  = ET (vd_i + U_i r_j)  [+ 2 w_j x (qd_j a) + qdd_j a, prismatic];  vd_0 = -gravity
    F_j   = m_j vd_j + U_j h_j                                 (force at the body origin)
    N_j   = I_o wd_j + w_j x (I_o w_j) + h_j x vd_j            (moment about the body origin)
    f_j   = F_j + sum_children E_c f_c
    n_j   = N_j + sum_children (E_c n_c + r_c x (E_c f_c))
    tau_j = a . n_j (revolute) or a . f_j (prismatic) + r^2 J_m qdd_j + viscous qd_j + coulomb sign(qd_j)

Every vector component that is not a plain symbol or number is stored as a named intermediate variable
(``W2z``, ``WP3x``, ``VP3y``, ``U2xy``, ``F4x``, ``N4z``, ``f4x``, ``n4z``, ...); SymPy drops products with
0 and 1 as they are formed, so structural zeros of the axes and rotation matrices cost nothing. Unused
variables are removed at the end (the customised model keeps only what tau needs).
"""

from __future__ import annotations

from typing import Dict, List

import sympy as sp

from .eom import _ops

__all__ = ["Program", "newton_euler_program"]

_XYZ = "xyz"


class Program:
    """A straight-line program: ordered assignments ``symbol = expression`` and named outputs."""

    def __init__(self, reserved=()):
        self.assignments: List[tuple] = []
        self.outputs: Dict[str, list] = {}
        self._names = {str(s) for s in reserved}

    def let(self, name: str, expr):
        """``expr`` itself when it is a number, a symbol or minus a symbol; else a new named variable."""
        expr = sp.sympify(expr)
        if expr.is_Atom or (expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1 and expr.args[1].is_Atom):
            return expr
        while name in self._names:
            name = name + "_"
        self._names.add(name)
        sym = sp.Symbol(name, real=True)
        self.assignments.append((sym, expr))
        return sym

    def prune(self) -> "Program":
        """Remove assignments the outputs do not use (dead-code elimination)."""
        needed = set()
        for exprs in self.outputs.values():
            for e in exprs:
                needed |= sp.sympify(e).free_symbols
        keep = []
        for sym, expr in reversed(self.assignments):
            if sym in needed:
                keep.append((sym, expr))
                needed |= expr.free_symbols
        self.assignments = keep[::-1]
        return self

    def op_count(self, cse: bool = False) -> Dict[str, int]:
        exprs = [e for _, e in self.assignments] + [e for v in self.outputs.values() for e in v]
        if cse:
            repl, red = sp.cse(exprs, order="none")
            exprs = [e for _, e in repl] + list(red)
        return _ops(exprs)

    def expanded(self, name: str = "tau") -> List:
        """The outputs with every intermediate variable substituted back (can be large)."""
        env: dict = {}
        for sym, expr in self.assignments:
            env[sym] = expr.xreplace(env)
        return [sp.sympify(e).xreplace(env) for e in self.outputs[name]]

    def evaluate(self, convert, name: str = "tau") -> List:
        """Evaluate the program in another arithmetic: ``convert(expr, env)`` maps an expression whose
        intermediate symbols are bound in ``env`` to a value (used to get exact ring elements)."""
        env: dict = {}
        for sym, expr in self.assignments:
            env[sym] = convert(expr, env)
        return [convert(sp.sympify(e), env) for e in self.outputs[name]]

    def __str__(self) -> str:
        lines = [f"{s} = {e}" for s, e in self.assignments]
        for name, exprs in self.outputs.items():
            lines += [f"{name}{k + 1} = {e}" for k, e in enumerate(exprs)]
        return "\n".join(lines)


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _matvec(A, v):
    return [sum((A[r][k] * v[k] for k in range(3)), sp.Integer(0)) for r in range(3)]


def _matTvec(A, v):
    return [sum((A[k][r] * v[k] for k in range(3)), sp.Integer(0)) for r in range(3)]


def newton_euler_program(robot, q, qd, qdd, parameters=None, gravity: bool = True, friction: bool = True, exact=None) -> Program:
    """The customised Newton-Euler model of ``robot`` (see the module docstring).

    ``parameters``: optional list of per-body 10-vectors [m, mx, my, mz, XX, XY, YY, XZ, YZ, ZZ]
    (about the body origin, body axes) replacing the description's inertias (e.g. general symbols).
    ``exact``: the value converter (kinedyn.symbolic.lagrange._exact)."""
    from .lagrange import _exact, _matrix

    exact = exact or _exact
    bodies = robot.tree.bodies
    n = len(bodies)
    prog = Program(reserved=set(robot.symbols) | set(q) | set(qd) | set(qdd))
    let = prog.let
    zero = sp.Integer(0)
    children: Dict[int, list] = {i: [] for i in range(-1, n)}
    for j, b in enumerate(bodies):
        children[b.parent].append(j)
    E, r, axis, w, wd, vd, U, pi = {}, {}, {}, {}, {}, {}, {}, {}
    g = [exact(x) for x in robot.gravity]
    w[-1] = [zero] * 3
    wd[-1] = [zero] * 3
    vd[-1] = [-x for x in g] if gravity else [zero] * 3
    U[-1] = [[zero] * 3 for _ in range(3)]
    # ---- forward recursion: velocities and accelerations, base to tip
    for j, b in enumerate(bodies):
        J = j + 1
        i = b.parent
        T = _matrix(b.placement)
        PR = [row[:3] for row in T[:3]]
        Pp = [row[3] for row in T[:3]]
        a = [exact(x) for x in b.joint.axis]
        axis[j] = a
        off = exact(b.joint.offset)
        if b.joint.kind == "revolute":
            # joint rotation (Rodrigues) with C = cos(q + offset), S = sin(q + offset)
            C = let(f"C{J}", sp.cos(q[j] + off))
            S = let(f"S{J}", sp.sin(q[j] + off))
            Sa = [[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]]
            Rj = [[(C if rr == k else 0) + S * Sa[rr][k] + (1 - C) * a[rr] * a[k] for k in range(3)] for rr in range(3)]
            Rj = [[sp.expand(x) for x in row] for row in Rj]
            Ej = [[let(f"E{J}{_XYZ[rr]}{_XYZ[k]}", sum((PR[rr][m] * Rj[m][k] for m in range(3)), zero)) for k in range(3)] for rr in range(3)]
            rj = Pp
        else:
            Ej = PR
            d = q[j] + off
            rj = [let(f"P{J}{_XYZ[k]}", Pp[k] + sum((PR[k][m] * a[m] for m in range(3)), zero) * d) for k in range(3)]
        E[j], r[j] = Ej, rj
        # w_j = ET w_i + qd a ; wd_j = ET wd_i + qdd a + (ET w_i) x (qd a)
        wi = [let(f"WI{J}{_XYZ[k]}", x) for k, x in enumerate(_matTvec(Ej, w[i]))]
        wdi = _matTvec(Ej, wd[i])
        if b.joint.kind == "revolute":
            qa = [qd[j] * x for x in a]
            w[j] = [let(f"W{J}{_XYZ[k]}", wi[k] + qa[k]) for k in range(3)]
            cr = _cross(wi, qa)
            wd[j] = [let(f"WP{J}{_XYZ[k]}", wdi[k] + qdd[j] * a[k] + cr[k]) for k in range(3)]
        else:
            w[j] = wi
            wd[j] = [let(f"WP{J}{_XYZ[k]}", x) for k, x in enumerate(wdi)]
        # vd_j = ET (vd_i + U_i r_j) [+ 2 w_j x (qd a) + qdd a]
        Ur = _matvec(U[i], rj)
        vin = [let(f"VI{J}{_XYZ[k]}", vd[i][k] + Ur[k]) for k in range(3)]
        v = _matTvec(Ej, vin)
        if b.joint.kind == "prismatic":
            qa = [qd[j] * x for x in a]
            cr = _cross(w[j], qa)
            v = [v[k] + 2 * cr[k] + qdd[j] * a[k] for k in range(3)]
        vd[j] = [let(f"VP{J}{_XYZ[k]}", x) for k, x in enumerate(v)]
        # U_j = [wd]x + [w]x[w]x with the products w_a w_b as variables
        ww = {}
        for a1 in range(3):
            for a2 in range(a1, 3):
                ww[a1, a2] = ww[a2, a1] = let(f"WW{J}{_XYZ[a1]}{_XYZ[a2]}", w[j][a1] * w[j][a2])
        Sw = [[0, -wd[j][2], wd[j][1]], [wd[j][2], 0, -wd[j][0]], [-wd[j][1], wd[j][0], 0]]
        U[j] = [[let(f"U{J}{_XYZ[a1]}{_XYZ[a2]}", Sw[a1][a2] + ww[a1, a2] - (ww[0, 0] + ww[1, 1] + ww[2, 2] if a1 == a2 else 0)) for a2 in range(3)] for a1 in range(3)]
        params = parameters[j] if parameters is not None else b.inertia.parameters()
        pi[j] = [exact(sp.expand(sp.cancel(x)) if isinstance(x, sp.Basic) else x) for x in params]
    # ---- per-body force and moment at the body origin
    F, N = {}, {}
    for j in range(n):
        J = j + 1
        m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = pi[j]
        h = [hx, hy, hz]
        Io = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]
        Uh = _matvec(U[j], h)
        F[j] = [let(f"F{J}{_XYZ[k]}", m * vd[j][k] + Uh[k]) for k in range(3)]
        Jw = [let(f"JW{J}{_XYZ[k]}", x) for k, x in enumerate(_matvec(Io, w[j]))]
        Jwd = _matvec(Io, wd[j])
        c1 = _cross(w[j], Jw)
        c2 = _cross(h, vd[j])
        N[j] = [let(f"N{J}{_XYZ[k]}", Jwd[k] + c1[k] + c2[k]) for k in range(3)]
    # ---- backward recursion: f_j = F_j + sum E_c f_c ; n_j = N_j + sum (E_c n_c + r_c x E_c f_c)
    f, nn, tau = {}, {}, [None] * n
    for j in reversed(range(n)):
        J = j + 1
        fj, nj = list(F[j]), list(N[j])
        for c in children[j]:
            Ef = [let(f"FE{c + 1}{_XYZ[k]}", x) for k, x in enumerate(_matvec(E[c], f[c]))]
            En = _matvec(E[c], nn[c])
            rf = _cross(r[c], Ef)
            fj = [fj[k] + Ef[k] for k in range(3)]
            nj = [nj[k] + En[k] + rf[k] for k in range(3)]
        f[j] = [let(f"f{J}{_XYZ[k]}", x) for k, x in enumerate(fj)]
        nn[j] = [let(f"n{J}{_XYZ[k]}", x) for k, x in enumerate(nj)]
        b = bodies[j]
        gen = nn[j] if b.joint.kind == "revolute" else f[j]
        t = sum((axis[j][k] * gen[k] for k in range(3)), zero)
        t = t + exact(b.joint.armature) * qdd[j]
        if friction:
            t = t + exact(b.joint.viscous) * qd[j] + exact(b.joint.coulomb) * sp.sign(qd[j])
        tau[j] = t
    prog.outputs["tau"] = tau
    return prog.prune()
