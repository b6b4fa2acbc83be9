"""Customised symbolic recursive Newton-Euler model (Khalil & Dombre, *Modeling, Identification and
Control of Robots*, §9.4-9.5 "customized symbolic model", §14.5 grouped (base) parameters; Khalil &
Kleinfinger 1987).

The recursion is the textbook one (Spong §9.6, Craig eqs. 6.45-6.53; K&D ch. 9, Newton-Euler formulation) written in
body frames, with the 10 standard inertial parameters about each body origin (first moments h = m c,
inertia I_o), so no centre-of-mass position is ever formed. Symbols: ``E`` = parent_from_body
rotation, ``ET`` its transpose, ``r`` = body origin in parent axes, ``a`` = joint axis in body axes::

    w_j   = ET w_i + qd_j a                                   (angular velocity; revolute)
    wd_j  = ET wd_i + qdd_j a + (ET w_i) x (qd_j a)           (angular acceleration; revolute)
    U_i   = [wd_i]x + [w_i]x [w_i]x                           (Khalil's U matrix)
    vd_j  = ET (vd_i + U_i r_j)  [+ 2 w_j x (qd_j a) + qdd_j a, prismatic];  vd_0 = -gravity
    F_j   = m_j vd_j + U_j h_j                                 (force at the body origin)
    N_j   = I_o wd_j + w_j x (I_o w_j) + h_j x vd_j            (moment about the body origin)
    f_j   = F_j + sum_children E_c f_c
    n_j   = N_j + sum_children (E_c n_c + r_c x (E_c f_c))
    tau_j = a . n_j (revolute) or a . f_j (prismatic) + r^2 J_m qdd_j + viscous qd_j + coulomb sign(qd_j)

With reduced mimic joints (``robot.mimic_joints``) the recursion runs over every body, a follower's
joint variables being ``m q_k + o``, ``m qd_k``, ``m qdd_k`` (its leader k;
:func:`kinedyn.symbolic.lagrange.body_states`), and the generalised forces of the coordinates are
``tau = G^T tau_joints`` (principle of virtual work: a follower's joint force adds ``m tau_j`` to its
leader's; ``qd_joints = G qd``).

Two reductions of the customised model (``group=True``), neither of which changes tau:

* **Grouped parameters** (K&D ch. 9, the grouping rules of the base inertial parameters; Gautier & Khalil 1990,
  Khalil & Kleinfinger 1987):
  a body rotationally symmetric about a revolute joint's axis, with no moment of inertia about it --
  parameters (M_j, MZ_j a, YY_j (1 - a a^T)) for a joint about z -- has the same kinetic and potential
  energy whether it moves with link j or with its parent, so those three parameters move to the
  parent, transformed by the parallel-axis rule (m' = m, h' = E h + m r,
  I' = E I E^T - m [r]x[r]x - [r]x[Eh]x - [Eh]x[r]x): link j keeps XXR_j = XX_j - YY_j and M_j = MZ_j =
  YY_j = 0. Across a prismatic joint the rotational inertia moves to the parent whole. Transfers run
  from the tips to the base; what reaches the fixed base has no effect. Grouped parameters that are
  not plain symbols are named ``XXR3``, ``ZZR2``, ``MXR2``, ... (parameter-only operations, counted).
* **The moment through U** (linearity in the inertia entries): I wd + w x (I w) written per parameter
  reuses the entries of U and the products w_a w_b that F already needs::

      N_x = XX wd_x + (ZZ - YY) w_y w_z + XY (-U_zx) + XZ U_yx + YZ (w_y^2 - w_z^2) + (h x vd)_x
      N_y = YY wd_y + (XX - ZZ) w_x w_z + XY U_zy + XZ (w_z^2 - w_x^2) + YZ (-U_xy) + (h x vd)_y
      N_z = ZZ wd_z + (YY - XX) w_x w_y + XY (w_x^2 - w_y^2) + XZ (-U_yz) + YZ U_xz + (h x vd)_z

Every vector component that is not a plain symbol or number is stored as a named intermediate variable
(``W2z``, ``WP3x``, ``VP3y``, ``U2xy``, ``F4x``, ``N4z``, ``f4x``, ``n4z``, ...); SymPy drops products with
0 and 1 as they are formed, so structural zeros of the axes and rotation matrices cost nothing. Unused
variables are removed at the end (the customised model keeps only what tau needs). Each variable
carries a tag (stage, link) and the per-link vectors are kept in ``Program.vectors``, so the
derivation can be shown step by step (:func:`newton_euler_steps`).
"""

