"""Floating bases (issue 14): kinedyn vs Pinocchio's Python on Talos (free-flyer, nv = 50) and the
Solo-12 and ANYmal quadrupeds (nv = 18), rnea, crba and aba.

    OMP_WAIT_POLICY=PASSIVE PYTHONPATH=python python benches/bench_floating.py [--robots talos solo12 anymal]

Both sides load the same example-robot-data URDF with a free-flyer root: kinedyn with
``Robot.from_urdf(path, floating_base=True)`` (URDF damping removed: Pinocchio leaves it out),
Pinocchio with ``buildModelFromUrdf(path, JointModelFreeFlyer())``; joints are matched by name (the
two parsers may order the branches differently). The results agree to 1e-9 first; then

* per call from Python (one state): ``robot.inverse_dynamics / mass_matrix / forward_dynamics`` vs
  ``pin.rnea / crba / aba``;
* per state of a 10,000-state batch on one thread (RAYON_NUM_THREADS=1): one kinedyn call vs
  Pinocchio's C++ loops ``rneaInParallel(1, ...)`` / ``abaInParallel(1, ...)`` (OMP_WAIT_POLICY=PASSIVE:
  OpenMP's spin-wait would cost milliseconds), and ``mass_matrix`` vs a Python loop of ``pin.crba``
  (Pinocchio has no batch CRBA). Batches are timed twice: wall time, and the process's CPU time
  (on a loaded machine a ~50 ms batch is descheduled, a 1 ms run of single calls rarely is).

The two sides of each ratio are timed alternately and each keeps its fastest round (benches/common.py
``paired``); speed-up = Pinocchio time / kinedyn time. Never run in CI.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

parser = argparse.ArgumentParser()
parser.add_argument("--robots", nargs="+", default=["talos", "solo12", "anymal"])
parser.add_argument("--batch", type=int, default=10_000)
parser.add_argument("--rounds", type=int, default=15, help="rounds of the per-call timings")
args = parser.parse_args()
os.environ["RAYON_NUM_THREADS"] = "1"  # read once, when rayon's pool starts: one thread, like for like
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from common import FLOATING_URDFS, erd_robots_dir, fmt_us, paired, random_state, without_friction  # noqa: E402

import kinedyn as kd  # noqa: E402


def load_floating(name: str):
    """(kinedyn robot, Pinocchio model, q index map, v index map): ``q_pin = q[q_map]``, ``v_pin = v[v_map]``."""
    path = str(erd_robots_dir() / FLOATING_URDFS[name])
    robot = without_friction(
        kd.Robot.from_urdf(path, floating_base=True, mimic="independent")
    )  # as Pinocchio builds it
    model = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    assert (model.nq, model.nv) == (robot.nq, robot.nv), (name, model.nq, model.nv, robot.nq, robot.nv)
    q_at = np.cumsum([0] + [j.nq for j in robot.joints])
    v_at = np.cumsum([0] + [j.nv for j in robot.joints])
    names = list(robot.joint_names)
    q_map, v_map = [], []
    for j in range(1, model.njoints):
        k = names.index(model.names[j])
        if (model.nqs[j], model.nvs[j]) != (robot.joints[k].nq, robot.joints[k].nv):
            raise SystemExit(
                f"{name}: joint '{model.names[j]}' has (nq, nv) = ({model.nqs[j]}, {model.nvs[j]}) in Pinocchio, "
                f"({robot.joints[k].nq}, {robot.joints[k].nv}) in kinedyn: no plain permutation"
            )
        if not robot.joints[k].is_multi_dof and float(robot.joints[k].offset) != 0.0:
            raise SystemExit(f"{name}: joint '{model.names[j]}' has an offset")
        q_map.extend(range(q_at[k], q_at[k + 1]))
        v_map.extend(range(v_at[k], v_at[k + 1]))
    return robot, model, np.array(q_map), np.array(v_map)


def sym(M):
    return np.triu(M) + np.triu(M, 1).T


def bench(name: str) -> None:
    robot, model, q_map, v_map = load_floating(name)
    data = model.createData()
    rng = np.random.default_rng(14)
    q, v, a = random_state(robot, rng)
    qp, vp, ap = q[q_map], v[v_map], a[v_map]
    tau = robot.inverse_dynamics(q, v, a)
    taup = tau[v_map]

    # the same numbers first, in kinedyn's order
    assert np.allclose(pin.rnea(model, data, qp, vp, ap), taup, rtol=0, atol=1e-9), "rnea differs"
    assert np.allclose(sym(pin.crba(model, data, qp)), robot.mass_matrix(q)[np.ix_(v_map, v_map)], rtol=0, atol=1e-9), (
        "crba differs"
    )
    assert np.allclose(
        pin.aba(model, data, qp, vp, taup), robot.forward_dynamics(q, v, tau)[v_map], rtol=0, atol=1e-9
    ), "aba differs"

    print(f"\n{name} (nq = {robot.nq}, nv = {robot.nv}, {len(robot.joints)} joints)")
    print(f"{'':46s} {'kinedyn':>12s} {'pinocchio':>12s}   speed-up")
    for label, kd_one, pin_one in [
        (
            "rnea (inverse_dynamics), per call",
            lambda: robot.inverse_dynamics(q, v, a),
            lambda: pin.rnea(model, data, qp, vp, ap),
        ),
        ("crba (mass_matrix), per call", lambda: robot.mass_matrix(q), lambda: pin.crba(model, data, qp)),
        (
            "aba (forward_dynamics), per call",
            lambda: robot.forward_dynamics(q, v, tau),
            lambda: pin.aba(model, data, qp, vp, taup),
        ),
    ]:
        t_kd, t_pin = paired(kd_one, pin_one, rounds=args.rounds)
        print(f"{label:46s} {fmt_us(t_kd)} {fmt_us(t_pin)}   {t_pin / t_kd:6.2f}x")

    N = args.batch
    states = [random_state(robot, rng) for _ in range(N)]
    Q, V, A = (np.array([s[k] for s in states]) for k in range(3))
    TAU = robot.inverse_dynamics(Q, V, A)
    # Pinocchio's batches are (nq, N) matrices: the transpose of a C-ordered (N, nq) array is free
    Qp, Vp, Ap, TAUp = Q[:, q_map].copy(), V[:, v_map].copy(), A[:, v_map].copy(), TAU[:, v_map].copy()
    pool = pin.ModelPool(model)
    out = np.zeros((robot.nv, N), order="F")
    pin.rneaInParallel(1, pool, Qp.T, Vp.T, Ap.T, out)
    assert np.allclose(out.T, TAUp, rtol=0, atol=1e-8), "rneaInParallel differs"
    pin.abaInParallel(1, pool, Qp.T, Vp.T, TAUp.T, out)
    assert np.allclose(out.T, robot.forward_dynamics(Q, V, TAU)[:, v_map], rtol=0, atol=1e-7), "abaInParallel differs"
    for label, kd_batch, pin_batch in [
        (
            "rnea, per state vs rneaInParallel(1)",
            lambda: robot.inverse_dynamics(Q, V, A),
            lambda: pin.rneaInParallel(1, pool, Qp.T, Vp.T, Ap.T, out),
        ),
        (
            "aba, per state vs abaInParallel(1)",
            lambda: robot.forward_dynamics(Q, V, TAU),
            lambda: pin.abaInParallel(1, pool, Qp.T, Vp.T, TAUp.T, out),
        ),
        (
            "crba, per state vs a Python loop of pin.crba",
            lambda: robot.mass_matrix(Q),
            lambda: [pin.crba(model, data, Qp[k]) for k in range(N)],
        ),
    ]:
        t_kd, t_pin = paired(kd_batch, pin_batch, rounds=9, number=1)
        print(f"{label:46s} {fmt_us(t_kd / N)} {fmt_us(t_pin / N)}   {t_pin / t_kd:6.2f}x")
        # a batch outlasts the time slice: on a loaded machine wall time also counts other jobs' turns
        t_kd, t_pin = paired(kd_batch, pin_batch, rounds=9, number=1, timer=time.process_time)
        print(f"{'  same, CPU time of the process':46s} {fmt_us(t_kd / N)} {fmt_us(t_pin / N)}   {t_pin / t_kd:6.2f}x")


if __name__ == "__main__":
    print(
        f"pinocchio {pin.__version__}; kinedyn batch threads: 1 (cores: {os.cpu_count()}; load average {os.getloadavg()[0]:.1f})"
    )
    for robot_name in args.robots:
        bench(robot_name)
