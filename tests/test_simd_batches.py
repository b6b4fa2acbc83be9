"""Batches in SIMD lanes (issue 17): a batch of states is computed several states at once, one per
lane (kinedyn_core::batch), and must give each state's single-call numbers. Checked on built-in,
URDF, random, branching and floating-base robots, for batch sizes that are not multiples of the
lane count, with every lane kind this CPU runs (child interpreters with KINEDYN_SIMD set)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn import testing

pytest.importorskip("kinedyn._core", reason="the native module is not built")

REL = 1e-13  # lanes run the single call's operations in the same order: equal to rounding


def _robots():
    yield "ur5", kd.robots.get("ur5")
    yield "puma560", kd.robots.get("puma560")
    yield "chain", testing.random_robot(seed=11, n=7)
    yield "tree", testing.random_robot(seed=12, n=8, branching=True)
    yield "floating", testing.random_robot(seed=13, n=7, floating=True, spherical=0.3, planar=0.2)
    folder = testing.example_robot_data_dir()
    if folder is not None:  # URDFs: the Panda (its finger mimic reduced) and Solo-12 on a free-flyer
        yield "panda", kd.Robot.from_urdf(os.path.join(folder, "panda_description/urdf/panda.urdf"))
        yield (
            "solo12",
            kd.Robot.from_urdf(os.path.join(folder, "solo_description/robots/solo12.urdf"), floating_base=True),
        )


def _states(robot, count: int, seed: int):
    rng = np.random.default_rng(seed)
    q = np.array([robot.random_configuration(rng) for _ in range(count)])
    return q, rng.uniform(-2, 2, (count, robot.nv)), rng.uniform(-2, 2, (count, robot.nv))


def _calls(robot, q, v, a):
    """(name, batch result, per-state results) of every batched algorithm."""
    model = robot._model
    links = len(model.link_bodies)  # f_ext is one wrench per link (a mimic follower's too)
    f_ext = np.random.default_rng(1).normal(size=(len(q), links, 6))
    tau = model.inverse_dynamics(q, v, a)
    calls = {
        "inverse_dynamics": (lambda *x: model.inverse_dynamics(*x), (q, v, a)),
        "inverse_dynamics f_ext": (lambda *x: model.inverse_dynamics(*x), (q, v, a, f_ext)),
        "mass_matrix": (lambda *x: model.mass_matrix(*x), (q,)),
        "mass_matrix_inverse": (lambda *x: model.mass_matrix_inverse(*x), (q,)),
        "forward_dynamics": (lambda *x: model.forward_dynamics(*x), (q, v, tau)),
        "forward_dynamics f_ext": (lambda *x: model.forward_dynamics(*x), (q, v, tau, f_ext)),
        "gravity_torque": (lambda *x: model.gravity_torque(*x), (q,)),
        "bias_torque": (lambda *x: model.bias_torque(*x), (q, v)),
        "coriolis_matrix": (lambda *x: model.coriolis_matrix(*x), (q, v)),
        "christoffel": (lambda *x: model.christoffel(*x), (q,)),
        "regressor": (lambda *x: model.regressor(*x), (q, v, a)),
        "kinetic_energy": (lambda *x: model.kinetic_energy(*x), (q, v)),
        "potential_energy": (lambda *x: model.potential_energy(*x), (q,)),
        "frame_poses": (lambda q: model.frame_poses(q, np.arange(model.n_frames)), (q,)),
    }
    for reference in ("world", "local", "spatial"):
        calls[f"jacobian {reference}"] = (lambda q, r=reference: model.jacobian(q, model.n_frames - 1, r), (q,))
        calls[f"jacobian {reference} at a point"] = (
            lambda q, r=reference: model.jacobian(q, model.n_frames - 1, r, np.array([0.1, -0.2, 0.3])),
            (q,),
        )
    for name, (fn, args) in calls.items():
        yield name, fn(*args), np.array([fn(*(x[k] for x in args)) for k in range(len(q))])
    for name, fn, args in [
        ("inverse_dynamics_derivatives", model.inverse_dynamics_derivatives, (q, v, a)),
        ("inverse_dynamics_derivatives f_ext", model.inverse_dynamics_derivatives, (q, v, a, f_ext)),
        ("forward_dynamics_derivatives", model.forward_dynamics_derivatives, (q, v, tau)),
        ("forward_dynamics_derivatives f_ext", model.forward_dynamics_derivatives, (q, v, tau, f_ext)),
    ]:
        batch = fn(*args)
        single = [fn(*(x[k] for x in args)) for k in range(len(q))]
        for part in range(3):  # each of the three results
            yield f"{name} [{part}]", batch[part], np.array([s[part] for s in single])


def _assert_close(name, got, expected):
    scale = np.max(np.abs(expected), axis=tuple(range(1, expected.ndim)), keepdims=True)
    err = np.abs(got - expected) / np.maximum(scale, 1e-300)
    assert np.all(err <= REL), (
        f"{name}: state {np.unravel_index(np.argmax(err), err.shape)[0]} differs by {err.max():.2e} (relative)"
    )


@pytest.mark.parametrize("count", [5, 13, 64 + 3])
def test_batches_equal_single_calls(count):
    """The batch (lanes, padded last block, rayon chunks of 64) equals each state's single call."""
    for label, robot in _robots():
        q, v, a = _states(robot, count, seed=count)
        for name, batch, single in _calls(robot, q, v, a):
            assert batch.shape == single.shape
            _assert_close(f"{label} {name}", batch, single)


