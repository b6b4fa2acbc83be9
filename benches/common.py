"""Shared helpers of the Python benchmarks: peer robots and a median timer.

Benchmarks print ratios measured in the same run; they are never run in CI (see shared notes on
how the peers were installed and measured on this kind of machine)."""

from __future__ import annotations

import statistics
import time
from pathlib import Path


def erd_robots_dir() -> Path:
    from kinedyn.testing import example_robot_data_dir

    folder = example_robot_data_dir()
    if folder is None:
        raise FileNotFoundError("example-robot-data's robots folder was not found")
    return Path(folder)


PEER_URDFS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
}
LOCKED = {"panda": ["panda_finger_joint1", "panda_finger_joint2"]}


def load_pair(name: str):
    """(kinedyn robot, pinocchio model) of the same URDF, finger joints locked for the Panda."""
    import numpy as np
    import pinocchio as pin

    import kinedyn as kd

    path = erd_robots_dir() / PEER_URDFS[name]
    robot = kd.Robot.from_urdf(str(path))
    model = pin.buildModelFromUrdf(str(path))
    if name in LOCKED:
        robot = robot.lock_joints({j: 0.0 for j in LOCKED[name]})
        ids = [model.getJointId(j) for j in LOCKED[name]]
        model = pin.buildReducedModel(model, ids, pin.neutral(model))
    assert model.nq == robot.n, (model.nq, robot.n)
    _ = np
    return robot, model


def median_time(fn, repeat: int = 7, number: int = 1000) -> float:
    """Median over `repeat` runs of the time per call of `fn` (seconds), each run `number` calls."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t0) / number)
    return statistics.median(times)


def fmt_us(seconds: float) -> str:
    return f"{seconds * 1e6:9.3f} us"
