"""The kinematic Hessian dJ/dq (Robotics Toolbox's hessian0 / hessiane) and the manipulability
Jacobian dw/dq (RTB's jacobm), checked by independent routes: central finite differences of the
numeric Jacobian, the drift dJ/dt qd of the recursive acceleration pass, RTB's own definitions
written out here, and the closed form of the planar 2R arm."""

from __future__ import annotations

import numpy as np
import pytest
from reference import PANDA, UR5, erd

import kinedyn as kd
from kinedyn import kinematics as kin

pytest.importorskip("kinedyn._core", reason="the native module is not built")

ROBOTS = {name: kd.robots.get(name) for name in kd.robots.names()}
REFERENCES = ["world", "local", "spatial"]
RNG = np.random.default_rng(20261201)


def fd_hessian(robot, q, frame=None, reference="world", point=None, h=1e-6):
    """(n, 6, n): H[i] = (J(q + h e_i) - J(q - h e_i)) / 2h, central differences of the numeric Jacobian."""
    H = np.zeros((robot.n, 6, robot.n))
    for i in range(robot.n):
        dq = np.zeros(robot.n)
        dq[i] = h
        H[i] = (robot.jacobian(q + dq, frame, reference, point) - robot.jacobian(q - dq, frame, reference, point)) / (
            2 * h
        )
    return H


def rtb_hessian_definition(J):
    """Robotics Toolbox's ETS.hessian0 / hessiane, written from its definition (Haviland & Corke
    2022, Part I): for j <= i, H[j, :3, i] = w_j x Jv_i and H[j, 3:, i] = w_j x w_i, the linear
    rows mirrored, H[i, :3, j] = H[j, :3, i]; the angular rows of j > i are zero. Applied to J0 it
    is hessian0, to Je it is hessiane."""
    n = J.shape[1]
    H = np.zeros((n, 6, n))
    for j in range(n):
        for i in range(j, n):
            H[j, :3, i] = np.cross(J[3:, j], J[:3, i])
            H[j, 3:, i] = np.cross(J[3:, j], J[3:, i])
            if i != j:
                H[i, :3, j] = H[j, :3, i]
    return H


def urdf_robots():
    return {
        "ur5": kd.Robot.from_urdf(erd(*UR5)),
        "panda": kd.Robot.from_urdf(erd(*PANDA), mimic="independent"),
    }  # 9 coordinates, as before mimic support


