"""Mechanisms built from robots (Spong §9.4): a change of coordinates of a robot's equations, and
closed chains assembled from serial trees and loop-closure constraints.

Change of coordinates (a drive map, e.g. the remotely driven arm of Spong §9.4.3: the second link
driven from the base by a belt, q = A p with A = [[1, 0], [-1, 1]]). With A constant and
invertible, qd = A pd, and by virtual work (tau_q . dq = tau_p . dp) the generalised forces map by
A^T:

    D_p(p)     = A^T D_q(A p) A                      (K = qd^T D_q qd / 2 = pd^T D_p pd / 2)
    g_p(p)     = A^T g_q(A p)                        (= dP/dp by the chain rule)
    friction_p = A^T friction_q(A pd),  tau_p = A^T tau_q
    c_ijk(p)   = (dD_p,kj/dp_i + dD_p,ki/dp_j - dD_p,ij/dp_k) / 2   (Spong eq. 9.58, recomputed),
    C_p        = A^T C_q(A p, A pd) A                (the symbols transform as a tensor; tested)

Closed chains (Spong §9.4.4, the five-bar): a set of serial trees with coordinates theta (their
equations block-diagonal), loop-closure constraints phi(theta) = 0, independent coordinates q (a
subset of theta) and one branch of the closure's solution theta_dep = s(q) given explicitly. With
theta = Theta(q) (the independent coordinates themselves and s(q)) and J = dTheta/dq (n_tree x n):

    D(q) = J^T D_tree(Theta(q)) J,   g(q) = J^T g_tree(Theta(q)),   friction = J^T friction_tree(J qd)

and C(q, qd) from the Christoffel symbols of D(q) (the reduced Lagrangian is K = qd^T D qd / 2 - P).
Without an explicit branch the same mechanism is a constrained :class:`LagrangianSystem` (tree +
holonomic closure, solved numerically per evaluation): :func:`closed_chain_system`.

:func:`decoupling_condition` solves "D(q) diagonal (and constant) for every q" for a parameter:
each off-diagonal entry, in its unique Fourier normal form, is a sum of parameter coefficients times
independent trigonometric terms, so every coefficient must vanish.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..derive.kinematics import pose
from ..derive.lagrange import latex_names
from ..derive.simplify import simplify_trig
from ..eom import EquationsOfMotion
from ..render.mathml import rate_names
from ..steps import Step
from .system import LagrangianSystem

__all__ = [
    "change_coordinates",
    "tree_equations",
    "loop_closure",
    "closed_chain",
    "closed_chain_system",
    "decoupling_condition",
    "christoffel_symbols",
]


def _simplify(e, coordinates):
    return simplify_trig(sp.expand(e), list(coordinates))


def christoffel_symbols(D: sp.Matrix, q: Sequence, simplify=None):
    """c[i][j][k] = (dD_kj/dq_i + dD_ki/dq_j - dD_ij/dq_k) / 2 (Spong eq. 9.58), nested lists."""
    n = len(q)
    simp = simplify or (lambda e: sp.expand(e))
    dD = [[[sp.diff(D[a, b], c) for c in q] for b in range(n)] for a in range(n)]  # dD[a][b][i] = dD_ab/dq_i
    return [
        [[simp((dD[k][j][i] + dD[k][i][j] - dD[i][j][k]) / 2) for k in range(n)] for j in range(n)] for i in range(n)
    ]


def _from_inertia(
    q, qd, qdd, D, g, friction, P, *, name, steps, extra, simplify_in, latex_names=None
) -> EquationsOfMotion:
    """Equations of motion of the natural system K = qd^T D qd / 2, P, with C from D's Christoffel symbols."""
    n = len(q)
    chris = christoffel_symbols(D, q, simplify_in)
    C = sp.Matrix(n, n, lambda k, j: simplify_in(sum(chris[i][j][k] * qd[i] for i in range(n))))
    K = simplify_in((sp.Matrix(qd).T * D * sp.Matrix(qd))[0, 0] / 2)
    return EquationsOfMotion(
        q,
        qd,
        qdd,
        D,
        C,
        g,
        K=K,
        P=P,
        friction=friction,
        christoffel=chris,
        steps=steps,
        name=name,
        method="lagrange",
        latex_names=latex_names,
        extra=extra,
    )


