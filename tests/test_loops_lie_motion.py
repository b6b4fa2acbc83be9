"""kd.simulate on robots with loops and ball or floating joints (docs/closed-loops.md, "Motion"): the
Delta robot (ball-jointed rods) and the push-rod leg (a floating trunk). The configuration moves on
its group at every stage (Runge-Kutta-Munthe-Kaas, kinedyn.simulate.lie_steps), then is projected.
Checked: the loops stay closed, the quaternions unit, a frictionless passive mechanism keeps its
energy, the order is four, and the trajectory agrees with an independent route: Pinocchio's
constraintDynamics integrated by its own exponential (pin.integrate) and Jacobian (pin.dIntegrate),
without projection, at a quarter of the step."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.simulate.fixed_step import fixed_step_trajectory
from kinedyn.simulate.lie_steps import GroupStep

pin = pytest.importorskip("pinocchio")

from pinocchio_pairs import PinPair  # noqa: E402
from test_loops_parallel import MOTORS, ROBOTS, closed_state, delta, pinocchio_delta  # noqa: E402

T = 0.3  # s: the Delta's arms swing 1.1 rad; later (0.6 s from neutral) it reaches a singular configuration


def quaternion_norm_error(robot, q):
    """max | |quaternion| - 1 | over every ball and floating joint's block, every sample."""
    worst, at = 0.0, 0
    for joint in robot.joints:
        if joint.kind in ("spherical", "floating"):
            start = at + (3 if joint.kind == "floating" else 0)
            worst = max(worst, float(np.abs(np.linalg.norm(q[:, start : start + 4], axis=1) - 1).max()))
        at += joint.nq
    return worst


def pinocchio_rkmk4(model, acceleration, q, v, h, steps):
    """Classical RK4 on the chart q ⊕ Ω (Munthe-Kaas 1999; HLW IV.8.2), written from Pinocchio's own
    pieces: its exponential pin.integrate and dΩ/dt = Jr(Ω)^-1 v with Jr = pin.dIntegrate's ARG1
    Jacobian. No projection: the loops hold to the scheme's truncation error."""

    def rate(omega, w):
        return np.linalg.solve(pin.dIntegrate(model, q, omega, pin.ArgumentPosition.ARG1), w)

    for _ in range(steps):
        rates, accelerations = [v], [acceleration(q, v)]
        for c in (0.5 * h, 0.5 * h, h):
            w = v + c * accelerations[-1]
            accelerations.append(acceleration(pin.integrate(model, q, c * rates[-1]), w))
            rates.append(rate(c * rates[-1], w))
        mean = (rates[0] + 2 * rates[1] + 2 * rates[2] + rates[3]) / 6
        q = pin.integrate(model, q, h * mean)
        v = v + h / 6 * (accelerations[0] + 2 * accelerations[1] + 2 * accelerations[2] + accelerations[3])
    return q, v


def constrained(model, constraints):
    """Pinocchio's constraintDynamics under zero torque, as a function of (q, v)."""
    data = model.createData()
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    for constraint in constraints:
        models.append(constraint)
        datas.append(constraint.createData())
    pin.initConstraintDynamics(model, data, models, datas)
    settings, tau = pin.ProximalSettings(1e-14, 1e-10, 100), np.zeros(model.nv)
    return lambda q, v: pin.constraintDynamics(model, data, q, v, tau, models, datas, settings).copy()


# ----------------------------------------------------------------------------- the Delta robot
@pytest.fixture(scope="module")
def delta_robot():
    return delta()


@pytest.fixture(scope="module")
def delta_start(delta_robot):
    """A closed state near neutral with a velocity that keeps the loops closed (rod spins included)."""
    q, qd, _ = closed_state(delta_robot, MOTORS, 0)
    return np.concatenate([q, qd])


@pytest.fixture(scope="module")
def delta_swing(delta_robot, delta_start):
    """0.3 s of the passive Delta (no torque, no friction, gravity), RK4 at 1 ms."""
    return kd.simulate(delta_robot, T, delta_start, dt=1e-3)