from __future__ import annotations

import re
from typing import Any

import sympy as sp

from .. import values
from ..render.mathml import name, symbol_name, vector_name
from ..steps import Step, op_counts
from .lagrange import body_coordinates, body_states

__all__ = ["Program", "newton_euler_program", "newton_euler_steps"]

_XYZ = "xyz"


class Program:
    """A straight-line program: ordered assignments ``symbol = expression`` and named outputs."""

    def __init__(self, reserved=()):
        self.assignments: list[tuple] = []
        self.outputs: dict[str, list] = {}
        self.tags: dict[sp.Symbol, tuple] = {}  # variable -> (stage, link) for the step-by-step display
        self.vectors: dict[tuple, list] = {}  # (quantity, link) -> 3 expressions (w, wd, vd, F, N, f, n, ...)
        self.tag = ("", 0)  # the tag given to variables made now
        self.all_assignments: list[tuple] = []
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
        self.tags[sym] = self.tag
        return sym

    def prune(self) -> Program:
        """Remove assignments the outputs do not use (dead-code elimination); ``all_assignments`` keeps
        the whole recursion for the step-by-step display."""
        self.all_assignments = list(self.assignments)
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

    def op_count(self, cse: bool = False) -> dict[str, int]:
        exprs = [e for _, e in self.assignments] + [e for v in self.outputs.values() for e in v]
        if cse:
            repl, red = sp.cse(exprs, order="none")
            exprs = [e for _, e in repl] + list(red)
        return op_counts(exprs)

    def expanded(self, name: str = "tau") -> list:
        """The outputs with every intermediate variable substituted back (can be large)."""
        env: dict = {}
        for sym, expr in self.assignments:
            env[sym] = expr.xreplace(env)
        return [sp.sympify(e).xreplace(env) for e in self.outputs[name]]

    def evaluate(self, convert, name: str = "tau") -> list:
        """Evaluate the program in another arithmetic: ``convert(expr, env)`` maps an expression whose
        intermediate symbols are bound in ``env`` to a value (used to get exact ring elements)."""
        env: dict = {}
        for sym, expr in self.assignments:
            env[sym] = convert(expr, env)
        return [convert(sp.sympify(e), env) for e in self.outputs[name]]

    def __str__(self) -> str:
        lines = [f"{s} = {e}" for s, e in self.assignments]
        for output, exprs in self.outputs.items():
            lines += [f"{output}{k + 1} = {e}" for k, e in enumerate(exprs)]
        return "\n".join(lines)


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _matvec(A, v):
    return [sum((A[r][k] * v[k] for k in range(3)), sp.Integer(0)) for r in range(3)]


def _matTvec(A, v):
    return [sum((A[k][r] * v[k] for k in range(3)), sp.Integer(0)) for r in range(3)]


_PNAMES = ("M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ")


def _skew(v):
    return [[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]]


def _matmul(A, B):
    return [[sum((A[r][k] * B[k][c] for k in range(3)), sp.Integer(0)) for c in range(3)] for r in range(3)]


def _to_parent(m, h, I, E, r):
    """Parameters (m, h, I about the origin) of a body, re-expressed about the parent origin in parent
    axes: m' = m, h' = E h + m r, I' = E I E^T - m [r]x[r]x - [r]x[Eh]x - [Eh]x[r]x (parallel axes)."""
    Eh = _matvec(E, h)
    ET = [[E[c][r_] for c in range(3)] for r_ in range(3)]
    EIE = _matmul(_matmul(E, I), ET)
    Sr, SEh = _skew(r), _skew(Eh)
    SrSr, SrSEh, SEhSr = _matmul(Sr, Sr), _matmul(Sr, SEh), _matmul(SEh, Sr)
    I2 = [[sp.expand(EIE[a][b] - m * SrSr[a][b] - SrSEh[a][b] - SEhSr[a][b]) for b in range(3)] for a in range(3)]
    return m, [sp.expand(Eh[k] + m * r[k]) for k in range(3)], I2


def _unpack(pi):
    m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = pi
    return m, [hx, hy, hz], [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]


def _pack(m, h, I):
    return [m, h[0], h[1], h[2], I[0][0], I[0][1], I[1][1], I[0][2], I[1][2], I[2][2]]


