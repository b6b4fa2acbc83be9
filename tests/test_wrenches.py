"""External wrenches about link-frame origins, taken natively by the core (``Model.with_link_origins``).

Three oracles: the route kinedyn used before the core took link origins (the core's body-origin
wrenches, the moments moved and the derivatives corrected in NumPy, kept below as ``OldRoute``);
Pinocchio (its ``f_ext`` is one force per joint, expressed in the joint's frame, about its origin);
and central differences of the analytic derivatives on a floating base (``q ⊕ dq``)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import kinedyn as kd
from kinedyn._math import homogeneous
from kinedyn.testing import random_robot

pytest.importorskip("kinedyn._core", reason="the native module is not built")


def with_link_offsets(robot, seed):
    """``robot`` with each link frame moved off its joint frame (a ``post`` transform, as standard
    DH's ``Tx(a)``), so that the moments of f_ext are taken about points off the body origins."""
    rng = np.random.default_rng(seed)
    links = []
    for link in robot.links:
        axis = rng.normal(size=3)
        angle = rng.uniform(-1, 1)
        K = np.cross(np.eye(3), axis / np.linalg.norm(axis))
        R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
        links.append(dataclasses.replace(link, post=homogeneous(R, rng.uniform(-0.4, 0.4, 3))))
    return kd.Robot(links, list(robot.frames), gravity=robot.gravity, name=robot.name)


class OldRoute:
    """The former Python half of the seam (kinedyn.native.wrenches, until the core took link origins),
    as an oracle: the core with wrenches about the body origins, the moments moved there by
    ``n_body = n_link + R_body t_bl x f`` and ``dtau/dq`` corrected by ``-sum_i Jw_i^T ((w_j x d_i) x f_i)``."""

    def __init__(self, robot):
        assert not robot.has_multi_dof_joints  # the old route's layout for these is not repeated here
        self.robot = robot
        self.model = robot._model.with_link_origins(np.zeros((robot.n, 3)))
        # R_bl^T t_bl: the link origin from the body origin, in the link's axes
        placements = [np.asarray(robot.tree.frames[robot.frame_index(b)].placement, float) for b in robot.body_names]
        self.u = np.array([T[:3, :3].T @ T[:3, 3] for T in placements])

    def body_wrenches(self, q, f):
        R = self.robot.forward_kinematics(q)[..., :3, :3]
        d = np.einsum("...ij,...j->...i", R, self.u)
        f = np.array(f, dtype=float)
        f[..., 3:] += np.cross(d, f[..., :3])
        return f

    def shift(self, q, f):
        r = self.robot
        R = r.forward_kinematics(q)[..., :3, :3]
        d = np.einsum("...bij,bj->...bi", R, self.u)
        Jw = np.stack([r.jacobian(q, frame=name)[..., 3:, :] for name in r.body_names], axis=-3)
        dd = np.cross(np.swapaxes(Jw, -1, -2), d[..., :, None, :])
        dm = np.cross(dd, f[..., :, None, :3])
        return -np.einsum("...bkr,...bjk->...rj", Jw, dm)

    def inverse_dynamics(self, q, qd, qdd, f):
        return self.model.inverse_dynamics(q, qd, qdd, self.body_wrenches(q, f))

    def forward_dynamics(self, q, qd, tau, f):
        return self.model.forward_dynamics(q, qd, tau, self.body_wrenches(q, f))

    def inverse_dynamics_derivatives(self, q, qd, qdd, f):
        dq, dqd, M = self.model.inverse_dynamics_derivatives(q, qd, qdd, self.body_wrenches(q, f))
        return dq + self.shift(q, f), dqd, M

    def forward_dynamics_derivatives(self, q, qd, tau, f):
        dq, dqd, Minv = self.model.forward_dynamics_derivatives(q, qd, tau, self.body_wrenches(q, f))
        return dq - Minv @ self.shift(q, f), dqd, Minv


def close(got, want, tol=1e-12, what=""):
    got, want = np.asarray(got), np.asarray(want)
    scale = max(1.0, float(np.abs(want).max()))
    err = float(np.abs(got - want).max())
    assert err <= tol * scale, f"{what}: max difference {err:.3e} (scale {scale:.3g})"


ROBOTS = {
    "puma560 (standard DH)": lambda: kd.robots.puma560(),
    "ur5 (standard DH)": lambda: kd.robots.ur5(),
    "random tree, link offsets": lambda: with_link_offsets(random_robot(4, n=6, branching=True), 4),
}


@pytest.mark.parametrize("name", ROBOTS)
def test_native_link_origins_equal_the_former_python_route(name):
    robot = ROBOTS[name]()
    assert np.any(OldRoute(robot).u), "the robot must have link frames off its joint frames"
    old = OldRoute(robot)
    rng = np.random.default_rng(1)
    n = robot.n
    for batch in ((), (3,)):
        q, qd, qdd = (rng.uniform(-1.5, 1.5, size=batch + (n,)) for _ in range(3))
        f = rng.normal(size=batch + (n, 6))
        tau = robot.inverse_dynamics(q, qd, qdd, f_ext=f)
        close(tau, old.inverse_dynamics(q, qd, qdd, f), what="tau")
        close(robot.forward_dynamics(q, qd, tau, f_ext=f), old.forward_dynamics(q, qd, tau, f), what="qdd")
        if batch:
            continue  # (the old correction was written for single states)
        for got, want, what in zip(
            robot.inverse_dynamics_derivatives(q, qd, qdd, f_ext=f),
            old.inverse_dynamics_derivatives(q, qd, qdd, f),
            ("dtau/dq", "dtau/dqd", "M"),
        ):
            close(got, want, what=what)
        for got, want, what in zip(
            robot.forward_dynamics_derivatives(q, qd, tau, f_ext=f),
            old.forward_dynamics_derivatives(q, qd, tau, f),
            ("dqdd/dq", "dqdd/dqd", "M^-1"),
        ):
            close(got, want, 1e-11, what=what)


def test_the_wrench_maps_through_the_link_frames_jacobian():
    """tau(f) - tau(0) = -sum_i J_i^T f_i with J_i the world-aligned Jacobian of link i's frame, on
    a floating tree with spherical and planar joints whose link frames sit off their joint frames."""
    robot = with_link_offsets(random_robot(5, n=6, branching=True, floating=True, spherical=0.3, planar=0.2), 5)
    assert robot.has_multi_dof_joints
    rng = np.random.default_rng(2)
    q = robot.random_configuration(rng)
    qd, qdd = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    f = rng.normal(size=(len(robot.body_names), 6))
    want = -sum(robot.jacobian(q, frame=b).T @ f[i] for i, b in enumerate(robot.body_names))
    close(robot.inverse_dynamics(q, qd, qdd, f_ext=f) - robot.inverse_dynamics(q, qd, qdd), want, 1e-11, "J^T f")


def test_derivatives_with_f_ext_on_a_floating_base_match_central_differences():
    """dtau/dq, dqdd/dq along the manifold (q ⊕ h e_j) and the rate derivatives, wrenches held in
    base axes at the moving link-frame origins."""
    robot = with_link_offsets(
        random_robot(6, n=5, branching=True, floating=True, spherical=0.3, friction=False, prismatic=0.2), 6
    )
    rng = np.random.default_rng(3)
    nv = robot.nv
    q = robot.random_configuration(rng)
    qd, qdd = rng.normal(size=nv), rng.normal(size=nv)
    f = 3 * rng.normal(size=(len(robot.body_names), 6))
    dq, dqd, _ = robot.inverse_dynamics_derivatives(q, qd, qdd, f_ext=f)
    tau = robot.inverse_dynamics(q, qd, qdd, f_ext=f)
    aq, aqd, _ = robot.forward_dynamics_derivatives(q, qd, tau, f_ext=f)
    h = 1e-6
    for j in range(nv):
        e = np.zeros(nv)
        e[j] = h
        qp, qm = robot.integrate(q, e), robot.integrate(q, -e)
        fd = (robot.inverse_dynamics(qp, qd, qdd, f_ext=f) - robot.inverse_dynamics(qm, qd, qdd, f_ext=f)) / (2 * h)
        close(dq[:, j], fd, 1e-6, f"dtau/dq column {j}")
        fd = (robot.forward_dynamics(qp, qd, tau, f_ext=f) - robot.forward_dynamics(qm, qd, tau, f_ext=f)) / (2 * h)
        close(aq[:, j], fd, 1e-6, f"dqdd/dq column {j}")
        fd = (robot.inverse_dynamics(q, qd + e, qdd, f_ext=f) - robot.inverse_dynamics(q, qd - e, qdd, f_ext=f)) / (
            2 * h
        )
        close(dqd[:, j], fd, 1e-6, f"dtau/dqd column {j}")
        fd = (robot.forward_dynamics(q, qd + e, tau, f_ext=f) - robot.forward_dynamics(q, qd - e, tau, f_ext=f)) / (
            2 * h
        )
        close(aqd[:, j], fd, 1e-6, f"dqdd/dqd column {j}")


@pytest.mark.parametrize("name", ["puma560 (standard DH)", "random tree, link offsets"])
def test_f_ext_against_pinocchio(name):
    """Pinocchio's rnea/aba take f_ext per joint, in the joint's (= kinedyn's body) frame about its
    origin: kinedyn's wrench about the link origin, in base axes, moved there by hand."""
    pin = pytest.importorskip("pinocchio")
    from pinocchio_pairs import PinPair, pinocchio_model  # the tests' own builder of the same robot

    robot = ROBOTS[name]()
    pair = PinPair(robot, pinocchio_model(robot))
    model, data, P = pair.model, pair.data, pair.perm
    rng = np.random.default_rng(4)
    n = robot.n
    q, qd, qdd = (rng.uniform(-1.5, 1.5, n) for _ in range(3))
    f = rng.normal(size=(n, 6))
    qp = pair.to_pin_q(q)
    pin.forwardKinematics(model, data, qp)
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    links = robot.forward_kinematics(q)
    for i, name in enumerate(robot.joint_names):
        oMi = data.oMi[model.getJointId(name)]
        R, p_joint = oMi.rotation, oMi.translation
        # about the joint origin: n_joint = n_link + (p_link - p_joint) x f; then in the joint's axes
        moment = f[i, 3:] + np.cross(links[i][:3, 3] - p_joint, f[i, :3])
        fext[model.getJointId(name)] = pin.Force(R.T @ f[i, :3], R.T @ moment)
    friction = robot.friction_torque(qd)
    # (Pinocchio 3 includes the armature, as kinedyn; friction is kinedyn's alone)
    tau_pin = pin.rnea(model, data, qp, qd[P], qdd[P], fext)
    close((robot.inverse_dynamics(q, qd, qdd, f_ext=f) - friction)[P], tau_pin, 1e-10, "rnea")
    tau = rng.normal(size=n)
    qdd_pin = pin.aba(model, data, qp, qd[P], (tau - friction)[P], fext)
    close(robot.forward_dynamics(q, qd, tau, f_ext=f)[P], qdd_pin, 1e-9, "aba")


# ------------------------------------------------------------------ simulation
def python_loop(robot, method, x0, steps, dt, f_ext, hold=False):
    """The Python fixed-step loop (what simulated robots with f_ext before the core took them; now
    only LagrangianSystem's), on the robot's compiled dynamics."""
    from kinedyn.simulate.fixed_step import run_fixed_step

    n = robot.n
    zero = np.zeros(n)
    Q, QD, *_ = run_fixed_step(
        robot,
        True,
        f_ext,
        method,
        x0[:n],
        x0[n:],
        0.0,
        dt,
        steps,
        lambda i: lambda k, t, q, qd: zero,
        hold,
        1,
        1e6,
        None,
        None,
    )
    return Q, QD


@pytest.mark.parametrize("method", ["rk4", "implicit", "semi_implicit", "euler"])
def test_simulation_with_f_ext_is_native_and_equals_the_python_loop(method):
    robot = kd.robots.puma560()
    rng = np.random.default_rng(7)
    x0 = np.r_[rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6)]
    F = 5 * rng.normal(size=(6, 6))

    def pushing(t, q, qd):  # a wrench that depends on the time and the state
        return F * np.cos(3 * t) + 0.5 * np.outer(np.tanh(q), np.ones(6))

    for f_ext, fn in ((F, lambda t, q, qd: F), (pushing, pushing)):
        traj = kd.simulate(robot, 0.3, x0, dt=1e-3, method=method, f_ext=f_ext)
        assert traj.info["native"]
        Q, QD = python_loop(robot, method, x0, 300, 1e-3, fn)
        close(traj.q, Q, 1e-10, f"{method}: q")
        close(traj.qd, QD, 1e-10, f"{method}: qd")
        # and the wrench did act: the run without it differs
        assert np.abs(kd.simulate(robot, 0.3, x0, dt=1e-3, method=method).q - traj.q).max() > 1e-3


