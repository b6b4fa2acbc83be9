"""The report's numbers: :func:`collect` gathers them from a robot into a :class:`ReportData`, which
the templates render (:mod:`kinedyn.report.html`) and ``kinedyn report --json`` prints.

A :class:`ReportData` reads like the dict it replaces (``data["singular_values"]``, ``data.items()``:
the keys of the page's JSON block ``#kinedyn-data``); the symbolic equations, which are no JSON, are
its attribute ``eom``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from .. import robots
from .._ui.files import readable_source
from .._ui.progress import Steps
from ..analysis.properties import mass_matrix_rate
from ..closed_loops import RANK_TOLERANCE
from ..configuration import check_configuration, default_configuration
from ..coordinates import (  # noqa: F401 (the report's names for them)
    Q_ENTRIES,
    V_ENTRIES,
    coordinate_labels,
    coordinate_units,
    in_multi_dof_block,
    velocity_labels,
)
from ..description.snap import SNAP_TOLERANCE
from ..kinematics import singularity_report
from ..simulate import SimulationError, SimulationTruncatedWarning, simulate

__all__ = [
    "ReportData",
    "collect",
    "coordinate_labels",
    "velocity_labels",
    "coordinate_units",
    "in_multi_dof_block",
    "joint_rows",
    "property_checks",
    "simulate_free_motion",
    "closest_singular_passage",
    "NEAR_SINGULAR",
    "symbolic_equations",
    "SIMULATION_BUDGET",
    "Q_ENTRIES",
    "V_ENTRIES",
]


#: Wall-clock seconds the report's free-motion simulation may take (the rest of a report takes a few
#: seconds at most; the symbolic equations are derived only for small arms, see ``eom_joints``).
SIMULATION_BUDGET = 30.0


def simulate_free_motion(
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


# s_r / s_1 below which the report calls a configuration near a singular one of the loops (wording only)
NEAR_SINGULAR = 1e-2


def closest_singular_passage(robot, t, q) -> dict | None:
    """Where the sampled motion ``q`` (S, nq) of a robot with loops comes nearest a singular
    configuration of its loops: the sample whose loop Jacobian has the smallest ratio
    ``s_r / s_1`` of its r-th to its largest singular value, r the largest rank over the samples
    (counted as ``reduced_dynamics`` counts it). None when the loops leave no rank to lose."""
    s = np.linalg.svd(robot.loop_jacobian(np.asarray(q, dtype=float)), compute_uv=False)
    largest = s[:, :1]
    rank = int(np.max(np.sum(s > RANK_TOLERANCE * np.maximum(largest, 1.0), axis=1), initial=0))
    if rank == 0:
        return None
    ratio = s[:, rank - 1] / largest[:, 0]
    k = int(np.argmin(ratio))
    return {"t": float(t[k]), "ratio": float(ratio[k]), "rank": rank}


def property_checks(robot, q, qd, rng) -> list[dict]:
    """The textbook's properties at (q, qd), each with its measured residual."""
    out: list[dict] = []
    n = robot.n
    if n == 0:
        return out  # no moving joint: the equations of motion are empty, with no property to measure
    M = robot.mass_matrix(q)
    eig = np.linalg.eigvalsh((M + M.T) / 2)
    scale = max(1.0, float(np.max(np.abs(M), initial=0.0)))  # initial: a robot with no joint has an empty M
    asym = float(np.max(np.abs(M - M.T), initial=0.0))
    out.append({"property": "M(q) symmetric", "measure": "max |M - M^T|", "value": asym, "ok": asym <= 1e-12 * scale})
    out.append(
        {
            "property": "M(q) positive definite",
            "measure": "smallest eigenvalue of M",
            "value": float(eig[0]),
            "ok": bool(eig[0] > 0),
        }
    )
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


