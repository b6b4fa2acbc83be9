"""Symbolic kinematics: a frame's pose and geometric Jacobian as SymPy matrices, and the textbook's
operations on them (inverse of a square block with its determinant and singular set, J qd, J^T F).

Everything is computed exactly in the trigonometric ring of the equations of motion
(:class:`kinedyn.symbolic.lagrange.RingModel`, the same forward kinematics the Lagrange derivation
uses), in the joint symbols of ``robot.equations_of_motion().q``, then written in the book's form:
sums of products of parameters with cos/sin of joint sums (``l1 cos(q1) + l2 cos(q1 + q2)``; Spong,
Hutchinson & Vidyasagar, *Robot Modeling and Control*, §3.2 and §4.6-4.9).

Jacobian conventions are those of the numeric ``Robot.jacobian`` (docs/conventions.md): rows
``[linear; angular]``; ``reference="world"`` the velocity of the frame origin (or of ``point``, given
in the frame's axes) and the angular velocity in base axes (Pinocchio's LOCAL_WORLD_ALIGNED);
``"local"`` both in the frame's axes; ``"spatial"`` the spatial twist (velocity of the body point at
the base origin, angular velocity, base axes).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any, NamedTuple

import sympy as sp

from ...description.parametrise import euler_parametrised
from ..render.text import abbreviate
from ..values import exact
from .lagrange import RingModel, state_symbols
from .simplify import simplify_trig

__all__ = [
    "pose",
    "jacobian",
    "jacobian_inverse",
    "JacobianInverse",
    "tool_velocity",
    "joint_torques",
    "abbreviate",
    "joint_symbols",
]

_REFERENCES = ("world", "local", "spatial")


def joint_symbols(robot) -> list[sp.Symbol]:
    """The joint symbols of ``robot.equations_of_motion().q`` (the same SymPy objects)."""
    return state_symbols(robot)[0]


def _minimal(robot):
    """The robot in minimal coordinates (multi-DOF joints as Euler-angle chains)."""
    return euler_parametrised(robot)


def _model(robot, frame: str | None = None, point=None) -> RingModel:
    """The exact kinematics, with the frame's placement and the point among the ring's parameters."""
    q, qd, qdd = state_symbols(robot)
    f = robot.tree.frames[robot.frame_index(frame or robot.tool)]
    extra = [x for row in _rows(f.placement) for x in row] + list(point if point is not None else [])
    return RingModel(robot, q, qd, qdd, extra_leaves=extra)


def _rows(M) -> list:
    return M.tolist() if hasattr(M, "tolist") else [list(r) for r in M]


def _frame(robot, model: RingModel, frame: str | None):
    """(R, p) of the frame in the base and (Rf, pf) of its placement in its body, as ring elements;
    body index (-1 for a frame fixed to the base)."""
    f = robot.tree.frames[robot.frame_index(frame or robot.tool)]
    T = [[model._c(exact(x)) for x in row] for row in _rows(f.placement)]
    Rf = [row[:3] for row in T[:3]]
    pf = [row[3] for row in T[:3]]
    if f.body < 0:
        return Rf, pf, Rf, pf, -1
    Rb, pb = model.R[f.body], model.p[f.body]
    R = model._mat(Rb, Rf)
    p = [pb[k] + model.ring.dot(Rb[k], pf) for k in range(3)]
    return R, p, Rf, pf, f.body


def _book(model: RingModel, e, factor: bool = True):
    """The book's form of a ring element: the Fourier form (cos/sin of joint sums), or, if shorter,
    the trigsimp'd product form (cos(q1) (L2 cos(q2) + L3 cos(q2 + q3)) for a spatial arm)."""
    ring = model.ring
    f = ring.to_sympy(e, factor)
    if len(sp.Add.make_args(f)) <= 1:
        return f
    prod = ring.to_product_form(ring.chop(e))
    if len(sp.Add.make_args(sp.expand(prod))) > 8:  # trigsimp grows fast: long entries stay in Fourier form
        return f
    g = _trigsimp_factored(prod)
    return _unminus(g if sp.count_ops(g) < sp.count_ops(f) else f)


