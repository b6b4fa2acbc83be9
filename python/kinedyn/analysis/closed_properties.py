"""The numeric property checks of a robot with closed loops, on its reduced equations at sampled
closed states (docs/closed-loops.md, "Checks"; :func:`kinedyn.analysis.check_properties` forwards
here).

At a closed configuration ``q`` with independent velocities ``qd_i`` (coordinate partitioning,
``robot.reduced_dynamics``: ``qd = G qd_i``), the reduced equations are
``M_r qdd_i + C_r qd_i + g_r = G^T tau`` with ``M_r = G^T M G`` and ``C_r = G^T (M dG/dt + C G)``
(Spong §9.4.4 for the five-bar; Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, §13.4).
Each derivative along the motion is a central difference along the closed curve ``P(q ⊕ t qd)``
(``P``: ``robot.project_configuration``, least-norm Gauss-Newton, whose derivative on the manifold
is the projector onto its tangent space, so the curve's velocity at ``q`` is ``qd``), with ``G`` there
for the same split of the velocity columns (:func:`partition_map`): ``dM_r/dt`` and ``dG/dt``.
Measured:

- ``M_r`` symmetric positive definite;
- ``dM_r/dt - 2 C_r`` skew-symmetric and ``dM_r/dt == C_r + C_r^T`` (Spong Prop. 9.1 carried to the
  reduced model: with ``dM/dt = C + C^T`` of the tree, ``dM_r/dt = dG^T M G + G^T (C + C^T) G + G^T M dG``);
- ``C_r qd_i`` equal to the core's reduced bias less friction (so ``C_r`` is the Coriolis matrix of
  the numbers ``reduced_dynamics`` gives, not only some skew-consistent matrix);
- the energy balance ``dH/dt = qd . (tau - friction)`` at each state under a random torque, with
  ``qdd`` from ``robot.constrained_forward_dynamics`` and ``H`` the tree's energy (the loop forces do
  no work: ``J qd = 0``), ``dH/dt = qd^T M qdd + qd^T dM/dt qd / 2 + g . qd`` (Spong eq. 9.113 in its
  differential form).

Ball, planar and floating joints included: the independent velocity columns need not be whole
joints, since the curve is not held at them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..closed_loops import RANK_TOLERANCE
from ..property_checks import Check, PropertiesReport

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["check_closed_chain_properties", "partition_map"]


def _refuse(robot, why: str) -> ValueError:
    names = ", ".join(loop.name for loop in robot.loops)
    return ValueError(
        f"robot '{robot.name}' has closed loops ({names}): {why}; "
        "robot.equations_of_motion().check_properties() proves the properties on the symbolic reduced model "
        "(kinedyn check --prove)"
    )


def closed_states(robot: Robot, samples: int, rng: np.random.Generator) -> np.ndarray:
    """``samples`` closed configurations: random configurations projected onto the loops (starts
    from which Gauss-Newton does not close are drawn again, up to 20 per sample)."""
    found = []
    for _ in range(20 * samples):
        try:
            found.append(robot.project_configuration(robot.random_configuration(rng)))
        except ValueError:
            continue
        if len(found) == samples:
            return np.array(found)
    raise _refuse(robot, f"no closed configuration found from {20 * samples} random starts")


def check_closed_chain_properties(robot: Robot, samples: int = 200, seed: int = 0, h: float = 1e-6) -> PropertiesReport:
    """The checks of the module docstring on ``samples`` closed states drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    pool: list = []
    worst = dict(sym=0.0, skew=0.0, cct=0.0, bias=0.0, energy=0.0)
    least_eigenvalue, dof = np.inf, None
    done = skipped = 0
    while done < samples:
        if not pool:  # more closed states where singular ones were skipped
            pool = list(closed_states(robot, samples - done, rng))
        q = pool.pop()
        try:
            measured = _measure(robot, q, rng, h)
        except ValueError:  # the rank of J changes within h: a singular configuration of the mechanism
            skipped += 1
            if skipped > 20 * samples:
                raise _refuse(robot, f"{skipped} sampled closed states sit at singular configurations") from None
            continue
        done += 1
        dof = measured.pop("dof")
        if dof == 0:
            raise _refuse(robot, "the loops leave no degree of freedom: the reduced equations are empty")
        least_eigenvalue = min(least_eigenvalue, measured.pop("least_eigenvalue"))
        for key, value in measured.items():
            worst[key] = max(worst[key], value)
    tol_fd = 1e-6
    skipped_note = f"; {skipped} singular closed states (J's rank changing within h) drawn again" if skipped else ""
    along = f"central differences (step {10 * h:g}) along closed motions, {dof} independent velocity columns"
    checks = [
        Check(
            "M_r symmetric positive definite",
            bool(worst["sym"] <= 1e-12 and least_eigenvalue > 0),
            worst["sym"],
            1e-12,
            f"M_r = G^T M G at {samples} closed states: max |M_r - M_r^T| / max |M_r| = {worst['sym']:.2g}; "
            f"smallest eigenvalue {least_eigenvalue:.6g} > 0{skipped_note}",
            "Spong eq. 9.42 (reduced: Spong §9.4.4)",
            dict(min_eigenvalue=least_eigenvalue),
        ),
        Check(
            "dM_r/dt - 2C_r skew-symmetric",
            bool(worst["skew"] <= tol_fd),
            worst["skew"],
            tol_fd,
            f"max |N + N^T| / max(1, |dM_r/dt|), N = dM_r/dt - 2 C_r, C_r = G^T (M dG/dt + C G); {along}",
            "Spong Prop. 9.1, eq. 9.109, on the reduced model",
        ),
        Check(
            "dM_r/dt == C_r + C_r^T",
            bool(worst["cct"] <= tol_fd),
            worst["cct"],
            tol_fd,
            f"max |dM_r/dt - C_r - C_r^T| / max(1, |dM_r/dt|); {along}",
            "Spong eq. 9.110, on the reduced model",
        ),
        Check(
            "C_r qd_i == reduced bias",
            bool(worst["bias"] <= tol_fd),
            worst["bias"],
            tol_fd,
            "max |C_r qd_i - (bias - G^T friction)| / max(1, |.|): robot.reduced_dynamics' bias is C_r qd_i",
            "Spong eqs. 9.58-9.62, on the reduced model",
        ),
        Check(
            "energy balance dH/dt == qd . (tau - friction)",
            bool(worst["energy"] <= tol_fd),
            worst["energy"],
            tol_fd,
            f"at {samples} closed states under random torques, qdd from constrained_forward_dynamics, "
            "dH/dt = qd^T M qdd + qd^T (dM/dt) qd / 2 + g . qd; the loop forces do no work (J qd = 0)",
            "Spong eq. 9.113 (differential form)",
        ),
    ]
    return PropertiesReport(robot.name, samples, checks)


