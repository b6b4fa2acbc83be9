"""A robot with closed loops (docs/closed-loops.md, "Motion"): the fixed-step schemes of
:mod:`.fixed_step` on the constrained forward dynamics, with the state projected back onto the loops'
manifold after every step and at every stage.

The method is the standard projection method for differential equations on a manifold (Hairer,
Lubich and Wanner, *Geometric Numerical Integration*, 2nd ed., section IV.4, Algorithm 4.2): one step
of the underlying scheme on the index-1 form ``qdd = constrained_forward_dynamics(q, qd, tau)``
(``J qdd + gamma = 0``, which holds the loops only up to the integrator's truncation error, so the
residual would drift), then ``q`` onto ``phi(q) = 0`` (``Robot.project_configuration``: Gauss-Newton,
least-norm steps) and ``qd`` onto ``J(q) qd = 0`` (``Robot.project_velocity``). The projection keeps
the scheme's order (the step's error is already of that order, and the projection moves the state by
no more than it), has no gain to tune (Baumgarte's stabilisation has two, and its drift depends on
them and on ``dt``), and leaves the residual at the Gauss-Newton tolerance at every step.

The stages are projected too before their dynamics are evaluated: the scheme then integrates the
vector field ``f(P(x))`` (``P`` the projection), which is smooth near the manifold, equals ``f`` on
it and leaves it invariant, so its exact flow from a closed state is the true motion and the scheme
keeps its order. Unprojected, a stage sits off the manifold by the truncation error, and near a
singular configuration (the Jacobian's smallest singular value ``s`` small: Spong's five-bar passing
its flat parallelogram) the loop force that error calls for grows as ``1/s^2``: the five-bar's free
fall in the report drifted by 2e-2 J at 1 ms, 4e-7 J with the stages projected. A loop whose rows
are redundant only on the manifold (the push-rod leg's planar loop on a turning trunk) has such a
direction everywhere off it, and the core refuses the unprojected stage as conflicting.

The dynamics run in the core, one call per stage; the loop is Python (the core's integrators take a
tree), so a step costs a few tenths of a millisecond."""

from __future__ import annotations

import numpy as np

from .errors import StopRun
from .fixed_step import run_each
from .lie_steps import GroupStep

__all__ = ["LOOP_METHODS", "run_closed_loops", "closed_start", "loop_forces", "project"]

# the schemes that take a projection after each step (the implicit scheme linearises the tree's dynamics)
LOOP_METHODS = ("rk4", "semi_implicit", "euler")

# The projection's tolerance on |residual| (m). Tighter than project_configuration's default 1e-12:
# a loop whose rows are redundant only where it is exactly closed (the push-rod leg's planar loop on
# a tumbling trunk: turning the trunk moves the two ends apart by omega x (p_a - p_b)) has a Jacobian
# whose smallest singular value is the residual itself, and a demand b along it of the residual
# times the velocities; at 1e-12 that demand (2e-13) is above what the constrained dynamics accept
# (1e-12 of |b|), and they refuse the state as conflicting. Gauss-Newton converges quadratically,
# so 1e-14 costs at most one more iteration; where rounding keeps a large mechanism above it, the
# default tolerance is taken instead.
TOLERANCE, FALLBACK = 1e-14, 1e-12


def project(robot, q, qd):
    """``(q, qd)`` projected onto the loops (``TOLERANCE``, else ``FALLBACK``) and their velocities."""
    try:
        q = np.asarray(robot.project_configuration(q, tolerance=TOLERANCE), dtype=float)
    except ValueError:
        q = np.asarray(robot.project_configuration(q, tolerance=FALLBACK), dtype=float)
    return q, np.asarray(robot.project_velocity(q, qd), dtype=float)


def closed_start(robot, q0, qd0):
    """``(q, qd)`` on the loops' manifold nearest the start, and how far each moved (max abs). A
    ValueError (the core's, naming the loop) when no closed configuration is near ``q0``."""
    q, qd = project(robot, q0, qd0)
    return q, qd, float(np.max(np.abs(q - q0), initial=0.0)), float(np.max(np.abs(qd - qd0), initial=0.0))


