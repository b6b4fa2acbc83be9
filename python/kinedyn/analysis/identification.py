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
from dataclasses import replace as dc_replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..display import identification_html
from .closed_loop import instrumental_fit, simulate_model
from .estimators import (
    METHODS,
    Identifiability,
    delay_window,
    estimate_delay,
    identifiability,
    irls,
    joint_noise,
    least_squares,
    resolve_method,
    speed_rows,
    stribeck_search,
    unseparable_mask,
)
from .friction import FrictionModel, parse_friction
from .logs import Log, load_log
from .measurements import Measurements, Validation, aligned, excitation, simulate_measurements
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
    "Identifiability",
    "METHODS",
]


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
    #: the samples fitted (a Log or Measurements, its torques aligned by ``delay``), for plots and reports
    data: Any = field(default=None, repr=False)
    #: the estimator used (:data:`METHODS`, ``auto`` resolved)
    method: str = "ols"
    #: seconds the torques lag the positions (estimated or given; the fit reads them at t + delay)
    delay: float = 0.0
    #: iterations of an iterative estimator (irls, iv, didim)
    iterations: int = 0
    #: what the data can see: scaled cond(W), the groups of parameters it cannot separate
    identifiability: Identifiability | None = field(default=None, repr=False)
    #: standard deviation of each joint's Stribeck velocity (Gauss-Newton, with the linear parameters)
    stribeck_velocity_std: np.ndarray | None = None
    #: what the estimator had to do differently (e.g. IV's fallback on the prior model's instruments)
    notes: tuple = ()
    #: iv / didim: the last iteration's relative change, the tolerance, and the OLS and WLS (the start)
    #: estimates of the same rows, ``names`` then ``friction_names`` (the report's closed-loop section)
    closed_loop: dict | None = field(default=None, repr=False)

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

    @property
    def exact(self) -> bool:
        """The fit reproduces the torques to round-off (noise-free data): the standard deviations are
        then round-off too, and an error divided by one measures nothing."""
        if self.data is None:
            return False
        scale = float(np.sqrt(np.mean(np.asarray(self.data.tau) ** 2)))
        return bool(np.all(self.residual_rms <= 1e-9 * max(scale, 1e-300)))

    @property
    def stribeck(self) -> list:
        """Per joint with a Stribeck term: velocity (and its std), the excess ``Fs - Fc`` and the
        static level(s) ``Fs`` (one per direction with asymmetric Coulomb friction)."""
        model = self.friction
        if "stribeck" not in model.terms or model.velocities is None:
            return []
        cols = model.columns()
        k = len(cols)
        out = []
        for j in range(self.nominal.n):
            c = dict(zip(cols, self.friction_estimates[j * k : (j + 1) * k]))
            levels = [c["coulomb"]] if "coulomb" in c else [c["coulomb+"], c["coulomb-"]]
            vstd = None if self.stribeck_velocity_std is None else float(self.stribeck_velocity_std[j])
            out.append(
                dict(
                    joint=self.nominal.joints[j].name,
                    velocity=float(model.velocities[j]),
                    velocity_std=vstd,
                    excess=float(c["stribeck"]),
                    static=[float(v + c["stribeck"]) for v in levels],
                )
            )
        return out

    def predict_torque(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, offset: bool = True) -> np.ndarray:
        """Torques of the identified model, (n,) or (S, n): rigid body (base regressor times the
        estimates, or the full regressor times the consistent standard parameters) plus the drive
        terms (the nominal rotor inertia, and the identified or the nominal friction). The delay is
        not in it (it is the arm's torque at the given state); ``offset=False`` leaves out the
        identified torque offsets (a sensor's, not the arm's)."""
        q, qd, qdd = (np.asarray(a, dtype=float) for a in (q, qd, qdd))
        armature = self.nominal.armature.copy()
        armature[list(self.rotor_joints)] = 0.0  # estimated: in the regressor (or standard_armature)
        if self.standard is not None:
            rigid = self.nominal.regressor(q, qd, qdd) @ self.standard
            if self.standard_armature is not None:
                armature[list(self.rotor_joints)] = self.standard_armature
        else:
            rigid = self._regressor(q, qd, qdd)[..., self.base.indices[self._rows()]] @ self.estimates
        fric = self.friction.torque(qd, self.friction_estimates, offset) if self.friction.terms else 0.0
        if self.friction.known:
            fric = fric + self.nominal.friction_torque(qd)
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
        if self.friction.known or not ({"viscous", "coulomb", "asymmetric"} & set(self.friction.terms)):
            return robot
        return with_friction(robot, self.friction, self.friction_estimates)

    def validate(self, log, **load_options) -> Validation:
        """Torque prediction on another log (a :class:`Log`, or anything :func:`load_log` reads,
        processed with ``load_options``): RMS error and R^2 per joint. Its torques are read at
        ``t + delay`` (the identified delay: the same sensors lag alike), except on the fitted data."""
        data = log if isinstance(log, Measurements) else load_log(log, n=self.nominal.n, **load_options)
        if self.delay and log is not self.data:
            data = aligned(data, self.delay)
        predicted = self.predict_torque(data.q, data.qd, data.qdd)
        sign = getattr(data, "filtered_sign", None)
        if sign is not None and self.friction.terms:  # the log's torques went through its filter
            predicted = predicted - self.friction.torque(data.qd, self.friction_estimates)
            F = self.friction.regressor(np.asarray(data.qd), sign, getattr(data, "parallel", None))
            predicted = predicted + F @ self.friction_estimates
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
            method=self.method,
            delay=self.delay,
        )
        if self.iterations:
            d.update(iterations=self.iterations)
        if self.notes:
            d.update(notes=list(self.notes))
        if self.closed_loop is not None:
            d.update(closed_loop=self.closed_loop)
        if self.identifiability is not None:
            d.update(identifiability=self.identifiability.to_dict())
        if self.stribeck:
            d.update(stribeck=self.stribeck)
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
                # on noise-free data the std is round-off, and an error over it measures nothing
                max_error_in_std=(
                    float(np.abs(errors / self.std).max()) if np.all(self.std > 0) and not self.exact else None
                ),
            )
        return d

    def _repr_html_(self) -> str:  # notebooks: estimates, std and errors as a table (kinedyn.display)
        return identification_html(self)

    def __str__(self) -> str:
        lines = [
            f"{len(self.names)} base parameters, cond(W) = {self.condition_number:.4g}, method {self.method}"
            + (f", torques {1e3 * self.delay:.3g} ms late" if self.delay else "")
        ]
        for k, nm in enumerate(self.names):
            s = f"  {nm:<22} {self.estimates[k]: .8g} +- {self.std[k]:.2g}"
            if self.true_values is not None:
                s += f"   true {self.true_values[k]: .8g}   error {self.estimates[k] - self.true_values[k]: .2g}"
            lines.append(s)
        for k, nm in enumerate(self.friction_names):
            lines.append(f"  {nm:<22} {self.friction_estimates[k]: .8g} +- {self.friction_std[k]:.2g}")
        return "\n".join(lines)


