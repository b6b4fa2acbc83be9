"""``method="auto"``: RK4, or the linearly implicit Euler step where RK4 would be unstable at ``dt``
(the stiffness measured on the linearised dynamics at the initial state)."""

from __future__ import annotations

import numpy as np

from ..native.compile import dof_links

__all__ = ["RK4_STABLE", "choose_method"]

#: ``method="auto"`` keeps RK4 while ``dt`` times the largest eigenvalue modulus of the linearised
#: dynamics stays below this; RK4's stability region reaches 2.79 on the negative real axis and 2.83
#: on the imaginary axis (Hairer & Wanner, *Solving ODEs II*, §IV.2, Fig. 2.1), so this leaves a margin
#: for the stiffness growing along the run.
RK4_STABLE = 2.0


def choose_method(robot, q0, qd0, t0, dt, jacobian, names) -> tuple:
    """``method="auto"``: RK4 unless ``dt |lambda|max`` of the linearised dynamics
    ``J = [[0, I], [dqdd/dq, dqdd/dqd]]`` (analytical derivatives; the controller's gains included
    when it has ``jacobian``) exceeds :data:`RK4_STABLE` at an initial state, else the implicit
    step. Returns (method, reason)."""
    states = [(q0, qd0)] if q0.ndim == 1 else list(zip(q0[:16], qd0[:16]))
    n = qd0.shape[-1]
    if n == 0:
        return "rk4", "auto: rk4 (the robot has no degrees of freedom)"
    worst, joint = 0.0, None
    for q, qd in states:
        try:
            A_q, A_v, Minv = robot.forward_dynamics_derivatives(q, qd, np.zeros(n))
        except (RuntimeError, ValueError):
            return "rk4", "auto: rk4 (the linearised dynamics are not available at the initial state)"
        if jacobian is not None:
            K = jacobian(t0, q, qd)
            if K is not None:
                A_q, A_v = A_q + Minv @ K[0], A_v + Minv @ K[1]
        J = np.block([[np.zeros((n, n)), np.eye(n)], [A_q, A_v]])
        lam, vec = np.linalg.eig(J)
        i = int(np.argmax(np.abs(lam)))
        if abs(lam[i]) > worst:
            worst = float(abs(lam[i]))
            joint = int(np.argmax(np.abs(vec[:n, i]) + np.abs(vec[n:, i]) / max(worst, 1e-300)))
            joint = int(dof_links(robot.description)[joint])  # a degree of freedom -> its joint
    stiffness = dt * worst
    if stiffness <= RK4_STABLE:
        return "rk4", f"auto: rk4 (dt |lambda|max = {stiffness:.3g} <= {RK4_STABLE:g}, inside RK4's stability region)"
    return "implicit", (
        f"auto: implicit Euler, because RK4 at dt = {dt:g} s would be unstable: dt |lambda|max = {stiffness:.3g} > {RK4_STABLE:g} "
        f"(stiffest mode at joint '{names[joint]}'; |lambda|max = {worst:.3g} 1/s); RK4 would need dt < {RK4_STABLE / worst:.2g} s"
    )
