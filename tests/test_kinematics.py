"""Forward kinematics and Jacobians of the Rust core, checked by independent routes:
DH products written here in NumPy, central finite differences of FK, closed forms derived here."""

from __future__ import annotations

import math

import numpy as np
import pytest

import kinedyn as kd
from kinedyn import kinematics as kin

pytest.importorskip("kinedyn._core", reason="the native module is not built")

ROBOTS = {name: kd.robots.get(name) for name in kd.robots.names()}
RNG = np.random.default_rng(20261122)


def dh_matrix(theta, d, a, alpha, convention):
    """One DH transform, written out element by element (Spong eq. 3.10; Craig eq. 3.6)."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    if convention == "standard":  # Rz(theta) Tz(d) Tx(a) Rx(alpha)
        return np.array(
            [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1.0]]
        )
    # modified: Rx(alpha) Tx(a) Rz(theta) Tz(d)
    return np.array([[ct, -st, 0, a], [st * ca, ct * ca, -sa, -sa * d], [st * sa, ct * sa, ca, ca * d], [0, 0, 0, 1.0]])


def dh_chain(robot, q):
    """Link frames 1..n of a DH robot as the product of the table's matrices."""
    T = np.eye(4)
    out = []
    for row, qi in zip(robot.dh, q):
        theta = float(row.theta) + (qi if row.kind == "revolute" else 0.0)
        d = float(row.d) + (qi if row.kind == "prismatic" else 0.0)
        T = T @ dh_matrix(theta, d, float(row.a), float(row.alpha), robot.dh_convention)
        out.append(T)
    return np.array(out)


def rotation_log_rate(R_minus, R_plus, h):
    """Angular velocity in base axes from dR/dt R^T by central differences."""
    W = (R_plus - R_minus) / (2 * h) @ ((R_plus + R_minus) / 2).T
    return np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / 2


def fd_jacobian_world(robot, q, frame, h=1e-6):
    """[dp/dq; w per unit qd] of a frame by central differences of the pose."""
    J = np.zeros((6, robot.n))
    for j in range(robot.n):
        dq = np.zeros(robot.n)
        dq[j] = h
        Tp, Tm = robot.pose(q + dq, frame), robot.pose(q - dq, frame)
        J[:3, j] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        J[3:, j] = rotation_log_rate(Tm[:3, :3], Tp[:3, :3], h)
    return J


DH_ROBOTS = [name for name, r in ROBOTS.items() if r.dh is not None]


@pytest.mark.parametrize("name", DH_ROBOTS)
def test_fk_equals_product_of_dh_matrices(name):
    robot = ROBOTS[name]
    for q in robot.random_configuration(RNG, size=5):
        np.testing.assert_allclose(robot.forward_kinematics(q), dh_chain(robot, q), atol=1e-12)


def test_standard_and_modified_dh_give_the_same_tool_pose():
    # A 3R arm written in both conventions: modified row i carries (alpha_{i-1}, a_{i-1}) of standard row i-1.
    std = [(0.1, 0.4, 0.3, math.pi / 2), (-0.2, 0.0, 0.7, 0.0), (0.3, 0.2, 0.5, -math.pi / 2)]
    mod = [(0.1, 0.4, 0.0, 0.0), (-0.2, 0.0, 0.3, math.pi / 2), (0.3, 0.2, 0.7, 0.0)]
    last = std[-1]
    tool = dh_matrix(0.0, 0.0, last[2], last[3], "modified")  # the trailing Tx(a_n) Rx(alpha_n)
    a = kd.Robot.from_dh(std, "standard")
    b = kd.Robot.from_dh(mod, "modified", tool=tool)
    for q in RNG.uniform(-3, 3, size=(5, 3)):
        np.testing.assert_allclose(a.pose(q), b.pose(q), atol=1e-12)


