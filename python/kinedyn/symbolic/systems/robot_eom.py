"""Builds :class:`EquationsOfMotion` for a :class:`kinedyn.Robot` by either method."""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from typing import Any

import sympy as sp

from ...description.parametrise import euler_parametrised
from ...description.snap import snap_note, snap_right_angles
from ..derive.cse import CSE_JOINTS, CSE_THRESHOLD, closed_form_of_program, closed_form_steps
from ..derive.lagrange import (
    RingModel,
    body_coordinates,
    christoffel,
    coriolis_matrix,
    derive_lagrange,
    latex_names,
    state_symbols,
)
from ..derive.newton_euler import newton_euler_program, newton_euler_steps
from ..eom import EquationsOfMotion
from ..render.mathml import Name, ddt_dL_dqd, dL_dq, dL_dqd, lagrangian, mi, name, of_q, tokens
from ..steps import Step
from ..values import exact
from .closed_loops import closed_loop_equations

__all__ = ["equations_of_motion", "lagrange_eom", "newton_euler_eom", "general_parameters"]


def general_parameters(robot):
    """Per-body symbols [M_j, MX_j, MY_j, MZ_j, XX_j, XY_j, YY_j, XZ_j, YZ_j, ZZ_j] (Khalil & Dombre's
    names for the standard parameters about the body origin): a robot with general symbolic inertias."""
    out = []
    for j in range(1, len(robot.tree.bodies) + 1):  # per body: mimic followers' too
        out.append(list(sp.symbols(f"M{j} MX{j} MY{j} MZ{j} XX{j} XY{j} YY{j} XZ{j} YZ{j} ZZ{j}", real=True)))
    return out


class _Inertias:
    """Adapter: a 10-vector of parameters where RingModel expects an Inertia."""

    def __init__(self, pi):
        self._pi = list(pi)
        m = pi[0]
        self.com = tuple(sp.sympify(h) / m for h in pi[1:4]) if m != 0 else (0, 0, 0)

    def parameters(self):
        return self._pi


def _friction(robot, qd):
    """Each joint's friction at its rate; with reduced mimic joints G^T of those (a follower's, at
    ``m qd_k``, adds m times itself to its leader's)."""
    out = [sp.Integer(0)] * len(qd)
    for b, (k, m, _) in zip(robot.tree.bodies, body_coordinates(robot)):
        v = m * qd[k]
        out[k] = out[k] + m * (exact(b.joint.viscous) * v + b.joint.coulomb_torque(v, exact))
    return sp.Matrix(out)


def _outputs(model, d, simplify):
    ring = model.ring
    conv = (lambda p: ring.to_sympy(p)) if simplify else ring.to_product_form
    mat = lambda rows: sp.Matrix([[conv(e) for e in row] for row in rows])
    vec = lambda xs: sp.Matrix([conv(e) for e in xs])
    return conv, mat, vec


