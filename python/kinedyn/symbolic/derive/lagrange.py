"""Euler-Lagrange derivation of a robot's equations of motion, step by step (Spong §9.2-9.3).

Symbols: q, qd, qdd (joint coordinates, velocities, accelerations); for body i with parent p:
``E`` = parent_from_body rotation, ``r`` = body origin in parent axes, ``R``/``p`` = world_from_body
rotation/origin, ``Jv``/``Jw`` = body-frame Jacobians of the body origin's linear velocity and of the
angular velocity (3 x n), ``pi`` = [m, h = m c, I_o] the ten inertial parameters about the body origin.

    Jw_i = E^T Jw_p + a_i e_i                (revolute)        omega_i = Jw_i qd
    Jv_i = E^T (Jv_p - [r]x Jw_p) + a_i e_i  (prismatic)       v_i = Jv_i qd
    D_i  = m Jv^T Jv - Jv^T [h]x Jw + Jw^T [h]x Jv + Jw^T I_o Jw
         (= m Jvc^T Jvc + Jw^T R I_c R^T Jw of Spong eq. 9.46, written about the body origin so it is
          linear in the parameters and needs no division by the mass)
    D    = sum_i D_i + diag(r_i^2 J_m,i)          K = qd^T D qd / 2             (Spong 9.47)
    P    = - sum_i g^T (m_i p_i + R_i h_i)                                        (Spong 9.48-9.49)
    tau_k = d/dt dL/dqd_k - dL/dq_k,  L = K - P                                   (Spong 9.40)
    c_ijk = (dD_kj/dq_i + dD_ki/dq_j - dD_ij/dq_k) / 2,  C_kj = sum_i c_ijk qd_i   (Spong 9.58, 9.62)

Mimic joints (reduced, ``robot.mimic_joints``): a follower body's joint coordinate is
``m q_k + o`` (m, o its relation to the independent leader k; :func:`body_coordinates`), its rate
``m qd_k``. The kinematics above then run per body with that coordinate, and a body's joint adds
``m a_i`` to the Jacobian column of its leader (``J_reduced = J_full G``, G the constant map
``qd_full = G qd`` of :mod:`kinedyn.description.mimic`). D, K, P and L are formed in the reduced
coordinates only, and Lagrange's equations, the Christoffel symbols and C follow from them by the
same formulas, derivatives taken by the chain rule (:class:`~kinedyn.symbolic.simplify.TrigRing`:
cos(m q_k) for a fractional m is a generator differentiated as a function of q_k). A follower's
rotor inertia adds ``m^2 r^2 J_m`` to its leader's diagonal entry (``G^T diag G``).

All arithmetic is exact, in the normal form of :class:`kinedyn.symbolic.simplify.TrigRing`.
"""

from __future__ import annotations

import re

import sympy as sp
from sympy.printing.conventions import split_super_sub

from ..render.mathml import rate_names
from ..values import exact, matrix, rational
from .simplify import TrigRing

__all__ = ["RingModel", "state_symbols", "derive_lagrange", "body_coordinates"]


def state_symbols(robot):
    """(q, qd, qdd) symbol lists named after the joints: q1 -> qdot1, qddot1 (printed q̇₁, \\dot{q}_{1});
    shoulder -> shoulderdot, shoulderddot (see :func:`kinedyn.symbolic.render.rate_names`)."""
    q, qd, qdd = [], [], []  # one per coordinate: reduced mimic followers have none (body_coordinates)
    taken = {str(s) for s in robot.symbols}
    for name in robot.joint_names:
        names = (name, *rate_names(name))
        for n in names:
            if n in taken:
                raise ValueError(
                    f"joint variable name '{n}' is also a parameter symbol of robot '{robot.name}': rename the joint or the symbol"
                )
        q.append(sp.Symbol(names[0], real=True))
        qd.append(sp.Symbol(names[1], real=True))
        qdd.append(sp.Symbol(names[2], real=True))
    return q, qd, qdd


def mimic_multiplier(value):
    """A mimic relation's multiplier as an exact value: the small rational a decimal from a file stands
    for (-1.5 -> -3/2) when it is exactly that float, else the float (so that cos(3 q/2) prints as
    such, and an integer multiplier is recognised)."""
    if isinstance(value, sp.Basic) and not value.is_number:
        return value
    f = float(value)
    return sp.Integer(int(f)) if f.is_integer() else rational(f)