def test_a_batch_with_constant_f_ext_runs_in_parallel_as_single_runs():
    robot = kd.robots.ur5()
    rng = np.random.default_rng(8)
    x0 = rng.uniform(-1, 1, size=(3, 12))
    F = 3 * rng.normal(size=(6, 6))
    batch = kd.simulate(robot, 0.1, x0, dt=1e-3, f_ext=F)
    for k in range(3):
        close(batch.q[k], kd.simulate(robot, 0.1, x0[k], dt=1e-3, f_ext=F).q, 1e-13, "batch")


def test_f_ext_on_a_floating_tree_changes_its_momentum_as_newton_and_euler_say():
    """A free-floating tree (no joint friction: its joint torques are internal) under gravity and
    wrenches about link origins off the joints: dp/dt = m g + sum f_i and, about the base origin,
    dL/dt = c x m g + sum (n_i + p_i x f_i) with p_i the moving link-frame origins."""
    robot = with_link_offsets(random_robot(9, n=4, branching=True, floating=True, spherical=0.3, friction=False), 9)
    rng = np.random.default_rng(10)
    links = len(robot.body_names)
    F = rng.normal(size=(links, 6))
    x0 = np.r_[robot.random_configuration(rng), 0.3 * rng.normal(size=robot.nv)]
    dt = 1e-3
    traj = kd.simulate(robot, 0.2, x0, dt=dt, method="rk4", f_ext=F)
    assert traj.info["native"]
    h = robot.momentum(traj.q, traj.qd)
    mass = float(robot.inertial_parameters().reshape(-1, 10)[:, 0].sum())
    g = np.asarray(robot.gravity, dtype=float)
    p = robot.forward_kinematics(traj.q)[..., :3, 3]  # (T, links, 3)
    rate_p = mass * g + F[:, :3].sum(axis=0)
    rate_L = np.cross(robot.center_of_mass(traj.q), mass * g) + (F[:, 3:] + np.cross(p, F[:, :3])).sum(axis=1)
    close(h[-1, :3] - h[0, :3], rate_p * (traj.t[-1] - traj.t[0]), 1e-6, "linear momentum")
    # trapezoidal rule over the samples: O(dt^2)
    L = h[0, 3:] + np.concatenate([[np.zeros(3)], np.cumsum((rate_L[1:] + rate_L[:-1]) / 2 * dt, axis=0)])
    close(h[:, 3:], L, 1e-5, "angular momentum")


