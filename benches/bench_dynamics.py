"""Dynamics: kinedyn (Rust core from Python) vs Pinocchio's Python calls, on the UR5 and the Panda.

    OMP_WAIT_POLICY=PASSIVE python benches/bench_dynamics.py [--threads K]

Per call from Python (one state), and per state in a 10,000-state batch: one kinedyn call (rayon,
``--threads`` workers, default 1 for a like-for-like comparison) vs Pinocchio's Python loop, and for
inverse dynamics vs Pinocchio's own batch ``rneaInParallel`` on one thread. Prints medians and the
ratios measured in this run (speed-up = Pinocchio time / kinedyn time). The two sides of each
ratio are timed alternately, many times, and the fastest run of each is kept: on a shared machine
the minimum is the least disturbed estimate. Never run in CI.
"""

from __future__ import annotations

import argparse
import os
import sys

parser = argparse.ArgumentParser()
parser.add_argument("--threads", type=int, default=1, help="rayon threads of kinedyn's batch calls")
args = parser.parse_args()
os.environ["RAYON_NUM_THREADS"] = str(args.threads)  # read once, when rayon's pool starts
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # see shared notes: OpenMP's spin-wait costs ms

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from common import fmt_us, load_pair, paired  # noqa: E402

BATCH = 10_000


def sym(M):
    return np.triu(M) + np.triu(M, 1).T