def _steps(robot, model, d, conv, mat, vec, q, qd):
    """The derivation in the tutorial's order (Spong §9.2-9.3, eqs. 9.45-9.62)."""
    ring, n = model.ring, model.n
    steps = []
    try:
        pc = model.com_positions()
        st = Step(
            "Centre-of-mass positions r_ci(q) in the base frame",
            "Each link's centre of mass, from the forward kinematics.",
        )
        for i in range(model.n_bodies):
            st.equations.append((name(f"r_{{c{i + 1}}}", f"r_c{i + 1}", "r", f"c{i + 1}"), vec(pc[i])))
        steps.append(st)
        st = Step(
            "Velocity Jacobians", "v_ci = J_vci(q) qd and omega_i = J_wi(q) qd (Spong eq. 9.45); J_vci = d r_ci / dq."
        )
        for i in range(model.n_bodies):
            Jvc = [[ring.diff_q(pc[i][k], j) for j in range(n)] for k in range(3)]
            st.equations.append((_jac_name("v", f"c{i + 1}"), mat(Jvc)))
            st.equations.append((_jac_name("omega", f"{i + 1}"), mat(model.world_angular_jacobian(i))))
        steps.append(st)
    except Exception:  # centre of mass not polynomial (e.g. h/m with symbolic m): skip the display step
        pass
    steps.append(
        Step(
            "Kinetic energy K = qd^T M(q) qd / 2",
            "M(q) = sum_i m_i J_vci^T J_vci + J_wi^T R_i I_i R_i^T J_wi, plus reflected rotor inertia r^2 J_m on the diagonal (Spong eqs. 9.46-9.47).",
            [(of_q("M"), mat(d["D"])), (name("K", "K", "K"), conv(d["K"]))],
        )
    )
    steps.append(
        Step(
            "Potential energy P = sum_i m_i g^T r_ci",
            "(Spong eqs. 9.48-9.49; g points along gravity)",
            [(name("P", "P", "P"), conv(d["P"]))],
        )
    )
    steps.append(Step("Lagrangian L = K - P", "", [(lagrangian(), conv(d["L"]))]))
    st = Step(
        "Derivatives of the Lagrangian",
        "For each coordinate: dL/dqd_k, its time derivative, and dL/dq_k (Spong eq. 9.40).",
    )
    for k in range(n):
        st.equations.append((dL_dqd(q[k], qd[k]), conv(d["dL_dqd"][k])))
        st.equations.append((ddt_dL_dqd(q[k], qd[k]), conv(d["ddt_dL_dqd"][k])))
        st.equations.append((dL_dq(q[k]), conv(d["dL_dq"][k])))
    steps.append(st)
    st = Step(
        "Joint torques tau_k = d/dt dL/dqd_k - dL/dq_k",
        "Friction, if any, is added separately: viscous qd + coulomb sign(qd).",
    )
    for k in range(n):
        st.equations.append((name(f"\\tau_{{{k + 1}}}", f"tau_{k + 1}", "tau", f"{k + 1}"), conv(d["tau"][k])))
    steps.append(st)
    st = Step(
        "Christoffel symbols c_ijk (non-zero ones)",
        "c_ijk = (dD_kj/dq_i + dD_ki/dq_j - dD_ij/dq_k) / 2 (Spong eq. 9.58), C_kj = sum_i c_ijk qd_i (eq. 9.62).",
    )
    c = d["christoffel"]
    for k in range(n):
        for i in range(n):
            for j in range(i, n):
                if c[i][j][k]:
                    st.equations.append(
                        (
                            name(
                                f"c_{{{i + 1}{j + 1}{k + 1}}}",
                                f"c_{i + 1}{j + 1}{k + 1}",
                                "c",
                                f"{i + 1}{j + 1}{k + 1}",
                            ),
                            conv(c[i][j][k]),
                        )
                    )
    steps.append(st)
    return steps


def _jac_name(kind, index):
    """J_{v_{c1}} (text J_vc1) or J_{omega_1} (text J_w1), with MathML subscripts of subscripts."""
    if kind == "v":
        return Name(
            f"J_{{v_{{{index}}}}}", f"J_v{index}", f"<msub><mi>J</mi><msub><mi>v</mi>{tokens(index)}</msub></msub>"
        )
    return Name(
        f"J_{{\\omega_{{{index}}}}}", f"J_w{index}", f"<msub><mi>J</mi><msub>{mi('ω')}{tokens(index)}</msub></msub>"
    )


def _christoffel_sympy(c, conv):
    n = len(c)
    return [[[conv(c[i][j][k]) for k in range(n)] for j in range(n)] for i in range(n)]


def _use_cse(form: str, prog, n: int) -> bool:
    """Whether the results are shown in CSE form: ``form`` "cse", "expanded" or "auto": CSE above
    :data:`kinedyn.symbolic.cse.CSE_THRESHOLD` operations of the customised model or above
    :data:`kinedyn.symbolic.cse.CSE_JOINTS` coordinates, numeric parameters or not (a 6-joint arm's
    expanded Lagrange steps run to hundreds of pages either way)."""
    if form not in ("auto", "cse", "expanded"):
        raise ValueError(f"form must be 'auto', 'cse' or 'expanded', got {form!r}")
    return form == "cse" or (form == "auto" and (n > CSE_JOINTS or prog.op_count()["total"] > CSE_THRESHOLD))