def identify(
    robot: Robot,
    data,
    weighted: bool = False,
    base=None,
    *,
    friction=None,
    consistent: bool = False,
    rotor: bool | None = None,
    armature: bool | None = None,
    offset: bool = False,
    delay: float | str | None = None,
    max_delay: float = 0.02,
    method: str = "auto",
    controller=None,
    control_period: float = 1e-3,
    min_speed: float = 0.0,
    smoothing: float | None = None,
    regularization: float = 1e-4,
    margin: float = 1e-8,
    solver: str | None = None,
    **load_options,
) -> Identification:
    """Estimates of ``robot``'s base parameters and its drive train (armature, friction, offsets, the
    torque delay) from ``data`` (docs/identification.md).

    ``data``: simulated :class:`Measurements`, a :class:`~kinedyn.analysis.logs.Log`, or anything
    :func:`~kinedyn.analysis.load_log` reads (CSV / NPZ path, DataFrame; ``load_options`` go to it).
    ``robot`` gives the kinematics, the rotor inertia (taken as known) and the prior parameters.
    ``friction``: the terms estimated per joint (:mod:`.friction`: ``"viscous+coulomb"``,
    ``"stribeck"``, ``"viscous+asymmetric"``, ...; ``"none"``) or ``"known"`` (the robot's own friction
    subtracted); default ``"known"`` for Measurements, ``"viscous+coulomb"`` for a log; ``offset``: add
    a torque offset per joint. ``smoothing``: Coulomb sign smoothed as tanh(qd / smoothing).
    ``rotor``: estimate the armature ``r^2 J_m`` of every joint whose model has a gear ratio or a
    rotor inertia (:func:`geared_joints`), or take it as known (False); default: estimated for a log,
    known for Measurements. ``armature=True``: estimate every joint's armature (False: none).
    ``delay``: None (none), seconds, or ``"estimate"`` (within +-``max_delay``, :mod:`.estimators`).
    ``method``: ``ols``, ``wls`` (also ``weighted=True``), ``irls``, ``iv`` or ``didim``
    (:mod:`.closed_loop`: they need the ``controller`` that ran the experiment, run at
    ``control_period``); ``auto``: ``iv`` when a controller is given, else ``ols`` (``wls`` with
    ``weighted=True``). ``min_speed``: rows of joint j where ``|qd_j|`` is below it are left out
    (stick and Coulomb's jump, :func:`~.estimators.speed_rows`). ``consistent``: the physically consistent estimate (an SDP with every body's
    pseudo-inertia ``>= margin I``, ``regularization`` the weight of the pull toward ``robot``'s
    parameters, the armatures kept ``>= 0``; a least-squares data term, so with ols or wls)."""
    # joint logs hold one number per coordinate and a fixed base; a floating base needs its pose
    # and the contact wrenches in the log, which this workflow does not read
    robot.require_one_dof_joints("identification from joint logs")
    n = robot.n
    method = resolve_method(method, weighted, controller)
    if consistent and method not in ("ols", "wls"):
        raise ValueError(f"consistent=True fits a least-squares data term: use method 'ols' or 'wls', not '{method}'")
    simulated = isinstance(data, Measurements)
    if not simulated:
        data = data if isinstance(data, Log) else load_log(data, n=n, **load_options)
        if data.n != n:
            raise ValueError(f"the log has {data.n} joints but robot '{robot.name}' has {n}")
    if armature is not None:
        rotor_joints = tuple(range(n)) if armature else ()
    else:
        rotor_joints = geared_joints(robot) if (not simulated if rotor is None else rotor) else ()
    if base is None:
        base = base_parameters_with_rotors(robot, rotor_joints)
    elif rotor_joints and base.grouping.shape[1] != 10 * n + len(rotor_joints):
        raise ValueError(
            f"base: {base.grouping.shape[1]} parameters, but the link parameters and the armatures of the joints "
            f"{[robot.joints[j].name for j in rotor_joints]} are {10 * n + len(rotor_joints)} (see base_parameters_with_rotors, or rotor=False)"
        )
    true_values = np.asarray(base.values, dtype=float) if simulated else None
    model = parse_friction(("known" if simulated else "viscous+coulomb") if friction is None else friction, smoothing)
    if offset and "offset" not in model.terms:
        model = dc_replace(model, terms=(*model.terms, "offset"))
    qd_max = np.maximum(np.abs(np.asarray(data.qd, dtype=float)).max(axis=0), 1e-9)
    if "stribeck" in model.terms:
        model = dc_replace(model, velocities=tuple(0.05 * qd_max))
    nr = len(rotor_joints)
    known_armature = robot.armature.copy()
    known_armature[list(rotor_joints)] = 0.0

    def columns(q, qd, qdd, sign, model=model, parallel=None):
        """(S, n, nb + nf): the base regressor (links and estimated armatures), the friction columns."""
        Y = robot.regressor(q, qd, qdd)
        if nr:  # the armatures' columns after the links' (S, n, 10 n + nr)
            Y = np.concatenate([Y, rotor_regressor(qdd, rotor_joints, n)], axis=2)
        return np.concatenate([Y[..., base.indices], model.regressor(qd, sign, parallel)], axis=2)

    def known(q, qd, qdd):
        """The torques of the known drive terms, subtracted from the measured ones."""
        return known_armature * qdd + (robot.friction_torque(qd) if model.known else 0.0)

    def arrays(data):
        q, qd, qdd, tau = (np.ascontiguousarray(a, dtype=float) for a in (data.q, data.qd, data.qdd, data.tau))
        return q, qd, qdd, tau, getattr(data, "filtered_sign", None), getattr(data, "parallel", None)

    q, qd, qdd, tau, sign, parallel = arrays(data)
    raw, edge, window = data, 0, np.zeros(0, dtype=bool)
    if isinstance(delay, str):
        if delay.strip().lower() != "estimate":
            raise ValueError(f"delay must be a number of seconds, None or 'estimate', got {delay!r}")
        t = np.asarray(data.t, dtype=float)
        edge, window = delay_window(t, max_delay)
        W0 = columns(q, qd, qdd, sign, model, parallel).reshape(len(t) * n, -1)
        W0 = W0[:, np.linalg.norm(W0, axis=0) > 0]
        delay_s, *_ = estimate_delay(t, tau, W0, known(q, qd, qdd), window, max_delay)
        data = aligned(data, delay_s, edge)
    elif delay is not None and float(delay) != 0.0:
        delay_s = float(delay)
        if not np.isfinite(delay_s):
            raise ValueError(f"delay must be finite, got {delay}")
        data = aligned(data, delay_s)
    else:
        delay_s = 0.0
    q, qd, qdd, tau, sign, parallel = arrays(data)
    S = q.shape[0]
    y = tau - known(q, qd, qdd)
    yv = y.reshape(S * n)
    nb, nf = base.count, n * len(model.columns())
    if S * n <= nb + nf:
        raise ValueError(
            f"{S} samples x {n} joints = {S * n} equations cannot determine {nb} base parameters and {nf} friction coefficients"
        )
    if "stribeck" in model.terms:
        k = len(model.columns())
        index = [nb + j * k + model.columns().index("stribeck") for j in range(n)]
        ranges = [(1e-3 * v, 0.5 * v) for v in qd_max]
        velocities = stribeck_search(
            lambda v: columns(q, qd, qdd, sign, dc_replace(model, velocities=tuple(v)), parallel).reshape(S * n, -1),
            yv,
            index,
            ranges,
        )
        model = dc_replace(model, velocities=tuple(float(v) for v in velocities))
    W = columns(q, qd, qdd, sign, model, parallel).reshape(S * n, nb + nf)
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
    names = tuple(nm for nm, u in zip(base.names, used) if u) + model.names(n)
    cut = getattr(data, "cutoff", None)  # a filtered log: its low-pass spreads a stick over 1 / cutoff
    rows = speed_rows(qd, min_speed, int(np.ceil(1.0 / (cut * np.median(np.diff(data.t))))) if cut else 0)
    seen = identifiability(W[rows > 0], names)
    est, cov, r = least_squares(W, yv, n, rows)
    ols = est
    sig = joint_noise(r, W.shape[1], rows)
    w = rows if method == "ols" else rows * np.tile(1.0 / sig, S)
    iterations, note, loop = 0, None, None
    if method in ("wls", "iv", "didim"):
        est, cov, r = least_squares(W, yv, n, w)
    if method == "irls":
        est, cov, r, w, iterations = irls(W, yv, n, rows=rows)
    elif method in ("iv", "didim"):

        def simulated_regressor(theta, times, q0, qd0):
            """The regressor of the model ``theta`` simulated under the controller at ``times``."""

            def torque(a, b, c):
                return columns(a, b, c, None, model)[..., keep] @ theta + known(a, b, c)

            if getattr(raw, "cutoff", None) is None:
                qs, qds, qdds = simulate_model(torque, controller, times, q0, qd0, control_period)
                return columns(qs, qds, qdds, None, model)[..., keep].reshape(len(times) * n, -1)
            # a filtered log: the simulated regressor through the log's low-pass, as its torques
            # went (the Coulomb columns' jumps smeared alike), then read at the log's samples
            grid, qs, qds, qdds = simulate_model(torque, controller, times, q0, qd0, control_period, dense=True)
            Z = raw.lowpass(columns(qs, qds, qdds, None, model)[..., keep], 1.0 / control_period)
            Z = Z.reshape(len(grid), -1)
            return np.column_stack([np.interp(times, grid, z) for z in Z.T]).reshape(len(times) * n, -1)

        # the prior model's parameters (the friction from the fit): simulable, so valid instruments
        prior = np.concatenate([np.asarray(base.values, dtype=float)[used], est[int(used.sum()) :]])
        settle = 3.0 / raw.cutoff if getattr(raw, "cutoff", None) else 0.0

        def settled(times):
            """Samples past the filter's start-up at either end of a simulated span (weight 0 else)."""
            return (times >= times[0] + settle) & (times <= times[-1] - settle)

        # the delay again, against the simulated loop's regressor: the measured W carries the encoder
        # noise the controller's torque also carries, and that correlation pulls the least-squares
        # profile's minimum away from the true delay (the simulated motion's phase follows the model
        # simulated, so what is left is of the order of the start's tracking lag error)
        rq, rqd, rqdd, rtau, *_ = arrays(raw)
        rt = np.asarray(raw.t)
        if window.any():
            try:
                Z0 = simulated_regressor(est, rt, rq[0], rqd[0])
            except ValueError:  # a start that cannot be simulated: the prior's instruments
                Z0 = simulated_regressor(prior, rt, rq[0], rqd[0])
            delay_s, *_ = estimate_delay(rt, rtau, Z0, known(rq, rqd, rqdd), window & settled(rt), max_delay)
            data = aligned(raw, delay_s, edge)
            q, qd, qdd, tau, sign, parallel = arrays(data)
            yv = (tau - known(q, qd, qdd)).reshape(S * n)
            W = columns(q, qd, qdd, sign, model, parallel).reshape(S * n, nb + nf)[:, keep]
            seen = identifiability(W[w > 0], names)
        wz = w * np.repeat(settled(np.asarray(data.t)), n)
        start, tol = est, 0.02
        est, cov, iterations, change, note = instrumental_fit(
            method,
            W,
            yv,
            wz,
            est,
            lambda theta: simulated_regressor(theta, data.t, q[0], qd[0]),
            tol=tol,
            fallback=prior,
        )
        loop = dict(ols=ols.tolist(), start=start.tolist(), last_change=change, tolerance=tol, converged=change < tol)
        r = (yv - W @ est).reshape(S, n)
    cond = float(np.linalg.cond(W * w[:, None]))
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    std[unseparable_mask(seen, names)] = np.inf
    vstd = None
    if "stribeck" in model.terms:  # Gauss-Newton: the velocities' columns beside the linear ones
        fk = est[int(used.sum()) :]
        D = model.stribeck_derivative(qd, sign, fk).reshape(S * n, n)
        J = np.concatenate([W, D], axis=1) * w[:, None]
        s2 = float(((r.reshape(-1) * w) ** 2).sum()) / max(S * n - J.shape[1], 1)
        vstd = np.sqrt(np.maximum(np.diag(s2 * np.linalg.pinv(J.T @ J))[-n:], 0.0))
    kb = int(used.sum())
    rm = (w > 0).reshape(S, n)  # the rows in the fit

    def result(est, r, **extra) -> Identification:
        return Identification(
            names=names[:kb],
            estimates=est[:kb],
            std=std[:kb],
            covariance=cov[:kb, :kb],
            true_values=None if true_values is None else true_values[used],
            condition_number=cond,
            residual_rms=np.sqrt((r**2 * rm).sum(axis=0) / np.maximum(rm.sum(axis=0), 1)),
            weighted=method != "ols",
            base=base,
            nominal=robot,
            dropped=dropped,
            used=used,
            friction=model,
            friction_names=model.names(n),
            friction_estimates=est[kb:],
            friction_std=std[kb:],
            noise=joint_noise(r, W.shape[1], rm),
            samples=S,
            rotor_joints=rotor_joints,
            data=data,
            method=method,
            delay=delay_s,
            iterations=iterations,
            identifiability=seen,
            stribeck_velocity_std=vstd,
            notes=() if note is None else (note,),
            closed_loop=loop,
            **extra,
        )

    free = result(est, r)
    if not consistent:
        return free
    Yfull = robot.regressor(q, qd, qdd)
    if nr:
        Yfull = np.concatenate([Yfull, rotor_regressor(qdd, rotor_joints, n)], axis=2)
    F = model.regressor(qd, sign, parallel)
    full = np.concatenate([Yfull.reshape(S * n, 10 * n + nr), F.reshape(S * n, nf)], axis=1)
    standard, armature_est, fric = consistent_fit(
        robot, full * w[:, None], yv * w, nf, rotor_joints, regularization, margin, solver
    )
    x = np.concatenate([standard, armature_est])
    r = (yv - full @ np.concatenate([x, fric])).reshape(S, n)
    return result(
        np.concatenate([base.grouping[used] @ x, fric]),
        r,
        standard=standard,
        standard_armature=armature_est if nr else None,
        unconstrained=free,
    )
