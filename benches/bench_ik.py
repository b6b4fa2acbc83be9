"""Inverse kinematics benchmark (never a CI gate; prints figures and ratios measured in one run).

    PYTHONPATH=python python benches/bench_ik.py [--targets 300] [--calls 3000]

1. Closed forms, all solutions, per call from Python (``robot.inverse_kinematics(T)``), for the
   tutorial elbow arm (position target), the PUMA 560 and the UR5 (poses); also the native call
   alone (``_core.AnalyticIk.solve``). Target of issue 5: UR5 under 10 us per call.
2. Numeric (Levenberg-Marquardt) on the Panda (example-robot-data URDF, fingers locked) and the
   UR5: success rate and median time per single-target call from the default start, beside
   Robotics Toolbox's ``ikine_LM`` (Python) and ``ik_LM`` (C++) on its own DH models of the same
   arms (``rtb.models.DH.Panda``, ``rtb.models.DH.UR5``), targets from random joint vectors within
   each model's limits. RTB's default tolerance is 1e-6 on its error E; kinedyn's 1e-10 m / rad.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

import kinedyn as kd
from kinedyn.testing import example_robot_data_dir


def per_call(fn, items, repeat=3) -> float:
    """Best-of-`repeat` mean seconds per call over `items`."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        for x in items:
            fn(x)
        best = min(best, (time.perf_counter() - t0) / len(items))
    return best


def panda():
    path = Path(example_robot_data_dir() or "/nonexistent") / "panda_description/urdf/panda.urdf"
    if not path.exists():
        return None
    return kd.Robot.from_urdf(str(path)).lock_joints({"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0})


def analytic_section(calls: int) -> None:
    print(f"\n== closed-form IK, all solutions, per call ({calls} targets) ==")
    print(
        f"{'robot':10s} {'structure':28s} {'solutions':>9s} {'Python us':>10s} {'native us':>10s} {'batch us/target':>16s}"
    )
    rng = np.random.default_rng(0)
    for name, position in (("elbow_3r", True), ("puma560", False), ("ur5", False)):
        robot = kd.robots.get(name)
        Q = robot.random_configuration(rng, size=calls)
        T = robot.pose(Q)
        targets = [np.ascontiguousarray(t[:3, 3] if position else t) for t in T]
        counts = [len(robot.inverse_kinematics(t, respect_limits=False)) for t in targets[:200]]
        py = per_call(lambda t: robot.inverse_kinematics(t, respect_limits=False), targets)
        chain = kd.ik.solve._chain(robot, None)
        ref = np.zeros(robot.n)
        native = per_call(lambda t: chain.solver.solve(t, ref, False, 1e-9), targets)
        batch_in = np.ascontiguousarray(np.array(targets))
        refs = np.zeros((calls, robot.n))
        t0 = time.perf_counter()
        chain.solver.solve_nearest(batch_in, refs, False, 1e-9)
        batch = (time.perf_counter() - t0) / calls
        print(
            f"{name:10s} {chain.solver.structure:28s} {statistics.mean(counts):9.2f} {py * 1e6:10.2f} {native * 1e6:10.2f} {batch * 1e6:16.3f}"
        )
    print("(solutions: mean count over 200 random targets without joint limits; batch: solve_nearest, all threads)")


def rtb_models():
    try:
        import roboticstoolbox as rtb
    except ImportError:
        return None
    return {"panda": rtb.models.DH.Panda(), "ur5": rtb.models.DH.UR5()}


def numeric_section(n_targets: int) -> None:
    print(f"\n== numeric IK (Levenberg-Marquardt), {n_targets} random reachable targets, single-target calls ==")
    arms = {"panda": (panda(), "panda_hand_tcp"), "ur5": (kd.robots.ur5(), None)}
    peers = rtb_models()
    if peers is None:
        print("Robotics Toolbox is not installed (pip install roboticstoolbox-python): kinedyn figures only")
    print(
        f"{'robot':6s} {'solver':26s} {'success':>8s} {'median us':>10s} {'mean us':>9s} {'ratio (RTB / kinedyn)':>22s}"
    )
    for name, (robot, frame) in arms.items():
        if robot is None:
            print(f"{name:6s} skipped: example-robot-data is not installed")
            continue
        rng = np.random.default_rng(1)
        Q = robot.random_configuration(rng, size=n_targets)
        T = robot.pose(Q, frame)
        times, ok = [], 0
        for t in T:
            t0 = time.perf_counter()
            r = robot.inverse_kinematics(t, frame=frame, method="numeric")
            times.append(time.perf_counter() - t0)
            ok += r.success
        ours = statistics.median(times)
        print(
            f"{name:6s} {'kinedyn numeric:lm':26s} {ok / n_targets:8.1%} {ours * 1e6:10.1f} {statistics.mean(times) * 1e6:9.1f} {'':>22s}"
        )
        t0 = time.perf_counter()
        batch = robot.inverse_kinematics(T, frame=frame, method="numeric")
        dt = time.perf_counter() - t0
        print(
            f"{name:6s} {'kinedyn batch (threads)':26s} {batch.success_rate:8.1%} {'':>10s} {dt / n_targets * 1e6:9.1f} {'':>22s}"
        )
        if peers is None:
            continue
        model = peers[name]
        lo, hi = model.qlim
        Qp = rng.uniform(lo, hi, size=(n_targets, model.n))
        Tp = [model.fkine(q) for q in Qp]
        for label, solve in (
            ("RTB ikine_LM (Python)", model.ikine_LM),
            ("RTB ik_LM (C++)", getattr(model, "ik_LM", None)),
        ):
            if solve is None:
                continue
            times, ok = [], 0
            for t in Tp:
                t0 = time.perf_counter()
                s = solve(t)
                times.append(time.perf_counter() - t0)
                ok += bool(s[1] if isinstance(s, tuple) else s.success)
            theirs = statistics.median(times)
            print(
                f"{name:6s} {label:26s} {ok / n_targets:8.1%} {theirs * 1e6:10.1f} {statistics.mean(times) * 1e6:9.1f} {theirs / ours:21.1f}x"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--calls", type=int, default=3000, help="targets for the closed-form timings")
    parser.add_argument("--targets", type=int, default=300, help="targets for the numeric comparison")
    args = parser.parse_args()
    import os

    print(f"kinedyn {kd.__version__}; numpy {np.__version__}; CPUs {os.cpu_count()}")
    analytic_section(args.calls)
    numeric_section(args.targets)


if __name__ == "__main__":
    main()
