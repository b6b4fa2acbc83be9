"""eom.compile(backend="jax"): JAX functions equal the Rust core, are jit/vmap-able, differentiate to
kinedyn's analytical derivatives, and compute in float64 without kinedyn flipping JAX's precision at
import (issue 15 §3). CPU only."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from reference import symbolic_backend_robots

import kinedyn as kd

jax = pytest.importorskip("jax")
jnp = pytest.importorskip("jax.numpy")

RNG = np.random.default_rng(16)
TOL = 1e-10


ROBOTS = symbolic_backend_robots()


@pytest.fixture(scope="module", params=list(ROBOTS))
def robot_and_functions(request):
    robot = ROBOTS[request.param]()
    return robot, robot.equations_of_motion(method="newton_euler", steps=False).compile(backend="jax")


def _close(a, b, tol=TOL):
    a, b = np.asarray(a), np.asarray(b, dtype=float)
    assert a.dtype == np.float64
    np.testing.assert_allclose(a, b, rtol=tol, atol=tol * max(1.0, float(np.abs(b).max())))


def test_values_equal_the_core(robot_and_functions):
    robot, f = robot_and_functions
    assert f.backend == "jax"
    for _ in range(4):
        q, qd, qdd = RNG.uniform(-2, 2, size=(3, robot.n))
        _close(f.M(q), robot.mass_matrix(q))
        _close(f.C(q, qd), robot.coriolis_matrix(q, qd))
        _close(f.g(q), robot.gravity_torque(q))
        _close(f.tau(q, qd, qdd), robot.inverse_dynamics(q, qd, qdd))


def test_jacfwd_and_grad_equal_the_analytical_derivatives(robot_and_functions):
    robot, f = robot_and_functions
    tau = jax.jit(f.tau)
    for _ in range(2):
        q, qd, qdd = RNG.uniform(-2, 2, size=(3, robot.n))
        dq, dqd, M = robot.inverse_dynamics_derivatives(q, qd, qdd)
        _close(jax.jacfwd(tau, argnums=0)(q, qd, qdd), dq)
        _close(jax.jacrev(tau, argnums=1)(q, qd, qdd), dqd)
        w = RNG.normal(size=robot.n)  # grad of a scalar: w . tau
        _close(jax.grad(lambda q: jnp.dot(w, f.tau(q, qd, qdd)))(q), w @ dq)


def test_vmap_over_states_equals_the_core_batch(robot_and_functions):
    robot, f = robot_and_functions
    Q, QD, QDD = RNG.uniform(-2, 2, size=(3, 100, robot.n))
    expected = robot.inverse_dynamics(Q, QD, QDD)
    _close(jax.jit(jax.vmap(f.tau))(Q, QD, QDD), expected)
    _close(f.tau(Q, QD, QDD), expected)  # a batch (N, n) directly, as the other backends take it
    _close(jax.vmap(f.M)(Q), robot.mass_matrix(Q))


def test_symbolic_parameters_are_passed_as_p():
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    values = dict(l1=1.3, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13, g=9.81)
    p = [values[str(s)] for s in eom.parameters]
    f = eom.compile(backend="jax", p=p)
    robot = kd.robots.planar_2r(l2=0.9, **values)
    q, qd, qdd = RNG.uniform(-2, 2, size=(3, 2))
    _close(f.tau(q, qd, qdd), robot.inverse_dynamics(q, qd, qdd))
    with pytest.raises(ValueError, match="still contain the parameters"):
        eom.compile(backend="jax")
    with pytest.raises(ValueError, match="p has 2 values"):
        eom.compile(backend="jax", p=[1.0, 2.0])


def test_bad_shapes_are_named():
    f = kd.robots.planar_2r().equations_of_motion(steps=False).compile(backend="jax")
    with pytest.raises(ValueError, match=r"expected arrays of shape \(2,\) or \(N, 2\)"):
        f.M(np.zeros(3))
    with pytest.raises(ValueError, match="qd has shape"):
        f.tau(np.zeros(2), np.zeros((4, 2)), np.zeros(2))


def test_float64_is_enabled_only_when_the_backend_is_requested():
    code = (
        "import jax, kinedyn as kd\n"
        "assert not jax.config.jax_enable_x64, 'kinedyn import turned on x64'\n"
        "f = kd.robots.planar_2r().equations_of_motion(steps=False).compile(backend='jax')\n"
        "assert jax.config.jax_enable_x64\n"
        "print(f.tau([0.1, 0.2], [0.3, 0.4], [0.5, 0.6]).dtype)\n"
    )
    env = dict(os.environ, PYTHONPATH=str(Path(kd.__file__).parents[1]))
    env.pop("JAX_ENABLE_X64", None)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "float64"


def test_parameters_at_call_time_are_differentiable():
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    names = [str(s) for s in eom.parameters]
    base = dict(l1=1.3, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13, g=9.81)
    f = eom.compile(backend="jax", p=[base[k] for k in names])
    other = dict(base, m2=2.5, I1=0.3)
    q, qd, qdd = RNG.uniform(-2, 2, size=(3, 2))
    p_other = jnp.asarray([other[k] for k in names])
    _close(f.tau(q, qd, qdd, p=p_other), kd.robots.planar_2r(l2=0.9, **other).inverse_dynamics(q, qd, qdd))
    # tau is linear in m2 for fixed lengths: d tau / d m2 is the difference quotient, exactly
    k = names.index("m2")
    grad = jax.jacfwd(lambda p: f.tau(q, qd, qdd, p=p))(p_other)[:, k]
    step = np.zeros(len(names))
    step[k] = 1.0
    _close(grad, np.asarray(f.tau(q, qd, qdd, p=p_other + step)) - np.asarray(f.tau(q, qd, qdd, p=p_other)), tol=1e-9)
    with pytest.raises(ValueError, match="p has shape"):
        f.tau(q, qd, qdd, p=jnp.zeros(3))
