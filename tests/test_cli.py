"""The command line: exit codes, --json documents equal to the library's numbers, bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.cli import main

pytest.importorskip("kinedyn._core", reason="the native module is not built")


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def run_json(capsys, *argv):
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0, err
    return json.loads(out)


def test_robots_lists_the_catalogue(capsys):
    doc = run_json(capsys, "robots")
    assert set(doc["robots"]) == set(kd.robots.names())
    code, out, _ = run(capsys, "robots")
    assert code == 0 and "planar_2r" in out


def test_info_default_robot_is_the_tutorial_arm(capsys):
    doc = run_json(capsys, "info")
    robot = kd.robots.planar_2r()
    assert doc["name"] == "planar_2r" and doc["n"] == 2
    assert [r["a"] for r in doc["dh"]] == [2.0, 3.0]
    assert doc["total_mass"] == pytest.approx(sum(float(b.inertia.mass) for b in robot.tree.bodies))
    code, out, _ = run(capsys, "info", "puma560")
    assert code == 0 and "DH table" in out and "mass properties" in out


def test_fk_json_equals_library_pose(capsys):
    doc = run_json(capsys, "fk", "elbow_3r", "--q", "10", "20", "-30", "--deg")
    robot = kd.robots.elbow_3r()
    expected = robot.pose(np.radians([10, 20, -30]))
    np.testing.assert_allclose(doc["frames"]["tool"]["pose"], expected, atol=1e-12)
    doc = run_json(capsys, "fk", "elbow_3r", "--all")
    assert set(doc["frames"]) == set(robot.frame_names)


def test_jacobian_json_reports_singularity(capsys):
    doc = run_json(capsys, "jacobian", "--q", "0.5", "0", "--task", "planar")
    robot = kd.robots.planar_2r()
    np.testing.assert_allclose(doc["jacobian"], robot.jacobian([0.5, 0.0])[:2], atol=1e-12)
    assert doc["singular"] is True and doc["rank"] == 1
    doc = run_json(capsys, "jacobian", "--q", "0.5", "1.0", "--task", "planar")
    assert doc["singular"] is False
    assert doc["manipulability"] == pytest.approx(2 * 3 * math.sin(1.0))


def test_robot_files_are_accepted(capsys, tmp_path):
    path = tmp_path / "arm.yaml"
    kd.robots.elbow_3r().save(path)
    doc = run_json(capsys, "fk", str(path), "--q", "0.1", "0.2", "0.3")
    np.testing.assert_allclose(doc["frames"]["tool"]["pose"], kd.robots.elbow_3r().pose([0.1, 0.2, 0.3]), atol=1e-12)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["fk", "no_such_robot"], "neither a built-in"),
        (["fk", "planar_2r", "--q", "1", "2", "3"], "needs 2 values"),
        (["jacobian", "planar_2r", "--frame", "hand"], "unknown frame"),
        (["info", "missing.urdf"], "does not exist"),
        (["jacobian", "planar_2r", "--task", "xy"], "unknown task"),
    ],
)
def test_bad_input_exits_nonzero_with_a_message(capsys, argv, message):
    code, _, err = run(capsys, *argv)
    assert code == 1 and message in err and "Traceback" not in err


def test_derive_symbolic_json_equals_the_library(capsys):
    import sympy as sp

    doc = run_json(capsys, "derive", "--symbolic")
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion()
    names = {str(s): s for s in eom.M.free_symbols | eom.g.free_symbols | set(eom.q) | set(eom.qd)}
    M = sp.Matrix(doc["M"]).subs({sp.Symbol(k): v for k, v in names.items()})
    assert sp.simplify(M - eom.M) == sp.zeros(2, 2)
    assert doc["op_count"] and doc["q"] == ["q1", "q2"]


@pytest.mark.parametrize("fmt, marker", [("latex", "\\"), ("c", "void"), ("python", "def "), ("markdown", "$")])
def test_derive_formats_write_files(capsys, tmp_path, fmt, marker):
    out = tmp_path / f"eom.{fmt}"
    code, text, err = run(capsys, "derive", "elbow_3r", "--format", fmt, "-o", str(out))
    assert code == 0, err
    assert marker in out.read_text() and str(out) in text
    if fmt == "python":
        compile(out.read_text(), str(out), "exec")


def test_derive_rejects_symbolic_for_a_robot_without_symbols(capsys):
    code, _, err = run(capsys, "derive", "puma560", "--symbolic")
    assert code == 1 and "--symbolic needs a built-in" in err


@pytest.mark.parametrize(
    "argv, message",
    [
        (["check", "no_such_robot"], "neither a built-in"),
        (["identify", "planar_2r", "--noise", "-1"], "argument --noise: must be a number >= 0"),
        (["simulate", "planar_2r", "--t", "1", "--dt", "0"], "argument --dt: must be a positive number"),
        (["ik", "elbow_3r", "--xyz", "1", "0.2", "nan"], "NaN"),
        (["derive", "no_such_robot"], "neither a built-in"),
        (["dynamics", "planar_2r", "--q", "0", "0", "--qd", "1"], "--qd needs 2 values"),
        (["dynamics", "planar_2r", "--tau", "1", "2", "3"], "--tau needs 2 values"),
    ],
)
def test_capability_commands_reject_bad_input(capsys, argv, message):
    code, _, err = run(capsys, *argv)
    assert code == 1 and message in err and "Traceback" not in err


def test_python_dash_m_kinedyn_is_the_command():
    import os
    import subprocess
    import sys
    from pathlib import Path

    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(Path(kd.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])
    )
    done = subprocess.run(
        [sys.executable, "-m", "kinedyn", "fk", "planar_2r", "--q", "0", "0", "--json"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["frames"]["tool"]["position"] == [5.0, 0.0, 0.0]


def test_dynamics_json_equals_the_library(capsys):
    q, qd, qdd, tau = (
        [0.1, -0.4, 0.7, 0.2, -1.0, 0.5],
        [0.3, 0.2, -0.1, 0.4, 0.0, 1.0],
        [1.0, -2.0, 0.5, 0.0, 0.3, -0.2],
        [5.0, 40.0, 10.0, 1.0, 0.5, 0.1],
    )
    args = [
        "dynamics",
        "ur5",
        "--q",
        *map(str, q),
        "--qd",
        *map(str, qd),
        "--qdd",
        *map(str, qdd),
        "--tau",
        *map(str, tau),
        "--derivatives",
    ]
    doc = run_json(capsys, *args)
    robot = kd.robots.ur5()
    np.testing.assert_allclose(doc["mass_matrix"], robot.mass_matrix(q), rtol=1e-13)
    np.testing.assert_allclose(doc["coriolis_matrix"], robot.coriolis_matrix(q, qd), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(doc["gravity_torque"], robot.gravity_torque(q), rtol=1e-13)
    np.testing.assert_allclose(doc["tau"], robot.inverse_dynamics(q, qd, qdd), rtol=1e-13)
    np.testing.assert_allclose(doc["forward_dynamics_qdd"], robot.forward_dynamics(q, qd, tau), rtol=1e-12)
    np.testing.assert_allclose(
        doc["dtau_dq"], robot.inverse_dynamics_derivatives(q, qd, qdd)[0], rtol=1e-13, atol=1e-13
    )
    assert doc["kinetic_energy"] == pytest.approx(robot.kinetic_energy(q, qd))
    code, text, _ = run(capsys, *args)
    assert code == 0 and "mass matrix" in text and "dtau/dq" in text


def test_jsonable_converts_every_numpy_scalar():
    import json as _json

    from kinedyn._ui.json import jsonable as _jsonable

    payload = {
        "b": np.bool_(True),
        "i": np.int32(3),
        "f": np.float32(0.5),
        "nan": np.float64("nan"),
        "inf": np.float64("inf"),
        "c": np.complex128(1 + 2j),
        "a": np.array([np.True_, np.False_]),
    }
    back = _json.loads(_json.dumps(_jsonable(payload)))
    assert back == {"b": True, "i": 3, "f": 0.5, "nan": None, "inf": "inf", "c": [1.0, 2.0], "a": [True, False]}


def test_simulate_energy_drift_has_a_scale_when_H0_is_zero(capsys):
    """planar_2r from rest at q = 0 has H(0) = 0: the relative drift was max|H - H(0)| / 1e-300 = 3e290.
    It is now relative to the energy the run exchanges, max K + range of P, recomputed here."""
    assert main(["simulate", "planar_2r", "--t", "1", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["energy_initial"] == 0.0
    robot = kd.robots.planar_2r()
    traj = kd.simulate(robot, 1.0, np.zeros(2 * robot.n))
    K = np.array([robot.kinetic_energy(q, qd) for q, qd in zip(traj.q, traj.qd)])
    P = np.array([robot.potential_energy(q) for q in traj.q])
    scale = K.max() + P.max() - P.min()
    assert scale > 1.0 and d["energy_scale"] == pytest.approx(scale, rel=1e-9)
    assert d["energy_drift"] == pytest.approx(np.abs(K + P).max(), rel=1e-6, abs=1e-14)
    assert d["energy_drift_relative"] == pytest.approx(d["energy_drift"] / scale) and d["energy_drift_relative"] < 1e-9
    assert main(["simulate", "planar_2r", "--t", "1"]) == 0
    out = capsys.readouterr().out
    assert "energy scale" in out and "max K + (max P - min P)" in out and "e+2" not in out


def test_simulate_energy_drift_at_rest_has_no_relative_value():
    from types import SimpleNamespace

    from kinedyn.cli.commands.simulate import energy_drift as _energy_drift

    still = SimpleNamespace(H=np.full(5, -3.0), K=np.zeros(5), P=np.full(5, -3.0))
    assert _energy_drift(still) == {
        "energy_drift": 0.0,
        "energy_scale": 0.0,
        "energy_scale_basis": "max K + (max P - min P) over the run",
        "energy_drift_relative": None,
    }


def _elbow_linear_jacobian(q, L2=2.0, L3=1.0):
    """The elbow arm's linear Jacobian, derived by hand: p = (c1 r, s1 r, L1 + z), r = L2 c2 + L3 c23, z = L2 s2 + L3 s23."""
    c1, s1 = math.cos(q[0]), math.sin(q[0])
    r = L2 * math.cos(q[1]) + L3 * math.cos(q[1] + q[2])
    z = L2 * math.sin(q[1]) + L3 * math.sin(q[1] + q[2])
    s23, c23 = math.sin(q[1] + q[2]), math.cos(q[1] + q[2])
    return np.array([[-s1 * r, -c1 * z, -L3 * c1 * s23], [c1 * r, -s1 * z, -L3 * s1 * s23], [0.0, r, L3 * c23]])


