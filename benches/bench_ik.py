"""Inverse kinematics benchmark (never a CI gate; prints figures and ratios measured in one run).

    PYTHONPATH=python python benches/bench_ik.py [--targets 300] [--calls 3000] [--sections analytic,peers,numeric]

1. Closed forms, all solutions, per call from Python (``robot.inverse_kinematics(T)``), for the
   tutorial elbow arm (position target), the PUMA 560 and the UR5 (poses); also the native call
   alone (``_core.AnalyticIk.solve``). Target of issue 5: UR5 under 10 us per call.
2. Every branch beside the peers (issue 28), the same arm built on each side from kinedyn's screw
   axes at q = 0 (EAIK's ``H, P``): per call from Python and per target in one batch call, kinedyn
   against EAIK (``HPRobot.IK`` / ``IK_batched``) and ssik (``Manipulator.from_axes(...).solve``),
   printed as ratios (peer time / kinedyn time: above 1, kinedyn is faster). Arms: UR5 and PUMA 560
   (Pieper 6R), the KUKA iiwa with joint 3 held (EAIK's ``fixed_axes``; ssik on the locked six-joint
   chain), the Panda with joint 7 held (EAIK only: ssik prepares that chain in minutes and finds
   nothing), and the iiwa at one arm angle (kinedyn only: neither peer takes an arm angle).
3. Numeric (Levenberg-Marquardt) on the Panda (example-robot-data URDF, fingers locked) and the
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
    """Mean seconds per call over `items`: the best of `repeat` passes when `repeat` is 1 or 2 (slow
    peers), else the minimum over 10 x `repeat` rounds of the mean over (up to) 100 of them, which a
    loaded shared machine disturbs far less (as `crates/kinedyn-core/benches/quick.rs`)."""
    if repeat < 3:
        best = float("inf")
        for _ in range(repeat):
            t0 = time.perf_counter()
            for x in items:
                fn(x)
            best = min(best, (time.perf_counter() - t0) / len(items))
        return best
    chunk = items[:100]
    best = float("inf")
    for _ in range(10 * repeat):
        t0 = time.perf_counter()
        for x in chunk:
            fn(x)
        best = min(best, (time.perf_counter() - t0) / len(chunk))
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


def hp_of(robot, frame=None):
    """EAIK's (H, P) of the chain at q = 0 and the tool's rotation there (tests/test_ik_oracles.py)."""
    q = np.zeros(robot.nq)
    J = robot.jacobian(q, frame, reference="spatial")
    H = J[3:].T.copy()
    feet = np.cross(H, J[:3].T)
    points = feet.copy()
    for i in range(1, len(H)):
        w0, w1, d = H[i - 1], H[i], feet[i] - points[i - 1]
        n = np.cross(w0, w1)
        if np.linalg.norm(n) > 1e-9:
            points[i] = feet[i] + w1 * (np.cross(d, w0) @ n) / (n @ n)
        else:
            points[i] = feet[i] + w1 * (w1 @ (points[i - 1] - feet[i]))
    home = robot.pose(q, frame)
    return H, np.diff(np.vstack([np.zeros(3), points, home[:3, 3]]), axis=0), home[:3, :3]


def iiwa():
    try:
        import pybullet_data
    except ImportError:
        return None
    path = Path(pybullet_data.getDataPath()) / "kuka_iiwa/model.urdf"
    return kd.load(str(path)) if path.exists() else None


def peers_section(calls: int) -> None:
    print(f"\n== every branch, beside EAIK and ssik ({calls} targets; ratio = peer time / kinedyn time) ==")
    try:
        from eaik.IK_HP import HPRobot
    except ImportError:
        HPRobot = None
        print("EAIK is not installed (pip install EAIK): no EAIK column")
    try:
        import ssik
    except ImportError:
        ssik = None
        print("ssik is not installed (pip install ssik): no ssik column")
    print(
        f"{'arm':22s} {'structure':44s} {'branches':>8s} {'kinedyn us':>10s} {'batch us':>9s} "
        f"{'EAIK us':>8s} {'ratio':>6s} {'EAIK batch':>10s} {'ratio':>6s} {'ssik us':>8s} {'ratio':>6s}"
    )
    rng = np.random.default_rng(5)
    arms = [
        ("ur5", kd.robots.ur5(), None, None),
        ("puma560", kd.robots.puma560(), None, None),
        ("iiwa, joint 3 held", iiwa(), None, ("held", 2)),
        ("panda, joint 7 held", panda(), "panda_hand_tcp", ("held", 6)),
        ("iiwa, arm angle", iiwa(), None, ("arm_angle", None)),
    ]
    for label, robot, frame, param in arms:
        if robot is None:
            print(f"{label:22s} skipped: its URDF is not installed")
            continue
        Q = robot.random_configuration(rng, size=calls)
        value = 0.4
        if param is not None and param[0] == "held":
            Q[:, param[1]] = value
            redundancy = {"joint": param[1], "value": value}
        elif param is not None:
            redundancy = {"arm_angle": value}
        else:
            redundancy = None
        T = robot.pose(Q, frame)
        kw = dict(frame=frame, respect_limits=False)
        if redundancy is not None:
            kw["redundancy"] = redundancy
        first = robot.inverse_kinematics(T[0], **kw)
        counts = [len(robot.inverse_kinematics(t, **kw).solutions) for t in T[:200]]
        ours = per_call(lambda t: robot.inverse_kinematics(t, **kw), T)
        batch_kw = dict(kw) if redundancy is not None else dict(kw, all_branches=True)
        t0 = time.perf_counter()
        robot.inverse_kinematics(T, **batch_kw)
        batch = (time.perf_counter() - t0) / calls
        cells = [
            f"{label:22s} {first.structure:44s} {statistics.mean(counts):8.2f} {ours * 1e6:10.2f} {batch * 1e6:9.3f}"
        ]
        H, P, R0 = hp_of(robot, frame)
        X = np.eye(4)
        X[:3, :3] = R0.T
        Tp = np.ascontiguousarray(T @ X)
        eaik_cells = f"{'':>8s} {'':>6s} {'':>10s} {'':>6s}"
        if HPRobot is not None and (param is None or param[0] == "held"):
            peer = HPRobot(H, P) if param is None else HPRobot(H, P, fixed_axes=[(param[1], value)])
            theirs = per_call(peer.IK, Tp)
            t0 = time.perf_counter()
            peer.IK_batched(list(Tp))
            theirs_batch = (time.perf_counter() - t0) / calls
            eaik_cells = (
                f"{theirs * 1e6:8.2f} {theirs / ours:5.2f}x {theirs_batch * 1e6:10.3f} {theirs_batch / batch:5.2f}x"
            )
        ssik_cells = f"{'':>8s} {'':>6s}"
        if ssik is not None and (param is None or (param[0] == "held" and "panda" not in label)):
            if param is None:
                chain = ssik.Manipulator.from_axes(H, P)
            else:
                locked = robot.lock_joints({robot.joint_names[param[1]]: value})
                Hl, Pl, Rl = hp_of(locked, frame)
                chain = ssik.Manipulator.from_axes(Hl, Pl)
                Xl = np.eye(4)
                Xl[:3, :3] = Rl.T
                Tp = np.ascontiguousarray(T @ Xl)
            chain.solve(Tp[0], respect_limits=False)  # its one-time preparation, outside the timing
            n_ssik = min(calls, 300)
            theirs = per_call(lambda t: chain.solve(t, respect_limits=False), Tp[:n_ssik], repeat=1)
            ssik_cells = f"{theirs * 1e6:8.1f} {theirs / ours:5.1f}x"
        print(" ".join([cells[0], eaik_cells, ssik_cells]))
    print(
        "(kinedyn us: robot.inverse_kinematics(T, respect_limits=False) per call, every branch, with its statement of "
        "completeness; batch: one call for all targets (all_branches=True, or a redundancy batch), all threads; "
        "EAIK batch: IK_batched; ssik: solve(T, respect_limits=False) per call, 300 targets)"
    )


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
    parser.add_argument(
        "--sections",
        default="analytic,peers,numeric",
        help="comma-separated sections to run (analytic, peers, numeric)",
    )
    args = parser.parse_args()
    sections = set(args.sections.split(","))
    import os

    print(f"kinedyn {kd.__version__}; numpy {np.__version__}; CPUs {os.cpu_count()}")
    if "analytic" in sections:
        analytic_section(args.calls)
    if "peers" in sections:
        peers_section(args.calls)
    if "numeric" in sections:
        numeric_section(args.targets)


if __name__ == "__main__":
    main()