def _new_coordinates(coordinates, n, taken):
    if coordinates is None:
        coordinates = [f"p{i + 1}" for i in range(n)]
    elif isinstance(coordinates, str):
        coordinates = coordinates.replace(",", " ").split()
    p = [sp.Symbol(c, real=True) if isinstance(c, str) else c for c in coordinates]
    if len(p) != n or not all(isinstance(c, sp.Symbol) for c in p):
        raise ValueError(f"coordinates must be {n} names or symbols, got {coordinates!r}")
    pd = [sp.Symbol(rate_names(c.name)[0], real=True) for c in p]
    pdd = [sp.Symbol(rate_names(c.name)[1], real=True) for c in p]
    clash = {s.name for s in p + pd + pdd} & {s.name for s in taken}
    if clash:
        raise ValueError(
            f"the new coordinates' names {sorted(clash)} are already symbols of the equations: choose other names"
        )
    return p, pd, pdd, latex_names(p, pd, pdd)


def change_coordinates(eom: EquationsOfMotion, A, coordinates=None, name: str | None = None) -> EquationsOfMotion:
    """The equations of ``eom`` (in q) in new coordinates p with q = A p (``A`` constant, n x n,
    invertible): D_p = A^T D_q A, g_p = A^T g_q, friction_p = A^T friction_q, tau_p = A^T tau_q and
    the Christoffel symbols of D_p (see the module docstring). ``coordinates``: names of p (default
    p1..pn; velocities pd1.., accelerations pdd1..)."""
    n = eom.n
    A = sp.Matrix(A)
    if A.shape != (n, n):
        raise ValueError(
            f"the drive map q = A p needs a square A of shape ({n}, {n}) for {n} coordinates, got {A.shape}"
        )
    state = set(eom.q) | set(eom.qd) | set(eom.qdd)
    if A.free_symbols & state:
        raise ValueError(
            "A must be constant (no joint coordinates or velocities in it): q = A p with A depending on q is not a linear change of coordinates"
        )
    if sp.simplify(A.det()) == 0:
        raise ValueError(f"A = {A.tolist()} is singular: the new coordinates would not determine q")
    params = set().union(*(m.free_symbols for m in (eom.M, eom.g, eom.friction))) - state
    p, pd, pdd, names = _new_coordinates(coordinates, n, params | state)
    to_p = {
        **dict(zip(eom.q, A * sp.Matrix(p))),
        **dict(zip(eom.qd, A * sp.Matrix(pd))),
        **dict(zip(eom.qdd, A * sp.Matrix(pdd))),
    }
    simp = lambda e: _simplify(e, p)
    D = (A.T * eom.M.xreplace(to_p) * A).applyfunc(simp)
    g = (A.T * eom.g.xreplace(to_p)).applyfunc(simp)
    friction = (A.T * eom.friction.xreplace(to_p)).applyfunc(sp.expand)
    P = simp(sp.sympify(eom.P).xreplace(to_p)) if eom.P is not None else None
    steps = [
        Step(
            "Change of coordinates q = A p",
            "qd = A pd; M_p = A^T M_q A, g_p = A^T g_q, tau_p = A^T tau_q (virtual work)",
            [("A", A), (r"M(p)", D), (r"g(p)", g)],
        )
    ]
    return _from_inertia(
        p,
        pd,
        pdd,
        D,
        g,
        friction,
        P,
        name=name or f"{eom.name} in coordinates {', '.join(map(str, p))}",
        steps=steps,
        extra=dict(A=A, original=eom),
        simplify_in=simp,
        latex_names=names,
    )


def tree_equations(*trees) -> EquationsOfMotion:
    """The block-diagonal equations of several independent trees (Robots or EquationsOfMotion) with
    distinct joint names: D = diag(D_1, D_2, ...), g and friction stacked, P summed."""
    eoms = [t if isinstance(t, EquationsOfMotion) else t.equations_of_motion(steps=False) for t in trees]
    if not eoms:
        raise ValueError("tree_equations() needs at least one tree")
    q = [s for e in eoms for s in e.q]
    if len({s.name for s in q}) != len(q):
        raise ValueError(
            f"the trees' joint coordinates repeat ({[s.name for s in q]}): name the joints of each tree differently"
        )
    qd = [s for e in eoms for s in e.qd]
    qdd = [s for e in eoms for s in e.qdd]
    D = sp.diag(*[e.M for e in eoms])
    C = sp.diag(*[e.C for e in eoms])
    g = sp.Matrix.vstack(*[e.g for e in eoms])
    friction = sp.Matrix.vstack(*[e.friction for e in eoms])
    P = sum((sp.sympify(e.P) for e in eoms), sp.Integer(0))
    names: dict = {}
    for e in eoms:
        names.update(e.latex_names)
    chris = None
    if all(e.christoffel for e in eoms):
        n = len(q)
        chris = [[[sp.Integer(0)] * n for _ in range(n)] for _ in range(n)]
        offset = 0
        for e in eoms:
            for i in range(e.n):
                for j in range(e.n):
                    for k in range(e.n):
                        chris[offset + i][offset + j][offset + k] = e.christoffel[i][j][k]
            offset += e.n
    return EquationsOfMotion(
        q,
        qd,
        qdd,
        D,
        C,
        g,
        K=None,
        P=P,
        friction=friction,
        christoffel=chris,
        name=" + ".join(e.name for e in eoms),
        method="lagrange",
        latex_names=names,
    )


