"""Controllers and reference trajectories for :func:`kinedyn.simulate`.

A controller is any callable ``tau = controller(t, q, qd)``; ``q`` and ``qd`` are (n,) or, when a
batch of initial states is simulated, (N, n). The classes below accept both.

Control laws (``e = q_d - q``, ``ed = qd_d - qd``):

- :class:`PD`: ``tau = Kp e + Kd ed``.
- :class:`PDGravity`: ``tau = Kp e + Kd ed + g(q)`` (Takegaki & Arimoto 1981; Spong, Hutchinson &
  Vidyasagar, *Robot Modeling and Control*, "PD control revisited" / ch. 8-9). For a constant set
  point and Kp, Kd symmetric positive definite, ``V = 1/2 qd^T M(q) qd + 1/2 e^T Kp e`` has
  ``dV/dt = qd^T (tau - C qd - g) + 1/2 qd^T dM/dt qd - qd^T Kp e = -qd^T Kd qd <= 0`` (using the
  skew symmetry of ``dM/dt - 2C``); by LaSalle's invariance principle the state converges to
  ``(q_d, 0)``. Friction only adds dissipation.
- :class:`ComputedTorque`: ``tau = M(q) (qdd_d + Kd ed + Kp e) + C(q, qd) qd + g(q) + friction(qd)``
  (inverse dynamics / feedback linearisation, Spong et al. "inverse dynamics control"); with an
  exact model the error obeys ``ed' + Kd ed + Kp e = 0``. Evaluated by one recursive Newton-Euler
  call, ``tau = rnea(q, qd, a)`` with ``a = qdd_d + Kd ed + Kp e``. ``model=`` uses another robot
  (e.g. identified parameters) as the controller's model.
- :class:`FunctionController`: wraps any callable.

References (each ``ref(t) -> (q_d, qd_d, qdd_d)``, ``t`` a number or an array (T,) giving (T, n)):

- :class:`Cubic` and :class:`Quintic` point-to-point polynomials with zero boundary velocities (and
  accelerations for the quintic) (Spong et al. §5.5 / Craig ch. 7), holding the end point after ``T``.
- :class:`Fourier`: finite Fourier series excitation (Swevers, Ganseman, Tukel, De Schutter & Van
  Brussel, "Optimal robot excitation and identification", IEEE T-RA 13(5), 1997, eq. 4):
  ``q_i(t) = q_i0 + sum_l a_il / (wf l) sin(wf l t) - b_il / (wf l) cos(wf l t)``, periodic with
  period ``2 pi / wf``, so that measurements can be averaged over periods.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = [
    "Controller",
    "PD",
    "PDGravity",
    "ComputedTorque",
    "FunctionController",
    "Reference",
    "Constant",
    "Cubic",
    "Quintic",
    "Fourier",
    "as_reference",
    "make_controller",
]


# ------------------------------------------------------------------ references
class Reference:
    """A desired motion: ``ref(t) -> (q, qd, qdd)``."""

    n: int

    def __call__(self, t):
        raise NotImplementedError

    def sample(self, t) -> tuple:
        """(q, qd, qdd) at the times ``t`` (T,), each (T, n)."""
        t = np.asarray(t, dtype=float)
        return self(t)


class Constant(Reference):
    """A set point: ``q_d`` constant, ``qd_d = qdd_d = 0``."""

    def __init__(self, q):
        self.q = np.asarray(q, dtype=float)
        self.n = self.q.size

    def __call__(self, t):
        shape = np.shape(t) + (self.n,)
        return np.broadcast_to(self.q, shape).copy(), np.zeros(shape), np.zeros(shape)


class _PointToPoint(Reference):
    def __init__(self, q0, q1, T: float, t0: float = 0.0):
        self.q0 = np.asarray(q0, dtype=float)
        self.q1 = np.asarray(q1, dtype=float)
        if self.q0.shape != self.q1.shape or self.q0.ndim != 1:
            raise ValueError(
                f"q0 and q1 must be vectors of the same length, got shapes {self.q0.shape} and {self.q1.shape}"
            )
        if not T > 0:
            raise ValueError(f"the duration T must be positive, got {T}")
        self.n = self.q0.size
        self.T = float(T)
        self.t0 = float(t0)

    def _profile(self, s):
        raise NotImplementedError

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        s = np.clip((t - self.t0) / self.T, 0.0, 1.0)
        inside = ((t - self.t0) > 0) & ((t - self.t0) < self.T)
        p, dp, ddp = self._profile(s)
        dp = np.where(inside, dp, 0.0) / self.T
        ddp = np.where(inside, ddp, 0.0) / self.T**2
        dq = self.q1 - self.q0
        return (self.q0 + p[..., None] * dq, dp[..., None] * dq, ddp[..., None] * dq)


class Cubic(_PointToPoint):
    """Cubic from q0 (at t0) to q1 (at t0 + T), zero velocity at both ends: s(u) = 3u^2 - 2u^3."""

    def _profile(self, s):
        return 3 * s**2 - 2 * s**3, 6 * s - 6 * s**2, 6 - 12 * s


class Quintic(_PointToPoint):
    """Quintic from q0 to q1 in T, zero velocity and acceleration at both ends:
    s(u) = 10u^3 - 15u^4 + 6u^5."""

    def _profile(self, s):
        return 10 * s**3 - 15 * s**4 + 6 * s**5, 30 * s**2 - 60 * s**3 + 30 * s**4, 60 * s - 180 * s**2 + 120 * s**3


class Fourier(Reference):
    """Finite Fourier series (Swevers et al. 1997): ``a``, ``b`` (n, L) coefficients, base angular
    frequency ``wf`` [rad/s], offsets ``q0`` (n,).

    ``Fourier.random(n, harmonics, wf, amplitude, q0, seed)`` draws coefficients and scales each
    joint so that its excursion from q0 is at most ``amplitude`` (rad or m)."""

    def __init__(self, a, b, wf: float, q0=None):
        self.a = np.atleast_2d(np.asarray(a, dtype=float))
        self.b = np.atleast_2d(np.asarray(b, dtype=float))
        if self.a.shape != self.b.shape:
            raise ValueError(f"a and b must have the same shape (n, harmonics), got {self.a.shape} and {self.b.shape}")
        if not wf > 0:
            raise ValueError(f"the base frequency wf must be positive, got {wf}")
        self.n, self.harmonics = self.a.shape
        self.wf = float(wf)
        self.q0 = np.zeros(self.n) if q0 is None else np.asarray(q0, dtype=float)

    @property
    def period(self) -> float:
        return 2 * np.pi / self.wf

    @classmethod
    def random(cls, n: int, harmonics: int = 5, wf: float = 2 * np.pi * 0.1, amplitude=0.8, q0=None, seed=0) -> Fourier:
        rng = np.random.default_rng(seed)
        a = rng.normal(size=(n, harmonics))
        b = rng.normal(size=(n, harmonics))
        ref = cls(a, b, wf, q0)
        t = np.linspace(0.0, ref.period, 2001)
        excursion = np.abs(ref(t)[0] - ref.q0).max(axis=0)
        scale = np.broadcast_to(np.asarray(amplitude, dtype=float), (n,)) / np.maximum(excursion, 1e-12)
        return cls(a * scale[:, None], b * scale[:, None], wf, q0)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        l = np.arange(1, self.harmonics + 1)
        w = self.wf * l  # (L,)
        wt = t[..., None] * w  # (..., L)
        s, c = np.sin(wt), np.cos(wt)
        # q_i = q_i0 + sum_l a_il/(wf l) sin(wf l t) - b_il/(wf l) cos(wf l t)
        q = self.q0 + (s / w) @ self.a.T - (c / w) @ self.b.T
        qd = c @ self.a.T + s @ self.b.T
        qdd = (-s * w) @ self.a.T + (c * w) @ self.b.T
        return q, qd, qdd


def as_reference(ref, n: int) -> Reference:
    """A Reference from a Reference, a callable ``t -> (q, qd, qdd)`` or a constant vector."""
    if isinstance(ref, Reference) or callable(ref):
        return ref
    q = np.asarray(ref, dtype=float)
    if q.shape != (n,):
        raise ValueError(f"a set point needs {n} values, got shape {q.shape}")
    if not np.all(np.isfinite(q)):
        raise ValueError("the set point contains NaN or inf")
    return Constant(q)


# ------------------------------------------------------------------ controllers
def _gain(K, n: int, what: str) -> np.ndarray:
    K = np.asarray(K, dtype=float)
    if K.ndim == 0:
        K = K * np.eye(n)
    elif K.ndim == 1:
        if K.size != n:
            raise ValueError(f"{what} needs {n} diagonal entries, got {K.size}")
        K = np.diag(K)
    if K.shape != (n, n):
        raise ValueError(f"{what} must be a scalar, {n} diagonal gains or an {n}x{n} matrix, got shape {K.shape}")
    if not np.all(np.isfinite(K)):
        raise ValueError(f"{what} contains a non-finite gain (NaN or inf)")
    return K


class Controller:
    """Base class: ``tau = controller(t, q, qd)``; ``reset()`` before a run."""

    name = "controller"

    def __call__(self, t, q, qd):
        raise NotImplementedError

    def reset(self) -> None:
        pass

    def describe(self) -> str:
        return self.name


class PD(Controller):
    """``tau = Kp (q_d - q) + Kd (qd_d - qd)``; ``reference``: a set point or a Reference."""

    name = "PD"

    def __init__(self, kp, kd, reference, n: int | None = None):
        if n is None:
            n = np.asarray(reference).size if not callable(reference) else reference.n
        self.n = n
        self.Kp = _gain(kp, n, "Kp")
        self.Kd = _gain(kd, n, "Kd")
        self.reference = as_reference(reference, n)

    def errors(self, t, q, qd):
        qr, qdr, qddr = self.reference(t)
        return qr - q, qdr - qd, qddr

    def __call__(self, t, q, qd):
        e, ed, _ = self.errors(t, q, qd)
        return e @ self.Kp.T + ed @ self.Kd.T

    def jacobian(self, t, q, qd):
        """``(dtau/dq, dtau/dqd) = (-Kp, -Kd)`` at one state: what the implicit integrator needs to
        stay stable under stiff gains."""
        return -self.Kp, -self.Kd


class PDGravity(PD):
    """``tau = Kp e + Kd ed + g(q)`` with ``g`` from ``robot`` (or ``model``, another robot)."""

    name = "PD + gravity compensation"

    def __init__(self, robot, kp, kd, reference, model=None):
        super().__init__(kp, kd, reference, n=robot.n)
        self.model = model if model is not None else robot

    def __call__(self, t, q, qd):
        return super().__call__(t, q, qd) + self.model.gravity_torque(q)

    def jacobian(self, t, q, qd):
        """``(-Kp + dg/dq, -Kd)``; ``dg/dq`` is the analytical ``dtau/dq`` of inverse dynamics at rest."""
        zero = np.zeros_like(np.asarray(q, dtype=float))
        dg = self.model.inverse_dynamics_derivatives(q, zero, zero)[0]
        return dg - self.Kp, -self.Kd


class ComputedTorque(PD):
    """``tau = rnea_model(q, qd, qdd_d + Kd ed + Kp e)``: exact linearisation with an exact model."""

    name = "computed torque"

    def __init__(self, robot, kp, kd, reference, model=None):
        super().__init__(kp, kd, reference, n=robot.n)
        self.model = model if model is not None else robot

    def __call__(self, t, q, qd):
        e, ed, qddr = self.errors(t, q, qd)
        a = qddr + e @ self.Kp.T + ed @ self.Kd.T
        a = np.broadcast_to(a, np.shape(q))
        return self.model.inverse_dynamics(q, qd, np.ascontiguousarray(a))

    def jacobian(self, t, q, qd):
        """``tau = rnea(q, qd, a)`` with ``a = qdd_d + Kd (qd_d - qd) + Kp (q_d - q)``:
        ``dtau/dq = drnea/dq - M Kp``, ``dtau/dqd = drnea/dqd - M Kd`` (analytical derivatives)."""
        e, ed, qddr = self.errors(t, q, qd)
        a = np.ascontiguousarray(qddr + e @ self.Kp.T + ed @ self.Kd.T)
        dq, dqd, M = self.model.inverse_dynamics_derivatives(q, qd, a)
        return dq - M @ self.Kp, dqd - M @ self.Kd


class FunctionController(Controller):
    """Any callable ``fn(t, q, qd) -> tau``."""

    def __init__(self, fn: Callable, name: str = "user"):
        if not callable(fn):
            raise TypeError(f"a controller must be callable as fn(t, q, qd), got {type(fn).__name__}")
        self.fn = fn
        self.name = name

    def __call__(self, t, q, qd):
        return self.fn(t, q, qd)


def make_controller(robot, kind: str, *, q_goal=None, kp=None, kd=None, T: float = 2.0, q0=None) -> Controller:
    """Controllers by name for the command line: ``pd``, ``pdg`` (PD + gravity compensation),
    ``ct`` (computed torque along a quintic from q0 to q_goal in T), ``none``.
    Default gains: Kp = 100, Kd = 20 (computed torque: critically damped, wn = 10 rad/s)."""
    n = robot.n
    q_goal = np.zeros(n) if q_goal is None else np.asarray(q_goal, dtype=float)
    kind = kind.lower().replace("-", "_")
    kp = 100.0 if kp is None else kp
    kd = 20.0 if kd is None else kd
    if kind == "pd":
        return PD(kp, kd, q_goal, n=n)
    if kind in ("pdg", "pd_gravity", "pd+g", "pd_g"):
        return PDGravity(robot, kp, kd, q_goal)
    if kind in ("ct", "computed_torque"):
        start = np.zeros(n) if q0 is None else np.asarray(q0, dtype=float)
        return ComputedTorque(robot, kp, kd, Quintic(start, q_goal, T))
    raise ValueError(f"unknown controller '{kind}' (pd, pdg, ct, none)")
