"""Identification from robot logs (issue 16 §1, §2, §4): simulated logs of a robot whose parameters
differ from the prior model, with friction, 1 kHz, torque noise of 0.5 % of each joint's range,
17-bit encoder quantisation, velocities and accelerations withheld (positions and torques only)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinedyn as kd
import kinedyn.analysis as an

RATE = 1000.0
NOISE = 0.005  # of each joint's torque range
ENCODER = 2 * np.pi / 2**17
VISCOUS, COULOMB = 0.5, 1.0


@pytest.fixture(scope="module")
def true_robot():
    """The 'real' UR5: every link 15 % heavier than the prior's, centres of mass moved 1 cm."""
    return perturbed(kd.robots.get("ur5"))


def perturbed(prior, seed=42):
    """``prior`` with every link 15 % heavier, its centre of mass moved by up to 1 cm per axis."""
    pi = prior.inertial_parameters().reshape(prior.n, 10).copy()
    rng = np.random.default_rng(seed)
    for k in range(prior.n):
        m, h = pi[k, 0], pi[k, 1:4]
        c = h / m + rng.uniform(-0.01, 0.01, 3)
        # I_o = I_c + m (|c|^2 1 - c c^T): keep I_c, move the centre, scale the whole body by 1.15
        Ic = _inertia(pi[k]) - m * (np.dot(h / m, h / m) * np.eye(3) - np.outer(h / m, h / m))
        m2 = 1.15 * m
        Io = 1.15 * Ic + m2 * (np.dot(c, c) * np.eye(3) - np.outer(c, c))
        pi[k] = [m2, *(m2 * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]]
    return an.with_inertial_parameters(prior, pi.reshape(-1))


def _inertia(p):
    return np.array([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]])


def simulated_log(robot, seed, amplitude=0.8, T=20.0, noise=NOISE):
    """Columns t, q1..qn (quantised), tau1..taun (friction and noise added) as a dict, and the truth."""
    ref = an.excitation(robot, harmonics=5, period=10.0, amplitude=amplitude, seed=seed)
    t = np.arange(int(T * RATE)) / RATE
    q, qd, qdd = ref(t)
    tau_true = robot.inverse_dynamics(q, qd, qdd) + VISCOUS * qd + COULOMB * np.sign(qd)
    sigma = noise * (tau_true.max(axis=0) - tau_true.min(axis=0))
    rng = np.random.default_rng(seed)
    tau = tau_true + rng.normal(size=tau_true.shape) * sigma
    cols = {"t": t}
    for j in range(robot.n):
        cols[f"q{j + 1}"] = np.round(q[:, j] / ENCODER) * ENCODER
        cols[f"tau{j + 1}"] = tau[:, j]
    return cols, dict(q=q, qd=qd, qdd=qdd, tau=tau_true, sigma=sigma)


def write_csv(path, cols):
    names = list(cols)
    np.savetxt(path, np.column_stack([cols[k] for k in names]), delimiter=",", header=",".join(names), comments="")


@pytest.fixture(scope="module")
def logs(true_robot):
    return simulated_log(true_robot, seed=1), simulated_log(true_robot, seed=7)


# ---------------------------------------------------------------- §1 data in


def test_load_log_derives_velocities_and_accelerations(true_robot, logs):
    (cols, truth), _ = logs
    log = an.load_log(cols, n=6)
    assert log.cutoff is not None and 1.0 <= log.cutoff <= 0.4 * RATE / 2
    assert log.rate * log.decimation == pytest.approx(RATE)
    idx = np.searchsorted(truth_t := cols["t"], log.t)
    assert np.allclose(truth_t[idx], log.t)
    # filtered and differentiated quantised positions against the exact ones
    for name, est in (("qd", log.qd), ("qdd", log.qdd)):
        exact = truth[name][idx]
        err = np.sqrt(np.mean((est - exact) ** 2)) / np.sqrt(np.mean(exact**2))
        assert err < 0.02, (name, err)
    assert log.t[0] > 0.0 and log.t[-1] < cols["t"][-1]  # filter edges trimmed


def test_cutoff_rule_follows_the_signal():
    t = np.arange(20000) / RATE
    slow = np.sin(2 * np.pi * 0.5 * t)[:, None]
    fast = np.sin(2 * np.pi * 8.0 * t)[:, None]
    assert an.logs.motion_bandwidth(slow, RATE) == pytest.approx(0.5, abs=0.1)
    assert an.logs.choose_cutoff(fast, RATE) == pytest.approx(40.0, rel=0.05)
    assert an.logs.choose_cutoff(slow, RATE) == pytest.approx(2.5, rel=0.2)
    # a record that is not a whole number of periods: its end jump must not leak into the bandwidth
    uneven = np.sin(2 * np.pi * 0.33 * t + 0.4)[:, None]
    assert an.logs.motion_bandwidth(uneven, RATE) < 0.6


