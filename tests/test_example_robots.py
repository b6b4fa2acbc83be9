"""The robot files shipped in examples/robots describe the same arms as the built-ins: equal tool
poses, mass matrices and gravity torques at random states (three formats, three routes)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd

pytest.importorskip("kinedyn._core", reason="the native module is not built")

FILES = Path(__file__).resolve().parents[1] / "examples" / "robots"
RNG = np.random.default_rng(7)


def same_arm(a, b, states=5):
    for q in RNG.uniform(-3, 3, size=(states, a.n)):
        np.testing.assert_allclose(a.pose(q), b.pose(q), atol=1e-12)
        np.testing.assert_allclose(a.mass_matrix(q), b.mass_matrix(q), atol=1e-12)
        np.testing.assert_allclose(a.gravity_torque(q), b.gravity_torque(q), atol=1e-12)


@pytest.mark.parametrize(
    "file, builtin, kwargs",
    [
        ("tutorial_two_link.yaml", "planar_2r", {}),
        ("planar_2r.urdf", "planar_2r", {"gravity": (0.0, -9.81, 0.0)}),
        ("elbow_arm.toml", "elbow_3r", {}),
    ],
)
def test_robot_files_equal_the_builtins(file, builtin, kwargs):
    same_arm(kd.load(FILES / file, **kwargs), kd.robots.get(builtin))


def test_symbolic_file_derives_the_builtin_equations():
    import sympy as sp

    from_file = kd.load(FILES / "two_link_symbolic.yaml")
    builtin = kd.robots.planar_2r(symbolic=True)
    assert {s.name for s in from_file.symbols} == {s.name for s in builtin.symbols}
    values = {"l1": 2.0, "l2": 3.0, "lc1": 0.8, "lc2": 1.1, "m1": 1.5, "m2": 0.7, "I1": 0.2, "I2": 0.4, "g": 9.81}
    a = from_file.subs({s: values[s.name] for s in from_file.symbols})
    b = builtin.subs({s: values[s.name] for s in builtin.symbols})
    same_arm(a, b)
    eom = from_file.equations_of_motion()
    assert isinstance(eom.M, sp.MatrixBase) and eom.M.shape == (2, 2)