@pytest.mark.parametrize("name", list(ROBOTS))
@pytest.mark.parametrize("reference", REFERENCES)
def test_hessian_matches_finite_differences_of_the_jacobian(name, reference):
    robot = ROBOTS[name]
    frames = [robot.tool, robot.body_names[len(robot.body_names) // 2]]
    for q in robot.random_configuration(RNG, size=2):
        for frame in frames:
            H = robot.jacobian_hessian(q, frame, reference)
            assert H.shape == (robot.n, 6, robot.n)
            np.testing.assert_allclose(H, fd_hessian(robot, q, frame, reference), atol=1e-6)


@pytest.mark.parametrize("reference", REFERENCES)
def test_hessian_of_example_robot_data_urdfs(reference):
    for name, robot in urdf_robots().items():
        q = robot.random_configuration(RNG)
        point = np.array([0.05, -0.02, 0.1])
        np.testing.assert_allclose(
            robot.jacobian_hessian(q, reference=reference),
            fd_hessian(robot, q, None, reference),
            atol=1e-6,
            err_msg=name,
        )
        np.testing.assert_allclose(
            robot.jacobian_hessian(q, reference=reference, point=point),
            fd_hessian(robot, q, None, reference, point),
            atol=1e-6,
            err_msg=name,
        )


@pytest.mark.parametrize("name", ["puma560", "stanford", "ur5", "cartesian_2p"])
@pytest.mark.parametrize("reference", REFERENCES)
def test_hessian_contracted_with_qd_twice_is_the_acceleration_drift(name, reference):
    """sum_ij H[i, :, j] qd_i qd_j = dJ/dt qd, computed by the recursive acceleration pass."""
    robot = ROBOTS[name]
    q = robot.random_configuration(RNG)
    qd = RNG.normal(size=robot.n)
    H = robot.jacobian_hessian(q, reference=reference)
    np.testing.assert_allclose(
        np.einsum("i,irj,j->r", qd, H, qd), robot.jacobian_dot_qd(q, qd, reference=reference), atol=1e-10
    )


# RTB's cross-product definition is for revolute joints only
@pytest.mark.parametrize("name", [name for name, r in ROBOTS.items() if all(j.kind == "revolute" for j in r.joints)])
def test_world_hessian_is_rtb_hessian0_and_frame_axes_is_rtb_hessiane(name):
    robot = ROBOTS[name]
    q = robot.random_configuration(RNG)
    np.testing.assert_allclose(robot.jacobian_hessian(q), rtb_hessian_definition(robot.jacobian(q)), atol=1e-12)
    np.testing.assert_allclose(
        kin.hessian_in_frame_axes(robot, q), rtb_hessian_definition(robot.jacobian(q, reference="local")), atol=1e-12
    )


def test_rtb_hessians_of_the_ur5_and_panda_urdfs():
    for name, robot in urdf_robots().items():
        q = robot.random_configuration(RNG)
        np.testing.assert_allclose(
            robot.jacobian_hessian(q), rtb_hessian_definition(robot.jacobian(q)), atol=1e-12, err_msg=name
        )
        np.testing.assert_allclose(
            kin.hessian_in_frame_axes(robot, q),
            rtb_hessian_definition(robot.jacobian(q, reference="local")),
            atol=1e-12,
            err_msg=name,
        )


def test_hessian_in_frame_axes_is_not_the_derivative_of_the_local_jacobian():
    """RTB's hessiane is the world Hessian turned into the tool's axes; the derivative of the local
    Jacobian also carries the turning of those axes (both documented)."""
    robot = ROBOTS["planar_2r"]
    q = np.array([0.3, 0.9])
    He = kin.hessian_in_frame_axes(robot, q)
    Hl = robot.jacobian_hessian(q, reference="local")
    R = robot.pose(q)[:3, :3]
    H0 = robot.jacobian_hessian(q)
    np.testing.assert_allclose(He[:, :3], np.einsum("ba,ibj->iaj", R, H0[:, :3]), atol=1e-12)
    # planar 2R, local axes: the tip's velocity from joint 2 is l2 along the tool's y at every q,
    # and joint 1's column turns only with q2: dJ_local/dq1 = 0
    np.testing.assert_allclose(Hl[0], 0.0, atol=1e-12)
    assert np.abs(He[0]).max() > 0.1


def test_hessian_takes_batches_and_task_rows():
    robot = ROBOTS["puma560"]
    qs = robot.random_configuration(RNG, size=4)
    H = robot.jacobian_hessian(qs, reference="local")
    assert H.shape == (4, 6, 6, 6)
    for k in range(4):
        np.testing.assert_allclose(H[k], robot.jacobian_hessian(qs[k], reference="local"), atol=0)
    Hp = kin.jacobian_hessian(robot, qs, task="position")
    np.testing.assert_array_equal(Hp, robot.jacobian_hessian(qs)[..., :3, :])
    He = kin.hessian_in_frame_axes(robot, qs)
    for k in range(4):
        np.testing.assert_allclose(He[k], kin.hessian_in_frame_axes(robot, qs[k]), atol=1e-15)


def test_hessian_bad_inputs_give_clear_errors():
    robot = ROBOTS["planar_2r"]
    with pytest.raises(ValueError, match="unknown frame 'nope'"):
        robot.jacobian_hessian([0, 0], "nope")
    with pytest.raises(ValueError, match="reference must be one of"):
        robot.jacobian_hessian([0, 0], reference="base")
    with pytest.raises(ValueError, match=r"q must have shape \(2,\)"):
        robot.jacobian_hessian([0, 0, 0])
    with pytest.raises(ValueError, match="q"):
        robot.jacobian_hessian([0, np.nan])
    # a frame fixed to the base does not move: its Jacobian and Hessian are zero
    np.testing.assert_array_equal(robot.jacobian_hessian([0.3, 0.4], "base"), np.zeros((2, 6, 2)))


# ------------------------------------------------------------------ manipulability Jacobian (RTB's jacobm)
def fd_manipulability_gradient(robot, q, task, h=1e-6):
    g = np.zeros(robot.n)
    for i in range(robot.n):
        dq = np.zeros(robot.n)
        dq[i] = h
        g[i] = (kin.manipulability(robot, q + dq, task=task) - kin.manipulability(robot, q - dq, task=task)) / (2 * h)
    return g


def rtb_jacobm_definition(J, H):
    """RTB's ETS.jacobm: Jm[i] = w vec(J H_i^T) . vec((J J^T)^-1), with w = sqrt(det(J J^T))."""
    b = np.linalg.inv(J @ J.T)
    w = np.sqrt(np.linalg.det(J @ J.T))
    return np.array([w * (J @ H[i].T).flatten("F") @ b.flatten("F") for i in range(H.shape[0])])


@pytest.mark.parametrize(
    "name,task",
    [
        ("puma560", "full"),
        ("puma560", "position"),
        ("stanford", "full"),
        ("elbow_3r", "position"),
        ("planar_2r", "planar"),
        ("ur5", "full"),
        ("planar_3r", "planar"),
    ],
)
def test_manipulability_jacobian_matches_finite_differences_and_rtb_definition(name, task):
    robot = ROBOTS[name]
    rows = kin.task_rows(task)
    for q in robot.random_configuration(RNG, size=3):
        g = kin.manipulability_jacobian(robot, q, task=task)
        np.testing.assert_allclose(g, fd_manipulability_gradient(robot, q, task), atol=1e-6)
        J = robot.jacobian(q)[rows]
        np.testing.assert_allclose(g, rtb_jacobm_definition(J, fd_hessian(robot, q)[:, rows]), atol=1e-6)


def test_manipulability_jacobian_of_the_2r_arm_in_closed_form():
    """w = l1 l2 |sin q2| (Spong §4.12): dw/dq = (0, l1 l2 cos q2 sign(sin q2))."""
    l1, l2 = 2.0, 3.0
    robot = kd.robots.planar_2r(l1=l1, l2=l2)
    for q in ([0.3, 0.7], [-1.0, -2.0], [2.0, 2.9]):
        expected = [0.0, l1 * l2 * np.cos(q[1]) * np.sign(np.sin(q[1]))]
        np.testing.assert_allclose(kin.manipulability_jacobian(robot, q, task="planar"), expected, atol=1e-12)


def test_manipulability_jacobian_batches_singularities_and_wide_tasks():
    robot = ROBOTS["planar_2r"]
    qs = np.array([[0.1, 0.5], [0.2, -1.0], [0.3, 2.0]])
    g = kin.manipulability_jacobian(robot, qs, task="planar")
    assert g.shape == (3, 2)
    for k in range(3):
        np.testing.assert_allclose(g[k], kin.manipulability_jacobian(robot, qs[k], task="planar"), atol=0)
    # at q2 = 0, w = l1 l2 |sin q2| has a kink: no derivative, a clear error (never NaN)
    with pytest.raises(
        ValueError,
        match=r"w = sqrt\(det\(J J\^T\)\) is 0 at q = \[0\.3 0\. \] \(configuration 1 of the batch\) and has no derivative",
    ):
        kin.manipulability_jacobian(robot, [[0.1, 0.5], [0.3, 0.0]], task="planar")
    # more task rows than joints: w = 0 everywhere, so is its gradient
    np.testing.assert_array_equal(kin.manipulability_jacobian(robot, [0.1, 0.5], task="full"), np.zeros(2))
    # two zero singular values: w ~ s_1 s_2 s_3 with two factors 0 is flat to first order, gradient 0.
    # The anthropomorphic arm stretched straight up its first axis is shoulder- and elbow-singular:
    # joint 1 does not move the tip, joints 2 and 3 move it the same way.
    arm = ROBOTS["elbow_3r"]
    q = np.array([0.4, np.pi / 2, 0.0])
    s = np.linalg.svd(arm.jacobian(q)[:3], compute_uv=False)
    assert np.sum(s < 1e-9) == 2
    np.testing.assert_allclose(kin.manipulability_jacobian(arm, q, task="position"), np.zeros(3), atol=1e-12)


def test_hessian_equals_pinocchios_kinematic_hessian():
    """Pinocchio (an optional oracle) stores H[:, :, i] = dJ/dq_i of a joint frame, (6, n, n), for
    WORLD (our "spatial"), LOCAL ("local") and LOCAL_WORLD_ALIGNED ("world"). pin 4.1's binding hands
    the column-major tensor over as a C-ordered array; the test reads the buffer both ways and
    requires one reading to equal ours to rounding (a fixed binding reads the other way)."""
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is an optional test oracle")
    path = erd(*PANDA)
    locked = {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02}
    robot = kd.Robot.from_urdf(path).lock_joints(locked)
    model = pin.buildModelFromUrdf(path)
    q_ref = pin.neutral(model)
    for name, value in locked.items():
        q_ref[model.joints[model.getJointId(name)].idx_q] = value
    model = pin.buildReducedModel(model, [model.getJointId(name) for name in locked], q_ref)
    data = model.createData()
    n = robot.n
    assert model.nv == n == 7
    q = robot.random_configuration(RNG)
    pin.computeJointJacobians(model, data, q)
    pin.computeJointKinematicHessians(model, data, q)
    for jid in (3, n):  # a mid-chain joint frame and the last
        body = robot.tree.bodies[jid - 1].name
        assert model.names[jid] == robot.tree.bodies[jid - 1].joint.name
        for reference, frame in (("spatial", pin.WORLD), ("local", pin.LOCAL), ("world", pin.LOCAL_WORLD_ALIGNED)):
            raw = np.asarray(pin.getJointKinematicHessian(model, data, jid, frame))
            readings = [raw.reshape(-1).reshape((6, n, n), order=order) for order in ("F", "C")]
            ours = np.transpose(robot.jacobian_hessian(q, body, reference), (1, 2, 0))  # [r, j, i]
            errors = [np.abs(h - ours).max() for h in readings]
            assert min(errors) < 1e-10, f"joint {jid} {reference}: {errors}"
