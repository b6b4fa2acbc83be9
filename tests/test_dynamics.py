"""Numeric dynamics (issue 3): identities between the algorithms on every built-in robot, URDF
robots and a branching tree; finite differences; power balance along an integrated trajectory;
base parameters; batches; bad input."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.inertia import Inertia
from kinedyn.description.joint import Joint
from kinedyn.description.link import Link

pytest.importorskip("kinedyn._core", reason="the native module is not built")

REL = 1e-10  # identities between exact algorithms, relative to the size of the quantities
FD = 1e-6  # identities checked by central finite differences


def _rot(axis, angle):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def branching_tree(seed: int = 3) -> kd.Robot:
    """A 7-body tree (a torso carrying two arms, one with a prismatic joint), random parameters."""
    rng = np.random.default_rng(seed)
    parents = [None, "b0", "b1", "b2", "b1", "b4", "b0"]
    links = []
    for i, p in enumerate(parents):
        T = np.eye(4)
        T[:3, :3] = _rot(rng.normal(size=3), rng.uniform(-2, 2))
        T[:3, 3] = rng.uniform(-0.4, 0.4, 3)
        kind = "prismatic" if i == 5 else "revolute"
        joint = Joint(
            f"j{i}",
            kind,
            tuple(rng.normal(size=3)),
            viscous=rng.uniform(0, 0.3),
            coulomb=rng.uniform(0, 0.3),
            gear_ratio=rng.uniform(1, 50),
            rotor_inertia=rng.uniform(0, 1e-4),
        )
        R = _rot(rng.normal(size=3), rng.uniform(-2, 2))
        a, b = rng.uniform(0.01, 0.1, 2)
        principal = np.diag([a, b, rng.uniform(abs(a - b) + 1e-3, a + b)])
        inertia = Inertia(rng.uniform(0.3, 2.0), tuple(rng.uniform(-0.2, 0.2, 3)), R @ principal @ R.T)
        links.append(Link(f"b{i}", p, joint, T, np.eye(4), inertia))
    return kd.Robot(links, name="tree")


def with_drives(robot: kd.Robot, seed: int = 0) -> kd.Robot:
    """The same robot with rotor inertia, gear ratios and friction on every joint."""
    rng = np.random.default_rng(seed)
    links = []
    for link in robot.links:
        j = link.joint
        if j.is_moving:
            j = dataclasses.replace(
                j,
                gear_ratio=rng.uniform(10, 100),
                rotor_inertia=rng.uniform(1e-5, 1e-4),
                viscous=rng.uniform(0, 0.5),
                coulomb=rng.uniform(0, 0.5),
            )
        links.append(dataclasses.replace(link, joint=j))
    return robot.replace(links=links, name=robot.name + "+drives", dh=None)


def urdf_dir() -> str:
    from kinedyn.testing import example_robot_data_dir

    return example_robot_data_dir() or ""


def urdf_robots() -> dict:
    d = urdf_dir()
    if not d:
        return {}
    ur5 = kd.Robot.from_urdf(os.path.join(d, "ur_description/urdf/ur5_robot.urdf"))
    panda = kd.Robot.from_urdf(os.path.join(d, "panda_description/urdf/panda.urdf"))
    panda = panda.lock_joints({"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02})
    return {"urdf_ur5": ur5, "urdf_panda": panda}


ROBOTS = {name: factory for name, factory in kd.robots.CATALOGUE.items()}
ROBOTS["tree"] = branching_tree
ROBOTS["puma560+drives"] = lambda: with_drives(kd.robots.puma560())
ROBOTS["tree+drives"] = lambda: with_drives(branching_tree(4), 1)
URDF = urdf_robots()
for _name, _robot in URDF.items():
    ROBOTS[_name] = (lambda r: lambda: r)(_robot)


@pytest.fixture(params=list(ROBOTS), scope="module")
def robot(request) -> kd.Robot:
    return ROBOTS[request.param]()


def states(robot, count=3, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield robot.random_configuration(rng), rng.uniform(-2, 2, robot.n), rng.uniform(-3, 3, robot.n)


def friction(robot, qd):
    v = np.array([float(j.viscous) for j in robot.joints])
    c = np.array([float(j.coulomb) for j in robot.joints])
    return v * qd + c * np.sign(qd)


def armature(robot):
    return np.array([float(j.armature) for j in robot.joints])


def close(got, want, tol=REL, what=""):
    got, want = np.asarray(got, float), np.asarray(want, float)
    scale = max(1.0, np.abs(want).max(initial=0.0))
    err = np.abs(got - want).max(initial=0.0)
    assert err <= tol * scale, f"{what}: max |diff| {err:.3g} > {tol:g} * {scale:.3g}"


# ---------------------------------------------------------------------------------- identities
def test_inverse_dynamics_is_m_qdd_plus_c_qd_plus_g_plus_friction(robot):
    for q, qd, qdd in states(robot):
        tau = robot.inverse_dynamics(q, qd, qdd)
        M, C, g = robot.mass_matrix(q), robot.coriolis_matrix(q, qd), robot.gravity_torque(q)
        close(tau, M @ qdd + C @ qd + g + friction(robot, qd), what="rnea")
        close(robot.bias_torque(q, qd), C @ qd + g, what="bias")
        assert np.array_equal(M, M.T), "M must be exactly symmetric"
        assert np.all(np.linalg.eigvalsh(M) > 0), "M must be positive definite"


def test_forward_dynamics_inverts_inverse_dynamics(robot):
    rng = np.random.default_rng(1)
    for q, qd, qdd in states(robot):
        for f_ext in (None, rng.normal(size=(robot.n, 6))):
            tau = robot.inverse_dynamics(q, qd, qdd, f_ext)
            close(robot.forward_dynamics(q, qd, tau, f_ext), qdd, what="aba(rnea)")
        Minv = robot.mass_matrix_inverse(q)
        close(Minv @ robot.mass_matrix(q), np.eye(robot.n), what="Minv M")
        assert np.array_equal(Minv, Minv.T)
        tau = rng.normal(size=robot.n)
        close(
            robot.forward_dynamics(q, qd, tau),
            Minv @ (tau - robot.bias_torque(q, qd) - friction(robot, qd)),
            what="aba vs Minv",
        )


def test_external_wrenches_are_body_wrenches_in_base_axes_at_the_body_origin(robot):
    """tau(f_ext) - tau(0) == -sum_i J_i^T f_i, J_i the world-aligned Jacobian of body i's frame."""
    rng = np.random.default_rng(2)
    q, qd, qdd = next(states(robot))
    f = rng.normal(size=(robot.n, 6))
    want = -sum(robot.jacobian(q, frame=name, reference="world").T @ f[i] for i, name in enumerate(robot.body_names))
    close(robot.inverse_dynamics(q, qd, qdd, f) - robot.inverse_dynamics(q, qd, qdd), want, what="f_ext")