def group_parameters(bodies, pi, placements, exact=None, let=None):
    """Grouped parameters (K&D's grouping rules; see the module docstring): per-body 10-vectors, tips to base.

    ``pi``: per-body exact parameter lists about the body origin; ``placements``: per-body
    (E, r) = parent_from_joint-frame rotation and origin. ``let(name, expr)``: names the transferred
    totals (MR4 = M4 + MR5, ...) so that the parents' groupings share them. Returns new lists."""
    exact = exact or values.exact
    let = let or (lambda name, e: e)
    zero = sp.Integer(0)
    pi = [list(p) for p in pi]
    for j in reversed(range(len(bodies))):
        b = bodies[j]
        J = j + 1
        m, h, I = _unpack(pi[j])
        a = [exact(x) for x in b.joint.axis]
        E, r = placements[j]
        if b.joint.kind == "revolute":
            k = next((k for k in range(3) if abs(a[k]) == 1 and all(a[i] == 0 for i in range(3) if i != k)), None)
            if k is None:  # an oblique axis: left ungrouped (correct, only less reduced)
                continue
            z = (k + 2) % 3  # the perpendicular diagonal entry made zero (YY for an axis along z)
            # what stays: XXR = XX - YY (axis z), formed from the expressions so that common terms cancel
            rest_I = [
                [sp.expand(I[i][c] - (I[z][z] if (i == c and i != k) else zero)) for c in range(3)] for i in range(3)
            ]
            rest = (zero, [zero if i == k else h[i] for i in range(3)], rest_I)
            m = let(f"MR{J}", m)
            hk = let(f"{_PNAMES[1 + k]}R{J}", h[k])
            lam = let(f"{_PNAMES[(4, 6, 9)[z]]}R{J}", I[z][z])
            sym_h = [hk if i == k else zero for i in range(3)]
            sym_I = [[(lam if (i == c and i != k) else zero) for c in range(3)] for i in range(3)]
            sym = (m, sym_h, sym_I)
            shift = r
        else:  # prismatic: the rotational inertia moves with the parent's rotation
            names = [["XX", "XY", "XZ"], ["XY", "YY", "YZ"], ["XZ", "YZ", "ZZ"]]
            Iv = {}
            for i in range(3):
                for c in range(i, 3):
                    Iv[i, c] = Iv[c, i] = let(f"{names[i][c]}R{J}", I[i][c])
            sym = (zero, [zero] * 3, [[Iv[i, c] for c in range(3)] for i in range(3)])
            rest = (m, h, [[zero] * 3 for _ in range(3)])
            shift = [zero] * 3
        pi[j] = _pack(*rest)
        if b.parent >= 0:  # what reaches the fixed base has no effect
            pi[b.parent] = [sp.expand(x + y) for x, y in zip(pi[b.parent], _pack(*_to_parent(*sym, E, shift)))]
    return pi


