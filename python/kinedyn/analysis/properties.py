"""The properties of a robot's equations of motion that control design relies on (Spong §9.5),
each measured with its residual.

- M(q) symmetric positive definite (Spong eq. 9.42: K = qd^T M qd / 2 > 0 for qd != 0).
- Inertia bounds ``lambda_min I <= M(q) <= lambda_max I`` (Spong eqs. 9.119-9.120) from a global
  search over the configuration space (:func:`global_inertia_bounds`: multistart bounded truncated Newton (TNC) on the
  extreme eigenvalues with their analytic gradient d lambda / dq_k = v^T (dM/dq_k) v, dM/dq_k from the
  Christoffel symbols), reported with the configurations that attain them (for a revolute arm the
  bounds exist because M depends on q only through sines and cosines).
- Skew symmetry of ``dM/dt - 2C`` (Spong Prop. 9.1, eqs. 9.109-9.112) and ``dM/dt = C + C^T`` (which
  skew symmetry alone does not imply: a transposed C is also skew-consistent), dM/dt by central
  differences along qd (on the configuration manifold, q ⊕ t qd: :func:`mass_matrix_rate`).
- Passivity / energy balance (Spong eqs. 9.113-9.118): along a simulated trajectory
  ``int_0^T qd . tau dt = H(T) - H(0)`` (+ the energy friction dissipates).
- Linearity in the parameters (Spong §9.5.3, eq. 9.121): ``Y(q, qd, qdd) pi == tau`` (rigid-body
  part; rotor inertia and friction are separate known terms).

Robots with floating, spherical and planar joints (q of nq entries, qd of nv) are measured on their
configuration manifold: random configurations with uniformly distributed rotations, dM/dt along
q ⊕ t qd, the inertia bounds searched in the coordinates of :class:`~kinedyn.analysis.bounds.ManifoldChart`.

:func:`check_properties` measures these on the numeric engine (status "sampled", "searched" or
"simulated"); :func:`prove_properties` (``eom.check_properties()``) proves the identities of a symbolic
model by exact simplification (status "proved"), says "sampled" where simplification cannot decide
and random states find no counterexample, and "failed" with the state that shows a counterexample.

The results are :class:`Check` and :class:`PropertiesReport` (:mod:`kinedyn.property_checks`, beside the
inertia bounds' search, which the symbolic proofs share); the robot's chart of the search is :mod:`.bounds`,
the symbolic proofs :mod:`kinedyn.symbolic.derive.proofs`. This module measures a numeric robot
and keeps every name importable from ``kinedyn.analysis.properties``.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from ..property_checks import STATUSES, Check, InertiaBounds, PropertiesReport, global_inertia_bounds  # noqa: F401 (STATUSES: its old home)
from ..simulate import PDGravity, SimulationError, simulate
from ..simulate.control import Controller
from ..symbolic.derive.proofs import prove_properties
from .bounds import robot_inertia_bounds
from .closed_properties import check_closed_chain_properties

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = [
    "Check",
    "PropertiesReport",
    "InertiaBounds",
    "check_properties",
    "global_inertia_bounds",
    "mass_matrix_rate",
    "prove_properties",
]


def joint_pd_gravity(robot: Robot, kp: np.ndarray, kd: np.ndarray, goal: np.ndarray):
    """``tau = Kp (goal - q) - Kd qd + g(q)`` on the 1-DOF joints' coordinates, ``-Kd v + g`` on the
    multi-DOF joints' (damped, not steered: their error would need robot.difference at every step,
    20x the cost of the rest): the input of the passivity check on a robot with multi-DOF joints, whose
    q (nq) and qd (nv) do not line up."""
    iq, iv = [], []
    start_q = start_v = 0
    for j in robot.joints:
        if not j.is_multi_dof:
            iq.append(start_q)
            iv.append(start_v)
        start_q, start_v = start_q + j.nq, start_v + j.nv
    q_index, v_index = np.array(iq, dtype=np.intp), np.array(iv, dtype=np.intp)
    kp_joints = np.asarray(kp, dtype=float)[v_index]
    kd = np.asarray(kd, dtype=float)
    goal_joints = np.asarray(goal, dtype=float)[q_index]

    class JointPDGravity(Controller):
        name = "PD on the 1-DOF joints, damping on the multi-DOF joints, + gravity compensation"
        n = robot.nv

        def __call__(self, t, q, qd):
            tau = robot.gravity_torque(q) - kd * np.asarray(qd, dtype=float)
            tau[..., v_index] += kp_joints * (goal_joints - np.asarray(q, dtype=float)[..., q_index])
            return tau

    return JointPDGravity()


def without_coulomb_friction(robot: Robot) -> Robot:
    """``robot`` with every joint's Coulomb friction levels set to zero (viscous friction kept)."""
    links = [
        dataclasses.replace(link, joint=dataclasses.replace(link.joint, coulomb=0.0, coulomb_negative=None))
        for link in robot.description.links
    ]
    return robot.replace(links=links)


