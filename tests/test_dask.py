"""Robot's batched methods on dask arrays (issue 15 §1, docs/scale.md): the same numbers as the
in-process batch on a real LocalCluster of worker processes, a killed worker recomputed, the
description sent and the native model built once per worker process, joint-axis chunks refused."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

import kinedyn
from kinedyn._dask import process_cache_info

da = pytest.importorskip("dask.array", reason="the scale extra (dask[array], distributed) is not installed")
distributed = pytest.importorskip("distributed")
import cloudpickle  # noqa: E402  (comes with dask)
import dask  # noqa: E402

# the helpers below run on the workers, which cannot import this test module by name
cloudpickle.register_pickle_by_value(sys.modules[__name__])

N = 500
CHUNK = 120  # five chunks of states, the last one short


@pytest.fixture(scope="module")
def client():
    """One LocalCluster of two worker processes (one thread each) for the module."""
    env = {"PYTHONPATH": os.pathsep.join([str(Path(kinedyn.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])}
    with (
        distributed.LocalCluster(
            processes=True, n_workers=2, threads_per_worker=1, dashboard_address=":0", env=env, silence_logs=40
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


@pytest.fixture(scope="module")
def robot():
    return kinedyn.robots.puma560()


@pytest.fixture(scope="module")
def states(robot):
    rng = np.random.default_rng(15)
    q = robot.random_configuration(rng, N)
    qd = rng.normal(size=(N, robot.n))
    qdd = rng.normal(size=(N, robot.n))
    return q, qd, qdd


def lazy(x, chunk=CHUNK):
    return da.from_array(x, chunks=(chunk,) + x.shape[1:])


# every batched method, with its state arguments (q, qd, and qdd or tau)
CALLS = {
    "forward_kinematics": lambda r, q, qd, a: r.forward_kinematics(q),
    "frame_poses": lambda r, q, qd, a: r.frame_poses(q),
    "pose": lambda r, q, qd, a: r.pose(q),
    "jacobian": lambda r, q, qd, a: r.jacobian(q, reference="local"),
    "jacobian_hessian": lambda r, q, qd, a: r.jacobian_hessian(q),
    "frame_velocity": lambda r, q, qd, a: r.frame_velocity(q, qd),
    "jacobian_dot_qd": lambda r, q, qd, a: r.jacobian_dot_qd(q, qd),
    "inverse_dynamics": lambda r, q, qd, a: r.inverse_dynamics(q, qd, a),
    "inverse_dynamics_f_ext": lambda r, q, qd, a: r.inverse_dynamics(q, qd, a, f_ext=np.full((r.n, 6), 0.5)),
    "mass_matrix": lambda r, q, qd, a: r.mass_matrix(q),
    "mass_matrix_inverse": lambda r, q, qd, a: r.mass_matrix_inverse(q),
    "forward_dynamics": lambda r, q, qd, a: r.forward_dynamics(q, qd, a),
    "inverse_dynamics_derivatives": lambda r, q, qd, a: r.inverse_dynamics_derivatives(q, qd, a),
    "forward_dynamics_derivatives": lambda r, q, qd, a: r.forward_dynamics_derivatives(q, qd, a),
    "coriolis_matrix": lambda r, q, qd, a: r.coriolis_matrix(q, qd),
    "christoffel": lambda r, q, qd, a: r.christoffel(q),
    "gravity_torque": lambda r, q, qd, a: r.gravity_torque(q),
    "bias_torque": lambda r, q, qd, a: r.bias_torque(q, qd),
    "kinetic_energy": lambda r, q, qd, a: r.kinetic_energy(q, qd),
    "potential_energy": lambda r, q, qd, a: r.potential_energy(q),
    "center_of_mass": lambda r, q, qd, a: r.center_of_mass(q),
    "momentum": lambda r, q, qd, a: r.momentum(q, qd),
    "centroidal_momentum_matrix": lambda r, q, qd, a: r.centroidal_momentum_matrix(q),
    "center_of_mass_jacobian": lambda r, q, qd, a: r.center_of_mass_jacobian(q),
    "regressor": lambda r, q, qd, a: r.regressor(q, qd, a),
    "friction_torque": lambda r, q, qd, a: r.friction_torque(qd),
}


def test_every_batched_method_is_covered():
    """A batched method added to Robot without a line in CALLS would go untested here."""
    wrapped = {name for name, f in vars(kinedyn.Robot).items() if hasattr(f, "__kinedyn_batched__")}
    assert wrapped == {name.removesuffix("_f_ext") for name in CALLS}


@pytest.mark.parametrize("name", list(CALLS))
def test_lazy_equals_in_process_batch_on_threads(robot, states, name):
    """Lazy (no work until compute), chunked like q, float64, and bit-equal to the NumPy batch."""
    q, qd, qdd = states
    expected = CALLS[name](robot, q, qd, qdd)
    # q and qd chunked differently: qd is rechunked to q's chunks; qdd stays a NumPy array
    got = CALLS[name](robot, lazy(q), lazy(qd, 77), qdd)
    expected, got = (expected, got) if isinstance(expected, tuple) else ((expected,), (got,))
    assert len(got) == len(expected)
    with dask.config.set(scheduler="threads"):
        for e, g in zip(expected, got):
            assert isinstance(g, da.Array)
            assert g.dtype == np.float64 and g.shape == e.shape
            # the states are chunked as the first dask argument (qd for friction_torque)
            assert g.chunks[0] == (lazy(qd, 77).chunks[0] if name == "friction_torque" else (120, 120, 120, 120, 20))
            assert all(len(c) == 1 for c in g.chunks[1:])
            np.testing.assert_array_equal(g.compute(), e)


def test_cluster_equals_in_process_batch(client, robot, states):
    """A real LocalCluster of worker processes gives the in-process batch's numbers exactly."""
    q, qd, qdd = states
    robot.mass_matrix(q[:1])  # the native model is built here: the robot must still travel
    M, tau = robot.mass_matrix(lazy(q)), robot.inverse_dynamics(lazy(q), lazy(qd), lazy(qdd))
    dq, dqd, Minv = robot.forward_dynamics_derivatives(lazy(q), lazy(qd), lazy(qdd))
    got = dask.compute(M, tau, dq, dqd, Minv, scheduler=client.get)
    expected = (
        robot.mass_matrix(q),
        robot.inverse_dynamics(q, qd, qdd),
        *robot.forward_dynamics_derivatives(q, qd, qdd),
    )
    for g, e in zip(got, expected):
        np.testing.assert_array_equal(g, e)
    # the tasks really ran in the worker processes
    pids = set(client.run(os.getpid).values())
    assert os.getpid() not in pids and len(pids) == 2