def body_coordinates(robot) -> list:
    """Per body of ``robot.tree.bodies``: ``(k, m, o)``, its joint's coordinate being ``m q[k] + o``
    (exact SymPy numbers; 1 and 0 for an independent joint, k its own index in q). Followers are
    ``robot.mimic_joints`` (reduced mimic joints, chains resolved to an independent leader)."""
    names = list(robot.joint_names)
    relations = getattr(robot, "mimic_joints", None) or {}
    one, zero = sp.Integer(1), sp.Integer(0)
    out = []
    for b in robot.tree.bodies:
        relation = relations.get(b.joint.name)
        if relation is None:
            out.append((names.index(b.joint.name), one, zero))
        else:
            out.append((names.index(relation.leader), mimic_multiplier(relation.multiplier), exact(relation.offset)))
    return out


def body_states(robot, q, qd, qdd) -> tuple:
    """Per body: its joint's coordinate, rate and acceleration as SymPy expressions in the symbols
    ``q``, ``qd``, ``qdd`` of the coordinates (``m q_k + o``, ``m qd_k``, ``m qdd_k`` for a follower)."""
    qb, qdb, qddb = [], [], []
    for k, m, o in body_coordinates(robot):
        qb.append(m * q[k] + o)
        qdb.append(m * qd[k])
        qddb.append(m * qdd[k])
    return qb, qdb, qddb


def readable_name(name: str) -> bool:
    """Whether SymPy's LaTeX of a joint variable named ``name`` reads as that name: ``q1``, ``theta_2``,
    ``x_a``, ``shoulder`` do; ``shoulder_pan_joint`` (typeset shoulder_{pan joint}) and
    ``panda_joint1`` (panda_{joint1}) do not."""
    base, sups, subs = split_super_sub(name)
    if sups or len(subs) > 1:
        return False
    if not subs:
        return True
    return len(base) == 1 or base.lower() in _GREEK or subs[0].isdigit()


_GREEK = {"alpha", "beta", "gamma", "delta", "theta", "phi", "psi", "chi", "eta", "mu", "nu", "rho", "sigma", "tau"}


def joint_symbols_renamed(q) -> bool:
    """Whether the joint variables are printed as q_1, ..., q_n (with a legend) because some joint's
    name does not read well as a symbol (:func:`readable_name`)."""
    return not all(readable_name(a.name) for a in q)


def latex_names(q, qd, qdd) -> dict:
    """LaTeX names for the velocity/acceleration symbols (\\dot q_1, \\ddot q_1); when a joint's name
    does not read well as a symbol (``shoulder_pan_joint``), every joint variable is printed as
    q_1, ..., q_n instead (the documents print which joint each is)."""
    out = {}
    renamed = joint_symbols_renamed(q)
    for k, (a, b, c) in enumerate(zip(q, qd, qdd), start=1):
        if renamed:
            out[a] = f"q_{{{k}}}"
        base = out.get(a) or sp.latex(a)
        m = re.fullmatch(r"(.+?)_\{(.+)\}", base)
        head, tail = (m.group(1), "_{" + m.group(2) + "}") if m else (base, "")
        out[b] = r"\dot{" + head + "}" + tail
        out[c] = r"\ddot{" + head + "}" + tail
    return out


