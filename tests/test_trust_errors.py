"""Errors that name the problem, and no non-finite result that slips through (issue 25).

Each input here gave Python's own words (ZeroDivisionError, the int-limit message), a NaN result or a
silently changed value before; each must now be a ValueError or TypeError that names the file, line,
joint or argument.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
from kinedyn.analysis.logs import LogError, load_log  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from test_mimic import gripper_urdf  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def test_a_5000_digit_yaml_integer_names_the_line(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_text("joints:\n  - {a: 1, mass: " + "9" * 5000 + "}\n")
    with pytest.raises(ValueError, match=r"big\.yaml: .*line 2.*the integer has 5000 digits"):
        kd.load(path)
    path.write_text("joints:\n  - {a: 1, mass: 0x1f}\n")
    assert kd.load(path).links[0].inertia.mass == 31  # ordinary integers still read


def test_an_mjcf_capsule_of_radius_1e_300_names_the_body(tmp_path):
    path = tmp_path / "cap.xml"
    path.write_text(
        '<mujoco><worldbody><body name="arm"><joint name="j" axis="0 0 1"/>\n'
        '<geom type="capsule" fromto="0 0 0 0 0 1" size="1e-300"/></body></worldbody></mujoco>'
    )
    with pytest.raises(ValueError, match=r"cap\.xml:2: .*body 'arm'.*not finite"):
        kd.load(path)


def test_a_log_step_of_1e_302_s_is_named(tmp_path):
    t = np.arange(400) * 1e-302
    q = np.sin(np.linspace(0, 20, 400))
    np.savez(tmp_path / "tiny.npz", t=t, q1=q, tau1=q)
    with pytest.raises(LogError, match=r"tiny\.npz: the filtered .* are not finite.*1e-302 s"):
        load_log(tmp_path / "tiny.npz", n=1, cutoff=1e300)


@pytest.fixture(scope="module")
def floating():
    return kd.Robot.from_urdf(str(ROOT / "examples" / "robots" / "planar_2r.urdf"), floating_base=True)


def test_integrate_and_interpolate_never_return_nan(floating):
    r = floating
    q0 = kd.configuration.neutral(r)
    q1 = kd.configuration.integrate(r, q0, np.r_[1.0, 0, 0, 0, 0, 1.0, 0, 0])
    with pytest.raises(ValueError, match="floating joint 'root_joint'.*beyond what float64 holds"):
        kd.configuration.integrate(r, q0, np.full(r.nv, 1e300))
    with pytest.raises(ValueError, match="beyond what float64 holds"):
        kd.configuration.interpolate(r, q0, q1, 1e200)
    with pytest.raises(TypeError, match="t must be real numbers.*complex"):
        kd.configuration.interpolate(r, q0, q1, 0.5 + 1j)
    assert np.all(np.isfinite(kd.configuration.interpolate(r, q0, q1, 0.5)))


@pytest.mark.parametrize("bad", [np.nan, np.inf, None])
def test_normalize_refuses_what_is_not_a_number(floating, bad):
    q = np.array(kd.configuration.neutral(floating), dtype=object)
    q[2] = bad
    with pytest.raises((ValueError, TypeError), match=r"q\[2\]|real numbers"):
        kd.configuration.normalize(floating, q)


def test_forward_dynamics_with_mimic_joints_never_returns_nan():
    r = kd.Robot.from_urdf(gripper_urdf(chain=True))
    assert r.mimic_joints
    with pytest.raises(kd.NonFiniteResultError, match=r"forward_dynamics: qdd\[\d\] is nan"):
        r.forward_dynamics(np.zeros(r.nq), np.zeros(r.n), np.full(r.n, 1.7e308))
    assert np.all(np.isfinite(r.forward_dynamics(np.zeros(r.nq), np.zeros(r.n), np.ones(r.n))))


def test_a_bad_inertial_pos_names_the_file_once(tmp_path):
    """Found by the fuzz suite's MJCF cases: the pose's own error was wrapped in a second prefix."""
    path = tmp_path / "arm.xml"
    path.write_text(
        '<mujoco><worldbody><body name="l1"><joint name="j1" axis="0 0 1"/>\n'
        '<inertial pos="0.15 0 0x1F" mass="0.7" diaginertia="0.001 0.004 0.004"/></body></worldbody></mujoco>'
    )
    with pytest.raises(ValueError, match=r"arm\.xml:2: <inertial> attribute 'pos' must be numbers") as e:
        kd.load(path)
    assert str(e.value).count(str(path)) == 1
