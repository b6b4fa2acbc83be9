"""Seven-joint arms in closed form (issue 28): a held joint or the arm angle as the redundancy
parameter, every branch for one value, the self-motion manifold along a sweep, the statement of
completeness every result carries, and many targets in one native call.

Every returned branch is checked by the robot's forward kinematics (an algorithm independent of
the subproblems that produced it); the held joint must keep its value; the arm angle of each
branch, recomputed from its joint vector, must be the one asked for; and the configuration a
target came from must be among the branches."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.testing import example_robot_data_dir

pytest.importorskip("kinedyn._core", reason="the native module is not built")

TWO_PI = 2 * np.pi


def iiwa_robot():
    pybullet_data = pytest.importorskip("pybullet_data", reason="pybullet_data ships the KUKA iiwa URDF")
    path = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"
    if not path.exists():
        pytest.skip("pybullet_data has no kuka_iiwa/model.urdf")
    return kd.load(str(path))


def panda_robot():
    path = Path(example_robot_data_dir() or "/nonexistent") / "panda_description/urdf/panda.urdf"
    if not path.exists():
        pytest.skip("example-robot-data is not installed (no panda.urdf)")
    return kd.Robot.from_urdf(str(path)).lock_joints({"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0})


@pytest.fixture(scope="module")
def iiwa():
    return iiwa_robot()


@pytest.fixture(scope="module")
def panda():
    return panda_robot()


def wrapped(d):
    return d - TWO_PI * np.round(d / TWO_PI)


def contains(solutions, q, atol=1e-7) -> bool:
    return any(np.abs(wrapped(s - q)).max() < atol for s in solutions)


def assert_reaches(robot, solutions, target, frame=None, atol=1e-9):
    assert len(solutions)
    for s in solutions:
        T = robot.pose(s, frame)
        assert np.abs(T - target).max() < atol, (s, T, target)


def targets(robot, count, seed, frame=None):
    Q = robot.random_configuration(np.random.default_rng(seed), size=count)
    return Q, robot.pose(Q, frame)


# ------------------------------------------------------------------ the arm angle (SRS)
def test_iiwa_every_arm_angle_branch_reaches_the_target(iiwa):
    Q, T = targets(iiwa, 20, 0)
    for q, t in zip(Q, T):
        psi = kd.ik.arm_angle(iiwa, q)
        r = iiwa.inverse_kinematics(t, redundancy={"arm_angle": psi}, respect_limits=False)
        assert r.success and r.structure == "srs_arm_angle" and r.max_solutions == 8
        assert r.found == len(r.solutions) == 8, r.completeness
        assert_reaches(iiwa, r.solutions, t)
        assert contains(r.solutions, q), "the configuration the target came from is a branch"
        for s in r.solutions:  # every branch has the arm angle asked for
            assert abs(wrapped(kd.ik.arm_angle(iiwa, s) - psi)) < 1e-9
        assert r.worst_residual < 1e-9
        assert "8 of at most 8" in r.completeness
        within = iiwa.inverse_kinematics(t, redundancy={"arm_angle": psi})
        assert contains(within.solutions, q)
        for s in within.solutions:
            assert np.all(s >= iiwa.lower_limits - 1e-12) and np.all(s <= iiwa.upper_limits + 1e-12)


def test_iiwa_held_joint_keeps_its_value(iiwa):
    Q, T = targets(iiwa, 10, 1)
    for joint in (0, 2, 6):
        name = iiwa.joint_names[joint]
        for q, t in zip(Q, T):
            r = iiwa.inverse_kinematics(t, redundancy={"joint": name, "value": q[joint]}, respect_limits=False)
            assert r.solver.startswith("analytic:held"), r.solver
            assert 0 < len(r.solutions) <= r.max_solutions == 8
            assert np.all(r.solutions[:, joint] == q[joint])
            assert_reaches(iiwa, r.solutions, t)
            assert contains(r.solutions, q)


@pytest.fixture(scope="module")
def iiwa_sweep(iiwa):
    """(q, target, the arm-angle sweep of 1441 samples at the target), shared by two tests."""
    q = np.array([0.4, 0.7, -0.5, 1.2, 0.3, -0.8, 0.6])
    t = iiwa.pose(q)
    return q, t, kd.ik.self_motion(iiwa, t, samples=1441)


def test_iiwa_self_motion_is_continuous_and_reaches_the_target(iiwa, iiwa_sweep):
    q, t, sm = iiwa_sweep
    assert sm.q.shape == (1441, 8, 7) and sm.parameter == "arm_angle"
    step = sm.values[1] - sm.values[0]
    for b in range(sm.branches):
        rows = sm.q[:, b]
        ok = np.isfinite(rows).all(axis=1)
        assert ok.mean() > 0.9
        assert_reaches(iiwa, rows[ok][::40], t)
        both = ok[1:] & ok[:-1]
        jumps = np.abs(np.diff(rows, axis=0)[both]).max(axis=1)
        # continuous: a step in psi moves each joint by a bounded multiple of it (no branch swaps)
        assert jumps.max() < 60 * step, (b, jumps.max())
    # the original configuration lies on the manifold at its own arm angle
    psi = kd.ik.arm_angle(iiwa, q)
    m = np.argmin(np.abs(wrapped(sm.values - psi)))
    assert np.abs(wrapped(sm.q[m] - q)).max(axis=1).min() < 20 * step


def test_iiwa_arm_angle_limit_intervals(iiwa):
    q = np.array([0.4, 0.7, -0.5, 1.2, 0.3, -0.8, 0.6])
    t = iiwa.pose(q)
    sm = kd.ik.self_motion(iiwa, t, samples=181)
    lo, hi = iiwa.lower_limits, iiwa.upper_limits

    def branch_at(psi, near):
        """The branch's joint vector at psi: the solution there nearest its sample `near`."""
        r = iiwa.inverse_kinematics(t, redundancy={"arm_angle": psi}, respect_limits=False)
        return r.solutions[np.argmin(np.abs(wrapped(r.solutions - near)).max(axis=1))]

    def inside(s):
        return bool(np.all(s >= lo - 1e-9) and np.all(s <= hi + 1e-9))

    ends = 0
    for b in range(sm.branches):
        for a, z in sm.intervals(b):
            assert a <= z
            for end, outward in ((a, -1e-6), (z, 1e-6)):
                if end in (sm.values[0], sm.values[-1]):
                    continue  # the sweep's own end, not a limit
                m = int(np.argmin(np.abs(sm.values - end)))
                near = sm.q[m, b] if np.isfinite(sm.q[m, b]).all() else sm.q[m - int(np.sign(outward)), b]
                at = branch_at(end, near)
                assert inside(at), (b, end)
                assert not inside(branch_at(end + outward, at)), (b, end)
                ends += 1
    assert ends > 0