def newton_euler_program(
    robot, q, qd, qdd, parameters=None, gravity: bool = True, friction: bool = True, exact=None, group: bool = True
) -> Program:
    """The customised Newton-Euler model of ``robot`` (see the module docstring).

    ``parameters``: optional list of per-body 10-vectors [m, mx, my, mz, XX, XY, YY, XZ, YZ, ZZ]
    (about the body origin, body axes) replacing the description's inertias (e.g. general symbols).
    ``group``: use grouped parameters and the U-form of the moment (same tau, fewer operations).
    ``exact``: the value converter (:func:`kinedyn.symbolic.values.exact`)."""
    exact = exact or values.exact
    bodies = robot.tree.bodies
    n = len(bodies)
    coordinates = body_coordinates(robot)
    q_coordinates, qd_coordinates, qdd_coordinates = q, qd, qdd
    q, qd, qdd = body_states(robot, q, qd, qdd)  # per body (the coordinates' own symbols without mimic joints)
    prog = Program(reserved=set(robot.symbols) | set(q_coordinates) | set(qd_coordinates) | set(qdd_coordinates))
    let = prog.let
    zero = sp.Integer(0)
    children: dict[int, list] = {i: [] for i in range(-1, n)}
    for j, b in enumerate(bodies):
        children[b.parent].append(j)
    # ---- inertial parameters (about each body origin), grouped when asked
    pi, placements = {}, []
    for j, b in enumerate(bodies):
        params = parameters[j] if parameters is not None else b.inertia.parameters()
        pi[j] = [exact(sp.expand(sp.cancel(x)) if isinstance(x, sp.Basic) else x) for x in params]
        T = values.matrix(b.placement)
        placements.append(([row[:3] for row in T[:3]], [row[3] for row in T[:3]]))
    base = [pi[j] for j in range(n)]
    if group:
        grouped = group_parameters(bodies, base, placements, exact, let=lambda name, e: _let_tagged(prog, name, e))
        for j in range(n):
            prog.tag = ("parameters", j + 1)
            pi[j] = [
                let(f"{name}{'R' if sp.expand(new - old) != 0 else ''}{j + 1}", new)
                for name, new, old in zip(_PNAMES, grouped[j], base[j])
            ]
            prog.vectors[("pi", j)] = pi[j]
    E, r, axis, w, wd, vd, U, WW = {}, {}, {}, {}, {}, {}, {}, {}
    g = [exact(x) for x in robot.gravity]
    w[-1] = [zero] * 3
    wd[-1] = [zero] * 3
    vd[-1] = [-x for x in g] if gravity else [zero] * 3
    U[-1] = [[zero] * 3 for _ in range(3)]
    # ---- forward recursion: velocities and accelerations, base to tip
    for j, b in enumerate(bodies):
        J = j + 1
        prog.tag = ("forward", J)
        i = b.parent
        PR, Pp = placements[j]
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
            Ej = [
                [let(f"E{J}{_XYZ[rr]}{_XYZ[k]}", sum((PR[rr][m] * Rj[m][k] for m in range(3)), zero)) for k in range(3)]
                for rr in range(3)
            ]
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
        WW[j] = ww
        Sw = [[0, -wd[j][2], wd[j][1]], [wd[j][2], 0, -wd[j][0]], [-wd[j][1], wd[j][0], 0]]
        U[j] = [
            [
                let(
                    f"U{J}{_XYZ[a1]}{_XYZ[a2]}",
                    Sw[a1][a2] + ww[a1, a2] - (ww[0, 0] + ww[1, 1] + ww[2, 2] if a1 == a2 else 0),
                )
                for a2 in range(3)
            ]
            for a1 in range(3)
        ]
        prog.vectors[("w", j)], prog.vectors[("wd", j)], prog.vectors[("vd", j)] = w[j], wd[j], vd[j]
        prog.vectors[("U", j)] = U[j]
    # ---- per-body force and moment at the body origin
    F, N = {}, {}
    for j in range(n):
        J = j + 1
        prog.tag = ("forces", J)
        m, h, Io = _unpack(pi[j])
        Uh = _matvec(U[j], h)
        F[j] = [let(f"F{J}{_XYZ[k]}", m * vd[j][k] + Uh[k]) for k in range(3)]
        c2 = _cross(h, vd[j])
        if group:
            N[j] = [
                let(f"N{J}{_XYZ[k]}", x + c2[k]) for k, x in enumerate(_moment_u_form(prog, J, Io, wd[j], WW[j], U[j]))
            ]
        else:
            Jw = [let(f"JW{J}{_XYZ[k]}", x) for k, x in enumerate(_matvec(Io, w[j]))]
            Jwd = _matvec(Io, wd[j])
            c1 = _cross(w[j], Jw)
            N[j] = [let(f"N{J}{_XYZ[k]}", Jwd[k] + c1[k] + c2[k]) for k in range(3)]
        prog.vectors[("F", j)], prog.vectors[("N", j)] = F[j], N[j]
    # ---- backward recursion: f_j = F_j + sum E_c f_c ; n_j = N_j + sum (E_c n_c + r_c x E_c f_c)
    f: dict[int, Any] = {}
    nn: dict[int, Any] = {}
    joint_force: list[Any] = [None] * n
    for j in reversed(range(n)):
        J = j + 1
        prog.tag = ("backward", J)
        fj, nj = list(F[j]), list(N[j])
        for c in children[j]:
            Ef = [let(f"FE{c + 1}{_XYZ[k]}", x) for k, x in enumerate(_matvec(E[c], f[c]))]
            En = _matvec(E[c], nn[c])
            rf = _cross(r[c], Ef)
            fj = [fj[k] + Ef[k] for k in range(3)]
            nj = [nj[k] + En[k] + rf[k] for k in range(3)]
        f[j] = [let(f"f{J}{_XYZ[k]}", x) for k, x in enumerate(fj)]
        nn[j] = [let(f"n{J}{_XYZ[k]}", x) for k, x in enumerate(nj)]
        prog.vectors[("f", j)], prog.vectors[("n", j)] = f[j], nn[j]
        b = bodies[j]
        gen = nn[j] if b.joint.kind == "revolute" else f[j]
        t = sum((axis[j][k] * gen[k] for k in range(3)), zero)
        t = t + exact(b.joint.armature) * qdd[j]
        if friction:
            t = t + exact(b.joint.viscous) * qd[j] + b.joint.coulomb_torque(qd[j], exact)
        joint_force[j] = t
    # tau = G^T tau_joints: each joint's force on its coordinate, a follower's times its multiplier
    tau: list[Any] = [zero] * len(q_coordinates)
    for j, (k, m, _) in enumerate(coordinates):
        tau[k] = tau[k] + m * joint_force[j]
    if len(tau) < n:  # mimic joints: the joint forces, for the step-by-step display
        prog.vectors[("joint_forces",)] = joint_force
    prog.outputs["tau"] = tau
    return prog.prune()