def mass_matrix_rate(robot: Robot, q, qd, h: float = 1e-6) -> np.ndarray:
    """dM/dt = d/dt M(q ⊕ t qd) at t = 0 by central differences (step ``h``), along the configuration
    manifold (robot.integrate): for 1-DOF joints M(q + t qd); with multi-DOF joints q has nq entries
    and qd nv, and a quaternion moves by q ⊗ Exp(t omega), not by adding rates to its entries.
    ``q`` (nq,) or (N, nq), ``qd`` (nv,) or (N, nv)."""
    return (robot.mass_matrix(robot.integrate(q, qd, h)) - robot.mass_matrix(robot.integrate(q, qd, -h))) / (2 * h)


def check_properties(
    robot: Robot,
    samples: int = 200,
    seed: int = 0,
    T: float = 2.0,
    dt: float = 1e-3,
    h: float = 1e-6,
    *,
    time_budget: float | None = None,
    progress: bool | None = False,
) -> PropertiesReport:
    """Measure every property on ``samples`` random states (seeded) and one simulated trajectory of
    ``T`` seconds (RK4, step ``dt``, PD + gravity compensation towards a random set point, gains
    ``Kp = wn^2 m_i``, ``Kd = 2 wn m_i`` with wn = 5 rad/s and m_i the least M_ii over the goal and 64
    configurations drawn from the seed). The trajectory depends on ``seed`` only, not on ``samples``.
    ``time_budget`` (seconds, default none) bounds the inertia-bound search: when it runs out, the
    bounds are those found so far and the check says "sampled", not "searched"; ``progress``: a bar
    on stderr over that search (None: on a terminal, when it runs over a second).

    The passivity check simulates the robot without its Coulomb friction: passivity is a property of
    the rigid-body dynamics (Spong eq. 9.113: dH/dt = qd . tau), and Coulomb friction's sign switches
    make the right-hand side discontinuous, so RK4 and the quadrature of the balance lose their order
    there and the residual measures the integrator, not the model. Viscous friction stays in the
    simulated dynamics (its dissipation is a smooth term of the balance); that every friction torque
    dissipates, ``qd . friction(qd) >= 0``, is checked on the sampled rates.

    A robot with closed loops is measured on its reduced equations at sampled closed states instead
    (:mod:`kinedyn.analysis.closed_properties`; ``T``, ``dt`` and ``time_budget`` do not apply)."""
    if robot.loops:  # the reduced equations at sampled closed states (kinedyn.analysis.closed_properties)
        return check_closed_chain_properties(robot, samples=samples, seed=seed, h=h)
    rng = np.random.default_rng(seed)
    n = robot.n
    if n == 0:
        raise ValueError(
            f"robot '{robot.name}' has no degrees of freedom (no moving joint): its equations of motion are "
            "empty and have no property to check (floating_base=True makes a lone body a free flyer)"
        )
    Q = robot.random_configuration(rng, size=samples)
    QD = rng.uniform(-2.0, 2.0, size=(samples, n))
    QDD = rng.uniform(-4.0, 4.0, size=(samples, n))
    checks = []

    # M symmetric positive definite (one native call for all samples)
    M = robot.mass_matrix(Q)
    scale = np.abs(M).max()
    sym = float(np.abs(M - np.swapaxes(M, 1, 2)).max() / scale)
    eig = np.linalg.eigvalsh(M)
    lo = eig[:, 0]
    checks.append(
        Check(
            "M symmetric positive definite",
            bool(sym <= 1e-12 and lo.min() > 0),
            sym,
            1e-12,
            f"max |M - M^T| / max |M| = {sym:.2g}; smallest eigenvalue {lo.min():.6g} > 0",
            "Spong eq. 9.42",
            dict(min_eigenvalue=float(lo.min())),
            status="sampled",
        )
    )
    # inertia bounds: a global search over the configurations (on the manifold with multi-DOF joints)
    b = robot_inertia_bounds(
        robot, samples=max(samples, 64), starts=8, seed=seed, time_budget=time_budget, progress=progress
    )
    checks.append(
        Check(
            "inertia bounds lambda_min I <= M(q) <= lambda_max I",
            bool(b.lambda_min > 0),
            float(max(0.0, -b.lambda_min)),
            0.0,
            b.describe() + f"; condition number <= {b.lambda_max / b.lambda_min:.4g}"
            if b.lambda_min > 0
            else b.describe(),
            "Spong eqs. 9.119-9.120",
            dict(
                lambda_min=b.lambda_min,
                lambda_max=b.lambda_max,
                q_lambda_min=b.q_lambda_min,
                q_lambda_max=b.q_lambda_max,
                sampled_min=b.sampled_min,
                sampled_max=b.sampled_max,
                condition_number=float(b.lambda_max / b.lambda_min) if b.lambda_min > 0 else float("inf"),
                searches=b.searched,
                searches_planned=b.planned,
            ),
            status="searched" if b.complete else "sampled",
        )
    )

    # dM/dt - 2C skew, dM/dt == C + C^T (central differences along qd, on the manifold: q ⊕ t qd)
    C = robot.coriolis_matrix(Q, QD)
    Mdot = mass_matrix_rate(robot, Q, QD, h)
    N = Mdot - 2 * C
    ref = max(1.0, float(np.abs(Mdot).max()))
    skew = float(np.abs(N + np.swapaxes(N, 1, 2)).max() / ref)
    cct = float(np.abs(Mdot - C - np.swapaxes(C, 1, 2)).max() / ref)
    tol_fd = 1e-6
    checks.append(
        Check(
            "dM/dt - 2C skew-symmetric",
            bool(skew <= tol_fd),
            skew,
            tol_fd,
            f"max |N + N^T| / max(1, |dM/dt|) with N = dM/dt - 2C, dM/dt by central differences (h = {h:g})"
            + (
                " along q ⊕ t qd (robot.integrate: quaternions turned by Exp, not added to)"
                if robot.has_multi_dof_joints
                else ""
            ),
            "Spong Prop. 9.1, eq. 9.109",
            status="sampled",
        )
    )
    checks.append(
        Check(
            "dM/dt == C + C^T",
            bool(cct <= tol_fd),
            cct,
            tol_fd,
            "max |dM/dt - C - C^T| / max(1, |dM/dt|)",
            "Spong eq. 9.110",
        )
    )
    # neither identity sees a transposed C; the velocity product does
    cqd = np.einsum("skj,sj->sk", C, QD)
    h_minus_g = robot.bias_torque(Q, QD) - robot.gravity_torque(Q)
    cq = float(np.abs(cqd - h_minus_g).max() / max(1.0, float(np.abs(h_minus_g).max())))
    checks.append(
        Check(
            "C(q, qd) qd == Coriolis/centrifugal torque",
            bool(cq <= 1e-10),
            cq,
            1e-10,
            "max |C qd - (rnea(q, qd, 0) - g)| / max(1, |.|): C is the Christoffel matrix of these dynamics (a transposed C passes the two identities above)",
            "Spong eqs. 9.58-9.62",
        )
    )

    # linearity in the parameters
    tau = robot.inverse_dynamics(Q, QD, QDD)
    Y = robot.regressor(Q, QD, QDD)
    pi = robot.inertial_parameters()
    rigid = tau - robot.armature * QDD - robot.friction_torque(QD)
    lin = float(np.abs(np.einsum("skp,p->sk", Y, pi) - rigid).max() / max(1.0, float(np.abs(rigid).max())))
    checks.append(
        Check(
            "linearity in the parameters Y pi == tau",
            bool(lin <= 1e-10),
            lin,
            1e-10,
            f"max |Y pi - tau_rigid| / max(1, |tau|) over {samples} states; Y is {n} x {10 * n}",
            "Spong §9.5.3, eq. 9.121",
        )
    )

    # friction only dissipates: qd . friction(qd) >= 0 at every sampled rate (and 0 at rest)
    friction_power = np.einsum("si,si->s", QD, robot.friction_torque(QD))
    least = float(friction_power.min()) if friction_power.size else 0.0
    worst = max(0.0, -least)
    checks.append(
        Check(
            "friction dissipates: qd . friction(qd) >= 0",
            bool(worst == 0.0),
            worst,
            0.0,
            f"least qd . friction(qd) over {samples} sampled rates: {least:.6g} W "
            "(viscous and Coulomb levels >= 0 take energy out, never put it in)",
            "Spong eq. 9.118 (friction as a passive, dissipative term)",
        )
    )

    # passivity / energy balance along a simulated trajectory, from a stream of its own: the
    # trajectory depends on the seed only, not on how many samples were drawn above
    rng_trajectory = np.random.default_rng([seed, 1])
    goal = robot.random_configuration(rng_trajectory)
    x0 = np.concatenate(
        [robot.random_configuration(rng_trajectory), rng_trajectory.uniform(-1.0, 1.0, n)]
    )  # q (nq), qd (nv)
    # gains from the smallest inertia each joint shows (at the goal and 64 seeded configurations): each
    # joint's loop at most a critically damped 5 rad/s one, so a configuration where an axis carries
    # little inertia (elbow_3r upright) does not make the loop too stiff for RK4 at dt
    configurations = np.vstack([goal[None, :], robot.random_configuration(rng_trajectory, size=64)])
    d = np.min([np.diag(robot.mass_matrix(qc)) for qc in configurations], axis=0)
    wn = 5.0
    name = "passivity: int qd . tau dt == H(T) - H(0) + dissipated"
    coulomb = bool(np.any(robot.coulomb > 0) or np.any(robot.coulomb_negative > 0))
    simulated = without_coulomb_friction(robot) if coulomb else robot  # see the docstring
    tol_p = 1e-6
    # the residual is RK4's truncation error (O(dt^4)) plus the quadrature's: where it is above the
    # tolerance at dt (a fast passage, e.g. elbow_3r spinning about its axis when upright), the same
    # trajectory is integrated again at dt/2 and dt/4 before the check fails
    step = dt
    for refinement in range(3):
        try:
            if (
                robot.has_multi_dof_joints
            ):  # PD on the 1-DOF joints only (q and qd do not line up); RK4 as the detail says
                traj = simulate(
                    simulated,
                    T,
                    x0,
                    controller=joint_pd_gravity(simulated, wn**2 * d, 2 * wn * d, goal),
                    dt=step,
                    method="rk4",
                )
            else:
                traj = simulate(simulated, T, x0, controller=PDGravity(simulated, wn**2 * d, 2 * wn * d, goal), dt=step)
        except (SimulationError, RuntimeError, np.linalg.LinAlgError) as e:
            checks.append(
                Check(name, False, float("inf"), 0.0, f"the simulation failed: {e}", "Spong eqs. 9.113-9.117")
            )
            return PropertiesReport(robot.name, samples, checks)
        bal = traj.energy_balance()
        if bal["relative"] <= tol_p or refinement == 2:
            break
        step /= 2
    dt = step
    checks.append(
        Check(
            name,
            bool(bal["relative"] <= tol_p),
            bal["relative"],
            tol_p,
            f"{T:g} s of RK4 at dt = {dt:g} s under PD + gravity compensation: work {bal['work'][-1]:.6g} J, dH {bal['dH'][-1]:.6g} J, "
            f"friction {bal['dissipated'][-1]:.6g} J"
            + (
                "; simulated without Coulomb friction (its sign switches make RK4 and the quadrature first order; "
                "its dissipation is the check above)"
                if coulomb
                else ""
            ),
            "Spong eqs. 9.113-9.117",
            dict(work=float(bal["work"][-1]), dH=float(bal["dH"][-1]), dissipated=float(bal["dissipated"][-1])),
            status="simulated",
        )
    )
    return PropertiesReport(robot.name, samples, checks)