def test_iiwa_arm_angle_intervals_are_a_dense_sampling_s(iiwa, iiwa_sweep):
    # the closed-form intervals against the runs of a dense sampling's inside flags, to one step;
    # a coarse sweep gets the same intervals (they do not depend on the samples)
    _, t, dense = iiwa_sweep
    coarse = kd.ik.self_motion(iiwa, t, samples=7)
    step = dense.values[1] - dense.values[0]
    ends = 0
    for b in range(dense.branches):
        exact = dense.intervals(b)
        assert exact == coarse.intervals(b)
        member = np.zeros(len(dense.values), bool)
        near = np.zeros(len(dense.values), bool)
        for a, z in exact:
            member |= (dense.values >= a) & (dense.values <= z)
            near |= (np.abs(dense.values - a) < step) | (np.abs(dense.values - z) < step)
            ends += sum(-np.pi < e < np.pi for e in (a, z))
        assert np.array_equal(member[~near], dense.inside[~near, b]), b
    assert ends >= 4


# ------------------------------------------------------------------ Panda: a held joint
def test_panda_held_last_joint_is_a_reversed_spherical_wrist(panda):
    frame = "panda_hand_tcp"
    Q, T = targets(panda, 20, 2, frame)
    for q, t in zip(Q, T):
        r = panda.inverse_kinematics(
            t, redundancy={"joint": "panda_joint7", "value": q[6]}, frame=frame, respect_limits=False
        )
        assert r.structure == "held[panda_joint7]+reversed_spherical_wrist", r.structure
        assert 0 < r.found <= r.max_solutions == 8
        assert np.all(r.solutions[:, 6] == q[6])
        assert_reaches(panda, r.solutions, t, frame)
        assert contains(r.solutions, q)