def _let_tagged(prog, name, expr):
    """A grouped-parameter variable, tagged with its link (the digits of its name)."""
    link = re.search(r"(\d+)$", name)
    if link is None:
        raise ValueError(f"grouped-parameter name {name!r} does not end in its link's number")
    prog.tag = ("parameters", int(link.group(1)))
    return prog.let(name, expr)


def _moment_u_form(prog, J, Io, wd, ww, U):
    """I wd + w x (I w) per inertia entry, reusing U and w_a w_b (module docstring; the entries of
    U are U_ab = [wd]x_ab + w_a w_b - |w|^2 delta_ab)."""
    (XX, XY, XZ), (_, YY, YZ), (_, _, ZZ) = Io
    let = prog.let
    tag, prog.tag = prog.tag, ("parameters", J)  # differences of parameters: parameter-only work
    d_zy = let(f"ZY{J}", ZZ - YY)
    d_xz = let(f"XZD{J}", XX - ZZ)
    d_yx = let(f"YX{J}", YY - XX)
    prog.tag = tag
    x, y, z = 0, 1, 2
    # differences of squares, formed only when a product of inertia needs them
    sq = lambda a, b, name: let(f"WD{J}{name}", ww[a, a] - ww[b, b])
    Nx = XX * wd[x] + d_zy * ww[y, z] - XY * U[z][x] + XZ * U[y][x] + (YZ * sq(y, z, "yz") if YZ != 0 else 0)
    Ny = YY * wd[y] + d_xz * ww[x, z] + XY * U[z][y] + (XZ * sq(z, x, "zx") if XZ != 0 else 0) - YZ * U[x][y]
    Nz = ZZ * wd[z] + d_yx * ww[x, y] + (XY * sq(x, y, "xy") if XY != 0 else 0) - XZ * U[y][z] + YZ * U[x][z]
    return [Nx, Ny, Nz]