@functools.lru_cache(maxsize=4096)
def _trigsimp_factored(prod: sp.Expr) -> sp.Expr:
    """trigsimp between factor_terms, remembered: the pose, the Jacobians in each reference and the
    frames along the chain share many entries (a third to a half of the PUMA's), and trigsimp is
    nearly all of a derivation's time."""
    return sp.factor_terms(sp.trigsimp(sp.factor_terms(prod)))


def _unminus(e):
    """-(a + b) -> -a - b, as the book writes a sum; 1.0*q3 -> q3 (whole floats of a numeric robot)."""
    floats = {f: sp.Integer(int(f)) for f in e.atoms(sp.Float) if float(f).is_integer()}
    if floats:
        e = e.xreplace(floats)
    if e.is_Mul and len(e.args) == 2 and e.args[0] == -1 and e.args[1].is_Add:
        return sp.Add(*[-a for a in e.args[1].args])
    return e


def _matrix(model, rows, simplify: bool) -> sp.Matrix:
    if not simplify:
        return sp.Matrix([[model.ring.to_product_form(e) for e in row] for row in rows])
    return sp.Matrix([[_book(model, e) for e in row] for row in rows])


def pose(robot, frame: str | None = None, simplify: bool = True, abbreviations: bool = False) -> sp.Matrix:
    """The 4x4 homogeneous pose of ``frame`` (default: the tool) in the base, as a SymPy matrix in the
    joint symbols of ``robot.equations_of_motion().q`` and the robot's parameter symbols.

    ``simplify=False`` gives the raw product form (sin/cos of single joints); ``abbreviations=True``
    writes cos(q1 + q2) as ``c12`` (see :func:`abbreviate`). A multi-DOF joint is written in its
    position and ZYX Euler angles (:mod:`kinedyn.description.parametrise`)."""
    robot = _minimal(robot)
    model = _model(robot, frame)
    R, p, _, _, _ = _frame(robot, model, frame)
    ring = model.ring
    rows = [list(R[k]) + [p[k]] for k in range(3)] + [[ring.zero, ring.zero, ring.zero, ring.one]]
    T = _matrix(model, rows, simplify)
    return abbreviate(T, model.q) if abbreviations else T


def jacobian(
    robot,
    frame: str | None = None,
    reference: str = "world",
    point: Sequence[Any] | None = None,
    simplify: bool = True,
    abbreviations: bool = False,
) -> sp.Matrix:
    """The 6 x n geometric Jacobian of ``frame`` (default: the tool), rows ``[linear; angular]``, in the
    references of ``Robot.jacobian`` ("world", "local", "spatial"; see the module docstring).

    ``point``: a point fixed in the frame's body, given in the frame's coordinates (numbers or SymPy
    expressions, e.g. a centre of mass ``(lc2 - l2, 0, 0)``); its velocity replaces the origin's in the
    linear rows of "world" and "local" (the spatial twist does not depend on a point)."""
    if reference not in _REFERENCES:
        raise ValueError(f"reference must be one of {list(_REFERENCES)}, got '{reference}'")
    if point is not None and len(list(point)) != 3:
        raise ValueError(f"point must be 3 coordinates in the frame's axes, got {point!r}")
    robot = _minimal(robot)
    model = _model(robot, frame, point)
    ring, n = model.ring, model.n
    R, p, Rf, pf, body = _frame(robot, model, frame)
    zero = ring.zero
    if body < 0:
        rows = [[zero] * n for _ in range(6)]
        return _matrix(model, rows, simplify)
    if point is not None:
        pt = [model._c(exact(x)) for x in point]
    else:
        pt = [zero, zero, zero]
    # the point in body coordinates: r = Rf pt + pf
    r = [pf[k] + ring.dot(Rf[k], pt) for k in range(3)]
    Jv, Jw = model.Jv[body], model.Jw[body]  # body origin's linear and the angular velocity, body axes
    Rb = model.R[body]
    # velocity of the body point r, body axes: Jv + Jw x r = Jv - [r]x Jw
    Sr = model._skew(r)
    SJ = model._mat(Sr, Jw)
    Jvp = [[Jv[k][j] - SJ[k][j] for j in range(n)] for k in range(3)]
    if reference == "world":
        lin, ang = model._mat(Rb, Jvp), model._mat(Rb, Jw)
    elif reference == "local":
        lin, ang = model._matT(Rf, Jvp), model._matT(Rf, Jw)
    else:  # spatial: v at the base origin = v_o + w x (0 - p_o) = v_o + [p_o]x w (body origin o)
        ang = model._mat(Rb, Jw)
        vo = model._mat(Rb, Jv)
        Sp = model._skew(model.p[body])
        Spw = model._mat(Sp, ang)
        lin = [[vo[k][j] + Spw[k][j] for j in range(n)] for k in range(3)]
    rows = [[ring.reduce(x) for x in row] for row in lin + ang]
    J = _matrix(model, rows, simplify)
    return abbreviate(J, model.q) if abbreviations else J