def test_gravity_and_potential_energy(robot):
    h = 1e-6
    for q, _, _ in states(robot):
        z = np.zeros(robot.n)
        g = robot.gravity_torque(q)
        close(g, robot.inverse_dynamics(q, z, z), what="g == rnea(q, 0, 0)")
        dP = [
            (robot.potential_energy(q + h * e) - robot.potential_energy(q - h * e)) / (2 * h) for e in np.eye(robot.n)
        ]
        close(g, dP, FD, "g == dP/dq")


def test_coriolis_matrix_against_finite_differences_of_m(robot):
    h = 1e-6
    for q, qd, _ in states(robot, 2):
        C = robot.coriolis_matrix(q, qd)
        Mdot = (robot.mass_matrix(q + h * qd) - robot.mass_matrix(q - h * qd)) / (2 * h)
        close(C + C.T, Mdot, FD, "dM/dt == C + C^T")
        S = Mdot - 2 * C
        close(S, -S.T, FD, "dM/dt - 2C skew")
        close(qd @ C @ qd, 0.5 * qd @ Mdot @ qd, FD, "qd.C qd == 1/2 qd.dM/dt qd")
        dM = np.array(
            [(robot.mass_matrix(q + h * e) - robot.mass_matrix(q - h * e)) / (2 * h) for e in np.eye(robot.n)]
        )
        c = 0.5 * (np.einsum("ikj->ijk", dM) + np.einsum("jki->ijk", dM) - np.einsum("kij->ijk", dM))
        close(robot.christoffel(q), c, FD, "christoffel vs FD of M")
        close(np.einsum("ijk,i->kj", robot.christoffel(q), qd), C, REL, "C[k,j] == sum_i c_ijk qd_i")