def test_model_built_once_per_worker_process(client, robot, states):
    """Two calls of 5 chunks each over two workers: each worker process unpickled the description
    and built the native model once."""
    q, qd, qdd = states
    r = kinedyn.robots.ur5()  # a robot no other test sent to this cluster
    q6 = lazy(r.random_configuration(1, N))
    dask.compute(r.gravity_torque(q6), r.inverse_dynamics(q6, q6, q6), scheduler=client.get)
    dask.compute(r.mass_matrix(q6), scheduler=client.get)
    info = client.run(process_cache_info)
    pids = {i["pid"] for i in info.values()}
    assert len(pids) == 2
    digests = set.union(*(set(i["unpickled"]) for i in info.values()))
    ur5 = [d for d in digests if any(i["built"].get(d) for i in info.values())]
    assert ur5, info
    for i in info.values():
        for d, count in i["unpickled"].items():
            assert count == 1, (i["pid"], d, count)
            assert i["built"][d]


def _die_once(block, marker):
    """Kill this worker process the first time any task gets here (the marker file says it did)."""
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return block
    os.close(fd)
    os._exit(1)


def test_a_killed_worker_is_recomputed(client, robot, states, tmp_path):
    """A worker dies mid-run, taking its finished chunks with it: Dask recomputes them on the other
    worker (or its restarted replacement) and the result is complete and equal."""
    q, qd, qdd = states
    marker = tmp_path / "killed"
    tau = robot.inverse_dynamics(lazy(q), lazy(qd), lazy(qdd))
    survived = tau.map_blocks(_die_once, str(marker), meta=np.empty((0, 0)))  # meta: no trial call here
    got = survived.compute(scheduler=client.get)
    assert marker.exists()  # a worker did die
    np.testing.assert_array_equal(got, robot.inverse_dynamics(q, qd, qdd))


