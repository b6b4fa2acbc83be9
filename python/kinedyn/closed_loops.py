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
from .native.compile import body_wrenches

__all__ = [
    "constrained_forward_dynamics",
    "constrained_inverse_dynamics",
    "loop_gamma",
    "loop_jacobian",
    "loop_residual",
    "project_configuration",
    "project_velocity",
    "velocity_columns",
]


def _native(description, model, feature: str):
    """The native model, refusing robots whose loops the core cannot hold (reduced mimic joints: the
    core's model then has fewer columns than the loops' frames move)."""
    description.require_no_mimic_joints(feature)
    return model


def velocity_columns(description, joints, what: str) -> list:
    """The velocity columns (indices into qd) of the named joints: all of a multi-DOF joint's."""
    names = description.joint_names
    starts = np.concatenate([[0], np.cumsum([j.nv for j in description.joints])]).astype(int)
    columns = []
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
    return _native(description, model, "loop_residual").loop_residual(q)


def loop_jacobian(description, model, q):
    """(m, nv) or (N, m, nv): the loops' Jacobian."""
    return _native(description, model, "loop_jacobian").loop_jacobian(q)


def loop_gamma(description, model, q, qd):
    """(m,) or (N, m): ``gamma = dJ/dt qd``."""
    return _native(description, model, "loop_gamma").loop_gamma(q, qd)


def constrained_forward_dynamics(description, model, q, qd, tau, f_ext=None):
    """``(qdd, lambda)``, each with the batch's leading axis when ``q`` has one (a control loop's
    call: the checks are the core's, only the mimic refusal and the wrench layout are here)."""
    if description.mimic_map is not None:
        _native(description, model, "constrained_forward_dynamics")
    if f_ext is not None:
        q = float64_array(q)
        f_ext = body_wrenches(description, q, f_ext)
    out = model.constrained_forward_dynamics(q, qd, tau, f_ext)
    n = model.n
    return out[..., :n], out[..., n:]


def constrained_inverse_dynamics(description, model, q, qd, qdd, actuated, f_ext=None):
    """(nv,) or (N, nv) torques, zero off the actuated joints' columns."""
    native = _native(description, model, "constrained_inverse_dynamics")
    if isinstance(actuated, str):
        actuated = [actuated]
    columns = velocity_columns(description, actuated, "constrained_inverse_dynamics, actuated")
    q = float64_array(q)
    return native.constrained_inverse_dynamics(q, qd, qdd, columns, body_wrenches(description, q, f_ext))


def project_configuration(description, model, q, hold=None, tolerance=1e-12, max_iter=50):
    """(nq,) or (N, nq): a configuration near ``q`` that closes the loops, the ``hold`` joints fixed."""
    native = _native(description, model, "project_configuration")
    if isinstance(hold, str):
        hold = [hold]
    columns = velocity_columns(description, hold or (), "project_configuration, hold")
    if not tolerance > 0:
        raise ValueError(f"project_configuration: tolerance must be positive, got {tolerance}")
    return native.project_configuration(q, columns, float(tolerance), int(max_iter))


def project_velocity(description, model, q, qd):
    """(nv,) or (N, nv): the velocity nearest ``qd`` with ``J qd = 0``."""
    return _native(description, model, "project_velocity").project_velocity(q, qd)
