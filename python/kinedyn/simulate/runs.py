"""What the runners share: the progress bar over simulated time, the wall-clock budget, the
right-hand side (accelerations and their derivatives) of a system integrated from Python, and the
stacking of per-trajectory results into a batch."""

from __future__ import annotations

import time

import numpy as np

from .._ui.progress import Delayed

__all__ = ["TimeBar", "Deadline", "acceleration_fn", "derivatives_fn", "stack_runs"]


class TimeBar(Delayed):
    """Progress over simulated time: ``update(t)`` with the time reached."""

    def __init__(self, enabled: bool, t0: float, t1: float, label: str, delay: float):
        self.t0 = t0
        super().__init__(enabled, t1 - t0, label, "t = {task.completed:.3g} / {task.total:.3g} s", delay)

    def update(self, t: float) -> None:
        super().update(t - self.t0)


class Deadline:
    """A wall-clock budget shared by the trajectories of a run: ``expired()`` once it is spent; the
    first trajectory to stop sets ``step``, and the others stop there too."""

    def __init__(self, budget):
        self.budget = budget
        self.end = None if budget is None else time.perf_counter() + budget
        self.step = None

    def expired(self) -> bool:
        return self.end is not None and time.perf_counter() > self.end


def acceleration_fn(target, robot, fext_fn):
    if robot:
        if fext_fn is None:
            return lambda t, q, qd, tau: target.forward_dynamics(q, qd, tau)
        return lambda t, q, qd, tau: target.forward_dynamics(q, qd, tau, fext_fn(t, q, qd))
    return lambda t, q, qd, tau: target.accelerations(q, qd, tau)[0]


def derivatives_fn(target, robot, fext_fn):
    """(t, q, qd, tau) -> (dqdd/dq, dqdd/dqd, M^-1): analytical for robots, central differences of
    the accelerations for other mechanical systems."""
    if robot:
        if fext_fn is None:
            return lambda t, q, qd, tau: target.forward_dynamics_derivatives(q, qd, tau)
        return lambda t, q, qd, tau: target.forward_dynamics_derivatives(q, qd, tau, fext_fn(t, q, qd))
    accel = acceleration_fn(target, robot, fext_fn)

    def numeric(t, q, qd, tau):
        n = q.size
        out = []
        for which in range(3):
            D = np.zeros((n, n))
            for j in range(n):
                args = [q.copy(), qd.copy(), np.array(tau, dtype=float)]
                h = 1e-6 * max(1.0, abs(args[which][j]))
                args[which][j] += h
                plus = accel(t, *args)
                args[which][j] -= 2 * h
                D[:, j] = (plus - accel(t, *args)) / (2 * h)
            out.append(D)
        return tuple(out)

    return numeric


def stack_runs(results, batch):
    def pick(j):
        return np.stack([r[j] for r in results]) if batch is not None else results[0][j]

    return (pick(0), pick(1), pick(2), pick(3), np.array([r[4] for r in results]), [r[6] for r in results])
