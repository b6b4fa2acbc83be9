"""The drive train in identification (issue 29): armature, Stribeck friction, asymmetric Coulomb
levels, torque offsets and the torque delay, each recovered from synthetic logs of a known arm.

The logs' torques come from the native inverse dynamics of a Robot that carries the drive train
(rotor inertia through its gear ratio, viscous and per-direction Coulomb friction in its joints),
plus the Stribeck term and the offsets written out here: an independent route from the regressor
columns identify builds."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import kinedyn as kd
import kinedyn.analysis as an
from kinedyn.analysis.parameters import with_friction

pytest.importorskip("kinedyn._core", reason="the native module is not built")

RATE = 500.0
GEAR = 40.0
ARMATURE = np.array([0.35, 0.12])  # r^2 J_m, kg m^2
VISCOUS = np.array([0.8, 0.4])
COULOMB = np.array([(1.5, 1.1), (0.7, 0.9)])  # (Fc+, Fc-) per joint, N m
STRIBECK = np.array([0.9, 0.5])  # Fs - Fc, N m
VST = np.array([0.08, 0.12])  # Stribeck velocities, rad/s
OFFSET = np.array([0.6, -0.4])  # N m


def arm(symmetric: bool = False) -> kd.Robot:
    """A vertical 2R arm with the drive train above in its joints."""
    base = kd.robots.planar_2r(l1=0.5, l2=0.4, m1=3.0, m2=2.0)
    links = []
    for link in base.links:
        j = base.joint_names.index(link.joint.name) if link.joint.name in base.joint_names else None
        if j is not None:
            plus, minus = COULOMB[j]
            joint = dataclasses.replace(
                link.joint,
                gear_ratio=GEAR,
                rotor_inertia=ARMATURE[j] / GEAR**2,
                viscous=VISCOUS[j],
                coulomb=(plus + minus) / 2 if symmetric else plus,
                coulomb_negative=None if symmetric else minus,
            )
            link = dataclasses.replace(link, joint=joint)
        links.append(link)
    return base.replace(links=links)


def log(robot, seed=0, T=12.0, delay=0.0, noise=0.0, stribeck=True, offset=True, derivatives=True):
    """q, qd, qdd exact along a Fourier excitation; tau from the robot's RNEA (armature, viscous and
    Coulomb friction inside) plus the Stribeck term and offsets, read ``delay`` seconds late."""
    ref = an.excitation(robot, harmonics=4, period=6.0, amplitude=1.0, seed=seed)
    t = np.arange(int(T * RATE)) / RATE
    q, qd, qdd = ref(t)
    qs, qds, qdds = ref(t - delay)  # the torques logged at t belong to the state at t - delay
    tau = robot.inverse_dynamics(qs, qds, qdds)
    if stribeck:
        tau = tau + STRIBECK * np.exp(-((qds / VST) ** 2)) * np.sign(qds)
    if offset:
        tau = tau + OFFSET
    tau = tau + np.random.default_rng(seed + 100).normal(scale=noise, size=tau.shape)
    cols = {"t": t}
    for j in range(2):
        cols[f"q{j + 1}"], cols[f"tau{j + 1}"] = q[:, j], tau[:, j]
        if derivatives:
            cols[f"qd{j + 1}"], cols[f"qdd{j + 1}"] = qd[:, j], qdd[:, j]
    return an.load_log(cols, n=2)


def friction_of(result, joint, column):
    return result.friction_estimates[list(result.friction_names).index(f"joint{joint + 1}.{column}")]


@pytest.fixture(scope="module")
def prior():
    """What we start from: the arm without its drive train, links 20 % off."""
    return kd.robots.planar_2r(l1=0.5, l2=0.4, m1=2.4, m2=2.5)


def test_armature_stribeck_and_offset_are_recovered(prior):
    true = arm(symmetric=True)
    data = log(true, noise=0.01)
    result = an.identify(prior, data, friction="stribeck", offset=True, armature=True)
    assert result.friction.terms == ("viscous", "coulomb", "stribeck", "offset")
    for j in range(2):
        assert friction_of(result, j, "viscous") == pytest.approx(VISCOUS[j], rel=0.02)
        assert friction_of(result, j, "coulomb") == pytest.approx(COULOMB[j].mean(), rel=0.02)
        assert friction_of(result, j, "stribeck") == pytest.approx(STRIBECK[j], rel=0.05)
        assert friction_of(result, j, "offset") == pytest.approx(OFFSET[j], abs=0.01)
        s = result.stribeck[j]
        assert s["velocity"] == pytest.approx(VST[j], rel=0.05)
        assert s["static"][0] == pytest.approx(COULOMB[j].mean() + STRIBECK[j], rel=0.03)
        assert abs(s["velocity"] - VST[j]) < 4 * s["velocity_std"]  # the std is honest
    # joint 1 turns about a fixed axis: its armature only acts with link 1's Izz; joint 2's is seen
    rotors = {r.joint: r for r in result.rotors}
    first, second = (rotors[n] for n in prior.joint_names)
    assert first.armature is None and any("Izz" in g for g in first.grouped_into)
    assert second.armature == pytest.approx(ARMATURE[1], rel=0.02)
    # the truth's base parameters: Izz1 + a1 is what the data see
    truth = an.identify(true, log(true), friction="stribeck", offset=True, armature=True)
    assert np.allclose(result.estimates, truth.estimates, rtol=0.02, atol=2e-3)
    # without the Stribeck column the fit is visibly worse near the reversals
    plain = an.identify(prior, data, friction="viscous+coulomb", offset=True, armature=True)
    assert plain.residual_rms.max() > 3 * result.residual_rms.max()


def test_stribeck_and_delay_on_a_filtered_log(prior):
    """Positions and torques only: the Stribeck column goes through the log's low-pass as the
    torques did (parallel filtering), so its level, its velocity and the delay come out right."""
    true = arm(symmetric=True)
    data = log(true, delay=0.004, noise=0.01, derivatives=False)
    assert data.cutoff is not None and data.decimation > 1
    result = an.identify(prior, data, friction="stribeck", offset=True, armature=True, delay="estimate")
    assert result.delay == pytest.approx(0.004, abs=0.2 / RATE)
    for j in range(2):
        assert friction_of(result, j, "stribeck") == pytest.approx(STRIBECK[j], rel=0.1)
        assert result.stribeck[j]["velocity"] == pytest.approx(VST[j], rel=0.1)
        assert friction_of(result, j, "coulomb") == pytest.approx(COULOMB[j].mean(), rel=0.03)
    check = result.validate(log(true, seed=5, delay=0.004, noise=0.01, derivatives=False))
    assert check.rms.max() < 0.01


def test_asymmetric_coulomb_levels_are_recovered(prior):
    data = log(arm(), noise=0.01, stribeck=False, offset=False)
    result = an.identify(prior, data, friction="viscous+asymmetric", armature=True)
    for j in range(2):
        assert friction_of(result, j, "coulomb+") == pytest.approx(COULOMB[j][0], rel=0.02)
        assert friction_of(result, j, "coulomb-") == pytest.approx(COULOMB[j][1], rel=0.02)
    assert result.identifiability.groups == ()
    model = with_friction(prior, result.friction, result.friction_estimates)  # the levels go into the joints
    assert np.allclose([j.coulomb_levels for j in model.joints], COULOMB, rtol=0.02)
    symmetric = an.identify(prior, data, friction="viscous+coulomb", armature=True)
    assert symmetric.residual_rms.max() > 3 * result.residual_rms.max()


def test_asymmetric_levels_and_offset_are_reported_as_one_group(prior):
    """A joint that always moves sees [qd > 0] + [qd < 0] = 1: Fc+, Fc- and the offset act only as
    Fc+ + offset and Fc- - offset. identify says so instead of printing a split it cannot know."""
    data = log(arm(), noise=0.01, stribeck=False, offset=True)
    result = an.identify(prior, data, friction="viscous+asymmetric+offset", armature=True)
    groups = {frozenset(g) for g in result.identifiability.groups}
    for j in (1, 2):
        assert frozenset({f"joint{j}.coulomb+", f"joint{j}.coulomb-", f"joint{j}.offset"}) in groups
    assert np.all(np.isinf(result.friction_std[[1, 2, 3, 5, 6, 7]]))  # the groups' members
    for j in range(2):
        plus, minus, off = (friction_of(result, j, c) for c in ("coulomb+", "coulomb-", "offset"))
        assert plus + off == pytest.approx(COULOMB[j][0] + OFFSET[j], rel=0.02)
        assert minus - off == pytest.approx(COULOMB[j][1] - OFFSET[j], rel=0.02)
        assert friction_of(result, j, "viscous") == pytest.approx(VISCOUS[j], rel=0.02)
    with pytest.raises(ValueError, match="'coulomb' .* and 'asymmetric' .* name one"):
        an.identify(prior, data, friction="coulomb+asymmetric")


@pytest.mark.parametrize("delay", [0.0037, -0.0012])
def test_delay_is_estimated_to_a_fraction_of_a_sample(prior, delay):
    """On a log of positions and torques (filtered and differentiated as a real one is: the torques'
    Coulomb jumps band-limited, so a shift by a fraction of a sample reads them right)."""
    true = arm(symmetric=True)
    data = log(true, delay=delay, noise=0.01, stribeck=False, derivatives=False)
    result = an.identify(prior, data, friction="viscous+coulomb", offset=True, armature=True, delay="estimate")
    assert result.delay == pytest.approx(delay, abs=0.1 / RATE)
    ignored = an.identify(prior, data, friction="viscous+coulomb", offset=True, armature=True)
    assert ignored.residual_rms.max() > 2 * result.residual_rms.max()
    assert result.residual_rms.max() < 0.01  # the noise (0.01), not the delay, is what is left
    # the validation of another log reads its torques at t + delay too
    check = result.validate(log(true, seed=5, delay=delay, noise=0.01, stribeck=False, derivatives=False))
    assert check.rms.max() < 0.02
    given = an.identify(prior, data, friction="viscous+coulomb", offset=True, armature=True, delay=delay)
    assert given.delay == delay and np.allclose(given.estimates, result.estimates, rtol=1e-3, atol=1e-4)


def test_bad_options_are_named(prior):
    data = log(arm(symmetric=True), stribeck=False)
    with pytest.raises(ValueError, match="delay must be a number of seconds, None or 'estimate'"):
        an.identify(prior, data, delay="guess")
    with pytest.raises(ValueError, match="unknown identification method 'lsq'"):
        an.identify(prior, data, method="lsq")
    with pytest.raises(ValueError, match="method 'iv' simulates the identified model .* give controller="):
        an.identify(prior, data, method="iv")
    with pytest.raises(ValueError, match="consistent=True fits a least-squares data term"):
        an.identify(prior, data, method="irls", consistent=True)


def test_irls_ignores_spikes_that_pull_least_squares(prior):
    true = arm(symmetric=True)
    data = log(true, noise=0.01, stribeck=False)
    spiky = dataclasses.replace(data, tau=data.tau.copy())
    rng = np.random.default_rng(3)
    rows = rng.choice(len(spiky.t), size=len(spiky.t) // 50, replace=False)
    spiky.tau[rows, 0] += 40.0  # one-sided current spikes on joint 1 (2 % of the samples)
    clean = an.identify(prior, data, friction="viscous+coulomb", offset=True, armature=True)
    ols = an.identify(prior, spiky, friction="viscous+coulomb", offset=True, armature=True, method="ols")
    robust = an.identify(prior, spiky, friction="viscous+coulomb", offset=True, armature=True, method="irls")
    assert robust.method == "irls" and robust.iterations > 1

    def worst(r):  # the largest change from the clean fit, relative (parameters near 0: absolute)
        a = np.concatenate([r.estimates, r.friction_estimates])
        b = np.concatenate([clean.estimates, clean.friction_estimates])
        return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 0.05)))

    # the spikes pull OLS (link 2's Izz by ~40 %); IRLS gives them no weight and keeps the clean fit
    assert worst(ols) > 0.2
    assert worst(robust) < 0.01


def test_cli_hides_error_over_std_on_noise_free_data(capsys):
    """Issue 23: on noise-free data the std is round-off, and error / std printed 39.96 for a
    ratio of two rounding noises. With noise the column is there and near 1."""
    from kinedyn.cli import main

    assert main(["identify", "planar_2r"]) == 0
    out = capsys.readouterr().out
    assert "noise-free data" in out and "error / std is not shown" in out
    rows = [line for line in out.splitlines() if "link2.Izz" in line]
    assert rows and rows[0].rstrip(" │|").endswith("-")
    assert main(["identify", "planar_2r", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["max_error_in_std"] is None
    assert main(["identify", "planar_2r", "--noise", "0.5", "--json"]) == 0
    noisy = json.loads(capsys.readouterr().out)
    assert 0 < noisy["max_error_in_std"] < 5
    assert main(["identify", "planar_2r", "--noise", "0.5"]) == 0
    assert "noise-free" not in capsys.readouterr().out


def test_cli_fits_the_drive_train_and_the_delay(tmp_path, prior, capsys):
    from kinedyn.cli import main

    true = arm(symmetric=True)
    ref = an.excitation(true, harmonics=4, period=6.0, amplitude=1.0, seed=0)
    t = np.arange(int(12.0 * RATE)) / RATE
    q, _, _ = ref(t)
    qs, qds, qdds = ref(t - 0.004)  # the torques 4 ms late
    tau = true.inverse_dynamics(qs, qds, qdds) + OFFSET
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([t, q, tau]), delimiter=",", header="t,q1,q2,tau1,tau2", comments="")
    args = [
        "identify",
        "planar_2r",
        "--set",
        "l1=0.5",
        "--set",
        "l2=0.4",
        "--data",
        str(path),
        "--offset",
        "--armature",
    ]
    assert main([*args, "--delay", "estimate", "--method", "irls", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == "irls" and out["delay"] == pytest.approx(0.004, abs=2e-4)
    offsets = [v for n, v in zip(out["friction_names"], out["friction_estimates"]) if n.endswith("offset")]
    assert offsets == pytest.approx(OFFSET, abs=0.02)
    assert main([*args, "--delay", "soon"]) == 1
    assert "--delay: a number of seconds or 'estimate', got 'soon'" in capsys.readouterr().err
    assert main([*args, "--delay", "0.004", "--friction", "viscous+asymmetric"]) == 0
    text = capsys.readouterr().out
    assert "method ols" in text and "4 ms behind the positions" in text
    assert "not separable by the data" in text and "joint1.coulomb+, joint1.coulomb-, joint1.offset" in text


def test_excitation_optimised_for_the_drive_train_within_torque_limits():
    """Issue 29 §4: the armature and friction columns join Swevers' criterion; the torque limits
    hold at the sampled instants."""
    robot = kd.robots.planar_2r(l1=0.5, l2=0.4, m1=3.0, m2=2.0)
    drive = dict(armature=True, friction="viscous+coulomb+offset")
    options = dict(period=6.0, harmonics=4, samples=60, maxiter=40)
    fitted = an.optimize_excitation(robot, **options, **drive)
    rigid = an.optimize_excitation(robot, **options)
    random = an.excitation(robot, harmonics=4, period=6.0, amplitude=1.0, seed=0)
    cond = {
        k: an.excitation_condition(robot, r, samples=60, **drive)
        for k, r in dict(fitted=fitted, rigid=rigid, random=random).items()
    }
    assert cond["fitted"] < 0.5 * cond["random"]
    assert cond["fitted"] < cond["rigid"]  # the rigid-body criterion alone sees the drive train worse
    # about the upright pose (gravity small at the centre, so the limits can be met)
    t = np.arange(60) * 6.0 / 60
    upright = dict(q=([0.6, -1.0], [2.5, 1.0]))
    free = an.optimize_excitation(robot, limits=upright, **options, **drive)
    limits = dict(upright, tau=[10.0, 5.0])
    held = an.optimize_excitation(robot, limits=limits, **options, **drive)
    assert np.abs(robot.inverse_dynamics(*free(t))[:, 0]).max() > 15.0  # the limit binds
    tau = np.abs(robot.inverse_dynamics(*held(t))).max(axis=0)
    assert np.all(tau <= np.array(limits["tau"]) * (1 + 1e-6))
    assert an.excitation_condition(robot, held, samples=60, **drive) < 100
    with pytest.raises(ValueError, match="torque limits must be positive"):
        an.optimize_excitation(robot, limits=dict(tau=[0.0, 4.0]), **options)


def test_report_and_consistent_fit_carry_the_drive_train(prior, tmp_path):
    from kinedyn.report import identification_html
    from kinedyn.report.identification import identification_data

    pytest.importorskip("cvxpy")
    data = log(arm(symmetric=True), delay=0.003, noise=0.01, stribeck=True, offset=True)
    result = an.identify(prior, data, friction="stribeck", offset=True, armature=True, delay="estimate", method="irls")
    d = identification_data(result)
    assert d["method"] == "irls" and d["delay"] == pytest.approx(0.003, abs=2e-4)
    assert [s["velocity"] for s in d["stribeck"]] == pytest.approx(VST, rel=0.05)
    page = identification_html(result)
    assert "iteratively reweighted least squares" in page and "ms behind the positions" in page
    assert "static - Coulomb [N m]" in page
    consistent = an.identify(prior, data, friction="stribeck", offset=True, armature=True, delay=0.003, consistent=True)
    assert np.linalg.eigvalsh(consistent.mass_matrix(data.q[::100])).min() > 0
    for j in range(2):
        assert friction_of(consistent, j, "stribeck") == pytest.approx(STRIBECK[j], rel=0.1)
