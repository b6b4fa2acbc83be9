"""The properties of a robot's equations of motion that control design relies on (Spong §9.5),
each measured with its residual.

- M(q) symmetric positive definite (Spong eq. 9.42: K = qd^T M qd / 2 > 0 for qd != 0).
- Inertia bounds ``lambda_min I <= M(q) <= lambda_max I`` (Spong eqs. 9.119-9.120), measured over
  sampled configurations with the worst ones reported (for a revolute arm the bounds exist because
  M depends on q only through sines and cosines).
- Skew symmetry of ``dM/dt - 2C`` (Spong Prop. 9.1, eqs. 9.109-9.112) and ``dM/dt = C + C^T`` (which
  skew symmetry alone does not imply: a transposed C is also skew-consistent), dM/dt by central
  differences along qd.
- Passivity / energy balance (Spong eqs. 9.113-9.118): along a simulated trajectory
  ``int_0^T qd . tau dt = H(T) - H(0)`` (+ the energy friction dissipates).
- Linearity in the parameters (Spong §9.5.3, eq. 9.121): ``Y(q, qd, qdd) pi == tau`` (rigid-body
  part; rotor inertia and friction are separate known terms).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional

import numpy as np

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["Check", "PropertiesReport", "check_properties"]


@dataclass
class Check:
    """One property: ``passed`` when ``residual <= tolerance``; ``detail`` says what was measured."""

    name: str
    passed: bool
    residual: float
    tolerance: float
    detail: str = ""
    source: str = ""
    data: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return dict(name=self.name, passed=self.passed, residual=self.residual, tolerance=self.tolerance, detail=self.detail, source=self.source, **self.data)


@dataclass
class PropertiesReport:
    robot: str
    samples: int
    checks: list

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def __getitem__(self, name: str) -> Check:
        for c in self.checks:
            if c.name == name or c.name.startswith(name):
                return c
        raise KeyError(f"no check named '{name}' (checks: {[c.name for c in self.checks]})")

    def to_dict(self) -> dict:
        return dict(robot=self.robot, samples=self.samples, passed=self.passed, checks=[c.to_dict() for c in self.checks])

    def _repr_html_(self) -> str:  # notebooks: the checks as a table (kinedyn.display)
        from ..display import properties_html

        return properties_html(self)

    def __str__(self) -> str:
        lines = [f"properties of '{self.robot}' over {self.samples} sampled states:"]
        for c in self.checks:
            mark = "ok  " if c.passed else "FAIL"
            lines.append(f"  [{mark}] {c.name}: residual {c.residual:.3g} (tolerance {c.tolerance:.3g}); {c.detail}")
        return "\n".join(lines)


def check_properties(robot: Robot, samples: int = 200, seed: int = 0, T: float = 2.0, dt: float = 1e-3, h: float = 1e-6) -> PropertiesReport:
    """Measure every property on ``samples`` random states (seeded) and one simulated trajectory of
    ``T`` seconds (RK4, step ``dt``, PD + gravity compensation towards a random set point, gains
    ``Kp = wn^2 m_i``, ``Kd = 2 wn m_i`` with wn = 5 rad/s and m_i the least M_ii over the goal and 64
    configurations drawn from the seed). The trajectory depends on ``seed`` only, not on ``samples``."""
    from ..simulate import PDGravity, SimulationError, simulate

    rng = np.random.default_rng(seed)
    n = robot.n
    Q = robot.random_configuration(rng, size=samples)
    QD = rng.uniform(-2.0, 2.0, size=(samples, n))
    QDD = rng.uniform(-4.0, 4.0, size=(samples, n))
    checks = []

    # M symmetric positive definite; inertia bounds (one native call for all samples)
    M = robot.mass_matrix(Q)
    scale = np.abs(M).max()
    sym = float(np.abs(M - np.swapaxes(M, 1, 2)).max() / scale)
    eig = np.linalg.eigvalsh(M)
    lo, hi = eig[:, 0], eig[:, -1]
    kmin, kmax = int(np.argmin(lo)), int(np.argmax(hi))
    checks.append(Check(
        "M symmetric positive definite", bool(sym <= 1e-12 and lo.min() > 0), sym, 1e-12,
        f"max |M - M^T| / max |M| = {sym:.2g}; smallest eigenvalue {lo.min():.6g} > 0", "Spong eq. 9.42",
        dict(min_eigenvalue=float(lo.min())),
    ))
    checks.append(Check(
        "inertia bounds lambda_min I <= M(q) <= lambda_max I", bool(lo.min() > 0), float(max(0.0, -lo.min())), 0.0,
        f"lambda_min = {lo.min():.6g} at q = {np.array2string(Q[kmin], precision=3)}, lambda_max = {hi.max():.6g} at q = "
        f"{np.array2string(Q[kmax], precision=3)}; worst condition number {float((hi / lo).max()):.4g}",
        "Spong eqs. 9.119-9.120",
        dict(lambda_min=float(lo.min()), lambda_max=float(hi.max()), q_lambda_min=Q[kmin], q_lambda_max=Q[kmax], condition_number=float((hi / lo).max())),
    ))

    # dM/dt - 2C skew, dM/dt == C + C^T (central differences along qd)
    C = robot.coriolis_matrix(Q, QD)
    Mdot = (robot.mass_matrix(Q + h * QD) - robot.mass_matrix(Q - h * QD)) / (2 * h)
    N = Mdot - 2 * C
    ref = max(1.0, float(np.abs(Mdot).max()))
    skew = float(np.abs(N + np.swapaxes(N, 1, 2)).max() / ref)
    cct = float(np.abs(Mdot - C - np.swapaxes(C, 1, 2)).max() / ref)
    tol_fd = 1e-6
    checks.append(Check(
        "dM/dt - 2C skew-symmetric", bool(skew <= tol_fd), skew, tol_fd,
        f"max |N + N^T| / max(1, |dM/dt|) with N = dM/dt - 2C, dM/dt by central differences (h = {h:g})", "Spong Prop. 9.1, eq. 9.109",
    ))
    checks.append(Check(
        "dM/dt == C + C^T", bool(cct <= tol_fd), cct, tol_fd, "max |dM/dt - C - C^T| / max(1, |dM/dt|)", "Spong eq. 9.110",
    ))
    # neither identity sees a transposed C; the velocity product does
    cqd = np.einsum("skj,sj->sk", C, QD)
    h_minus_g = robot.bias_torque(Q, QD) - robot.gravity_torque(Q)
    cq = float(np.abs(cqd - h_minus_g).max() / max(1.0, float(np.abs(h_minus_g).max())))
    checks.append(Check(
        "C(q, qd) qd == Coriolis/centrifugal torque", bool(cq <= 1e-10), cq, 1e-10,
        "max |C qd - (rnea(q, qd, 0) - g)| / max(1, |.|): C is the Christoffel matrix of these dynamics (a transposed C passes the two identities above)",
        "Spong eqs. 9.58-9.62",
    ))

    # linearity in the parameters
    tau = robot.inverse_dynamics(Q, QD, QDD)
    Y = robot.regressor(Q, QD, QDD)
    pi = robot.inertial_parameters()
    rigid = tau - robot.armature * QDD - robot.friction_torque(QD)
    lin = float(np.abs(np.einsum("skp,p->sk", Y, pi) - rigid).max() / max(1.0, float(np.abs(rigid).max())))
    checks.append(Check(
        "linearity in the parameters Y pi == tau", bool(lin <= 1e-10), lin, 1e-10,
        f"max |Y pi - tau_rigid| / max(1, |tau|) over {samples} states; Y is {n} x {10 * n}", "Spong §9.5.3, eq. 9.121",
    ))

    # passivity / energy balance along a simulated trajectory, from a stream of its own: the
    # trajectory depends on the seed only, not on how many samples were drawn above
    rng_trajectory = np.random.default_rng([seed, 1])
    goal = robot.random_configuration(rng_trajectory)
    x0 = np.concatenate([robot.random_configuration(rng_trajectory), rng_trajectory.uniform(-1.0, 1.0, n)])
    # gains from the smallest inertia each joint shows (at the goal and 64 seeded configurations): each
    # joint's loop at most a critically damped 5 rad/s one, so a configuration where an axis carries
    # little inertia (elbow_3r upright) does not make the loop too stiff for RK4 at dt
    configurations = np.vstack([goal[None, :], robot.random_configuration(rng_trajectory, size=64)])
    d = np.min([np.diag(robot.mass_matrix(qc)) for qc in configurations], axis=0)
    wn = 5.0
    name = "passivity: int qd . tau dt == H(T) - H(0) + dissipated"
    coulomb = bool(np.any(robot.coulomb > 0) or np.any(robot.coulomb_negative > 0))
    tol_p = 1e-3 if coulomb else 1e-6
    # the residual is RK4's truncation error (O(dt^4)) plus the quadrature's: where it is above the
    # tolerance at dt (a fast passage, e.g. elbow_3r spinning about its axis when upright), the same
    # trajectory is integrated again at dt/2 and dt/4 before the check fails
    step = dt
    for refinement in range(3):
        try:
            traj = simulate(robot, T, x0, controller=PDGravity(robot, wn**2 * d, 2 * wn * d, goal), dt=step)
        except (SimulationError, RuntimeError, np.linalg.LinAlgError) as e:
            checks.append(Check(name, False, float("inf"), 0.0, f"the simulation failed: {e}", "Spong eqs. 9.113-9.117"))
            return PropertiesReport(robot.name, samples, checks)
        bal = traj.energy_balance()
        if bal["relative"] <= tol_p or refinement == 2:
            break
        step /= 2
    dt = step
    checks.append(Check(
        name, bool(bal["relative"] <= tol_p), bal["relative"], tol_p,
        f"{T:g} s of RK4 at dt = {dt:g} s under PD + gravity compensation: work {bal['work'][-1]:.6g} J, dH {bal['dH'][-1]:.6g} J, "
        f"friction {bal['dissipated'][-1]:.6g} J" + ("; Coulomb friction's sign switches limit the quadrature" if coulomb else ""),
        "Spong eqs. 9.113-9.117",
        dict(work=float(bal["work"][-1]), dH=float(bal["dH"][-1]), dissipated=float(bal["dissipated"][-1])),
    ))
    return PropertiesReport(robot.name, samples, checks)
