"""Forward kinematics and Jacobians: kinedyn (Rust core from Python) vs Pinocchio's Python calls.

    python benches/bench_kinematics.py

Per call from Python, and per state in a 10,000-state batch (one kinedyn call vs Pinocchio's
Python loop), on the UR5 and the Panda (7 DOF). Prints times and ratios measured in this run.
Pinocchio's `forwardKinematics` fills its Data and returns nothing, while kinedyn returns every
link pose as an array: the "returning the poses" row times Pinocchio doing the same.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from common import fmt_us, load_pair, median_time

BATCH = 10_000


def bench(name: str) -> None:
    robot, model = load_pair(name)
    data = model.createData()
    tool = robot.tool
    fid = model.getFrameId(tool)
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, robot.n)
    Q = rng.uniform(-np.pi, np.pi, (BATCH, robot.n))
    # same numbers first: the tool pose and its Jacobian
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    assert np.allclose(data.oMf[fid].homogeneous, robot.pose(q, tool), atol=1e-10)
    Jp = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
    assert np.allclose(Jp, robot.jacobian(q, tool), atol=1e-10)

    rows = []
    t_kd = median_time(lambda: robot.forward_kinematics(q))
    t_pin = median_time(lambda: pin.forwardKinematics(model, data, q))
    rows.append(("forward_kinematics, per call", t_kd, t_pin))
    # the same output as kinedyn's: every moving link's pose as one (n, 4, 4) array
    link_frames = [model.getFrameId(name) for name in robot.body_names]

    def pin_fk_poses():
        pin.framesForwardKinematics(model, data, q)
        return np.array([data.oMf[f].homogeneous for f in link_frames])

    assert np.allclose(pin_fk_poses(), robot.forward_kinematics(q), atol=1e-10)
    rows.append(("forward_kinematics returning the poses, per call", t_kd, median_time(pin_fk_poses)))
    t_kd = median_time(lambda: robot.jacobian(q, tool))
    t_pin = median_time(lambda: pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED))
    rows.append(("tool jacobian, per call", t_kd, t_pin))

    def pin_fk_loop():
        for qi in Q:
            pin.forwardKinematics(model, data, qi)

    def pin_jac_loop():
        for qi in Q:
            pin.computeFrameJacobian(model, data, qi, fid, pin.LOCAL_WORLD_ALIGNED)

    t_kd = median_time(lambda: robot.forward_kinematics(Q), repeat=5, number=3) / BATCH
    t_pin = median_time(pin_fk_loop, repeat=3, number=1) / BATCH
    rows.append(("forward_kinematics, per state in a batch", t_kd, t_pin))
    t_kd = median_time(lambda: robot.jacobian(Q, tool), repeat=5, number=3) / BATCH
    t_pin = median_time(pin_jac_loop, repeat=3, number=1) / BATCH
    rows.append(("tool jacobian, per state in a batch", t_kd, t_pin))

    print(f"\n{name} ({robot.n} joints)")
    print(f"{'':50s} {'kinedyn':>12s} {'pinocchio':>12s}   speed-up")
    for label, a, b in rows:
        print(f"{label:50s} {fmt_us(a)} {fmt_us(b)}   {b / a:6.2f}x")


if __name__ == "__main__":
    import os

    print(f"pinocchio {pin.__version__}; threads for kinedyn batches: rayon default ({os.cpu_count()} cores)")
    for robot_name in ("ur5", "panda"):
        bench(robot_name)