def test_energies_and_momentum(robot):
    h = 1e-6
    for q, qd, _ in states(robot, 2):
        K = robot.kinetic_energy(q, qd)
        assert isinstance(K, float)
        close(K, 0.5 * qd @ robot.mass_matrix(q) @ qd, what="K")
        # from the description: every moving link's mass at its centre of mass, in its link frame
        links = [l for l in robot.links if robot.tree.frames[robot.frame_index(l.name)].body >= 0]
        total = sum(float(l.inertia.mass) for l in links)
        poses = robot.frame_poses(q, [l.name for l in links])
        first = sum(
            float(l.inertia.mass) * (T[:3, :3] @ np.array(l.inertia.com, float) + T[:3, 3])
            for l, T in zip(links, poses)
        )
        close(robot.center_of_mass(q), first / total, what="centre of mass")
        close(robot.potential_energy(q), -total * np.dot(robot.gravity, robot.center_of_mass(q)), what="P")
        cdot = (robot.center_of_mass(q + h * qd) - robot.center_of_mass(q - h * qd)) / (2 * h)
        close(robot.momentum(q, qd)[:3], total * cdot, FD, "linear momentum")


def test_regressor_reproduces_rigid_body_torque(robot):
    pi = robot.inertial_parameters()
    for q, qd, qdd in states(robot):
        Y = robot.regressor(q, qd, qdd)
        assert Y.shape == (robot.n, 10 * robot.n)
        rigid = robot.inverse_dynamics(q, qd, qdd) - friction(robot, qd) - armature(robot) * qdd
        close(Y @ pi, rigid, what="Y pi")


def test_base_parameters(robot):
    bp = robot.base_parameters(samples=60)
    pi = robot.inertial_parameters()
    assert bp.grouping.shape == (bp.count, 10 * robot.n)
    close(bp.values, bp.grouping @ pi)
    rng = np.random.default_rng(5)
    q = robot.random_configuration(rng, size=30)
    qd, qdd = rng.uniform(-2, 2, (2, 30, robot.n))
    Y = robot.regressor(q, qd, qdd)
    Yb = bp.regressor(Y).reshape(-1, bp.count)
    assert np.linalg.matrix_rank(Yb / np.linalg.norm(Yb, axis=0)) == bp.count, "base regressor not of full column rank"
    close(Yb @ bp.values, (Y @ pi).reshape(-1), 1e-9, "Y_base pi_base == Y pi")
    # any other parameter vector too: the grouping is a property of the kinematics
    other = rng.normal(size=pi.size)
    close(Yb @ (bp.grouping @ other), (Y @ other).reshape(-1), 1e-9, "grouping")


def test_base_parameters_of_a_planar_2r_arm():
    """Planar 2R in a vertical plane (Spong §7.4): the classical 6 base parameters
    Izz1 + m2 l1^2, m1 cx1 + m2 l1, m1 cy1, Izz2, m2 cx2, m2 cy2."""
    bp = kd.robots.planar_2r().base_parameters(samples=40)
    assert bp.count == 6


# ---------------------------------------------------------------------------- power balance
def test_power_balance_along_an_integrated_trajectory():
    """d/dt (K + P) == qd . tau without friction: integrate the dynamics and the work together."""
    from scipy.integrate import solve_ivp

    for robot in (kd.robots.puma560(), branching_tree(6), with_drives(kd.robots.ur5()).replace(name="ur5")):
        robot = _frictionless(robot)
        n = robot.n
        q0 = robot.random_configuration(7)

        def tau(t):
            return 2.0 * np.sin(3.0 * t + np.arange(n))

        def rhs(t, x):
            q, qd = x[:n], x[n : 2 * n]
            u = tau(t)
            return np.concatenate([qd, robot.forward_dynamics(q, qd, u), [qd @ u]])

        sol = solve_ivp(
            rhs, (0.0, 0.5), np.concatenate([q0, np.zeros(n), [0.0]]), method="DOP853", rtol=1e-12, atol=1e-12
        )
        assert sol.success
        q, qd, work = sol.y[:n, -1], sol.y[n : 2 * n, -1], sol.y[-1, -1]
        E0 = robot.potential_energy(q0)
        E1 = robot.kinetic_energy(q, qd) + robot.potential_energy(q)
        assert abs(work) > 1e-3, "the trajectory should do work"
        assert abs((E1 - E0) - work) < 1e-8 * max(1.0, abs(E0), abs(E1)), f"{robot.name}: dE {E1 - E0} vs work {work}"


