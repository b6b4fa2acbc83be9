"""Sweeps over a robot's configuration space, chunk by chunk into a Zarr store, on any dask scheduler
(docs/scale.md; needs the ``scale`` extra: dask[array], distributed, zarr).

``kinedyn.sweep(robot, "maps.zarr", ["mass_matrix", "gravity_torque"], samples=10**8)`` draws the
configurations chunk by chunk on the workers (a random sample reproducible from ``seed``, whatever
the scheduler or the chunk order; or a regular grid within the joint limits), evaluates each
quantity on the chunk with Robot's batched methods (kinedyn/_dask.py), and writes every chunk to
its place in the store as soon as it is done: no process ever holds more than a few chunks.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from ._ui.progress import Delayed, wanted

if TYPE_CHECKING:
    from ._typing import PathLike
    from .robot import Robot

__all__ = ["sweep", "configurations"]

Quantity = Union[str, Callable[["Robot", np.ndarray], np.ndarray]]

# Robot methods of q alone that a sweep evaluates by name
_OF_Q = (
    "forward_kinematics",
    "frame_poses",
    "pose",
    "jacobian",
    "jacobian_hessian",
    "mass_matrix",
    "mass_matrix_inverse",
    "christoffel",
    "gravity_torque",
    "potential_energy",
    "center_of_mass",
)


def _bounds(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """The box a sweep covers: the joint limits, [-pi, pi] (revolute) or [-1, 1] (prismatic) where
    a side is infinite (as Robot.random_configuration)."""
    lo, hi = robot.lower_limits.copy(), robot.upper_limits.copy()
    for i, joint in enumerate(robot.joints):
        span = math.pi if joint.kind == "revolute" else 1.0
        lo[i] = lo[i] if math.isfinite(lo[i]) else -span
        hi[i] = hi[i] if math.isfinite(hi[i]) else span
    return lo, hi


def _random_block(index: np.ndarray, lo, hi, seed: int, chunk: int) -> np.ndarray:
    """Configurations of the states ``index`` (one chunk): chunk k of the sample is drawn from its
    own stream ``default_rng([seed, k])``, so the sample does not depend on who computes what."""
    k = int(index[0]) // chunk
    rng = np.random.default_rng([seed, k])
    return rng.uniform(lo, hi, size=(len(index), len(lo)))


def _grid_block(index: np.ndarray, axes: tuple) -> np.ndarray:
    """Grid points ``index`` (row-major over the joints, the last joint fastest)."""
    digits = np.unravel_index(index, tuple(len(a) for a in axes))
    return np.stack([a[d] for a, d in zip(axes, digits)], axis=1)


def configurations(
    robot: Robot,
    *,
    samples: int | None = None,
    grid: Union[int, Sequence[int], None] = None,
    chunk: int = 100_000,
    seed: int = 0,
):
    """The configurations of a sweep as a lazy (N, n) dask array chunked by ``chunk`` states:
    ``samples`` uniform random configurations in the joint limits (chunk k drawn from
    ``numpy.random.default_rng([seed, k])``), or a ``grid`` of points per joint (one number, or one
    per joint; endpoints included, the last joint varying fastest)."""
    import dask.array as da

    if (samples is None) == (grid is None):
        raise ValueError("give either samples=N (a random sample) or grid=points per joint (a regular grid)")
    if not (isinstance(chunk, (int, np.integer)) and chunk >= 1):
        raise ValueError(f"chunk must be a whole number of states >= 1, got {chunk!r}")
    lo, hi = _bounds(robot)
    n = robot.n
    if samples is not None:
        if not (isinstance(samples, (int, np.integer)) and samples >= 1):
            raise ValueError(f"samples must be a whole number of configurations >= 1, got {samples!r}")
        index = da.arange(int(samples), chunks=int(chunk), dtype=np.int64)
        return index.map_blocks(
            _random_block,
            lo,
            hi,
            int(seed),
            int(chunk),
            new_axis=1,
            chunks=(index.chunks[0], (n,)),
            dtype=np.float64,
            meta=np.empty((0, 0)),
        )
    points: list = [grid] * n if isinstance(grid, (int, np.integer)) else list(grid or ())
    if len(points) != n or not all(isinstance(p, (int, np.integer)) and p >= 1 for p in points):
        raise ValueError(f"grid must be a number of points >= 1 per joint (one number, or {n} of them), got {grid!r}")
    axes = tuple(
        np.linspace(lo[i], hi[i], int(p)) if p > 1 else np.array([(lo[i] + hi[i]) / 2]) for i, p in enumerate(points)
    )
    total = int(np.prod([int(p) for p in points], dtype=object))
    index = da.arange(total, chunks=int(chunk), dtype=np.int64)
    return index.map_blocks(
        _grid_block, axes, new_axis=1, chunks=(index.chunks[0], (n,)), dtype=np.float64, meta=np.empty((0, 0))
    )


def _evaluate(robot: Robot, q, name: str, quantity: Quantity):

    if isinstance(quantity, str):
        if quantity not in _OF_Q:
            raise ValueError(
                f"sweep quantity '{quantity}' is not a Robot method of q alone; one of {list(_OF_Q)}, "
                "or a function f(robot, q) of a NumPy (m, n) block returning (m, ...)"
            )
        return getattr(robot, quantity)(q)
    # a function of a NumPy block of configurations: its per-state shape from one state
    probe = np.asarray(quantity(robot, robot.neutral()[None]))
    if probe.ndim < 1 or probe.shape[0] != 1:
        raise ValueError(
            f"sweep quantity '{name}' must return one row per configuration, (m, ...); for 1 state it gave shape {probe.shape}"
        )
    trailing = probe.shape[1:]
    return q.map_blocks(
        _apply,
        robot,
        quantity,
        drop_axis=1,
        new_axis=list(range(1, 1 + len(trailing))),
        chunks=(q.chunks[0],) + tuple((s,) for s in trailing),
        dtype=np.float64,
        meta=np.empty((0,) * probe.ndim),
    )


def _apply(block: np.ndarray, robot: Robot, function) -> np.ndarray:
    return np.asarray(function(robot, block), dtype=np.float64)


def sweep(
    robot: Robot,
    store: Union[PathLike, Any],
    quantities: Union[Sequence[Quantity], Mapping[str, Quantity]] = ("mass_matrix",),
    *,
    samples: int | None = None,
    grid: Union[int, Sequence[int], None] = None,
    chunk: int = 100_000,
    seed: int = 0,
    progress: Union[bool, None, Callable[[int, int], Any]] = None,
    overwrite: bool = False,
):
    """Evaluate ``quantities`` over a random sample or a grid of configurations, writing each chunk
    of states to the Zarr ``store`` (a path or a Zarr store) as it is computed, on the active dask
    scheduler (threads by default; a ``distributed.Client`` when one exists).

    ``quantities``: names of Robot methods of q alone (``"mass_matrix"``, ``"gravity_torque"``,
    ``"pose"``, ``"jacobian"``, ...) or a mapping name -> method name or function ``f(robot, q)``
    of a NumPy (m, n) block of configurations returning (m, ...). The store gets one array per
    quantity and ``q`` (the configurations), chunked by ``chunk`` states, and attributes naming the
    robot, its joints and the sampling. ``samples``/``grid``/``seed``: as :func:`configurations`.
    ``progress``: a bar on stderr (None: when stderr is a terminal), or a function called with
    (states written, total) after each chunk. Returns the Zarr group, opened for reading.
    """
    import dask
    import dask.array as da
    import zarr

    named: dict[str, Quantity] = (
        dict(quantities)
        if isinstance(quantities, Mapping)
        else {
            (q if isinstance(q, str) else getattr(q, "__name__", f"quantity{i}")): q for i, q in enumerate(quantities)
        }
    )
    if "q" in named:
        raise ValueError("'q' is the name of the configurations' array in the store: name the quantity otherwise")
    q = configurations(robot, samples=samples, grid=grid, chunk=chunk, seed=seed)
    arrays = {"q": q}
    for name, quantity in named.items():
        arrays[name] = _evaluate(robot, q, name, quantity)
    import os

    if not overwrite and isinstance(store, (str, os.PathLike)) and os.path.exists(store):
        raise FileExistsError(f"sweep: {os.fspath(store)} exists; pass overwrite=True to replace it")
    group = zarr.open_group(store, mode="w" if overwrite else "w-")
    group.attrs.update(
        {
            "kinedyn": "sweep",
            "robot": robot.name,
            "joint_names": list(robot.joint_names),
            "sampling": "random" if samples is not None else "grid",
            "seed": int(seed),
            "chunk": int(chunk),
            "grid": None
            if grid is None
            else ([int(grid)] * robot.n if isinstance(grid, (int, np.integer)) else [int(g) for g in grid]),
            "lower": _bounds(robot)[0].tolist(),
            "upper": _bounds(robot)[1].tolist(),
        }
    )
    targets = {}
    for name, x in arrays.items():
        targets[name] = group.create_array(name, shape=x.shape, chunks=(chunk,) + x.shape[1:], dtype=x.dtype)
    # one write task per chunk of states, all arrays of the chunk together
    total = q.shape[0]
    flat = [arrays[k].reshape(total, -1) for k in arrays]
    writes = da.map_blocks(
        _write_chunk,
        *flat,
        targets=[targets[k] for k in arrays],
        shapes=[arrays[k].shape[1:] for k in arrays],
        drop_axis=1,
        chunks=((1,) * len(q.chunks[0]),),
        dtype=np.int64,
        meta=np.empty((0,), dtype=np.int64),
    )
    report = _progress(progress, total)
    chunks = writes.to_delayed().ravel()
    done = 0
    try:
        client = _distributed_client()
        if client is not None:
            from distributed import as_completed

            for future in as_completed(client.compute(list(chunks))):
                done += int(future.result()[0])
                report(done, total)
        else:
            step = _parallelism()  # a few chunks per worker thread at a time, so the bar moves
            for start in range(0, len(chunks), step):
                done += sum(int(c[0]) for c in dask.compute(*chunks[start : start + step]))
                report(done, total)
    finally:
        getattr(report, "close", lambda: None)()
    return zarr.open_group(store, mode="r")


def _write_chunk(*blocks, targets, shapes, block_info=None) -> np.ndarray:
    """Write one chunk of states of every array; returns the chunk's state count (one number)."""
    start, stop = block_info[0]["array-location"][0]
    for block, target, shape in zip(blocks, targets, shapes):
        target[start:stop] = block.reshape((stop - start,) + tuple(shape))
    return np.array([stop - start], dtype=np.int64)


def _distributed_client():
    try:
        from distributed import default_client

        return default_client()
    except (ImportError, ValueError):
        return None


def _parallelism() -> int:
    import os

    return 2 * (os.cpu_count() or 1)


def _progress(progress, total: int):
    """A function (done, total) -> None reporting progress, with a close()."""
    if callable(progress):
        return progress
    bar = Delayed(wanted(progress), total, "sweep", "{task.completed:.0f} / {task.total:.0f} states", 0.0)

    class Report:
        def __call__(self, done: int, total: int) -> None:
            bar.update(done)

        def close(self) -> None:
            bar.close()

    return Report()
