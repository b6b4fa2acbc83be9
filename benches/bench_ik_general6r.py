"""General-6R inverse kinematics (issue 28): every branch of arms without a special structure, per
call and per target of a batch, beside ssik's generated solver for the same arm (never a CI gate;
prints figures and ratios measured in one run).

    PYTHONPATH=python python benches/bench_ik_general6r.py [--calls 2000]

Arms: the UFactory xArm 6 (a generic general 6R: the 12 x 12 elimination) and the arms whose
consecutive axes all meet or are parallel (JACO 2, Gen3 lite, CRX-10iA, HC10, xMate CR7: the
extended 24 x 16 elimination), built as in tests/test_ik_general6r.py and
tests/test_ik_general6r_arms.py (the geometry ssik bakes into ``ssik.prebuilt``). Columns:
kinedyn per call from Python (``robot.inverse_kinematics(T, respect_limits=False)``, every branch
with its statement of completeness), the native call alone (``AnalyticIk.solve``), per target of
one batch call (``all_branches=True``, all threads), ssik's ``solve(T, respect_limits=False,
enumerate_windings=False)`` per call (its generated module, 200 targets) and the ratio
ssik / kinedyn per call (issue 28's target: at least 5).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import time
from pathlib import Path

import numpy as np

import kinedyn as kd

TESTS = Path(__file__).resolve().parent.parent / "tests"


def load_test_module(name: str):
    """The arms' definitions, shared with the tests (a script, not a package: loaded by path)."""
    spec = importlib.util.spec_from_file_location(name, TESTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def per_call(fn, items, repeat=3) -> float:
    """Best-of-`repeat` mean seconds per call over `items`."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        for x in items:
            fn(x)
        best = min(best, (time.perf_counter() - t0) / len(items))
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--calls", type=int, default=2000)
    args = parser.parse_args()
    general = load_test_module("test_ik_general6r")
    special = load_test_module("test_ik_general6r_arms")
    try:
        importlib.import_module("ssik.prebuilt")
        has_ssik = True
    except ImportError:
        has_ssik = False
        print("ssik is not installed (pip install ssik): no ssik column")
    arms = [("xarm6", general.xarm6(), "ufactory.xarm6_ik")]
    arms += [(name, special.arm(name), special.MODULES[name]) for name in sorted(special.ARMS)]
    print(f"kinedyn {kd.__version__}; CPUs {os.cpu_count()}; {args.calls} targets per arm")
    print(
        f"{'arm':10s} {'solver':24s} {'branches':>8s} {'Python us':>10s} {'native us':>10s} "
        f"{'batch us':>9s} {'ssik us':>9s} {'ratio':>6s}"
    )
    rng = np.random.default_rng(0)
    for name, robot, module in arms:
        Q = rng.uniform(-np.pi, np.pi, (args.calls, 6))
        T = robot.pose(Q)
        counts = [len(robot.inverse_kinematics(t, respect_limits=False)) for t in T[:200]]
        solver = robot.inverse_kinematics(T[0], respect_limits=False).solver
        ours = per_call(lambda t: robot.inverse_kinematics(t, respect_limits=False), T)
        chain = kd.ik.solve._chain(robot, None)
        ref = np.zeros(6)
        native = float("nan")
        if chain.solver is not None:
            native = per_call(lambda t: chain.solver.solve(t, ref, False, 1e-9), T)
        batch = float("nan")
        if chain.solver is not None:  # every branch of a batch needs a closed form
            t0 = time.perf_counter()
            robot.inverse_kinematics(T, all_branches=True, respect_limits=False)
            batch = (time.perf_counter() - t0) / args.calls
        cells = f"{name:10s} {solver:24s} {statistics.mean(counts):8.2f} {ours * 1e6:10.1f} {native * 1e6:10.1f} {batch * 1e6:9.2f}"
        if has_ssik:
            peer = importlib.import_module(f"ssik.prebuilt.{module}")
            peer.solve(T[0], respect_limits=False)  # first-call preparation outside the timing
            theirs = per_call(
                lambda t: peer.solve(t, respect_limits=False, enumerate_windings=False), T[:200], repeat=1
            )
            cells += f" {theirs * 1e6:9.1f} {theirs / ours:5.1f}x"
        print(cells)


if __name__ == "__main__":
    main()
