"""The numbers of a robot's closed loops, computed by the core (``crates/kinedyn-core/src/constraints``):
the closure residual, its Jacobian, the drift ``gamma = dJ/dt qd``, constrained forward and inverse
dynamics, and projections onto the loops' manifold (docs/closed-loops.md, "The numbers").

Conventions (the core's module header has the derivations): everything is in base axes. A point
loop's rows are ``p_a - p_b``; a weld adds ``R_b log3(R_b^T R_a)``. ``J qd`` is the velocity of frame
a relative to frame b (linear, then angular for a weld), ``J qdd + gamma = 0`` along a closed
motion, and ``M qdd + h = tau + J^T lambda``: ``lambda`` is the force (then, for a weld, the moment
about frame a's origin) that the loop applies to frame a's link, in base axes; frame b's link
receives the opposite. Redundant rows (a planar four-bar's out-of-plane row) get the multipliers of
least norm.

Each function takes what a ``Robot`` holds: its description and its compiled native model.
"""

from __future__ import annotations

import numpy as np

from ._arrays import float64_array
from ._ui.names import did_you_mean

__all__ = [
    "constrained_forward_dynamics",
    "constrained_inverse_dynamics",
    "independent_joints",
    "loop_gamma",
    "loop_jacobian",
    "loop_residual",
    "project_configuration",
    "project_velocity",
    "reduced_dynamics",
    "velocity_columns",
]


def velocity_columns(description, joints, what: str) -> list:
    """The velocity columns (indices into qd) of the named joints: all of a multi-DOF joint's."""
    names = description.joint_names
    starts = np.concatenate([[0], np.cumsum([j.nv for j in description.joints])]).astype(int)
    columns: list[int] = []
    for name in joints:
        if name not in names:
            raise ValueError(
                f"robot '{description.name}', {what}: unknown joint '{name}'{did_you_mean(str(name), names)}"
            )
        k = names.index(name)
        columns.extend(range(starts[k], starts[k + 1]))
    return columns


def loop_residual(description, model, q):
    """(m,) or (N, m): the closure residual."""
    return model.loop_residual(q)


def loop_jacobian(description, model, q):
    """(m, nv) or (N, m, nv): the loops' Jacobian."""
    return model.loop_jacobian(q)


def loop_gamma(description, model, q, qd):
    """(m,) or (N, m): ``gamma = dJ/dt qd``."""
    return model.loop_gamma(q, qd)


def constrained_forward_dynamics(description, model, q, qd, tau, f_ext=None):
    """``(qdd, lambda)``, each with the batch's leading axis when ``q`` has one (a control loop's
    call: the checks are the core's, the wrenches' layout too). A robot with reduced mimic joints has a
    ReducedModel, which composes the full model's loops with its map (kinedyn.native.mimic_loops)."""
    out = model.constrained_forward_dynamics(q, qd, tau, f_ext)
    n = model.n
    return out[..., :n], out[..., n:]


def constrained_inverse_dynamics(description, model, q, qd, qdd, actuated, f_ext=None):
    """(nv,) or (N, nv) torques, zero off the actuated joints' columns."""
    if isinstance(actuated, str):
        actuated = [actuated]
    columns = velocity_columns(description, actuated, "constrained_inverse_dynamics, actuated")
    return model.constrained_inverse_dynamics(q, qd, qdd, columns, f_ext)


def project_configuration(description, model, q, hold=None, tolerance=1e-12, max_iter=50):
    """(nq,) or (N, nq): a configuration near ``q`` that closes the loops, the ``hold`` joints fixed."""
    if isinstance(hold, str):
        hold = [hold]
    columns = velocity_columns(description, hold or (), "project_configuration, hold")
    if not tolerance > 0:
        raise ValueError(f"project_configuration: tolerance must be positive, got {tolerance}")
    return model.project_configuration(q, columns, float(tolerance), int(max_iter))


def project_velocity(description, model, q, qd):
    """(nv,) or (N, nv): the velocity nearest ``qd`` with ``J qd = 0``."""
    return model.project_velocity(q, qd)


RANK_TOLERANCE = 1e-9  # singular values of J below this (relative to its largest entry) count as zero


