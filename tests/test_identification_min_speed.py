"""Rows near zero speed left out of the fit (issue 29): where a joint sticks, or its speed chatters
about zero within a sample, the friction is any torque within the static levels, not Fc sign(qd), and
those rows bias every estimator (on the closed-loop PUMA 560 of benches/bench_identification.py they
made OLS 20 % wrong on noise-free data). Here an exact open-loop log of the drive-train 2R gets
arbitrary stick torques, within +-Fc, wherever a joint is slower than 0.05 rad/s: with ``min_speed``
the fit sees only the rows the model describes and recovers the truth, without it is biased."""

from __future__ import annotations

import numpy as np
import pytest
from test_identification_drive import arm

import kinedyn.analysis as an
from kinedyn.analysis.estimators import speed_rows

SLOW = 0.05  # rad/s


@pytest.fixture(scope="module")
def case():
    true = arm(symmetric=True)
    ref = an.excitation(true, harmonics=3, period=5.0, amplitude=0.5, seed=3)
    t = np.arange(5001) * 1e-3
    q, qd, qdd = ref(t)
    tau = true.inverse_dynamics(q, qd, qdd)  # the drive train's friction included
    friction = true.friction_torque(qd)
    slow = np.abs(qd) < SLOW
    stick = np.random.default_rng(0).uniform(-1.0, 1.0, size=tau.shape) * np.abs(friction).max(axis=0)
    tau = np.where(slow, tau - friction + stick, tau)  # inside the static band, not Fc sign(qd)
    assert slow.mean() > 0.02  # the reference reverses: stick rows exist
    cols = {"t": t, "q1": q[:, 0], "q2": q[:, 1], "tau1": tau[:, 0], "tau2": tau[:, 1]}
    exact = an.simulate_measurements(true, ref, T=10.0, rate=100.0)
    truth = an.identify(true, exact, friction="viscous+coulomb", armature=True)
    return cols, truth


def error(result, truth):
    return np.linalg.norm(result.estimates - truth.estimates) / np.linalg.norm(truth.estimates)


def test_rows_near_zero_speed_left_out_recover_the_truth(case):
    cols, truth = case
    log = an.load_log(cols, n=2, cutoff=15.0)
    options = dict(friction="viscous+coulomb", armature=True)
    biased = an.identify(truth.nominal, log, **options)
    kept = an.identify(truth.nominal, log, min_speed=SLOW, **options)
    assert list(kept.names) == list(truth.names)
    assert error(kept, truth) < 0.005 and error(biased, truth) > 0.03
    # the residual and noise figures are those of the rows in the fit
    assert np.all(kept.residual_rms < 0.2 * biased.residual_rms)
    for method in ("wls", "irls"):
        assert error(an.identify(truth.nominal, log, method=method, min_speed=SLOW, **options), truth) < 0.02


def test_the_rows_left_out_reach_as_far_as_the_spread():
    qd = np.array([[1.0, 1.0], [1.0, 1.0], [0.01, 1.0], [1.0, 1.0], [1.0, -0.01], [1.0, 1.0], [1.0, 1.0]])
    keep = speed_rows(qd, 0.05).reshape(-1, 2)
    assert keep[:, 0].tolist() == [1, 1, 0, 1, 1, 1, 1] and keep[:, 1].tolist() == [1, 1, 1, 1, 0, 1, 1]
    keep = speed_rows(qd, 0.05, spread=1).reshape(-1, 2)
    assert keep[:, 0].tolist() == [1, 0, 0, 0, 1, 1, 1] and keep[:, 1].tolist() == [1, 1, 1, 0, 0, 0, 1]
    assert speed_rows(qd, 0.0).all()


def test_bad_min_speed_is_named(case):
    cols, truth = case
    log = an.load_log(cols, n=2, cutoff=15.0)
    with pytest.raises(ValueError, match="min_speed must be"):
        an.identify(truth.nominal, log, min_speed=-1.0)
    with pytest.raises(ValueError, match="leaves .* of joint"):
        an.identify(truth.nominal, log, min_speed=100.0)


def test_the_consistent_fit_with_the_drive_train_stays_feasible_on_the_rows_kept(case):
    """The semidefinite fit with armature and friction columns, on the rows min_speed keeps: every
    body's pseudo-inertia positive definite, the armatures >= 0, and as close to the truth as the
    unconstrained fit (the truth is physical, so the constraints cost nothing here)."""
    pytest.importorskip("cvxpy")
    from kinedyn.analysis.parameters import pseudo_inertia

    cols, truth = case
    log = an.load_log(cols, n=2, cutoff=15.0)
    fit = an.identify(truth.nominal, log, friction="viscous+coulomb", armature=True, min_speed=SLOW, consistent=True)
    for body in np.asarray(fit.standard).reshape(-1, 10):
        assert np.linalg.eigvalsh(pseudo_inertia(body)).min() > 0
    assert np.all(fit.standard_armature >= 0)
    assert error(fit, truth) < 0.01 and error(fit.unconstrained, truth) < 0.01
