"""The configuration space's ``integrate`` / ``difference``, their Jacobians and the quaternion helpers
of :mod:`kinedyn.lie` are the core's (crates/kinedyn-core/src/lie.rs and lie/jacobians.rs,
``kinedyn._core.lie_*``): against the NumPy operations they replaced (tests/lie_oracle.py) on batches
of every joint kind, at generic angles, near zero and near π."""

from __future__ import annotations

import lie_oracle as oracle
import numpy as np
import pytest

from kinedyn import Joint, lie
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


def rotation_vectors(rng, size):
    """Rotation vectors at angles 0, in the series branches (below 1e-2 and 0.5), generic and near π."""
    w = rng.normal(size=(size, 3))
    angle = np.concatenate(
        [[0.0, 1e-9, 3e-3, 0.2, 0.45], rng.uniform(0.5, 3.0, size - 7), [np.pi - 1e-6, np.pi - 1e-3]]
    )
    return w / np.linalg.norm(w, axis=1, keepdims=True) * angle[:, None]


def test_quaternion_helpers_equal_the_numpy_oracle():
    rng = np.random.default_rng(31)
    omega = rotation_vectors(rng, 30)
    quat = oracle.exp3(omega)
    np.testing.assert_allclose(lie.exp3(omega), quat, atol=1e-15, rtol=0)
    np.testing.assert_allclose(lie.log3(quat), oracle.log3(quat), atol=1e-12, rtol=0)
    np.testing.assert_allclose(lie.log3(-quat), oracle.log3(-quat), atol=1e-12, rtol=0)  # w < 0: the short way
    other = oracle.exp3(rotation_vectors(rng, 30)[::-1])
    np.testing.assert_allclose(
        lie.quaternion_multiply(quat, other), oracle.quaternion_multiply(quat, other), atol=1e-15
    )
    p = rng.normal(size=(30, 3))
    np.testing.assert_allclose(lie.quaternion_rotate(quat, p), oracle.quaternion_rotate(quat, p), atol=1e-14)
    np.testing.assert_allclose(lie.quaternion_to_matrix(quat), oracle.quaternion_to_matrix(quat), atol=1e-15)
    # shapes broadcast as NumPy's: one quaternion against a batch, one state without a batch axis
    np.testing.assert_allclose(lie.quaternion_rotate(quat[3], p), oracle.quaternion_rotate(quat[3], p), atol=1e-14)
    assert lie.quaternion_to_matrix(quat[0]).shape == (3, 3) and lie.exp3(omega[:4].reshape(2, 2, 3)).shape == (2, 2, 4)
    with pytest.raises(ValueError, match="multiply: expected arrays of"):
        lie.quaternion_multiply(quat, p)


@pytest.mark.parametrize("kind", ["floating", "spherical", "planar"])
def test_group_jacobians_equal_the_numpy_oracle(kind):
    rng = np.random.default_rng(32)
    omega = rotation_vectors(rng, 30)
    if kind == "floating":
        tau = np.concatenate([rng.normal(size=(30, 3)), omega], axis=1)
    elif kind == "spherical":
        tau = omega
    else:  # the planar angle in (-π, π), both signs
        tau = np.concatenate(
            [rng.normal(size=(30, 2)), (np.linalg.norm(omega, axis=1) * rng.choice([-1, 1], 30))[:, None]], 1
        )
    for got, want, what in zip(
        lie.block_jacobians(kind, tau), oracle.block_jacobians(kind, tau), ("Ad", "Jl", "Jl^-1")
    ):
        np.testing.assert_allclose(got, want, atol=1e-13, rtol=0, err_msg=f"{kind} {what}")


def test_integrate_and_difference_jacobians_equal_the_oracle_joint_by_joint():
    joints = [Joint(f"j{i}", kind=k) for i, k in enumerate(KINDS * 2)]
    space = cfg.ConfigurationSpace(joints)
    rng = np.random.default_rng(33)
    q0 = space.random(rng, size=6)
    v = rng.normal(size=(6, space.nv))
    v[0] *= 1e-6  # the series branches
    d_q, d_v = space.integrate_jacobians(q0, v, 0.4)
    q1 = space.integrate(q0, v)
    d_0, d_1 = space.difference_jacobians(q0, q1)
    d = space.difference(q0, q1)
    assert d_q.shape == d_v.shape == d_0.shape == d_1.shape == (6, space.nv, space.nv)
    iv = 0
    for j in joints:
        cols = slice(iv, iv + j.nv)
        if j.nv == 1:
            want = (np.ones(6), np.full(6, 0.4), -np.ones(6), np.ones(6))
            for got, w in zip((d_q, d_v, d_0, d_1), want):
                np.testing.assert_array_equal(got[:, iv, iv], w)
        else:
            ad, jl, _ = oracle.block_jacobians(j.kind, -0.4 * v[:, cols])
            np.testing.assert_allclose(d_q[:, cols, cols], ad, atol=1e-13, rtol=0, err_msg=j.kind)
            np.testing.assert_allclose(d_v[:, cols, cols], 0.4 * jl, atol=1e-13, rtol=0, err_msg=j.kind)
            np.testing.assert_allclose(d_0[:, cols, cols], -oracle.block_jacobians(j.kind, d[:, cols])[2], atol=1e-12)
            np.testing.assert_allclose(d_1[:, cols, cols], oracle.block_jacobians(j.kind, -d[:, cols])[2], atol=1e-12)
        # block diagonal: nothing between joints
        for M in (d_q, d_v, d_0, d_1):
            assert not np.any(M[:, cols, :iv]) and not np.any(M[:, cols, iv + j.nv :])
        iv += j.nv
