"""``kinedyn report``: one self-contained HTML file about a robot that opens offline.

Sections: the joint and DH tables; an interactive 3-D view (the robot's meshes, or solid links, lit,
drawn by plotly.js inlined from the plotly package; assets/viewer.js runs the same forward kinematics
as kinedyn.Robot, so the joint sliders and the simulation's playback move the meshes); the tool pose, Jacobian and singular values;
the equations of motion typeset as MathML from the symbolic engine; the properties check (M symmetric
positive definite, dM/dt - 2C skew and dM/dt = C + C^T by finite differences, the regressor reproduces
tau, RNEA = M qdd + C qd + g); and plots (inline SVG) of a short free motion under gravity with its
energy. Every script and style is inlined; nothing is fetched. All numbers shown are also in the JSON
block ``#kinedyn-data`` (and ``kinedyn report --json``).

Robots with floating, spherical and planar joints: q (nq entries) is shown joint block by joint block
(position, unit quaternion x y z w; planar x, y, cos θ, sin θ), velocities, M, J and g per degree of
freedom (nv), dM/dt along q ⊕ t qd; the viewer moves each block, and what does not apply (sliders for
rotations, equations of a large robot) says so on the page.
"""

from __future__ import annotations

import html
import json
import math
import re
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["default_configuration", "collect", "build_report", "write_report", "latex_to_mathml", "svg_plot"]


# ------------------------------------------------------------------ data
def default_configuration(robot) -> np.ndarray:
    """A generic (non-singular) configuration: 0.5, -0.7, 0.5, -0.7, ... rad (m for prismatic joints,
    x 0.2), clipped to the joint limits."""
    q, start = robot.neutral(), 0
    for i, j in enumerate(robot.joints):
        if not j.is_multi_dof:  # a multi-DOF joint keeps its neutral block (identity rotation)
            q[start] = (0.5 if i % 2 == 0 else -0.7) * (1.0 if j.kind == "revolute" else 0.2)
        start += j.nq
    return np.clip(q, robot.lower_limits, robot.upper_limits)


#: the names of a joint's entries of q and of qd (docs/conventions.md, "Configurations and velocities")
Q_ENTRIES = {
    "floating": ("x", "y", "z", "qx", "qy", "qz", "qw"),
    "spherical": ("qx", "qy", "qz", "qw"),
    "planar": ("x", "y", "cos θ", "sin θ"),
}
V_ENTRIES = {
    "floating": ("vx", "vy", "vz", "ωx", "ωy", "ωz"),
    "spherical": ("ωx", "ωy", "ωz"),
    "planar": ("vx", "vy", "ω"),
}


def coordinate_labels(robot) -> list[str]:
    """One label per entry of q (nq): a 1-DOF joint's name, ``joint.x`` ... ``joint.qw`` for a
    multi-DOF joint's block."""
    return [
        label
        for j in robot.joints
        for label in ([f"{j.name}.{e}" for e in Q_ENTRIES[j.kind]] if j.is_multi_dof else [j.name])
    ]


def velocity_labels(robot) -> list[str]:
    """One label per degree of freedom (nv: entries of qd, rows and columns of M, columns of J): a
    1-DOF joint's name, ``joint.vx`` ... ``joint.ωz`` for a multi-DOF joint (velocities in its child's frame)."""
    return [
        label
        for j in robot.joints
        for label in ([f"{j.name}.{e}" for e in V_ENTRIES[j.kind]] if j.is_multi_dof else [j.name])
    ]


def _coordinate_units(robot) -> list[str]:
    """Per entry of q: "rad", "m", or "" (a quaternion's or a (cos θ, sin θ) pair's entries)."""
    out: list[str] = []
    for j in robot.joints:
        if j.kind == "floating":
            out += ["m"] * 3 + [""] * 4
        elif j.kind == "spherical":
            out += [""] * 4
        elif j.kind == "planar":
            out += ["m"] * 2 + [""] * 2
        else:
            out.append("rad" if j.kind == "revolute" else "m")
    return out


def _in_multi_dof_block(robot) -> list[bool]:
    """Per entry of q: whether it belongs to a multi-DOF joint's block."""
    return [j.is_multi_dof for j in robot.joints for _ in range(j.nq)]


def _q_text(q, labels: Sequence[str], units: Sequence[str], named: Sequence[bool]) -> str:
    """q as the report writes it: "0.5 rad (28.6°), 0.2 m" for 1-DOF joints; the entries of a
    multi-DOF joint's block are named ("root_joint.z = 0.3 m, root_joint.qw = 1")."""
    parts = []
    for v, label, unit, name in zip(q, labels, units, named):
        value = (
            f"{_f(v)} rad ({_f(math.degrees(v), 5)}°)" if unit == "rad" else (f"{_f(v)} m" if unit == "m" else _f(v))
        )
        parts.append(f"{label} = {value}" if name else value)
    return ", ".join(parts)


def _has_dynamics(robot) -> bool:
    """Whether this build of kinedyn has the numeric dynamics (the native core's mass matrix)."""
    try:
        robot.mass_matrix(robot.neutral())
        return True
    except (AttributeError, NotImplementedError):
        return False


