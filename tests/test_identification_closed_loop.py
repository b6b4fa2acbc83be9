"""Identification from closed-loop data (issue 29): an arm with a drive train tracks a Fourier
reference under a PD controller that reads noisy encoder positions; the log holds those positions
and the controller's torques. The noise reaches the regressor (filtered, differentiated twice) and,
through the controller, the motion itself: ordinary least squares is biased, toward smaller
inertias (errors in the regressor attenuate its coefficients), and IDIM-IV and DIDIM are not.

The arm is simulated by kinedyn.simulate (the native ABA with the drive train in the joints): an
independent route from the inverse-dynamics model simulation IV and DIDIM run."""

from __future__ import annotations

import numpy as np
import pytest
from test_identification_drive import arm

import kinedyn as kd
import kinedyn.analysis as an
from kinedyn.simulate.control import PD

pytest.importorskip("kinedyn._core", reason="the native module is not built")

DT = 1e-3  # the controller's period
T = 6.0
ENCODER_NOISE = 2e-3  # rad, white, seen by the controller and logged
CUTOFF = 10.0  # Hz: a cut-off that lets some of that noise into qdd, as a real log's often does


@pytest.fixture(scope="module")
def experiment():
    true = arm(symmetric=True)
    ref = an.excitation(true, harmonics=4, period=6.0, amplitude=1.0, seed=0)
    controller = PD(np.diag([400.0, 200.0]), np.diag([40.0, 20.0]), ref)
    steps = int(round(T / DT))
    noise = np.random.default_rng(1).normal(scale=ENCODER_NOISE, size=(steps + 1, 2))

    def noisy(t, q, qd):  # the controller sees the encoder, not the true angle
        return controller(t, q + noise[int(round(t / DT))], qd)

    q0, qd0, _ = ref(np.zeros(1))
    traj = kd.simulate(true, T, np.concatenate([q0[0], qd0[0]]), controller=noisy, method="rk4", dt=DT, hold=True)
    q = traj.q + noise[: len(traj.t)]
    tau = np.array([controller(t, qk, qdk) for t, qk, qdk in zip(traj.t, q, traj.qd)])
    assert np.allclose(tau, traj.tau, atol=1e-9)  # the torques logged are the ones applied
    log = an.load_log(
        {"t": traj.t, "q1": q[:, 0], "q2": q[:, 1], "tau1": tau[:, 0], "tau2": tau[:, 1]}, n=2, cutoff=CUTOFF
    )
    # the truth's base parameters: the true arm identified on exact open-loop data
    exact = an.simulate_measurements(true, ref, T=12.0, rate=100.0)
    truth = an.identify(true, exact, friction="viscous+coulomb", armature=True)
    assert truth.exact
    prior = kd.robots.planar_2r(l1=0.5, l2=0.4, m1=2.4, m2=2.5)
    fits = {
        m: an.identify(
            prior,
            log,
            friction="viscous+coulomb",
            armature=True,
            method=m,
            controller=controller if m != "ols" else None,
        )
        for m in ("ols", "iv", "didim")
    }
    late = 3  # samples (ms): the current sensor's torques arrive after the encoder's positions
    delayed = an.load_log(
        {"t": traj.t[late:], "q1": q[late:, 0], "q2": q[late:, 1], "tau1": tau[:-late, 0], "tau2": tau[:-late, 1]},
        n=2,
        cutoff=CUTOFF,
    )
    return truth, fits, controller, log, prior, delayed


def inertias(result):
    """The base parameters that are inertias: joint 1's Izz group (link 1's Izz + a_1 + ...) and
    joint 2's armature."""
    names = list(result.names)
    return np.array([result.estimates[names.index("link1.Izz")], result.estimates[names.index("q2.armature")]])


def inertia_std(result):
    names = list(result.names)
    return np.array([result.std[names.index("link1.Izz")], result.std[names.index("q2.armature")]])