def _closed_form_getter(prog, q, qd, qdd) -> Callable[[], Any]:
    """A cached getter of M, C, g in CSE form (kinedyn.symbolic.cse), built on first call."""
    cache: dict[str, Any] = {}

    def closed():
        if "cf" not in cache:
            cache["cf"] = closed_form_of_program(prog, q, qd, qdd)
        return cache["cf"]

    return closed


class _LazyDerivation:
    """The Lagrange derivation (:func:`derive_lagrange`'s dict), computed on the first lookup: a CSE-form
    display never needs it."""

    def __init__(self, model):
        self._model = model

    @cached_property
    def values(self) -> dict[str, Any]:
        return derive_lagrange(self._model)

    def __getitem__(self, key: str):
        return self.values[key]


def lagrange_eom(
    robot, simplify: bool = True, with_steps: bool = True, parameters=None, form: str = "auto"
) -> EquationsOfMotion:
    """Euler-Lagrange equations (Spong §9.2-9.3). With ``form`` "cse" (or "auto" for a large model) the
    rendered results are M, C, g in CSE form from the customised Newton-Euler model -- the same unique M,
    g and Christoffel C -- and the Lagrange steps, too large to read, are replaced by a note; ``eom.M``,
    ``eom.C``... are the expanded matrices either way, formed on first use."""
    q, qd, qdd = state_symbols(robot)
    inertias = [_Inertias(p) for p in parameters] if parameters is not None else None
    model = RingModel(robot, q, qd, qdd, inertias=inertias)
    d = _LazyDerivation(model)
    conv, mat, vec = _outputs(model, d, simplify)
    friction = _friction(robot, qd)
    prog = None
    if form != "expanded":
        try:
            prog = newton_euler_program(robot, q, qd, qdd, parameters=parameters, friction=False)
        except Exception:  # noqa: BLE001 - a model the recursion cannot take is shown expanded, as before
            if form == "cse":
                raise
    cse = prog is not None and _use_cse(form, prog, len(q))
    closed = _closed_form_getter(prog, q, qd, qdd) if cse else None
    steps: Any = None
    if with_steps and cse:

        def steps():
            note = Step(
                "Lagrange's steps omitted (too large to read)",
                f"K, P, L and their derivatives of this {robot.n}-joint model run to thousands of terms. M, C and g below are the "
                "same unique inertia matrix, Christoffel Coriolis matrix and gravity vector, formed from the customised "
                "Newton-Euler model and printed with named intermediate variables; in Python the result's attributes M, C and g hold them expanded.",
            )
            assert closed is not None
            return [note] + closed_form_steps(closed())
    elif with_steps:
        steps = lambda: _steps(robot, model, d, conv, mat, vec, q, qd)
    return EquationsOfMotion(
        q,
        qd,
        qdd,
        M=lambda: mat(d["M"]),
        C=lambda: mat(d["C"]),
        g=lambda: vec(d["g"]),
        K=lambda: conv(d["K"]),
        P=lambda: conv(d["P"]),
        friction=friction,
        christoffel=lambda: _christoffel_sympy(d["christoffel"], conv),
        tau=lambda: vec(d["tau"]) + friction,
        steps=steps,
        name=robot.name,
        method="lagrange",
        latex_names=latex_names(q, qd, qdd),
        model=(model, d),
        closed_form=closed,
        robot=robot,
    )