@pytest.mark.parametrize("name", list(ROBOTS))
@pytest.mark.parametrize("reference", ["world", "local", "spatial"])
def test_jacobian_matches_finite_differences(name, reference):
    robot = ROBOTS[name]
    frames = [robot.tool, robot.body_names[len(robot.body_names) // 2]]
    for q in robot.random_configuration(RNG, size=3):
        for frame in frames:
            Jw = fd_jacobian_world(robot, q, frame)
            T = robot.pose(q, frame)
            R, p = T[:3, :3], T[:3, 3]
            if reference == "world":
                expected = Jw
            elif reference == "local":
                expected = np.vstack([R.T @ Jw[:3], R.T @ Jw[3:]])
            else:  # velocity of the body point at the base origin: v_o - w x p
                expected = np.vstack([Jw[:3] - np.cross(Jw[3:].T, p).T, Jw[3:]])
            np.testing.assert_allclose(robot.jacobian(q, frame, reference), expected, atol=1e-7)


def test_jacobian_of_a_point_is_the_derivative_of_that_point():
    robot = ROBOTS["elbow_3r"]
    point = np.array([0.1, -0.2, 0.3])
    q = robot.random_configuration(RNG)
    h = 1e-6
    Jp = np.zeros((3, robot.n))
    for j in range(robot.n):
        dq = np.zeros(robot.n)
        dq[j] = h
        Jp[:, j] = ((robot.pose(q + dq, "link2") - robot.pose(q - dq, "link2")) @ np.append(point, 1))[:3] / (2 * h)
    np.testing.assert_allclose(robot.jacobian(q, "link2", point=point)[:3], Jp, atol=1e-7)


@pytest.mark.parametrize("name", list(ROBOTS))
@pytest.mark.parametrize("reference", ["world", "local", "spatial"])
def test_velocity_and_drift_match_derivatives_of_J_qd(name, reference):
    robot = ROBOTS[name]
    h = 1e-6
    for _ in range(3):
        q = robot.random_configuration(RNG)
        qd = RNG.normal(size=robot.n)
        J = robot.jacobian(q, reference=reference)
        np.testing.assert_allclose(robot.frame_velocity(q, qd, reference=reference), J @ qd, atol=1e-12)
        # d/dt (J(q) qd) at qdd = 0, along q(t) = q + t qd
        rate = (
            robot.jacobian(q + h * qd, reference=reference) @ qd - robot.jacobian(q - h * qd, reference=reference) @ qd
        ) / (2 * h)
        np.testing.assert_allclose(
            robot.jacobian_dot_qd(q, qd, reference=reference), rate, atol=1e-6 * max(1, np.abs(rate).max())
        )


def test_tutorial_two_link_arm_velocity_and_torques():
    """Tutorial Q1a/Q2a/Q2b at theta = (167.028 deg, -156.44 deg), l = (2, 3), from the closed form
    x = l1 c1 + l2 c12, y = l1 s1 + l2 s12 differentiated here by hand."""
    robot = kd.robots.planar_2r()
    q = np.radians([167.028, -156.44])
    l1, l2 = 2.0, 3.0
    s1, c1 = math.sin(q[0]), math.cos(q[0])
    s12, c12 = math.sin(q.sum()), math.cos(q.sum())
    J_expected = np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12]])
    J = kin.task_jacobian(robot, q, task="planar")
    np.testing.assert_allclose(J, J_expected, atol=1e-12)
    v = kin.tool_velocity(robot, q, [1.0, 3.0], task="planar")
    np.testing.assert_allclose(v, J_expected @ [1.0, 3.0], atol=1e-12)
    tau = kin.joint_torques(robot, q, [30.0, -20.0], task="planar")
    np.testing.assert_allclose(tau, J_expected.T @ [30.0, -20.0], atol=1e-12)
    # the tool point itself: FK closed form
    np.testing.assert_allclose(robot.pose(q)[:2, 3], [l1 * c1 + l2 * c12, l1 * s1 + l2 * s12], atol=1e-12)


def test_inverse_jacobian_rates_and_manipulability_of_the_2r_arm():
    robot = kd.robots.planar_2r()
    q = np.array([0.4, 1.1])
    v = np.array([0.3, -0.7])
    J = kin.task_jacobian(robot, q, task="planar")
    for method in ("inverse", "pinv"):
        qd = kin.joint_velocities(robot, q, v, task="planar", method=method)
        np.testing.assert_allclose(J @ qd, v, atol=1e-12)
    # damped least squares trades accuracy for boundedness: close to, not equal to, the exact rates
    qd_dls = kin.joint_velocities(robot, q, v, task="planar", method="dls", damping=1e-3)
    np.testing.assert_allclose(J @ qd_dls, v, atol=1e-5)
    # det J = l1 l2 sin q2 for the planar 2R arm
    assert kin.manipulability(robot, q, task="planar") == pytest.approx(2 * 3 * abs(math.sin(q[1])), rel=1e-12)


def test_singularity_report_names_the_lost_direction():
    robot = kd.robots.planar_2r()
    q1 = 0.7
    report = kin.singularity_report(robot, [q1, 0.0], task="planar")
    assert report.singular and report.rank == 1
    # outstretched arm: the tool cannot move radially, along (cos q1, sin q1)
    lost = report.lost_directions[0]
    assert abs(abs(lost @ [math.cos(q1), math.sin(q1)]) - 1) < 1e-9
    assert "cannot move" in report.summary()
    with pytest.raises(ValueError, match="singular"):
        kin.joint_velocities(robot, [q1, 0.0], [0.1, 0.1], task="planar", method="inverse")
    assert not kin.singularity_report(robot, [q1, 1.0], task="planar").singular


