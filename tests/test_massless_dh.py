"""A DH table without masses says so when it is built (not at the first forward-dynamics error), and
every message names a joint by its name, never its 0-based index beside a 1-based name."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.dh import MasslessRobotWarning

pytest.importorskip("kinedyn._core", reason="the native module is not built")


def test_from_dh_without_masses_warns_at_construction():
    with pytest.warns(MasslessRobotWarning, match=r"M\(q\) = 0.*kinematics"):
        robot = kd.Robot.from_dh([kd.DHRow(a=1.0), kd.DHRow(a=1.0), kd.DHRow(a=0.5)])
    assert not np.any(robot.mass_matrix(np.zeros(3)))  # what the warning announces
    with warnings.catch_warnings():
        warnings.simplefilter("error", MasslessRobotWarning)
        kd.Robot.from_dh([kd.DHRow(a=1.0, inertia=kd.Inertia.rod(1.0, 1.0)), kd.DHRow(a=1.0)])  # one mass: no warning
        kd.Robot.from_dh([kd.DHRow(a=1.0, rotor_inertia=1e-4, gear_ratio=50.0)])  # a rotor: M = diag(r^2 J_m)
        kd.robots.planar_2r(symbolic=True)  # symbolic masses are not known to be zero


def test_forward_dynamics_error_names_the_joint_not_its_index():
    with pytest.warns(MasslessRobotWarning):
        robot = kd.Robot.from_dh([kd.DHRow(a=1.0), kd.DHRow(a=1.0), kd.DHRow(a=0.5)])
    with pytest.raises(RuntimeError) as info:
        robot.forward_dynamics(np.zeros(3), np.zeros(3), np.ones(3))
    message = str(info.value)
    assert "joint 'q3' (moving body 'link3')" in message
    assert "joint 2" not in message  # the core's 0-based index of q3
    assert "no mass or inertia on any link" in message
    # a robot with some mass: the same naming, and no "no mass" note
    arm = kd.Robot.from_dh([kd.DHRow(a=1.0, inertia=kd.Inertia.rod(1.0, 1.0)), kd.DHRow(a=1.0), kd.DHRow(a=0.5)])
    with pytest.raises(RuntimeError) as info:
        arm.mass_matrix_inverse(np.zeros(3))
    message = str(info.value)
    assert "joint 'q3'" in message and "joint 2" not in message and "no mass or inertia on any link" not in message