def symbolic_equations(robot, name: str | None, max_joints: int):
    """The equations of motion to typeset: of the built-in arm with its parameters as symbols where the
    catalogue offers that, else of the robot as given. None (with the reason) for large arms."""
    if robot.n > max_joints:
        return (
            None,
            f"The symbolic equations of motion are typeset for arms with up to {max_joints} joints (this one has {robot.n}); `kinedyn report --eom-joints {robot.n}` derives them anyway.",
        )
    subject = robot
    if name in robots.CATALOGUE:
        try:
            subject = robots.get(name, symbolic=True)
        except (TypeError, ValueError, AttributeError):
            subject = robot
    # above 3 joints the results are shown in CSE form (kinedyn.symbolic.cse): readable, and seconds
    # a file's right angles written with a few digits made exact, as `kinedyn derive` does (and said)
    eom = subject.equations_of_motion(form="cse" if subject.n > 3 else "auto", snap_angles=SNAP_TOLERANCE)
    note = "with the catalogue's parameters as symbols" if subject is not robot else "with this robot's numbers"
    return eom, note + (" (" + " ".join(eom.notes).rstrip(".") + ")" if eom.notes else "")


def joint_rows(robot) -> list[dict]:
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


@dataclass(eq=False)
class ReportData(Mapping):
    """Every number of the report of one robot at (q, qd): JSON-ready lists, numbers and strings (the
    page's ``#kinedyn-data`` block is :meth:`to_dict`), plus the symbolic equations in :attr:`eom`.

    Read-only as a mapping of its public fields (``data["rank"]``), as the dict of earlier versions."""

    robot: str
    source: str | None
    n: int
    nq: int
    nv: int
    joint_names: list[str]
    coordinate_labels: list[str]
    velocity_labels: list[str]
    gravity: list[float]
    q: list[float]
    qd: list[float]
    tool: str
    tool_pose: list[list[float]]
    jacobian: list[list[float]]
    singular_values: list[float]
    rank: int
    singular: bool
    condition_number: float
    singularity: str
    joints: list[dict]
    dh_convention: str | None
    dh: list[dict] | None
    bodies: list[dict]
    mass_matrix: list[list[float]]
    mass_matrix_eigenvalues: list[float]
    gravity_torque: list[float]
    properties_qd: list[float]
    properties: list[dict]
    simulation: dict[str, Any]
    eom_note: str | None = None
    #: the audit of the robot's file (kinedyn.description.audit: source, counts, findings), or None
    audit: dict | None = None
    #: the symbolic equations of motion typeset on the page (a kinedyn.symbolic EquationsOfMotion), or
    #: None where they are not derived (``eom_note`` says why); not part of the JSON
    eom: Any = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """The public numbers as a dict (the page's JSON block and ``kinedyn report --json``)."""
        out = {f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("eom", "eom_note")}
        # "dynamics" stays in the JSON for its readers: every build has the numeric dynamics (since issue 3)
        out["dynamics"] = True
        for key in ("mass_matrix", "mass_matrix_eigenvalues", "gravity_torque", "properties_qd", "properties"):
            out[key] = out.pop(key)  # the order of earlier versions: after "dynamics"
        out["simulation"] = out.pop("simulation")
        out["eom_note"] = self.eom_note
        out["audit"] = out.pop("audit")
        return out

    def __getitem__(self, key: str):
        return self.to_dict()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.to_dict())

    def __len__(self) -> int:
        return len(self.to_dict())


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
) -> ReportData:
    """Every number of the report of ``robot`` at ``q`` (default: :func:`kinedyn.configuration.default_configuration`)
    and ``qd`` (default: at rest). ``name``: the catalogue name, whose symbolic twin (parameters as symbols)
    gives the equations; ``t_end``: seconds of free motion simulated; ``eom_joints``: the largest robot whose
    equations are derived; ``time_budget``: wall-clock seconds for the simulation (None: unbounded);
    ``progress``: a progress bar on stderr (None: on a terminal); ``steps``: a :class:`kinedyn._ui.progress.Steps`
    to advance (4 steps)."""
    own = steps is None
    steps = Steps("report", 4, progress) if own else steps
    try:
        return _collect(robot, q, qd, name, t_end, eom_joints, seed, time_budget, progress, steps)
    finally:
        if own:
            steps.close()


