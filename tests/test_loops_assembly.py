"""A closed mechanism's assembly mode: the reference configuration a robot file states (YAML/TOML
``reference_configuration:``, URDF ``<reference_configuration>``), which the drawings start from
(``default_configuration``), the writers keep, and whose errors name file and joint
(docs/closed-loops.md, "The assembly mode")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.configuration import default_configuration

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "robots"


@pytest.fixture(scope="module")
def five_bar():
    return kd.load(str(EXAMPLES / "five_bar.yaml"))


def test_five_bar_starts_on_its_parallelogram(five_bar):
    """Spong's five-bar closes on two branches; projected from the generic configuration it lands on
    the crossed one (q4 = q3), from its stated reference on the parallelogram of section 9.4."""
    i = {name: k for k, name in enumerate(five_bar.joint_names)}
    q = default_configuration(five_bar)
    assert np.abs(five_bar.loop_residual(q)).max() < 1e-12
    q1, q2, q3, q4 = (q[i[n]] for n in ("q1", "q2", "q3", "q4"))
    assert q3 == pytest.approx(q1 - q2, abs=1e-9) and q4 == pytest.approx(q2 - q1, abs=1e-9)
    # without the statement: the other branch, the reason the statement exists
    crossed = default_configuration(five_bar.replace(reference_configuration=None))
    assert crossed[i["q4"]] == pytest.approx(crossed[i["q3"]], abs=1e-9)
    # a statement slightly open is still closed (projected), on its branch
    near = {"q1": 0.5, "q2": 2.0, "q3": -1.5 + 1e-3, "q4": 1.5 - 2e-3}
    q = default_configuration(five_bar.replace(reference_configuration=near))
    assert np.abs(five_bar.loop_residual(q)).max() < 1e-12
    assert q[i["q3"]] == pytest.approx(q[i["q1"]] - q[i["q2"]], abs=1e-9)


def test_parallelogram_arm_starts_uncrossed():
    robot = kd.load(str(EXAMPLES / "parallelogram_arm.urdf"))
    q = dict(zip(robot.joint_names, default_configuration(robot)))
    assert q["elbow_drive"] == pytest.approx(q["shoulder"] + q["elbow"], abs=1e-9)
    assert q["rod_pin"] == pytest.approx(-q["elbow"], abs=1e-9)


@pytest.mark.parametrize("suffix", [".yaml", ".toml", ".urdf"])
def test_reference_round_trips_through_the_writers(five_bar, tmp_path, suffix):
    path = tmp_path / f"five_bar{suffix}"
    if suffix == ".urdf":
        five_bar.to_urdf(path)
    else:
        five_bar.save(path)
    back = kd.load(str(path), gravity=five_bar.gravity) if suffix == ".urdf" else kd.load(str(path))
    assert back.description.reference_configuration == five_bar.description.reference_configuration
    assert np.array_equal(default_configuration(back), default_configuration(five_bar))


def test_lock_joints_drops_the_locked_joints_statement(five_bar):
    locked = five_bar.lock_joints({"q1": 0.3})
    assert set(locked.description.reference_configuration) == {"q2", "q3", "q4"}


def test_wrong_joint_names_and_counts_are_named(tmp_path):
    text = (EXAMPLES / "five_bar.yaml").read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("reference_configuration: {q1:", "reference_configuration: {qq1:"))
    with pytest.raises(
        ValueError, match=r"bad\.yaml, line \d+: reference_configuration\.qq1: names no moving joint 'qq1'"
    ):
        kd.load(str(bad))
    urdf = (EXAMPLES / "parallelogram_arm.urdf").read_text().replace('name="elbow" value', 'name="elbo" value')
    with pytest.raises(
        ValueError, match=r":\d+: <reference_configuration> names joint 'elbo', which is no moving <joint>"
    ):
        kd.Robot.from_urdf(urdf)
    urdf = (EXAMPLES / "parallelogram_arm.urdf").read_text().replace('value="1.1"', 'value="1.1 2"')
    with pytest.raises(ValueError, match=r":\d+: the reference value of joint 'elbow' must be 1 numbers"):
        kd.Robot.from_urdf(urdf)
    robot = kd.load(str(EXAMPLES / "pushrod_leg.urdf"))
    with pytest.raises(ValueError, match=r"joint 'root' \(floating\) needs 7 numbers"):
        robot.replace(reference_configuration={"root": [0, 0, 0, 1]})


def test_mjcf_states_its_assembly_mode_by_qpos0():
    """An MJCF body-form equality closes at MuJoCo's qpos0 (each hinge at its ``ref``): the reader
    states qpos0 as the reference, and the drawing starts there (closed by construction)."""
    mjcf = """<mujoco model="pinned"><compiler angle="radian"/><worldbody>
      <body name="crank"><joint name="j1" axis="0 0 1" ref="0.3"/><geom size="0.01"/>
        <body name="coupler" pos="0.1 0 0"><joint name="j2" axis="0 0 1" ref="-0.2"/><geom size="0.01"/></body></body>
      <body name="rocker" pos="0.4 0 0"><joint name="j3" axis="0 0 1" ref="0.1"/><geom size="0.01"/></body>
    </worldbody><equality><connect name="pin" body1="coupler" body2="rocker" anchor="0.3 0.2 0"/></equality></mujoco>"""
    with pytest.warns(UserWarning, match="softness"):
        robot = kd.Robot.from_mjcf(mjcf)
    assert robot.reference_configuration == {"j1": 0.3, "j2": -0.2, "j3": 0.1}
    q = default_configuration(robot)
    np.testing.assert_allclose(q, [0.3, -0.2, 0.1], atol=1e-12)
