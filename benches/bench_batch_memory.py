"""Peak memory of a 10^7-state mass-matrix batch (issue 17 §2: output plus O(threads) scratch, and
the copy of the inputs Batch::gather makes). Run: PYTHONPATH=python python3 benches/bench_batch_memory.py 10000000"""

import resource
import sys

import numpy as np

import kinedyn as kd

robot = kd.robots.ur5()
N = int(sys.argv[1])
Q = np.random.default_rng(0).uniform(-3, 3, (N, robot.n))
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
M = robot._model.mass_matrix(Q)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(
    f"N={N}: inputs {Q.nbytes / 2**20:.0f} MiB, output {M.nbytes / 2**20:.0f} MiB, peak RSS before {base / 1024:.0f} MiB, after {peak / 1024:.0f} MiB, growth {(peak - base) / 1024:.0f} MiB ({(peak - base) * 1024 / M.nbytes:.3f} x output)"
)