def test_csv_npz_dataframe_and_currents_agree(tmp_path, logs):
    pd = pytest.importorskip("pandas")
    (cols, _), _ = logs
    write_csv(tmp_path / "log.csv", cols)
    np.savez(tmp_path / "log.npz", **cols)
    a = an.load_log(tmp_path / "log.csv")
    b = an.load_log(tmp_path / "log.npz")
    c = an.load_log(pd.DataFrame(cols))
    for other in (b, c):
        np.testing.assert_allclose(other.tau, a.tau, atol=1e-9)
        np.testing.assert_allclose(other.qdd, a.qdd, atol=1e-6)
    kt, r = np.linspace(0.1, 0.2, 6), np.full(6, 100.0)
    cur = {k: v for k, v in cols.items() if not k.startswith("tau")}
    for j in range(6):
        cur[f"i{j + 1}"] = cols[f"tau{j + 1}"] / (kt[j] * r[j])
    d = an.load_log(cur, torque_constants=kt, gear_ratios=r)
    np.testing.assert_allclose(d.tau, a.tau, atol=1e-9)


def _broken(cols, **changes):
    out = dict(cols)
    for k, v in changes.items():
        if v is None:
            out.pop(k)
        else:
            out[k] = v
    return out


def test_bad_logs_give_named_errors(tmp_path, logs):
    (cols, _), _ = logs
    nan_q3 = cols["q3"].copy()
    nan_q3[123] = np.nan
    back = cols["t"].copy()
    back[500] = back[498]
    cur = {k: v for k, v in cols.items() if not k.startswith("tau")}
    cur.update({f"i{j}": np.ones_like(cols["t"]) for j in range(1, 7)})
    cases = [
        (_broken(cols, t=None), r"missing column 't'"),
        (_broken(cols, tau4=None), r"missing column 'tau4'"),
        (_broken(cols, q1=None), r"missing columns 'q1'"),
        (_broken(cols, q3=nan_q3), r"column 'q3' has a non-finite value .* sample 123"),
        (_broken(cols, t=back), r"time is not increasing at sample 500 \(t = 0.499 then 0.498\)"),
        (cur, r"motor currents .* torque_constants and gear_ratios"),
    ]
    for bad, message in cases:
        with pytest.raises(an.LogError, match=message):
            an.load_log(bad)
    with pytest.raises(an.LogError, match=r"6 position columns .* robot has 7 joints"):
        an.load_log(cols, n=7)
    with pytest.raises(an.LogError, match=r"no such file"):
        an.load_log(tmp_path / "absent.csv")
    path = tmp_path / "bad.csv"
    path.write_text("t,q1,tau1\n0,0,0\n0.001,x,0\n")
    with pytest.raises(an.LogError, match=r"bad\.csv: line 3: not a number"):
        an.load_log(path)


# ---------------------------------------------------------------- §2 estimators


@pytest.mark.parametrize("weighted", [False, True])
def test_prediction_on_a_held_out_log_within_twice_the_noise(true_robot, logs, weighted):
    (cols, _), (held_out, truth) = logs
    prior = kd.robots.get("ur5")
    result = an.identify(prior, cols, weighted=weighted)
    # the prior model alone misses by far more than the noise
    assert np.any(
        np.sqrt(np.mean((prior.inverse_dynamics(truth["q"], truth["qd"], truth["qdd"]) - truth["tau"]) ** 2, axis=0))
        > 2 * truth["sigma"]
    )
    check = result.validate(held_out)
    assert np.all(check.rms < 2 * truth["sigma"]), check.rms / truth["sigma"]
    assert np.all(check.r2 > 0.99)
    # the model itself, at the exact states of the held-out trajectory, against the noise-free torques
    exact = result.predict_torque(truth["q"], truth["qd"], truth["qdd"])
    assert np.all(np.sqrt(np.mean((exact - truth["tau"]) ** 2, axis=0)) < 2 * truth["sigma"])
    np.testing.assert_allclose(result.friction_estimates.reshape(6, 2), np.tile([VISCOUS, COULOMB], (6, 1)), rtol=0.1)
    assert result.noise is not None and result.noise.shape == (6,)
    assert np.all(result.relative_std > 0) and np.all(np.isfinite(result.std))
    assert result.friction_names[:2] == ("joint1.viscous", "joint1.coulomb")


def test_friction_none_leaves_friction_in_the_residual(true_robot, logs):
    (cols, _), (held_out, truth) = logs
    result = an.identify(kd.robots.get("ur5"), cols, friction="none")
    assert len(result.friction_estimates) == 0
    assert np.any(result.validate(held_out).rms > 2 * truth["sigma"])


# the consistent estimate against the unconstrained one: tests/test_identification_urdf.py (the UR5 URDF)