def test_delta_stays_closed_with_unit_quaternions(delta_robot, delta_swing):
    # measured: max |residual| 9.1e-15 m (the projection's tolerance 1e-14), quaternion norms 1 to 2e-16
    residual = np.abs(delta_robot.loop_residual(delta_swing.q)).max()
    assert residual < 2e-14 and delta_swing.info["loop_residual_max"] == pytest.approx(residual)
    velocity = np.abs(np.einsum("smn,sn->sm", delta_robot.loop_jacobian(delta_swing.q), delta_swing.qd)).max()
    assert velocity < 1e-10
    assert quaternion_norm_error(delta_robot, delta_swing.q) < 1e-14
    assert np.ptp(delta_swing.q[:, 0]) > 1.0  # the first motor's arm swings over a radian: a real motion


def test_passive_delta_conserves_energy(delta_robot, delta_swing):
    K = np.array([delta_robot.kinetic_energy(q, qd) for q, qd in zip(delta_swing.q, delta_swing.qd)])
    P = np.array([delta_robot.potential_energy(q) for q in delta_swing.q])
    assert np.allclose(K + P, delta_swing.H, atol=1e-12)
    scale = K.max() + np.ptp(P)  # 4.25 J exchanged between K and P
    assert scale > 4.0
    # measured: max |H - H(0)| = 3.1e-6 J at dt = 1 ms (5.4e-5 at 2 ms, 1.8e-7 at 0.5 ms: fourth order)
    assert np.abs(delta_swing.H - delta_swing.H[0]).max() < 1e-5


def test_delta_agrees_with_pinocchio_integrated_independently(delta_robot, delta_start, delta_swing, tmp_path):
    """The reference: Pinocchio's dynamics, exponential and Jacobian (pinocchio_rkmk4) at 0.25 ms. kinedyn
    at 1 ms and 2 ms against it: the error falls by over 8 when the step halves (order 4: 16; a stage
    step without the chart's rate Jr^-1 is of order 2, 4)."""
    model, constraints = pinocchio_delta(tmp_path)
    n = delta_robot.nq
    q_ref, v_ref = pinocchio_rkmk4(
        model, constrained(model, constraints), delta_start[:n], delta_start[n:], 2.5e-4, 1200
    )
    assert np.abs(delta_robot.loop_residual(q_ref)).max() < 1e-9  # unprojected, still closed: a fine reference
    coarse = kd.simulate(delta_robot, T, delta_start, dt=2e-3)
    errors = []
    for run in (delta_swing, coarse):
        errors.append(np.abs(pin.difference(model, run.q[-1], q_ref)).max())
    # measured: 2.6e-7 rad at 1 ms, 3.2e-6 at 2 ms (ratio 12, short of the asymptotic 16); velocities
    # 6.4e-6 rad/s at 1 ms
    assert errors[0] < 5e-7, errors
    assert np.abs(delta_swing.qd[-1] - v_ref).max() < 2e-5
    assert errors[1] / errors[0] > 8, errors


def test_group_rk4_on_a_tree_matches_the_cores_native_rk4(delta_robot, delta_start):
    """The Python Munthe-Kaas step (exact Jr^-1) against the core's native RK4 (its series of Jr^-1)
    on the Delta's tree without its loops: the same method to fourth order. Measured: 1.4e-16 rad, 5.9e-15 rad/s."""
    tree = delta_robot.replace(loops=())
    n = tree.nq
    q0, qd0 = delta_start[:n], delta_start[n:]
    native = kd.simulate(tree, 0.05, delta_start, dt=1e-3, method="rk4")
    assert native.info["native"]
    zero = np.zeros(tree.n)
    Q, QD, *_ = fixed_step_trajectory(
        lambda t, q, qd, tau: tree.forward_dynamics(q, qd, tau),
        lambda k, t, q, qd: zero,
        "rk4", 0.0, 1e-3, 50, q0, qd0, 1, 1e6, False, None, group=GroupStep(tree),
    )  # fmt: skip
    assert np.abs(tree.difference(Q[-1], native.q[-1])).max() < 1e-12
    assert np.abs(QD[-1] - native.qd[-1]).max() < 1e-11


# ----------------------------------------------------------------------------- the push-rod leg
@pytest.fixture(scope="module")
def leg():
    return kd.load(ROBOTS / "pushrod_leg.urdf")