def closed_configuration(robot, q, tries: int = 20):
    """A regular closed configuration near ``q`` for a start that has none given (the command line's
    default): ``q`` and ``q`` plus deterministic offsets in [-1, 1] rad (a seeded generator), each
    projected; the first whose loop Jacobian has the largest rank among them. Zeros are often a
    singular configuration of a linkage (a four-bar stretched flat, Spong's five-bar folded), where
    the Jacobian loses rank and the constrained dynamics have no solution. A ValueError when none
    projects."""
    q = np.asarray(q, dtype=float)
    rng = np.random.default_rng(0)
    error, found = None, []
    for k in range(tries):
        start = q if k == 0 else q + rng.uniform(-1.0, 1.0, q.size)
        try:
            closed = np.asarray(robot.project_configuration(start), dtype=float)
        except ValueError as e:
            error = e
            continue
        found.append((int(np.linalg.matrix_rank(robot.loop_jacobian(closed), tol=1e-9)), closed))
    if not found:
        raise ValueError(
            f"robot '{robot.name}': no closed configuration found near {np.array2string(q, precision=4)} "
            f"({tries} starts); give a closed start (--q): {error}"
        )
    best = max(rank for rank, _ in found)
    return next(closed for rank, closed in found if rank == best)


def run_closed_loops(
    robot, fext_fn, method, q0, qd0, t0, dt, steps, torque_for, hold, every, max_speed, bar, batch, limits, deadline
):
    """The fixed-step run of :mod:`.fixed_step`, the acceleration the constrained one and a
    projection after each step (the module docstring)."""

    closed = {"q": q0}  # the last state projected onto the loops (the current step's start)

    def accel(t, q, qd, tau):
        try:
            if not np.array_equal(q, closed["q"]):  # a stage, off the loops by the truncation error
                q, qd = project(robot, q, qd)
            f = None if fext_fn is None else fext_fn(t, q, qd)
            return robot.constrained_forward_dynamics(q, qd, tau, f)[0]
        except ValueError as e:  # a singular configuration of the mechanism: the loops cannot all hold
            raise StopRun(dict(step=None, t=t, joint=None, kind="singular", value=None, message=str(e))) from None

    def onto_loops(k, t, q, qd):
        try:
            q, qd = project(robot, q, qd)
            closed["q"] = q
            return q, qd
        except ValueError as e:  # the step left the manifold's reach (a singular configuration)
            raise StopRun(dict(step=k, t=t, joint=None, kind="singular", value=None, message=str(e))) from None

    # ball, planar and floating joints: each stage moves q on its group (Lie-Euler, Munthe-Kaas RK4; :mod:`.lie_steps`)
    group = GroupStep(robot) if robot.has_multi_dof_joints else None

    def run_one(i):  # each state of a batch starts its own record of the last closed state
        closed["q"] = q0[i] if batch is not None else q0
        return torque_for(i)

    return run_each(accel, run_one, method, t0, dt, steps, q0, qd0, batch, every, max_speed, hold, bar, None,
                    limits, deadline, onto_loops, group)  # fmt: skip


def loop_forces(robot, fext_fn, t, Q, QD, TAU):
    """The loops' multipliers at the samples, one batched call: (S, m) or (N, S, m)."""
    lead = Q.shape[:-1]
    q, qd, tau = (a.reshape(-1, a.shape[-1]) for a in (Q, QD, TAU))
    f = None
    if fext_fn is not None:
        times = np.broadcast_to(t, lead).reshape(-1)
        f = np.stack([np.asarray(fext_fn(ti, a, b), dtype=float) for ti, a, b in zip(times, q, qd)])
    lam = np.asarray(robot.constrained_forward_dynamics(q, qd, tau, f)[1])
    return lam.reshape(*lead, lam.shape[-1])