def _model_for_view(robot, q, geometry: str = "visual", budget: int | None = None) -> dict:
    """What the inline viewer needs to run the forward kinematics itself and draw the meshes (each
    once, in its frame's coordinates: kinedyn.visual.web)."""
    import warnings

    from ..visual.scene import DEFAULT_BUDGET, MissingMeshWarning, robot_scene, scene_bounds
    from ..visual.web import encode_scene

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MissingMeshWarning)  # said in the report instead (model["missing"])
        scene = robot_scene(robot, geometry, DEFAULT_BUDGET if budget is None else budget)
    from ..description.joint import planar_basis as _planar_basis

    tree = robot.tree
    # where each joint's block starts in q: a multi-DOF joint's q[start:start + nq] moves its body as a
    # whole (viewer.js: position, then a unit quaternion; planar x, y, cos, sin)
    starts, start = {}, 0
    for j in robot.joints:
        starts[j.name] = start
        start += j.nq
    bodies = []
    for b in tree.bodies:
        body = {
            "parent": int(b.parent),
            "name": b.joint.name,
            "kind": b.joint.kind,
            "axis": [float(a) for a in b.joint.axis],
            "offset": float(b.joint.offset),
            "placement": np.asarray(b.placement, dtype=float).ravel().tolist(),
        }
        if b.joint.name in starts:
            body["q"] = starts[b.joint.name]
        if b.joint.kind == "planar":  # the plane's in-plane axes (x along e1, y along e2; the rotation about e1 x e2)
            e1, e2 = _planar_basis(np.asarray(b.joint.axis, dtype=float))
            body["e1"], body["e2"] = e1.tolist(), e2.tolist()
        bodies.append(body)
    if robot.mimic_joints:  # each body's coordinate: q[q] for its own, scale * q[q] + shift for a mimic follower
        from ..description.mimic import body_coordinates

        names = robot.joint_names
        for body, coordinate in zip(bodies, body_coordinates(robot)):
            body.update(coordinate)
            body["q"] = starts[names[coordinate["q"]]]  # body_coordinates numbers the joints; q numbers their entries
    # a slider per 1-DOF coordinate and per position entry of a floating or planar joint (a rotation
    # has none: it is shown at q and moves in the playback)
    labels, units = coordinate_labels(robot), _coordinate_units(robot)
    sliders = []
    for k, (label, unit, lo, hi) in enumerate(zip(labels, units, robot.lower_limits, robot.upper_limits)):
        if unit:
            sliders.append(
                {
                    "name": label,
                    "q": k,
                    "revolute": unit == "rad",
                    "lower": float(lo) if math.isfinite(lo) else None,
                    "upper": float(hi) if math.isfinite(hi) else None,
                }
            )
    frames = [
        {"name": f.name, "body": int(f.body), "placement": np.asarray(f.placement, dtype=float).ravel().tolist()}
        for f in tree.frames
    ]
    # size of the scene: the farthest frame origin over q and a few random configurations
    qs = np.vstack([q, robot.random_configuration(np.random.default_rng(1), size=64)])
    origins = np.vstack([np.zeros((1, 3)), robot.frame_poses(qs)[..., :3, 3].reshape(-1, 3)])
    reach = max(float(np.max(np.linalg.norm(origins, axis=-1))), 1e-3)
    # the cube the view shows: around every frame origin of those configurations, with a margin for the meshes
    lo, hi = origins.min(axis=0), origins.max(axis=0)
    half = float(np.max(hi - lo)) / 2 + 0.12 * reach
    # the camera looks at the robot as it stands at q: the box of its shapes (and frame origins)
    focus_lo, focus_hi = scene_bounds(robot, scene, q)
    gravity = np.asarray(robot.gravity, dtype=float)
    up = -gravity / np.linalg.norm(gravity) if np.linalg.norm(gravity) > 0 else np.array([0.0, 0.0, 1.0])
    axes = np.array([np.asarray(robot.pose(q, name)[:3, 2]) for name in robot.body_names])
    planar = (
        all(j.kind == "revolute" for j in robot.joints)
        and np.allclose(np.abs(axes @ axes[0]), 1.0, atol=1e-9)
        and abs(axes[0] @ up) < 1e-9
    )
    if planar:  # look along the common joint axis: the arm is drawn as in the textbook's figure
        view_from = axes[0]
    else:  # an isometric view from the front-right, above the base
        side = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
        side /= np.linalg.norm(side)
        front = np.cross(side, up)
        view_from = 0.8 * front - 0.6 * side + 0.45 * up
    return {
        "bodies": bodies,
        "frames": frames,
        "joint_names": robot.joint_names,
        "joint_kinds": [j.kind for j in robot.joints],
        "coordinate_labels": labels,
        "coordinate_units": units,
        "coordinate_named": _in_multi_dof_block(robot),
        "sliders": sliders,
        "lower": [float(x) if math.isfinite(x) else None for x in robot.lower_limits],
        "upper": [float(x) if math.isfinite(x) else None for x in robot.upper_limits],
        "q": [float(x) for x in q],
        "tool": robot.tool,
        "reach": reach,
        "center": ((lo + hi) / 2).tolist(),
        "half": half,
        "focus": {"center": ((focus_lo + focus_hi) / 2).tolist(), "size": float(np.linalg.norm(focus_hi - focus_lo))},
        "up": up.tolist(),
        "view_from": np.asarray(view_from, dtype=float).tolist(),
        "planar": bool(planar),  # drawn as the textbook's figure: orthographic, along the joint axes
        "meshes": encode_scene(scene),
        "geometry": geometry,
        "shapes": scene.shapes,  # visuals described
        "shapes_drawn": scene.drawn,  # of those, read and drawn (the rest are in "missing")
        "missing": scene.missing,
        "generated": scene.generated,  # solid links made from the kinematics (no visuals described)
        "label_joints": scene.generated and robot.n <= 8,
    }


#: Wall-clock seconds the report's free-motion simulation may take (the rest of a report takes a few
#: seconds at most; the symbolic equations are derived only for small arms, see ``eom_joints``).
SIMULATION_BUDGET = 30.0


def _simulate(
    robot,
    q0,
    qd0,
    t_end: float,
    samples: int = 241,
    time_budget: float | None = SIMULATION_BUDGET,
    progress: bool | None = False,
) -> dict[str, Any]:
    """Free motion (tau = 0) from (q0, qd0) with kd.simulate (method "auto": RK4, or implicit Euler
    for a stiff robot), about ``samples`` samples kept, bounded by ``time_budget`` wall-clock seconds.
    A run cut short (the budget, or a blow-up) keeps its samples and says why in "note"."""
    import warnings

    from ..simulate import SimulationError, SimulationTruncatedWarning, simulate

    dt = 1e-3
    steps = max(1, int(math.ceil(t_end / dt - 1e-9)))
    every = max(1, steps // max(samples - 1, 1))
    x0 = np.concatenate([q0, qd0])
    note = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SimulationTruncatedWarning)  # said in the report instead
            traj = simulate(
                robot, (0.0, t_end), x0, dt=dt, record_every=every, time_budget=time_budget, progress=progress
            )
        if traj.info.get("truncated"):
            note = f"The simulation was cut short: {traj.info['truncated']}."
    except SimulationError as e:
        traj = e.trajectory
        note = f"The simulation stopped early: {e}"
    info = traj.info
    how = f"kd.simulate(robot, (0, T), x0, dt = {dt:g} s): {info.get('method_choice') or traj.method}"
    t, q, qd = np.asarray(traj.t), np.asarray(traj.q), np.asarray(traj.qd)
    K = np.asarray(robot.kinetic_energy(q, qd), dtype=float)
    P = np.asarray(robot.potential_energy(q), dtype=float)
    return {
        "t": t,
        "q": q,
        "qd": qd,
        "K": K,
        "P": P,
        "H": K + P,
        "method": how,
        "integrator": traj.method,
        "t_end_requested": float(t_end),
        "note": note,
        "wall_time": float(info.get("wall_time", 0.0)),
    }


