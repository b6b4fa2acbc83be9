"""The parameters identification estimates, and models rebuilt from them.

- :func:`pseudo_inertia`: a body's 4x4 pseudo-inertia, positive semidefinite exactly when some mass
  distribution has its standard parameters (Wensing, Kim & Slotine, IEEE RA-L 3(1), 2018); the
  physically consistent fit (:func:`consistent_fit`) constrains it.
- Rotor inertia: the armature ``a_j = r_j^2 J_m,j`` of each geared joint (:func:`geared_joints`) adds
  ``a_j qdd_j`` to joint j's torque (:func:`rotor_regressor`); :func:`base_parameters_with_rotors`
  finds the base parameters of the link parameters and the armatures together.
- A robot with given standard parameters (:func:`with_inertial_parameters`), armatures
  (:func:`with_armatures`) or friction coefficients (:func:`with_friction`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from dataclasses import replace as dc_replace
from typing import TYPE_CHECKING

import numpy as np

from ..description.inertia import Inertia
from ..description.link import Link
from ..dynamics import BaseParameters
from .friction import FrictionModel

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..robot import Robot

__all__ = [
    "pseudo_inertia",
    "pseudo_inertia_basis",
    "consistent_fit",
    "with_inertial_parameters",
    "with_friction",
    "with_armatures",
    "geared_joints",
    "rotor_regressor",
    "base_parameters_with_rotors",
    "RotorEstimate",
]


def pseudo_inertia(parameters: ArrayLike) -> np.ndarray:
    """The 4x4 pseudo-inertia J = [[Sigma, h], [h^T, m]] of a body's 10 standard parameters
    [m, hx, hy, hz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about its frame origin, with the second moment
    Sigma = 1/2 tr(I) 1 - I (Wensing, Kim & Slotine, "Linear matrix inequalities for physically
    consistent inertial parameter identification", IEEE RA-L 3(1), 2018; ``J = int [r; 1] [r; 1]^T dm``,
    so J >= 0 exactly when some mass distribution has these parameters)."""
    m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = np.asarray(parameters, dtype=float)
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    J = np.zeros((4, 4))
    J[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    J[:3, 3] = J[3, :3] = (hx, hy, hz)
    J[3, 3] = m
    return J


def pseudo_inertia_basis() -> np.ndarray:
    """(10, 4, 4): J(pi) = sum_k pi_k B_k (pseudo_inertia is linear)."""
    return np.array([pseudo_inertia(e) for e in np.eye(10)])


def consistent_fit(
    robot: Robot,
    A: np.ndarray,
    b: np.ndarray,
    nf: int,
    rotor_joints: tuple,
    regularization: float,
    margin: float,
    solver: str | None,
):
    """min |A [pi; a; f] - b|^2 + lam |[pi; a] - [pi0; a0]|^2 subject to J_k(pi) >= margin I for
    every body and the armatures a >= 0: a semidefinite program (cvxpy; Clarabel, else SCS). The data
    term enters through the R factor of A = QR, so the program's size does not grow with the number
    of samples. Returns pi (10 n), a (len(rotor_joints)), f (nf)."""
    try:
        import cvxpy as cp  # cvxpy (optional, heavy) loads only for a consistent fit
    except ImportError:  # pragma: no cover - depends on the installation
        raise ImportError(
            "consistent identification needs cvxpy with Clarabel or SCS: pip install 'kinedyn[identify]'"
        ) from None
    n = robot.n
    nr = len(rotor_joints)
    m = 10 * n + nr  # inertial unknowns: link parameters, then armatures
    pi0 = np.concatenate([robot.inertial_parameters(), robot.armature[list(rotor_joints)]])
    scale = np.linalg.norm(A, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    # column scaling keeps the program well conditioned (masses ~ 1, inertias ~ 1e-3 ...)
    R = np.asarray(np.linalg.qr(A / scale, mode="r"))
    Q_b = np.linalg.lstsq(R.T, (A / scale).T @ b, rcond=None)[0]  # Q^T b without forming Q
    x = cp.Variable(A.shape[1])
    pi = cp.multiply(x[: 10 * n], 1.0 / scale[: 10 * n])
    B = pseudo_inertia_basis()
    constraints = []
    for k in range(n):
        J = sum(pi[10 * k + c] * B[c] for c in range(10))
        constraints.append(J - margin * np.eye(4) >> 0)
    if nr:
        constraints.append(x[10 * n : m] >= 0)
    # the prior term in the scaled coordinates: a parameter's deviation weighs by its column norm,
    # i.e. by how much torque it moves over the log (each scaled column has unit norm)
    objective = cp.Minimize(cp.sum_squares(R @ x - Q_b) + regularization * cp.sum_squares(x[:m] - pi0 * scale[:m]))
    problem = cp.Problem(objective, constraints)
    solvers = [solver] if solver else [s for s in ("CLARABEL", "SCS") if s in cp.installed_solvers()]
    if not solvers:
        raise ImportError("consistent identification needs the Clarabel or SCS solver for cvxpy")
    last: Exception | None = None
    for name in solvers:
        try:
            problem.solve(solver=name)
        except cp.error.SolverError as e:
            last = e
            continue
        if problem.status in ("optimal", "optimal_inaccurate") and x.value is not None:
            xs = np.asarray(x.value) / scale
            return xs[: 10 * n], np.maximum(xs[10 * n : m], 0.0), xs[m:]
        last = RuntimeError(f"solver {name}: {problem.status}")
    raise RuntimeError(f"the consistent (SDP) identification failed: {last}")


def with_friction(robot: Robot, model: FrictionModel, coefficients: np.ndarray) -> Robot:
    """``robot`` with the identified viscous and Coulomb coefficients in its joints (asymmetric
    Coulomb levels as the joint's two levels; the Stribeck and offset terms have no place in a joint
    and are left out)."""
    cols = model.columns()
    k = len(cols)
    index = {j.name: i for i, j in enumerate(robot.joints)}
    links = []
    for link in robot.links:
        i = index.get(link.joint.name) if link.joint.is_moving else None
        if i is not None:
            c = dict(zip(cols, coefficients[i * k : (i + 1) * k]))
            if "coulomb+" in c:
                levels = (float(max(c["coulomb+"], 0.0)), float(max(c["coulomb-"], 0.0)))
                coulomb, negative = levels if levels[0] != levels[1] else (levels[0], None)
            else:
                coulomb, negative = float(abs(c.get("coulomb", link.joint.coulomb))), None
            joint = dc_replace(
                link.joint,
                viscous=float(c.get("viscous", link.joint.viscous)),
                coulomb=coulomb,
                coulomb_negative=negative,
            )
            link = Link(link.name, link.parent, joint, link.placement, link.post, link.inertia)
        links.append(link)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return robot.replace(links=links)


def with_inertial_parameters(robot: Robot, pi: ArrayLike) -> Robot:
    """A copy of ``robot`` whose moving bodies have the standard parameters ``pi`` (10 n, about each
    body-frame origin, as :meth:`Robot.inertial_parameters`); fixed links merged into a moving body
    carry zero inertia in the copy. ValueError for physically invalid parameters."""
    pi = np.asarray(pi, dtype=float).reshape(robot.n, 10)
    bodies = {b.name: k for k, b in enumerate(robot.tree.bodies)}
    moving_descendant = set()
    parents = {l.name: l.parent for l in robot.links}
    for link in robot.links:
        p, moved = link.parent, False
        while p is not None and p in parents:
            if p in bodies:
                moved = True
                break
            p = parents[p]
        if moved and not link.joint.is_moving:
            moving_descendant.add(link.name)
    links = []
    for link in robot.links:
        if link.name in bodies:
            m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = pi[bodies[link.name]]
            Io = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
            if abs(m) < 1e-12:
                if np.abs([hx, hy, hz]).max() > 1e-9:
                    raise ValueError(f"body '{link.name}': zero mass with a non-zero first moment {[hx, hy, hz]}")
                body_inertia = Inertia(0.0, (0.0, 0.0, 0.0), Io)
            else:
                c = np.array([hx, hy, hz]) / m
                S = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
                Ic = Io + m * S @ S  # I_c = I_o + m [c]x [c]x
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    try:
                        body_inertia = Inertia(m, tuple(c), 0.5 * (Ic + Ic.T))
                    except ValueError as e:
                        raise ValueError(f"body '{link.name}': {e}") from None
            check = body_inertia.consistency()
            if check is not None and not check.positive:  # a Robot would only warn (inertia policy)
                raise ValueError(f"body '{link.name}': {check.describe()}")
            post = np.asarray(link.post, dtype=float)
            inv = np.eye(4)
            inv[:3, :3] = post[:3, :3].T
            inv[:3, 3] = -post[:3, :3].T @ post[:3, 3]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                link = Link(
                    link.name, link.parent, link.joint, link.placement, link.post, body_inertia.transformed(inv)
                )
        elif link.name in moving_descendant:
            link = Link(link.name, link.parent, link.joint, link.placement, link.post, Inertia())
        links.append(link)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return robot.replace(links=links)


def geared_joints(robot: Robot) -> tuple:
    """Indices of the joints whose model has a drive train: a gear ratio other than 1 or a rotor
    inertia (their armature ``r^2 J_m`` is estimated from a log)."""
    out = []
    for k, j in enumerate(robot.joints):
        try:
            if float(j.gear_ratio) != 1.0 or float(j.rotor_inertia) != 0.0:
                out.append(k)
        except TypeError:  # a symbolic drive train: not something to fit numbers to
            raise ValueError(f"joint '{j.name}': identification needs a numeric gear ratio and rotor inertia") from None
    return tuple(out)


def rotor_regressor(qdd: ArrayLike, joints: tuple, n: int) -> np.ndarray:
    """(S, n, len(joints)) for qdd (S, n): column k is ``qdd_j`` in joint ``j = joints[k]``'s row
    (the armature's torque ``a_j qdd_j``), zero in the other rows."""
    qdd = np.asarray(qdd, dtype=float).reshape(-1, n)
    out = np.zeros((qdd.shape[0], n, len(joints)))
    for k, j in enumerate(joints):
        out[:, j, k] = qdd[:, j]
    return out


def base_parameters_with_rotors(
    robot: Robot, joints: tuple, samples: int = 200, rng=0, tol: float = 1e-9, dependence: float = 1e-7
) -> BaseParameters:
    """Base parameters of the link parameters and the armatures of ``joints`` together.

    The parameter vector is ``[pi (10 n); a (len(joints))]`` and the regressor ``[Y, R]`` with R of
    :func:`rotor_regressor`. The link part is :meth:`Robot.base_parameters` (Gautier 1991); then each
    rotor column in turn, stacked at ``samples`` random states, is tested against the span of the
    columns kept so far (least squares, residual ``<= dependence`` times its norm): an independent one
    becomes a base parameter ``<joint>.armature``; a dependent one, ``R_k = W_kept beta``, is grouped
    (``grouping[:, 10 n + k] = beta``), i.e. it only acts through those base parameters. Returns a
    :class:`~kinedyn.dynamics.BaseParameters` over the augmented vector (``indices`` into ``[Y, R]``)."""
    link = robot.base_parameters(samples=samples, rng=rng, tol=tol)
    n, nr = robot.n, len(joints)
    if nr == 0:
        return link
    gen = np.random.default_rng(rng if isinstance(rng, (int, np.integer)) else None)
    q = robot.random_configuration(gen, size=samples)
    qd = gen.uniform(-2.0, 2.0, size=(samples, n))
    qdd = gen.uniform(-4.0, 4.0, size=(samples, n))
    kept = robot.regressor(q, qd, qdd)[..., link.indices].reshape(samples * n, link.count)
    R = rotor_regressor(qdd, joints, n).reshape(samples * n, nr)
    rows = [np.concatenate([g, np.zeros(nr)]) for g in link.grouping]
    indices = list(link.indices)
    names = list(link.names)
    for k, j in enumerate(joints):
        col = R[:, k]
        beta, *_ = np.linalg.lstsq(kept, col, rcond=None)
        if np.linalg.norm(col - kept @ beta) <= dependence * np.linalg.norm(col):
            beta[np.abs(beta) < 1e-10 * max(1.0, float(np.abs(beta).max()))] = 0.0
            for i, b in enumerate(beta):
                rows[i][10 * n + k] += b
        else:
            row = np.zeros(10 * n + nr)
            row[10 * n + k] = 1.0
            rows.append(row)
            indices.append(10 * n + k)
            names.append(f"{robot.joints[j].name}.armature")
            kept = np.column_stack([kept, col])
    grouping = np.array(rows)
    values = grouping @ np.concatenate([robot.inertial_parameters(), robot.armature[list(joints)]])
    return BaseParameters(indices=np.array(indices), grouping=grouping, values=values, names=tuple(names))


@dataclass
class RotorEstimate:
    """The armature ``a = r^2 J_m`` of one geared joint as identified: ``armature`` and ``std``
    (and ``rotor_inertia = armature / r^2``) when the data identify it on its own; otherwise
    ``grouped_into`` names the base parameters it only acts through, and ``armature`` is None."""

    joint: str
    gear_ratio: float
    nominal: float
    armature: float | None
    std: float | None
    grouped_into: tuple = ()

    @property
    def rotor_inertia(self) -> float | None:
        return None if self.armature is None else self.armature / self.gear_ratio**2

    def to_dict(self) -> dict:
        return dict(
            joint=self.joint,
            gear_ratio=self.gear_ratio,
            nominal_armature=self.nominal,
            armature=self.armature,
            std=self.std,
            rotor_inertia=self.rotor_inertia,
            grouped_into=list(self.grouped_into),
        )


def with_armatures(robot: Robot, armatures: dict) -> Robot:
    """``robot`` with joint index -> armature ``r^2 J_m`` set through the rotor inertia ``a / r^2``.
    ValueError naming the joint for a negative armature (not physical)."""
    by_name = {robot.joints[k].name: float(a) for k, a in armatures.items()}
    links = []
    for link in robot.links:
        a = by_name.get(link.joint.name) if link.joint.is_moving else None
        if a is not None:
            r = float(link.joint.gear_ratio)
            if a < 0:
                raise ValueError(
                    f"joint '{link.joint.name}': the identified armature r^2 J_m = {a:.4g} is negative (not physical; try consistent=True)"
                )
            link = Link(
                link.name,
                link.parent,
                dc_replace(link.joint, rotor_inertia=a / r**2),
                link.placement,
                link.post,
                link.inertia,
            )
        links.append(link)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return robot.replace(links=links)
