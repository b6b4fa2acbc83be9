"""Issue 11 §5 figures (a benchmark, not a test): wall time of `kinedyn report` on the default robot
and on example-robot-data's Talos (44 joints; 17 minutes in its RK45 simulation before the report had
budgets), and of the Panda PD + gravity run (docs/simulation.md) with the default method.

    PYTHONPATH=python python benches/bench_longwork.py
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

import numpy as np


def _erd():
    from kinedyn.testing import example_robot_data_dir

    return example_robot_data_dir()


def _report(args, out):
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "kinedyn", "report", *args, "-o", out], check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> None:
    import kinedyn as kd

    erd = _erd()
    with tempfile.TemporaryDirectory() as tmp:
        print(
            f"kinedyn report (default robot, with the tutorial): {_report([], os.path.join(tmp, 'default.html')):.1f} s"
        )
        if erd is None:
            print("example-robot-data is not installed: no Talos or Panda figures")
            return
        talos = os.path.join(erd, "talos_data", "robots", "talos_full_v2.urdf")
        print(
            f"kinedyn report talos_full_v2.urdf (44 joints): {_report([talos], os.path.join(tmp, 'talos.html')):.1f} s (the issue's bound: 60 s)"
        )
    panda = kd.load(os.path.join(erd, "panda_description", "urdf", "panda.urdf"))
    goal = np.array([0.3, -0.5, 0.4, -1.5, 0.3, 1.2, 0.2, 0.01, 0.01])
    start = time.perf_counter()
    traj = kd.simulate(
        panda, 4.0, np.zeros(18), controller=kd.simulate.PDGravity(panda, 100.0, 20.0, goal), record_every=10
    )
    print(
        f"Panda PD + gravity, 4 s at dt = 1 ms, method {traj.method}: {time.perf_counter() - start:.2f} s wall, final error {np.abs(traj.q[-1] - goal).max():.2g} rad"
    )


if __name__ == "__main__":
    main()