def newton_euler_steps(prog: Program, robot, q, qd, qdd) -> list:
    """The derivation of the customised model, step by step (for ``eom.steps``): the grouped parameters,
    then per link the forward recursion (w, wd, vd and the centre-of-mass acceleration vdc), the force
    and moment of each link, and the backward recursion (f, n, tau) from the tip to the base. Every
    equation is an intermediate variable with its expression, as formed (K&D ch. 9; Spong §9.6 and Craig
    eqs. 6.45-6.53 for the textbook form); the variables tau does not need are shown too."""
    n = len(robot.tree.bodies)
    assignments = prog.all_assignments or prog.assignments
    by_tag: dict[tuple, list] = {}
    for sym, expr in assignments:
        by_tag.setdefault(prog.tags.get(sym, ("", 0)), []).append((symbol_name(sym), expr))
    V = lambda key, j: sp.Matrix(prog.vectors[(key, j)]) if (key, j) in prog.vectors else None
    steps = []
    # in program order (tips to base), and only those tau uses: the rest reached the fixed base
    grouped = [
        (symbol_name(sym), expr) for sym, expr in prog.assignments if prog.tags.get(sym, ("",))[0] == "parameters"
    ]
    if grouped:
        steps.append(
            Step(
                "Grouped inertial parameters",
                "Across a revolute joint about z, M_j, MZ_j and YY_j move to the parent (parallel-axis rule), leaving XXR_j = XX_j - YY_j; "
                "across a prismatic joint the rotational inertia moves (Khalil & Dombre ch. 9; Gautier & Khalil 1990). Differences such as ZZ - YY are formed once.",
                grouped,
            )
        )
    for j in range(n):
        J = j + 1
        st = Step(
            f"Forward recursion, link {J}: w, wd, vd, vdc",
            "w_j = E^T w_i + qd_j a_j, wd_j = E^T wd_i + qdd_j a_j + (E^T w_i) x qd_j a_j, U_j = [wd_j]x + [w_j]x[w_j]x, "
            "vd_j = E^T (vd_i + U_i r_j), vd_cj = vd_j + U_j c_j (Craig eqs. 6.45-6.48 in body frames; K&D ch. 9); vd_0 = -gravity.",
            list(by_tag.get(("forward", J), [])),
        )
        for key, lhs in (
            ("w", vector_name(r"\omega", "w", "ω", J)),
            ("wd", vector_name(r"\omega", "wd", "ω", J, accent=1)),
            ("vd", vector_name("v", "vd", "v", J, accent=1)),
        ):
            if V(key, j) is not None:
                st.equations.append((lhs, V(key, j)))
        inertia = robot.tree.bodies[j].inertia
        if V("vd", j) is not None and V("U", j) is not None and values.exact(inertia.mass) != 0:
            c = sp.Matrix([values.exact(x) for x in inertia.com])
            U = sp.Matrix(prog.vectors[("U", j)])
            st.equations.append((vector_name("v", "vd", "v", f"c{J}", accent=1), V("vd", j) + U * c))
        steps.append(st)
    for j in range(n):
        J = j + 1
        st = Step(
            f"Force and moment of link {J} at its origin",
            "F_j = m_j vd_cj = M_j vd_j + U_j MS_j, N_j = I_j wd_j + w_j x (I_j w_j) + MS_j x vd_j (Craig eqs. 6.49-6.50 about the origin; K&D ch. 9), "
            "the moment written per inertia entry through U.",
            list(by_tag.get(("forces", J), [])),
        )
        for key, latex, text in (("F", "F", "F"), ("N", "N", "N")):
            if V(key, j) is not None:
                st.equations.append((name(f"{latex}_{{{J}}}", f"{text}{J}", latex, str(J)), V(key, j)))
        steps.append(st)
    tau = prog.outputs.get("tau", [])
    joint_forces = prog.vectors.get(("joint_forces",))  # mimic joints: per joint, then tau = G^T of them
    for j in reversed(range(n)):
        J = j + 1
        st = Step(
            f"Backward recursion, link {J}: f, n, tau",
            "f_j = F_j + sum_children E_c f_c, n_j = N_j + sum_children (E_c n_c + r_c x E_c f_c), "
            "tau_j = a_j . n_j (revolute) or a_j . f_j (prismatic), plus r^2 J_m qdd_j (Craig eqs. 6.51-6.53).",
            list(by_tag.get(("backward", J), [])),
        )
        for key in ("f", "n"):
            if V(key, j) is not None:
                st.equations.append((name(f"{key}_{{{J}}}", f"{key}{J}", key, str(J)), V(key, j)))
        if joint_forces is not None:
            st.equations.append((name(f"Q_{{{J}}}", f"Q_{J}", "Q", str(J)), joint_forces[j]))
        elif j < len(tau):
            st.equations.append((name(f"\\tau_{{{J}}}", f"tau_{J}", "tau", str(J)), tau[j]))
        steps.append(st)
    if joint_forces is not None:
        number = lambda x: f"{float(x):g}" if x.is_number else str(x)
        follows = [
            f"joint {j + 1}: {b.joint.name} = {number(m)} {robot.joint_names[k]} + {number(o)}"
            for j, (b, (k, m, o)) in enumerate(zip(robot.tree.bodies, body_coordinates(robot)))
            if b.joint.name not in robot.joint_names
        ]
        steps.append(
            Step(
                "Mimic joints: the forces on the coordinates, tau = G^T Q",
                "Q_j is joint j's force from the recursion; a follower joint moves as m q_k + o, so by virtual work its force adds m Q_j "
                f"to its leader's coordinate k ({'; '.join(follows)}).",
                [(name(f"\\tau_{{{k + 1}}}", f"tau_{k + 1}", "tau", str(k + 1)), t) for k, t in enumerate(tau)],
            )
        )
    return steps
