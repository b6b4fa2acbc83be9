"""eom.to_casadi(): CasADi Functions equal the Rust core, CasADi's own Jacobians equal kinedyn's
analytical derivatives, and a trajectory optimisation through them is reproduced by kinedyn's simulate
(issue 15 §2)."""

from __future__ import annotations

import numpy as np
import pytest
from reference import symbolic_backend_robots

import kinedyn as kd

ca = pytest.importorskip("casadi")

RNG = np.random.default_rng(15)
TOL = 1e-10


ROBOTS = symbolic_backend_robots()


@pytest.fixture(scope="module", params=list(ROBOTS))
def robot_and_functions(request):
    robot = ROBOTS[request.param]()
    return robot, robot.equations_of_motion(method="newton_euler", steps=False).to_casadi()


def _close(a, b, tol=TOL):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    np.testing.assert_allclose(a.reshape(b.shape), b, rtol=tol, atol=tol * max(1.0, float(np.abs(b).max())))


def test_functions_equal_the_core(robot_and_functions):
    robot, f = robot_and_functions
    assert f.parameters == []
    for _ in range(5):
        q, qd, qdd, tau = RNG.uniform(-2, 2, size=(4, robot.n))
        _close(f.M(q), robot.mass_matrix(q))
        _close(f.C(q, qd), robot.coriolis_matrix(q, qd))
        _close(f.g(q), robot.gravity_torque(q))
        _close(f.tau(q, qd, qdd), robot.inverse_dynamics(q, qd, qdd))
        _close(f.forward_dynamics(q, qd, tau), robot.forward_dynamics(q, qd, tau))
        _close(f.pose(q), robot.pose(q))
        _close(f.jacobian(q), robot.jacobian(q))


def test_named_inputs_and_outputs(robot_and_functions):
    _, f = robot_and_functions
    assert f.tau.name_in() == ["q", "qd", "qdd"] and f.tau.name_out() == ["tau"]
    assert f.forward_dynamics.name_in() == ["q", "qd", "tau"] and f.forward_dynamics.name_out() == ["qdd"]
    assert f.M.name_in() == ["q"] and f.C.name_in() == ["q", "qd"] and f.jacobian.name_out() == ["J"]
    assert f.tau.sparsity_in(0).is_dense() and f.tau.size1_out(0) == f.n


def test_casadi_jacobians_equal_the_analytical_derivatives(robot_and_functions):
    robot, f = robot_and_functions
    q, qd, qdd = (ca.SX.sym(s, robot.n) for s in ("q", "qd", "qdd"))
    tau = f.tau(q, qd, qdd)
    jac = ca.Function(
        "tau_derivatives", [q, qd, qdd], [ca.jacobian(tau, q), ca.jacobian(tau, qd), ca.jacobian(tau, qdd)]
    )
    for _ in range(3):
        x = RNG.uniform(-2, 2, size=(3, robot.n))
        dq, dqd, M = robot.inverse_dynamics_derivatives(*x)
        got = jac(*x)
        _close(got[0], dq)
        _close(got[1], dqd)
        _close(got[2], M)


def test_symbolic_parameters_form_p_in_eom_order():
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    values = dict(l1=1.3, l2=0.9, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13, g=9.81)
    f = eom.to_casadi(params={"g": 9.81})
    dynamic = [str(s) for s in eom.parameters if str(s) != "g"]
    assert "l2" not in dynamic  # the tool offset: only the pose and Jacobian see it, at the end of p
    assert [str(s) for s in f.parameters] == dynamic + ["l2"]
    assert f.tau.name_in() == ["q", "qd", "qdd", "p"]
    p = [values[str(s)] for s in f.parameters]
    robot = kd.robots.planar_2r(**values)
    q, qd, qdd = RNG.uniform(-2, 2, size=(3, 2))
    _close(f.tau(q, qd, qdd, p), robot.inverse_dynamics(q, qd, qdd))
    _close(f.pose(q, p), robot.pose(q))
    _close(f.jacobian(q, p), robot.jacobian(q))
    numeric = eom.compile(backend="numpy", params={"g": 9.81}, p=p[:-1])  # compile's p order, a prefix
    _close(f.tau(q, qd, qdd, p), numeric.tau(q, qd, qdd))


def test_common_subexpressions_are_shared():
    f = kd.robots.puma560().equations_of_motion(method="newton_euler", steps=False).to_casadi()
    eom = kd.robots.puma560().equations_of_motion(method="newton_euler", steps=False)
    expanded = sum(1 for e in eom.tau for _ in __import__("sympy").preorder_traversal(e))
    assert f.tau.n_instructions() < expanded / 4