def reduced_dynamics(description, model, q, qd_independent, independent=None):
    """The equations of motion in independent coordinates at one closed state (Nikravesh,
    Computer-Aided Analysis of Mechanical Systems, §13.4; Wehage & Haug 1982, "Generalized coordinate
    partitioning"): the velocity columns split into independent ``i`` and dependent ``d`` ones, the
    dependent rows of ``J`` being of full rank, so that ``J_d qd_d + J_i qd_i = 0`` gives
    ``qd = G qd_i`` with ``G = [1; -J_d^+ J_i]`` (rows in column order), and ``J qdd + gamma = 0``
    gives ``qdd = G qdd_i + a0``, ``a0 = [0; -J_d^+ gamma]``. Then
    ``G^T M G qdd_i + G^T (M a0 + C qd + friction) + G^T g = G^T tau``.

    ``independent``: joint names, or None to choose them by QR with column pivoting of ``J``
    (Golub & Van Loan §5.4.2: the first ``rank J`` pivots are dependent). Returns a dict: ``G``
    (nv, k), ``M`` (k, k), ``bias`` (k,) (the velocity terms ``G^T (M a0 + C qd + friction)``),
    ``g`` (k,), ``a0`` (nv,), ``qd`` (nv,) and ``independent`` (the velocity columns)."""
    native = model
    q = float64_array(q)
    n = native.n
    jac = native.loop_jacobian(q)
    # the rank at the closure's accuracy, not at machine precision: a column that only a residual of
    # 1e-13 makes nonzero (the yaw of a planar loop turned as a whole) is not a constraint direction
    rank_tol = RANK_TOLERANCE * max(1.0, float(np.abs(jac).max())) if jac.size else 0.0
    rank = int(np.linalg.matrix_rank(jac, tol=rank_tol)) if jac.size else 0
    if independent is None:
        from scipy.linalg import qr  # scipy loads only for this choice

        _, _, pivots = qr(jac, pivoting=True, mode="economic") if jac.size else (None, None, np.arange(n))
        dependent = sorted(int(k) for k in pivots[:rank])
        columns = [k for k in range(n) if k not in dependent]
    else:
        columns = velocity_columns(description, independent, "reduced_dynamics, independent")
        dependent = [k for k in range(n) if k not in columns]
        if len(dependent) != rank or (rank and np.linalg.matrix_rank(jac[:, dependent], tol=rank_tol) < rank):
            raise ValueError(
                f"robot '{description.name}', reduced_dynamics: the joints {list(independent)} are not independent "
                f"coordinates: the loops' Jacobian has rank {rank}, and its {len(dependent)} other columns must "
                "have that rank and number"
            )
    qd_i = np.asarray(qd_independent, dtype=float)
    if qd_i.shape != (len(columns),):
        raise ValueError(f"reduced_dynamics: qd_independent must have shape ({len(columns)},), got {qd_i.shape}")
    pinv_d = np.linalg.pinv(jac[:, dependent]) if dependent else np.zeros((0, jac.shape[0]))
    big_g = np.zeros((n, len(columns)))
    big_g[columns, np.arange(len(columns))] = 1.0
    big_g[dependent] = -pinv_d @ jac[:, columns]
    qd = big_g @ qd_i
    a0 = np.zeros(n)
    a0[dependent] = -pinv_d @ native.loop_gamma(q, qd)
    mass = native.mass_matrix(q, None)
    gravity = native.gravity_torque(q, None)
    velocity_terms = native.inverse_dynamics(q, qd, np.zeros(n), None, None) - gravity
    return {
        "G": big_g,
        "M": big_g.T @ mass @ big_g,
        "bias": big_g.T @ (mass @ a0 + velocity_terms),
        "g": big_g.T @ gravity,
        "a0": a0,
        "qd": qd,
        "independent": columns,
    }


def independent_joints(description, model, q) -> list:
    """Names of 1-DOF joints that are independent coordinates of the loops at ``q``: holding them
    fixes every other 1-DOF coordinate (a slider each, in the drawings; ``hold=`` of
    ``project_configuration``). With ``N`` a basis of the null space of ``J`` (the closed motions),
    a set ``S`` of columns is independent when the rows ``N[S]`` are (coordinate partitioning, Wehage
    & Haug 1982); the joints are taken greedily nearest the base first (fewest ancestors; a parallel
    mechanism's motors sit there), then in joint order, until there are ``nv - rank J`` or no 1-DOF
    joint is left (the remaining freedom is then in multi-DOF joints: a Delta robot's rod spins)."""
    q = float64_array(q)
    jac = model.loop_jacobian(q)
    n = jac.shape[1]
    rank_tol = RANK_TOLERANCE * max(1.0, float(np.abs(jac).max())) if jac.size else 0.0
    _, sigma, vt = np.linalg.svd(jac) if jac.size else (None, np.zeros(0), np.zeros((0, n)))
    rank = int(np.sum(sigma > rank_tol))
    null = vt[rank:].T if jac.size else np.eye(n)  # (n, n - rank), orthonormal columns
    starts = np.concatenate([[0], np.cumsum([j.nv for j in description.joints])]).astype(int)
    bodies = description.tree.bodies
    depth: dict[str, int] = {}
    for b in bodies:  # parents come first (parent < own index)
        depth[b.joint.name] = 0 if b.parent < 0 else depth[bodies[b.parent].joint.name] + 1
    order = sorted(
        (k for k, j in enumerate(description.joints) if j.nv == 1 and not j.is_multi_dof),
        key=lambda k: (depth.get(description.joints[k].name, 0), k),
    )
    chosen: list[int] = []
    for k in order:
        if len(chosen) == null.shape[1]:
            break
        rows = null[[starts[c] for c in chosen + [k]]]
        # the rows stay independent: their least singular value well above the rank tolerance
        if np.linalg.svd(rows, compute_uv=False)[-1] > 1e-6:
            chosen.append(k)
    return [description.joints[k].name for k in sorted(chosen)]
