"""Analytical derivatives of inverse and forward dynamics (issue 3, stretch goal): against central
finite differences of the dynamics themselves on every built-in robot, URDF robots and a branching
tree (with drives and external wrenches), batches, and Pinocchio's derivatives as an oracle."""

from __future__ import annotations

import numpy as np
import pytest
from test_dynamics import ROBOTS

import kinedyn as kd
from kinedyn.description.joint import Joint
from kinedyn.description.link import Link

pytest.importorskip("kinedyn._core", reason="the native module is not built")

H = 1e-6  # central-difference step
TOL = 2e-6  # relative to the size of the derivative (central differences: O(h^2) + rounding/h)


@pytest.fixture(params=list(ROBOTS), scope="module")
def robot(request):
    return ROBOTS[request.param]()


def jacobian_fd(f, x):
    """Columns d f / d x_j by central differences."""
    return np.stack([(f(x + H * e) - f(x - H * e)) / (2 * H) for e in np.eye(len(x))], axis=-1)


def close(got, want, what):
    scale = max(1.0, np.abs(want).max())
    err = np.abs(got - want).max()
    assert err <= TOL * scale, f"{what}: max |diff| {err:.3g} (scale {scale:.3g})"


def state(robot, seed):
    rng = np.random.default_rng(seed)
    q = robot.random_configuration(rng)
    # velocities away from zero: Coulomb friction's sign(qd) is smooth only there
    qd = rng.choice([-1, 1], robot.n) * rng.uniform(0.3, 2, robot.n)
    return q, qd, rng.uniform(-3, 3, robot.n), rng.uniform(-5, 5, (robot.n, 6))


@pytest.mark.parametrize("with_wrenches", [False, True])
def test_inverse_dynamics_derivatives_match_finite_differences(robot, with_wrenches):
    q, qd, qdd, f = state(robot, 1)
    f = f if with_wrenches else None
    dq, dqd, M = robot.inverse_dynamics_derivatives(q, qd, qdd, f)
    close(dq, jacobian_fd(lambda x: robot.inverse_dynamics(x, qd, qdd, f), q), "dtau/dq")
    close(dqd, jacobian_fd(lambda x: robot.inverse_dynamics(q, x, qdd, f), qd), "dtau/dqd")
    close(M, jacobian_fd(lambda x: robot.inverse_dynamics(q, qd, x, f), qdd), "dtau/dqdd")
    # M from the derivative pass (world-coordinate CRBA, or the CRBA itself with wrenches) == the CRBA
    np.testing.assert_allclose(M, robot.mass_matrix(q), rtol=0, atol=1e-12 * np.abs(M).max())
    assert np.array_equal(M, M.T)


@pytest.mark.parametrize("with_wrenches", [False, True])
def test_forward_dynamics_derivatives_match_finite_differences(robot, with_wrenches):
    q, qd, qdd, f = state(robot, 2)
    f = f if with_wrenches else None
    tau = robot.inverse_dynamics(q, qd, qdd, f)
    dq, dqd, dtau = robot.forward_dynamics_derivatives(q, qd, tau, f)
    close(dq, jacobian_fd(lambda x: robot.forward_dynamics(x, qd, tau, f), q), "dqdd/dq")
    close(dqd, jacobian_fd(lambda x: robot.forward_dynamics(q, x, tau, f), qd), "dqdd/dqd")
    close(dtau, jacobian_fd(lambda x: robot.forward_dynamics(q, qd, x, f), tau), "dqdd/dtau")
    close(dtau @ robot.mass_matrix(q), np.eye(robot.n), "M^-1 M")
    # the two sets are tied by the implicit function theorem: dqdd/dx = -M^-1 dtau/dx at the same state
    idq, idqd, _ = robot.inverse_dynamics_derivatives(q, qd, robot.forward_dynamics(q, qd, tau, f), f)
    close(dq, -dtau @ idq, "dqdd/dq = -M^-1 dtau/dq")
    close(dqd, -dtau @ idqd, "dqdd/dqd = -M^-1 dtau/dqd")


def test_batch_equals_loop():
    robot = ROBOTS["puma560+drives"]()
    rng = np.random.default_rng(5)
    N = 4
    Q, V, A = rng.uniform(-2, 2, (3, N, robot.n))
    F = rng.uniform(-3, 3, (N, robot.n, 6))
    for method in (robot.inverse_dynamics_derivatives, robot.forward_dynamics_derivatives):
        for f in (None, F):
            batch = method(Q, V, A, f)
            assert all(b.shape == (N, robot.n, robot.n) for b in batch)
            for k in range(N):
                one = method(Q[k], V[k], A[k], None if f is None else f[k])
                for b, o in zip(batch, one):
                    np.testing.assert_allclose(b[k], o, rtol=1e-12, atol=1e-12)


