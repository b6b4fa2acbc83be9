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
- Drive terms. Friction: known and subtracted, or estimated per joint (:mod:`.friction`). Rotor
  inertia: the armature ``a_j = r_j^2 J_m,j`` adds ``a_j qdd_j`` to joint j's torque (it sits on
  M's diagonal), linear in ``a_j`` like the link parameters. For a log, every joint whose model has
  a gear ratio or a rotor inertia gets a regressor column ``qdd_j`` (in joint j's row) beside the
  link columns, and the base parameters are found for the whole set
  (:func:`base_parameters_with_rotors`): a rotor column can be a combination of link columns (the
  first joint about a fixed vertical axis: ``a_1`` and link 1's ``Izz`` only ever act as
  ``Izz + a_1``), and is then grouped into those base parameters, not estimated on its own.
- Estimates plug back into a model: :meth:`Identification.robot` returns a Robot whose base
  parameters are the estimates (the nominal robot's parameters corrected by the minimum-norm change
  ``pi = pi_0 + G^+ (pi_hat - G pi_0)``), and :meth:`Identification.predict` the torques.

The parameters themselves (pseudo-inertia, the consistent fit, rotor and friction terms, models
rebuilt from estimates) are in :mod:`.parameters`; this module holds the workflow (excitation,
measurements, :func:`identify`, validation).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..display import identification_html
from ..simulate.control import Fourier
from .friction import FrictionModel, parse_friction
from .logs import Log, load_log
from .parameters import (
    RotorEstimate,
    base_parameters_with_rotors,
    consistent_fit,
    geared_joints,
    pseudo_inertia,
    rotor_regressor,
    with_armatures,
    with_friction,
    with_inertial_parameters,
)

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..dynamics import BaseParameters
    from ..robot import Robot

__all__ = [
    "Measurements",
    "Identification",
    "Validation",
    "RotorEstimate",
    "pseudo_inertia",
    "excitation",
    "simulate_measurements",
    "identify",
    "with_inertial_parameters",
    "base_parameters_with_rotors",
    "geared_joints",
]


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
    true_values: np.ndarray | None
    condition_number: float
    residual_rms: np.ndarray  # per joint
    weighted: bool
    base: BaseParameters = field(repr=False)
    nominal: Robot = field(repr=False)
    #: base parameters left out because their regressor columns vanish on the data (round-off level)
    dropped: tuple = ()
    #: which rows of ``base`` the estimates are for (None: all of them)
    used: np.ndarray | None = field(default=None, repr=False)
    #: the friction model (``known``: the nominal robot's friction, subtracted, not estimated)
    friction: FrictionModel = field(default_factory=lambda: FrictionModel((), known=True))
    friction_names: tuple = ()
    friction_estimates: np.ndarray = field(default_factory=lambda: np.zeros(0))
    friction_std: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: per-joint torque noise standard deviation estimated from the least-squares residuals
    noise: np.ndarray | None = None
    #: physically consistent estimate (``consistent=True``): all 10 n standard parameters
    standard: np.ndarray | None = field(default=None, repr=False)
    samples: int = 0
    #: joints whose armature r^2 J_m is estimated (their columns follow the 10 n link columns of the
    #: augmented parameter vector that ``base`` is over); the other joints' rotor inertia is known
    rotor_joints: tuple = ()
    #: consistent estimate: the armature of each of ``rotor_joints`` (>= 0)
    standard_armature: np.ndarray | None = field(default=None, repr=False)
    #: consistent estimate: the unconstrained (ordinary or weighted least-squares) fit of the same data
    unconstrained: Identification | None = field(default=None, repr=False)
    #: the samples fitted (a Log or Measurements), for plots and reports
    data: Any = field(default=None, repr=False)

    @property
    def consistent(self) -> bool:
        return self.standard is not None

    @property
    def relative_std(self) -> np.ndarray:
        """100 std / |estimate| (%) per base parameter (Gautier's criterion: above ~10 % an estimate
        is poorly identified by the data)."""
        return 100.0 * self.std / np.maximum(np.abs(self.estimates), 1e-300)

    def _rows(self) -> np.ndarray:
        """Indices of the rows of ``base`` the estimates are for."""
        return np.arange(len(self.base.indices)) if self.used is None else self.used

    @property
    def errors(self) -> np.ndarray | None:
        """estimates - true values (if the true values are known)."""
        return None if self.true_values is None else self.estimates - self.true_values

    @property
    def relative_errors(self) -> np.ndarray | None:
        if self.true_values is None:
            return None
        return np.abs(self.estimates - self.true_values) / np.maximum(
            np.abs(self.true_values), 1e-12 * max(1.0, np.abs(self.true_values).max())
        )

    def predict_torque(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """Torques of the identified model, (n,) or (S, n): rigid body (base regressor times the
        estimates, or the full regressor times the consistent standard parameters) plus the drive
        terms (the nominal rotor inertia, and the identified or the nominal friction)."""
        q, qd, qdd = (np.asarray(a, dtype=float) for a in (q, qd, qdd))
        armature = self.nominal.armature.copy()
        armature[list(self.rotor_joints)] = 0.0  # estimated: in the regressor (or standard_armature)
        if self.standard is not None:
            rigid = self.nominal.regressor(q, qd, qdd) @ self.standard
            if self.standard_armature is not None:
                armature[list(self.rotor_joints)] = self.standard_armature
        else:
            rigid = self._regressor(q, qd, qdd)[..., self.base.indices[self._rows()]] @ self.estimates
        if self.friction.known:
            fric = self.nominal.friction_torque(qd)
        else:
            fric = self.friction.torque(qd, self.friction_estimates)
        return rigid + armature * qdd + fric

    def _regressor(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """The link regressor, with the rotor columns of ``rotor_joints`` after it."""
        Y = self.nominal.regressor(q, qd, qdd)
        if not self.rotor_joints:
            return Y
        n = self.nominal.n
        R = rotor_regressor(qdd, self.rotor_joints, n).reshape(Y.shape[:-1] + (len(self.rotor_joints),))
        return np.concatenate([Y, R], axis=-1)

    @property
    def rotors(self) -> list:
        """A :class:`RotorEstimate` per joint of ``rotor_joints``: the identified armature, or the
        base parameters it is grouped into when the data cannot separate it from link parameters."""
        n = self.nominal.n
        names = list(self.names)
        rows = self._rows()
        G = self.base.grouping[rows]
        out = []
        for k, j in enumerate(self.rotor_joints):
            joint = self.nominal.joints[j]
            own = f"{joint.name}.armature"
            nominal = float(self.nominal.armature[j])
            if own in names:
                i = names.index(own)
                value = (
                    float(self.standard_armature[k]) if self.standard_armature is not None else float(self.estimates[i])
                )
                out.append(RotorEstimate(joint.name, float(joint.gear_ratio), nominal, value, float(self.std[i])))
            else:
                grouped = tuple(names[i] for i in np.flatnonzero(np.abs(G[:, 10 * n + k]) > 0))
                out.append(RotorEstimate(joint.name, float(joint.gear_ratio), nominal, None, None, grouped))
        return out

    predict = predict_torque

    def mass_matrix(self, q: ArrayLike) -> np.ndarray:
        """M(q) of the identified model, (n, n) or (S, n, n), from its regressor alone (no Robot is
        built, so it exists for any estimate): column k is tau(q, 0, e_k) - tau(q, 0, 0), rotor
        inertia included. Its eigenvalues show whether an estimate can be simulated."""
        q = np.asarray(q, dtype=float)
        batch = q.reshape(-1, self.nominal.n)
        S, n = batch.shape
        zero = np.zeros((S, n))
        rows = [self.predict_torque(batch, zero, np.tile(e, (S, 1))) for e in np.eye(n)]
        rest = self.predict_torque(batch, zero, zero)
        # friction at qd = 0 (an offset, sign(0) = 0) is the same in both and cancels
        M = np.stack([r - rest for r in rows], axis=-1)
        return M.reshape(q.shape[:-1] + (n, n))

    @property
    def robot(self):
        """A :class:`kinedyn.Robot` with the identified parameters: the consistent standard
        parameters, or (unconstrained) the nominal robot's corrected by the minimum-norm change
        (see the module docstring); identified viscous and Coulomb friction go into its joints.
        ValueError if the parameters are not physically valid (e.g. a negative mass): only the
        consistent estimate is always valid."""
        n, rotor = self.nominal.n, list(self.rotor_joints)
        if self.standard is not None:
            pi = self.standard
            armature = self.standard_armature if self.standard_armature is not None else self.nominal.armature[rotor]
        else:
            G = self.base.grouping[self._rows()]
            x0 = np.concatenate([self.nominal.inertial_parameters(), self.nominal.armature[rotor]])
            # a grouped armature keeps its nominal value: the links' parameters take up the group
            free = np.ones(x0.size, dtype=bool)
            free[10 * n :] = [r.armature is not None for r in self.rotors]
            x = x0.copy()
            x[free] += np.linalg.pinv(G[:, free]) @ (self.estimates - G @ x0)
            pi, armature = x[: 10 * n], x[10 * n :]
        robot = with_inertial_parameters(self.nominal, pi)
        if rotor:
            robot = with_armatures(robot, dict(zip(rotor, armature)))
        if self.friction.known or not ({"viscous", "coulomb"} & set(self.friction.terms)):
            return robot
        return with_friction(robot, self.friction, self.friction_estimates)

    def validate(self, log, **load_options) -> Validation:
        """Torque prediction on another log (a :class:`Log`, or anything :func:`load_log` reads,
        processed with ``load_options``): RMS error and R^2 per joint."""
        data = log if isinstance(log, Measurements) else load_log(log, n=self.nominal.n, **load_options)
        predicted = self.predict_torque(data.q, data.qd, data.qdd)
        sign = getattr(data, "filtered_sign", None)
        if sign is not None and not self.friction.known:  # the log's torques went through its filter
            predicted = predicted - self.friction.torque(data.qd, self.friction_estimates)
            predicted = predicted + (self.friction.regressor(np.asarray(data.qd), sign) @ self.friction_estimates)
        return Validation(np.asarray(data.t), np.asarray(data.tau), predicted, getattr(data, "source", "<data>"))

    def plot(self, log=None, **load_options):
        """Measured vs predicted torques and the residuals on ``log`` (default: the fitted data), a
        matplotlib Figure."""
        if log is None:
            if self.data is None:
                raise ValueError("this result does not hold the data it was fitted to: give a log to plot")
            log = self.data
        return self.validate(log, **load_options).plot()

    def to_html(self, validate=None, **load_options) -> str:
        """Deprecated: ``kinedyn.report.identification_html(result, validate)`` (the report sits above
        the analysis; this forwards to it)."""
        warnings.warn(
            "Identification.to_html is deprecated: use kinedyn.report.identification_html(result, validate)",
            DeprecationWarning,
            stacklevel=2,
        )
        # the one import of the report from the analysis (declared in the import contract): the old spelling
        from ..report.identification import identification_html

        return identification_html(self, validate, **load_options)

    def write_html(self, path, validate=None, **load_options):
        """Deprecated: ``kinedyn.report.write_identification_html(result, path, validate)``."""
        warnings.warn(
            "Identification.write_html is deprecated: use kinedyn.report.write_identification_html(result, path, validate)",
            DeprecationWarning,
            stacklevel=2,
        )
        from ..report.identification import write_identification_html

        return write_identification_html(self, path, validate, **load_options)

    def to_dict(self) -> dict:
        d = dict(
            names=list(self.names),
            estimates=self.estimates,
            std=self.std,
            condition_number=self.condition_number,
            residual_rms=self.residual_rms,
            weighted=self.weighted,
            dropped=list(self.dropped),
        )
        if not self.friction.known:
            d.update(
                relative_std_percent=self.relative_std,
                friction_names=list(self.friction_names),
                friction_estimates=self.friction_estimates,
                friction_std=self.friction_std,
                consistent=self.consistent,
                samples=self.samples,
            )
            if self.noise is not None:
                d.update(noise=self.noise)
            if self.standard is not None:
                d.update(standard_parameters=self.standard)
            if self.rotor_joints:
                d.update(rotors=[r.to_dict() for r in self.rotors])
        if self.true_values is not None:
            errors = self.estimates - self.true_values
            d.update(
                true_values=self.true_values,
                errors=errors,
                max_abs_error=float(np.abs(errors).max()),
                max_error_in_std=float(np.abs(errors / self.std).max()) if np.all(self.std > 0) else None,
            )
        return d

    def _repr_html_(self) -> str:  # notebooks: estimates, std and errors as a table (kinedyn.display)
        return identification_html(self)

    def __str__(self) -> str:
        lines = [
            f"{len(self.names)} base parameters, cond(W) = {self.condition_number:.4g}, {'weighted' if self.weighted else 'ordinary'} least squares"
        ]
        for k, nm in enumerate(self.names):
            s = f"  {nm:<22} {self.estimates[k]: .8g} +- {self.std[k]:.2g}"
            if self.true_values is not None:
                s += f"   true {self.true_values[k]: .8g}   error {self.estimates[k] - self.true_values[k]: .2g}"
            lines.append(s)
        for k, nm in enumerate(self.friction_names):
            lines.append(f"  {nm:<22} {self.friction_estimates[k]: .8g} +- {self.friction_std[k]:.2g}")
        return "\n".join(lines)


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


def identify(
    robot: Robot,
    data,
    weighted: bool = False,
    base=None,
    *,
    friction=None,
    consistent: bool = False,
    rotor: bool | None = None,
    smoothing: float | None = None,
    regularization: float = 1e-4,
    margin: float = 1e-8,
    solver: str | None = None,
    **load_options,
) -> Identification:
    """Least-squares estimates of ``robot``'s base parameters (and friction) from ``data``.

    ``data``: simulated :class:`Measurements`, a :class:`~kinedyn.analysis.logs.Log`, or anything
    :func:`~kinedyn.analysis.load_log` reads (CSV / NPZ path, DataFrame; ``load_options`` go to it).
    ``robot`` gives the kinematics, the rotor inertia (taken as known) and the prior parameters.
    ``friction``: the terms estimated per joint (``"viscous+coulomb"``, ``"+offset"``, ``"none"``) or
    ``"known"`` (the robot's own friction subtracted); default ``"known"`` for Measurements,
    ``"viscous+coulomb"`` for a log. ``smoothing``: Coulomb sign smoothed as tanh(qd / smoothing).
    ``weighted``: weighted least squares, each joint's rows divided by its noise level estimated from
    the ordinary fit's residuals. ``consistent``: the physically consistent estimate (see the module
    docstring: an SDP with every body's pseudo-inertia ``>= margin I``, ``regularization`` the weight
    of the pull toward ``robot``'s parameters relative to the data term, the armatures kept ``>= 0``).
    ``rotor``: estimate the armature ``r^2 J_m`` of every joint whose model has a gear ratio or a
    rotor inertia (:func:`geared_joints`; see the module docstring), or take it as known (False);
    default: estimated for a log, known for Measurements."""
    # joint logs hold one number per coordinate and a fixed base; a floating base needs its pose
    # and the contact wrenches in the log, which this workflow does not read
    robot.require_one_dof_joints("identification from joint logs")
    n = robot.n
    simulated = isinstance(data, Measurements)
    if not simulated:
        data = data if isinstance(data, Log) else load_log(data, n=n, **load_options)
        if data.n != n:
            raise ValueError(f"the log has {data.n} joints but robot '{robot.name}' has {n}")
    rotor_joints = geared_joints(robot) if (not simulated if rotor is None else rotor) else ()
    if base is None:
        base = base_parameters_with_rotors(robot, rotor_joints)
    elif rotor_joints and base.grouping.shape[1] != 10 * n + len(rotor_joints):
        raise ValueError(
            f"base: {base.grouping.shape[1]} parameters, but the link parameters and the armatures of the geared joints "
            f"{[robot.joints[j].name for j in rotor_joints]} are {10 * n + len(rotor_joints)} (see base_parameters_with_rotors, or rotor=False)"
        )
    true_values: np.ndarray | None = None
    if simulated:
        model = parse_friction("known" if friction is None else friction, smoothing)
        true_values = np.asarray(base.values, dtype=float)
    else:
        model = parse_friction("viscous+coulomb" if friction is None else friction, smoothing)
    q, qd, qdd, tau = (np.ascontiguousarray(a, dtype=float) for a in (data.q, data.qd, data.qdd, data.tau))
    S = q.shape[0]
    nr = len(rotor_joints)
    Yfull = robot.regressor(q, qd, qdd)  # (S, n, 10 n)
    if nr:  # the armatures' columns after the links' (S, n, 10 n + nr)
        Yfull = np.concatenate([Yfull, rotor_regressor(qdd, rotor_joints, n)], axis=2)
    F = model.regressor(qd, getattr(data, "filtered_sign", None))  # (S, n, f)
    known_armature = robot.armature.copy()
    known_armature[list(rotor_joints)] = 0.0
    y = tau - known_armature * qdd
    if model.known:
        y = y - robot.friction_torque(qd)
    nb, nf = base.count, F.shape[2]
    if S * n <= nb + nf:
        raise ValueError(
            f"{S} samples x {n} joints = {S * n} equations cannot determine {nb} base parameters and {nf} friction coefficients"
        )
    W = np.concatenate([Yfull[..., base.indices], F], axis=2).reshape(S * n, nb + nf)
    yv = y.reshape(S * n)
    # a column that is round-off noise on the data carries no information: leave it out
    norms = np.linalg.norm(W, axis=0)
    keep = norms > 1e-9 * norms.max()
    if not keep[nb:].all():
        idle = [nm for nm, k in zip(model.names(n), keep[nb:]) if not k]
        raise ValueError(
            f"friction terms {idle} have no excitation in the data (a joint that never moves?): use friction='none' or move the joint"
        )
    used = keep[:nb]
    dropped = tuple(nm for nm, u in zip(base.names, used) if not u)
    W = W[:, keep]
    p = W.shape[1]
    dof = S * n - p
    est, *_ = np.linalg.lstsq(W, yv, rcond=None)
    r = (yv - W @ est).reshape(S, n)
    # per-joint noise (Gautier & Poignet 2001): residual variance of each joint's S equations
    sig = np.sqrt((r**2).sum(axis=0) / max(S - p / n, 1.0))
    sig = np.where(sig > 0, sig, max(float(sig.max()), 1e-300))
    if weighted:
        w = np.tile(1.0 / sig, S)
        Ww = W * w[:, None]
        est, *_ = np.linalg.lstsq(Ww, yv * w, rcond=None)
        r = (yv - W @ est).reshape(S, n)
        rw = (r / sig).reshape(-1)
        s2 = float(rw @ rw) / dof
        cov = s2 * np.linalg.pinv(Ww.T @ Ww)
        cond = float(np.linalg.cond(Ww))
    else:
        w = np.ones(S * n)
        s2 = float((r**2).sum()) / dof
        cov = s2 * np.linalg.pinv(W.T @ W)
        cond = float(np.linalg.cond(W))
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    kb = int(used.sum())

    def result(est, r, **extra) -> Identification:
        return Identification(
            names=tuple(nm for nm, u in zip(base.names, used) if u),
            estimates=est[:kb],
            std=std[:kb],
            covariance=cov[:kb, :kb],
            true_values=None if true_values is None else true_values[used],
            condition_number=cond,
            residual_rms=np.sqrt((r**2).mean(axis=0)),
            weighted=weighted,
            base=base,
            nominal=robot,
            dropped=dropped,
            used=used,
            friction=model,
            friction_names=model.names(n),
            friction_estimates=est[kb:],
            friction_std=std[kb:],
            noise=sig,
            samples=S,
            rotor_joints=rotor_joints,
            data=data,
            **extra,
        )

    free = result(est, r)
    if not consistent:
        return free
    full = np.concatenate([Yfull.reshape(S * n, 10 * n + nr), F.reshape(S * n, nf)], axis=1)
    standard, armature, fric = consistent_fit(
        robot, full * w[:, None], yv * w, nf, rotor_joints, regularization, margin, solver
    )
    x = np.concatenate([standard, armature])
    r = (yv - full @ np.concatenate([x, fric])).reshape(S, n)
    return result(
        np.concatenate([base.grouping[used] @ x, fric]),
        r,
        standard=standard,
        standard_armature=armature if nr else None,
        unconstrained=free,
    )