def _frictionless(robot):
    links = [
        dataclasses.replace(l, joint=dataclasses.replace(l.joint, viscous=0.0, coulomb=0.0)) if l.joint.is_moving else l
        for l in robot.links
    ]
    return robot.replace(links=links, dh=None)


# ----------------------------------------------------------------------------------- batches
def test_batch_equals_loop():
    robot = with_drives(kd.robots.ur5())
    rng = np.random.default_rng(3)
    N, n = 130, robot.n  # more than one parallel chunk
    q = robot.random_configuration(rng, size=N)
    qd, qdd = rng.uniform(-2, 2, (2, N, n))
    f = rng.normal(size=(N, n, 6))
    calls = {
        "inverse_dynamics": (q, qd, qdd),
        "mass_matrix": (q,),
        "mass_matrix_inverse": (q,),
        "forward_dynamics": (q, qd, qdd),
        "coriolis_matrix": (q, qd),
        "christoffel": (q,),
        "gravity_torque": (q,),
        "bias_torque": (q, qd),
        "kinetic_energy": (q, qd),
        "potential_energy": (q,),
        "regressor": (q, qd, qdd),
        "center_of_mass": (q,),
        "momentum": (q, qd),
    }
    for name, args in calls.items():
        method = getattr(robot, name)
        batch = method(*args)
        loop = np.array([method(*(a[k] for a in args)) for k in range(N)])
        assert batch.shape == loop.shape, name
        assert np.array_equal(batch, loop), name
    for name in ("inverse_dynamics", "forward_dynamics"):
        method = getattr(robot, name)
        batch = method(q, qd, qdd, f)
        loop = np.array([method(q[k], qd[k], qdd[k], f[k]) for k in range(N)])
        assert np.array_equal(batch, loop), name + " with f_ext"


# --------------------------------------------------------------------------------- bad input
def test_bad_shapes_and_non_finite_values():
    robot = kd.robots.ur5()
    q = np.zeros(6)
    with pytest.raises(ValueError, match="qd"):
        robot.inverse_dynamics(q, np.zeros(5), q)
    with pytest.raises(ValueError, match="q"):
        robot.mass_matrix(np.zeros((2, 3, 6)))
    with pytest.raises(ValueError, match="batch"):
        robot.forward_dynamics(np.zeros((4, 6)), np.zeros((3, 6)), np.zeros((4, 6)))
    with pytest.raises(ValueError, match="f_ext"):
        robot.inverse_dynamics(q, q, q, np.zeros((6, 3)))
    bad = q.copy()
    bad[2] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        robot.coriolis_matrix(q, bad)
    with pytest.raises(ValueError, match="tau"):
        robot.forward_dynamics(q, q, np.full(6, np.inf))


def test_python_side_helpers_check_their_inputs_too():
    """friction_torque, random_configuration and base_parameters run in Python: they used to
    broadcast a wrong shape, warn on inf, or return an empty parameter set."""
    robot = kd.robots.ur5()
    with pytest.raises(ValueError, match=r"qd must have shape \(6,\) or a batch \(N, 6\), got \(5,\)"):
        robot.friction_torque(np.zeros(5))
    with pytest.raises(ValueError, match="non-finite"):
        robot.friction_torque(np.full(6, np.inf))
    assert robot.friction_torque(np.zeros((3, 6))).shape == (3, 6)
    with pytest.raises(ValueError, match="size must be a whole number"):
        robot.random_configuration(size=-1)
    with pytest.raises(ValueError, match="samples must be a whole number"):
        robot.base_parameters(samples=0)