def _ring_converter(model):
    """convert(expr, env) for Program.evaluate: SymPy expression -> exact ring element."""
    ring = model.ring
    qset = set(model.q)

    def convert(e, env):
        if e in env:
            return env[e]
        if e.is_Symbol:
            if e in model.qd:
                return ring.velocity(model.qd.index(e))
            if e in model.qdd:
                return ring.acceleration(model.qdd.index(e))
            if e in qset:
                return ring.angle(model.q.index(e))
            return ring.const(e)
        if isinstance(e, (sp.sin, sp.cos)):  # of m q_i + offset (m = 1 but for a mimic follower)
            arg = sp.expand(e.args[0])
            i = next(k for k, x in enumerate(model.q) if arg.has(x))
            m = arg.coeff(model.q[i])
            off = sp.expand(arg - m * model.q[i])
            return ring.cos_multiple(i, m, off) if isinstance(e, sp.cos) else ring.sin_multiple(i, m, off)
        if not (e.free_symbols & (set(env) | qset | set(model.qd) | set(model.qdd))):
            return ring.const(e)
        if e.is_Add:
            out = ring.zero
            for a in e.args:
                out += convert(a, env)
            return out
        if e.is_Mul:
            out = ring.one
            for a in e.args:
                out = ring.reduce(out * convert(a, env))
            return out
        if e.is_Pow and e.exp.is_Integer and e.exp > 0:
            base = convert(e.base, env)
            out = ring.one
            for _ in range(int(e.exp)):
                out = ring.reduce(out * base)
            return out
        raise ValueError(f"cannot evaluate {e} exactly")

    return convert


def newton_euler_eom(
    robot, simplify: bool = True, parameters=None, with_steps: bool = True, form: str = "auto"
) -> EquationsOfMotion:
    """Equations from the customised Newton-Euler model; tau, M, g, C come from the program alone
    (M = d tau / d qdd and g = tau(q, 0, 0) of the exactly evaluated program, C from M's Christoffel
    symbols), P and K from the kinematics."""
    q, qd, qdd = state_symbols(robot)
    prog = newton_euler_program(robot, q, qd, qdd, parameters=parameters, friction=False)
    closed = _closed_form_getter(prog, q, qd, qdd) if _use_cse(form, prog, len(q)) else None
    friction = _friction(robot, qd)
    inertias = [_Inertias(p) for p in parameters] if parameters is not None else None
    cache: dict[str, Any] = {}

    def derived():
        if not cache:
            model = RingModel(robot, q, qd, qdd, inertias=inertias)
            ring, n = model.ring, model.n
            tau = [ring.reduce(t) for t in prog.evaluate(_ring_converter(model))]
            M = [[ring.diff_qdd(tau[k], j) for j in range(n)] for k in range(n)]
            g = [ring.substitute_state(t, qd_zero=True, qdd_zero=True) for t in tau]
            c = christoffel(ring, M)
            C = coriolis_matrix(ring, c)
            P = model.potential_energy()
            cache.update(model=model, tau=tau, M=M, g=g, christoffel=c, C=C, P=P)
            conv, mat, vec = _outputs(model, None, simplify)
            cache.update(conv=conv, mat=mat, vec=vec)
        return cache

    def potential():  # from the kinematics alone (cheap), not the whole derivation
        if "P" in cache:
            return derived()["conv"](cache["P"])
        model = RingModel(robot, q, qd, qdd, inertias=inertias)
        return _outputs(model, None, simplify)[0](model.potential_energy())

    return EquationsOfMotion(
        q,
        qd,
        qdd,
        M=lambda: derived()["mat"](derived()["M"]),
        C=lambda: derived()["mat"](derived()["C"]),
        g=lambda: derived()["vec"](derived()["g"]),
        P=potential,
        friction=friction,
        christoffel=lambda: _christoffel_sympy(derived()["christoffel"], derived()["conv"]),
        tau=lambda: derived()["vec"](derived()["tau"]) + friction,
        steps=(
            lambda: (
                newton_euler_steps(prog, robot, q, qd, qdd)
                + (closed_form_steps(closed()) if closed is not None else [])
            )
        )
        if with_steps
        else None,
        name=robot.name,
        method="newton_euler",
        latex_names=latex_names(q, qd, qdd),
        program=prog,
        closed_form=closed,
        derivation=derived,
        robot=robot,
    )