class RingModel:
    """The robot's kinematics and energies in the exact trigonometric ring (see module docstring)."""

    def __init__(self, robot, q, qd, qdd, inertias=None, extra_leaves=()):
        """``extra_leaves``: further parameter expressions the ring must hold (a frame's placement, a
        point given with symbols) for :mod:`kinedyn.symbolic.kinematics`."""
        self.robot = robot
        bodies = robot.tree.bodies
        self.n_bodies = len(bodies)
        self.n = len(q)  # coordinates (fewer than the bodies with reduced mimic joints)
        # per body: its joint coordinate is scale * q[column] + shift (body_coordinates)
        self.column, self.scale, self.shift = [], [], []
        for k, m, o in body_coordinates(robot):
            self.column.append(k)
            self.scale.append(m)
            self.shift.append(o)
        kinds = [j.kind for j in robot.joints]  # of the coordinates
        # ---- the description as exact SymPy values
        self.place_R, self.place_p, self.axis, self.offset, self.pi = [], [], [], [], []
        self.com, self.armature, self.viscous, self.coulomb = [], [], [], []
        leaves = []
        for k, b in enumerate(bodies):
            T = matrix(b.placement)
            self.place_R.append([row[:3] for row in T[:3]])
            self.place_p.append([row[3] for row in T[:3]])
            self.axis.append([exact(a) for a in b.joint.axis])
            off = exact(b.joint.offset)
            self.offset.append(off)
            inertia = b.inertia if inertias is None else inertias[k]
            pi = [sp.expand(sp.cancel(exact(v))) if isinstance(v, sp.Basic) else exact(v) for v in inertia.parameters()]
            self.pi.append(pi)
            self.com.append([exact(c) for c in inertia.com])
            self.armature.append(exact(b.joint.armature))
            self.viscous.append(exact(b.joint.viscous))
            self.coulomb.append(exact(b.joint.coulomb))
            leaves += sum(self.place_R[-1], []) + self.place_p[-1] + self.axis[-1] + pi + [self.armature[-1]]
            phase = off + self.shift[k]  # the joint variable is scale q + phase
            if b.joint.kind == "revolute":
                leaves += [sp.cos(phase), sp.sin(phase)] if not phase.has(sp.Float) else []
            else:
                leaves.append(phase)
            if self.scale[k] != 1:
                leaves.append(self.scale[k])
        self.gravity = [exact(g) for g in robot.gravity]
        leaves += self.gravity
        leaves += [exact(x) for x in extra_leaves]
        self.leaves = leaves
        # generators for the followers' coordinates that are no polynomial in their leader's (simplify.py)
        multiples, angles = [], []
        for k, b in enumerate(bodies):
            col, m = self.column[k], self.scale[k]
            if b.joint.kind == "revolute" and not (kinds[col] == "revolute" and m.is_Integer):
                multiples.append((col, m))
            elif b.joint.kind == "prismatic" and kinds[col] == "revolute":
                angles.append(col)
        self.ring = TrigRing(list(zip(q, kinds)), qd, qdd, leaves, multiples=multiples, angles=angles)
        self.q, self.qd, self.qdd = q, qd, qdd
        self._kinematics()

    # ------------------------------------------------------------------ helpers
    def _c(self, v):
        return self.ring.const(v)

    def _mat(self, A, B):
        ring = self.ring
        return [[ring.dot(A[i], [B[k][j] for k in range(len(B))]) for j in range(len(B[0]))] for i in range(len(A))]

    def _matT(self, A, B):  # A^T B
        ring = self.ring
        return [
            [ring.dot([A[k][i] for k in range(len(A))], [B[k][j] for k in range(len(B))]) for j in range(len(B[0]))]
            for i in range(len(A[0]))
        ]

    def _vec(self, A, v):
        return [self.ring.dot(row, v) for row in A]

    @staticmethod
    def _skew(v):
        x, y, z = v
        return [[0 * x, -z, y], [z, 0 * x, -x], [-y, x, 0 * x]]

    def _joint_rotation(self, i):
        """Rodrigues: R = C I + S [a]x + (1 - C) a a^T, with C, S the cosine/sine of q_i + offset."""
        ring = self.ring
        a = [self._c(x) for x in self.axis[i]]
        C, S = self.joint_cos(i), self.joint_sin(i)
        one_c = ring.one - C
        ax = self._skew(a)
        return [
            [ring.reduce((C if r == k else ring.zero) + S * ax[r][k] + one_c * a[r] * a[k]) for k in range(3)]
            for r in range(3)
        ]

    def joint_cos(self, i):
        """cos of body i's joint angle (its coordinate plus the joint offset)."""
        return self.ring.cos_multiple(self.column[i], self.scale[i], self.offset[i] + self.shift[i])

    def joint_sin(self, i):
        return self.ring.sin_multiple(self.column[i], self.scale[i], self.offset[i] + self.shift[i])

    def joint_displacement(self, i):
        """Body i's prismatic joint variable (its coordinate plus the joint offset), a polynomial."""
        return self.ring.angle(self.column[i]) * self._c(self.scale[i]) + self._c(self.offset[i] + self.shift[i])

    # ------------------------------------------------------------------ kinematics
    def _kinematics(self):
        ring, n = self.ring, self.n
        bodies = self.robot.tree.bodies
        zero = ring.zero
        # per body: the ring's polynomial matrices and vectors (lists of lists of ring elements)
        self.E: list = []
        self.r: list = []
        self.R: list = []
        self.p: list = []
        self.Jv: list = []
        self.Jw: list = []
        for i, b in enumerate(bodies):
            P_R = [[self._c(x) for x in row] for row in self.place_R[i]]
            P_p = [self._c(x) for x in self.place_p[i]]
            a = [self._c(x) for x in self.axis[i]]
            if b.joint.kind == "revolute":
                E = self._mat(P_R, self._joint_rotation(i))
                r = P_p
            else:
                E = P_R
                d = self.joint_displacement(i)
                r = [P_p[k] + ring.dot(P_R[k], [x * d for x in a]) for k in range(3)]
            parent = b.parent
            if parent < 0:
                R, p = E, r
                Jw = [[zero] * n for _ in range(3)]
                Jv = [[zero] * n for _ in range(3)]
            else:
                Rp, pp = self.R[parent], self.p[parent]
                R = self._mat(Rp, E)
                p = [pp[k] + ring.dot(Rp[k], r) for k in range(3)]
                # Jw_i = E^T Jw_p ; Jv_i = E^T (Jv_p - [r]x Jw_p)
                Jw = self._matT(E, self.Jw[parent])
                Sr = self._skew(r)
                SJ = self._mat(Sr, self.Jw[parent])
                Jv = self._matT(E, [[self.Jv[parent][k][j] - SJ[k][j] for j in range(n)] for k in range(3)])
            # the joint's own column: its axis times d(joint coordinate)/d(q[column]) = scale
            col, scale = self.column[i], self._c(self.scale[i])
            J_own = Jw if b.joint.kind == "revolute" else Jv
            for k in range(3):
                J_own[k][col] = J_own[k][col] + a[k] * scale
            self.E.append(E)
            self.r.append(r)
            self.R.append(R)
            self.p.append(p)
            self.Jw.append(Jw)
            self.Jv.append(Jv)

    def body_mass_matrix(self, i):
        """D_i = m Jv^T Jv - Jv^T [h]x Jw + Jw^T [h]x Jv + Jw^T I_o Jw (body-origin form of Spong 9.46)."""
        ring, n = self.ring, self.n
        m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = [self._c(v) for v in self.pi[i]]
        Jv, Jw = self.Jv[i], self.Jw[i]
        Sh = self._skew([hx, hy, hz])
        Io = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]
        ShJw = self._mat(Sh, Jw)
        ShJv = self._mat(Sh, Jv)
        IJw = self._mat(Io, Jw)
        B = [[ring.reduce(m * Jv[k][j] - ShJw[k][j]) for j in range(n)] for k in range(3)]  # m Jv - [h]x Jw
        A = [[ring.reduce(IJw[k][j] + ShJv[k][j]) for j in range(n)] for k in range(3)]  # I_o Jw + [h]x Jv
        D = [[None] * n for _ in range(n)]
        for r in range(n):
            for c in range(r, n):
                v = ring.dot([Jv[k][r] for k in range(3)], [B[k][c] for k in range(3)])
                v = ring.reduce(v + ring.dot([Jw[k][r] for k in range(3)], [A[k][c] for k in range(3)]))
                D[r][c] = D[c][r] = v
        return D

    def mass_matrix(self):
        ring, n = self.ring, self.n
        D = [[ring.zero] * n for _ in range(n)]
        for i in range(self.n_bodies):
            Di = self.body_mass_matrix(i)
            for r in range(n):
                for c in range(n):
                    D[r][c] = D[r][c] + Di[r][c]
        for i in range(self.n_bodies):  # rotor inertia on G^T diag(armature) G: scale^2 on the leader's entry
            col = self.column[i]
            D[col][col] = D[col][col] + self._c(self.armature[i]) * self._c(self.scale[i]) ** 2
        return D

    def potential_energy(self):
        """P = - sum_i g^T (m_i p_i + R_i h_i)."""
        ring = self.ring
        g = [self._c(x) for x in self.gravity]
        P = ring.zero
        for i in range(self.n_bodies):
            m = self._c(self.pi[i][0])
            h = [self._c(x) for x in self.pi[i][1:4]]
            Rh = self._vec(self.R[i], h)
            P = P - ring.dot(g, [m * self.p[i][k] + Rh[k] for k in range(3)])
        return ring.reduce(P)

    def com_positions(self):
        """World positions of the centres of mass, p_ci = p_i + R_i c_i (for the derivation's steps)."""
        out = []
        for i in range(self.n_bodies):
            c = [self._c(x) for x in self.com[i]]
            Rc = self._vec(self.R[i], c)
            out.append([self.ring.reduce(self.p[i][k] + Rc[k]) for k in range(3)])
        return out

    def world_angular_jacobian(self, i):
        return self._mat(self.R[i], self.Jw[i])


