"""Dask benchmark (issue 15 §1; not a timed test): ``inverse_dynamics`` and ``mass_matrix`` over
N states (default 10^7, PUMA 560) on a 2-worker ``LocalCluster`` (processes, one thread each)
against one in-process batch call, in the same run.

Both sides do the same work: draw N uniform configurations (and velocities, accelerations), evaluate,
and reduce the result to its sum over the states (so that the cluster does not ship gigabytes back
to the client, and the in-process side pays its one big allocation). Prints the seconds of each,
the overhead ``dask / in-process - 1``, and each worker's peak resident memory against the size of
one chunk's result and of the whole result (memory per worker is bounded by the chunk size, not N).

    PYTHONPATH=python python benches/bench_dask.py [--states N] [--chunk C] [--repeat R]
"""

from __future__ import annotations

import argparse
import os
import resource
import time
from pathlib import Path

import numpy as np


def peak_rss_mib() -> float:
    """This process's peak resident memory (MiB; Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def in_process(robot, n_states: int, quantity: str) -> float:
    start = time.perf_counter()
    rng = np.random.default_rng(0)
    q = robot.random_configuration(rng, n_states)
    if quantity == "mass_matrix":
        total = robot.mass_matrix(q).sum(axis=0)
    else:
        qd, qdd = rng.normal(size=(n_states, robot.n)), rng.normal(size=(n_states, robot.n))
        total = robot.inverse_dynamics(q, qd, qdd).sum(axis=0)
    assert np.all(np.isfinite(total))
    return time.perf_counter() - start


def on_cluster(client, robot, n_states: int, chunk: int, quantity: str) -> float:
    import dask.array as da

    from kinedyn.scale import configurations

    start = time.perf_counter()
    q = configurations(robot, samples=n_states, chunk=chunk, seed=0)  # drawn on the workers
    if quantity == "mass_matrix":
        result = robot.mass_matrix(q)
    else:
        rs = da.random.default_rng(1)
        qd = rs.standard_normal((n_states, robot.n), chunks=(chunk, -1))
        qdd = rs.standard_normal((n_states, robot.n), chunks=(chunk, -1))
        result = robot.inverse_dynamics(q, qd, qdd)
    total = result.sum(axis=0).compute()
    assert np.all(np.isfinite(total))
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10**7)
    parser.add_argument("--chunk", type=int, default=250_000)
    parser.add_argument("--repeat", type=int, default=2, help="runs of each side; the best is kept")
    args = parser.parse_args()

    from distributed import Client, LocalCluster

    import kinedyn

    robot = kinedyn.robots.puma560()
    env = {"PYTHONPATH": os.pathsep.join([str(Path(kinedyn.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])}
    with (
        LocalCluster(
            processes=True,
            n_workers=2,
            threads_per_worker=1,
            dashboard_address=":0",
            env=env,
            memory_limit="6GiB",
            silence_logs=40,
        ) as cluster,
        Client(cluster) as client,
    ):
        on_cluster(client, robot, 4 * args.chunk, args.chunk, "mass_matrix")  # workers warm: imports, model built
        rss_start = client.run(peak_rss_mib)
        print(
            f"PUMA 560, {args.states:.3g} states, chunks of {args.chunk} states; best of {args.repeat}; "
            f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}"
        )
        for quantity, _per_state in (("inverse_dynamics", robot.n), ("mass_matrix", robot.n**2)):
            local = min(in_process(robot, args.states, quantity) for _ in range(args.repeat))
            dask_s = min(on_cluster(client, robot, args.states, args.chunk, quantity) for _ in range(args.repeat))
            print(
                f"  {quantity:17s} in-process {local:7.2f} s ({local / args.states * 1e9:6.1f} ns/state)   "
                f"2-worker LocalCluster {dask_s:7.2f} s   overhead {dask_s / local - 1:+.0%}"
            )
        rss = client.run(peak_rss_mib)
        chunk_mib = args.chunk * robot.n**2 * 8 / 2**20
        whole_mib = args.states * robot.n**2 * 8 / 2**20
        print(
            f"  worker peak RSS (MiB): {', '.join(f'{v:.0f} (after warm-up {rss_start[k]:.0f})' for k, v in rss.items())}; "
            f"one chunk of M {chunk_mib:.0f} MiB, the whole M {whole_mib:.0f} MiB"
        )
    print(f"  this process's peak RSS (the in-process batch holds the whole result): {peak_rss_mib():.0f} MiB")


if __name__ == "__main__":
    main()