def loop_closure(tree_a, tree_b, frame_a: str | None = None, frame_b: str | None = None) -> list:
    """Loop-closure constraints phi = 0 joining two trees (Robots) at a point: the origin of
    ``frame_a`` of tree a (default its tool) coincides with the origin of ``frame_b`` of tree b, both
    in the common base frame; rows that vanish identically (z of a planar mechanism) are left out."""
    pa = pose(tree_a, frame_a)[:3, 3]
    pb = pose(tree_b, frame_b)[:3, 3]
    rows = [sp.expand(a - b) for a, b in zip(pa, pb)]
    return [r for r in rows if r != 0]


def _tree_and_closure(trees, closure):
    tree = trees if isinstance(trees, EquationsOfMotion) else tree_equations(*trees)
    closure = [sp.sympify(c) for c in closure]
    if not closure:
        raise ValueError("a closed chain needs at least one loop-closure constraint phi(theta) = 0")
    velocity = set(tree.qd) | set(tree.qdd)
    for c in closure:
        if c.free_symbols & velocity:
            raise ValueError(
                f"loop-closure constraint {c} = 0 depends on velocities; it must be a function of the joint coordinates"
            )
    return tree, closure


def closed_chain(trees, closure, independent, solution: dict, name: str = "closed chain") -> EquationsOfMotion:
    """The reduced equations of a closed chain in its ``independent`` coordinates (see the module
    docstring). ``trees``: Robots (distinct joint names) or their :func:`tree_equations`;
    ``closure``: expressions phi(theta) = 0 (e.g. :func:`loop_closure`); ``independent``: tree
    coordinates (symbols or names) kept as the closed chain's coordinates; ``solution``: {dependent
    coordinate: expression of the independent ones}, one branch of the closure's solution, checked
    here to satisfy every closure row identically."""
    tree, closure = _tree_and_closure(trees, closure)
    by_name = {s.name: s for s in tree.q}

    def coordinate(c):
        key = c if isinstance(c, str) else getattr(c, "name", None)
        if key not in by_name:
            raise ValueError(f"{c!r} is not a coordinate of the trees (coordinates: {sorted(by_name)})")
        return by_name[key]

    q = [coordinate(c) for c in independent]
    solution = {coordinate(k): sp.sympify(v) for k, v in dict(solution).items()}
    dependent = [c for c in tree.q if c not in q]
    if set(solution) != set(dependent):
        raise ValueError(
            f"solution must give every dependent coordinate {[c.name for c in dependent]} as an expression of {[c.name for c in q]}, got {[c.name for c in solution]}"
        )
    for k, v in solution.items():
        stray = v.free_symbols & (set(dependent) | set(tree.qd))
        if stray:
            raise ValueError(
                f"solution for {k}: {v} must depend on the independent coordinates only, not on {sorted(map(str, stray))}"
            )
    if len(tree.q) - len(q) != len(closure):
        raise ValueError(
            f"{len(closure)} closure constraints for {len(dependent)} dependent coordinates: give as many independent constraints as dependent coordinates"
        )
    for r, c in enumerate(closure):
        residual = _simplify(c.xreplace(solution), q)
        if residual != 0 and sp.simplify(residual) != 0:
            raise ValueError(f"the solution does not close the loop: closure row {r + 1} leaves {residual}")
    vel_index = {c: i for i, c in enumerate(tree.q)}
    qd = [tree.qd[vel_index[c]] for c in q]
    qdd = [tree.qdd[vel_index[c]] for c in q]
    Theta = sp.Matrix([solution.get(c, c) for c in tree.q])
    J = Theta.jacobian(q)
    on_manifold = dict(zip(tree.q, Theta))
    on_manifold.update(dict(zip(tree.qd, J * sp.Matrix(qd))))
    simp = lambda e: _simplify(e, q)
    D = (J.T * tree.M.xreplace(on_manifold) * J).applyfunc(simp)
    g = (J.T * tree.g.xreplace(on_manifold)).applyfunc(simp)
    friction = (J.T * tree.friction.xreplace(on_manifold)).applyfunc(sp.expand)
    P = simp(sp.sympify(tree.P).xreplace(on_manifold)) if tree.P is not None else None
    steps = [
        Step(
            "Loop closure",
            "phi(theta) = 0, and the branch of its solution used",
            [(r"\phi", sp.Matrix(closure)), (r"\Theta(q)", Theta)],
        ),
        Step(
            "Reduced dynamics",
            "J = dTheta/dq, M = J^T M_tree J, g = J^T g_tree, C from the Christoffel symbols of M",
            [("J", J), ("M(q)", D), ("g(q)", g)],
        ),
    ]
    return _from_inertia(
        q,
        qd,
        qdd,
        D,
        g,
        friction,
        P,
        name=name,
        steps=steps,
        simplify_in=simp,
        latex_names=tree.latex_names,
        extra=dict(tree=tree, closure=sp.Matrix(closure), embedding=Theta, embedding_jacobian=J),
    )


