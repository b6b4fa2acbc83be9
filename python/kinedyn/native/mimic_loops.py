"""Closed loops on a robot with reduced mimic joints (docs/closed-loops.md, "Mimic joints"): the loop
numbers of :class:`~kinedyn.native.mimic.ReducedModel`, composed from the full native model's.

The loops live on the full model (``_core.Model.with_loops``); with the constant map
``qd_full = G qd`` (a follower moves ``multiplier`` times its leader) they carry over by the chain
rule, as the reduced model's frame Jacobians do:

- the residual at ``q_full = expand(q)``; ``J_r = J G`` (``J_r qd = J qd_full``); ``gamma_r =
  dJ_r/dt qd = (dJ/dt) G qd = gamma(q_full, G qd)`` (G is constant);
- the constrained dynamics ``M_r qdd + h_r = tau + J_r^T lam``, ``J_r qdd + gamma_r = 0`` (``M_r = G^T
  M G``, ``h_r = G^T h``: the reduced model's own): the proximal method of multipliers of the core
  (Carpentier, Budhiraja and Mansard, RSS 2021), in NumPy: ``(A + mu 1) lam_{k+1} = b + mu lam_k``
  with ``A = J_r M_r^-1 J_r^T``, ``b = -(J_r qdd_free + gamma_r)``, ``mu = 1e-9`` of A's largest
  diagonal entry, until ``|A lam - b|`` is below 1e-12 of ``|b|`` (or its rounding floor); ``lam`` is
  the same loop force as without the mimic joints (the loops and frames are the full model's);
- inverse dynamics ``[S | J_r^T] (tau_a; lam) = M_r qdd + h_r`` by the SVD, the projections by
  Gauss-Newton on the residual with least-norm steps (``q + step``: the reduced coordinates are
  1-DOF joints; a reduced model with ball, planar or floating joints is refused by name).

These are NumPy loops over the states of a batch, not the core's SIMD lanes."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

__all__ = ["ReducedLoops"]

# the core's (crates/kinedyn-core/src/constraints): proximal weight, steps, accuracy; SVD rank
MU, MAX_ITER, ACCURACY, RANK_TOLERANCE = 1e-9, 200, 1e-12, 1e-10


class ReducedLoops:
    """The loop methods of ``_core.Model`` in reduced coordinates (mixed into ReducedModel, whose
    ``native``, ``map``, ``G``, ``_q``, ``_v``, ``_arg``, ``mass_matrix``, ``forward_dynamics`` and
    ``inverse_dynamics`` they use)."""

    loops: tuple  # (name, rows) of each loop, in the row order of the full model's

    if TYPE_CHECKING:  # ReducedModel's, which these methods use
        native: Any
        map: Any
        G: np.ndarray
        robot: str

        @property
        def n(self) -> int: ...

        def _q(self, q) -> tuple: ...

        def _v(self, v, name: str, q: np.ndarray) -> np.ndarray: ...

        def _arg(self, x, name: str, size: int, batch: int | None = None) -> np.ndarray: ...

        def mass_matrix(self, q, out=None) -> np.ndarray: ...

        def forward_dynamics(self, q, qd, tau, f_ext=None, out=None) -> np.ndarray: ...

        def inverse_dynamics(self, q, qd, qdd, f_ext=None, out=None) -> np.ndarray: ...

    def _loop_row(self, k: int) -> tuple:
        for name, rows in self.loops:
            if k < rows:
                return name, k
            k -= rows
        return "?", k

    def loop_residual(self, q):
        return self.native.loop_residual(self._q(q)[1])

    def loop_jacobian(self, q):
        return self.native.loop_jacobian(self._q(q)[1]) @ self.G

    def loop_gamma(self, q, qd):
        q, qf = self._q(q)
        return self.native.loop_gamma(qf, self._v(qd, "qd", q))

    # ------------------------------------------------------------------ dynamics
    def constrained_forward_dynamics(self, q, qd, tau, f_ext=None):
        """``[qdd; lam]`` (..., n + m), as the core returns it."""
        q = self._arg(q, "q", self.map.nq)
        if q.ndim == 2:
            qd, tau = (self._arg(x, name, self.n, 2) for x, name in ((qd, "qd"), (tau, "tau")))
            wrenches = [None] * len(q) if f_ext is None else np.asarray(f_ext, dtype=float)
            return np.stack([self._constrained_one(*s) for s in zip(q, qd, tau, wrenches)])
        return self._constrained_one(q, qd, tau, f_ext)

    def _constrained_one(self, q, qd, tau, f_ext):
        free = self.forward_dynamics(q, qd, tau, f_ext)
        jac, gamma = self.loop_jacobian(q), self.loop_gamma(q, qd)
        y = np.linalg.solve(self.mass_matrix(q), jac.T)  # M_r^-1 J_r^T
        a, b = jac @ y, -(jac @ free + gamma)
        scale = float(np.max(np.diag(a), initial=0.0))
        mu = MU * max(scale, np.finfo(float).tiny)
        factor = np.linalg.cholesky(a + mu * np.eye(len(b)))
        lam, size_b, residual = np.zeros(len(b)), float(np.abs(b).max(initial=0.0)), b
        for _ in range(MAX_ITER):
            new = np.linalg.solve(factor.T, np.linalg.solve(factor, b + mu * lam))
            residual, lam = mu * (lam - new), new  # A lam_new - b
            floor = 64 * np.finfo(float).eps * scale * float(np.abs(lam).max(initial=0.0))
            if np.abs(residual).max(initial=0.0) <= max(ACCURACY * size_b, floor):
                return np.concatenate([free + y @ lam, lam])
        name, row = self._loop_row(int(np.argmax(np.abs(residual))))
        raise ValueError(
            f"constrained forward dynamics: the loop constraints cannot all hold at this state (loop '{name}', "
            f"row {row}: J qdd + gamma = {residual[np.argmax(np.abs(residual))]:e} after {MAX_ITER} proximal steps): "
            "the loops conflict here (a singular configuration of the mechanism, or a state far from closed: "
            "project it first)"
        )

    def constrained_inverse_dynamics(self, q, qd, qdd, actuated, f_ext=None):
        q = self._arg(q, "q", self.map.nq)
        if q.ndim == 2:
            qd, qdd = (self._arg(x, name, self.n, 2) for x, name in ((qd, "qd"), (qdd, "qdd")))
            wrenches = [None] * len(q) if f_ext is None else np.asarray(f_ext, dtype=float)
            return np.stack([self._inverse_one(a, b, c, actuated, w) for a, b, c, w in zip(q, qd, qdd, wrenches)])
        return self._inverse_one(q, qd, qdd, actuated, f_ext)

    def _inverse_one(self, q, qd, qdd, actuated, f_ext):
        n, actuated = self.n, list(actuated)
        jac, gamma = self.loop_jacobian(q), self.loop_gamma(q, qd)
        qdd = np.asarray(qdd, dtype=float)
        violation = jac @ qdd + gamma
        size = float(np.abs(jac).max(initial=0.0) * np.abs(qdd).max(initial=0.0) + np.abs(gamma).max(initial=0.0))
        if violation.size and np.abs(violation).max() > 1e-8 * max(size, np.finfo(float).tiny):
            name, row = self._loop_row(int(np.argmax(np.abs(violation))))
            raise ValueError(
                f"constrained inverse dynamics: qdd does not keep loop '{name}' closed (row {row}: J qdd + gamma = "
                f"{violation[np.argmax(np.abs(violation))]:e}); a closed motion has J qdd + gamma = 0"
            )
        tau = self.inverse_dynamics(q, qd, qdd, f_ext)
        select = np.zeros((n, len(actuated)))
        select[actuated, np.arange(len(actuated))] = 1.0
        system = np.hstack([select, jac.T])
        u, s, vt = np.linalg.svd(system)
        kept = s > RANK_TOLERANCE * max(float(s.max(initial=0.0)), np.finfo(float).tiny)
        x = vt[: len(s)][kept].T @ ((u[:, : len(s)][:, kept].T @ tau) / s[kept])
        miss = system @ x - tau
        if np.abs(miss).max() > 1e-8 * max(float(np.abs(tau).max()), 1e-12):
            k = int(np.argmax(np.abs(miss)))
            raise ValueError(
                f"constrained inverse dynamics: the actuated joints cannot produce this motion (joint column {k} misses "
                f"{miss[k]:e} of torque that neither an actuator nor a loop force can give): actuate other joints"
            )
        null = vt[len(s) :] if vt.shape[0] > len(s) else np.zeros((0, vt.shape[1]))
        null = np.vstack([null, vt[: len(s)][~kept]])
        if len(null) and np.abs(null[:, : len(actuated)]).max() > 1e-6:
            raise ValueError(
                "constrained inverse dynamics: the actuated joints do not determine their torques (they can push "
                "against each other through a loop without moving it): actuate fewer joints"
            )
        out = np.zeros(n)
        np.add.at(out, actuated, x[: len(actuated)])
        return out

    # ------------------------------------------------------------------ projections
    def _scalar_only(self, feature: str) -> None:
        if self.map.nq != self.map.nv:
            raise ValueError(
                f"robot '{self.robot}': {feature} with reduced mimic joints steps q + dq, and this robot has ball, "
                "planar or floating joints: load it with mimic='independent'"
            )

    def project_configuration(self, q, hold, tolerance, max_iter):
        self._scalar_only("project_configuration")
        q = self._arg(q, "q", self.map.nq)
        if q.ndim == 2:
            return np.stack([self._project_one(x, hold, tolerance, max_iter) for x in q])
        return self._project_one(q, hold, tolerance, max_iter)

    def _project_one(self, q, hold, tolerance, max_iter):
        free = [k for k in range(self.n) if k not in set(hold)]
        current = np.array(q, dtype=float)
        r = self.loop_residual(current)
        size = float(np.abs(r).max(initial=0.0))
        for iteration in range(max_iter + 1):
            if size <= tolerance:
                return current
            if iteration == max_iter or not free:
                break
            step = np.zeros(self.n)
            step[free] = -np.linalg.lstsq(self.loop_jacobian(current)[:, free], r, rcond=RANK_TOLERANCE)[0]
            for halving in range(40):  # backtracking: halve the step until |r| decreases
                trial = current + 0.5**halving * step
                rt = self.loop_residual(trial)
                if np.abs(rt).max() < size:
                    current, r, size = trial, rt, float(np.abs(rt).max())
                    break
            else:
                break
        name, row = self._loop_row(int(np.argmax(np.abs(r))))
        held = " with the held joints fixed" if hold else ""
        raise ValueError(
            f"project_configuration: the loops do not close from this start{held} (loop '{name}', row {row}: residual "
            f"{r[np.argmax(np.abs(r))]:e} after Gauss-Newton, tolerance {tolerance:e}): the held joints or the geometry "
            "leave no closed configuration near it"
        )

    def project_velocity(self, q, qd):
        q = self._arg(q, "q", self.map.nq)
        qd = self._arg(qd, "qd", self.n, q.ndim)
        jac = self.loop_jacobian(q)
        return qd - np.einsum(
            "...ij,...j->...i", np.linalg.pinv(jac, rcond=RANK_TOLERANCE), np.einsum("...ij,...j->...i", jac, qd)
        )
