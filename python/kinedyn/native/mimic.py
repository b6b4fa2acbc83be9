"""The native model of a robot with mimic joints, seen in reduced coordinates.

:class:`ReducedModel` wraps the native ``_core.Model`` (built in full coordinates, every moving joint
a coordinate) and has the same methods and signatures, in the reduced coordinates of
:class:`kinedyn.description.mimic.MimicMap` (single states and (N, n) batches; ``out=``): so
``Robot``'s methods run unchanged on it. With the constant maps ``v_full = G v`` and
``q_full = expand(q)`` (G does not depend on q, so also ``qd_full = G qd`` and ``qdd_full = G qdd``):

- kinematics: the frame poses at ``q_full``; ``J_r = J G`` (a frame's twist is ``J qd_full = J G qd``);
  ``Jdot_r qd = Jdot G qd`` (G is constant); the kinematic Hessian by the chain rule,
  ``H_r[k, :, l] = sum_ij G[i, k] H[i, :, j] G[j, l]``.
- dynamics by the principle of virtual work (a generalised force ``tau`` on the full coordinates does
  the work ``tau . G dq`` on reduced ones): ``tau_r = G^T tau(q_full, G qd, G qdd)``, so
  ``M_r = G^T M G``, ``bias_r = G^T bias(q_full, G qd)``, ``g_r = G^T g``, ``C_r = G^T C G``, the
  Christoffel symbols ``c_r[i, j, k] = sum G[a, i] G[b, j] G[c, k] c[a, b, c]``, the regressor
  ``Y_r = G^T Y`` (the same inertial parameters), the followers' friction and rotor inertia included
  through ``G^T``. External wrenches act on links, as without mimic joints.
- ``C_r`` keeps the Christoffel property: ``M_r(q) = G^T M(expand(q)) G`` with ``d expand/dq = G``,
  so ``dM_r/dq_k = sum_a G[a, k] G^T (dM/dq_a) G`` and the Christoffel symbols of ``M_r`` are those of
  ``M`` contracted with G on each index, which is the formula above; hence ``dM_r/dt - 2 C_r =
  G^T (dM/dt - 2 C) G`` (along ``qd_full = G qd``), skew-symmetric because ``dM/dt - 2 C`` is.
- forward dynamics: ``qdd = M_r^-1 (tau_r - G^T tau(q_full, G qd, 0))`` by a Cholesky factorisation of
  ``M_r`` (not the articulated-body algorithm, which works on the tree's own coordinates, and the
  reduced robot is no longer a tree of independent joints); derivatives by the chain rule
  (``dtau_r/dq = G^T (dtau/dq) G``, the same for qd, and ``-M_r^-1`` times those for forward dynamics).
- energies, centre of mass and momentum: those of the full state.
"""

from __future__ import annotations

import numpy as np

from .._arrays import finite_result, real_array
from .._core import NonFiniteResultError
from ..description.mimic import MimicMap
from .mimic_loops import ReducedLoops

__all__ = ["ReducedModel"]