def closed_chain_system(trees, closure, name: str = "closed chain"):
    """The closed chain as a constrained :class:`LagrangianSystem` in all the tree coordinates, the
    closure as holonomic constraints (no branch needed; solved numerically per evaluation by
    :meth:`LagrangianSystem.numeric`). Generalised forces: symbols u1..un at the tree joints."""
    tree, closure = _tree_and_closure(trees, closure)
    K = (tree.qd.T * tree.M * tree.qd)[0, 0] / 2
    P = sp.sympify(tree.P) if tree.P is not None else sp.Integer(0)
    B = tree.friction if any(e != 0 for e in tree.friction) else None
    return LagrangianSystem(list(tree.q), K=K, P=P, qd=list(tree.qd), B=B, holonomic=closure, name=name)


def decoupling_condition(eom: EquationsOfMotion, solve_for=None, constant: bool = False):
    """(equations, solution): the conditions on the parameters under which D(q) is diagonal for every
    q (``constant=True``: also constant), each as ``Eq(positive terms, negative terms)``, and their
    solution for ``solve_for`` (a parameter symbol or name, or a list; ``None``: no solving, ``{}``).

    Each entry is brought to its unique Fourier normal form (:func:`simplify_trig`): a sum of
    parameter coefficients times cos/sin of distinct integer combinations of the coordinates, which
    are linearly independent functions, so the entry vanishes identically exactly when every
    coefficient does."""
    q = list(eom.q)
    entries = [eom.M[i, j] for i in range(eom.n) for j in range(i + 1, eom.n)]
    if constant:
        entries += [eom.M[i, i] for i in range(eom.n)]
    conditions = []
    for k, e in enumerate(entries):
        e = sp.expand(_simplify(e, q))
        diagonal = constant and k >= len(entries) - eom.n
        terms: dict = {}
        for term in sp.Add.make_args(e):
            trig = sp.Mul(*[f for f in sp.Mul.make_args(term) if f.has(*q)])
            coeff = sp.Mul(*[f for f in sp.Mul.make_args(term) if not f.has(*q)])
            if diagonal and trig == 1:
                continue  # the constant part of a diagonal entry may stay
            terms[trig] = terms.get(trig, sp.Integer(0)) + coeff
        for coeff in terms.values():
            coeff = sp.expand(coeff)
            if coeff == 0:
                continue
            positive = sp.Add(*[t for t in sp.Add.make_args(coeff) if not t.could_extract_minus_sign()])
            negative = -sp.Add(*[t for t in sp.Add.make_args(coeff) if t.could_extract_minus_sign()])
            condition = sp.Eq(sp.factor(positive), sp.factor(negative), evaluate=False)
            if condition not in conditions:
                conditions.append(condition)
    if solve_for is None:
        return conditions, {}
    params = {s.name: s for s in eom.parameters}
    targets = [solve_for] if isinstance(solve_for, (str, sp.Symbol)) else list(solve_for)
    unknowns = []
    for t in targets:
        name = t if isinstance(t, str) else t.name
        if name not in params:
            raise ValueError(f"{t} is not a parameter of the equations (parameters: {sorted(params)})")
        unknowns.append(params[name])
    if not conditions:
        return conditions, {}
    solutions = sp.solve([c.lhs - c.rhs for c in conditions], unknowns, dict=True)
    if not solutions:
        raise ValueError(f"no value of {[u.name for u in unknowns]} satisfies the decoupling conditions {conditions}")
    return conditions, solutions[0]