def test_bad_input_is_a_clear_error():
    robot = ROBOTS["planar_2r"]()
    with pytest.raises(ValueError, match=r"qd must have shape \(2,\)"):
        robot.inverse_dynamics_derivatives([0, 0], [0, 0, 0], [0, 0])
    with pytest.raises(ValueError, match="non-finite"):
        robot.forward_dynamics_derivatives([0, np.nan], [0, 0], [0, 0])
    links = [Link("a", None, Joint("shoulder")), Link("b", "a", Joint("elbow", axis=(0, 1, 0)), np.eye(4))]
    with pytest.raises(RuntimeError, match=r"singular mass matrix.*'elbow'"):
        kd.Robot(links, name="massless").forward_dynamics_derivatives(np.zeros(2), np.zeros(2), np.ones(2))


def test_same_derivatives_as_pinocchio():
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is an optional test oracle")
    from test_pinocchio import CASES  # the same URDFs as the other oracle tests

    for name in ("ur5", "panda", "iiwa"):
        where, locked = CASES[name]
        path = where()
        robot = kd.Robot.from_urdf(path)
        model = pin.buildModelFromUrdf(path)
        if locked:
            robot = robot.lock_joints(locked)
            q_ref = pin.neutral(model)
            for joint, value in locked.items():
                q_ref[model.joints[model.getJointId(joint)].idx_q] = value
            model = pin.buildReducedModel(model, [model.getJointId(j) for j in locked], q_ref)
        # Pinocchio leaves URDF friction out of its algorithms: compare the rigid-body equations
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
        rng = np.random.default_rng(3)
        for _ in range(3):
            q, qd, qdd = robot.random_configuration(rng), rng.uniform(-2, 2, robot.n), rng.uniform(-3, 3, robot.n)
            dq, dqd, M = robot.inverse_dynamics_derivatives(q, qd, qdd)
            pq, pqd, pM = pin.computeRNEADerivatives(model, data, q, qd, qdd)
            pM = np.triu(pM) + np.triu(pM, 1).T
            for got, want, what in ((dq, pq, "dtau/dq"), (dqd, pqd, "dtau/dqd"), (M, pM, "M")):
                assert np.abs(got - want).max() <= 1e-9 * max(1.0, np.abs(want).max()), f"{name} {what}"
            tau = robot.inverse_dynamics(q, qd, qdd)
            aq, aqd, atau = robot.forward_dynamics_derivatives(q, qd, tau)
            bq, bqd, btau = pin.computeABADerivatives(model, data, q, qd, tau)
            btau = np.triu(btau) + np.triu(btau, 1).T
            for got, want, what in ((aq, bq, "dqdd/dq"), (aqd, bqd, "dqdd/dqd"), (atau, btau, "dqdd/dtau")):
                assert np.abs(got - want).max() <= 1e-9 * max(1.0, np.abs(want).max()), f"{name} {what}"


def test_linearize_matches_finite_differences_and_stabilises_an_upright_arm():
    """kinedyn.dynamics.linearize: A, B against central differences of the nonlinear state equation;
    at the tutorial arm's upright equilibrium (unstable: A has an eigenvalue with positive real part)
    an LQR gain from (A, B) makes the closed loop stable, and in simulation holds the arm up."""
    from scipy.linalg import solve_continuous_are

    import kinedyn as kd
    from kinedyn.dynamics import linearize

    robot = ROBOTS["puma560+drives"]()
    rng = np.random.default_rng(2)
    q, qd, tau = robot.random_configuration(rng), rng.uniform(-1, 1, robot.n), rng.uniform(-5, 5, robot.n)
    n = robot.n
    A, B = linearize(robot, q, qd, tau)
    f = lambda x, u: np.r_[x[n:], robot.forward_dynamics(x[:n], x[n:], u)]  # noqa: E731
    x0 = np.r_[q, qd]
    close(A, jacobian_fd(lambda x: f(x, tau), x0), "A")
    close(B, jacobian_fd(lambda u: f(x0, u), tau), "B")
    # a batch gives the stacked matrices
    Ab, Bb = linearize(robot, np.stack([q, q]), np.stack([qd, qd]), np.stack([tau, tau]))
    np.testing.assert_allclose(Ab[1], A, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(Bb[0], B, rtol=1e-12, atol=1e-12)

    arm = kd.robots.planar_2r()
    up = np.array([np.pi / 2, 0.0])  # both links vertical, against gravity
    A, B = linearize(arm, up)
    assert np.linalg.eigvals(A).real.max() > 0.1  # it falls
    P = solve_continuous_are(A, B, np.eye(4), np.eye(2))
    K = B.T @ P
    assert np.linalg.eigvals(A - B @ K).real.max() < 0
    tau0 = arm.gravity_torque(up)
    x = np.r_[up + [0.05, -0.05], 0.0, 0.0]
    for _ in range(3000):  # 3 s of u = tau0 - K dx, semi-implicit Euler at 1 ms
        u = tau0 - K @ (x - np.r_[up, 0.0, 0.0])
        qdd = arm.forward_dynamics(x[:2], x[2:], u)
        x[2:] += 1e-3 * qdd
        x[:2] += 1e-3 * x[2:]
    assert np.abs(x[:2] - up).max() < 1e-3