@pytest.mark.parametrize("method", ["inverse", "pinv", "dls"])
def test_velocity_and_force_maps_take_batches(method):
    """tool_velocity / joint_torques / joint_velocities on (N, n) configurations (and (N, m) vectors)
    equal the loop over single ones (a batch used to be refused with a wrong component count)."""
    robot = ROBOTS["puma560"]
    Q = robot.random_configuration(np.random.default_rng(3), size=5)
    V = np.random.default_rng(4).normal(size=(5, 6))
    np.testing.assert_allclose(
        kin.tool_velocity(robot, Q, V), [kin.tool_velocity(robot, q, v) for q, v in zip(Q, V)], atol=1e-12
    )
    np.testing.assert_allclose(
        kin.tool_velocity(robot, Q, V[0]), [kin.tool_velocity(robot, q, V[0]) for q in Q], atol=1e-12
    )
    np.testing.assert_allclose(
        kin.joint_torques(robot, Q, V[0]), [kin.joint_torques(robot, q, V[0]) for q in Q], atol=1e-12
    )
    qd = kin.joint_velocities(robot, Q, V, method=method)
    assert qd.shape == (5, 6)
    np.testing.assert_allclose(
        qd, [kin.joint_velocities(robot, q, v, method=method) for q, v in zip(Q, V)], rtol=1e-9, atol=1e-9
    )
    with pytest.raises(
        ValueError, match=r"wrench must have 6 components for this task, shape \(6,\) or \(5, 6\); got shape \(4, 6\)"
    ):
        kin.joint_torques(robot, Q, V[:4])


def test_inverse_rates_name_the_singular_configuration_of_a_batch():
    robot = kd.robots.planar_2r()
    Q = np.array([[0.4, 1.0], [0.7, 0.0]])
    with pytest.raises(ValueError, match=r"singular at q = \[0.7 0. \] \(configuration 1 of the batch\)"):
        kin.joint_velocities(robot, Q, [0.1, 0.1], task="planar", method="inverse")


@pytest.mark.parametrize("name", ["planar_2r", "elbow_3r", "puma560"])
def test_batch_equals_loop(name):
    robot = ROBOTS[name]
    Q = robot.random_configuration(RNG, size=130)  # above the parallel threshold
    QD = RNG.normal(size=Q.shape)
    fk, J, jd = robot.forward_kinematics(Q), robot.jacobian(Q), robot.jacobian_dot_qd(Q, QD)
    assert fk.shape == (130, robot.n, 4, 4) and J.shape == (130, 6, robot.n) and jd.shape == (130, 6)
    for k in (0, 63, 64, 129):
        np.testing.assert_array_equal(fk[k], robot.forward_kinematics(Q[k]))
        np.testing.assert_array_equal(J[k], robot.jacobian(Q[k]))
        np.testing.assert_array_equal(jd[k], robot.jacobian_dot_qd(Q[k], QD[k]))


def test_any_layout_and_lists_are_accepted():
    robot = ROBOTS["elbow_3r"]
    Q = np.asfortranarray(robot.random_configuration(RNG, size=4))
    expected = robot.jacobian(np.ascontiguousarray(Q))
    np.testing.assert_array_equal(robot.jacobian(Q), expected)
    np.testing.assert_array_equal(robot.jacobian(Q.tolist()), expected)
    wide = np.zeros((4, 6))
    wide[:, ::2] = Q
    np.testing.assert_array_equal(robot.jacobian(wide[:, ::2]), expected)
    np.testing.assert_array_equal(robot.pose([0, 0, 0]), robot.pose(np.zeros(3, dtype=np.int32)))