def christoffel(ring: TrigRing, D):
    """c[i][j][k] = (dD_kj/dq_i + dD_ki/dq_j - dD_ij/dq_k) / 2 (Spong eq. 9.58), symmetric in i, j."""
    n = len(D)
    half = ring.const(sp.Rational(1, 2))
    dD = [[[ring.diff_q(D[a][b], i) for i in range(n)] for b in range(n)] for a in range(n)]  # dD[a][b][i]
    c = [[[None] * n for _ in range(n)] for _ in range(n)]
    for i in range(n):
        for j in range(i, n):
            for k in range(n):
                v = ring.reduce((dD[k][j][i] + dD[k][i][j] - dD[i][j][k]) * half)
                c[i][j][k] = c[j][i][k] = v
    return c


def coriolis_matrix(ring: TrigRing, c):
    """C[k][j] = sum_i c_ijk qd_i (Spong eq. 9.62)."""
    n = len(c)
    return [
        [ring.reduce(sum((c[i][j][k] * ring.velocity(i) for i in range(n)), ring.zero)) for j in range(n)]
        for k in range(n)
    ]


def derive_lagrange(model: RingModel):
    """The Euler-Lagrange equations from K and P: returns a dict of ring elements (see module doc)."""
    ring, n = model.ring, model.n
    D = model.mass_matrix()
    P = model.potential_energy()
    # K = qd^T D qd / 2  (Spong 9.47)
    half = ring.const(sp.Rational(1, 2))
    K = ring.zero
    for i in range(n):
        K += D[i][i] * ring.velocity(i) ** 2 * half
        for j in range(i + 1, n):
            K += D[i][j] * ring.velocity(i) * ring.velocity(j)
    K = ring.reduce(K)
    L = K - P
    dL_dqd = [ring.diff_qd(L, k) for k in range(n)]
    ddt_dL_dqd = [ring.time_derivative(x) for x in dL_dqd]
    dL_dq = [ring.diff_q(L, k) for k in range(n)]
    tau = [ring.reduce(ddt_dL_dqd[k] - dL_dq[k]) for k in range(n)]
    # M = d tau / d qdd ; g = tau(q, 0, 0) = dP/dq ; C from the Christoffel symbols of D
    M = [[ring.diff_qdd(tau[k], j) for j in range(n)] for k in range(n)]
    g = [ring.substitute_state(tau[k], qd_zero=True, qdd_zero=True) for k in range(n)]
    c = christoffel(ring, D)
    C = coriolis_matrix(ring, c)
    # self-check (an identity, Spong 9.55-9.61): tau == M qdd + C qd + g, exactly
    for k in range(n):
        rhs = g[k]
        for j in range(n):
            rhs = rhs + M[k][j] * ring.acceleration(j) + C[k][j] * ring.velocity(j)
        if not ring.is_zero(ring.reduce(rhs - tau[k]), tau[k]):
            raise RuntimeError("internal error: Euler-Lagrange tau differs from M qdd + C qd + g")
        for j in range(n):
            if not ring.is_zero(M[k][j] - D[k][j], D[k][j]):
                raise RuntimeError("internal error: d tau/d qdd differs from D(q)")
    return dict(
        D=D, P=P, K=K, L=L, dL_dqd=dL_dqd, ddt_dL_dqd=ddt_dL_dqd, dL_dq=dL_dq, tau=tau, M=M, g=g, christoffel=c, C=C
    )
