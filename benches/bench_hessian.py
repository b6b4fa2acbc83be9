"""Kinematic Hessian dJ/dq: kinedyn (Rust core from Python) vs Pinocchio's Python calls.

    python benches/bench_hessian.py

The world-aligned Hessian of the last joint's frame, per call from Python and per state in a
10,000-state batch (one kinedyn call vs Pinocchio's Python loop of computeJointJacobians +
computeJointKinematicHessians + getJointKinematicHessian), on the UR5 and the Panda. Also times the
finite-difference route a user would otherwise take (2 n Jacobian calls). Prints times and the
ratios measured in this run (speed-up = other time / kinedyn time). Never run in CI.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from common import fmt_us, load_pair, median_time

BATCH = 10_000


def bench(name: str) -> None:
    robot, model = load_pair(name)
    data = model.createData()
    n, jid = robot.n, model.njoints - 1
    body = robot.tree.bodies[-1].name
    rng = np.random.default_rng(0)
    q = rng.uniform(-np.pi, np.pi, n)
    Q = rng.uniform(-np.pi, np.pi, (BATCH, n))

    def pin_hessian(qi):
        pin.computeJointJacobians(model, data, qi)
        pin.computeJointKinematicHessians(model, data, qi)
        return pin.getJointKinematicHessian(model, data, jid, pin.LOCAL_WORLD_ALIGNED)

    # same numbers first (pin 4.1's binding returns the column-major (6, n, n) buffer C-ordered)
    raw = np.asarray(pin_hessian(q)).reshape(-1)
    ours = np.transpose(robot.jacobian_hessian(q, body), (1, 2, 0))
    assert min(np.abs(raw.reshape((6, n, n), order=o) - ours).max() for o in "FC") < 1e-10

    def finite_differences():
        h = 1e-6
        return np.stack(
            [(robot.jacobian(q + h * e, body) - robot.jacobian(q - h * e, body)) / (2 * h) for e in np.eye(n)]
        )

    rows = []
    t_kd = median_time(lambda: robot.jacobian_hessian(q, body))
    rows.append(("hessian, per call (vs Pinocchio)", t_kd, median_time(lambda: pin_hessian(q))))
    rows.append(("hessian, per call (vs finite differences of J)", t_kd, median_time(finite_differences)))

    def pin_loop():
        for qi in Q:
            pin_hessian(qi)

    t_kd = median_time(lambda: robot.jacobian_hessian(Q, body), repeat=5, number=3) / BATCH
    rows.append(
        ("hessian, per state in a batch (vs Pinocchio loop)", t_kd, median_time(pin_loop, repeat=3, number=1) / BATCH)
    )

    print(f"\n{name} ({n} joints)")
    print(f"{'':52s} {'kinedyn':>12s} {'other':>12s}   speed-up")
    for label, a, b in rows:
        print(f"{label:52s} {fmt_us(a)} {fmt_us(b)}   {b / a:6.2f}x")


if __name__ == "__main__":
    import os

    print(f"pinocchio {pin.__version__}; threads for kinedyn batches: rayon default ({os.cpu_count()} cores)")
    for robot_name in ("ur5", "panda"):
        bench(robot_name)
