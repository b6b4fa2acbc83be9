"""Identification of the base inertial parameters from (simulated) measurements.

The torques are linear in the inertial parameters (Spong §9.5.3): ``tau_rigid = Y(q, qd, qdd) pi``.
Stacking the samples gives the observation matrix ``W`` and ``y = W pi``; only the base parameters
``pi_base = G pi`` are identifiable (Gautier & Khalil, "Direct calculation of minimum set of inertial
parameters of serial robots", IEEE T-RA 6(3), 1990; numerically Gautier 1991, as in
:meth:`kinedyn.Robot.base_parameters`), so ``y = W_base pi_base``.

- Excitation: a finite Fourier series per joint (Swevers et al., IEEE T-RA 13(5), 1997), periodic,
  so data can be taken over whole periods (:func:`excitation`).
- Measurements: q, qd, qdd sampled along the reference and ``tau = rnea(q, qd, qdd)`` plus Gaussian
  noise of standard deviation ``noise`` per joint (:func:`simulate_measurements`).
- Estimation: ordinary least squares ``pi_hat = argmin |W pi - y|``, and weighted least squares with
  each joint's rows divided by its noise level estimated from the OLS residuals (Gautier & Poignet,
  "Extended Kalman filtering and weighted least squares dynamic identification of robot", Control
  Eng. Practice 9(12), 2001). Covariance ``sigma^2 (W^T W)^-1`` (``(W^T S^-1 W)^-1`` weighted) gives a
  standard deviation per estimate; ``cond(W)`` measures how well the excitation separates them.
- The drive terms (rotor inertia ``r^2 J_m qdd``, friction) are taken as known and subtracted.
- Estimates plug back into a model: :meth:`Identification.robot` returns a Robot whose base
  parameters are the estimates (the nominal robot's parameters corrected by the minimum-norm change
  ``pi = pi_0 + G^+ (pi_hat - G pi_0)``), and :meth:`Identification.predict` the torques.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional

import numpy as np

from ..simulate.control import Fourier

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..dynamics import BaseParameters
    from ..robot import Robot

__all__ = ["Measurements", "Identification", "excitation", "simulate_measurements", "identify", "with_inertial_parameters"]


@dataclass
class Measurements:
    """Samples (S,) / (S, n): t, q, qd, qdd, measured torques ``tau`` and the noise-free ``tau_true``."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    tau_true: np.ndarray
    noise: np.ndarray