def test_joint_axis_chunks_are_refused_with_the_fix(robot, states):
    q, qd, qdd = states
    with pytest.raises(ValueError, match=r"q is chunked along axis 1 .*q\.rechunk\(\{1: -1\}\)"):
        robot.mass_matrix(da.from_array(q, chunks=(100, 3)))
    with pytest.raises(ValueError, match=r"qd is chunked along axis 1"):
        robot.inverse_dynamics(lazy(q), da.from_array(qd, chunks=(100, 2)), qdd)
    with pytest.raises(ValueError, match=r"dask inputs must be batches"):
        robot.mass_matrix(da.from_array(q[0], chunks=3))
    with pytest.raises(ValueError, match=r"q has 500 states but qd has 400"):
        robot.inverse_dynamics(lazy(q), lazy(qd[:400]), qdd[:400])
    with pytest.raises(ValueError, match=r"out= cannot be used"):
        robot.mass_matrix(lazy(q), out=np.empty((N, 6, 6)))


def test_results_compose_and_stay_lazy(robot, states):
    """A dask result feeds the next call (the tool's speed from q, qd) without computing."""
    q, qd, _ = states
    v = robot.frame_velocity(lazy(q), lazy(qd))
    speed = da.linalg.norm(v[:, :3], axis=1)
    assert isinstance(speed, da.Array)
    np.testing.assert_array_equal(
        speed.compute(scheduler="sync"), np.linalg.norm(robot.frame_velocity(q, qd)[:, :3], axis=1)
    )


def test_batch_inverse_kinematics(client, robot, states):
    """A dask batch of targets (and of starts) gives lazy IKBatchResult fields equal to the NumPy
    batch's, on the cluster; positions as well as poses."""
    q, _, _ = states
    poses, starts = robot.pose(q), q + 0.01
    expected = robot.inverse_kinematics(poses, q0=starts)
    got = robot.inverse_kinematics(lazy(poses), q0=lazy(starts, 90))
    assert isinstance(got.q, da.Array) and got.q.chunks == ((120, 120, 120, 120, 20), (robot.n,))
    assert got.solver == expected.solver
    fields = ("q", "success", "position_error", "orientation_error", "iterations")
    for name, value in zip(fields, dask.compute(*(getattr(got, f) for f in fields), scheduler=client.get)):
        assert value.dtype == getattr(expected, name).dtype, name
        np.testing.assert_array_equal(value, getattr(expected, name), err_msg=name)
    assert expected.success.all()
    # position targets (the numeric solver: its random restarts are drawn per chunk, so its answers
    # are other solutions than the NumPy batch's, each reaching its target), one start for all
    points = poses[:, :3, 3]
    numeric = robot.inverse_kinematics(lazy(points), q0=q[0], method="numeric")
    assert numeric.solver == "numeric:lm"
    solutions, success = dask.compute(numeric.q, numeric.success, scheduler="sync")
    assert success.all()
    np.testing.assert_allclose(robot.pose(solutions)[:, :3, 3], points, rtol=0, atol=1e-9)
    # NumPy targets with a dask batch of starts
    np.testing.assert_array_equal(
        robot.inverse_kinematics(poses, q0=lazy(starts)).q.compute(scheduler="sync"), expected.q
    )
    with pytest.raises(ValueError, match=r"target is chunked along axis 1"):
        robot.inverse_kinematics(da.from_array(poses, chunks=(100, 2, 4)))


def _manipulability(robot, q):
    """Yoshikawa's manipulability sqrt(det(J J^T)) of a block of configurations."""
    J = robot.jacobian(q)
    return np.sqrt(np.abs(np.linalg.det(J @ np.swapaxes(J, -1, -2))))


