"""kinedyn.analysis: the properties report (each check passes on real robots and fails on a broken
model) and base-parameter identification (exact without noise, within its predicted confidence
with noise, estimates usable as a model)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import kinedyn as kd
from kinedyn import analysis as an

pytest.importorskip("kinedyn._core", reason="the native module is not built")


@pytest.fixture(scope="module")
def puma():
    return kd.robots.puma560()


@pytest.fixture(scope="module")
def excitation_data(puma):
    ref = an.excitation(puma, harmonics=5, period=10.0, amplitude=0.6, seed=1)
    return ref, an.simulate_measurements(puma, ref, rate=100.0)


@pytest.mark.parametrize("name", ["planar_2r", "puma560", "ur5"])
def test_properties_hold_on_built_ins(name):
    robot = kd.robots.get(name)
    report = an.check_properties(robot, samples=50, T=1.0)
    assert report.passed, str(report)
    bounds = report["inertia bounds"]
    assert 0 < bounds.data["lambda_min"] <= bounds.data["lambda_max"]
    M = robot.mass_matrix(bounds.data["q_lambda_min"])
    assert np.linalg.eigvalsh(M)[0] == pytest.approx(bounds.data["lambda_min"], rel=1e-12)
    assert set(report.to_dict()) >= {"robot", "passed", "checks"}


def test_properties_with_friction_and_a_random_tree():
    from kinedyn.testing import random_robot

    robot = random_robot(seed=3, n=5, branching=True, friction=True)
    report = an.check_properties(robot, samples=30, T=0.5)
    assert report["passivity"].data["dissipated"] > 0
    assert report.passed, str(report)


def test_properties_report_catches_a_wrong_model(puma, monkeypatch):
    """The checks can fail: a transposed C passes both dM/dt identities but not C qd == the Coriolis
    torque; a scaled C fails skew symmetry; a mass matrix shifted by -2 I fails positive definiteness."""
    real_c = type(puma).coriolis_matrix
    monkeypatch.setattr(type(puma), "coriolis_matrix", lambda self, q, qd: np.swapaxes(real_c(self, q, qd), -1, -2))
    report = an.check_properties(puma, samples=20, T=0.2)
    assert not report["C(q, qd) qd"].passed
    assert report["dM/dt - 2C skew"].passed and report["dM/dt == C + C^T"].passed
    monkeypatch.setattr(type(puma), "coriolis_matrix", lambda self, q, qd: 1.1 * real_c(self, q, qd))
    report = an.check_properties(puma, samples=20, T=0.2)
    assert not report["dM/dt - 2C skew"].passed and not report["dM/dt == C + C^T"].passed
    monkeypatch.undo()
    real_m = type(puma).mass_matrix
    monkeypatch.setattr(type(puma), "mass_matrix", lambda self, q: real_m(self, q) - 2.0 * np.eye(6))
    report = an.check_properties(puma, samples=20, T=0.2)
    assert not report["M symmetric positive definite"].passed
    assert not report["inertia bounds"].passed


def test_identification_is_exact_from_noise_free_data(puma, excitation_data):
    _, data = excitation_data
    result = an.identify(puma, data)
    assert len(result.names) >= 30
    assert result.condition_number < 1e4  # the excitation separates the base parameters
    assert np.abs(result.errors).max() < 1e-8
    # the regressor columns of dropped parameters really are zero on the data
    for name in result.dropped:
        k = list(result.base.names).index(name)
        col = puma.regressor(data.q, data.qd, data.qdd)[..., result.base.indices[k]]
        assert np.abs(col).max() < 1e-10


def test_estimates_plug_back_into_a_model(puma, excitation_data):
    _, data = excitation_data
    result = an.identify(puma, data)
    identified = result.robot
    rng = np.random.default_rng(7)
    q, qd, qdd = puma.random_configuration(rng, size=30), rng.normal(size=(30, 6)), rng.normal(size=(30, 6))
    tau = puma.inverse_dynamics(q, qd, qdd)
    np.testing.assert_allclose(identified.inverse_dynamics(q, qd, qdd), tau, atol=1e-9)
    np.testing.assert_allclose(result.predict(q, qd, qdd), tau, atol=1e-9)
    # computed torque with the identified model tracks like the exact one
    ref = kd.simulate.Quintic(np.zeros(6), np.array([0.4, -0.3, 0.2, 0.5, -0.4, 0.6]), 1.0)
    ctl = kd.simulate.ComputedTorque(puma, 100.0, 20.0, ref, model=identified)
    traj = kd.simulate(puma, 1.0, np.zeros(12), controller=ctl, record_every=10)
    assert np.abs(traj.q - ref(traj.t)[0]).max() < 1e-8


def test_identification_from_a_different_prior_still_gives_the_true_base_parameters(puma, excitation_data):
    """Only the base parameters are identifiable and the estimates do not depend on the nominal model:
    a prior with 20 % heavier links gives the same estimates and predicts the true torques. Its
    minimum-norm correction needs inertias no rigid body has, so .robot says so."""
    _, data = excitation_data
    prior = kd.robots.puma560(masses=[1.2 * m for m in kd.robots.industrial.PUMA560_MASSES])
    result = an.identify(prior, data)
    assert np.abs(result.estimates - an.identify(puma, data).estimates).max() < 1e-8
    rng = np.random.default_rng(8)
    q, qd, qdd = puma.random_configuration(rng, size=10), rng.normal(size=(10, 6)), rng.normal(size=(10, 6))
    np.testing.assert_allclose(result.predict(q, qd, qdd), puma.inverse_dynamics(q, qd, qdd), atol=1e-8)
    assert np.abs(prior.inverse_dynamics(q, qd, qdd) - puma.inverse_dynamics(q, qd, qdd)).max() > 1e-2
    with pytest.raises(ValueError, match=r"body 'link\d': .*(positive semi-definite|negative)"):
        result.robot


@pytest.mark.parametrize("weighted", [False, True])
def test_noisy_identification_is_within_its_predicted_confidence(puma, excitation_data, weighted):
    ref, _ = excitation_data
    sigma = np.array([0.5, 2.0, 1.0, 0.05, 0.05, 0.05])
    data = an.simulate_measurements(puma, ref, rate=100.0, noise=sigma, seed=3)
    result = an.identify(puma, data, weighted=weighted)
    z = result.errors / result.std
    # standardised errors: all within 4.5 sigma, and their spread near 1 (the covariance is right)
    assert np.abs(z).max() < 4.5
    assert 0.6 < np.sqrt(np.mean(z**2)) < 1.5
    assert np.abs(result.errors).max() > 1e-6  # the noise does reach the estimates
    if weighted:
        ols = an.identify(puma, data, weighted=False)
        assert np.mean(np.abs(result.errors)) < np.mean(np.abs(ols.errors))
        np.testing.assert_allclose(result.residual_rms, sigma, rtol=0.1)


def test_identification_bad_input(puma, excitation_data):
    ref, _ = excitation_data
    with pytest.raises(ValueError, match="cannot determine"):
        an.identify(puma, an.simulate_measurements(puma, ref, T=0.02, rate=100.0))
    with pytest.raises(ValueError, match="noise standard deviations"):
        an.simulate_measurements(puma, ref, noise=-1.0)


def test_cli_check_and_identify(capsys):
    import json

    from kinedyn.cli import main

    code = main(["check", "planar_2r", "--samples", "20", "--t", "0.5", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["passed"] and len(doc["checks"]) == 8  # with "friction dissipates"
    code = main(["identify", "planar_2r", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["max_abs_error"] < 1e-8
    base = kd.robots.planar_2r().base_parameters()
    np.testing.assert_allclose(doc["true_values"], base.values)


def test_identification_without_used_rows_means_all_base_parameters():
    """``Identification.used`` defaults to None: the estimates are for every base parameter (it
    indexed the regressor with None before, adding an axis to the predicted torques)."""
    from dataclasses import replace

    robot = kd.robots.planar_2r()
    data = an.simulate_measurements(robot, an.excitation(robot, harmonics=3, period=2.0), T=2.0, rate=50.0)
    result = an.identify(robot, data)
    assert result.dropped == ()
    everything = replace(result, used=None)
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.normal(size=(5, 2)), rng.normal(size=(5, 2)), rng.normal(size=(5, 2))
    np.testing.assert_allclose(everything.predict(q, qd, qdd), robot.inverse_dynamics(q, qd, qdd), atol=1e-8)
    np.testing.assert_allclose(
        everything.robot.inverse_dynamics(q, qd, qdd), robot.inverse_dynamics(q, qd, qdd), atol=1e-8
    )


# ------------------------------------------------------------------ elbow_3r upright; check deterministic
@pytest.mark.parametrize("q3", [0.0, math.pi])
def test_elbow_inertia_is_regular_when_upright(q3):
    """elbow_3r's links were thin rods with no inertia about their own axes, so M(q) was singular with
    the arm upright (both links on z0). Upright, turning about z0 turns every link about its own axis:
    M11 = (m1 + m2 + m3) r^2 / 2 for solid cylinders of radius r, derived here; radius=0 is the
    textbook's thin rods, singular exactly there."""
    for q2 in (math.pi / 2, -math.pi / 2):
        q = np.array([0.4, q2, q3])
        robot = kd.robots.elbow_3r(m1=1.0, m2=1.5, m3=0.5, radius=0.05)
        M = robot.mass_matrix(q)
        assert M[0, 0] == pytest.approx((1.0 + 1.5 + 0.5) * 0.05**2 / 2, rel=1e-9)
        assert np.linalg.eigvalsh(M)[0] > 1e-3
        thin = kd.robots.elbow_3r(radius=0).mass_matrix(q)
        assert abs(np.linalg.eigvalsh(thin)[0]) < 1e-12


def test_check_passivity_does_not_depend_on_the_sample_count():
    """`kinedyn check elbow_3r` passed or failed passivity with the number of samples: the trajectory
    was drawn from the same random stream after the samples. It now depends on the seed only."""
    robot = kd.robots.elbow_3r()
    reports = [kd.analysis.check_properties(robot, samples=s, seed=0) for s in (20, 1000)]
    passivity = [[c for c in r.checks if c.name.startswith("passivity")][0] for r in reports]
    assert passivity[0].residual == passivity[1].residual and passivity[0].detail == passivity[1].detail
    assert all(c.passed for r in reports for c in r.checks), [c.name for r in reports for c in r.checks if not c.passed]