@dataclass
class Identification:
    """Result of :func:`identify` (all per base parameter unless noted)."""

    names: tuple
    estimates: np.ndarray
    std: np.ndarray
    covariance: np.ndarray
    true_values: Optional[np.ndarray]
    condition_number: float
    residual_rms: np.ndarray  # per joint
    weighted: bool
    base: BaseParameters = field(repr=False)
    nominal: Robot = field(repr=False)
    #: base parameters left out because their regressor columns vanish on the data (round-off level)
    dropped: tuple = ()
    #: which rows of ``base`` the estimates are for (None: all of them)
    used: Optional[np.ndarray] = field(default=None, repr=False)

    def _rows(self) -> np.ndarray:
        """Indices of the rows of ``base`` the estimates are for."""
        return np.arange(len(self.base.indices)) if self.used is None else self.used

    @property
    def errors(self) -> Optional[np.ndarray]:
        """estimates - true values (if the true values are known)."""
        return None if self.true_values is None else self.estimates - self.true_values

    @property
    def relative_errors(self) -> Optional[np.ndarray]:
        if self.true_values is None:
            return None
        return np.abs(self.estimates - self.true_values) / np.maximum(np.abs(self.true_values), 1e-12 * max(1.0, np.abs(self.true_values).max()))

    def predict(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """Torques of the identified model (base regressor times estimates plus the known drives)."""
        Y = self.nominal.regressor(q, qd, qdd)[..., self.base.indices[self._rows()]]
        return Y @ self.estimates + self.nominal.armature * np.asarray(qdd) + self.nominal.friction_torque(qd)

    def robot(self):
        """A :class:`kinedyn.Robot` with these base parameters (see the module docstring). Raises
        ValueError if the corrected parameters are not physically valid (e.g. a negative mass)."""
        G = self.base.grouping[self._rows()]
        pi0 = self.nominal.inertial_parameters()
        pi = pi0 + np.linalg.pinv(G) @ (self.estimates - G @ pi0)
        return with_inertial_parameters(self.nominal, pi)

    def to_dict(self) -> dict:
        d = dict(
            names=list(self.names), estimates=self.estimates, std=self.std, condition_number=self.condition_number,
            residual_rms=self.residual_rms, weighted=self.weighted, dropped=list(self.dropped),
        )
        if self.true_values is not None:
            errors = self.estimates - self.true_values
            d.update(true_values=self.true_values, errors=errors, max_abs_error=float(np.abs(errors).max()),
                     max_error_in_std=float(np.abs(errors / self.std).max()) if np.all(self.std > 0) else None)
        return d

    def _repr_html_(self) -> str:  # notebooks: estimates, std and errors as a table (kinedyn.display)
        from ..display import identification_html

        return identification_html(self)

    def __str__(self) -> str:
        lines = [f"{len(self.names)} base parameters, cond(W) = {self.condition_number:.4g}, {'weighted' if self.weighted else 'ordinary'} least squares"]
        for k, nm in enumerate(self.names):
            s = f"  {nm:<22} {self.estimates[k]: .8g} +- {self.std[k]:.2g}"
            if self.true_values is not None:
                s += f"   true {self.true_values[k]: .8g}   error {self.estimates[k] - self.true_values[k]: .2g}"
            lines.append(s)
        return "\n".join(lines)


def excitation(robot: Robot, harmonics: int = 5, period: float = 10.0, amplitude=0.6, q0: Optional[ArrayLike] = None, seed: int = 0) -> Fourier:
    """A random Fourier excitation for ``robot`` (Swevers et al. 1997): ``harmonics`` harmonics of
    the base frequency 2 pi / period, each joint's excursion ``amplitude`` about ``q0`` (default: the
    middle of finite joint limits, else 0)."""
    if q0 is None:
        lo, hi = robot.lower_limits, robot.upper_limits
        finite = np.isfinite(lo) & np.isfinite(hi)
        q0 = np.zeros(robot.n)
        q0[finite] = (lo[finite] + hi[finite]) / 2  # (-inf + inf) would be NaN
    return Fourier.random(robot.n, harmonics=harmonics, wf=2 * np.pi / period, amplitude=amplitude, q0=q0, seed=seed)


def simulate_measurements(robot: Robot, reference, T: Optional[float] = None, rate: float = 100.0, noise=0.0, seed: int = 0) -> Measurements:
    """Sample ``reference`` at ``rate`` Hz over ``T`` seconds (default: two periods of a Fourier
    reference) and measure torques by inverse dynamics (one native batch call) plus Gaussian noise of
    standard deviation ``noise`` (scalar or per joint, N m / N)."""
    if T is None:
        T = 2 * getattr(reference, "period", 10.0)
    if not rate > 0 or not T > 0:
        raise ValueError(f"rate and T must be positive, got rate={rate}, T={T}")
    t = np.arange(int(round(T * rate))) / rate
    q, qd, qdd = (np.ascontiguousarray(a) for a in reference(t))
    tau_true = robot.inverse_dynamics(q, qd, qdd)
    sigma = np.broadcast_to(np.asarray(noise, dtype=float), (robot.n,)).copy()
    if np.any(sigma < 0):
        raise ValueError(f"noise standard deviations must be >= 0, got {noise}")
    rng = np.random.default_rng(seed)
    tau = tau_true + rng.normal(size=tau_true.shape) * sigma
    return Measurements(t, q, qd, qdd, tau, tau_true, sigma)


def identify(robot: Robot, data: Measurements, weighted: bool = False, base=None) -> Identification:
    """Least-squares estimates of ``robot``'s base parameters from ``data`` (``robot`` gives the
    kinematics, the known drive terms and, for comparison, the true values)."""
    base = robot.base_parameters() if base is None else base
    n = robot.n
    S = data.q.shape[0]
    Y = robot.regressor(data.q, data.qd, data.qdd)[..., base.indices]  # (S, n, b)
    y = data.tau - robot.armature * data.qdd - robot.friction_torque(data.qd)  # (S, n)
    b = base.count
    if S * n <= b:
        raise ValueError(f"{S} samples x {n} joints = {S * n} equations cannot determine {b} base parameters")
    W = Y.reshape(S * n, b)
    yv = y.reshape(S * n)
    # a base column that is round-off noise on the data carries no information: leave it out
    norms = np.linalg.norm(W, axis=0)
    used = norms > 1e-9 * norms.max()
    dropped = tuple(nm for nm, u in zip(base.names, used) if not u)
    W = W[:, used]
    b = int(used.sum())
    est, *_ = np.linalg.lstsq(W, yv, rcond=None)
    r = (yv - W @ est).reshape(S, n)
    dof = S * n - b
    if weighted:
        # per-joint noise variance from the OLS residuals, then rows scaled by 1 / sigma_j
        sig = np.sqrt((r**2).sum(axis=0) / max(S - b / n, 1.0))
        sig = np.where(sig > 0, sig, max(float(sig.max()), 1e-300))
        w = np.tile(1.0 / sig, S)
        Ww = W * w[:, None]
        est, *_ = np.linalg.lstsq(Ww, yv * w, rcond=None)
        r = (yv - W @ est).reshape(S, n)
        rw = (r / sig).reshape(-1)
        s2 = float(rw @ rw) / dof
        cov = s2 * np.linalg.pinv(Ww.T @ Ww)
        cond = float(np.linalg.cond(Ww))
    else:
        s2 = float((r**2).sum()) / dof
        cov = s2 * np.linalg.pinv(W.T @ W)
        cond = float(np.linalg.cond(W))
    return Identification(
        names=tuple(nm for nm, u in zip(base.names, used) if u), estimates=est, std=np.sqrt(np.maximum(np.diag(cov), 0.0)), covariance=cov,
        true_values=np.asarray(base.values, dtype=float)[used], condition_number=cond, residual_rms=np.sqrt((r**2).mean(axis=0)),
        weighted=weighted, base=base, nominal=robot, dropped=dropped, used=used,
    )


def with_inertial_parameters(robot: Robot, pi: ArrayLike) -> Robot:
    """A copy of ``robot`` whose moving bodies have the standard parameters ``pi`` (10 n, about each
    body-frame origin, as :meth:`Robot.inertial_parameters`); fixed links merged into a moving body
    carry zero inertia in the copy. ValueError for physically invalid parameters."""
    from ..description.inertia import Inertia
    from ..description.link import Link

    pi = np.asarray(pi, dtype=float).reshape(robot.n, 10)
    bodies = {b.name: k for k, b in enumerate(robot.tree.bodies)}
    moving_descendant = set()
    parents = {l.name: l.parent for l in robot.links}
    for link in robot.links:
        p, moved = link.parent, False
        while p is not None and p in parents:
            if p in bodies:
                moved = True
                break
            p = parents[p]
        if moved and not link.joint.is_moving:
            moving_descendant.add(link.name)
    links = []
    for link in robot.links:
        if link.name in bodies:
            m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = pi[bodies[link.name]]
            Io = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
            if abs(m) < 1e-12:
                if np.abs([hx, hy, hz]).max() > 1e-9:
                    raise ValueError(f"body '{link.name}': zero mass with a non-zero first moment {[hx, hy, hz]}")
                body_inertia = Inertia(0.0, (0.0, 0.0, 0.0), Io)
            else:
                c = np.array([hx, hy, hz]) / m
                S = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
                Ic = Io + m * S @ S  # I_c = I_o + m [c]x [c]x
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    try:
                        body_inertia = Inertia(m, tuple(c), 0.5 * (Ic + Ic.T))
                    except ValueError as e:
                        raise ValueError(f"body '{link.name}': {e}") from None
            check = body_inertia.consistency()
            if check is not None and not check.positive:  # a Robot would only warn (inertia policy)
                raise ValueError(f"body '{link.name}': {check.describe()}")
            post = np.asarray(link.post, dtype=float)
            inv = np.eye(4)
            inv[:3, :3] = post[:3, :3].T
            inv[:3, 3] = -post[:3, :3].T @ post[:3, 3]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                link = Link(link.name, link.parent, link.joint, link.placement, link.post, body_inertia.transformed(inv))
        elif link.name in moving_descendant:
            link = Link(link.name, link.parent, link.joint, link.placement, link.post, Inertia())
        links.append(link)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return robot.replace(links=links)