def equations_of_motion(
    robot,
    method: str = "lagrange",
    simplify: bool = True,
    steps: bool = True,
    parameters=None,
    form: str = "auto",
    snap_angles: float | None = None,
    independent=None,
    solution=None,
) -> EquationsOfMotion:
    """The symbolic equations of motion of a :class:`kinedyn.Robot` (numbers, symbols, or a mix).

    ``method="lagrange"``: Euler-Lagrange from K and P with every step kept (Spong §9.2-9.3).
    ``method="newton_euler"``: the customised symbolic recursive Newton-Euler model with intermediate
    variables (Khalil & Dombre); M, g and C are formed from it as well.
    ``simplify=True`` gives the textbook (Fourier) form of every entry; ``False`` the product form.
    ``parameters="general"`` replaces every body's inertia by the ten symbols M_j, MX_j, MY_j, MZ_j,
    XX_j, XY_j, YY_j, XZ_j, YZ_j, ZZ_j (about the body origin, Khalil & Dombre's names), so that
    ``eom.regressor()`` groups them into base parameters; a list of per-body 10-vectors is used as given.
    ``form``: how the renderings (``str``, ``to_latex`` ...) show M, C, g: ``"expanded"``, ``"cse"``
    (named intermediate variables, Khalil & Dombre's way; :mod:`kinedyn.symbolic.cse`) or ``"auto"``
    (CSE for a large model, e.g. a 6-joint arm with general inertias). ``eom.M`` etc. are the same.

    Floating, spherical and planar joints are derived in minimal coordinates: position and ZYX Euler
    angles (x, y, z, yaw, pitch, roll), (yaw, pitch, roll), (x, y, theta), with their rates as the
    velocities (:mod:`kinedyn.description.parametrise`; ``eom.robot`` is that robot). Reduced mimic
    joints stay reduced: a follower's joint variable is ``m q_leader + o`` (docs/symbolic.md, "Mimic
    joints"; :mod:`kinedyn.symbolic.lagrange`).

    ``snap_angles``: a tolerance in radians; the robot's rotation angles within it of a multiple of
    pi/2 (a file's ``1.570796325``) are made exact first, so that cos(pi/2) terms vanish instead of
    printing as 1e-12 (:func:`kinedyn.description.snap.snap_right_angles`); ``eom.notes`` says what
    moved and ``eom.robot`` is the snapped robot. ``kinedyn derive`` snaps within 1e-6 rad by default.

    A robot with loops (``robot.loops``) gets a :class:`~kinedyn.symbolic.systems.closed_loops.ClosedLoopEquations`:
    the tree's M, C, g with the closure phi(q) = 0, A = dphi/dq and M qdd + C qd + g = tau + A^T lambda, and
    ``eom.reduced``, the equations in the independent coordinates (``independent``: their names, chosen
    from A when not given; ``solution``: {dependent coordinate: expression of the independent ones},
    an explicit branch of the closure; docs/closed-loops.md, "The equations").
    """
    if (independent is not None or solution is not None) and not robot.loops:
        raise ValueError(
            f"independent= and solution= choose the reduced coordinates of a robot with loops; robot '{robot.name}' has none"
        )
    notes = []
    if snap_angles:
        snapped, moved = snap_right_angles(robot.description, snap_angles)
        if moved:
            robot = robot.replace(links=snapped.links, frames=snapped.frames)
            notes.append(snap_note(moved, snap_angles))
    robot = euler_parametrised(robot)
    if isinstance(parameters, str):
        if parameters != "general":
            raise ValueError(f"parameters must be 'general' or a list of per-body 10-vectors, got {parameters!r}")
        parameters = general_parameters(robot)
    bodies = len(robot.tree.bodies)  # robot.n, or more with reduced mimic joints
    if parameters is not None and (len(parameters) != bodies or any(len(p) != 10 for p in parameters)):
        raise ValueError(f"parameters must hold {bodies} vectors of 10 inertial parameters (one per moving body)")
    if method == "lagrange":
        eom = lagrange_eom(robot, simplify=simplify, with_steps=steps, parameters=parameters, form=form)
    elif method in ("newton_euler", "newton-euler", "rnea"):
        eom = newton_euler_eom(robot, simplify=simplify, parameters=parameters, with_steps=steps, form=form)
    else:
        raise ValueError(f"method must be 'lagrange' or 'newton_euler', got {method!r}")
    eom.notes = notes
    if robot.loops:
        return closed_loop_equations(eom, robot, independent=independent, solution=solution, steps=steps)
    return eom
