"""Issue 11 §5, long work is bounded and visible: the implicit integrator for stiff robots (and
method="auto" choosing it), joint limits in simulation, wall-clock budgets that say when they cut a
run short, the report's budget on a 44-joint robot, per-joint gains on the command line, and
progress bars that stay off stdout."""

from __future__ import annotations

import json
import sys
import time
import warnings

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

from reference import PANDA, erd  # noqa: E402

import kinedyn as kd  # noqa: E402
from kinedyn.cli import main  # noqa: E402
from kinedyn.simulate import PD, ComputedTorque, PDGravity, Quintic, SimulationError, SimulationTruncatedWarning  # noqa: E402

TALOS = ("talos_data", "robots", "talos_full_v2.urdf")
PANDA_GOAL = np.array([0.3, -0.5, 0.4, -1.5, 0.3, 1.2, 0.2, 0.01, 0.01])


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def panda():
    return kd.load(erd(*PANDA), mimic="independent")  # 9 coordinates: the stiff fingers each their own


@pytest.fixture(scope="module")
def puma():
    return kd.robots.puma560()


# ------------------------------------------------------------------ stiff robots
def test_panda_pd_gravity_converges_with_the_default_method(panda):
    """docs/simulation.md's PD + gravity example with its gains (Kp = 100, Kd = 20) on the Panda URDF:
    RK4 at 1 ms blows up within a few steps; the default method sees it and takes the implicit step."""
    x0 = np.zeros(2 * panda.n)
    with pytest.raises(SimulationError, match="blew up"):
        kd.simulate(panda, 0.5, x0, controller=PDGravity(panda, 100.0, 20.0, PANDA_GOAL), method="rk4")
    traj = kd.simulate(panda, 4.0, x0, controller=PDGravity(panda, 100.0, 20.0, PANDA_GOAL), record_every=10)
    assert traj.method == "implicit"
    assert "RK4 at dt = 0.001 s would be unstable" in traj.info["method_choice"]
    assert np.abs(traj.q[-1] - PANDA_GOAL).max() < 1e-4
    assert np.abs(traj.qd[-1]).max() < 1e-3
    assert np.all(np.isfinite(traj.q))


def test_auto_keeps_rk4_where_it_is_stable(puma):
    x0 = np.r_[0.1, 0.5, -0.3, 0.2, 0.4, 0.1, 0.5, -0.3, 0.2, 1.0, -0.5, 0.8]
    auto = kd.simulate(puma, 0.5, x0)
    assert auto.method == "rk4" and auto.info["method_choice"].startswith("auto: rk4")
    assert np.array_equal(auto.q, kd.simulate(puma, 0.5, x0, method="rk4").q)


def test_implicit_converges_at_first_order_against_a_tight_rk45(puma):
    x0 = np.r_[0.1, 0.5, -0.3, 0.2, 0.4, 0.1, 0.5, -0.3, 0.2, 1.0, -0.5, 0.8]
    reference = kd.simulate(puma, 0.4, x0, method="dop853", dt=0.1, rtol=1e-12, atol=1e-12)
    errors = []
    for dt in (2e-3, 1e-3, 5e-4):
        traj = kd.simulate(puma, 0.4, x0, method="implicit", dt=dt, record_every=int(round(0.1 / dt)))
        assert np.allclose(traj.t, reference.t)
        errors.append(np.abs(traj.q - reference.q).max())
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    assert all(1.8 < r < 2.2 for r in ratios), (errors, ratios)


def _python_loop(robot, method, x0, steps, dt, limits=None, every=1):
    """The Python fixed-step loop (LagrangianSystem's, and robots with reduced mimic joints') run on
    a robot's compiled dynamics, as the core's scheme's second implementation."""
    from kinedyn.simulate.fixed_step import run_fixed_step

    n = robot.n
    zero = np.zeros(n)
    return run_fixed_step(
        robot,
        True,
        None,
        method,
        x0[:n],
        x0[n:],
        0.0,
        dt,
        steps,
        lambda i: lambda k, t, q, qd: zero,
        False,
        every,
        1e6,
        None,
        None,
        None,
        limits,
    )


def test_implicit_python_loop_matches_the_core(puma):
    """The Python loop's implicit step is the core's scheme (same numbers)."""
    x0 = np.r_[0.1, 0.5, -0.3, 0.2, 0.4, 0.1, 0.5, -0.3, 0.2, 1.0, -0.5, 0.8]
    core = kd.simulate(puma, 0.2, x0, method="implicit")
    assert core.info["native"]
    Q = _python_loop(puma, "implicit", x0, core.t.size - 1, float(core.t[1] - core.t[0]))[0]
    np.testing.assert_allclose(Q, core.q, atol=1e-10)


