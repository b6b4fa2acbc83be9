"""Joint friction models for identification (Armstrong-Helouvry, Dupont & Canudas de Wit, "A survey
of models, analysis tools and compensation methods for the control of machines with friction",
Automatica 30(7), 1994; the viscous + Coulomb + offset model of Gautier & Khalil's identification
practice).

Per joint j, the friction torque is a sum of terms, each a regressor column times a coefficient:

- ``viscous`` ``Fv qd`` (N m s / rad);
- ``coulomb`` ``Fc s(qd)`` (N m), ``s`` the sign, or ``tanh(qd / v_s)`` when a smoothing velocity
  ``v_s`` is given (the sign's jump at rest smeared over |qd| < ~2 v_s);
- ``asymmetric`` Coulomb friction of its own level per direction, ``Fc+`` when qd > 0 and ``-Fc-``
  when qd < 0 (two columns ``[qd > 0]`` and ``-[qd < 0]``; Corke's PUMA 560 table gives such pairs);
- ``stribeck``: static friction above the Coulomb level, decaying with speed,
  ``(Fs - Fc) exp(-(qd / v_st)^2) s(qd)`` (the Gaussian Stribeck curve of the survey's §2.1). The
  coefficient ``Fs - Fc`` is linear; the Stribeck velocity ``v_st`` is a small nonlinear parameter
  that :func:`~kinedyn.analysis.identify` finds by a 1-D search per joint around the linear fit;
- ``offset`` (N m): a torque-sensor or current offset, or an unmodelled constant load.

Which combinations the data can separate is a property of the data, not of the model: with the
joint always moving, ``[qd > 0] - (-[qd < 0]) = 1``, so asymmetric Coulomb levels and an offset act
only as ``Fc+ + offset`` and ``Fc- - offset`` (identify reports such groups).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FrictionModel", "parse_friction", "TERMS", "stribeck_shape"]

TERMS = ("viscous", "coulomb", "asymmetric", "stribeck", "offset")

#: the columns each term adds per joint, and their names
_COLUMNS = {
    "viscous": ("viscous",),
    "coulomb": ("coulomb",),
    "asymmetric": ("coulomb+", "coulomb-"),
    "stribeck": ("stribeck",),
    "offset": ("offset",),
}


def stribeck_shape(qd: np.ndarray, velocity) -> np.ndarray:
    """exp(-(qd / v_st)^2): 1 at rest, decaying over a few v_st."""
    return np.exp(-((np.asarray(qd, dtype=float) / velocity) ** 2))


@dataclass(frozen=True)
class FrictionModel:
    """Which terms are estimated (``terms``), or ``known`` (the robot's own friction subtracted).
    ``velocities``: the Stribeck velocity per joint (rad/s or m/s) when ``stribeck`` is a term."""

    terms: tuple = ()
    known: bool = False
    smoothing: float | None = None
    velocities: tuple | None = None

    def columns(self) -> tuple:
        """The column names of one joint, in order (``coulomb+``, ``coulomb-`` for asymmetric)."""
        return tuple(c for t in self.terms for c in _COLUMNS[t])

    def names(self, n: int) -> tuple:
        """Parameter names, joint by joint: ``joint1.viscous``, ``joint1.coulomb``, ..."""
        return tuple(f"joint{j + 1}.{c}" for j in range(n) for c in self.columns())

    def sign(self, qd: np.ndarray) -> np.ndarray:
        return np.sign(qd) if self.smoothing is None else np.tanh(qd / self.smoothing)

    def regressor(self, qd: np.ndarray, sign: np.ndarray | None = None, parallel=None) -> np.ndarray:
        """(S, n, n k) for qd (S, n): column block j holds joint j's columns (zero in other rows).
        ``sign``: a filtered sign(qd) to use for the Coulomb columns (ignored with smoothing);
        ``parallel``: a filtered log's :meth:`~kinedyn.analysis.Log.parallel`, through which the
        Stribeck column passes as the torques did."""
        qd = np.asarray(qd, dtype=float)
        S, n = qd.shape
        cols = self.columns()
        k = len(cols)
        out = np.zeros((S, n, n * k))
        if "stribeck" in self.terms and (self.velocities is None or len(self.velocities) != n):
            raise ValueError(f"the Stribeck term needs one Stribeck velocity per joint ({n}), got {self.velocities}")
        s = sign if sign is not None and self.smoothing is None else self.sign(qd)
        # a joint that moves at all (rest: |qd| below 1e-9 of its largest, the log module's rule);
        # filtering the constant 1 of a moving joint leaves 1, so (moving +- s) / 2 are the filtered
        # direction indicators when s is the filtered sign
        moving = (np.abs(qd) > 1e-9 * np.maximum(np.abs(qd).max(axis=0), 1e-300)).astype(float)
        stribeck = None
        if "stribeck" in self.terms:
            v = np.asarray(self.velocities, dtype=float)
            if parallel is not None and self.smoothing is None:
                stribeck = parallel(lambda raw: stribeck_shape(raw, v) * np.sign(raw))
            if stribeck is None:
                stribeck = stribeck_shape(qd, v) * s
        for j in range(n):
            for c, name in enumerate(cols):
                col = out[:, j, j * k + c]
                if name == "viscous":
                    col[:] = qd[:, j]
                elif name == "coulomb":
                    col[:] = s[:, j]
                elif name == "coulomb+":
                    col[:] = (moving[:, j] + s[:, j]) / 2
                elif name == "coulomb-":
                    col[:] = -(moving[:, j] - s[:, j]) / 2
                elif name == "stribeck":
                    assert stribeck is not None
                    col[:] = stribeck[:, j]
                else:
                    col[:] = 1.0
        return out

    def stribeck_derivative(self, qd: np.ndarray, sign: np.ndarray | None, coefficients: np.ndarray) -> np.ndarray:
        """(S, n, n): d tau_f / d v_st,j, the Gauss-Newton column of joint j's Stribeck velocity."""
        qd = np.asarray(qd, dtype=float)
        S, n = qd.shape
        cols = self.columns()
        k, c = len(cols), cols.index("stribeck")
        s = sign if sign is not None and self.smoothing is None else self.sign(qd)
        out = np.zeros((S, n, n))
        assert self.velocities is not None
        for j in range(n):
            v = self.velocities[j]
            # d/dv exp(-(qd/v)^2) = exp(-(qd/v)^2) 2 qd^2 / v^3
            out[:, j, j] = coefficients[j * k + c] * stribeck_shape(qd[:, j], v) * 2 * qd[:, j] ** 2 / v**3 * s[:, j]
        return out

    def torque(self, qd: np.ndarray, coefficients: np.ndarray, offset: bool = True) -> np.ndarray:
        """The friction torque of ``coefficients`` (the offset left out with ``offset=False``)."""
        qd = np.asarray(qd, dtype=float)
        batch = qd.reshape(-1, qd.shape[-1])
        coefficients = np.asarray(coefficients, dtype=float)
        if not offset and "offset" in self.terms:
            cols = self.columns()
            coefficients = coefficients.copy()
            coefficients[cols.index("offset") :: len(cols)] = 0.0
        return (self.regressor(batch) @ coefficients).reshape(qd.shape)


def parse_friction(spec, smoothing: float | None = None) -> FrictionModel:
    """Terms joined by ``+`` (``"viscous+coulomb"``, ``"viscous+asymmetric+offset"``), ``"stribeck"``
    alone (viscous + Coulomb + Stribeck), ``"none"`` (no friction), ``"known"`` (the robot's own
    friction model, subtracted), or a sequence of term names. ``stribeck`` brings a Coulomb term
    (the static level lies above it) when none is named."""
    if isinstance(spec, FrictionModel):
        return spec
    if spec is None or (isinstance(spec, str) and spec.strip().lower() in ("", "none")):
        return FrictionModel((), smoothing=smoothing)
    if isinstance(spec, str) and spec.strip().lower() == "known":
        return FrictionModel((), known=True)
    if isinstance(spec, str) and spec.strip().lower() == "stribeck":
        spec = "viscous+coulomb+stribeck"
    parts = [p.strip().lower() for p in (spec.split("+") if isinstance(spec, str) else spec)]
    for p in parts:
        if p not in TERMS:
            raise ValueError(f"unknown friction term '{p}' in {spec!r}: use {' + '.join(TERMS)}, 'none' or 'known'")
    if "coulomb" in parts and "asymmetric" in parts:
        raise ValueError(
            f"friction {spec!r}: 'coulomb' (one level) and 'asymmetric' (one level per direction) are two models of the same friction: name one"
        )
    if "stribeck" in parts and "asymmetric" not in parts and "coulomb" not in parts:
        parts.append("coulomb")
    if smoothing is not None and not smoothing > 0:
        raise ValueError(f"the Coulomb smoothing velocity must be positive, got {smoothing}")
    return FrictionModel(tuple(t for t in TERMS if t in parts), smoothing=smoothing)