def test_constant_f_ext_with_a_controller_and_a_bad_f_ext_function():
    """A controller sends the run through the core's callback loop, where a constant f_ext travels as
    data: the same run as the same wrench given as a function; a function returning the wrong shape
    is an error naming it."""
    robot = kd.robots.puma560()
    rng = np.random.default_rng(11)
    x0 = np.r_[rng.uniform(-1, 1, 6), np.zeros(6)]
    F = 2 * rng.normal(size=(6, 6))

    def controller(t, q, qd):
        return -5.0 * qd

    as_data = kd.simulate(robot, 0.1, x0, dt=1e-3, controller=controller, f_ext=F)
    as_function = kd.simulate(robot, 0.1, x0, dt=1e-3, controller=controller, f_ext=lambda t, q, qd: F)
    assert as_data.info["native"] and as_function.info["native"]
    close(as_data.q, as_function.q, 1e-14, "q")
    assert np.abs(as_data.q - kd.simulate(robot, 0.1, x0, dt=1e-3, controller=controller).q).max() > 1e-4
    with pytest.raises(ValueError, match=r"f_ext returned wrenches of shape \[5, 6\]"):
        kd.simulate(robot, 0.1, x0, dt=1e-3, f_ext=lambda t, q, qd: np.zeros((5, 6)))


