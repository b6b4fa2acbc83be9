"""The configuration space's ``integrate`` / ``difference`` are the core's (crates/kinedyn-core/src/lie.rs,
``kinedyn._core.lie_integrate`` / ``lie_difference``): against the NumPy operations they replaced
(tests/lie_oracle.py) on batches of every joint kind, at generic angles, near zero and near π."""

from __future__ import annotations

import lie_oracle as oracle
import numpy as np
import pytest

from kinedyn import Joint
from kinedyn import configuration as cfg

pytest.importorskip("kinedyn._core", reason="the native module is not built")

KINDS = ("revolute", "prismatic", "floating", "spherical", "planar")


def oracle_integrate(kind, q, v):
    if kind in ("revolute", "prismatic"):
        return q + v
    if kind == "floating":
        return oracle.integrate_floating(q, v)
    if kind == "spherical":
        return oracle.integrate_rotation(q, v)
    return oracle.integrate_planar(q, v)


def oracle_difference(kind, q0, q1):
    if kind in ("revolute", "prismatic"):
        return q1 - q0
    if kind == "floating":
        return oracle.difference_floating(q0, q1)
    if kind == "spherical":
        return oracle.log3(oracle.quaternion_multiply(q0 * np.array([-1.0, -1.0, -1.0, 1.0]), q1))
    return oracle.difference_planar(q0, q1)


def tangent(rng, kind, size, scale):
    """Velocities of one joint: generic, tiny (series branches) and with rotation angles near π."""
    nv = Joint("j", kind=kind).nv
    v = rng.normal(size=(size, nv)) * scale
    if kind in ("floating", "spherical"):
        w = v[:, -3:]
        angle = np.pi - np.logspace(-9, -1, size)
        v[:, -3:] = w / np.linalg.norm(w, axis=1, keepdims=True) * angle[:, None] * (scale >= 1)
    return v


@pytest.mark.parametrize("scale", [1e-9, 1e-3, 1.0])
def test_one_joint_of_each_kind_equals_the_numpy_oracle(scale):
    rng = np.random.default_rng(int(scale * 1e9) % 97)
    for kind in KINDS:
        space = cfg.ConfigurationSpace([Joint("j", kind=kind)])
        q0 = space.random(rng, size=40)
        v = tangent(rng, kind, 40, scale)
        q1 = space.integrate(q0, v)
        np.testing.assert_allclose(q1, oracle_integrate(kind, q0, v), atol=1e-13, rtol=0, err_msg=kind)
        d = space.difference(q0, q1)
        np.testing.assert_allclose(d, oracle_difference(kind, q0, q1), atol=1e-9 if scale >= 1 else 1e-13, err_msg=kind)


def test_a_mixed_robot_batch_equals_the_oracle_joint_by_joint():
    joints = [Joint(f"j{i}", kind=k) for i, k in enumerate(KINDS * 2)]
    space = cfg.ConfigurationSpace(joints)
    rng = np.random.default_rng(5)
    q0 = space.random(rng, size=(7))
    v = rng.normal(size=(7, space.nv))
    q1 = space.integrate(q0, v, 0.3)
    d = space.difference(q0, q1)
    iq = iv = 0
    for j in joints:
        a, b = q0[:, iq : iq + j.nq], q1[:, iq : iq + j.nq]
        np.testing.assert_allclose(b, oracle_integrate(j.kind, a, 0.3 * v[:, iv : iv + j.nv]), atol=1e-13, rtol=0)
        np.testing.assert_allclose(d[:, iv : iv + j.nv], oracle_difference(j.kind, a, b), atol=1e-12, rtol=0)
        iq, iv = iq + j.nq, iv + j.nv
    # broadcasting: one q0 for a batch of v, one v for a batch of q0
    np.testing.assert_allclose(space.integrate(q0[0], v), np.stack([space.integrate(q0[0], x) for x in v]), atol=0)
    np.testing.assert_allclose(space.integrate(q0, v[0]), np.stack([space.integrate(x, v[0]) for x in q0]), atol=0)


def test_the_core_rejects_bad_shapes_and_names_by_message():
    from kinedyn._core import lie_difference, lie_integrate

    with pytest.raises(ValueError, match=r"q must have shape \(7\)"):
        lie_integrate(["floating"], np.zeros(6), np.zeros(6))
    with pytest.raises(ValueError, match=r"v must have shape \(2, 6\)"):
        lie_integrate(["floating"], np.zeros((2, 7)), np.zeros((3, 6)))
    with pytest.raises(ValueError, match="joint 1: .*unknown joint kind 'helical'"):
        lie_difference(["", "helical"], np.zeros(2), np.zeros(2))