class ReducedModel(ReducedLoops):
    """``_core.Model`` in reduced coordinates (see the module). ``native``: the full model, with its
    loops; ``loops``: their (name, rows), for the errors that name one."""

    def __init__(self, native, coordinates: MimicMap, robot: str = "robot", loops: tuple = ()):
        self.loops = tuple(loops)
        self.native = native
        self.map = coordinates
        self.robot = robot
        self.G = coordinates.G

    # ------------------------------------------------------------------ shapes
    @property
    def n(self) -> int:
        return self.map.nv

    @property
    def nq(self) -> int:
        return self.map.nq

    @property
    def n_frames(self) -> int:
        return self.native.n_frames

    @property
    def link_bodies(self) -> np.ndarray:
        """The full model's body that carries each link (wrenches and inertial parameters belong to
        every link, mimic followers' too)."""
        return self.native.link_bodies

    # the core's methods a reduced model does not offer, refused by name through __getattr__ below:
    # loops and link origins come with the full model (native/compile.py), not after; the loops'
    # numbers are composed with G (:mod:`.mimic_loops`)
    refused = frozenset(("with_link_origins", "with_loops"))

    def __getattr__(self, name: str):
        # a method of the native model this wrapper does not map (added to the core after it): an
        # error naming it, never the full model's answer in the wrong coordinates
        if name.startswith("__") or name in ("native", "map", "robot", "G"):
            raise AttributeError(name)
        if callable(getattr(self.native, name, None)):
            raise NotImplementedError(
                f"robot '{self.robot}': '{name}' is not mapped to reduced mimic coordinates yet "
                "(kinedyn/native/mimic.py); load the robot with mimic='independent'"
            )
        raise AttributeError(f"'ReducedModel' object has no attribute '{name}'")

    def _arg(self, x, name: str, size: int, batch: int | None = None) -> np.ndarray:
        a = x if type(x) is np.ndarray and x.dtype == np.float64 else real_array(x, name)
        if a.shape[-1:] != (size,) or a.ndim > 2 or a.ndim < 1:
            raise ValueError(f"{name} must have shape ({size},) or a batch (N, {size}), got {a.shape}")
        if not np.isfinite(a).all():
            bad = np.flatnonzero(~np.isfinite(a.reshape(-1)))
            raise ValueError(f"{name} contains a non-finite value (NaN or inf) at index {bad[0] % size}")
        if batch is not None and a.ndim != batch:
            raise ValueError(
                f"{name} has shape {a.shape} but q has {'a batch' if batch == 2 else 'one state'} (shape {'(N, n)' if batch == 2 else '(n,)'})"
            )
        return a

    def _q(self, q) -> tuple:
        q = self._arg(q, "q", self.map.nq)
        with np.errstate(over="ignore", invalid="ignore"):
            full = self.map.expand_q(q)
        if not np.isfinite(full).all():
            raise ValueError(
                f"q is too large: a mimic follower's coordinate multiplier * q_leader + offset overflows float64 (robot '{self.robot}')"
            )
        return q, full

    def _v(self, v, name: str, q: np.ndarray) -> np.ndarray:
        v = self._arg(v, name, self.map.nv, q.ndim)
        if q.ndim == 2 and len(v) != len(q):
            raise ValueError(f"{name} has {len(v)} states but q has {len(q)}")
        return self.map.expand_v(v)

    @staticmethod
    def _out(result: np.ndarray, out: np.ndarray | None) -> np.ndarray:
        if out is None:
            return result
        if not isinstance(out, np.ndarray) or out.dtype != np.float64:
            raise TypeError(f"out must be a float64 NumPy array, got {type(out).__name__}")
        if out.shape != result.shape:
            raise ValueError(f"out must have shape {result.shape}, got {out.shape}")
        out[...] = result
        return out

    # G^T of finite but huge numbers can overflow: a NonFiniteResultError, never an inf returned
    def _left(self, tau: np.ndarray) -> np.ndarray:
        """G^T tau for (..., nv_full)."""
        out = tau @ self.G
        return out if np.isfinite(out).all() else finite_result(out, "G^T tau (mimic joints reduced)")

    def _both(self, A: np.ndarray) -> np.ndarray:
        """G^T A G for (..., nv_full, nv_full)."""
        out = self.G.T @ A @ self.G
        return out if np.isfinite(out).all() else finite_result(out, "G^T M G (mimic joints reduced)")

    # ------------------------------------------------------------------ kinematics
    def frame_poses(self, q, frames):
        return self.native.frame_poses(self._q(q)[1], frames)

    def frame_pose(self, q, frame):
        return self.native.frame_pose(self._q(q)[1], frame)

    def jacobian(self, q, frame, reference, point=None):
        return self.native.jacobian(self._q(q)[1], frame, reference, point) @ self.G

    def jacobian_hessian(self, q, frame, reference, point=None):
        H = self.native.jacobian_hessian(self._q(q)[1], frame, reference, point)  # (..., i, 6, j)
        return np.einsum("ik,...irj,jl->...krl", self.G, H, self.G)

    def frame_velocity(self, q, qd, frame, reference, point=None):
        q, qf = self._q(q)
        return self.native.frame_velocity(qf, self._v(qd, "qd", q), frame, reference, point)

    def jdot_qd(self, q, qd, frame, reference, point=None):
        q, qf = self._q(q)
        return self.native.jdot_qd(qf, self._v(qd, "qd", q), frame, reference, point)

    # ------------------------------------------------------------------ dynamics
    def inverse_dynamics(self, q, qd, qdd, f_ext=None, out=None):
        q, qf = self._q(q)
        tau = self.native.inverse_dynamics(qf, self._v(qd, "qd", q), self._v(qdd, "qdd", q), f_ext)
        return self._out(self._left(tau), out)

    def mass_matrix(self, q, out=None):
        return self._out(self._both(self.native.mass_matrix(self._q(q)[1])), out)

    def _cholesky(self, M: np.ndarray) -> np.ndarray:
        try:
            return np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            if np.abs(M).max() > 1e150:  # its factorisation squares the entries
                raise NonFiniteResultError(
                    f"robot '{self.robot}': the reduced mass matrix G^T M G has entries of "
                    f"{np.abs(M).max():.3g}, too large for float64 to factor"
                ) from None
            raise RuntimeError(
                "the reduced mass matrix G^T M G is singular or not positive definite "
                "(a massless leader with massless followers and no rotor inertia?)"
            ) from None

    def mass_matrix_inverse(self, q, out=None):
        L = self._cholesky(self.mass_matrix(q))
        eye = np.broadcast_to(np.eye(self.n), L.shape)
        Linv = np.linalg.solve(L, eye)
        return self._out(np.swapaxes(Linv, -1, -2) @ Linv, out)

    def _solve(self, M: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """M^-1 rhs (rhs (..., n) or (..., n, k)) by Cholesky."""
        L = self._cholesky(M)
        vector = rhs.ndim == M.ndim - 1
        b = rhs[..., None] if vector else rhs
        x = np.linalg.solve(np.swapaxes(L, -1, -2), np.linalg.solve(L, b))
        return x[..., 0] if vector else x

    def forward_dynamics(self, q, qd, tau, f_ext=None, out=None):
        q, qf = self._q(q)
        tau = self._arg(tau, "tau", self.n, q.ndim)
        qd_full = self._v(qd, "qd", q)
        drift = self._left(self.native.inverse_dynamics(qf, qd_full, np.zeros_like(qd_full), f_ext))
        M = self._both(self.native.mass_matrix(qf))
        with np.errstate(over="ignore", invalid="ignore"):  # checked below, as the core checks its own
            qdd = self._solve(M, tau - drift)
        qdd = finite_result(qdd, "forward_dynamics: qdd", batch_axes=qdd.ndim - 1)
        return self._out(qdd, out)

    def coriolis_matrix(self, q, qd, out=None):
        q, qf = self._q(q)
        return self._out(self._both(self.native.coriolis_matrix(qf, self._v(qd, "qd", q))), out)

    def christoffel(self, q):
        c = self.native.christoffel(self._q(q)[1])
        G = self.G
        return np.einsum("ai,bj,ck,...abc->...ijk", G, G, G, c, optimize=True)

    def gravity_torque(self, q, out=None):
        return self._out(self._left(self.native.gravity_torque(self._q(q)[1])), out)

    def bias_torque(self, q, qd, out=None):
        q, qf = self._q(q)
        return self._out(self._left(self.native.bias_torque(qf, self._v(qd, "qd", q))), out)

    def kinetic_energy(self, q, qd):
        q, qf = self._q(q)
        return self.native.kinetic_energy(qf, self._v(qd, "qd", q))

    def potential_energy(self, q):
        return self.native.potential_energy(self._q(q)[1])

    def inverse_dynamics_derivatives(self, q, qd, qdd, f_ext=None):
        q, qf = self._q(q)
        dq, dqd, M = self.native.inverse_dynamics_derivatives(qf, self._v(qd, "qd", q), self._v(qdd, "qdd", q), f_ext)
        return self._both(dq), self._both(dqd), self._both(M)

    def forward_dynamics_derivatives(self, q, qd, tau, f_ext=None):
        qdd = self.forward_dynamics(q, qd, tau, f_ext)
        dq, dqd, M = self.inverse_dynamics_derivatives(q, qd, qdd, f_ext)
        Minv = self.mass_matrix_inverse(q)
        return -Minv @ dq, -Minv @ dqd, Minv

    def regressor(self, q, qd, qdd):
        q, qf = self._q(q)
        Y = self.native.regressor(qf, self._v(qd, "qd", q), self._v(qdd, "qdd", q))
        return np.einsum("ai,...ap->...ip", self.G, Y)

    def centroidal_momentum_matrix(self, q):
        """A_G G: the momentum about the centre of mass is A_G qd_full = A_G G qd."""
        return self.native.centroidal_momentum_matrix(self._q(q)[1]) @ self.G

    def center_of_mass(self, q):
        return self.native.center_of_mass(self._q(q)[1])

    def momentum(self, q, qd):
        q, qf = self._q(q)
        return self.native.momentum(qf, self._v(qd, "qd", q))
