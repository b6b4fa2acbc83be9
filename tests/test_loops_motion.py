"""kd.simulate on a robot with closed loops (docs/closed-loops.md, "Motion"): the loops stay closed,
a frictionless four-bar keeps its energy, a batch is its runs, the command line runs the file."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd

ROOT = Path(__file__).resolve().parents[1]
FOUR_BAR = ROOT / "examples" / "robots" / "four_bar.yaml"
# the file's closed configuration (crank at 60 degrees, open branch)
Q_CLOSED = np.array([1.0471975511966, -0.418482423551057, 1.79577497339621])


@pytest.fixture(scope="module")
def four_bar():
    return kd.load(str(FOUR_BAR))


@pytest.fixture(scope="module")
def swing(four_bar):
    """5 s of the unforced four-bar from the crank turning at 3 rad/s, RK4 at 1 ms."""
    qd = four_bar.project_velocity(Q_CLOSED, [3.0, 0.0, 0.0])
    return kd.simulate(four_bar, 5.0, np.concatenate([Q_CLOSED, qd]), dt=1e-3)


def test_loop_stays_closed(four_bar, swing):
    # measured: max |residual| 1.0e-14 m over the run with the projection (its Gauss-Newton
    # tolerance); the same run without it drifts to 4.4e-7 m (3.7e-3 m at dt = 10 ms)
    residual = np.abs(four_bar.loop_residual(swing.q)).max()
    assert residual < 2e-14
    assert swing.info["loop_residual_max"] == pytest.approx(residual)
    velocity = np.abs(np.einsum("smn,sn->sm", four_bar.loop_jacobian(swing.q), swing.qd)).max()
    assert velocity < 1e-10
    # the crank swings through more than half a turn (5.8 rad): the run is not a small wiggle
    assert np.ptp(swing.q[:, 0]) > np.pi


def test_four_bar_conserves_energy(four_bar, swing):
    K = np.array([four_bar.kinetic_energy(q, qd) for q, qd in zip(swing.q, swing.qd)])
    P = np.array([four_bar.potential_energy(q) for q in swing.q])
    H = K + P
    scale = K.max() + np.ptp(P)  # ~1.3 J exchanged between K and P
    assert scale > 1.0
    # measured: max |H - H(0)| = 1.1e-8 J over 5 s (8e-9 of the scale)
    assert np.abs(H - H[0]).max() < 1e-7
    assert np.allclose(H, swing.H, atol=1e-12)


def test_loop_forces_hold_the_motion(four_bar, swing):
    """M qdd + h = tau + J^T lam at the samples, with the recorded qdd and loop forces."""
    lam = swing.loop_forces
    assert lam.shape == (len(swing), 3)
    for k in (0, 1000, 4000):
        q, qd, qdd = swing.q[k], swing.qd[k], swing.qdd[k]
        lhs = four_bar.inverse_dynamics(q, qd, qdd)
        rhs = swing.tau[k] + four_bar.loop_jacobian(q).T @ lam[k]
        assert np.allclose(lhs, rhs, atol=1e-9)


def test_batch_is_its_runs(four_bar):
    q1 = four_bar.project_configuration(Q_CLOSED + [0.3, 0.0, 0.0], hold=["crank_joint"])
    Q = np.stack([Q_CLOSED, q1])
    QD = four_bar.project_velocity(Q, np.array([[1.0, 0, 0], [-2.0, 0, 0]]))
    X = np.concatenate([Q, QD], axis=1)
    tau = [0.05, 0.0, 0.0]
    batch = kd.simulate(four_bar, 0.5, X, u=tau, dt=2e-3, method="semi_implicit")
    for i in range(2):
        one = kd.simulate(four_bar, 0.5, X[i], u=tau, dt=2e-3, method="semi_implicit")
        assert np.array_equal(batch.q[i], one.q)
        assert np.array_equal(batch[i].loop_forces, one.loop_forces)


def test_open_start_is_projected_and_bad_methods_refused(four_bar):
    start = Q_CLOSED + [0.0, 0.01, -0.01]
    traj = kd.simulate(four_bar, 0.01, np.concatenate([start, np.zeros(3)]), dt=1e-3)
    assert np.abs(four_bar.loop_residual(traj.q[0])).max() < 1e-12
    assert 0 < traj.info["loop_start_shift"]["q"] < 0.02
    with pytest.raises(ValueError, match="closed loops.*rk45"):
        kd.simulate(four_bar, 0.01, np.concatenate([Q_CLOSED, np.zeros(3)]), method="rk45")


@pytest.mark.parametrize("name", ["four_bar.yaml", "five_bar.yaml"])
def test_cli_simulates_a_linkage_from_a_closed_start(name):
    """Zeros are a singular configuration of both (stretched flat, folded): the command line starts
    from a regular closed one. Measured: four-bar 2.6e-9, five-bar 5.8e-11 of the energy scale (7.3e-6
    with the stages unprojected)."""
    out = subprocess.run(
        [sys.executable, "-m", "kinedyn", "simulate", str(ROOT / "examples" / "robots" / name), "--t", "1", "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    payload = json.loads(out.stdout)
    assert payload["method"] == "rk4"
    assert payload["loop_residual_max"] < 2e-14
    assert payload["energy_drift_relative"] < 1e-8


@pytest.mark.parametrize("name", ["four_bar.yaml", "five_bar.yaml", "parallelogram_arm.urdf"])
def test_drawings_start_closed(name):
    """The report, the viewer and the notebook drawings start at default_configuration: closed for a
    robot with loops (the generic 0.5, -0.7, ... projected onto them)."""
    from kinedyn.configuration import default_configuration
    from kinedyn.report.data import collect

    robot = kd.load(str(ROOT / "examples" / "robots" / name))
    q = default_configuration(robot)
    assert np.abs(robot.loop_residual(q)).max() < 1e-12
    data = collect(robot, t_end=0.05, eom_joints=0, time_budget=None)
    assert np.array_equal(np.asarray(data["q"]), q)
    # the frames the loop pins together are drawn at one point
    loop = robot.loops[0]
    a, b = robot.frame_poses(q, [loop.frame_a, loop.frame_b])
    assert np.allclose(a[:3, 3], b[:3, 3], atol=1e-12)


def test_singular_configuration_stops_the_run_with_its_samples():
    """Spong's five-bar folded flat (zeros) is closed but singular: the loops cannot all hold under
    gravity there, and the run stops with a SimulationError naming the loop, not a bare ValueError."""
    five_bar = kd.load(str(ROOT / "examples" / "robots" / "five_bar.yaml"))
    with pytest.raises(kd.simulate.SimulationError, match="loop 'parallelogram'") as caught:
        kd.simulate(five_bar, 0.1, np.zeros(8), dt=1e-3)
    assert caught.value.step == 0 and len(caught.value.trajectory) == 1


def test_report_energy_check_of_the_five_bar_passes_and_names_the_singular_passage():
    """The report's free fall of Spong's five-bar from its drawing configuration (the file's reference,
    the parallelogram at q1 = 0.5, q2 = 2.0; RK4 at 1 ms) passes near a singular configuration of the
    loop (the loop Jacobian's s_2/s_1 down to 1.8e-3 at the samples, t = 0.342 s). Measured: energy
    drift 1.4e-8 J over 0.5 s (8.8e-8 J over the report's 3 s; tolerance 1e-6 of max |H|)."""
    from kinedyn.report.data import NEAR_SINGULAR, collect

    five_bar = kd.load(str(ROOT / "examples" / "robots" / "five_bar.yaml"))
    data = collect(five_bar, t_end=0.5, eom_joints=0, time_budget=None)
    (energy,) = [p for p in data["properties"] if p["property"].startswith("energy conserved")]
    assert energy["ok"] and energy["value"] < 1e-6, energy
    passage = data["simulation"]["singular_passage"]
    assert passage["rank"] == 2 and passage["ratio"] < 3e-3 < NEAR_SINGULAR
    assert 0.3 < passage["t"] < 0.4
    assert "passes near a singular configuration of the loops" in energy["measure"]
    assert data["simulation"]["note"] is None  # the whole run
