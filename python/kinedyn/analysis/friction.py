"""Joint friction models for identification, linear in their coefficients (Armstrong-Helouvry,
Dupont & Canudas de Wit, "A survey of models, analysis tools and compensation methods for the
control of machines with friction", Automatica 30(7), 1994; the viscous + Coulomb + offset model of
Gautier & Khalil's identification practice).

Per joint j, ``tau_f,j = Fv_j qd_j + Fc_j s(qd_j) + off_j`` with any subset of the three terms:
``viscous`` (N m s / rad), ``coulomb`` (N m) and ``offset`` (N m: a torque-sensor or current
offset, or an unmodelled constant load). ``s`` is the sign function, or ``tanh(qd / v_s)`` when a
smoothing velocity ``v_s`` is given (the sign's jump at rest smeared over |qd| < ~2 v_s, which
matches real friction at slow reversals better than a jump does).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FrictionModel", "parse_friction", "TERMS"]

TERMS = ("viscous", "coulomb", "offset")


@dataclass(frozen=True)
class FrictionModel:
    """Which terms are estimated (``terms``), or ``known`` (the robot's own friction subtracted)."""

    terms: tuple = ()
    known: bool = False
    smoothing: float | None = None

    def names(self, n: int) -> tuple:
        """Parameter names, joint by joint: ``joint1.viscous``, ``joint1.coulomb``, ..."""
        return tuple(f"joint{j + 1}.{term}" for j in range(n) for term in self.terms)

    def sign(self, qd: np.ndarray) -> np.ndarray:
        return np.sign(qd) if self.smoothing is None else np.tanh(qd / self.smoothing)

    def regressor(self, qd: np.ndarray, sign: np.ndarray | None = None) -> np.ndarray:
        """(S, n, n k) for qd (S, n): column block j holds joint j's terms (zero in other rows).
        ``sign``: a filtered sign(qd) to use for the Coulomb term (ignored with smoothing)."""
        qd = np.asarray(qd, dtype=float)
        S, n = qd.shape
        k = len(self.terms)
        out = np.zeros((S, n, n * k))
        for j in range(n):
            for c, term in enumerate(self.terms):
                col = j * k + c
                if term == "viscous":
                    out[:, j, col] = qd[:, j]
                elif term == "coulomb":
                    out[:, j, col] = sign[:, j] if sign is not None and self.smoothing is None else self.sign(qd[:, j])
                else:
                    out[:, j, col] = 1.0
        return out

    def torque(self, qd: np.ndarray, coefficients: np.ndarray) -> np.ndarray:
        qd = np.asarray(qd, dtype=float)
        batch = qd.reshape(-1, qd.shape[-1])
        return (self.regressor(batch) @ np.asarray(coefficients, dtype=float)).reshape(qd.shape)


def parse_friction(spec, smoothing: float | None = None) -> FrictionModel:
    """``"viscous+coulomb"``, ``"viscous+coulomb+offset"``, ``"none"`` (no friction), ``"known"``
    (the robot's own friction model, subtracted), or a sequence of term names."""
    if isinstance(spec, FrictionModel):
        return spec
    if spec is None or (isinstance(spec, str) and spec.strip().lower() in ("", "none")):
        return FrictionModel((), smoothing=smoothing)
    if isinstance(spec, str) and spec.strip().lower() == "known":
        return FrictionModel((), known=True)
    parts = [p.strip().lower() for p in (spec.split("+") if isinstance(spec, str) else spec)]
    for p in parts:
        if p not in TERMS:
            raise ValueError(f"unknown friction term '{p}' in {spec!r}: use {' + '.join(TERMS)}, 'none' or 'known'")
    if smoothing is not None and not smoothing > 0:
        raise ValueError(f"the Coulomb smoothing velocity must be positive, got {smoothing}")
    return FrictionModel(tuple(t for t in TERMS if t in parts), smoothing=smoothing)
