"""The configuration update of the Python fixed-step schemes (:mod:`.fixed_step`) on a robot whose
coordinates are not all angles: ball (spherical), planar or floating joints, where ``q`` (unit
quaternions, (cos, sin) pairs) and the velocity ``v`` differ in size and ``q + h v`` leaves the
configuration space.

Each stage moves ``q`` along the group: ``q ⊕ Ω``, the joint's pose times the exponential of the
tangent vector ``Ω`` (``Robot.integrate``, the core's ``lie_integrate``), so a quaternion stays unit
to rounding and no renormalisation is needed. RK4 becomes the Runge-Kutta-Munthe-Kaas method
(Munthe-Kaas, "High order Runge-Kutta methods on manifolds", Appl. Numer. Math. 29, 1999; Hairer,
Lubich and Wanner, *Geometric Numerical Integration*, 2nd ed., section IV.8.2, Algorithm 8.4): the
classical tableau applied to the chart ``Ω`` of ``q(t) = q_k ⊕ Ω(t)``, whose rate is
``dΩ/dt = dexp⁻¹_Ω(v)``. With ``⊕`` multiplying on the right and ``v`` in the moving frame,
``d/dt (q_k ⊕ Ω) = Jr(Ω) dΩ/dt`` (``Jr`` the right Jacobian of the exponential, Solà, Deray and
Atchuthan 2018, eq. 41), so ``dΩ/dt = Jr(Ω)⁻¹ v``, taken here exactly (``Robot.integrate``'s Jacobian
with respect to the step, the core's ``lie_integrate_jacobians``; the core's native RK4 uses the
series ``v + [Ω, v]/2 + [Ω, [Ω, v]]/12``, the same to fourth order). RKMK keeps the classical
method's order 4. Euler and semi-implicit Euler are the Lie-Euler method (``q ⊕ h v``, order 1; HLW
IV.8.1).

For 1-DOF joints ``q ⊕ Ω = q + Ω`` and ``Jr = 1``: the same numbers as the plain schemes."""

from __future__ import annotations

import numpy as np

from .._core import lie_integrate, lie_integrate_jacobians
from ..configuration import ConfigurationSpace

__all__ = ["GroupStep"]


class GroupStep:
    """``advance(q, v, h) = q ⊕ h v``, ``chart_rate(omega, v) = Jr(omega)⁻¹ v`` and the joint-limit
    stop on the 1-DOF joints of a robot with multi-DOF joints (the module docstring)."""

    def __init__(self, robot):
        self.space = ConfigurationSpace.of(robot)
        # each joint's block as the core's lie_* name it ("" for a 1-DOF joint); q and v come from the
        # integrator (checked once at the start), so the per-stage calls skip ConfigurationSpace's checks
        self.blocks = [
            b.joint.kind if b.joint.kind in ("floating", "spherical", "planar") else "" for b in self.space.blocks
        ]
        scalar = [b for b in self.space.blocks if b.joint.nq == 1]
        self.scalar_q = np.array([b.iq for b in scalar], dtype=np.intp)
        self.scalar_v = np.array([b.iv for b in scalar], dtype=np.intp)
        # the joint (index in robot.joint_names) of each q and each v coordinate, for failures
        blocks = self.space.blocks
        self.joint_of_q = np.concatenate([np.full(b.joint.nq, i) for i, b in enumerate(blocks)]).astype(np.intp)
        self.joint_of_v = np.concatenate([np.full(b.joint.nv, i) for i, b in enumerate(blocks)]).astype(np.intp)

    def advance(self, q: np.ndarray, v: np.ndarray, h: float) -> np.ndarray:
        return lie_integrate(self.blocks, q, h * v)

    def chart_rate(self, q: np.ndarray, omega: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``dΩ/dt`` of ``q ⊕ Ω(t)`` moving at ``v``: ``Jr(Ω)⁻¹ v`` (block diagonal, 1 on 1-DOF joints)."""
        jr = lie_integrate_jacobians(self.blocks, omega, 1.0)[1]
        return np.linalg.solve(jr, v)

    def clamp(self, q: np.ndarray, qd: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> tuple:
        """Inelastic stops on the 1-DOF joints (limits are per q coordinate; a multi-DOF joint has none)."""
        iq, iv = self.scalar_q, self.scalar_v
        x, v = q[iq], qd[iv]
        low, high = x <= lower[iq], x >= upper[iq]
        q, qd = q.copy(), qd.copy()
        q[iq] = np.where(low, lower[iq], np.where(high, upper[iq], x))
        qd[iv] = np.where(low, np.maximum(v, 0.0), np.where(high, np.minimum(v, 0.0), v))
        return q, qd
