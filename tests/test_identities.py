"""kinedyn.testing: the identities between algorithms hold on random chains, trees and built-ins,
and the checker itself notices a wrong engine."""

from __future__ import annotations

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.testing import check_identities, random_robot

pytest.importorskip("kinedyn._core", reason="the native module is not built")

EXACT = 1e-11  # identities between exact algorithms
FD = 1e-6  # identities checked by central finite differences


def assert_identities(residuals: dict) -> None:
    for name, r in residuals.items():
        limit = FD if "finite differences" in name else EXACT
        assert r < limit, f"{name}: residual {r:.3g} >= {limit}"


@pytest.mark.parametrize("seed, n, branching", [(1, 1, False), (2, 6, False), (3, 9, True), (4, 12, True)])
def test_random_robots(seed, n, branching):
    robot = random_robot(seed, n, branching)
    assert robot.n == n
    assert_identities(check_identities(robot, states=4, seed=seed))


@pytest.mark.parametrize("name", kd.robots.names())
def test_builtins(name):
    assert_identities(check_identities(kd.robots.get(name), states=3))


def test_random_tree_really_branches():
    robot = random_robot(3, 9, True)
    parents = robot.parents
    assert len(set(parents)) < len(parents) - 1 or any(p < i - 1 for i, p in enumerate(parents))


def test_checker_catches_a_transposed_coriolis_matrix():
    """dM/dt == C + C^T cannot tell C from C^T; the RNEA identity can."""

    class Transposed(kd.Robot):  # a Robot is immutable: a wrong method comes with a subclass
        def coriolis_matrix(self, q, qd):
            return super().coriolis_matrix(q, qd).T

    robot = Transposed(random_robot(5, 5).description)
    residuals = check_identities(robot, states=2)
    assert residuals["dM/dt == C + C^T (finite differences)"] < FD
    assert residuals["rnea == M qdd + C qd + g + friction"] > 1e-3


def test_checker_catches_a_wrong_gravity():
    class Heavier(kd.Robot):
        def gravity_torque(self, q):
            return 1.01 * super().gravity_torque(q)

    robot = Heavier(random_robot(6, 4).description)
    residuals = check_identities(robot, states=2)
    assert residuals["g == dP/dq (finite differences)"] > 1e-4


def test_base_parameters_ignore_columns_that_are_rounding_noise():
    """PUMA 560 link 2's m cz column is ~1e-15 (its axis geometry makes it vanish): no base
    parameter may be such a column, and the base regressor is well conditioned and exact."""
    robot = kd.robots.puma560()
    base = robot.base_parameters()
    rng = np.random.default_rng(3)
    q, qd, qdd = robot.random_configuration(rng, size=50), rng.normal(size=(50, 6)), rng.normal(size=(50, 6))
    W = robot.regressor(q, qd, qdd).reshape(-1, 60)
    norms = np.linalg.norm(W[:, base.indices], axis=0)
    assert norms.min() > 1e-8 * norms.max()
    W_base = W[:, base.indices]  # Y_base: the independent columns
    assert np.linalg.matrix_rank(W_base) == len(base.indices)
    armature = np.array([float(j.armature) for j in robot.joints])
    tau = robot.inverse_dynamics(q, qd, qdd) - armature * qdd  # the regressor excludes rotor inertia
    np.testing.assert_allclose(W_base @ base.values, tau.ravel(), atol=1e-9)