def pushrod_pinocchio(leg):
    """Pinocchio's model of the leg's URDF (floating joint: its free-flyer) and the loop built by hand
    (a kinedyn extension Pinocchio skips), as tests/test_loops_parallel.py builds it."""
    model = pin.buildModelFromXML((ROBOTS / "pushrod_leg.urdf").read_text())

    def point(link, xyz):
        frame = model.frames[model.getFrameId(link)]
        return frame.parentJoint, frame.placement * pin.SE3(np.eye(3), np.array(xyz, float))

    (joint_a, at_a), (joint_b, at_b) = point("push_rod", [0, 0, -0.3]), point("shank", [0.05, 0, 0])
    loop = pin.RigidConstraintModel(
        pin.ContactType.CONTACT_3D, model, joint_a, at_a, joint_b, at_b, pin.ReferenceFrame.LOCAL
    )
    return model, [loop]


def test_pushrod_leg_on_a_floating_trunk_moves_closed_and_agrees_with_pinocchio(leg):
    """The trunk tumbling in gravity, the leg swinging: closed, unit quaternion, energy kept, and the
    same motion as Pinocchio's (the trunk's pose and the joints). The leg's planar loop has a row that
    is redundant only on the manifold: without the stages projected (loops_runner) the core refuses
    the first RK4 stage as conflicting."""
    q0, qd0, _ = closed_state(leg, ["root", "hip", "knee"], 1, spread=0.6)
    traj = kd.simulate(leg, 0.2, np.concatenate([q0, qd0]), dt=2e-3)
    # measured: residual 1e-14 m (the projection's tolerance), quaternion norm 1 to 2e-16
    assert np.abs(leg.loop_residual(traj.q)).max() < 2e-14
    assert quaternion_norm_error(leg, traj.q) < 1e-14
    assert np.ptp(traj.q[:, 7]) > 0.15  # the hip swings (0.18 rad)
    # measured: max |H - H(0)| 1.9e-8 J at 2 ms of 36 J exchanged (4e-8 at 1 ms, 1.1e-7 at 0.5 ms: the
    # stage projections' floor, each closing to 1e-14 m)
    assert np.abs(traj.H - traj.H[0]).max() < 1e-7
    model, loops = pushrod_pinocchio(leg)
    pair = PinPair(leg, model)
    q_ref, v_ref = pinocchio_rkmk4(model, constrained(model, loops), pair.to_pin_q(q0), qd0[pair.perm], 2.5e-4, 800)
    # measured: 3.6e-10 (configuration, Pinocchio's tangent) and 4.0e-9 (velocity); 5.5e-10 and 6.4e-9 at
    # kinedyn's 1 ms: the unprojected reference's own error
    assert np.abs(pin.difference(model, q_ref, pair.to_pin_q(traj.q[-1]))).max() < 2e-9
    assert np.abs(traj.qd[-1][pair.perm] - v_ref).max() < 2e-8


@pytest.mark.parametrize("method", ["semi_implicit", "euler"])
def test_first_order_methods_step_on_the_group_too(leg, method):
    q0, qd0, _ = closed_state(leg, ["root", "hip", "knee"], 2, spread=0.6)
    traj = kd.simulate(leg, 0.05, np.concatenate([q0, qd0]), dt=1e-3, method=method)
    assert np.abs(leg.loop_residual(traj.q)).max() < 2e-14
    assert quaternion_norm_error(leg, traj.q) < 1e-14
    assert np.ptp(traj.q[:, 7]) > 0.01


@pytest.mark.parametrize("name", ["delta.xml", "pushrod_leg.urdf"])
def test_cli_simulates_the_robots_with_ball_and_floating_joints(name, capsys):
    from kinedyn.cli import main

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the Delta's MJCF softness, not modelled
        assert main(["simulate", str(ROBOTS / name), "--t", "0.2", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["method"] == "rk4" and payload["loop_residual_max"] < 2e-14
    # measured: 1.4e-11 (the Delta's arms falling from neutral), 3.6e-15 (the leg falling at rest)
    assert payload["energy_drift_relative"] < 1e-8