def test_panda_other_held_joints_use_the_general_6r(panda):
    # joints 2..7 of the Panda have no special structure from either end: the general 6R solves them
    frame = "panda_hand_tcp"
    q = np.array([0.3, -0.5, 0.2, -2.0, 0.4, 1.5, 0.7])
    t = panda.pose(q, frame)
    r = panda.inverse_kinematics(t, redundancy={"joint": "panda_joint1", "value": 0.3}, frame=frame)
    assert r.success and r.solver == "analytic:held[panda_joint1]+general_6r" and r.max_solutions == 16
    assert np.all(r.solutions[:, 0] == 0.3)
    assert np.min(np.max(np.abs(r.solutions - q), axis=1)) < 1e-8
    assert_reaches(panda, r.solutions, t, frame)
    with pytest.raises(ValueError, match="not an SRS arm"):
        panda.inverse_kinematics(t, redundancy={"arm_angle": 0.0}, frame=frame)


def test_panda_self_motion_along_the_last_joint(panda):
    frame = "panda_hand_tcp"
    q = np.array([0.3, -0.5, 0.2, -2.0, 0.4, 1.5, 0.7])
    t = panda.pose(q, frame)
    sm = kd.ik.self_motion(panda, t, parameter="panda_joint7", samples=401, frame=frame)
    assert sm.parameter == "panda_joint7"
    np.testing.assert_allclose(sm.values[[0, -1]], [panda.lower_limits[6], panda.upper_limits[6]])
    finite = np.isfinite(sm.q).all(axis=2)
    assert finite[::50].any(axis=1).sum() >= 4  # (with q7 held elsewhere the target can be out of reach)
    for m in range(0, 401, 50):
        rows = sm.q[m][finite[m]]
        assert np.all(rows[:, 6] == sm.values[m])
        if len(rows):
            assert_reaches(panda, rows, t, frame)
    at = kd.ik.self_motion(panda, t, parameter=6, values=np.array([0.7]), frame=frame)
    assert contains(at.q[0][np.isfinite(at.q[0]).all(axis=1)], q)


# ------------------------------------------------------------------ batches
def test_a_batch_with_one_value_per_target(iiwa):
    Q, T = targets(iiwa, 50, 3)
    psi = np.array([kd.ik.arm_angle(iiwa, q) for q in Q])
    b = iiwa.inverse_kinematics(T, redundancy={"arm_angle": psi}, respect_limits=False)
    assert isinstance(b, kd.ik.IKBranches) and len(b) == 50
    assert np.all(b.count == 8) and np.all(b.max_solutions == 8)
    for k in range(50):
        rows = b.solutions[k, : b.count[k]]
        assert_reaches(iiwa, rows, T[k])
        assert contains(rows, Q[k])
        assert np.all(np.isnan(b.solutions[k, b.count[k] :]))
    held = iiwa.inverse_kinematics(T, redundancy={"joint": 2, "value": Q[:, 2]}, respect_limits=False)
    for k in range(50):
        assert np.all(held.solutions[k, : held.count[k], 2] == Q[k, 2])


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_all_branches_of_a_batch_match_single_calls(name):
    robot = kd.robots.get(name)
    Q, T = targets(robot, 100, 4)
    q0 = Q + 0.1  # each target's own reference: the order and the 2 pi k of its solutions
    b = robot.inverse_kinematics(T, q0=q0, all_branches=True, respect_limits=False)
    assert b.solutions.shape[:2] == (100, 8)
    for k in range(100):
        one = robot.inverse_kinematics(T[k], q0=q0[k], respect_limits=False)
        rows = b.solutions[k, : b.count[k]]
        assert b.count[k] == len(one.solutions) == b.found[k]
        np.testing.assert_allclose(rows, one.solutions, atol=1e-12)
        assert contains(rows, Q[k])
        assert b.result(k).completeness == one.completeness.replace(one.solver, b.solver)