@pytest.mark.parametrize("kind", ["pd", "pdg", "ct"])
def test_controller_jacobians_match_finite_differences(puma, kind):
    rng = np.random.default_rng(3)
    kp, kd_ = rng.uniform(50, 150, 6), rng.uniform(5, 20, 6)
    goal = rng.uniform(-1, 1, 6)
    ctl = {
        "pd": PD(kp, kd_, goal),
        "pdg": PDGravity(puma, kp, kd_, goal),
        "ct": ComputedTorque(puma, kp, kd_, Quintic(np.zeros(6), goal, 1.0)),
    }[kind]
    t, q, qd = 0.3, rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6)
    dq, dqd = ctl.jacobian(t, q, qd)
    h = 1e-6
    fd_q = np.column_stack([(ctl(t, q + h * e, qd) - ctl(t, q - h * e, qd)) / (2 * h) for e in np.eye(6)])
    fd_qd = np.column_stack([(ctl(t, q, qd + h * e) - ctl(t, q, qd - h * e)) / (2 * h) for e in np.eye(6)])
    np.testing.assert_allclose(dq, fd_q, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(dqd, fd_qd, rtol=1e-6, atol=1e-6)


def test_stiff_gains_need_the_controllers_jacobian(puma):
    """Kp = 1e6 on the PUMA at 1 ms: implicit Euler with the gains in its Jacobian converges; the same
    step without them (a plain callable) blows up."""
    goal = np.array([0.3, -0.5, 0.4, 0.2, 0.3, -0.2])
    ctl = PD(1e6, 1e4, goal)
    traj = kd.simulate(puma, 0.5, np.zeros(12), controller=ctl, method="implicit")
    assert np.abs(traj.q[-1] - goal).max() < 1e-3
    with pytest.raises(SimulationError, match="blew up"):
        kd.simulate(puma, 0.5, np.zeros(12), controller=lambda t, q, qd: ctl(t, q, qd), method="implicit")


# ------------------------------------------------------------------ joint limits
@pytest.mark.parametrize("method", ["rk4", "implicit", "semi_implicit"])
def test_a_falling_arm_stays_inside_its_limits(panda, method):
    lo, hi = panda.lower_limits, panda.upper_limits
    x0 = np.r_[np.clip(np.zeros(panda.n), lo, hi), np.zeros(panda.n)]
    free = kd.simulate(panda, 2.0, x0, method=method, dt=1e-4 if method != "implicit" else 1e-3, record_every=10)
    outside = (free.q < lo - 1e-9) | (free.q > hi + 1e-9)
    assert outside.any(), "the premise: without limits the free fall passes through them"
    held = kd.simulate(
        panda, 2.0, x0, method=method, dt=1e-4 if method != "implicit" else 1e-3, record_every=10, joint_limits=True
    )
    assert np.all(held.q >= lo - 1e-12) and np.all(held.q <= hi + 1e-12)
    # the joints that hit a stop rest on it
    on_stop = np.isclose(held.q[-1], lo) | np.isclose(held.q[-1], hi)
    assert on_stop.any()
    # without the option nothing changed: the same numbers as the option's default
    assert np.array_equal(
        free.q,
        kd.simulate(
            panda,
            2.0,
            x0,
            method=method,
            dt=1e-4 if method != "implicit" else 1e-3,
            record_every=10,
            joint_limits=False,
        ).q,
    )


def test_joint_limits_errors(puma):
    with pytest.raises(ValueError, match="joint_limits needs a fixed-step method"):
        kd.simulate(puma, 0.1, np.zeros(12), method="rk45", joint_limits=True)


def test_joint_limits_on_the_python_loop(panda):
    lo, hi = panda.lower_limits, panda.upper_limits
    x0 = np.r_[np.clip(np.zeros(panda.n), lo, hi), np.zeros(panda.n)]
    Q = _python_loop(panda, "implicit", x0, 1000, 1e-3, (np.asarray(lo, float), np.asarray(hi, float)), every=10)[0]
    assert np.all(Q >= lo - 1e-12) and np.all(Q <= hi + 1e-12)


# ------------------------------------------------------------------ budgets
@pytest.mark.parametrize(
    "how",
    [
        dict(),
        dict(method="implicit"),
        dict(method="rk45"),
        dict(f_ext=np.zeros((6, 6))),
        dict(controller=lambda t, q, qd: np.zeros(6)),
    ],
)
def test_a_time_budget_cuts_a_run_short_and_says_so(puma, how):
    x0 = np.r_[0.1, 0.5, -0.3, 0.2, 0.4, 0.1, np.zeros(6)]
    start = time.perf_counter()
    with pytest.warns(SimulationTruncatedWarning, match="time budget of 0.2 s"):
        traj = kd.simulate(puma, 1e4, x0, time_budget=0.2, **how)
    assert time.perf_counter() - start < 10.0  # unbounded, this run takes hours
    assert "stopped by its time budget" in traj.info["truncated"]
    assert 0 <= traj.t[-1] < 1e4
    assert traj.q.shape == (traj.t.size, 6) and np.all(np.isfinite(traj.q))
    np.testing.assert_allclose(traj.q[0], x0[:6])


def test_a_batch_cut_short_keeps_the_same_samples(puma):
    X = np.column_stack([puma.random_configuration(np.random.default_rng(0), size=3), np.zeros((3, 6))])
    with pytest.warns(SimulationTruncatedWarning):
        traj = kd.simulate(puma, 1e4, X, time_budget=0.2)
    assert traj.q.shape == (3, traj.t.size, 6)
    single = kd.simulate(puma, traj.t[-1], X[1])
    np.testing.assert_array_equal(traj.q[1], single.q)


def test_the_report_on_talos_is_bounded_and_says_when_it_cut_the_simulation(tmp_path, capsys):
    path = erd(*TALOS)
    start = time.perf_counter()
    code, text, err = run(capsys, "report", path, "-o", str(tmp_path / "talos.html"), "--json")
    elapsed = time.perf_counter() - start
    assert code == 0, err
    assert elapsed < 60.0  # the bound; it took 17 minutes before
    d = json.loads(text)
    # with its gripper's mimic joints reduced (the default since mimic support), Talos is no longer
    # stiff and the automatic choice is RK4; the stiff -> implicit choice is checked on the Panda above
    assert d["simulation_method"].startswith("kd.simulate") and d["simulation_note"] is None
    page = (tmp_path / "talos.html").read_text()
    assert "up to 3 joints" in page  # the symbolic equations are skipped, with a note
    # a budget too small for the run: the page and the terminal say that it was cut short
    code, text, err = run(
        capsys, "report", path, "-o", str(tmp_path / "cut.html"), "--t", "1000", "--time-budget", "0.5"
    )
    assert code == 0, err
    page = (tmp_path / "cut.html").read_text()
    assert "id='simulation-cut-short'" in page and "The simulation was cut short" in page
    assert "cut short" in text


# ------------------------------------------------------------------ command line
def test_cli_per_joint_gains_and_limits(capsys):
    # PD without gravity compensation settles where Kp e = g(q): each joint's own gain shows
    goal, kp = np.array([0.3, -0.5, 0.4, 0, 0, 0]), np.array([400, 300, 300, 50, 50, 50])
    code, text, err = run(
        capsys,
        "simulate",
        "puma560",
        "--t",
        "6",
        "--controller",
        "pd",
        "--goal",
        *map(str, goal),
        "--kp",
        *map(str, kp),
        "--kd",
        "40",
        "--json",
    )
    assert code == 0, err
    d = json.loads(text)  # nothing else on stdout: no progress bar
    q = np.array(d["q_final"])
    np.testing.assert_allclose(kp * (goal - q), kd.robots.puma560().gravity_torque(q), atol=1e-3)
    assert np.abs(d["qd_final"]).max() < 1e-4
    code, _, err = run(capsys, "simulate", "puma560", "--kp", "1", "2")
    assert code == 1 and "--kp takes one gain for every joint or one per joint (6" in err
    code, _, err = run(
        capsys, "simulate", "puma560", "--method", "rk4", "--controller", "pd", "--kp", "1e7", "--t", "0.1"
    )
    assert (
        code == 1 and "blew up" in err and "reduce --dt, use --method implicit" in err and "error.trajectory" not in err
    )
    code, _, err = run(capsys, "simulate", "puma560", "--joint-limits", "--method", "rk45")
    assert code == 1 and "--joint-limits needs a fixed-step --method" in err
    code, text, err = run(
        capsys, "simulate", "puma560", "--t", "2", "--q", "0", "1.2", "0", "0", "0", "0", "--joint-limits", "--json"
    )
    assert code == 0, err
    robot = kd.robots.puma560()
    q = np.array(json.loads(text)["q_final"])
    assert np.all(q >= robot.lower_limits - 1e-12) and np.all(q <= robot.upper_limits + 1e-12)


# ------------------------------------------------------------------ progress
def test_progress_is_on_stderr_only_when_asked_or_on_a_terminal(capsys, puma):
    from kinedyn._ui.progress import Steps

    with Steps("work", 2, progress=None) as s:  # pytest's stderr is not a terminal
        assert s.bar is None
        s.step("one")
    assert capsys.readouterr().err == ""
    with Steps("work", 2, progress=True) as s:
        assert s.bar is not None and s.bar.console.file is sys.stderr
        s.step("one")
        s.step("two")
        assert s.bar.tasks[0].completed == 1 and s.bar.tasks[0].description == "two"
    assert capsys.readouterr().out == ""
    kd.simulate(puma, 0.2, np.zeros(12), progress=True)
    assert capsys.readouterr().out == ""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kd.simulate(puma, 0.2, np.zeros(12))
    assert capsys.readouterr().err == ""


def test_stiff_scipy_methods_get_the_analytical_jacobian(panda):
    """Radau/BDF on the stiff Panda: the Jacobian comes from the analytical derivatives and the
    controller's own jacobian (called), and the run converges like the implicit fixed step."""
    ctl = PDGravity(panda, 100.0, 20.0, PANDA_GOAL)
    calls = []
    inner = ctl.jacobian
    ctl.jacobian = lambda t, q, qd: calls.append(t) or inner(t, q, qd)
    traj = kd.simulate(panda, 2.0, np.zeros(2 * panda.n), controller=ctl, method="bdf", dt=1e-2, rtol=1e-8, atol=1e-10)
    assert calls, "the controller's Jacobian was not used"
    implicit = kd.simulate(
        panda,
        2.0,
        np.zeros(2 * panda.n),
        controller=PDGravity(panda, 100.0, 20.0, PANDA_GOAL),
        dt=1e-4,
        record_every=100,
    )
    np.testing.assert_allclose(traj.q, implicit.q, atol=2e-3)


def test_a_batch_ik_with_progress_gives_the_same_answers(monkeypatch, capsys):
    """Progress sends a numeric IK batch to the core in chunks; each target's random restarts follow
    from the seed and its index in the whole batch, so the answers are those of one call."""
    from kinedyn.ik import solve as ik_solve

    robot = kd.robots.ur5()
    targets = robot.forward_kinematics(robot.random_configuration(rng=3, size=250))[:, -1]
    settings = dict(method="numeric", max_iterations=12, restarts=6, seed=7)  # few iterations: the restarts decide
    whole = robot.inverse_kinematics(targets, progress=False, **settings)
    monkeypatch.setattr(ik_solve, "IK_CHUNK", 64)
    chunked = robot.inverse_kinematics(targets, progress=True, **settings)
    assert 0 < whole.success.sum() < len(targets)  # some targets need their restarts
    np.testing.assert_array_equal(chunked.q, whole.q)
    np.testing.assert_array_equal(chunked.success, whole.success)
    assert capsys.readouterr().out == ""  # the bar is on stderr


@pytest.mark.parametrize("name", ["[/bold] arm", "a[red]b", "x[/]"])
def test_progress_shows_names_that_look_like_markup(name, monkeypatch, capsys):
    """Progress labels carry robot names; rich would read '[/bold]' as markup and fail."""
    from kinedyn._ui import progress

    bar = progress.Delayed(True, 10, f"simulate {name}")
    bar.update(5)
    bar.close()
    with progress.Steps(f"report {name}", 2, True) as steps:
        steps.step(f"simulation of {name}")
    with progress.busy(f"deriving {name}", True):
        pass
    assert capsys.readouterr().out == ""


def test_derive_runs_under_a_spinner_on_a_terminal(monkeypatch, capsys):
    from kinedyn._ui import progress

    labels = []
    real_busy = progress.busy

    def recording(label, progress=None):
        labels.append((label, progress))
        return real_busy(label, False)

    monkeypatch.setattr(progress, "busy", recording)
    assert main(["derive", "planar_2r", "--format", "text"]) == 0
    assert main(["derive", "planar_2r", "--json"]) == 0
    capsys.readouterr()
    assert labels == [
        ("deriving the equations of motion of 'planar_2r' (lagrange)", None),
        ("deriving the equations of motion of 'planar_2r' (lagrange)", False),
    ]