def test_sweep_to_zarr_on_the_cluster(client, robot, tmp_path):
    """A random sweep written chunk by chunk on the worker processes: every array equals the
    in-process batch at the stored configurations, progress reported per chunk up to the total,
    and the sample is the same on the cluster as on threads."""
    seen = []
    quantities = {"M": "mass_matrix", "g": "gravity_torque", "P": "potential_energy", "manipulability": _manipulability}
    store = kinedyn.sweep(
        robot,
        tmp_path / "cluster.zarr",
        quantities,
        samples=N,
        chunk=CHUNK,
        seed=7,
        progress=lambda d, t: seen.append((d, t)),
    )
    q = store["q"][:]
    assert q.shape == (N, robot.n) and len(np.unique(q, axis=0)) == N
    lo, hi = robot.lower_limits, robot.upper_limits
    assert np.all((q >= np.where(np.isfinite(lo), lo, -np.pi)) & (q <= np.where(np.isfinite(hi), hi, np.pi)))
    np.testing.assert_array_equal(store["M"][:], robot.mass_matrix(q))
    np.testing.assert_array_equal(store["g"][:], robot.gravity_torque(q))
    np.testing.assert_array_equal(store["P"][:], robot.potential_energy(q))
    np.testing.assert_array_equal(store["manipulability"][:], _manipulability(robot, q))
    assert [t for _, t in seen] == [N] * 5 and sorted(d for d, _ in seen) == [d for d, _ in seen] and seen[-1][0] == N
    assert store.attrs["robot"] == robot.name and store.attrs["joint_names"] == list(robot.joint_names)
    with dask.config.set(scheduler="threads"):
        again = kinedyn.sweep(
            robot, tmp_path / "threads.zarr", ["gravity_torque"], samples=N, chunk=CHUNK, seed=7, progress=False
        )
    np.testing.assert_array_equal(again["q"][:], q)
    with pytest.raises(Exception, match="exist"):  # never overwrites a store unless asked
        kinedyn.sweep(robot, tmp_path / "threads.zarr", ["gravity_torque"], samples=N, chunk=CHUNK, progress=False)


def test_sweep_grid(robot, tmp_path):
    """A grid sweep holds every combination of per-joint points once, the last joint fastest."""
    points = [3, 2, 1, 1, 2, 4]
    with dask.config.set(scheduler="sync"):
        store = kinedyn.sweep(robot, tmp_path / "grid.zarr", ["pose"], grid=points, chunk=7, progress=False)
    q = store["q"][:]
    assert q.shape == (48, robot.n)
    assert [len(np.unique(q[:, j])) for j in range(robot.n)] == points
    assert len(np.unique(q, axis=0)) == 48
    assert np.all(np.diff(q[:4, 5]) > 0)
    np.testing.assert_array_equal(store["pose"][:], robot.pose(q))
    with pytest.raises(ValueError, match="either samples=N .* or grid"):
        kinedyn.sweep(robot, tmp_path / "x.zarr", samples=3, grid=2)
    with pytest.raises(ValueError, match="not a Robot method of q alone"):
        kinedyn.sweep(robot, tmp_path / "y.zarr", ["inverse_dynamics"], samples=3)


def test_kinedyn_never_imports_dask_itself():
    """Without dask imported (or installed) a robot works and kinedyn does not import it: the
    dispatch only looks at sys.modules."""
    import subprocess

    use = (
        "import kinedyn, numpy as np\n"
        "r = kinedyn.robots.puma560()\n"
        "assert r.mass_matrix(np.zeros((3, 6))).shape == (3, 6, 6)\n"
        "assert r.inverse_kinematics(r.pose(np.zeros((2, 6)))).q.shape == (2, 6)\n"
    )
    env = dict(os.environ, PYTHONPATH=str(Path(kinedyn.__file__).parents[1]))
    # dask installed: still never imported
    subprocess.run(
        [sys.executable, "-c", "import sys\n" + use + "assert 'dask' not in sys.modules, 'kinedyn imported dask'\n"],
        env=env,
        check=True,
        timeout=120,
    )
    # dask not importable (as if not installed): everything works
    subprocess.run(
        [sys.executable, "-c", "import sys; sys.modules['dask'] = None\n" + use], env=env, check=True, timeout=120
    )
