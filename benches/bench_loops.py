"""Constrained forward dynamics of closed loops (issue 27 §2): kinedyn's
``robot.constrained_forward_dynamics`` (the core's proximal KKT solve) beside Pinocchio's
``constraintDynamics`` called from Python, in the same run, as ratios; per call (one state) and
per state of a batch (kinedyn: one native call for N states, SIMD lanes and threads; Pinocchio: a
Python loop, which is how a Python user batches it).

The mechanism: two chains of three revolute joints with skew axes whose ends are pinned together
(a spatial point loop, 3 rows, 6 joints), read by both from one URDF; states closed by
``project_configuration`` and ``project_velocity``.

    PYTHONPATH=python python benches/bench_loops.py [--states 10000] [--repeat 5] [--rounds 400]

One call is timed as the minimum over ``--rounds`` short rounds (50 calls each, cycling over the
states) of the mean time per call: on a machine shared by many jobs most rounds are preempted, and a
round short enough to run undisturbed measures the call itself (a round of 2000 calls rarely does:
the figures of the first table in benches/NOTES.md varied 30 % between runs). It is given for the
Python API (``robot.constrained_forward_dynamics``), for the native call alone
(``robot._model.constrained_forward_dynamics``: the binding and the core) and for Pinocchio.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import pinocchio as pin

import kinedyn as kd


def link(name, mass, com):
    return (
        f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/>'
        '<inertia ixx="0.01" iyy="0.02" izz="0.015" ixy="0.001" ixz="0" iyz="0.002"/></inertial></link>'
    )


def joint(name, parent, child, xyz, axis=None):
    if axis is None:
        return f'<joint name="{name}" type="fixed"><parent link="{parent}"/><child link="{child}"/><origin xyz="{xyz}"/></joint>'
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/><origin xyz="{xyz}"/>'
        f'<axis xyz="{axis}"/><limit lower="-10" upper="10" effort="10" velocity="10"/></joint>'
    )


URDF = (
    '<robot name="loop"><link name="base"/>'
    + "".join(
        link(n, m, c)
        for n, m, c in [
            ("l1", 1.0, "0.1 0 0.05"),
            ("l2", 0.9, "0.15 0.02 0"),
            ("l3", 0.7, "0.1 0 0"),
            ("r1", 1.1, "0 0.1 0.05"),
            ("r2", 0.6, "0.1 0.1 0"),
            ("r3", 0.5, "0.05 0 0.1"),
            ("tip_a", 0.0, "0 0 0"),
            ("tip_b", 0.0, "0 0 0"),
        ]
    )
    + joint("j1", "base", "l1", "0 0 0", "0 0 1")
    + joint("j2", "l1", "l2", "0.3 0 0.1", "0 1 0")
    + joint("j3", "l2", "l3", "0.3 0 0", "1 0 1")
    + joint("k1", "base", "r1", "0.5 0.3 0", "0 0 1")
    + joint("k2", "r1", "r2", "0 0.3 0.1", "1 0 0")
    + joint("k3", "r2", "r3", "0 0.3 0", "0 1 1")
    + joint("ta", "l3", "tip_a", "0.25 0 0")
    + joint("tb", "r3", "tip_b", "0 0.2 0")
    + "</robot>"
)


def best(fn, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def per_call(fn, count, rounds, calls=50):
    """Minimum over ``rounds`` rounds of ``calls`` calls ``fn(k)`` (k cycling over ``count`` states)
    of the mean time per call."""
    best_round = float("inf")
    for r in range(rounds):
        ks = [(r * calls + j) % count for j in range(calls)]
        start = time.perf_counter()
        for k in ks:
            fn(k)
        best_round = min(best_round, time.perf_counter() - start)
    return best_round / calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--states", type=int, default=10000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=400)
    args = parser.parse_args()
    robot = kd.Robot.from_urdf(URDF).add_loop("tip_a", "tip_b")
    rng = np.random.default_rng(0)
    count = min(args.states, 200)
    q = np.array([robot.project_configuration(rng.uniform(-0.6, 0.6, 6), hold=["j1"]) for _ in range(count)])
    qd = robot.project_velocity(q, rng.uniform(-1, 1, (count, 6)))
    q, qd = np.resize(q, (args.states, 6)), np.resize(qd, (args.states, 6))
    tau = rng.uniform(-2, 2, (args.states, 6))

    model = pin.buildModelFromXML(URDF)
    data = model.createData()
    fa, fb = model.frames[model.getFrameId("tip_a")], model.frames[model.getFrameId("tip_b")]
    cm = pin.RigidConstraintModel(
        pin.ContactType.CONTACT_3D,
        model,
        fa.parentJoint,
        fa.placement,
        fb.parentJoint,
        fb.placement,
        pin.ReferenceFrame.LOCAL,
    )
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    models.append(cm)
    datas.append(cm.createData())
    pin.initConstraintDynamics(model, data, models, datas)
    settings = pin.ProximalSettings(1e-12, 1e-10, 100)

    qdd, _ = robot.constrained_forward_dynamics(q[:50], qd[:50], tau[:50])
    ref = np.array(
        [pin.constraintDynamics(model, data, q[k], qd[k], tau[k], models, datas, settings) for k in range(50)]
    )
    print(f"largest |qdd_kinedyn - qdd_pinocchio| over 50 states: {np.abs(qdd - ref).max():.1e}")

    count = min(args.states, 2000)
    native = robot._model  # the binding and the core, without the Python layers
    one_kd = per_call(lambda k: robot.constrained_forward_dynamics(q[k], qd[k], tau[k]), count, args.rounds)
    one_native = per_call(lambda k: native.constrained_forward_dynamics(q[k], qd[k], tau[k], None), count, args.rounds)
    one_pin = per_call(
        lambda k: pin.constraintDynamics(model, data, q[k], qd[k], tau[k], models, datas, settings), count, args.rounds
    )
    n = args.states
    batch_kd = best(lambda: robot.constrained_forward_dynamics(q, qd, tau), args.repeat) / n
    batch_pin = (
        best(
            lambda: [
                pin.constraintDynamics(model, data, q[k], qd[k], tau[k], models, datas, settings) for k in range(n)
            ],
            1,
        )
        / n
    )
    print(
        f"one call     : kinedyn {one_kd * 1e6:7.2f} us   pinocchio {one_pin * 1e6:7.2f} us   ratio {one_pin / one_kd:5.2f}x"
        f"   (native call alone {one_native * 1e6:5.2f} us)"
    )
    print(
        f"batch of {n}: kinedyn {batch_kd * 1e6:7.3f} us/state   pinocchio loop {batch_pin * 1e6:7.3f} us/state   ratio {batch_pin / batch_kd:5.1f}x"
    )
    closed_chain_ik(args.repeat)


def closed_chain_ik(repeat: int) -> None:
    """Inverse kinematics on a closed chain (kinedyn.ik.closed_chain): Spong's five-bar, its tool at
    200 positions along a path of its motors, from one q0: one batched call against one call per
    target (no peer: Pinocchio has no inverse kinematics of a closed chain)."""
    from pathlib import Path

    robot = kd.load(str(Path(__file__).resolve().parents[1] / "examples" / "robots" / "five_bar.yaml"))
    t = np.linspace(0.0, 1.0, 200)
    q1, q2 = 0.2 + 1.5 * t, 1.0 + 1.2 * np.sin(3 * t)
    path = np.stack([q1, q2 - q1, q2, q1 - q2], axis=1)  # closed: the parallelogram branch
    targets = robot.frame_poses(path, ["tool"])[:, 0, :3, 3]
    batch = best(lambda: robot.inverse_kinematics(targets, path[0]), repeat)
    single = best(lambda: [robot.inverse_kinematics(x, path[0]) for x in targets], max(1, repeat // 3))
    solved = robot.inverse_kinematics(targets, path[0]).success.sum()
    print(
        f"closed-chain IK, 200 targets: batch {batch * 1e3:7.2f} ms   one by one {single * 1e3:7.1f} ms   "
        f"ratio {single / batch:5.1f}x   ({solved} solved)"
    )


if __name__ == "__main__":
    main()
