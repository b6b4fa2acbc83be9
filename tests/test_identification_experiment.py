"""IDIM-IV and DIDIM from the command line and in the report (issue 29): a log has no controller,
so ``kinedyn identify --method iv`` takes the experiment's controller as options (``--controller pd
--kp .. --kd .. --reference traj.csv``) or says what is missing; the HTML report says which method
ran, its iterations and convergence, and sets its estimates beside OLS's.

The experiment: the drive-train 2R under PD along a reference written by ``write_trajectory_csv``
(the file a real controller would be given), encoder noise seen by the controller, 4 s at 1 kHz."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_identification_drive import arm

import kinedyn as kd
import kinedyn.analysis as an
from kinedyn.analysis.excitation import write_trajectory_csv
from kinedyn.analysis.experiment import TabulatedReference, experiment_controller, load_reference
from kinedyn.simulate.control import PD

pytest.importorskip("kinedyn._core", reason="the native module is not built")

KP, KD = (400.0, 200.0), (40.0, 20.0)


@pytest.fixture(scope="module")
def experiment(tmp_path_factory):
    folder = tmp_path_factory.mktemp("experiment")
    true = arm(symmetric=True)
    ref = an.excitation(true, harmonics=3, period=4.0, amplitude=0.8, seed=2)
    controller = PD(np.diag(KP), np.diag(KD), ref)
    T, dt = 4.0, 1e-3
    noise = np.random.default_rng(3).normal(scale=1e-3, size=(int(T / dt) + 1, 2))

    def noisy(t, q, qd):
        return controller(t, q + noise[int(round(t / dt))], qd)

    q0, qd0, _ = ref(np.zeros(1))
    run = kd.simulate(true, T, np.concatenate([q0[0], qd0[0]]), controller=noisy, method="rk4", dt=dt, hold=True)
    q = run.q + noise[: len(run.t)]
    tau = np.array([controller(t, a, b) for t, a, b in zip(run.t, q, run.qd)])
    log_path = folder / "log.csv"
    np.savetxt(log_path, np.column_stack([run.t, q, tau]), delimiter=",", header="t,q1,q2,tau1,tau2", comments="")
    traj = folder / "traj.csv"
    write_trajectory_csv(ref, traj, rate=1000.0)
    prior = kd.robots.planar_2r(l1=0.5, l2=0.4, m1=2.4, m2=2.5)
    return dict(folder=folder, log=log_path, traj=traj, ref=ref, controller=controller, prior=prior)


def test_the_reference_file_reproduces_the_reference(experiment):
    ref = load_reference(experiment["traj"], 2)
    t = np.linspace(0.0, 4.0, 997)
    for a, b in zip(ref(t), experiment["ref"](t)):
        assert np.allclose(a, b, atol=1e-4 * np.abs(b).max())
    # only positions in the file: the derivatives of a spline through them
    tt = np.arange(0, 4.001, 1e-3)
    qs, qds, qdds = experiment["ref"](tt)
    only = TabulatedReference(tt, qs)
    _, qd, qdd = only(t)
    _, qd0, qdd0 = experiment["ref"](t)
    assert np.allclose(qd, qd0, atol=1e-4) and np.allclose(qdd[5:-5], qdd0[5:-5], atol=1e-2)
    # one instant: (n,) vectors, as a controller calls it
    q1, qd1, qdd1 = ref(1.0)
    assert q1.shape == (2,) and np.allclose(q1, experiment["ref"](1.0)[0], atol=1e-6)


def test_the_experiment_controller_is_the_one_that_ran(experiment):
    ref = load_reference(experiment["traj"], 2)
    built = experiment_controller(experiment["prior"], "pd", list(KP), list(KD), ref)
    rng = np.random.default_rng(0)
    for t in (0.0, 0.7, 2.3):
        q, qd = rng.normal(size=2), rng.normal(size=2)
        assert np.allclose(built(t, q, qd), experiment["controller"](t, q, qd), rtol=1e-5, atol=1e-6)
    ct = experiment_controller(experiment["prior"], "ct", 100.0, 20.0, ref)
    q, qd = rng.normal(size=2), rng.normal(size=2)
    qr, qdr, qddr = ref(0.5)
    a = qddr + 20.0 * (qdr - qd) + 100.0 * (qr - q)
    assert np.allclose(ct(0.5, q, qd), experiment["prior"].inverse_dynamics(q, qd, a))


def test_bad_controller_input_is_named(experiment, tmp_path):
    ref = load_reference(experiment["traj"], 2)
    with pytest.raises(ValueError, match="unknown controller 'pid'"):
        experiment_controller(experiment["prior"], "pid", 1.0, 1.0, ref)
    with pytest.raises(ValueError, match="kp: one gain >= 0, or one per joint"):
        experiment_controller(experiment["prior"], "pd", [1.0, 2.0, 3.0], 1.0, ref)
    with pytest.raises(ValueError, match="has 2 joints"):
        experiment_controller(kd.robots.planar_3r(), "pd", 1.0, 1.0, ref)
    bad = tmp_path / "bad.csv"
    bad.write_text("t,q1\n0,0\n0.1,0\n0.2,0\n0.3,0\n")
    with pytest.raises(ValueError, match="bad.csv: no column q2"):
        load_reference(bad, 2)


def test_cli_iv_needs_the_controller_and_says_so(experiment, capsys):
    from kinedyn.cli import main

    args = ["identify", "planar_2r", "--set", "l1=0.5", "--set", "l2=0.4", "--data", str(experiment["log"])]
    assert main([*args, "--method", "iv"]) == 1
    err = capsys.readouterr().err
    assert "a log does not hold it" in err and "--controller" in err and "--reference" in err
    assert main([*args, "--controller", "pd", "--kp", "400,200"]) == 1
    assert "needs --kd, --reference as well" in capsys.readouterr().err


def test_cli_didim_with_the_controller_matches_the_api(experiment, capsys):
    """The same fit through the command line (controller rebuilt from the options and the file) and
    through the API with the controller object that ran; the report says what ran."""
    from kinedyn.cli import main

    html = experiment["folder"] / "report.html"
    args = ["identify", "planar_2r", "--set", "l1=0.5", "--set", "l2=0.4", "--data", str(experiment["log"])]
    args += ["--armature", "--cutoff", "10", "--method", "didim", "--controller", "pd", "--kp", "400,200"]
    args += ["--kd", "40,20", "--reference", str(experiment["traj"]), "--json", "-o", str(html)]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == "didim" and out["iterations"] >= 1
    log = an.load_log(str(experiment["log"]), n=2, cutoff=10.0)
    api = an.identify(
        kd.robots.planar_2r(l1=0.5, l2=0.4),
        log,
        armature=True,
        method="didim",
        controller=experiment["controller"],
    )
    assert out["names"] == list(api.names)
    assert np.allclose(out["estimates"], api.estimates, rtol=2e-3, atol=2e-3 * np.abs(api.estimates).max())
    ols = an.identify(api.nominal, log, armature=True, method="ols")
    both = np.concatenate([ols.estimates, ols.friction_estimates])  # names, then friction_names
    assert np.allclose(out["closed_loop"]["ols"], both, rtol=1e-9, atol=1e-12)
    page = html.read_text()
    assert "Closed-loop estimator" in page and "closed-loop output error (DIDIM)" in page
    assert ("converged: the last iteration" in page) == out["closed_loop"]["converged"]
    assert page.count("<tr") >= 2 * len(out["names"])  # parameters' table and the comparison's
    assert main([a for a in args if a not in ("--json", "-o", str(html))]) == 0  # the text output says it too
    text = capsys.readouterr().out
    assert "method didim" in text and "simulation(s) under the experiment's controller" in text
