"""kinedyn._math.rpy_from_matrix, the one inverse of rpy_to_matrix (R = Rz(yaw) Ry(pitch) Rx(roll)):
it rebuilds R to rounding everywhere, gimbal lock (pitch = +-pi/2) and its neighbourhood included."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinedyn._math import rpy_from_matrix, rpy_to_matrix

EPS = np.finfo(float).eps


def rebuilt(R) -> np.ndarray:
    return np.asarray(rpy_to_matrix(*rpy_from_matrix(R)), dtype=float)[:3, :3]


def test_generic_angles_come_back():
    rng = np.random.default_rng(0)
    for _ in range(200):
        roll, yaw = rng.uniform(-math.pi, math.pi, 2)
        pitch = rng.uniform(-math.pi / 2, math.pi / 2)
        R = np.asarray(rpy_to_matrix(roll, pitch, yaw), dtype=float)
        r, p, y = rpy_from_matrix(R)  # a 4x4 pose is accepted too: its rotation is read
        assert np.allclose([r, p, y], [roll, pitch, yaw], atol=1e-12)
        assert np.abs(rebuilt(R[:3, :3]) - R[:3, :3]).max() < 8 * EPS


@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("offset", [0.0, 1e-17, 1e-12, 1e-9, 1e-6, -1e-9])
def test_near_and_at_gimbal_lock_r_is_rebuilt(sign, offset):
    """Pitch within rounding of +-pi/2, where yaw is read from a first column of length ~cos(pitch):
    roll is read from what remains after pitch and yaw, so R comes back to rounding."""
    rng = np.random.default_rng(1)
    for _ in range(50):
        roll, yaw = rng.uniform(-3, 3, 2)
        R = np.asarray(rpy_to_matrix(roll, sign * (math.pi / 2 - offset), yaw), dtype=float)[:3, :3]
        _, pitch, _ = rpy_from_matrix(R)
        assert -math.pi / 2 <= pitch <= math.pi / 2
        assert np.abs(rebuilt(R) - R).max() < 8 * EPS


@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("angle", [0.3, -2.5, math.pi])
def test_an_exact_lock_puts_yaw_at_zero(sign, angle):
    """At cos(pitch) = 0 only yaw -+ roll is defined: the choice is yaw = 0, roll takes the rest,
    also when the zeros are negative (atan2(0.0, -0.0) would be pi)."""
    c, s = math.cos(angle), math.sin(angle)
    for zero in (0.0, -0.0):
        R = np.array([[zero, -s, sign * c], [zero, c, sign * s], [-sign, 0.0, 0.0]])
        roll, pitch, yaw = rpy_from_matrix(R)
        assert yaw == 0.0 and pitch == sign * math.pi / 2
        assert np.abs(rebuilt(R) - R).max() < 1e-15
        assert all(math.copysign(1.0, a) == 1.0 or a != 0.0 for a in (roll, pitch, yaw))  # no -0.0
