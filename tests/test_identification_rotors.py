"""Rotor inertia in identification from a log (issue 16 §2): where the model has gears, each joint's
armature a_j = r_j^2 J_m,j (on M's diagonal) is a parameter beside the links'. The PUMA 560 of the
catalogue has Corke's gear ratios and motor inertias; the 'real' arm here has them changed, the log
is simulated at 1 kHz with friction, noise and quantised encoders (positions and torques only)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinedyn as kd
import kinedyn.analysis as an
from kinedyn.analysis.parameters import rotor_regressor, with_armatures

RATE = 1000.0
ENCODER = 2 * np.pi / 2**17
FACTORS = np.array([1.3, 0.8, 1.2, 0.7, 1.25, 0.9])  # the real motors' inertia / the catalogue's


@pytest.fixture(scope="module")
def prior():
    return kd.robots.puma560()


@pytest.fixture(scope="module")
def true_robot(prior):
    return with_armatures(prior, {k: a * f for k, (a, f) in enumerate(zip(prior.armature, FACTORS))})


def _log(robot, seed, T=10.0):
    ref = an.excitation(robot, harmonics=5, period=10.0, amplitude=0.8, seed=seed)
    t = np.arange(int(T * RATE)) / RATE
    q, qd, qdd = ref(t)
    tau = robot.inverse_dynamics(q, qd, qdd) + 0.5 * qd + 1.0 * np.sign(qd)
    sigma = 0.005 * (tau.max(axis=0) - tau.min(axis=0))
    tau = tau + np.random.default_rng(seed).normal(size=tau.shape) * sigma
    cols = {"t": t}
    for j in range(robot.n):
        cols[f"q{j + 1}"] = np.round(q[:, j] / ENCODER) * ENCODER
        cols[f"tau{j + 1}"] = tau[:, j]
    return cols


@pytest.fixture(scope="module")
def fit(prior, true_robot):
    return an.identify(prior, _log(true_robot, seed=1))


def test_rotor_columns_join_the_base_parameters(prior):
    """The augmented base parameters reproduce [Y, R] x for any x; the first two armatures are
    grouped with their links' Izz (joint 1 turns about the fixed vertical axis; joint 2's axis is
    perpendicular to joint 1's, so link 2's Izz, like a_2, only ever meets qdd_2 in tau_2)."""
    joints = an.geared_joints(prior)
    assert joints == tuple(range(6))
    base = an.base_parameters_with_rotors(prior, joints)
    armatures = [nm for nm in base.names if nm.endswith(".armature")]
    assert armatures == ["q3.armature", "q4.armature", "q5.armature", "q6.armature"]
    assert base.count == prior.base_parameters().count + 4
    rng = np.random.default_rng(5)
    q, qd, qdd = prior.random_configuration(rng, size=20), rng.normal(size=(20, 6)), rng.normal(size=(20, 6))
    Y = np.concatenate([prior.regressor(q, qd, qdd), rotor_regressor(qdd, joints, 6)], axis=2)
    x = rng.normal(size=66)
    np.testing.assert_allclose(Y[..., base.indices] @ (base.grouping @ x), Y @ x, atol=1e-9)
    # a_1 and a_2 enter the group of link1.Izz / link2.Izz with coefficient 1
    for k, name in ((0, "link1.Izz"), (1, "link2.Izz")):
        row = base.names.index(name)
        assert base.grouping[row, 60 + k] == pytest.approx(1.0)
        assert np.count_nonzero(base.grouping[:, 60 + k]) == 1
    # and the rotor-aware torques are the robot's own (armature included)
    np.testing.assert_allclose(
        Y[..., base.indices] @ base.values, prior.inverse_dynamics(q, qd, qdd) - prior.friction_torque(qd), atol=1e-8
    )


def test_identified_armatures_match_the_real_motors(prior, true_robot, fit):
    rotors = {r.joint: r for r in fit.rotors}
    assert list(rotors) == prior.joint_names
    for k, name in enumerate(prior.joint_names):
        r = rotors[name]
        if k < 2:  # grouped: no number of its own, and the group's estimate is the true group
            assert r.armature is None and r.std is None
            assert r.grouped_into == (f"link{k + 1}.Izz",)
            i = fit.names.index(f"link{k + 1}.Izz")
            truth = fit.base.grouping[fit.used][i] @ np.concatenate(
                [true_robot.inertial_parameters(), true_robot.armature]
            )
            assert fit.estimates[i] == pytest.approx(truth, rel=0.02)
        else:
            assert r.armature == pytest.approx(true_robot.armature[k], rel=0.03), name
            assert abs(r.armature - prior.armature[k]) > 5 * r.std  # the data moved it off the prior
            assert r.rotor_inertia == pytest.approx(r.armature / float(prior.joints[k].gear_ratio) ** 2)
    from kinedyn._ui.json import jsonable as _jsonable

    payload = json.loads(json.dumps(_jsonable(fit.to_dict())))
    assert payload["rotors"][0]["armature"] is None and payload["rotors"][0]["grouped_into"] == ["link1.Izz"]
    # rotor=False takes the catalogue's motors as known: the misfit shows in the held-out torques
    held_out = _log(true_robot, seed=2, T=6.0)
    known = an.identify(prior, _log(true_robot, seed=1), rotor=False)
    assert not known.rotor_joints
    assert np.all(fit.validate(held_out).r2 > 0.995)
    assert fit.validate(held_out).rms.max() < known.validate(held_out).rms.max() / 2


def test_consistent_robot_carries_the_identified_rotor_inertia(prior, true_robot):
    result = an.identify(prior, _log(true_robot, seed=1), consistent=True)
    model = result.robot
    for k, r in enumerate(result.rotors):
        assert model.armature[k] >= 0
        if r.armature is not None:
            assert model.joints[k].rotor_inertia == pytest.approx(r.rotor_inertia, rel=1e-12)
            assert model.armature[k] == pytest.approx(true_robot.armature[k], rel=0.03)
    states = result.data.q[::20]
    np.testing.assert_allclose(model.mass_matrix(states), result.mass_matrix(states), atol=1e-6)
    assert result.unconstrained is not None and not result.unconstrained.consistent