def _collect(robot, q, qd, name, t_end, eom_joints, seed, time_budget, progress, steps) -> ReportData:
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
    # a ValueError naming the joint for a quaternion or (cos, sin) pair that is not unit, or a value not finite
    q = check_configuration(robot, q)
    rng = np.random.default_rng(seed)
    rep = singularity_report(robot, q)
    kinematics = {
        "robot": robot.name,
        "source": readable_source(robot.source, shared=True),  # resolved, and no absolute path in a page
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
        "tool_pose": robot.pose(q).tolist(),
        "jacobian": robot.jacobian(q).tolist(),
        "singular_values": rep.singular_values.tolist(),
        "rank": rep.rank,
        "singular": rep.singular,
        "condition_number": rep.condition_number,
        "singularity": rep.summary(),
        "joints": joint_rows(robot),
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
    steps.step("dynamics and properties")
    qd_check = qd if np.any(qd) else rng.uniform(-1, 1, robot.n)
    M = robot.mass_matrix(q)
    properties = property_checks(robot, q, qd_check, rng)
    steps.step("simulation")
    sim = simulate_free_motion(robot, q, qd, t_end, time_budget=time_budget, progress=progress)
    simulation = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in sim.items()}
    H = sim["H"]
    simulation["energy_drift"] = float(np.max(np.abs(H - H[0])))
    friction = any(float(j.viscous) or float(j.coulomb) for j in robot.joints)
    # a robot with loops: how near its motion came to a singular configuration of the loops, where a
    # fixed step is least accurate (docs/closed-loops.md, "Motion"); the energy check names it
    passage = closest_singular_passage(robot, sim["t"], sim["q"]) if getattr(robot, "loops", ()) else None
    simulation["singular_passage"] = passage
    # energy is a property check only where the integrator conserves it (RK4; implicit Euler damps)
    if sim["integrator"] == "rk4" and not sim["note"]:
        near = ""
        if passage is not None:
            r = passage["rank"]
            near = (
                f"; the loops stay regular (s_{r}/s_1 >= {passage['ratio']:.2g}, s_i the loop Jacobian's singular values)"
                if passage["ratio"] >= NEAR_SINGULAR
                else f"; the motion passes near a singular configuration of the loops, s_{r}/s_1 = {passage['ratio']:.2g} "
                f"at t = {passage['t']:.3g} s (s_i the loop Jacobian's singular values, rank {r} elsewhere), where the "
                "step is least accurate"
            )
        properties.append(
            {
                "property": "energy conserved (tau = 0, no friction)",
                "measure": f"max |H(t) - H(0)| over the {t_end:g} s simulation{near}",
                "value": simulation["energy_drift"],
                "ok": simulation["energy_drift"] <= 1e-6 * max(1.0, float(np.max(np.abs(H)))) or friction,
            }
        )
    steps.step("equations of motion")
    eom, note = _equations_and_note(robot, name, eom_joints)
    # what is wrong with the file (docs/audit.md); a robot built in Python is audited from its description
    audit = robot.audit().to_dict()
    return ReportData(
        **kinematics,
        mass_matrix=M.tolist(),
        mass_matrix_eigenvalues=np.linalg.eigvalsh(M).tolist(),
        gravity_torque=robot.gravity_torque(q).tolist(),
        properties_qd=qd_check.tolist(),
        properties=properties,
        simulation=simulation,
        eom_note=note,
        audit=audit,
        eom=eom,
    )


def _equations_and_note(robot, name: str | None, eom_joints: int) -> tuple:
    """(the symbolic equations or None, what the page says about them)."""
    if robot.has_multi_dof_joints and robot.n > eom_joints:
        return (
            None,
            f"The symbolic equations of motion are typeset for up to {eom_joints} degrees of freedom (this robot has {robot.n}, "
            f"its multi-DOF joints included); `kinedyn report --eom-joints {robot.n}` derives them anyway, with each multi-DOF "
            "joint in position and ZYX Euler angles (docs/floating-base.md).",
        )
    eom, note = symbolic_equations(robot, name, eom_joints)
    if eom is not None and robot.has_multi_dof_joints:
        note += (
            f"; in the coordinates ({', '.join(map(str, eom.q))}): each multi-DOF joint in position and ZYX Euler angles "
            "(R = Rz(yaw) Ry(pitch) Rx(roll)), the symbolic engine's minimal coordinates, not the numeric q (quaternions) and "
            "q̇ above (docs/floating-base.md)"
        )
    return eom, note
