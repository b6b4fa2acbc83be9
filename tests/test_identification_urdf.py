"""Identification on example-robot-data's Panda and UR5 URDFs (issue 16, Tests): simulated logs made
here from the URDF robot with every link 15 % heavier and its centre of mass moved (up to 1 cm per
axis), viscous and Coulomb friction, 1 kHz, torque noise of 0.5 % of each joint's range, 17-bit
encoders, positions and torques only (the helpers of test_identification_logs, which runs the same
checks on the built-in UR5). Logs are short and the base parameters computed once per robot, to keep
each test at a few seconds."""

from __future__ import annotations

import numpy as np
import pytest
from reference import PANDA, UR5, erd
from test_identification_logs import COULOMB, VISCOUS, perturbed, simulated_log

import kinedyn as kd
import kinedyn.analysis as an

ROBOTS = {"panda": PANDA, "ur5": UR5}


def urdf_robot(name):
    robot = kd.load(erd(*ROBOTS[name]))
    fingers = [j for j in robot.joint_names if "finger" in j]  # the Panda's gripper: not part of the arm's log
    return robot.lock_joints(fingers) if fingers else robot


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def case(request):
    prior = urdf_robot(request.param)
    true = perturbed(prior)
    return dict(
        name=request.param,
        prior=prior,
        base=prior.base_parameters(),
        true=true,
        log=simulated_log(true, seed=1, T=20.0),
        held_out=simulated_log(true, seed=7, T=10.0),
    )


def test_held_out_torques_within_twice_the_noise(case):
    prior, (cols, _), (held_out, truth) = case["prior"], case["log"], case["held_out"]
    # the URDF's own parameters miss the 'real' arm by more than the noise
    miss = np.sqrt(np.mean((prior.inverse_dynamics(truth["q"], truth["qd"], truth["qdd"]) - truth["tau"]) ** 2, axis=0))
    assert np.any(miss > 2 * truth["sigma"])
    result = an.identify(prior, cols, base=case["base"])
    assert not result.rotor_joints  # a URDF has no drive train
    check = result.validate(held_out)
    assert np.all(check.rms < 2 * truth["sigma"]), check.rms / truth["sigma"]
    exact = result.predict_torque(
        truth["q"], truth["qd"], truth["qdd"]
    )  # at the exact states, against the noise-free torques
    assert np.all(np.sqrt(np.mean((exact - truth["tau"]) ** 2, axis=0)) < 2 * truth["sigma"])
    np.testing.assert_allclose(
        result.friction_estimates.reshape(prior.n, 2), np.tile([VISCOUS, COULOMB], (prior.n, 1)), rtol=0.1
    )


def test_consistent_estimate_is_simulable_where_the_unconstrained_is_not():
    """The UR5 URDF's wrist 3 moves by 1 mrad: the unconstrained fit gives an M(q) with a negative
    eigenvalue on the log's own states; the consistent fit's M is positive definite at all of them."""
    prior = urdf_robot("ur5")
    cols, truth = simulated_log(perturbed(prior), seed=0, amplitude=np.array([0.8] * 5 + [0.001]), T=20.0)
    states = truth["q"][::100]
    base = prior.base_parameters()
    free = an.identify(prior, cols, base=base)
    assert np.linalg.eigvalsh(free.mass_matrix(states)).min() < 0
    with pytest.raises(ValueError, match=r"body '.*'"):  # nor can it become a Robot
        free.robot
    fit = an.identify(prior, cols, base=base, consistent=True)
    assert fit.consistent
    assert np.linalg.eigvalsh(fit.mass_matrix(states)).min() > 0
    for k in range(prior.n):
        assert np.linalg.eigvalsh(an.pseudo_inertia(fit.standard[10 * k : 10 * k + 10])).min() > 0
    model = fit.robot  # a Robot: simulable, its M agrees with the regressor's, with the identified friction
    np.testing.assert_allclose(model.mass_matrix(states), fit.mass_matrix(states), atol=1e-6)
    np.testing.assert_allclose(model.viscous, fit.friction_estimates[0::2], rtol=1e-12)
    assert np.linalg.eigvalsh(fit.unconstrained.mass_matrix(states)).min() < 0  # the report's comparison
    # it still predicts the torques of the well-excited joints (joint 6's, 1 mrad at 17 bits, are
    # mostly quantisation-blurred Coulomb friction)
    assert np.all(fit.validate(fit.data).r2[:5] > 0.99)


def test_optimised_excitation_of_the_panda_conditions_ten_times_better():
    """Against a random Fourier trajectory of the same band (4 harmonics of 0.1 Hz) in the same limits
    (the optimiser's scaled random start), cond(Y_base) measured on 200 instants, not the 30 optimised on."""
    from kinedyn.analysis.excitation import excitation_condition, optimize_excitation

    robot = urdf_robot("panda")
    limits = dict(qd=1.5, qdd=5.0)
    random = optimize_excitation(robot, period=10.0, harmonics=4, limits=limits, samples=30, seed=0, maxiter=0)
    best = optimize_excitation(robot, period=10.0, harmonics=4, limits=limits, samples=30, seed=0, maxiter=20)
    before, after = excitation_condition(robot, random, samples=200), excitation_condition(robot, best, samples=200)
    print(f"Panda cond(Y_base): random {before:.4g}, optimised {after:.4g}, ratio {before / after:.3g}")
    assert after < before / 10
    q, qd, qdd = best(np.linspace(0.0, best.period, 2001))
    assert np.all(q >= robot.lower_limits) and np.all(q <= robot.upper_limits)
    assert np.all(np.abs(qd) <= 1.5 * 1.1) and np.all(np.abs(qdd) <= 5.0 * 1.1)  # held at 30 instants, 10 % between


def test_bad_logs_give_named_errors(case):
    """Cases beyond test_identification_logs's: the wrong robot, a joint that never moves, a log too
    short to filter, uneven sampling, a cut-off above Nyquist."""
    prior, (cols, _) = case["prior"], case["log"]
    other = "ur5" if case["name"] == "panda" else "panda"
    n_other = 6 if other == "ur5" else 7
    with pytest.raises(
        an.LogError, match=rf"{prior.n} position columns q1..q{prior.n} but the robot has {n_other} joints"
    ):
        an.identify(urdf_robot(other), cols)
    still = dict(cols, q3=np.full_like(cols["q3"], cols["q3"][0]))
    with pytest.raises(ValueError, match=r"friction terms \['joint3.viscous', 'joint3.coulomb'\] have no excitation"):
        an.identify(prior, still, base=case["base"])
    short = {k: v[:1500] for k, v in cols.items()}
    with pytest.raises(an.LogError, match=r"the log \(1.5 s\) is too short to trim 1.5 s of filter edge"):
        an.load_log(short, cutoff=2.0)  # the edge trimmed: 3 / cutoff
    uneven = dict(cols, t=cols["t"] * (1 + 0.2 * (np.arange(len(cols["t"])) > 5000)))
    with pytest.raises(an.LogError, match=r"sampling is not uniform"):
        an.load_log(uneven)
    with pytest.raises(an.LogError, match=r"cutoff 600 Hz must lie between 0 and the Nyquist frequency 500 Hz"):
        an.load_log(cols, cutoff=600.0)