# ---------------------------------------------------------------------------------- textbook helpers
def _coordinates(expr) -> list[sp.Symbol]:
    """The symbols that appear inside sin/cos (the joint angles of a Jacobian block), sorted by name."""
    out = set()
    for f in sp.sympify(expr).atoms(sp.sin, sp.cos):
        out |= f.args[0].free_symbols
    return sorted(out, key=sp.default_sort_key)


def _simp(e, coords):
    return simplify_trig(e, coords) if coords else sp.factor(sp.cancel(e))


class JacobianInverse(NamedTuple):
    """Inverse (or right pseudo-inverse) of a Jacobian block: ``inverse = adjugate / determinant``."""

    inverse: sp.Matrix
    determinant: Any
    singular: list

    @property
    def adjugate(self) -> sp.Matrix:
        """The matrix the textbook writes after ``1/det``: inverse * det, simplified."""
        coords = _coordinates(self.inverse)
        return (self.inverse * self.determinant).applyfunc(lambda e: _simp(sp.cancel(e), coords))

    def factored(self):
        """``1/det * adjugate`` as an unevaluated product, the textbook's display."""
        return sp.MatMul(1 / self.determinant, self.adjugate, evaluate=False)


def jacobian_inverse(J, coordinates: Sequence[sp.Symbol] | None = None) -> JacobianInverse:
    """(inverse, determinant, singular) of a square Jacobian block, in the textbook's form: the
    determinant factored (``l1*l2*sin(q2)`` for the planar arm's linear block), the inverse as the
    adjugate's simplified entries over it, and the singular set as a list of ``Eq(factor, 0)`` for each
    factor of the determinant that depends on the joint coordinates (parameter factors such as
    ``l1 = 0`` are left out). A non-square block of full row rank gets the right pseudo-inverse
    ``J^T (J J^T)^-1`` with the determinant of ``J J^T``.

    ``coordinates``: the joint symbols (default: every symbol found inside a sin or cos)."""
    J = sp.Matrix(J)
    coords = list(coordinates) if coordinates is not None else _coordinates(J)
    if J.rows == J.cols:
        A, tail = J, None
    else:
        A, tail = (J * J.T).applyfunc(lambda e: _simp(e, coords)), J.T
    det = sp.factor(_simp(A.det(method="berkowitz"), coords))
    if det == 0:
        raise ValueError("the block is singular everywhere (determinant 0)")
    adj = A.adjugate().applyfunc(lambda e: _simp(e, coords))
    if tail is not None:
        adj = (tail * adj).applyfunc(lambda e: _simp(e, coords))
    inverse = adj.applyfunc(lambda e: e / det)
    singular = []
    for fac in sp.Mul.make_args(det):
        base = fac.base if fac.is_Pow else fac
        if base.free_symbols & set(coords) and not base.is_number:
            cond = sp.Eq(base, 0)
            if cond not in singular:
                singular.append(cond)
    return JacobianInverse(inverse, det, singular)


def tool_velocity(J, qd, coordinates: Sequence[sp.Symbol] | None = None) -> sp.Matrix:
    """The twist J qd (or the velocity of any block of rows), simplified to the book's form."""
    J = sp.Matrix(J)
    coords = list(coordinates) if coordinates is not None else _coordinates(J)
    return (J * sp.Matrix(list(qd))).applyfunc(lambda e: _simp(sp.expand(e), coords))


def joint_torques(J, F, coordinates: Sequence[sp.Symbol] | None = None) -> sp.Matrix:
    """The joint torques J^T F that balance a wrench F (ordered as J's rows), in the book's form."""
    J = sp.Matrix(J)
    coords = list(coordinates) if coordinates is not None else _coordinates(J)
    return (J.T * sp.Matrix(list(F))).applyfunc(lambda e: _simp(sp.expand(e), coords))
