"""Shared helpers of the Python benchmarks: peer robots, random states, a median timer and a paired
(alternating, fastest-of-rounds) timer.

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
# floating-base robots (issue 14): loaded with a free-flyer root, in kinedyn as `floating_base=True`
# and in Pinocchio as `buildModelFromUrdf(path, JointModelFreeFlyer())`
FLOATING_URDFS = {
    "talos": "talos_data/robots/talos_full_v2.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "anymal": "anymal_b_simple_description/robots/anymal.urdf",
}
LOCKED = {"panda": ["panda_finger_joint1", "panda_finger_joint2"]}
# fixed-base arms of the generated-code comparison (issue 30): the two above and the KUKA iiwa
ARMS = ("ur5", "panda", "iiwa")


def iiwa_urdf() -> Path:
    """The KUKA LBR iiwa 14 URDF: example-robot-data has none; pybullet_data's (as tests/test_pinocchio.py)."""
    import pybullet_data

    return Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"


def load_arm(name: str):
    """kinedyn's robot of one of ``ARMS``, the Panda's finger joints locked."""
    import kinedyn as kd

    robot = kd.Robot.from_urdf(str(iiwa_urdf() if name == "iiwa" else erd_robots_dir() / PEER_URDFS[name]))
    if name in LOCKED:
        robot = robot.lock_joints({j: 0.0 for j in LOCKED[name]})
    return robot


def load_pair(name: str):
    """(kinedyn robot, pinocchio model) of the same URDF, finger joints locked for the Panda."""
    import numpy as np
    import pinocchio as pin

    path = erd_robots_dir() / PEER_URDFS[name]
    robot = load_arm(name)
    model = pin.buildModelFromUrdf(str(path))
    if name in LOCKED:
        ids = [model.getJointId(j) for j in LOCKED[name]]
        model = pin.buildReducedModel(model, ids, pin.neutral(model))
    assert model.nq == robot.n, (model.nq, robot.n)
    _ = np
    return robot, model


def without_friction(robot):
    """The robot with every joint's viscous and Coulomb friction set to zero: Pinocchio leaves URDF
    damping out of its algorithms, so both sides then compute the same equations."""
    links = []
    for link in robot.links:
        j = link.joint
        if j.is_moving:
            j = j.__class__(**{**j.__dict__, "viscous": 0.0, "coulomb": 0.0, "coulomb_negative": None})
        links.append(link.__class__(link.name, link.parent, j, link.placement, link.post, link.inertia))
    return robot.replace(links=links, dh=None)


def random_state(robot, rng):
    """A random ``(q, v, a)`` of ``robot``: a free-flyer's position in [-1, 1]^3 and a unit quaternion
    (x, y, z, w), 1-DOF joints uniform within their limits (else [-pi, pi]), v and a standard normal."""
    import numpy as np

    q = []
    for j in robot.joints:
        if j.kind == "floating":
            quat = rng.normal(size=4)
            q.extend([*rng.uniform(-1, 1, 3), *(quat / np.linalg.norm(quat))])
        elif j.kind == "spherical":
            quat = rng.normal(size=4)
            q.extend(quat / np.linalg.norm(quat))
        elif j.kind in ("revolute", "prismatic"):
            lo, hi = float(j.lower), float(j.upper)
            lo, hi = (lo, hi) if np.isfinite(lo) and np.isfinite(hi) and lo < hi else (-np.pi, np.pi)
            q.append(rng.uniform(lo, hi))
        else:
            raise ValueError(f"random_state: joint '{j.name}' of kind {j.kind} is not handled")
    return np.array(q), rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def paired(a, b, rounds: int = 15, number: int = 300, timer=time.perf_counter):
    """Seconds per call of ``a`` and ``b``, timed alternately; the fastest of ``rounds`` runs each
    (on a shared machine the minimum is the least disturbed estimate). ``timer=time.process_time``
    counts the process's CPU seconds instead of wall time: a run longer than the scheduler's time
    slice is then not charged for the time other jobs held the core."""
    a(), b()
    best = [float("inf"), float("inf")]
    for _ in range(rounds):
        for k, fn in enumerate((a, b)):
            t0 = timer()
            for _ in range(number):
                fn()
            best[k] = min(best[k], (timer() - t0) / number)
    return best


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