def bench(name: str) -> None:
    robot, model = load_pair(name)
    # Pinocchio leaves URDF damping out of its algorithms: compare the same equations
    robot = robot.replace(
        links=[
            l
            if not l.joint.is_moving
            else l.__class__(
                l.name,
                l.parent,
                l.joint.__class__(**{**l.joint.__dict__, "viscous": 0.0, "coulomb": 0.0}),
                l.placement,
                l.post,
                l.inertia,
            )
            for l in robot.links
        ],
        dh=None,
    )
    data = model.createData()
    n = robot.n
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)
    Q, V, A = rng.uniform(-np.pi, np.pi, (BATCH, n)), rng.uniform(-2, 2, (BATCH, n)), rng.uniform(-2, 2, (BATCH, n))
    tau = pin.rnea(model, data, q, qd, qdd)

    # the same numbers first
    assert np.allclose(robot.inverse_dynamics(q, qd, qdd), tau, atol=1e-9)
    assert np.allclose(robot.mass_matrix(q), sym(pin.crba(model, data, q)), atol=1e-9)
    assert np.allclose(robot.forward_dynamics(q, qd, tau), pin.aba(model, data, q, qd, tau), atol=1e-9)
    assert np.allclose(robot.coriolis_matrix(q, qd), pin.computeCoriolisMatrix(model, data, q, qd), atol=1e-9)
    assert np.allclose(robot.gravity_torque(q), pin.computeGeneralizedGravity(model, data, q), atol=1e-9)
    assert np.allclose(
        robot.inverse_dynamics_derivatives(q, qd, qdd)[0],
        pin.computeRNEADerivatives(model, data, q, qd, qdd)[0],
        atol=1e-8,
    )
    assert np.allclose(
        robot.forward_dynamics_derivatives(q, qd, tau)[0],
        pin.computeABADerivatives(model, data, q, qd, tau)[0],
        atol=1e-8,
    )

    cases = [
        (
            "inverse_dynamics",
            lambda: robot.inverse_dynamics(q, qd, qdd),
            lambda: pin.rnea(model, data, q, qd, qdd),
            lambda: robot.inverse_dynamics(Q, V, A),
            lambda: [pin.rnea(model, data, Q[k], V[k], A[k]) for k in range(BATCH)],
        ),
        (
            "mass_matrix",
            lambda: robot.mass_matrix(q),
            lambda: pin.crba(model, data, q),
            lambda: robot.mass_matrix(Q),
            lambda: [pin.crba(model, data, Q[k]) for k in range(BATCH)],
        ),
        (
            "forward_dynamics",
            lambda: robot.forward_dynamics(q, qd, tau),
            lambda: pin.aba(model, data, q, qd, tau),
            lambda: robot.forward_dynamics(Q, V, A),
            lambda: [pin.aba(model, data, Q[k], V[k], A[k]) for k in range(BATCH)],
        ),
        (
            "coriolis_matrix",
            lambda: robot.coriolis_matrix(q, qd),
            lambda: pin.computeCoriolisMatrix(model, data, q, qd),
            lambda: robot.coriolis_matrix(Q, V),
            lambda: [pin.computeCoriolisMatrix(model, data, Q[k], V[k]) for k in range(BATCH)],
        ),
        (
            "gravity_torque",
            lambda: robot.gravity_torque(q),
            lambda: pin.computeGeneralizedGravity(model, data, q),
            lambda: robot.gravity_torque(Q),
            lambda: [pin.computeGeneralizedGravity(model, data, Q[k]) for k in range(BATCH)],
        ),
        (
            "inverse_dynamics_derivatives",
            lambda: robot.inverse_dynamics_derivatives(q, qd, qdd),
            lambda: pin.computeRNEADerivatives(model, data, q, qd, qdd),
            lambda: robot.inverse_dynamics_derivatives(Q, V, A),
            lambda: [pin.computeRNEADerivatives(model, data, Q[k], V[k], A[k]) for k in range(BATCH)],
        ),
        (
            "forward_dynamics_derivatives",
            lambda: robot.forward_dynamics_derivatives(q, qd, tau),
            lambda: pin.computeABADerivatives(model, data, q, qd, tau),
            lambda: robot.forward_dynamics_derivatives(Q, V, A),
            lambda: [pin.computeABADerivatives(model, data, Q[k], V[k], A[k]) for k in range(BATCH)],
        ),
    ]
    print(f"\n{name} ({n} joints)")
    print(f"{'':46s} {'kinedyn':>12s} {'pinocchio':>12s}   speed-up")
    for label, kd_one, pin_one, kd_batch, pin_loop in cases:
        a, b = paired(kd_one, pin_one)
        print(f"{label + ', per call':46s} {fmt_us(a)} {fmt_us(b)}   {b / a:6.2f}x")
        a, b = paired(kd_batch, pin_loop, rounds=15, number=1)
        a, b = a / BATCH, b / BATCH
        print(f"{label + ', per state, 10k batch vs loop':46s} {fmt_us(a)} {fmt_us(b)}   {b / a:6.2f}x")
    # control-loop use: kinedyn writing into a preallocated array (out=), Pinocchio as above
    M_out, tau_out = np.empty((n, n)), np.empty(n)
    for label, kd_one, pin_one in [
        (
            "inverse_dynamics, per call with out=",
            lambda: robot.inverse_dynamics(q, qd, qdd, out=tau_out),
            lambda: pin.rnea(model, data, q, qd, qdd),
        ),
        ("mass_matrix, per call with out=", lambda: robot.mass_matrix(q, out=M_out), lambda: pin.crba(model, data, q)),
    ]:
        a, b = paired(kd_one, pin_one)
        print(f"{label:46s} {fmt_us(a)} {fmt_us(b)}   {b / a:6.2f}x")
    # Pinocchio's own batch: (nq, N) matrices; the transpose of a C-ordered (N, nq) array is free
    pool = pin.ModelPool(model)
    out = np.zeros((n, BATCH), order="F")
    pin.rneaInParallel(1, pool, Q.T, V.T, A.T, out)
    assert np.allclose(out.T, robot.inverse_dynamics(Q, V, A), atol=1e-9)
    a, b = paired(
        lambda: robot.inverse_dynamics(Q, V, A),
        lambda: pin.rneaInParallel(1, pool, Q.T, V.T, A.T, out),
        rounds=9,
        number=1,
    )
    a, b = a / BATCH, b / BATCH
    print(f"{'inverse_dynamics, per state vs rneaInParallel(1)':46s} {fmt_us(a)} {fmt_us(b)}   {b / a:6.2f}x")


if __name__ == "__main__":
    print(f"pinocchio {pin.__version__}; kinedyn batch threads: {args.threads} (cores: {os.cpu_count()})")
    for robot_name in ("ur5", "panda"):
        bench(robot_name)