def test_massless_chain_is_a_clear_error_from_forward_dynamics():
    links = [Link("a", None, Joint("shoulder")), Link("b", "a", Joint("elbow", axis=(0, 1, 0)), np.eye(4))]
    robot = kd.Robot(links, name="massless")
    with pytest.raises(RuntimeError, match=r"singular mass matrix.*'elbow'"):
        robot.forward_dynamics(np.zeros(2), np.zeros(2), np.ones(2))
    with pytest.raises(RuntimeError, match="singular mass matrix"):
        robot.mass_matrix_inverse(np.zeros(2))
    # the core's error carries the degree of freedom (no message parsing): the last one, 'elbow'
    with pytest.raises(kd._core.SingularMassMatrixError) as raised:
        robot._model.forward_dynamics(np.zeros(2), np.zeros(2), np.ones(2))
    assert isinstance(raised.value, RuntimeError)
    assert (raised.value.joint, raised.value.overflow) == (1, False)
    assert raised.value.message in str(raised.value) and "joint 1" in raised.value.message
    # rotor inertia alone makes the joints accelerate: qdd = tau / (r^2 J_m)
    geared = [
        dataclasses.replace(l, joint=dataclasses.replace(l.joint, gear_ratio=10.0, rotor_inertia=1e-3)) for l in links
    ]
    close(kd.Robot(geared).forward_dynamics(np.zeros(2), np.zeros(2), np.ones(2)), [10.0, 10.0])


def test_lists_and_integer_arrays_are_accepted():
    robot = kd.robots.puma560()
    q = [0, 1, 0, -1, 0, 2]
    qf = np.array(q, float)
    assert np.array_equal(robot.mass_matrix(q), robot.mass_matrix(qf))
    assert np.array_equal(robot.inverse_dynamics(q, q, np.array(q)), robot.inverse_dynamics(qf, qf, qf))
    assert np.array_equal(
        robot.gravity_torque(np.array(q, np.float32)), robot.gravity_torque(np.array(q, np.float32).astype(float))
    )
    assert robot.potential_energy(q) == robot.potential_energy(qf)


def test_out_parameter_writes_in_place():
    """NumPy's out=: the per-step methods write into the caller's array (no allocation per call),
    return it, give the same numbers, for one state and a batch; a wrong out is a clear error."""
    robot = with_drives(kd.robots.puma560())
    n = robot.n
    rng = np.random.default_rng(9)
    for N in (None, 4):
        shape = (n,) if N is None else (N, n)
        q, qd, qdd = (rng.uniform(-1.5, 1.5, shape) for _ in range(3))
        f = rng.uniform(-2, 2, shape[:-1] + (n, 6))
        calls = [
            ("inverse_dynamics", (q, qd, qdd), {}),
            ("inverse_dynamics", (q, qd, qdd), {"f_ext": f}),
            ("mass_matrix", (q,), {}),
            ("mass_matrix_inverse", (q,), {}),
            ("forward_dynamics", (q, qd, qdd), {}),
            ("forward_dynamics", (q, qd, qdd), {"f_ext": f}),
            ("coriolis_matrix", (q, qd), {}),
            ("gravity_torque", (q,), {}),
            ("bias_torque", (q, qd), {}),
        ]
        for name, args, kwargs in calls:
            method = getattr(robot, name)
            expected = method(*args, **kwargs)
            out = np.full(expected.shape, np.nan)
            got = method(*args, **kwargs, out=out)
            assert got is out, name
            np.testing.assert_array_equal(out, expected, err_msg=name)
    q = np.zeros(n)
    with pytest.raises(ValueError, match=r"out must have shape \(6, 6\), got \(6, 5\)"):
        robot.mass_matrix(q, out=np.empty((6, 5)))
    with pytest.raises(ValueError, match=r"out must have shape \(3, 6\)"):
        robot.gravity_torque(np.zeros((3, 6)), out=np.empty(6))
    with pytest.raises(TypeError, match="float64 NumPy array, got an array of dtype float32"):
        robot.mass_matrix(q, out=np.empty((6, 6), dtype=np.float32))
    with pytest.raises(TypeError, match="float64 NumPy array, got <class 'list'>"):
        robot.gravity_torque(q, out=[0.0] * 6)
    with pytest.raises(ValueError, match="writeable, C-contiguous"):
        robot.mass_matrix(q, out=np.empty((6, 6), order="F"))
    frozen = np.empty((6, 6))
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="writeable, C-contiguous"):
        robot.mass_matrix(q, out=frozen)
    with pytest.raises(ValueError, match="share memory with the inputs"):
        robot.gravity_torque(q, out=q)
    # a batch's inputs are copied before the GIL is released: an aliased out is fine there
    Q = rng.uniform(-1, 1, (3, n))
    expected = robot.gravity_torque(Q)
    assert robot.gravity_torque(Q, out=Q) is Q
    np.testing.assert_array_equal(Q, expected)