def test_ols_is_biased_toward_smaller_inertias_on_closed_loop_data(experiment):
    truth, fits, *_ = experiment
    ols = fits["ols"]
    ratio = inertias(ols) / inertias(truth)
    assert np.all(ratio < 0.85), ratio  # the direction of the bias, not only its size
    # joint 1's Izz group is far outside its own std (joint 2's armature is weakly seen by 6 s: ~1.5 std)
    assert (inertias(truth) - inertias(ols))[0] > 5 * inertia_std(ols)[0]


@pytest.mark.parametrize("method", ["iv", "didim"])
def test_iv_and_didim_recover_the_parameters(experiment, method):
    truth, fits, *_ = experiment
    result = fits[method]
    assert result.method == method and 1 <= result.iterations <= 6
    # within the estimator's own precision (IV trades variance for the bias: its std is a few times
    # least squares'), and within 10 %
    assert np.all(np.abs(inertias(result) - inertias(truth)) < 3 * inertia_std(result))
    assert np.all(np.abs(inertias(result) / inertias(truth) - 1) < 0.1)
    scale = np.maximum(np.abs(truth.estimates), 0.2)  # m cy is 0: its error counts against 0.2 kg m
    assert np.max(np.abs(result.estimates - truth.estimates) / scale) < 0.1
    assert np.max(np.abs(fits["ols"].estimates - truth.estimates) / scale) > 0.3
    assert result.friction_estimates == pytest.approx(truth.friction_estimates, rel=0.15)
    # the std is of the right size: the errors are a few std, not hundreds
    z = (result.estimates - truth.estimates) / result.std
    assert np.abs(z).max() < 6


def test_auto_picks_iv_when_the_controller_is_given(experiment, capsys):
    _, fits, controller, log, prior, _ = experiment
    assert an.identify(prior, log, friction="viscous+coulomb", armature=True).method == "ols"
    auto = an.identify(prior, log, friction="viscous+coulomb", armature=True, controller=controller)
    assert auto.method == "iv" and np.allclose(auto.estimates, fits["iv"].estimates)
    assert "method iv" in str(auto)
    assert an.identify(prior, log, friction="viscous+coulomb", armature=True, weighted=True).method == "wls"


def test_a_model_that_cannot_be_simulated_is_named(experiment):
    """IV simulates its estimate: one with a negative inertia diverges, and says so."""
    from kinedyn.analysis.closed_loop import simulate_model

    _, _, controller, log, _, _ = experiment

    def negative(q, qd, qdd):  # M = -I
        return -qdd

    with pytest.raises(ValueError, match=r"the identified model diverges under the controller at t = "):
        simulate_model(negative, controller, log.t, log.q[0], log.qd[0])


def test_iv_estimates_the_delay_against_the_simulated_loop(experiment):
    """The least-squares profile of the delay is pulled by the noise the regressor and the
    controller's torque share; IV estimates it again against the noise-free simulated regressor."""
    truth, _, controller, _, prior, delayed = experiment
    options = dict(friction="viscous+coulomb", armature=True, delay="estimate")
    ols = an.identify(prior, delayed, method="ols", **options)
    iv = an.identify(prior, delayed, method="iv", controller=controller, **options)
    assert abs(ols.delay - 0.003) > 3e-3  # off by more than 3 ms (the sample period is 19 ms)
    assert iv.delay == pytest.approx(0.003, abs=1.5e-3)
    assert np.all(np.abs(inertias(iv) - inertias(truth)) < 3 * inertia_std(iv))