def test_the_core_takes_one_wrench_per_link_on_the_body_that_carries_it():
    """With multi-DOF joints the native model has more bodies than links: f_ext is still one wrench
    per link ((links, 6), one set shared by a batch), the core placing each on the body that carries
    its link (``Model.link_bodies``: a joint's last body); one per native body is refused by shape."""
    robot = with_link_offsets(random_robot(7, n=6, branching=True, floating=True, spherical=0.4, planar=0.3), 7)
    links = len(robot.body_names)
    assert robot.n > links
    # the description's count: a joint of nv degrees of freedom ends nv - 1 bodies after its first
    np.testing.assert_array_equal(robot._model.link_bodies, np.cumsum([j.nv for j in robot.joints]) - 1)
    rng = np.random.default_rng(8)
    q = robot.random_configuration(rng, size=3)
    qd, qdd = rng.normal(size=(3, robot.nv)), rng.normal(size=(3, robot.nv))
    f = rng.normal(size=(links, 6))
    shared = robot.inverse_dynamics(q, qd, qdd, f_ext=f)
    np.testing.assert_array_equal(shared, robot.inverse_dynamics(q, qd, qdd, f_ext=np.stack([f] * 3)))
    np.testing.assert_array_equal(shared[1], robot.inverse_dynamics(q[1], qd[1], qdd[1], f_ext=f))
    with pytest.raises(ValueError, match=rf"f_ext must have shape \({links}, 6\)"):
        robot.inverse_dynamics(q[0], qd[0], qdd[0], f_ext=np.zeros((robot.n, 6)))
    with pytest.raises(
        ValueError, match=rf"f_ext returned wrenches of shape \[{robot.n}, 6\] at t = 0; the robot has {links} links"
    ):
        x0 = np.concatenate([q[0], np.zeros(robot.nv)])
        kd.simulate(robot, 0.01, x0, dt=1e-3, method="rk4", f_ext=lambda t, q, qd: np.zeros((robot.n, 6)))
