"""Cost of the non-finite result scan of the native glue (issue 11 section 8; target: under 2 %).

Every batch result is scanned for NaN/inf right after its kernel wrote it (``Batch::run_many`` in
``crates/kinedyn-py/src/lib.rs``). This times 10k-state batches of ``mass_matrix`` and
``inverse_dynamics`` on the UR5 (built-in) and the Panda (example-robot-data, fingers locked; skipped
when the package is missing) with the scan on and off (``_core._set_check_finite``, a
benchmark-only switch), interleaved, and prints the overhead of the fastest runs.

    PYTHONPATH=python python3 benches/bench_finite_check.py [--states 10000] [--repeat 101]

Times are CPU time of the process (all threads), the fastest of the runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import kinedyn as kd  # noqa: E402
from kinedyn import _core  # noqa: E402


def robots() -> dict:
    out = {"ur5": kd.robots.ur5()}
    try:
        from common import LOCKED, PEER_URDFS, erd_robots_dir

        panda = kd.Robot.from_urdf(str(erd_robots_dir() / PEER_URDFS["panda"]))
        out["panda"] = panda.lock_joints(LOCKED["panda"])
    except (ImportError, FileNotFoundError) as e:
        print(f"(panda skipped: {e})")
    return out


def timed(fn) -> float:
    """CPU seconds of the process for one call (all threads): on a shared machine, wall time also
    counts the time other processes hold the cores."""
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def overhead(fn, repeat: int) -> tuple:
    """(fastest time with the scan, fastest without, overhead %), runs interleaved on/off so that
    drifts of the machine hit both alike; the minimum, not the median, because on a shared machine
    the other load only ever adds time (the median of a busy 2-core machine swung by +-10 %)."""
    on, off = [], []
    fn()
    for _ in range(repeat):
        _core._set_check_finite(False)
        off.append(timed(fn))
        _core._set_check_finite(True)
        on.append(timed(fn))
    t_on, t_off = min(on), min(off)
    return t_on, t_off, 100.0 * (t_on - t_off) / t_off


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=101)
    args = parser.parse_args()
    print(f"{'robot':8s} {'method':18s} {'with scan':>12s} {'without':>12s} {'overhead':>9s}")
    for name, robot in robots().items():
        rng = np.random.default_rng(0)
        q, qd, qdd = (rng.uniform(-1, 1, (args.states, robot.n)) for _ in range(3))
        calls = {
            "mass_matrix": lambda: robot.mass_matrix(q),
            "inverse_dynamics": lambda: robot.inverse_dynamics(q, qd, qdd),
        }
        for method, fn in calls.items():
            t_on, t_off, pct = overhead(fn, args.repeat)
            print(f"{name:8s} {method:18s} {t_on * 1e3:10.3f}ms {t_off * 1e3:10.3f}ms {pct:+8.2f}%")
    _core._set_check_finite(True)


if __name__ == "__main__":
    main()