def test_jacobian_manipulability_of_a_positioning_arm_uses_the_rows_it_spans(capsys):
    """elbow_3r printed 'manipulability 0' beside 'full rank 3': w used all six rows of a 3-joint arm.
    It now uses vx, vy, vz, says so, and equals |det Jv| of the hand-derived Jv (= L2 L3 |s3| r)."""
    q = [0.3, 0.5, -1.0]
    assert main(["jacobian", "elbow_3r", "--q", *map(str, q), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    Jv = _elbow_linear_jacobian(q)
    assert d["analysis_rows"] == ["vx", "vy", "vz"] and "spans" in d["analysis_rows_basis"]
    assert d["manipulability"] == pytest.approx(abs(np.linalg.det(Jv)), rel=1e-9) and d["manipulability"] > 1
    assert d["rank"] == 3 and not d["singular"]
    assert len(d["rows"]) == 6  # the table still shows the whole Jacobian
    # stretched out (q3 = 0) the arm is singular in position, and the report says so
    assert main(["jacobian", "elbow_3r", "--q", "0.3", "0.5", "0", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["rank"] == 2 and d["singular"] and d["manipulability"] == pytest.approx(0, abs=1e-12)
    # the planar arm: vx, vy, w = l1 l2 |s2|
    assert main(["jacobian", "planar_2r", "--q", "0.2", "1.1", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    r = kd.robots.planar_2r()
    elbow, tip = (float(np.linalg.norm(r.frame_poses(np.zeros(2), [f])[0][:3, 3])) for f in ("link1", r.tool))
    l1, l2 = elbow, tip - elbow  # stretched out along x at q = 0
    assert d["analysis_rows"] == ["vx", "vy"]
    assert d["manipulability"] == pytest.approx(l1 * l2 * math.sin(1.1), rel=1e-9)
    # the human view names the rows
    assert main(["jacobian", "elbow_3r", "--q", *map(str, q)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "over rows vx, vy, vz" in out and "full rank 3" in out
    # a six-joint arm keeps all six rows; --task chooses explicitly
    assert main(["jacobian", "puma560", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["analysis_rows"] == ["vx", "vy", "vz", "wx", "wy", "wz"]
    assert main(["jacobian", "elbow_3r", "--q", *map(str, q), "--task", "orientation", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["analysis_rows"] == ["wx", "wy", "wz"]