def partition_map(jac, independent) -> np.ndarray:
    """``G`` with ``qd = G qd_i`` for the velocity columns ``independent`` (``robot.reduced_dynamics``'
    map, here for a given split at any configuration): ``[1; -J_d^+ J_i]``. A ValueError where the
    dependent columns lose rank (a singular configuration within the step)."""
    n = jac.shape[1]
    dependent = [k for k in range(n) if k not in independent]
    tol = RANK_TOLERANCE * max(1.0, float(np.abs(jac).max()))
    if np.linalg.matrix_rank(jac[:, dependent], tol=tol) < np.linalg.matrix_rank(jac, tol=tol):
        raise ValueError("the dependent columns of the loop Jacobian lose rank here")
    G = np.zeros((n, len(independent)))
    G[independent, np.arange(len(independent))] = 1.0
    G[dependent] = -np.linalg.pinv(jac[:, dependent]) @ jac[:, independent]
    return G


def _measure(robot, q, rng, h) -> dict:
    """Each check's residual at one closed state (the module docstring)."""
    jac = robot.loop_jacobian(q)
    rank = int(
        np.linalg.matrix_rank(jac, tol=RANK_TOLERANCE * max(1.0, float(np.abs(jac).max())))
    )  # as reduced_dynamics counts
    dof = robot.n - rank
    if not dof:
        return dict(dof=0)
    qd_i = rng.uniform(-2.0, 2.0, dof)
    here = robot.reduced_dynamics(q, qd_i)  # the independent velocity columns chosen by pivoted QR of J
    qd, G, M_r, independent = here["qd"], here["G"], here["M"], list(here["independent"])
    # the closed curve through q with velocity qd: q ⊕ t qd projected onto the loops (least-norm
    # Gauss-Newton, whose derivative on the manifold is the projector onto its tangent space, so the
    # curve's velocity at q is qd), closed to 1e-14, a step of 10 h (the projection's error over 20 h
    # stays near 1e-9 of the derivative); G along it for the same split of the velocity columns
    ahead = robot.project_configuration(robot.integrate(q, qd, 10 * h), tolerance=1e-14)
    behind = robot.project_configuration(robot.integrate(q, qd, -10 * h), tolerance=1e-14)
    G_ahead, G_behind = (partition_map(robot.loop_jacobian(x), independent) for x in (ahead, behind))
    M_r_dot = (G_ahead.T @ robot.mass_matrix(ahead) @ G_ahead - G_behind.T @ robot.mass_matrix(behind) @ G_behind) / (
        20 * h
    )
    G_dot = (G_ahead - G_behind) / (20 * h)
    M = robot.mass_matrix(q)
    C_r = G.T @ (M @ G_dot + robot.coriolis_matrix(q, qd) @ G)
    scale = max(1.0, float(np.abs(M_r_dot).max()))
    N = M_r_dot - 2 * C_r
    sym = float(np.abs(M_r - M_r.T).max() / np.abs(M_r).max())
    least = float(np.linalg.eigvalsh(0.5 * (M_r + M_r.T))[0])
    skew = float(np.abs(N + N.T).max() / scale)
    cct = float(np.abs(M_r_dot - C_r - C_r.T).max() / scale)
    bias = here["bias"] - G.T @ robot.friction_torque(qd)
    bias_error = float(np.abs(C_r @ qd_i - bias).max() / max(1.0, float(np.abs(bias).max())))
    # energy balance under a random torque (tree energy; the loop forces do no work)
    tau = rng.uniform(-2.0, 2.0, robot.n)
    qdd, _ = robot.constrained_forward_dynamics(q, qd, tau)
    M_dot = (robot.mass_matrix(robot.integrate(q, qd, h)) - robot.mass_matrix(robot.integrate(q, qd, -h))) / (2 * h)
    power_in = qd @ (tau - robot.friction_torque(qd))
    dH = qd @ M @ qdd + 0.5 * qd @ M_dot @ qd + robot.gravity_torque(q) @ qd
    energy = abs(dH - power_in) / max(1.0, abs(power_in))
    return dict(sym=sym, skew=skew, cct=cct, bias=bias_error, energy=energy, least_eigenvalue=least, dof=dof)