# ------------------------------------------------------------------ completeness
def test_the_statement_of_completeness():
    puma = kd.robots.puma560()
    q = np.array([0.3, 0.6, -0.5, 0.4, 0.9, -0.3])
    r = puma.inverse_kinematics(puma.pose(q), respect_limits=False)
    assert (r.structure, r.max_solutions, r.found) == ("spherical_wrist", 8, 8)
    assert not r.merged and r.worst_residual < 1e-12
    assert r.to_dict()["max_solutions"] == 8 and "8 of at most 8" in r.to_dict()["completeness"]
    # wrist axes 4 and 6 in line (theta_5 = 0 at the PUMA's DH offsets): branches merge
    flat = puma.inverse_kinematics(puma.pose(np.array([0.3, 0.6, -0.5, 0.4, 0.0, -0.3])), respect_limits=False)
    assert flat.merged and "merge" in flat.completeness
    # an elbow arm at the boundary of its workspace (stretched): two elbow branches become one
    elbow = kd.robots.elbow_3r()
    stretched = elbow.inverse_kinematics(elbow.pose(np.array([0.4, 0.3, 0.0]))[:3, 3], respect_limits=False)
    assert stretched.merged
    numeric = kd.robots.ur5().inverse_kinematics(kd.robots.ur5().pose(q), method="numeric")
    assert numeric.max_solutions is None and "states no bound" in numeric.completeness


# ------------------------------------------------------------------ errors
def test_bad_redundancy_arguments_are_named(iiwa):
    t = iiwa.pose(np.full(7, 0.3))
    with pytest.raises(ValueError, match="unknown joint"):
        iiwa.inverse_kinematics(t, redundancy={"joint": "elbow", "value": 0.1})
    with pytest.raises(ValueError, match="keys"):
        iiwa.inverse_kinematics(t, redundancy={"swivel": 0.1})
    with pytest.raises(ValueError, match="finite"):
        iiwa.inverse_kinematics(t, redundancy={"arm_angle": float("nan")})
    with pytest.raises(ValueError, match="finite"):
        iiwa.inverse_kinematics(t[None].repeat(2, 0), redundancy={"arm_angle": [0.1, np.inf]})
    with pytest.raises(ValueError, match="4x4 pose"):
        iiwa.inverse_kinematics(t[:3, 3], redundancy={"arm_angle": 0.1})
    with pytest.raises(ValueError, match="serial chain of 7"):
        kd.robots.ur5().inverse_kinematics(np.eye(4), redundancy={"arm_angle": 0.0})
    with pytest.raises(ValueError, match="no closed form"):
        arm7 = kd.Robot.from_dh([kd.DHRow(a=0.3 + 0.1 * i, alpha=0.4 * i + 0.2, d=0.05 * i) for i in range(7)])
        arm7.inverse_kinematics(np.eye(4)[None], all_branches=True)


# ------------------------------------------------------------------ the command line
def run_cli(argv, capsys):
    from kinedyn.cli import main

    code = main(argv)
    return code, capsys.readouterr().out


def test_cli_all_on_a_seven_joint_urdf(iiwa, capsys):
    import json

    pybullet_data = pytest.importorskip("pybullet_data")
    path = str(Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf")
    base = ["ik", path, "--xyz", "0.4", "0.2", "0.6", "--rpy", "3.0", "0.1", "0.2", "--all", "--ignore-limits"]
    code, out = run_cli([*base, "--json"], capsys)
    payload = json.loads(out)
    assert code == 0 and payload["count"] == 8 and payload["max_solutions"] == 8
    assert "arm_angle" in payload["redundancy"] and "8 of at most 8" in payload["completeness"]
    T = np.array(payload["target"])
    for q in payload["solutions"]:
        assert np.abs(iiwa.pose(np.array(q)) - T).max() < 1e-9
    code, out = run_cli([*base, "--hold", "lbr_iiwa_joint_3=0.2"], capsys)
    assert code == 0 and "held[lbr_iiwa_joint_3]+spherical_wrist: 8 of at most 8" in out
    code, out = run_cli([*base, "--arm-angle", "0.5", "--json"], capsys)
    payload = json.loads(out)
    assert payload["redundancy"] == {"arm_angle": 0.5}
    for q in payload["solutions"]:
        assert abs(wrapped(kd.ik.arm_angle(iiwa, np.array(q)) - 0.5)) < 1e-9
    code, out = run_cli(["ik", "ur5", "--xyz", "0.3", "0.2", "0.4", "--rpy", "3.1", "0", "0", "--all"], capsys)
    assert code == 0 and "three_parallel: 8 of at most 8 real solutions found" in out