def _swing_up(robot, N=30, T=2.0):
    """Minimum-effort swing-up of the tutorial's two-link arm from hanging (q1 = -pi/2) to upright,
    direct multiple shooting with one RK4 step per interval, IPOPT through casadi.Opti."""
    f = robot.equations_of_motion(steps=False).to_casadi()
    h = T / N
    x, u = ca.SX.sym("x", 4), ca.SX.sym("u", 2)

    def ode(x, u):
        return ca.vertcat(x[2:], f.forward_dynamics(x[:2], x[2:], u))

    k1 = ode(x, u)
    k2 = ode(x + h / 2 * k1, u)
    k3 = ode(x + h / 2 * k2, u)
    k4 = ode(x + h * k3, u)
    step = ca.Function("step", [x, u], [x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])
    opti = ca.Opti()
    X, U = opti.variable(4, N + 1), opti.variable(2, N)
    x0, x1 = np.array([-np.pi / 2, 0, 0, 0]), np.array([np.pi / 2, 0, 0, 0])
    opti.subject_to(X[:, 0] == x0)
    opti.subject_to(X[:, N] == x1)
    for k in range(N):
        opti.subject_to(X[:, k + 1] == step(X[:, k], U[:, k]))
    opti.subject_to(opti.bounded(-60, ca.vec(U), 60))
    opti.minimize(h * ca.sumsqr(U))
    for k in range(N + 1):
        opti.set_initial(X[:, k], x0 + (x1 - x0) * k / N)
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes"})
    sol = opti.solve()
    return sol, np.asarray(sol.value(X)).T, np.asarray(sol.value(U)).T, x0, x1, h, T


def test_trajectory_optimisation_is_reproduced_by_simulate():
    robot = kd.robots.planar_2r()
    sol, X, U, x0, x1, h, T = _swing_up(robot)
    assert sol.stats()["success"]
    assert np.abs(U).max() > 1.0  # it does work against gravity
    # 1. kinedyn's RK4 with the same step and the torques held over each step: the same scheme, so the
    # same trajectory up to rounding
    same = kd.simulate(robot, T, x0, u=U, method="rk4", dt=h)
    np.testing.assert_allclose(np.hstack([same.q, same.qd]), X, atol=1e-9)

    # 2. an accurate adaptive integration (DOP853, 1e-11) differs by the optimiser's RK4 discretisation
    # error; estimated by Richardson extrapolation (RK4 is 4th order: err(h) ~ 16/15 |x_h - x_h/2|),
    # integrating the same torques with two RK4 half steps per interval
    def rk4(x, u, dt):
        fx = lambda x: np.concatenate([x[2:], robot.forward_dynamics(x[:2], x[2:], u)])
        a = fx(x)
        b = fx(x + dt / 2 * a)
        c = fx(x + dt / 2 * b)
        d = fx(x + dt * c)
        return x + dt / 6 * (a + 2 * b + 2 * c + d)

    half = [x0]
    for u in U:
        half.append(rk4(rk4(half[-1], u, h / 2), u, h / 2))
    estimate = 16 / 15 * np.abs(np.array(half) - X).max()
    assert estimate < 0.05  # the grid is fine enough for the comparison to mean something
    exact = kd.simulate(robot, T, x0, u=U, method="dop853", dt=h, rtol=1e-11, atol=1e-11)
    deviation = np.abs(np.hstack([exact.q, exact.qd]) - X).max()
    assert deviation < 1.5 * estimate
    assert np.abs(np.concatenate([exact.q[-1], exact.qd[-1]]) - x1).max() < 1.5 * estimate  # it swings up


def test_lagrangian_system_without_a_robot():
    from kinedyn.symbolic import examples

    eom = examples.remotely_driven_arm().equations_of_motion()
    f = eom.to_casadi()
    assert "pose" not in f.functions and f.tau.name_in() == ["q", "qd", "qdd", "p"]
    p = RNG.uniform(0.5, 2.0, size=len(f.parameters))
    numeric = eom.compile(backend="numpy", p=p)
    q, qd, qdd, tau = RNG.uniform(-2, 2, size=(4, 2))
    _close(f.tau(q, qd, qdd, p), numeric.tau(q, qd, qdd))
    expected = np.linalg.solve(numeric.M(q), tau - numeric.tau(q, qd, np.zeros(2)))
    _close(f.forward_dynamics(q, qd, tau, p), expected)
