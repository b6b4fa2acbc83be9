"""The equations of motion as CasADi Functions (``eom.to_casadi()``), for optimal control with CasADi
(``casadi.Opti``, IPOPT, multiple shooting, collocation ...).

The SymPy programs of :mod:`kinedyn.symbolic.codegen` (with common subexpressions eliminated; for large
models the CSE form of :mod:`kinedyn.symbolic.cse`, never expanded) are translated node by node into
CasADi ``SX`` by :class:`kinedyn.symbolic.translate.Walker`, so every intermediate variable is one shared
SX node. Functions and their named inputs:

==================  =============================  ========================================
Function            inputs                          output
==================  =============================  ========================================
``M``               ``q`` [, ``p``]                ``M`` (n x n), rotor inertia included
``C``               ``q, qd`` [, ``p``]            ``C`` (n x n), Christoffel form
``g``               ``q`` [, ``p``]                ``g`` (n)
``tau``             ``q, qd, qdd`` [, ``p``]       ``tau`` (n) = M qdd + C qd + g + friction
``forward_dynamics`` ``q, qd, tau`` [, ``p``]      ``qdd`` (n), ``casadi.solve(M, tau - bias)``
``pose``            ``q`` [, ``p``]                ``T`` (4 x 4), the tool (or ``frame``)
``jacobian``        ``q`` [, ``p``]                ``J`` (6 x n), rows [linear; angular], world
==================  =============================  ========================================

``p`` is present only when parameters are left symbolic, and is the same vector for every Function;
its order is ``CasadiEOM.parameters``: ``eom.parameters`` less those given in ``params`` (the order of
:func:`kinedyn.symbolic.codegen.generate` and ``eom.compile``), then, sorted by name, any symbols that
only the pose and Jacobian use (a tool offset that the dynamics never see, such as the last link's
length of the two-link arm). ``pose``/``jacobian`` need the robot (known to equations from
``robot.equations_of_motion()``).
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from ..derive import kinematics
from . import program
from .walker import Walker

__all__ = ["CasadiEOM", "to_casadi"]


def _casadi():
    try:
        import casadi
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("eom.to_casadi() needs CasADi: pip install 'kinedyn[scale]' (or pip install casadi)") from exc
    return casadi


def _functions(ca) -> dict[str, Any]:
    return {
        "sin": ca.sin,
        "cos": ca.cos,
        "tan": ca.tan,
        "exp": ca.exp,
        "log": ca.log,
        "sqrt": ca.sqrt,
        "fabs": ca.fabs,
        "sign": ca.sign,
        "asin": ca.asin,
        "acos": ca.acos,
        "atan": ca.atan,
        "atan2": ca.atan2,
        "sinh": ca.sinh,
        "cosh": ca.cosh,
        "tanh": ca.tanh,
        "fmax": ca.fmax,
        "fmin": ca.fmin,
    }


class CasadiEOM:
    """CasADi Functions of one set of equations (see the module docstring): attributes ``M``, ``C``,
    ``g``, ``tau``, ``forward_dynamics`` and, for robots, ``pose`` and ``jacobian``; ``parameters``:
    the SymPy symbols of the input ``p`` in order; ``n``: joints."""

    def __init__(self, n: int, parameters: list, functions: dict[str, Any]):
        self.n = n
        self.parameters = parameters
        self.functions = functions
        for name, f in functions.items():
            setattr(self, name, f)

    def __repr__(self) -> str:
        return f"CasadiEOM(n={self.n}, functions={list(self.functions)}, p={[str(s) for s in self.parameters]})"


def _sx_matrix(ca, values: list[Any], shape: tuple):
    rows = shape[0]
    cols = shape[1] if len(shape) == 2 else 1
    out = ca.SX.zeros(rows, cols)
    for k, v in enumerate(values):
        out[k // cols, k % cols] = v
    return out


def to_casadi(eom, params=None, robot=None, frame: str | None = None) -> CasadiEOM:
    """CasADi Functions of ``eom``; ``params``: {symbol or name: value} fixed now (the others form ``p``);
    ``robot`` (default: the robot the equations came from) and ``frame`` (default: its tool) for the pose
    and Jacobian."""
    ca = _casadi()
    n = eom.n
    params = program.params_by_name(eom, params)
    blocks, pars = program.blocks(eom, ("M", "C", "g", "tau"), params)
    robot = robot if robot is not None else getattr(eom, "robot", None)
    state = {s: sp.Symbol(f"q[{i}]") for i, s in enumerate(eom.q)}
    kinematic = []
    if robot is not None:  # the tool pose and Jacobian; symbols only they use extend p at its end
        by_name = {str(k): v for k, v in params.items()}
        for label, matrix in (
            ("pose", kinematics.pose(robot, frame, simplify=False)),
            ("jacobian", kinematics.jacobian(robot, frame, simplify=False)),
        ):
            fixed = {s: by_name[str(s)] for s in matrix.free_symbols if str(s) in by_name}
            kinematic.append((label, matrix.subs(fixed) if fixed else matrix))
        known = set(state) | set(pars)
        pars = list(pars) + sorted({s for _, m in kinematic for s in m.free_symbols} - known, key=str)
    q, qd, qdd, tau_in = (ca.SX.sym(name, n) for name in ("q", "qd", "qdd", "tau"))
    p = ca.SX.sym("p", len(pars))
    env: dict[sp.Symbol, Any] = {}
    for name, vec in (("q", q), ("qd", qd), ("qdd", qdd)):
        for i in range(n):
            env[sp.Symbol(f"{name}[{i}]")] = vec[i]
    for i in range(len(pars)):
        env[sp.Symbol(f"p[{i}]")] = p[i]
    fns = _functions(ca)
    outputs = {}
    for name, shape, assignments, exprs in blocks:
        walker = Walker(env, fns)  # one walker per block: the blocks' own x1, x2, ... may clash
        walker.assign(assignments)
        outputs[name] = _sx_matrix(ca, [walker(e) for e in exprs], shape)

    inputs = {"q": q, "qd": qd, "qdd": qdd, "tau": tau_in}
    extra = [p] if len(pars) else []
    extra_names = ["p"] if len(pars) else []

    def function(name: str, args: tuple, out_name: str, value):
        return ca.Function(name, [inputs[a] for a in args] + extra, [value], list(args) + extra_names, [out_name])

    funcs = {
        "M": function("M", ("q",), "M", outputs["M"]),
        "C": function("C", ("q", "qd"), "C", outputs["C"]),
        "g": function("g", ("q",), "g", outputs["g"]),
        "tau": function("tau", ("q", "qd", "qdd"), "tau", outputs["tau"]),
    }
    # forward dynamics: M qdd = tau - bias, bias = tau(q, qd, 0) = C qd + g + friction (a linear solve,
    # never an inverse; CasADi's symbolic QR for SX)
    bias = ca.substitute(outputs["tau"], qdd, ca.SX.zeros(n))
    funcs["forward_dynamics"] = function(
        "forward_dynamics", ("q", "qd", "tau"), "qdd", ca.solve(outputs["M"], tau_in - bias)
    )

    pmap = {s: sp.Symbol(f"p[{i}]") for i, s in enumerate(pars)}
    for label, matrix in kinematic:
        m = matrix.xreplace({**state, **pmap})
        reps, reduced = sp.cse(list(m), symbols=sp.numbered_symbols("k"), order="none")
        walker = Walker(env, fns)
        walker.assign(reps)
        funcs[label] = function(
            label, ("q",), "T" if label == "pose" else "J", _sx_matrix(ca, [walker(e) for e in reduced], tuple(m.shape))
        )
    return CasadiEOM(n, list(pars), funcs)