def _properties(robot, q, qd, rng) -> list[dict]:
    """The textbook's properties at (q, qd), each with its measured residual."""
    out = []
    n = robot.n
    M = robot.mass_matrix(q)
    eig = np.linalg.eigvalsh((M + M.T) / 2)
    scale = max(1.0, float(np.max(np.abs(M))))
    asym = float(np.max(np.abs(M - M.T)))
    out.append({"property": "M(q) symmetric", "measure": "max |M - M^T|", "value": asym, "ok": asym <= 1e-12 * scale})
    out.append(
        {
            "property": "M(q) positive definite",
            "measure": "smallest eigenvalue of M",
            "value": float(eig[0]),
            "ok": bool(eig[0] > 0),
        }
    )
    from ..analysis.properties import mass_matrix_rate

    Mdot = mass_matrix_rate(robot, q, qd)  # along q ⊕ t qd: quaternions turned by Exp, not added to
    C = robot.coriolis_matrix(q, qd)
    N = Mdot - 2 * C
    tol = 1e-6 * max(1.0, float(np.max(np.abs(Mdot))), float(np.max(np.abs(C))))
    skew = float(np.max(np.abs(N + N.T)))
    how = "max |N + N^T|, dM/dt by central differences" + (" along q ⊕ t q̇" if robot.has_multi_dof_joints else "")
    out.append({"property": "dM/dt - 2C skew-symmetric", "measure": how, "value": skew, "ok": skew <= tol})
    cct = float(np.max(np.abs(Mdot - C - C.T)))
    out.append({"property": "dM/dt = C + C^T", "measure": "max |dM/dt - C - C^T|", "value": cct, "ok": cct <= tol})
    qdd = rng.uniform(-1, 1, n)
    tau = robot.inverse_dynamics(q, qd, qdd)
    lhs = M @ qdd + C @ qd + robot.gravity_torque(q)
    friction = any(float(j.viscous) or float(j.coulomb) for j in robot.joints)
    if not friction:
        r = float(np.max(np.abs(tau - lhs)))
        out.append(
            {
                "property": "RNEA = M qdd + C qd + g",
                "measure": "max |tau_RNEA - (M qdd + C qd + g)| at a random qdd",
                "value": r,
                "ok": r <= 1e-9 * max(1.0, float(np.max(np.abs(tau)))),
            }
        )
    rotor = any(float(j.rotor_inertia) for j in robot.joints)
    if hasattr(robot, "regressor") and not friction and not rotor:
        Y = robot.regressor(q, qd, qdd)
        r = float(np.max(np.abs(Y @ robot.inertial_parameters() - tau)))
        out.append(
            {
                "property": "linear in the parameters",
                "measure": "max |Y(q, qd, qdd) pi - tau|",
                "value": r,
                "ok": r <= 1e-9 * max(1.0, float(np.max(np.abs(tau)))),
            }
        )
    return out


def _symbolic_eom(robot, name: str | None, max_joints: int):
    """The equations of motion to typeset: of the built-in arm with its parameters as symbols where the
    catalogue offers that, else of the robot as given. None (with the reason) for large arms."""
    if robot.n > max_joints:
        return (
            None,
            f"The symbolic equations of motion are typeset for arms with up to {max_joints} joints (this one has {robot.n}); `kinedyn report --eom-joints {robot.n}` derives them anyway.",
        )
    from .. import robots

    subject = robot
    if name in robots.CATALOGUE:
        try:
            subject = robots.get(name, symbolic=True)
        except (TypeError, ValueError, AttributeError):
            subject = robot
    if not hasattr(subject, "equations_of_motion"):
        return None, "This kinedyn has no symbolic engine."
    try:
        # above 3 joints the results are shown in CSE form (kinedyn.symbolic.cse): readable, and seconds
        eom = subject.equations_of_motion(form="cse" if subject.n > 3 else "auto")
    except ImportError:
        return None, "This kinedyn has no symbolic engine."
    return eom, ("with the catalogue's parameters as symbols" if subject is not robot else "with this robot's numbers")


def _joint_rows(robot) -> list[dict]:
    """The joints table's data: kind, axis, offset, limits, and where the joint's entries sit in q and qd."""
    rows, iq, iv = [], 0, 0
    for j in robot.joints:
        row = {
            "name": j.name,
            "type": j.kind,
            "axis": [float(a) for a in j.axis],
            "offset": float(j.offset),
            "lower": float(j.lower),
            "upper": float(j.upper),
            "q_index": iq,
            "nq": j.nq,
            "v_index": iv,
            "nv": j.nv,
        }
        if j.is_multi_dof:
            row["q_entries"], row["v_entries"] = list(Q_ENTRIES[j.kind]), list(V_ENTRIES[j.kind])
        rows.append(row)
        iq, iv = iq + j.nq, iv + j.nv
    return rows


def collect(
    robot,
    q=None,
    qd=None,
    *,
    name: str | None = None,
    t_end: float = 3.0,
    eom_joints: int = 3,
    seed: int = 0,
    time_budget: float | None = SIMULATION_BUDGET,
    progress: bool | None = False,
    steps=None,
) -> dict:
    """Every number of the report (JSON-friendly, plus the symbolic equations under "_eom").
    ``time_budget``: wall-clock seconds for the simulation (None: unbounded); ``progress``: a progress
    bar on stderr (None: on a terminal); ``steps``: a :class:`kinedyn.progress.Steps` to advance."""
    from ..progress import Steps

    own = steps is None
    steps = Steps("report", 4, progress) if own else steps
    try:
        return _collect(robot, q, qd, name, t_end, eom_joints, seed, time_budget, progress, steps)
    finally:
        if own:
            steps.close()


