"""Data for identification: simulated measurements along an excitation, and the validation of an
identified model on a log (measured against predicted torques).

- Excitation: a finite Fourier series per joint (Swevers et al., IEEE T-RA 13(5), 1997), periodic,
  so data can be taken over whole periods (:func:`excitation`).
- Measurements: q, qd, qdd sampled along the reference and ``tau = rnea(q, qd, qdd)`` plus Gaussian
  noise of standard deviation ``noise`` per joint (:func:`simulate_measurements`).
- A log's torques aligned with its positions by a delay (:func:`aligned`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..simulate.control import Fourier
from .estimators import shift_torques

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..robot import Robot

__all__ = ["Measurements", "Validation", "excitation", "simulate_measurements", "aligned"]


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
class Validation:
    """Measured and predicted torques on a log, with the RMS error and R^2 per joint."""

    t: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    source: str = "<data>"

    @property
    def residuals(self) -> np.ndarray:
        return self.measured - self.predicted

    @property
    def rms(self) -> np.ndarray:
        return np.sqrt(np.mean(self.residuals**2, axis=0))

    @property
    def r2(self) -> np.ndarray:
        """1 - SS_res / SS_tot per joint (1: perfect; 0: no better than the mean torque)."""
        centred = self.measured - self.measured.mean(axis=0)
        total = np.sum(centred**2, axis=0)
        return 1.0 - np.sum(self.residuals**2, axis=0) / np.maximum(total, 1e-300)

    def to_dict(self) -> dict:
        return dict(source=self.source, samples=int(len(self.t)), rms=self.rms, r2=self.r2)

    def plot(self):
        """A matplotlib Figure: per joint, measured and predicted torque over time, and the residual."""
        from matplotlib.figure import Figure  # matplotlib loads only when a figure is drawn

        n = self.measured.shape[1]
        fig = Figure(figsize=(9, 1.8 * n + 0.5))
        axes = fig.subplots(n, 2, squeeze=False, sharex=True)
        for j in range(n):
            ax, rx = axes[j]
            ax.plot(self.t, self.measured[:, j], lw=0.8, label="measured")
            ax.plot(self.t, self.predicted[:, j], lw=0.8, ls="--", label="predicted")
            ax.set_ylabel(f"tau{j + 1}")
            ax.set_title(f"joint {j + 1}: RMS {self.rms[j]:.3g}, R² {self.r2[j]:.4f}", fontsize=8)
            rx.plot(self.t, self.residuals[:, j], lw=0.6, color="C3")
            rx.set_ylabel("residual")
        axes[0, 0].legend(fontsize=7)
        axes[-1, 0].set_xlabel("t (s)")
        axes[-1, 1].set_xlabel("t (s)")
        fig.tight_layout()
        return fig


def excitation(
    robot: Robot, harmonics: int = 5, period: float = 10.0, amplitude=0.6, q0: ArrayLike | None = None, seed: int = 0
) -> Fourier:
    """A random Fourier excitation for ``robot`` (Swevers et al. 1997): ``harmonics`` harmonics of
    the base frequency 2 pi / period, each joint's excursion ``amplitude`` about ``q0`` (default: the
    middle of finite joint limits, else 0)."""
    robot.require_one_dof_joints("an excitation trajectory (one Fourier series per joint coordinate)")
    if q0 is None:
        lo, hi = robot.lower_limits, robot.upper_limits
        finite = np.isfinite(lo) & np.isfinite(hi)
        q0 = np.zeros(robot.n)
        q0[finite] = (lo[finite] + hi[finite]) / 2  # (-inf + inf) would be NaN
    return Fourier.random(robot.n, harmonics=harmonics, wf=2 * np.pi / period, amplitude=amplitude, q0=q0, seed=seed)


def simulate_measurements(
    robot: Robot, reference, T: float | None = None, rate: float = 100.0, noise=0.0, seed: int = 0
) -> Measurements:
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


def aligned(data, delay: float, edge: int | None = None):
    """A copy of ``data`` (Log or Measurements) with its torques read at ``t + delay`` and ``edge``
    samples (default: those the shift reads past) dropped at each end."""
    t = np.asarray(data.t, dtype=float)
    if edge is None:
        edge = int(np.ceil(abs(delay) / float(np.median(np.diff(t))))) + 1
    if 2 * edge >= len(t) - 10:
        raise ValueError(f"a delay of {delay:g} s leaves too few samples of the {len(t)} in the data")
    sl = slice(edge, len(t) - edge)
    tau = shift_torques(t, np.asarray(data.tau, dtype=float), delay)
    changes: dict = {k: np.asarray(getattr(data, k))[sl] for k in ("t", "q", "qd", "qdd")}
    changes["tau"] = tau[sl]
    if isinstance(data, Measurements):
        changes["tau_true"] = np.asarray(data.tau_true)[sl]
    elif data.filtered_sign is not None:
        changes["filtered_sign"] = data.filtered_sign[sl]
        changes["window"] = data.subset(sl.start, sl.stop)
    return replace(data, **changes)