def test_bad_inputs_give_clear_errors():
    robot = ROBOTS["elbow_3r"]
    with pytest.raises(ValueError, match=r"q must have shape \(3,\) or a batch \(N, 3\), got \(2,\)$"):
        robot.pose([0.0, 0.0])
    with pytest.raises(ValueError, match=r"q must have shape"):
        robot.jacobian(np.zeros((2, 2, 3)))
    with pytest.raises(ValueError, match="non-finite"):
        robot.pose([0.0, float("nan"), 0.0])
    with pytest.raises(ValueError, match="non-finite.*state 1"):
        robot.jacobian([[0.0, 0, 0], [0.0, float("inf"), 0]])
    with pytest.raises(
        ValueError, match=r"qd has shape \(3, 3\), which does not match the other arguments \(a batch of 2 states\)"
    ):
        robot.frame_velocity(np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="unknown frame 'hand'"):
        robot.pose([0, 0, 0], "hand")
    with pytest.raises(ValueError, match="reference must be one of"):
        robot.jacobian([0, 0, 0], reference="body")
    with pytest.raises(ValueError, match="point"):
        robot.jacobian([0, 0, 0], point=[1, 2])
    with pytest.raises(ValueError, match="unknown task"):
        kin.task_jacobian(robot, [0, 0, 0], task="xy")


def test_native_model_rejects_bad_joint_records_without_panicking():
    """Errors from the native constructor are ValueErrors naming the joint (or frame) and the
    problem, never a Rust panic."""
    from kinedyn import _core

    eye = np.eye(4)
    base = dict(
        name="base", kind="floating", placement=eye.copy(), inertia=np.array([1.0, 0, 0, 0, 0.1, 0, 0.1, 0, 0, 0.1])
    )
    good = dict(
        name="elbow", kind="revolute", parent=0, placement=eye.copy(), axis=np.array([0, 0, 1.0]), inertia=np.zeros(10)
    )
    gravity = np.array([0, 0, -9.81])
    model = _core.Model([base, good], gravity, [(1, eye.copy())])
    assert (model.nq, model.n, model.n_frames) == (8, 7, 1)
    cases = {
        "axis": (dict(axis=np.array([0, 0, 2.0])), "joint 'elbow' .joint 1.: axis .* is not a unit vector"),
        "parent": (dict(parent=1), "joint 'elbow' .joint 1.: its parent joint 1 is not an earlier joint"),
        "negative parent": (dict(parent=-3), "joint 1 'elbow': parent must be an earlier joint's index or -1"),
        "kind": (dict(kind="helical"), "joint 1 'elbow': .*unknown joint kind .helical."),
        "no axis": (dict(kind="prismatic", axis=None), "joint 1 'elbow': .*a prismatic joint needs an axis"),
        "shape": (dict(placement=np.eye(3)), r"joint 1 'elbow': placement must have shape \(4, 4\), got \(3, 3\)"),
        "mass": (dict(inertia=np.array([-1.0] + [0] * 9)), "joint 'elbow' .joint 1.: its link has negative mass"),
        "nan": (dict(offset=np.nan), "joint 'elbow' .joint 1.: offset is NaN"),
        "typo": (dict(axes=np.array([0, 0, 1.0])), "joint 1 'elbow': unknown key 'axes'"),
        "text": (dict(viscous="wet"), "joint 1 'elbow': viscous must be a number"),
    }
    for what, (change, message) in cases.items():
        with pytest.raises(ValueError, match=message):
            _core.Model([base, {**good, **change}], gravity, [(1, eye.copy())])
        assert what
    with pytest.raises(ValueError, match="placement"):
        _core.Model([base, {k: v for k, v in good.items() if k != "placement"}], gravity)
    with pytest.raises(ValueError, match="frame 0 is fixed to joint 3, but there are 2 joints"):
        _core.Model([base, good], gravity, [(3, eye.copy())])
    with pytest.raises(ValueError, match="non-finite"):
        _core.Model([base, good], gravity, [(1, np.full((4, 4), np.nan))])


def test_frame_poses_of_no_frames_is_an_empty_array():
    """An empty result per state (no frames asked for) is an empty array, for one state or a batch."""
    robot = kd.robots.ur5()
    assert robot.frame_poses(np.zeros(6), []).shape == (0, 4, 4)
    assert robot.frame_poses(np.zeros((3, 6)), []).shape == (3, 0, 4, 4)


def test_analysis_rows_are_the_rows_an_arm_spans():
    """kin.analysis_rows: the rows on which rank and manipulability are measured, and why."""
    elbow, planar, puma = kd.robots.get("elbow_3r"), kd.robots.get("planar_2r"), kd.robots.get("puma560")
    full = kin.task_rows("full")
    assert kin.spanned_rows(elbow) == [0, 1, 2]
    assert kin.spanned_rows(planar) == [0, 1]
    assert kin.analysis_rows(elbow, full, False) == ([0, 1, 2], "spanned")
    assert kin.analysis_rows(puma, full, False) == (full, "all")
    assert kin.analysis_rows(elbow, [0, 1], True) == ([0, 1], "given")
    assert [kin.ROW_NAMES[r] for r in kin.spanned_rows(elbow)] == ["vx", "vy", "vz"]