def _collect(robot, q, qd, name, t_end, eom_joints, seed, time_budget, progress, steps) -> dict:
    from ..kinematics import singularity_report

    steps.step("kinematics")
    q = default_configuration(robot) if q is None else np.asarray(q, dtype=float)
    qd = np.zeros(robot.nv) if qd is None else np.asarray(qd, dtype=float)
    if q.shape != (robot.nq,) or qd.shape != (robot.nv,):
        sizes = (
            f"q needs {robot.nq} values and qd {robot.nv}"
            if robot.has_multi_dof_joints
            else f"q and qd need {robot.n} values"
        )
        raise ValueError(f"{sizes} for robot '{robot.name}', got q of shape {q.shape} and qd of shape {qd.shape}")
    if robot.has_multi_dof_joints:
        robot.integrate(
            q, qd, 0.0
        )  # a ValueError naming the joint for a quaternion or (cos, sin) pair that is not unit
    rng = np.random.default_rng(seed)
    T = robot.pose(q)
    J = robot.jacobian(q)
    rep = singularity_report(robot, q)
    data: dict = {
        "robot": robot.name,
        "source": robot.source,
        "n": robot.n,
        "nq": robot.nq,
        "nv": robot.nv,
        "joint_names": robot.joint_names,
        "coordinate_labels": coordinate_labels(robot),
        "velocity_labels": velocity_labels(robot),
        "gravity": [float(x) for x in robot.gravity],
        "q": q.tolist(),
        "qd": qd.tolist(),
        "tool": robot.tool,
        "tool_pose": T.tolist(),
        "jacobian": J.tolist(),
        "singular_values": rep.singular_values.tolist(),
        "rank": rep.rank,
        "singular": rep.singular,
        "condition_number": rep.condition_number,
        "singularity": rep.summary(),
        "joints": _joint_rows(robot),
        "dh_convention": robot.dh_convention,
        "dh": None
        if robot.dh is None
        else [
            {"theta": float(r.theta), "d": float(r.d), "a": float(r.a), "alpha": float(r.alpha), "type": r.kind}
            for r in robot.dh
        ],
        "bodies": [
            {"link": b.name, "mass": float(b.inertia.mass), "com": [float(c) for c in b.inertia.com]}
            for b in robot.tree.bodies
        ],
    }
    data["dynamics"] = _has_dynamics(robot)
    steps.step("dynamics and properties")
    if data["dynamics"]:
        qd_check = qd if np.any(qd) else rng.uniform(-1, 1, robot.n)
        data["mass_matrix"] = robot.mass_matrix(q).tolist()
        data["mass_matrix_eigenvalues"] = np.linalg.eigvalsh(robot.mass_matrix(q)).tolist()
        data["gravity_torque"] = robot.gravity_torque(q).tolist()
        data["properties_qd"] = qd_check.tolist()
        data["properties"] = _properties(robot, q, qd_check, rng)
        steps.step("simulation")
        sim = _simulate(robot, q, qd, t_end, time_budget=time_budget, progress=progress)
        data["simulation"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in sim.items()}
        H = sim["H"]
        data["simulation"]["energy_drift"] = float(np.max(np.abs(H - H[0])))
        friction = any(float(j.viscous) or float(j.coulomb) for j in robot.joints)
        # energy is a property check only where the integrator conserves it (RK4; implicit Euler damps)
        if sim["integrator"] == "rk4" and not sim["note"]:
            data["properties"].append(
                {
                    "property": "energy conserved (tau = 0, no friction)",
                    "measure": f"max |H(t) - H(0)| over the {t_end:g} s simulation",
                    "value": data["simulation"]["energy_drift"],
                    "ok": data["simulation"]["energy_drift"] <= 1e-6 * max(1.0, float(np.max(np.abs(H)))) or friction,
                }
            )
    steps.step("equations of motion")
    if robot.has_multi_dof_joints and robot.n > eom_joints:
        eom, note = (
            None,
            (
                f"The symbolic equations of motion are typeset for up to {eom_joints} degrees of freedom (this robot has {robot.n}, "
                f"its multi-DOF joints included); `kinedyn report --eom-joints {robot.n}` derives them anyway, with each multi-DOF "
                "joint in position and ZYX Euler angles (docs/floating-base.md)."
            ),
        )
    else:
        eom, note = _symbolic_eom(robot, name, eom_joints)
        if eom is not None and robot.has_multi_dof_joints:
            note += (
                f"; in the coordinates ({', '.join(map(str, eom.q))}): each multi-DOF joint in position and ZYX Euler angles "
                "(R = Rz(yaw) Ry(pitch) Rx(roll)), the symbolic engine's minimal coordinates, not the numeric q (quaternions) and "
                "q̇ above (docs/floating-base.md)"
            )
    data["_eom"] = eom
    data["eom_note"] = note
    return data


# ------------------------------------------------------------------ MathML
# equations come from the symbolic engine's own MathML (EquationsOfMotion.equation_mathml: SymPy's
# presentation printer, names built as MathML); latex_to_mathml stays importable from here
from ..symbolic.render import latex_to_mathml  # noqa: E402


def _equation(eom, lhs, value) -> str:
    m = eom.equation_mathml(lhs, value)
    # matrices: brackets drawn by CSS (class bm), which needs no stretchy glyphs in the reader's fonts
    m = re.sub(r"<mrow><mo>\[</mo><mtable>(.*?)</mtable><mo>\]</mo></mrow>", r'<mtable class="bm">\1</mtable>', m)
    return f'<div class="eq">{m}</div>'


# ------------------------------------------------------------------ SVG plots
_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"]


def _ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    if hi - lo <= 0:
        return [lo]
    raw = (hi - lo) / n
    mag = 10 ** math.floor(math.log10(raw))
    step = min((m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw), default=raw)
    start = math.ceil(lo / step) * step
    return [start + k * step for k in range(int((hi - start) / step + 1e-9) + 1)]


_DASHES = ["", "6 3", "2 2", "8 3 2 3"]  # after the colours run out: the same colours dashed


def _legend_rows(labels: Sequence[str], width: float, left: float, right: float) -> list[list[tuple]]:
    """Legend entries laid out in rows that fit between ``left`` and ``width - right``: each entry is
    (x, label), 26 px of line sample and gap plus ~6.6 px per character of 11-px text, 14 px apart."""
    rows: list[list[tuple]] = [[]]
    x = left + 4
    for label in labels:
        w = 26 + 6.6 * len(label)
        if rows[-1] and x + w > width - right:
            rows.append([])
            x = left + 4
        rows[-1].append((x, label))
        x += w + 14
    return rows


