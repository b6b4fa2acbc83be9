"""The controller of a closed-loop experiment, rebuilt for IDIM-IV and DIDIM (docs/identification.md).

A joint log holds positions and torques, not the controller that produced them, and IV and DIDIM
simulate the identified model under that controller (:mod:`.closed_loop`). What the controller needs
is its law, its gains and the reference it tracked; the command line takes them as options
(``--controller pd --kp 400,200 --kd 40,20 --reference traj.csv``), and :func:`experiment_controller`
builds the callable. The reference is the trajectory file the controller ran, in the format
``kinedyn identify --excite`` writes (t, q1..qn, qd1..qdn, qdd1..qddn, one header line; qd and qdd
optional), on the log's time base (t = 0 where the log's t = 0).
"""

from __future__ import annotations

import os

import numpy as np

from ..simulate.control import PD, ComputedTorque, PDGravity, Reference

__all__ = ["TabulatedReference", "load_reference", "experiment_controller", "CONTROLLERS"]

#: the controller laws the command line names (kinedyn.simulate.control): PD, PD with the model's
#: gravity, computed torque on the model
CONTROLLERS = ("pd", "pdg", "ct")


class TabulatedReference(Reference):
    """A reference sampled at the times ``t``: q, qd, qdd read by linear interpolation (held at
    either end). Without ``qd`` / ``qdd`` they are the derivatives of a cubic spline through ``q``
    (the trajectory a controller is given is smooth at its sample rate)."""

    def __init__(self, t, q, qd=None, qdd=None):
        t = np.asarray(t, dtype=float)
        q = np.asarray(q, dtype=float)
        if t.ndim != 1 or q.ndim != 2 or len(t) != len(q) or len(t) < 4:
            raise ValueError(
                f"a tabulated reference needs t (T,) and q (T, n) with T >= 4, got {t.shape} and {q.shape}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)):
            raise ValueError("a tabulated reference's times must be finite and increasing")
        if not np.all(np.isfinite(q)):
            raise ValueError("a tabulated reference's positions must be finite")
        if qd is None or qdd is None:
            from scipy.interpolate import CubicSpline  # scipy loads only for a reference without derivatives

            spline = CubicSpline(t, q, axis=0)
            qd = spline(t, 1) if qd is None else qd
            qdd = spline(t, 2) if qdd is None else qdd
        self.t, self.q = t, q
        self.qd, self.qdd = np.asarray(qd, dtype=float), np.asarray(qdd, dtype=float)
        self.n = q.shape[1]
        self.period = float(t[-1] - t[0])

    def __call__(self, t):
        tt = np.asarray(t, dtype=float)
        flat = np.atleast_1d(tt).reshape(-1)
        out = []
        for X in (self.q, self.qd, self.qdd):
            Y = np.column_stack([np.interp(flat, self.t, X[:, j]) for j in range(self.n)])
            out.append(Y.reshape(np.shape(tt) + (self.n,)))
        return tuple(out)


def load_reference(path, n: int) -> TabulatedReference:
    """The reference trajectory file (CSV with a header line, ``t, q1..qn[, qd1..qdn, qdd1..qddn]``)
    for an arm of ``n`` joints; ValueError naming the file and the missing column."""
    path = os.fspath(path)
    with open(path, encoding="utf-8") as f:
        header = [h.strip() for h in f.readline().strip().split(",")]
    try:
        values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as e:
        raise ValueError(f"{path}: not a numeric CSV after its header line ({e})") from None
    if values.shape[1] != len(header):
        raise ValueError(f"{path}: {len(header)} header names but {values.shape[1]} columns")
    col = {h: k for k, h in enumerate(header)}

    def block(prefix):
        names = [f"{prefix}{j + 1}" for j in range(n)]
        missing = [nm for nm in names if nm not in col]
        if len(missing) == n and prefix != "q":
            return None
        if missing:
            raise ValueError(
                f"{path}: no column {missing[0]} (the reference of a {n}-joint arm: t, q1..q{n}[, qd.., qdd..])"
            )
        return values[:, [col[nm] for nm in names]]

    if "t" not in col:
        raise ValueError(f"{path}: no column t (the reference's times, s)")
    try:
        return TabulatedReference(values[:, col["t"]], block("q"), block("qd"), block("qdd"))
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None


def _gains(value, n: int, what: str) -> np.ndarray:
    g = np.atleast_1d(np.asarray(value, dtype=float)).reshape(-1)
    if g.size == 1:
        g = np.full(n, g[0])
    if g.size != n or not np.all(np.isfinite(g)) or np.any(g < 0):
        raise ValueError(f"{what}: one gain >= 0, or one per joint ({n}), got {list(np.atleast_1d(value))}")
    return np.diag(g)


def experiment_controller(robot, kind: str, kp, kd, reference, model=None):
    """The controller law ``kind`` (``pd``: ``Kp e + Kd ed``; ``pdg``: plus the model's gravity;
    ``ct``: computed torque on the model, ``M (qdd_d + Kd ed + Kp e) + h``) with the gains ``kp``,
    ``kd`` (one number, or one per joint), tracking ``reference``; ``model``: the robot model the
    controller ran (default ``robot``, the prior model)."""
    kind = str(kind).lower()
    if kind not in CONTROLLERS:
        raise ValueError(f"unknown controller '{kind}': use one of {', '.join(CONTROLLERS)}")
    n = robot.n
    if getattr(reference, "n", n) != n:
        raise ValueError(f"the reference has {reference.n} joints but robot '{robot.name}' has {n}")
    Kp, Kd = _gains(kp, n, "kp"), _gains(kd, n, "kd")
    model = robot if model is None else model
    if kind == "pd":
        return PD(Kp, Kd, reference)
    if kind == "pdg":
        return PDGravity(model, Kp, Kd, reference)
    return ComputedTorque(model, np.diag(Kp), np.diag(Kd), reference, model=model)