def test_pseudo_inertia_matches_the_mass_distribution():
    """J = sum m_i [r_i; 1][r_i; 1]^T for point masses, against pseudo_inertia of their parameters."""
    rng = np.random.default_rng(3)
    r, m = rng.normal(size=(5, 3)), rng.uniform(0.5, 2, 5)
    inertia = sum(mi * (ri @ ri * np.eye(3) - np.outer(ri, ri)) for mi, ri in zip(m, r))
    h = (m[:, None] * r).sum(axis=0)
    params = [m.sum(), *h, inertia[0, 0], inertia[0, 1], inertia[1, 1], inertia[0, 2], inertia[1, 2], inertia[2, 2]]
    J = sum(mi * np.outer(np.append(ri, 1), np.append(ri, 1)) for mi, ri in zip(m, r))
    np.testing.assert_allclose(an.pseudo_inertia(params), J, atol=1e-12)


def test_identify_errors(true_robot, logs):
    (cols, _), _ = logs
    with pytest.raises(ValueError, match=r"unknown friction term 'dahl'"):
        an.identify(kd.robots.get("ur5"), cols, friction="viscous+dahl")
    with pytest.raises(an.LogError, match=r"robot has 3 joints"):
        an.identify(kd.robots.get("elbow_3r"), cols)
    with pytest.raises(ValueError, match=r"the log has 6 joints but robot 'elbow_3r' has 3"):
        an.identify(kd.robots.get("elbow_3r"), an.load_log(cols))


def test_plot(logs):
    (cols, _), (held_out, _) = logs
    fig = an.identify(kd.robots.get("ur5"), cols).plot(held_out)
    assert len(fig.axes) == 12


# ---------------------------------------------------------------- §4 command line


def test_cli_identify_from_a_log(tmp_path, logs, capsys):
    from kinedyn.cli import main

    (cols, _), (held_out, truth) = logs
    write_csv(tmp_path / "log.csv", cols)
    write_csv(tmp_path / "other.csv", held_out)
    assert (
        main(
            [
                "identify",
                "ur5",
                "--data",
                str(tmp_path / "log.csv"),
                "--validate",
                str(tmp_path / "other.csv"),
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert len(out["friction_estimates"]) == 12
    assert np.all(np.asarray(out["validation"]["rms"]) < 2 * truth["sigma"])
    bad = dict(cols)
    bad.pop("tau2")
    write_csv(tmp_path / "bad.csv", bad)
    assert main(["identify", "ur5", "--data", str(tmp_path / "bad.csv")]) == 1
    assert "missing column 'tau2'" in capsys.readouterr().err


# ---------------------------------------------------------------- §3 excitation


def test_optimised_excitation_lowers_the_condition_number(tmp_path):
    from kinedyn.analysis.excitation import excitation_condition, optimize_excitation, write_trajectory_csv

    robot = kd.robots.get("ur5")
    limits = dict(qd=1.5, qdd=5.0)
    start = optimize_excitation(robot, period=10.0, harmonics=4, limits=limits, samples=40, seed=0, maxiter=0)
    best = optimize_excitation(robot, period=10.0, harmonics=4, limits=limits, samples=40, seed=0, maxiter=40)
    before, after = excitation_condition(robot, start, samples=40), excitation_condition(robot, best, samples=40)
    print(f"cond(W_base): random start in the limits {before:.4g}, optimised {after:.4g}, ratio {before / after:.3g}")
    assert after < before / 10
    t = np.linspace(0.0, best.period, 4001)
    q, qd, qdd = best(t)
    np.testing.assert_allclose(qd[0], 0.0, atol=1e-12)  # at rest at the start and, periodic, at the end
    np.testing.assert_allclose(qdd[0], 0.0, atol=1e-12)
    lo, hi = robot.lower_limits, robot.upper_limits
    assert np.all(q >= np.where(np.isfinite(lo), lo, -np.pi)) and np.all(q <= np.where(np.isfinite(hi), hi, np.pi))
    assert np.all(np.abs(qd) <= 1.5 * 1.05) and np.all(
        np.abs(qdd) <= 5.0 * 1.05
    )  # limits held at 40 samples, 5 % between
    write_trajectory_csv(best, tmp_path / "traj.csv", rate=100.0)
    table = np.loadtxt(tmp_path / "traj.csv", delimiter=",", skiprows=1)
    assert table.shape == (1001, 1 + 18)
    np.testing.assert_allclose(table[:, 1:7], best(table[:, 0])[0], atol=1e-8)


def test_cli_writes_an_excitation(tmp_path, capsys):
    from kinedyn.cli import main

    out = tmp_path / "traj.csv"
    assert (
        main(
            [
                "identify",
                "planar_2r",
                "--excite",
                str(out),
                "--period",
                "4",
                "--harmonics",
                "3",
                "--rate",
                "50",
                "--json",
            ]
        )
        == 0
    )
    payload = json.loads(capsys.readouterr().out)
    assert payload["condition_number"] < payload["random_condition_number"]
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    assert table.shape == (201, 1 + 6)
    np.testing.assert_allclose(table[0, 3:], 0.0, atol=1e-12)  # qd, qdd at rest at the start