def svg_plot(
    x, series: Sequence[tuple], title: str, xlabel: str, ylabel: str, width: int = 520, height: int = 270
) -> str:
    """A line plot as inline SVG: ``series`` = [(label, y), ...]. The legend names every series, in as
    many rows as it needs (the plot grows taller to keep its area); colours repeat dashed after seven."""
    x = np.asarray(x, dtype=float)
    ys = [np.asarray(y, dtype=float) for _, y in series]
    ylo = min(float(np.min(y)) for y in ys)
    yhi = max(float(np.max(y)) for y in ys)
    if yhi - ylo < 1e-9 * max(1.0, abs(yhi)):
        ylo, yhi = ylo - 1.0, yhi + 1.0
    pad = 0.06 * (yhi - ylo)
    ylo, yhi = ylo - pad, yhi + pad
    L, R, B = 62, 14, 44
    legend = _legend_rows([str(label) for label, _ in series], width, L, R)
    Tp = 32 + 14 * len(legend)
    height += Tp - 46
    W, H = width - L - R, height - Tp - B
    px = lambda v: L + W * (v - x[0]) / (x[-1] - x[0] if x[-1] > x[0] else 1.0)
    py = lambda v: Tp + H * (1 - (v - ylo) / (yhi - ylo))
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" role="img" aria-label="{html.escape(title)}">',
        f'<text x="{width / 2}" y="18" text-anchor="middle" font-size="13" font-weight="600" fill="#243238">{html.escape(title)}</text>',
    ]
    for v in _ticks(ylo, yhi):
        out.append(f'<line x1="{L}" x2="{L + W}" y1="{py(v):.1f}" y2="{py(v):.1f}" stroke="#eceee9"/>')
        out.append(
            f'<text x="{L - 6}" y="{py(v) + 4:.1f}" text-anchor="end" font-size="11" fill="#5f6b73">{v:.4g}</text>'
        )
    for v in _ticks(float(x[0]), float(x[-1])):
        out.append(f'<line y1="{Tp}" y2="{Tp + H}" x1="{px(v):.1f}" x2="{px(v):.1f}" stroke="#f1f2ee"/>')
        out.append(
            f'<text y="{Tp + H + 16}" x="{px(v):.1f}" text-anchor="middle" font-size="11" fill="#5f6b73">{v:.4g}</text>'
        )
    out.append(f'<rect x="{L}" y="{Tp}" width="{W}" height="{H}" fill="none" stroke="#9aa5aa"/>')
    places = [(32 + 14 * r, x0) for r, row in enumerate(legend) for x0, _ in row]
    for k, ((label, _), y, (ly, lx)) in enumerate(zip(series, ys, places)):
        pts = " ".join(f"{px(a):.1f},{py(b):.1f}" for a, b in zip(x, y))
        c = _COLOURS[k % len(_COLOURS)]
        dash = _DASHES[(k // len(_COLOURS)) % len(_DASHES)]
        dash_attr = f' stroke-dasharray="{dash}"' if dash else ""
        out.append(f'<polyline points="{pts}" fill="none" stroke="{c}" stroke-width="1.8"{dash_attr}/>')
        out.append(
            f'<line x1="{lx:.1f}" x2="{lx + 18:.1f}" y1="{ly - 4}" y2="{ly - 4}" stroke="{c}" stroke-width="2.5"{dash_attr}/>'
            f'<text x="{lx + 22:.1f}" y="{ly}" font-size="11" fill="#243238">{html.escape(label)}</text>'
        )
    out.append(
        f'<text x="{L + W / 2}" y="{height - 8}" text-anchor="middle" font-size="12" fill="#36454c">{html.escape(xlabel)}</text>'
    )
    out.append(
        f'<text transform="translate(14 {Tp + H / 2}) rotate(-90)" text-anchor="middle" font-size="12" fill="#36454c">{html.escape(ylabel)}</text>'
    )
    out.append("</svg>")
    return "".join(out)


# ------------------------------------------------------------------ HTML
def _f(v, digits: int = 6) -> str:
    v = float(v)
    if math.isinf(v):
        return "∞" if v > 0 else "-∞"
    if abs(v) < 1e-13:
        v = 0.0
    return f"{v:.{digits}g}"


def _table(headers: Sequence[str], rows: Sequence[Sequence], numeric_from: int = 1, cls: str = "") -> str:
    h = "".join(f"<th>{html.escape(str(c))}</th>" for c in headers)
    body = []
    for r in rows:
        cells = []
        for k, c in enumerate(r):
            css = ' class="num"' if k >= numeric_from else ""
            cells.append(f"<td{css}>{c if isinstance(c, _Raw) else html.escape(str(c))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    # a box that scrolls when the table is wider than its card (a 44-joint Jacobian), and taller than
    # about a screen for a long one (the Talos joint table); its first column and header stay in view
    tall = " tall" if len(rows) > 16 else ""
    return f'<div class="table-box{tall}"><table class="{cls}"><thead><tr>{h}</tr></thead><tbody>{"".join(body)}</tbody></table></div>'


class _Raw(str):
    """Table cell HTML that is not escaped."""


def _matrix_table(M, rows: Sequence[str], cols: Sequence[str], cls: str) -> str:
    values = np.atleast_2d(M)
    if not any(rows) and not any(cols):  # a bare matrix (the tool pose): no label column or header row to take room
        body = "".join("<tr>" + "".join(f'<td class="num">{_f(v)}</td>' for v in row) + "</tr>" for row in values)
        return f'<div class="table-box"><table class="{cls} bare"><tbody>{body}</tbody></table></div>'
    return _table(["", *cols], [[r, *(_f(v) for v in row)] for r, row in zip(rows, values)], cls=cls)


def _asset(name: str) -> str:
    # one step per joinpath: Python 3.10's Traversable.joinpath takes a single name
    return resources.files("kinedyn.report").joinpath("assets").joinpath(name).read_text(encoding="utf-8")


# Characters that may not appear raw in JSON embedded in a <script> element, with their JSON escapes.
# Inside a script element the HTML tokenizer looks for "</script" and also enters its "escaped" states
# on "<!--" (after which "<script" makes it ignore the next "</script>": the rest of the page becomes
# script text), so no "<" may reach it; ">" and "&" are escaped too so that the text means the same in
# an XHTML/XML parser, and U+2028/U+2029 because they end a line in JavaScript before ES2019
# (HTML Standard 4.12.1.3 "Restrictions for contents of script elements"; the same set as Django's
# json_script and Go's html/template).
_SCRIPT_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}
_SCRIPT_UNSAFE = re.compile("[<>&\u2028\u2029]")


def script_json(obj) -> str:
    """``obj`` as JSON text that is safe as the content of an HTML ``<script>`` element, whatever
    strings it holds: the characters above become JSON's ``\\uXXXX`` escapes (valid only inside JSON
    strings, which is the only place JSON text can hold them), so ``JSON.parse`` returns ``obj``."""
    text = json.dumps(obj, allow_nan=False)
    return _SCRIPT_UNSAFE.sub(lambda m: _SCRIPT_ESCAPES[m.group(0)], text)


def _json_script(obj, element_id: str) -> str:
    """A ``<script type="application/json">`` block holding ``obj`` (read back by viewer.js)."""
    return f'<script type="application/json" id="{html.escape(element_id)}">{script_json(obj)}</script>'


def _configuration_table(robot, q, d) -> str:
    """Per joint: its block of q (named entries; a rotation also as angle and axis) and the names of its
    velocities, with why the sliders leave rotations out."""
    from ..configuration import log3

    rows = []
    for j in d["joints"]:
        block = np.asarray(q[j["q_index"] : j["q_index"] + j["nq"]], dtype=float)
        names = j.get("q_entries") or [j["name"]]
        values = ", ".join(f"{n} = {_f(v)}" for n, v in zip(names, block)) if j["nq"] > 1 else _f(block[0])
        if j["type"] in ("floating", "spherical"):
            r = log3(block[-4:])
            angle = float(np.linalg.norm(r))
            axis = r / angle if angle > 0 else np.array([0.0, 0.0, 1.0])
            values += f" (a rotation of {_f(math.degrees(angle), 5)}° about ({', '.join(_f(a, 4) for a in axis)}))"
        elif j["type"] == "planar":
            values += f" (θ = {_f(math.degrees(math.atan2(block[3], block[2])), 5)}°)"
        velocities = ", ".join(j.get("v_entries") or [j["name"]])
        rows.append([j["name"], j["type"], values, velocities])
    rotations = [j["name"] for j in d["joints"] if j["type"] in ("floating", "spherical", "planar")]
    return (
        "<h3>Configuration by joint</h3>"
        + _table(["joint", "type", "q", "q̇ entries"], rows, numeric_from=2, cls="configuration")
        + f"<p class='note' id='sliders-note'>The sliders move the 1-DOF joints and the positions of the floating and planar joints; "
        f"the rotations of {', '.join(html.escape(n) for n in rotations)} have no slider (a unit quaternion or angle is no single "
        "coordinate): they are drawn at q and move in the simulation's playback.</p>"
    )


def _motion_plots(robot, t, qs, labels) -> list[str]:
    """The simulated coordinates: the 1-DOF joints' in one plot; with multi-DOF joints, their positions
    (m) and their unit quaternions / (cos θ, sin θ) pairs in two more."""
    units, named = _coordinate_units(robot), _in_multi_dof_block(robot)
    if not any(named):
        return [
            svg_plot(t, [(nm, qs[:, k]) for k, nm in enumerate(labels)], "joint positions", "t [s]", "q [rad or m]")
        ]
    plots = []
    joints = [k for k, m in enumerate(named) if not m]
    if joints:
        plots.append(svg_plot(t, [(labels[k], qs[:, k]) for k in joints], "joint positions", "t [s]", "q [rad or m]"))
    positions = [k for k, (m, u) in enumerate(zip(named, units)) if m and u == "m"]
    if positions:
        plots.append(
            svg_plot(
                t,
                [(labels[k], qs[:, k]) for k in positions],
                "positions of the multi-DOF joints",
                "t [s]",
                "position [m]",
            )
        )
    rotations = [k for k, (m, u) in enumerate(zip(named, units)) if m and not u]
    plots.append(
        svg_plot(
            t,
            [(labels[k], qs[:, k]) for k in rotations],
            "orientations of the multi-DOF joints",
            "t [s]",
            "quaternion (x, y, z, w) or (cos θ, sin θ)",
        )
    )
    return plots


def build_report(
    robot,
    q=None,
    qd=None,
    *,
    name: str | None = None,
    t_end: float = 3.0,
    eom_joints: int = 3,
    data: dict | None = None,
    tutorial: bool = False,
    progress: bool | None = False,
    time_budget: float | None = SIMULATION_BUDGET,
    geometry: str = "visual",
) -> str:
    """The report as one HTML string (see the module docstring); ``tutorial``: add the seed
    tutorial's questions worked step by step (its arm is the default robot, planar_2r).
    ``geometry``: the 3-D view draws the "visual" shapes of the description, or the "collision" ones.
    ``progress``: a progress bar of the steps on stderr (None: on a terminal)."""
    from ..progress import Steps

    total = (0 if data is not None else 4) + 2 + (len(_tutorial_questions()) if tutorial else 0)
    with Steps("report", total, progress) as steps:
        return _build_report(
            robot, q, qd, name, t_end, eom_joints, data, tutorial, progress, time_budget, steps, geometry
        )


def _tutorial_questions():
    from .tutorial import QUESTIONS

    return QUESTIONS


def _build_report(
    robot, q, qd, name, t_end, eom_joints, data, tutorial, progress, time_budget, bar, geometry="visual"
) -> str:
    import kinedyn

    from ..cli import _jsonable
    from ..visual.web import plotly_script

    d = (
        data
        if data is not None
        else collect(
            robot,
            q,
            qd,
            name=name,
            t_end=t_end,
            eom_joints=eom_joints,
            time_budget=time_budget,
            progress=progress,
            steps=bar,
        )
    )
    bar.step("3-D view and tables")
    q = np.asarray(d["q"])
    eom = d.pop("_eom", None)
    multi = robot.has_multi_dof_joints
    q_labels, v_labels = (
        d.get("coordinate_labels") or coordinate_labels(robot),
        d.get("velocity_labels") or velocity_labels(robot),
    )
    q_text = _q_text(q, q_labels, _coordinate_units(robot), _in_multi_dof_block(robot))

    # --- description
    if multi:  # where each joint sits in q and qd; a multi-DOF joint has no single axis, offset or limits
        rows = []
        for j in d["joints"]:
            q_block = (
                f"q[{j['q_index']}]"
                if j["nq"] == 1
                else f"q[{j['q_index']}:{j['q_index'] + j['nq']}] = ({', '.join(j['q_entries'])})"
            )
            v_block = (
                f"q̇[{j['v_index']}]"
                if j["nv"] == 1
                else f"q̇[{j['v_index']}:{j['v_index'] + j['nv']}] = ({', '.join(j['v_entries'])})"
            )
            if j["type"] in ("floating", "spherical"):
                axis_offset_limits = ["—", "—", "—"]
            elif j["type"] == "planar":
                axis_offset_limits = ["normal " + " ".join(_f(a) for a in j["axis"]), "—", "—"]
            else:
                axis_offset_limits = [
                    " ".join(_f(a) for a in j["axis"]),
                    _f(j["offset"]),
                    f"[{_f(j['lower'])}, {_f(j['upper'])}]",
                ]
            rows.append([j["name"], j["type"], *axis_offset_limits, q_block, v_block])
        sec = [
            "<section id='description'><h2>Joints and links</h2>",
            _table(["joint", "type", "axis", "offset", "limits", "in q", "in q̇"], rows, numeric_from=2, cls="joints"),
            f"<p class='note' id='multi-dof-note'>q has nq = {d['nq']} entries and q̇ nv = {d['nv']}: a floating joint's block is its position "
            "then a unit quaternion (x, y, z, w), a spherical joint's a unit quaternion, a planar joint's (x, y, cos θ, sin θ); their "
            "velocities are in the child's frame, [linear; angular] (Pinocchio's conventions, docs/conventions.md).</p>",
        ]
    else:
        rows = [
            [
                j["name"],
                j["type"],
                " ".join(_f(a) for a in j["axis"]),
                _f(j["offset"]),
                f"[{_f(j['lower'])}, {_f(j['upper'])}]",
            ]
            for j in d["joints"]
        ]
        sec = [
            "<section id='description'><h2>Joints and links</h2>",
            _table(["joint", "type", "axis", "offset", "limits"], rows, numeric_from=2, cls="joints"),
        ]
    if d["dh"] is not None:
        dh_rows = []
        for i, r in enumerate(d["dh"], 1):
            rev = r["type"] == "revolute"
            dh_rows.append(
                [
                    str(i),
                    f"q{i}" + (f" + {_f(r['theta'])}" if r["theta"] else "") if rev else _f(r["theta"]),
                    _f(r["d"]) if rev else f"q{i}" + (f" + {_f(r['d'])}" if r["d"] else ""),
                    _f(r["a"]),
                    f"{_f(math.degrees(r['alpha']))}°",
                ]
            )
        sec.append(f"<h3>DH table ({html.escape(d['dh_convention'] or '')})</h3>")
        sec.append(_table(["link", "θ", "d [m]", "a [m]", "α"], dh_rows, cls="dh"))
    sec.append("<h3>Mass properties</h3>")
    sec.append(
        _table(
            ["link", "mass [kg]", "centre of mass in the link frame [m]"],
            [[b["link"], _f(b["mass"]), " ".join(_f(c) for c in b["com"])] for b in d["bodies"]],
            cls="bodies",
        )
    )
    sec.append(
        f"<p class='note'>gravity g = ({', '.join(_f(g) for g in d['gravity'])}) m/s² in base axes</p></section>"
    )
    description = "".join(sec)

    # --- 3-D view and kinematics
    model = _model_for_view(robot, q, geometry=geometry)
    if model["generated"]:
        looks = "No visual geometry is described, so the links are drawn as solids along the kinematics (joints orange when revolute, violet when prismatic)."
    else:
        looks = f"{model['shapes_drawn']} of the {model['shapes']} {geometry} shapes of the description are drawn."
    missing = "".join(f"<li>{html.escape(m)}</li>" for m in model["missing"])
    view = [
        f"<section id='view'><h2>The {'robot' if multi else 'arm'} at q</h2><div class='grid'><div>",
        '<div id="kinedyn-view" role="img" aria-label="3-D view of the arm"></div>',
        "<div id='kinedyn-playback' hidden><button id='kinedyn-play' type='button'>▶ play</button> "
        "<input id='kinedyn-time' type='range' aria-label='simulation time'> <span id='kinedyn-clock'></span>"
        " <span class='note'>the free motion simulated below</span></div>",
        f"<p class='note'>Drag to rotate, scroll to zoom. {html.escape(looks)} The stick figure joins the joints; base axes x red, y green, z blue; the small triad is the tool frame.</p>",
        f"<ul class='bad' id='kinedyn-missing'>{missing}</ul>" if missing else "",
        "</div><div><h3>Joints</h3><div id='kinedyn-sliders'></div><p><button id='kinedyn-reset' type='button'>reset</button> <span id='kinedyn-tool'></span></p>",
        f"<p class='note' id='kinedyn-q'>q = ({html.escape(q_text)})</p>",
        _configuration_table(robot, q, d) if multi else "",
        "<h3>Tool pose</h3>",
        _matrix_table(d["tool_pose"], ["", "", "", ""], ["", "", "", ""], "pose"),
        "</div></div>",
    ]
    names = ["vx", "vy", "vz", "ωx", "ωy", "ωz"]
    view.append(f"<h3>Jacobian of '{html.escape(d['tool'])}' (base axes, rows [v; ω])</h3>")
    view.append(_matrix_table(d["jacobian"], names, v_labels, "jacobian"))
    view.append(
        _table(
            ["", *[f"σ{k + 1}" for k in range(len(d["singular_values"]))]],
            [["singular values", *(_f(s) for s in d["singular_values"])]],
            cls="singular-values",
        )
    )
    cls = "bad" if d["singular"] else "ok"
    view.append(
        f"<p>Rank {d['rank']}, condition number {_f(d['condition_number'], 4)}: <span class='{cls}'>{html.escape(d['singularity'])}</span></p></section>"
    )
    view_html = "".join(view)

    # --- equations of motion
    bar.step("equations (MathML)")
    eq = [
        "<section id='equations'><h2>Equations of motion</h2>",
        "<p>M(q) q̈ + C(q, q̇) q̇ + g(q) = τ, derived symbolically by Lagrange's method (robot.equations_of_motion()).</p>",
    ]
    if eom is not None:
        eq.append(f"<p class='note'>{html.escape(d['eom_note'])}; C from Christoffel symbols (Spong eq. 9.62).</p>")
        from ..symbolic.render import name, of_q

        steps = getattr(eom, "steps", None) or []
        if getattr(eom, "final_equations", None) is not None:  # CSE form: entry names, their values, then the variables
            from ..symbolic.cse import block_equations

            for lhs, value in eom.final_equations():
                eq.append(_equation(eom, lhs, value))
            eq.append(
                "<p class='note'>Entries in terms of intermediate variables (Khalil &amp; Dombre's customised model, "
                "then common subexpressions x1, x2, ...); the variables are listed under each block.</p>"
            )
            cf = eom.closed_form()
            for key in ("M", "C", "g"):
                entries, intermediates = block_equations(cf[key])
                eq.append(f"<h3>{html.escape(cf[key].title)}</h3>")
                eq += [_equation(eom, lhs, value) for lhs, value in entries]
                eq.append(f"<details><summary>its {len(intermediates)} intermediate variables</summary>")
                eq += [_equation(eom, lhs, value) for lhs, value in intermediates]
                eq.append("</details>")
            steps = [s for s in steps if s.title not in {b.title for b in cf.blocks.values()}]
        else:
            for lhs, value in [(of_q("D"), eom.M), (of_q("C", rates=True), eom.C), (of_q("g"), eom.g)]:
                eq.append(_equation(eom, lhs, value))
            for k in range(eom.n):  # one line per joint: the torques are long
                eq.append(_equation(eom, name(f"\\tau_{{{k + 1}}}", f"tau_{k + 1}", "tau", str(k + 1)), eom.tau[k]))
        if steps:
            eq.append("<details><summary>every step of the derivation</summary>")
            for k, step in enumerate(steps, 1):
                eq.append(f"<h3>Step {k}: {html.escape(step.title)}</h3>")
                if step.text:
                    eq.append(f"<p class='note'>{html.escape(step.text)}</p>")
                for lhs, value in step.equations:
                    eq.append(_equation(eom, lhs, value))
            eq.append("</details>")
    else:
        eq.append(f"<p class='note'>{html.escape(d['eom_note'] or '')}</p>")
    eq.append("</section>")
    eq_html = "".join(eq)

    # --- dynamics: numbers, properties, simulation
    if d["dynamics"]:
        dyn = [
            "<section id='dynamics'><h2>Dynamics at q</h2>",
            "<h3>Mass matrix M(q)</h3>",
            _matrix_table(d["mass_matrix"], v_labels, v_labels, "mass-matrix"),
            _table(
                ["", *v_labels],
                [
                    ["eigenvalues of M", *(_f(v) for v in d["mass_matrix_eigenvalues"])],
                    ["gravity torque g(q) [N m]", *(_f(v) for v in d["gravity_torque"])],
                ],
                cls="gravity",
            ),
            "<h3>Properties check</h3>",
            f"<p class='note'>at q above and q̇ = ({', '.join(_f(v, 4) for v in d['properties_qd'])}).</p>",
        ]
        prow = [
            [
                p["property"],
                p["measure"],
                _f(p["value"], 3),
                _Raw("<span class='ok'>holds</span>" if p["ok"] else "<span class='bad'>FAILS</span>"),
            ]
            for p in d["properties"]
        ]
        dyn.append(_table(["property", "measured", "value", ""], prow, numeric_from=2, cls="properties"))
        s = d["simulation"]
        t = np.asarray(s["t"])
        qs = np.asarray(s["q"])
        plots = _motion_plots(robot, t, qs, q_labels)
        plots.append(
            svg_plot(
                t,
                [("kinetic K", s["K"]), ("potential P", s["P"]), ("total H", s["H"])],
                "energy",
                "t [s]",
                "energy [J]",
            )
        )
        dyn.append(f"<h3>Free motion under gravity (τ = 0) for {_f(t[-1], 3)} s from q, q̇ = 0</h3>")
        if any(j.kind == "floating" for j in robot.joints):
            dyn.append(
                "<p class='note' id='free-fall-note'>Nothing holds a floating joint: no contact or ground is modelled, so the robot falls "
                "freely (its position is plotted with the other multi-DOF coordinates); in free fall, uniform gravity alone does not "
                "move the joints relative to each other, only a starting q̇ (--qd) does.</p>"
            )
        if s.get("note"):
            dyn.append(f"<p class='bad' id='simulation-cut-short'>{html.escape(s['note'])}</p>")
        dyn.append("<div class='plots'>" + "".join(plots) + "</div>")
        damping = (
            " (implicit Euler damps energy numerically at O(dt), so the energy is not a property check here)"
            if s.get("integrator") == "implicit"
            else ""
        )
        dyn.append(
            f"<p class='note'>integrated with {html.escape(s['method'])}; the total energy changes by at most {_f(s['energy_drift'], 3)} J{damping}.</p></section>"
        )
        dyn_html = "".join(dyn)
    else:
        dyn_html = "<section id='dynamics'><h2>Dynamics</h2><p class='note'>This build of kinedyn has no numeric dynamics (robot.mass_matrix); the properties check and the simulation appear once it does.</p></section>"

    tutorial_html = ""
    if tutorial:
        from . import tutorial as worked

        answers = []
        for question in worked.QUESTIONS:
            bar.step(f"tutorial {question}")
            answers.append(worked.answer(question))
        tutorial_html = worked.render_html(answers)

    public = _jsonable({k: v for k, v in d.items() if not k.startswith("_")})
    title = f"kinedyn report: {d['robot']}"
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{html.escape(title)}</title>
<style>{_asset("report.css")}</style></head>
<body><header><h1>{html.escape(d["robot"])}</h1><p>{len(d["joints"]) if multi else d["n"]} joints{f" · nq = {d['nq']}, nv = {d['nv']}" if multi else ""} · {html.escape(d["source"] or "robot file")} · kinedyn {html.escape(kinedyn.__version__)}</p></header>
<main>{view_html}{description}{eq_html}{dyn_html}{tutorial_html}</main>
<footer>Generated by <code>kinedyn report</code>. Self-contained: no network access, every script and style is in this file.</footer>
{_json_script(model, "kinedyn-model")}
{_json_script(public, "kinedyn-data")}
{plotly_script()}
<script>{_asset("viewer.js")}</script>
</body></html>
"""
    return page


def write_report(robot, path="report.html", q=None, qd=None, **kwargs) -> Path:
    """Write the report to ``path``; returns the path."""
    path = Path(path)
    path.write_text(build_report(robot, q, qd, **kwargs), encoding="utf-8")
    return path