_CHILD = r"""
import json, sys
import numpy as np
from kinedyn import _core, testing
robot = testing.random_robot(seed=21, n=6, branching=True, floating=True, spherical=0.3)
rng = np.random.default_rng(2)
q = np.array([robot.random_configuration(rng) for _ in range(11)])
v, a = rng.normal(size=(2, 11, robot.nv))
m = robot._model
out = {"simd": _core.simd(), "tau": m.inverse_dynamics(q, v, a).tolist(), "M": m.mass_matrix(q).tolist(),
       "qdd": m.forward_dynamics(q, v, a).tolist()}
json.dump(out, sys.stdout)
"""


def test_every_lane_kind_gives_the_same_numbers():
    """KINEDYN_SIMD picks the lane kind (when the CPU has it; the best one otherwise): every kind
    gives the numbers of one state at a time ('off') to 1e-13."""
    env = {**os.environ, "PYTHONPATH": str(Path(kd.__file__).parents[1])}
    results = {}
    for kind in ["off", "portable", "avx2", "avx512"]:
        child = subprocess.run(
            [sys.executable, "-c", _CHILD],
            env={**env, "KINEDYN_SIMD": kind},
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert child.returncode == 0, child.stderr[-2000:]
        results[kind] = json.loads(child.stdout)
    assert results["off"]["simd"] == ["off", 1] and results["portable"]["simd"] == ["portable", 4]
    best = kd.simd()[0]
    for kind in ["avx2", "avx512"]:
        # a kind this CPU lacks falls back to the best one it has
        assert results[kind]["simd"][0] in (kind, best)
    for kind, got in results.items():
        for key in ("tau", "M", "qdd"):
            _assert_close(f"{kind} {key}", np.array(got[key]), np.array(results["off"][key]))


def test_a_singular_mass_matrix_fails_the_batch_as_a_single_call():
    """A singular mass matrix fails the batch with the single call's error (the lanes' block is rerun
    one state at a time to name it), not with numbers."""
    robot = testing.random_robot(seed=5, n=4, fixed=0)
    leaf = robot.links[-1]
    massless = leaf.__class__(
        leaf.name,
        leaf.parent,
        leaf.joint.__class__(**{**leaf.joint.__dict__, "rotor_inertia": 0.0}),
        leaf.placement,
        leaf.post,
        None,
    )
    robot = robot.replace(links=[*robot.links[:-1], massless])
    q, v, a = _states(robot, 12, seed=3)
    model = robot._model
    with pytest.raises(RuntimeError) as single:
        model.forward_dynamics(q[0], v[0], a[0])
    with pytest.raises(RuntimeError) as batch:
        model.forward_dynamics(q, v, a)
    assert "articulated inertia" in str(single.value) and str(batch.value) == str(single.value)