def test_iv_falls_back_on_the_prior_when_the_start_cannot_be_simulated():
    """Any simulable model gives valid instruments: a least-squares start that diverges is replaced
    by the prior's; a later iterate that diverges ends the iterations on the last instruments."""
    from kinedyn.analysis.closed_loop import instrumental_fit

    rng = np.random.default_rng(0)
    X = rng.normal(size=(20000, 3))  # the noise-free regressor
    theta = np.array([1.0, -2.0, 0.5])
    W = X + 0.3 * rng.normal(size=X.shape)  # measured with noise: OLS attenuated
    y = X @ theta + 0.01 * rng.normal(size=len(X))

    def instruments(t):
        if t[0] < 0:  # "diverges"
            raise ValueError("the identified model diverges under the controller at t = 1 s")
        return X

    est, _, it, _, note = instrumental_fit("iv", W, y, np.ones(len(X)), -theta, instruments, fallback=theta)
    assert "the first instruments are the prior model's" in note
    ols = np.linalg.lstsq(W, y, rcond=None)[0]
    assert np.all(np.abs(ols) < 0.95 * np.abs(theta))  # attenuated by the noise in W
    assert np.allclose(est, theta, atol=0.02) and it >= 1
    with pytest.raises(ValueError, match="diverges"):
        instrumental_fit("iv", W, y, np.ones(len(X)), -theta, instruments)
    flips = iter([False] + [True] * 10)  # every later model, halved steps too, diverges

    def later(t):
        if next(flips):
            raise ValueError("diverges at t = 2 s")
        return X

    est, _, it, _, note = instrumental_fit("iv", W, y, np.ones(len(X)), theta, later, tol=0.0)
    assert it == 1 and "iteration 2 could not be simulated" in note and np.allclose(est, theta, atol=0.02)


def test_a_step_into_a_model_that_cannot_be_simulated_is_halved():
    """DIDIM is a Gauss-Newton iteration: a full step that lands on a model that cannot be simulated
    is halved toward the last simulable estimate (step control) instead of ending the iterations."""
    from kinedyn.analysis.closed_loop import instrumental_fit

    rng = np.random.default_rng(1)
    X = rng.normal(size=(5000, 2))
    theta = np.array([2.0, 1.0])
    y = X @ theta + 0.01 * rng.normal(size=len(X))
    start = np.array([0.5, 1.0])
    tried = []

    def instruments(t):  # models with the first parameter above 1.5 "diverge" once, the first time
        tried.append(t.copy())
        if t[0] > 1.5 and len(tried) == 2:
            raise ValueError("the identified model diverges under the controller at t = 1 s")
        return X

    est, _, it, _, note = instrumental_fit("didim", X, y, np.ones(len(X)), start, instruments)
    assert "step was halved" in note
    assert np.allclose(tried[2], start + 0.5 * (tried[1] - start))  # halfway toward the last simulable one
    assert np.allclose(est, theta, atol=1e-3) and it >= 2


def test_iv_keeps_the_instruments_of_smallest_covariance():
    """Every noise-free simulation gives consistent instruments, not equally good ones: when an
    iteration's instruments are nearly uncorrelated with one column of W, its estimate is far off and
    its covariance says so; IV keeps the iterate whose covariance has the smallest log det."""
    from kinedyn.analysis.closed_loop import instrumental_fit

    rng = np.random.default_rng(2)
    X = rng.normal(size=(20000, 3))
    theta = np.array([1.0, -2.0, 0.5])
    W = X + 0.3 * rng.normal(size=X.shape)
    y = X @ theta + 0.05 * rng.normal(size=len(X))
    weak = X.copy()
    weak[:, 2] = 0.02 * X[:, 2] + rng.normal(size=len(X))  # a poor instrument for the third column
    calls = []

    def instruments(t):  # good, then poor ones: the iterations do not settle
        calls.append(t)
        return X if len(calls) == 1 else weak

    est, cov, it, _, note = instrumental_fit("iv", W, y, np.ones(len(X)), theta + 0.3, instruments, tol=0.0)
    assert it == 6 and "kept iteration 1's estimate" in note
    good = np.linalg.solve(X.T @ W, X.T @ y)
    assert np.allclose(est, good) and np.allclose(est, theta, atol=0.02)
    assert np.all(np.sqrt(np.diag(cov)) < 0.05)
