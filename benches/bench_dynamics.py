"""Dynamics: kinedyn (Rust core from Python) vs Pinocchio's Python calls, on the UR5 and the Panda.

    OMP_WAIT_POLICY=PASSIVE python benches/bench_dynamics.py [--threads K] [--single]

``--single``: only the table of single calls (every public per-state method beside its Pinocchio
counterpart, with kinedyn time / Pinocchio time: issue 30's target is at most 0.7) and the per-call
overhead (the same calls on a one-joint robot, where the core's work is a few nanoseconds).

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
import time

parser = argparse.ArgumentParser()
parser.add_argument("--threads", type=int, default=1, help="rayon threads of kinedyn's batch calls")
parser.add_argument("--single", action="store_true", help="only the single-call table and the overhead")
args = parser.parse_args()
os.environ["RAYON_NUM_THREADS"] = str(args.threads)  # read once, when rayon's pool starts
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # see shared notes: OpenMP's spin-wait costs ms

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from common import fmt_us, load_pair, paired, without_friction  # noqa: E402

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


def single_calls(robot, model, label: str, rounds: int = 21) -> None:
    """Every public single-state method beside Pinocchio's Python call computing the same (checked
    first), printed as kinedyn ns, Pinocchio ns and their ratio (kinedyn / Pinocchio, lower is
    better; issue 30: at most 0.7). Pinocchio's forwardKinematics returns nothing and computes the
    joints' placements only: it is the issue's counterpart of ``pose`` and ``forward_kinematics``."""
    data = model.createData()
    n = robot.n
    rng = np.random.default_rng(1)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)
    tau = pin.rnea(model, data, q, qd, qdd)
    tool = model.getFrameId(robot.tool)
    world = pin.LOCAL_WORLD_ALIGNED
    checks = [
        (robot.mass_matrix_inverse(q), sym(pin.computeMinverse(model, data, q))),
        (robot.bias_torque(q, qd), pin.nonLinearEffects(model, data, q, qd)),
        (robot.kinetic_energy(q, qd), pin.computeKineticEnergy(model, data, q, qd)),
        (robot.potential_energy(q), pin.computePotentialEnergy(model, data, q)),
        (robot.center_of_mass(q), pin.centerOfMass(model, data, q)),
        (robot.centroidal_momentum_matrix(q), pin.computeCentroidalMap(model, data, q)),
        (robot.jacobian(q), pin.computeFrameJacobian(model, data, q, tool, world)),
        (robot.pose(q), (pin.framesForwardKinematics(model, data, q), data.oMf[tool].homogeneous)[1]),
    ]
    for mine, theirs in checks:
        # (Pinocchio returns a (6, 1) matrix as a vector)
        assert np.allclose(mine, np.reshape(theirs, np.shape(mine)), atol=1e-9), (mine, theirs)
    cases = [
        ("inverse_dynamics", lambda: robot.inverse_dynamics(q, qd, qdd), lambda: pin.rnea(model, data, q, qd, qdd)),
        ("mass_matrix", lambda: robot.mass_matrix(q), lambda: pin.crba(model, data, q)),
        ("mass_matrix_inverse", lambda: robot.mass_matrix_inverse(q), lambda: pin.computeMinverse(model, data, q)),
        ("forward_dynamics", lambda: robot.forward_dynamics(q, qd, tau), lambda: pin.aba(model, data, q, qd, tau)),
        ("gravity_torque", lambda: robot.gravity_torque(q), lambda: pin.computeGeneralizedGravity(model, data, q)),
        ("bias_torque", lambda: robot.bias_torque(q, qd), lambda: pin.nonLinearEffects(model, data, q, qd)),
        (
            "coriolis_matrix",
            lambda: robot.coriolis_matrix(q, qd),
            lambda: pin.computeCoriolisMatrix(model, data, q, qd),
        ),
        (
            "kinetic_energy",
            lambda: robot.kinetic_energy(q, qd),
            lambda: pin.computeKineticEnergy(model, data, q, qd),
        ),
        ("potential_energy", lambda: robot.potential_energy(q), lambda: pin.computePotentialEnergy(model, data, q)),
        ("center_of_mass", lambda: robot.center_of_mass(q), lambda: pin.centerOfMass(model, data, q)),
        (
            "centroidal_momentum_matrix",
            lambda: robot.centroidal_momentum_matrix(q),
            lambda: pin.computeCentroidalMap(model, data, q),
        ),
        ("pose (vs forwardKinematics)", lambda: robot.pose(q), lambda: pin.forwardKinematics(model, data, q)),
        (
            "pose (vs framesForwardKinematics)",
            lambda: robot.pose(q),
            lambda: pin.framesForwardKinematics(model, data, q),
        ),
        (
            "forward_kinematics (vs forwardKinematics)",
            lambda: robot.forward_kinematics(q),
            lambda: pin.forwardKinematics(model, data, q),
        ),
        (
            "jacobian (vs computeFrameJacobian)",
            lambda: robot.jacobian(q),
            lambda: pin.computeFrameJacobian(model, data, q, tool, world),
        ),
        (
            "inverse_dynamics_derivatives",
            lambda: robot.inverse_dynamics_derivatives(q, qd, qdd),
            lambda: pin.computeRNEADerivatives(model, data, q, qd, qdd),
        ),
        (
            "forward_dynamics_derivatives",
            lambda: robot.forward_dynamics_derivatives(q, qd, tau),
            lambda: pin.computeABADerivatives(model, data, q, qd, tau),
        ),
    ]
    print(f"\n{label}: single calls ({n} joints), fastest of {rounds} alternating rounds (CPU time)")
    print(f"{'':44s} {'kinedyn':>9s} {'pinocchio':>10s}   kd/pin")
    for name, kd_one, pin_one in cases:
        # CPU time of this process: on a shared machine a run is not charged for other jobs' slices
        a, b = paired(kd_one, pin_one, rounds=rounds, number=2000, timer=time.process_time)
        print(f"{name:44s} {a * 1e9:6.0f} ns {b * 1e9:7.0f} ns   {a / b:5.2f}")


ONE_JOINT = """<robot name="one"><link name="base"/>
  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="tool"/><joint name="t" type="fixed"><parent link="arm"/><child link="tool"/>
    <origin xyz="0.4 0 0"/></joint></robot>"""


def overhead(rounds: int = 21) -> None:
    """The per-call overhead: single calls on a one-joint robot (the core's work is a few ns)."""
    import kinedyn as kd

    robot = kd.Robot.from_urdf(ONE_JOINT, tool="tool")
    model = pin.buildModelFromXML(ONE_JOINT)
    single_calls(robot, model, "per-call overhead: a one-joint robot", rounds)


if __name__ == "__main__":
    print(f"pinocchio {pin.__version__}; kinedyn batch threads: {args.threads} (cores: {os.cpu_count()})")
    for robot_name in ("ur5", "panda"):
        if not args.single:
            bench(robot_name)
        robot, model = load_pair(robot_name)
        single_calls(without_friction(robot), model, robot_name)
    overhead()
