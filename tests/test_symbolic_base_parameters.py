"""Symbolic base parameters against the numeric ones, and the size of the customised Newton-Euler model
(issue 4, follow-up items 3 and 4)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.description.dh import DHRow
from kinedyn.description.inertia import Inertia

warnings.filterwarnings("ignore", message=".*triangle inequality.*")


def _numeric_rank(robot, samples=60, seed=3):
    """Rank of the stacked numeric regressor by an SVD with a relative tolerance (independent of the
    pivoted QR inside robot.base_parameters())."""
    rng = np.random.default_rng(seed)
    q = robot.random_configuration(rng, size=samples)
    W = robot.regressor(q, rng.uniform(-2, 2, q.shape), rng.uniform(-4, 4, q.shape)).reshape(samples * robot.n, -1)
    scale = np.linalg.norm(W, axis=0)
    keep = scale > 1e-10 * scale.max()
    s = np.linalg.svd(W[:, keep] / scale[keep], compute_uv=False)
    return int(np.sum(s > 1e-9 * s[0]))


@pytest.mark.parametrize("name", ["puma560", "elbow_3r"])
def test_symbolic_and_numeric_base_parameter_counts_agree(name):
    """The PUMA's rotor inertias (numbers) used to count as a 37th 'parameter' in the symbolic grouping."""
    robot = getattr(kd.robots, name)()
    eom = robot.equations_of_motion(parameters="general", steps=False)
    theta = eom.base_parameters()
    numeric = len(robot.base_parameters().names)
    assert len(theta) == numeric == _numeric_rank(robot), (len(theta), numeric)
    # every grouped parameter is a combination of the general symbols only (no stray constant)
    for t in theta:
        assert all(term.free_symbols for term in sp.Add.make_args(t)), t


def _geared_2r():
    """A planar 2R arm whose drives have numeric rotor inertia: the known part of tau."""
    rod = lambda m, L: Inertia(m, (-L / 2, 0, 0), ((0, 0, 0), (0, m * L**2 / 12, 0), (0, 0, m * L**2 / 12)))
    rows = [DHRow(a=1.0, inertia=rod(2.0, 1.0), gear_ratio=10.0, rotor_inertia=1e-3),
            DHRow(a=0.5, inertia=rod(1.0, 0.5), gear_ratio=5.0, rotor_inertia=2e-3)]
    return kd.Robot.from_dh(rows, gravity=(0, -9.81, 0), name="geared_2r")


def test_regressor_splits_off_the_known_rotor_inertia():
    robot = _geared_2r()
    eom = robot.equations_of_motion(parameters="general", steps=False)
    r = eom.regressor()
    Y, theta = r  # still unpacks as a pair
    qdd = eom.qdd
    # the rotor terms r^2 J_m qdd_k are known numbers, not parameters
    assert sp.expand(r.tau_known - sp.Matrix([0.1 * qdd[0], 0.05 * qdd[1]])).applyfunc(lambda e: sp.nsimplify(e, tolerance=1e-12)) == sp.zeros(2, 1)
    assert len(theta) == len(robot.base_parameters().names)
    # Y Theta + tau_known == tau at random states and parameter values
    res = Y * theta + r.tau_known - (eom.tau - eom.friction)
    params = sorted(res.free_symbols - set(eom.q) - set(eom.qd) - set(eom.qdd), key=str)
    f = sp.lambdify([list(eom.q) + list(eom.qd) + list(eom.qdd), params], res)
    rng = np.random.default_rng(1)
    for _ in range(3):
        assert np.abs(np.asarray(f(rng.normal(size=6), rng.normal(size=len(params))), float)).max() < 1e-12
