"""Inverse kinematics of a batch of targets on a closed chain (docs/closed-loops.md, "Parallel
robots"): one call, the Gauss-Newton iterations on every target at once, warm starts along the batch
for the targets not reached from q0, and the targets out of reach reported one by one."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd

FIVE_BAR = Path(__file__).resolve().parents[1] / "examples" / "robots" / "five_bar.yaml"


@pytest.fixture(scope="module")
def path():
    """Spong's five-bar and the tool's positions along a path of its motors (q1, q2), on the
    parallelogram branch (q3 = q1 - q2, q4 = q2 - q1: the file's closed form), and the start."""
    robot = kd.load(str(FIVE_BAR))
    t = np.linspace(0.0, 1.0, 60)
    q1, q2 = 0.2 + 1.5 * t, 1.0 + 1.2 * np.sin(3 * t)
    q = np.stack([q1, q2 - q1, q2, q1 - q2], axis=1)
    assert np.abs(robot.loop_residual(q)).max() < 1e-12
    targets = robot.frame_poses(q, ["tool"])[:, 0, :3, 3]
    return robot, targets, q


def closes_and_reaches(robot, q, targets):
    return (
        np.abs(robot.loop_residual(q)).max(axis=1) < 1e-9,
        np.linalg.norm(robot.frame_poses(q, ["tool"])[:, 0, :3, 3] - targets, axis=1) < 1e-9,
    )


def test_a_batch_closes_every_loop_reaches_every_target_and_reports_the_unreachable(path):
    robot, targets, q = path
    q0, targets = q[0], targets.copy()
    unreachable = [7, 19]
    targets[7] = [3.0, 0.0, 0.0]  # beyond the arm's 1.2 m
    targets[19] = [0.0, 0.0, 0.5]  # off the arm's plane
    result = robot.inverse_kinematics(targets, q0)
    assert isinstance(result, kd.ik.IKBatchResult) and result.solver == "numeric:closed-chain"
    assert result.q.shape == (60, 4) and np.all(np.isfinite(result.q))
    expected = np.ones(60, dtype=bool)
    expected[unreachable] = False
    np.testing.assert_array_equal(result.success, expected)
    closed, reached = closes_and_reaches(robot, result.q[expected], targets[expected])
    assert closed.all() and reached.all()
    for k in unreachable:  # said per target, with what was left
        assert (
            result.extra["message"][k].startswith("did not converge") and "frame off by" in result.extra["message"][k]
        )
    assert result.extra["message"][0] == "converged"
    np.testing.assert_allclose(result.extra["closure"], np.abs(robot.loop_residual(result.q)).max(axis=1))
    # the targets reached from q0 get the answer of a single call from q0 (the iterations, vectorised)
    for k in (0, 12, 59):
        single = robot.inverse_kinematics(targets[k], q0)
        assert single.success
        np.testing.assert_allclose(result.q[k], single.q, atol=1e-12)


def test_a_batch_is_warm_started_along_the_path(path):
    """With few iterations, single calls from q0 do not reach the far end of the path; the batch
    reaches every target, each from its neighbour's solution; a start per target (N, nq) is taken."""
    robot, targets, q = path
    q0 = q[0]
    singles = [robot.inverse_kinematics(x, q0, max_iterations=5).success for x in targets]
    assert not all(singles)
    result = robot.inverse_kinematics(targets, q0, max_iterations=5)
    assert result.success.all()
    closed, reached = closes_and_reaches(robot, result.q, targets)
    assert closed.all() and reached.all()
    # the path's own configurations as starts (N, nq): each already solves its target
    own = robot.inverse_kinematics(targets, q)
    assert own.success.all() and not own.iterations.any()
    np.testing.assert_array_equal(own.q, q)
    with pytest.raises(ValueError, match=r"q0 must have shape \(4,\) or \(60, 4\)"):
        robot.inverse_kinematics(targets, np.zeros((59, 4)))
