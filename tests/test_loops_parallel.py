"""Parallel robots from the example files: the Delta robot (ball joints, five point loops) and the
push-rod leg (a loop on a floating base) against Pinocchio's constraintDynamics; the Delta's forward
kinematics from its motor angles against the intersection of three spheres (derived below)."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd

pin = pytest.importorskip("pinocchio")

ROBOTS = Path(__file__).resolve().parents[1] / "examples" / "robots"
MOTORS = ["arm1", "arm2", "arm3"]


def delta() -> kd.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # MuJoCo's softness is not modelled: the loader says so
        return kd.load(ROBOTS / "delta.xml")


def pinocchio_delta(tmp_path):
    """Pinocchio's model and its <connect> constraints of the same file. Its MJCF reader keeps only
    the first body under <worldbody>, so the three arms hang under one body without a joint."""
    text = (ROBOTS / "delta.xml").read_text()
    text = text.replace("<worldbody>", '<worldbody><body name="hang">', 1).replace(
        "</worldbody>", "</body></worldbody>"
    )
    path = tmp_path / "delta_hung.xml"
    path.write_text(text)
    model, constraints = pin.buildModelAndLegacyConstraintsFromMJCF(os.fspath(path))
    return model, list(constraints)


def pinocchio_solve(model, constraints, q, qd, tau):
    """qdd, and each loop's force on its first body in base axes (Pinocchio's LOCAL is that body's
    constraint frame)."""
    data = model.createData()
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    for constraint in constraints:
        models.append(constraint)
        datas.append(constraint.createData())
    pin.initConstraintDynamics(model, data, models, datas)
    qdd = pin.constraintDynamics(model, data, q, qd, tau, models, datas, pin.ProximalSettings(1e-14, 1e-10, 100))
    pin.forwardKinematics(model, data, q)
    forces = []
    for k, constraint in enumerate(constraints):
        rot = (data.oMi[constraint.joint1_id] * constraint.joint1_placement).rotation
        forces.extend(rot @ data.lambda_c[3 * k : 3 * k + 3])
    return qdd.copy(), np.array(forces)


def closed_state(robot, hold, seed, spread=0.3):
    rng = np.random.default_rng(seed)
    q = robot.project_configuration(robot.integrate(robot.neutral(), rng.uniform(-spread, spread, robot.n)), hold=hold)
    qd = robot.project_velocity(q, rng.uniform(-1, 1, robot.n))
    return q, qd, rng


def test_delta_constrained_forward_dynamics_matches_pinocchio(tmp_path):
    robot = delta()
    model, constraints = pinocchio_delta(tmp_path)
    assert (model.nq, model.nv, len(constraints)) == (robot.nq, robot.n, len(robot.loops))
    motors = [model.joints[model.getJointId(name)].idx_v for name in MOTORS]
    for seed in range(4):
        q, qd, rng = closed_state(robot, MOTORS, seed)
        jac = robot.loop_jacobian(q)
        assert np.abs(robot.loop_residual(q)).max() < 1e-12
        assert np.abs(jac @ qd).max() < 1e-12
        # the motors drive, the ball joints are passive. (A torque on a ball joint spins its thin
        # rod about its own axis, inertia ~1e-7 kg m^2: accelerations of 1e6 whose last digits
        # neither solver can promise.)
        tau = np.zeros(robot.n)
        tau[motors] = rng.uniform(-2, 2, 3)
        qdd, lam = robot.constrained_forward_dynamics(q, qd, tau)
        qdd_pin, lam_pin = pinocchio_solve(model, constraints, q, qd, tau)
        assert np.allclose(qdd, qdd_pin, rtol=0, atol=1e-9), np.abs(qdd - qdd_pin).max()
        assert np.allclose(jac.T @ lam, jac.T @ lam_pin, rtol=0, atol=1e-8)
        assert np.abs(jac @ qdd + robot.loop_gamma(q, qd)).max() < 1e-8


def test_pushrod_leg_on_its_floating_base_matches_pinocchio():
    """The leg's trunk is free; Pinocchio reads the URDF's floating joint as its free-flyer (the
    same q and v layout as kinedyn's) and a continuous joint as (cos, sin); the loop, a kinedyn
    extension Pinocchio skips, is built by hand from the file's two link points."""
    path = ROBOTS / "pushrod_leg.urdf"
    robot = kd.load(path)
    model = pin.buildModelFromXML(path.read_text())

    def point(link, xyz):
        frame = model.frames[model.getFrameId(link)]
        return frame.parentJoint, frame.placement * pin.SE3(np.eye(3), np.array(xyz, float))

    (joint_a, at_a), (joint_b, at_b) = point("push_rod", [0, 0, -0.3]), point("shank", [0.05, 0, 0])
    loop = pin.RigidConstraintModel(
        pin.ContactType.CONTACT_3D, model, joint_a, at_a, joint_b, at_b, pin.ReferenceFrame.LOCAL
    )

    def to_pinocchio(q):
        out, at = [], 0
        for joint in model.joints[1:]:
            width = 7 if joint.nq == 7 else 1
            x = q[at : at + width]
            at += width
            out.extend([np.cos(x[0]), np.sin(x[0])] if joint.nq == 2 else x)
        return np.array(out)

    for seed in range(3):
        q, qd, rng = closed_state(robot, ["root", "hip", "knee"], seed, spread=0.6)
        assert np.abs(robot.loop_residual(q)).max() < 1e-11
        tau = np.r_[np.zeros(6), rng.uniform(-2, 2, robot.n - 6)]  # nothing pushes the trunk
        qdd, _ = robot.constrained_forward_dynamics(q, qd, tau)
        qdd_pin, _ = pinocchio_solve(model, [loop], to_pinocchio(q), qd, tau)
        assert np.abs(qdd).max() > 1.0  # a real motion, not a resting one
        assert np.allclose(qdd, qdd_pin, rtol=0, atol=1e-9), np.abs(qdd - qdd_pin).max()


# The Delta's geometry as its file's comment states it (base radius 0.2, platform radius 0.05, upper
# arms 0.3 at 15.7 degrees below horizontal at angle 0, rods 0.8; arms at 0, 120, 240 degrees about z,
# each turning about its own y axis, so that a positive angle lowers it).
BASE, PLATFORM, UPPER, ROD = 0.2, 0.05, 0.3, 0.8
DROP = np.arctan2(0.0810993756978, 0.288830211822)


def delta_platform_closed_form(angles) -> np.ndarray:
    """The platform centre from the three motor angles: each parallelogram keeps the platform's
    axes, so the midpoint of arm i's rod ends is the platform centre plus PLATFORM u_i (u_i its radial
    direction), a rod length from the elbow E_i. The centre P lies on the three spheres
    |P - (E_i - PLATFORM u_i)| = ROD. Subtracting the first sphere from the others leaves two planes
    2 (c_i - c_1) . P = |c_i|^2 - |c_1|^2, whose line P0 + t n (n = (c_2 - c_1) x (c_3 - c_1)) meets
    the first sphere where |P0 + t n - c_1|^2 = ROD^2, a quadratic in t; the platform hangs below, the
    root of lower z."""
    centres = []
    for k, theta in enumerate(angles):
        phi = 2 * np.pi * k / 3
        u = np.array([np.cos(phi), np.sin(phi), 0.0])
        elbow = BASE * u + UPPER * (np.cos(DROP + theta) * u - np.sin(DROP + theta) * np.array([0, 0, 1.0]))
        centres.append(elbow - PLATFORM * u)
    c1, c2, c3 = centres
    n = np.cross(c2 - c1, c3 - c1)
    a = np.array([2 * (c2 - c1), 2 * (c3 - c1), n])
    p0 = np.linalg.solve(a, [c2 @ c2 - c1 @ c1, c3 @ c3 - c1 @ c1, n @ c1])  # the point of the line in c_1's plane
    d = p0 - c1
    qa, qb, qc = n @ n, 2 * n @ d, d @ d - ROD**2
    roots = (-qb + np.array([1.0, -1.0]) * np.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    points = p0 + roots[:, None] * n
    return points[np.argmin(points[:, 2])]


@pytest.mark.parametrize("angles", [(0.0, 0.0, 0.0), (0.3, -0.2, 0.5), (-0.4, 0.6, 0.1), (0.8, 0.7, -0.3)])
def test_delta_forward_kinematics_from_its_motors_is_the_three_spheres(angles):
    robot = delta()
    start = robot.neutral()
    columns = {name: np.flatnonzero(np.isfinite(robot.lower_limits))[k] for k, name in enumerate(MOTORS)}  # the hinges'
    for name, angle in zip(MOTORS, angles, strict=True):
        start[columns[name]] = angle
    q = robot.project_configuration(start, hold=MOTORS)
    assert np.allclose(q[list(columns.values())], angles, rtol=0, atol=1e-15)  # held
    assert np.abs(robot.loop_residual(q)).max() < 1e-12
    platform, tcp = robot.frame_poses(q, ["platform", "tcp"])
    assert np.allclose(platform[:3, 3], delta_platform_closed_form(angles), rtol=0, atol=1e-10)
    assert np.allclose(platform[:3, :3], np.eye(3), atol=1e-10)  # the parallelograms keep it level
    assert np.allclose(tcp[:3, 3], platform[:3, 3] - [0, 0, 0.02], atol=1e-12)


def test_inverse_kinematics_of_the_delta_closes_the_loops_and_finds_the_motor_angles():
    """Inverse of the above: the tool point from the closed form, back to the motor angles; the
    answer closes every loop (the tree's solvers would leave them open)."""
    robot = delta()
    motors = np.flatnonzero(np.isfinite(robot.lower_limits))
    for angles in [(0.3, -0.2, 0.5), (-0.4, 0.6, 0.1)]:
        target = delta_platform_closed_form(angles) - [0, 0, 0.02]
        result = robot.inverse_kinematics(target, frame="tcp")
        assert result.success and result.solver == "numeric:closed-chain", result
        assert np.abs(robot.loop_residual(result.q)).max() < 1e-9
        assert np.allclose(robot.frame_poses(result.q, ["tcp"])[0][:3, 3], target, atol=1e-9)
        assert np.allclose(result.q[motors], angles, atol=1e-8)  # the Delta's inverse problem is unique on its branch


def test_inverse_kinematics_on_loops_refuses_what_it_cannot_do():
    robot = delta()
    with pytest.raises(ValueError, match="closed loops.*no closed-form"):
        robot.inverse_kinematics([0.0, 0.0, -0.8], frame="tcp", method="analytic")
    with pytest.raises(ValueError, match=r"closed loops.*does not take \[.all_branches.\]"):
        robot.inverse_kinematics([0.0, 0.0, -0.8], frame="tcp", all_branches=True)
    with pytest.raises(ValueError, match=r"closed loops.*a batch of them.*got shape \(2, 2\)"):
        robot.inverse_kinematics(np.zeros((2, 2)), frame="tcp")  # a batch is solved: tests/test_loops_ik.py
    far = robot.inverse_kinematics([0.0, 0.0, -3.0], frame="tcp")  # beyond the rods' reach
    assert not far.success and len(far) == 0 and "did not converge" in far.message


# ----------------------------------------------------------------------------- properties of the reduced model
@pytest.mark.parametrize(
    "name", ["four_bar.yaml", "five_bar.yaml", "parallelogram_arm.urdf", "pushrod_leg.urdf", "delta.xml"]
)
def test_the_numeric_checks_run_on_the_reduced_model_at_closed_states(name):
    """Measured (30 samples): largest residual 2e-12 (four-bar) to 1.6e-8 (the Delta, ball joints: the
    rods' spins carry inertia of 1e-7); a transposed C fails the bias check (2e-1, 2)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the Delta's MJCF softness, not modelled
        robot = kd.load(ROBOTS / name)
    report = kd.analysis.check_properties(robot, samples=30)
    assert report.passed, report
    names = [check.name for check in report.checks]
    assert names == [
        "M_r symmetric positive definite",
        "dM_r/dt - 2C_r skew-symmetric",
        "dM_r/dt == C_r + C_r^T",
        "C_r qd_i == reduced bias",
        "energy balance dH/dt == qd . (tau - friction)",
    ]
    assert all(check.residual < 1e-7 for check in report.checks), [(c.name, c.residual) for c in report.checks]
    assert report.checks[0].data["min_eigenvalue"] > 0


def test_reduced_dynamics_counts_the_rank_at_the_closures_accuracy():
    """The parallelogram arm's loop is planar and turns with the yaw: where the loop is closed to 1e-13
    rather than exactly, the yaw's column of J is 1e-13, not zero; the mechanism still has 3 degrees
    of freedom, and G (qd = G qd_i) stays of order one."""
    robot = kd.load(ROBOTS / "parallelogram_arm.urdf")
    rng = np.random.default_rng(0)
    for _ in range(8):
        q = robot.project_configuration(robot.random_configuration(rng))
        reduced = robot.reduced_dynamics(q, np.ones(3))
        assert len(reduced["independent"]) == 3
        assert np.abs(reduced["G"]).max() < 1e3
        assert np.abs(robot.loop_jacobian(q) @ reduced["qd"]).max() < 1e-9


def test_the_checks_refuse_a_closed_chain_without_freedom_and_the_command_line_runs_them(capsys):
    """A weld at the four-bar's pin leaves it no degree of freedom (or no closed configuration): refused
    by name. The Delta (ball joints) runs from the command line."""
    from kinedyn.cli import main

    four_bar = kd.load(ROBOTS / "four_bar.yaml")
    loop = four_bar.loops[0]
    welded = four_bar.replace(loops=()).add_loop(loop.frame_a, loop.frame_b, kind="weld")
    with pytest.raises(ValueError, match="closed loops"):
        kd.analysis.check_properties(welded, samples=5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the Delta's MJCF softness, not modelled
        assert main(["check", os.fspath(ROBOTS / "delta.xml"), "--samples", "10", "--json"]) == 0
    out = capsys.readouterr().out
    assert "dM_r/dt - 2C_r skew-symmetric" in out and "energy balance" in out
