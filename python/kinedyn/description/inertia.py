"""Rigid-body inertia of one link: mass, centre of mass, and the 3x3 inertia about the centre of mass.

Conventions (docs/conventions.md):
- ``com`` is the centre of mass in the link frame, ``inertia`` is the rotational inertia tensor about
  the centre of mass, expressed in the link frame's axes (as URDF's ``<inertial>`` after its origin is
  applied, and Spong's I_i in §9.3 expressed in body axes).
- ``parameters()`` returns the 10 standard inertial parameters about the link-frame *origin*, in
  Pinocchio's order ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``, which is what makes the
  equations of motion linear in them (Spong §9.5.4; Atkeson, An & Hollerbach 1986).

Values may be floats or SymPy expressions.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
import sympy as sp

from .._math import as_value, is_symbolic

__all__ = ["Inertia", "PhysicalConsistencyWarning", "skew"]


class PhysicalConsistencyWarning(UserWarning):
    """Inertial data that no rigid body can have, kept as given (e.g. a published table)."""


_WARNED: set = set()


def skew(v):
    """[v]x with [v]x w = v x w (works on floats and SymPy values)."""
    x, y, z = v
    return [[0, -z, y], [z, 0, -x], [-y, x, 0]]


def _mat3(value) -> tuple:
    rows = [list(r) for r in (value.tolist() if hasattr(value, "tolist") else value)]
    if len(rows) != 3 or any(len(r) != 3 for r in rows):
        raise ValueError(f"an inertia tensor must be 3x3, got {np.shape(rows)}")
    return tuple(tuple(as_value(e) for e in r) for r in rows)


@dataclass(frozen=True)
class Inertia:
    """Mass properties of a rigid body (see module docstring for frames)."""

    mass: Any = 0.0
    com: tuple = (0.0, 0.0, 0.0)
    inertia: tuple = field(default=((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))

    def __post_init__(self):
        object.__setattr__(self, "mass", as_value(self.mass))
        com = tuple(as_value(c) for c in self.com)
        if len(com) != 3:
            raise ValueError(f"centre of mass must have 3 coordinates, got {len(com)}")
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", _mat3(self.inertia))
        self.validate()

    # ---- checks ---------------------------------------------------------------------------
    @property
    def is_symbolic(self) -> bool:
        return is_symbolic(self.mass, self.com, self.inertia)

    def validate(self, where: str = "") -> None:
        """Physical consistency of numeric values: m >= 0, I symmetric and PSD (errors); the triangle
        inequality of principal moments (a warning)."""
        where = f" of {where}" if where else ""
        if is_symbolic(self.mass, self.com, self.inertia):
            return
        m = float(self.mass)
        if not np.isfinite(m):
            raise ValueError(f"mass{where} is not finite: {m}")
        if m < 0:
            raise ValueError(f"mass{where} is negative: {m}")
        c = np.array(self.com, dtype=float)
        if not np.all(np.isfinite(c)):
            raise ValueError(f"centre of mass{where} is not finite: {c}")
        I = np.array(self.inertia, dtype=float)
        if not np.all(np.isfinite(I)):
            raise ValueError(f"inertia tensor{where} is not finite")
        if not np.allclose(I, I.T, rtol=0, atol=1e-12 * max(1.0, np.abs(I).max())):
            raise ValueError(f"inertia tensor{where} is not symmetric:\n{I}")
        eig = np.linalg.eigvalsh(I)
        tol = 1e-12 * max(1.0, np.abs(I).max())
        if eig[0] < -tol:
            raise ValueError(
                f"inertia tensor{where} is not positive semi-definite (eigenvalues {eig}); "
                "check the signs of the products of inertia (URDF uses +ixy for the tensor entry)"
            )
        # a real body's principal moments satisfy the triangle inequality; published tables (the
        # PUMA 560's) and CAD exports sometimes do not: warn, since M stays positive definite
        key = tuple(np.round(eig, 12))
        # one nonzero principal moment is the planar textbook idealisation (only Izz given): no warning
        planar = eig[1] <= tol
        if eig[0] + eig[1] < eig[2] - max(tol, 1e-9 * eig[2]) and not planar and key not in _WARNED:
            _WARNED.add(key)  # once per body: rotated copies made while compiling share eigenvalues
            warnings.warn(
                f"inertia tensor{where} violates the triangle inequality of principal moments "
                f"({eig}): no rigid body has this inertia (kept as given)",
                PhysicalConsistencyWarning,
                stacklevel=3,
            )

    # ---- named constructors -------------------------------------------------------------------
    @classmethod
    def from_urdf(cls, mass, ixx, ixy, ixz, iyy, iyz, izz, com=(0.0, 0.0, 0.0)) -> "Inertia":
        """URDF's ``<inertia ixx ixy ixz iyy iyz izz>`` (tensor entries about the centre of mass)."""
        return cls(mass, com, ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz)))

    @classmethod
    def point_mass(cls, mass, com=(0.0, 0.0, 0.0)) -> "Inertia":
        return cls(mass, com)

    @classmethod
    def rod(cls, mass, length, axis: str = "x", com=None) -> "Inertia":
        """Thin uniform rod of ``length`` along ``axis``; centre of mass at mid-length from the origin
        unless ``com`` is given. Inertia m L^2 / 12 about the two axes across the rod."""
        i = "xyz".index(axis)
        if com is None:
            com = [0, 0, 0]
            com[i] = length / 2
        Ic = mass * length**2 / 12
        diag = [Ic, Ic, Ic]
        diag[i] = 0
        return cls(mass, tuple(com), ((diag[0], 0, 0), (0, diag[1], 0), (0, 0, diag[2])))

    @classmethod
    def box(cls, mass, size: Sequence, com=(0.0, 0.0, 0.0)) -> "Inertia":
        """Solid uniform box with edge lengths (sx, sy, sz)."""
        sx, sy, sz = size
        k = mass / 12
        return cls(mass, com, ((k * (sy**2 + sz**2), 0, 0), (0, k * (sx**2 + sz**2), 0), (0, 0, k * (sx**2 + sy**2))))

    @classmethod
    def cylinder(cls, mass, radius, length, axis: str = "z", com=(0.0, 0.0, 0.0)) -> "Inertia":
        """Solid uniform cylinder with its symmetry axis along ``axis``."""
        i = "xyz".index(axis)
        across = mass * (3 * radius**2 + length**2) / 12
        diag = [across, across, across]
        diag[i] = mass * radius**2 / 2
        return cls(mass, com, ((diag[0], 0, 0), (0, diag[1], 0), (0, 0, diag[2])))

    @classmethod
    def sphere(cls, mass, radius, com=(0.0, 0.0, 0.0)) -> "Inertia":
        I = 2 * mass * radius**2 / 5
        return cls(mass, com, ((I, 0, 0), (0, I, 0), (0, 0, I)))

    @classmethod
    def from_parameters(cls, pi: Sequence) -> "Inertia":
        """Inverse of :meth:`parameters` (requires m != 0 to recover the centre of mass)."""
        m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = pi
        if not is_symbolic(m) and float(m) == 0.0:
            return cls(0.0)
        c = (hx / m, hy / m, hz / m)
        Io = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]
        # I_c = I_o + m [c]x [c]x   (parallel-axis theorem, Spong eq. 9.49 generalised)
        S = skew(c)
        Ic = [[Io[r][k] + m * sum(S[r][j] * S[j][k] for j in range(3)) for k in range(3)] for r in range(3)]
        if is_symbolic(*pi):
            Ic = [[sp.simplify(e) for e in row] for row in Ic]
        return cls(m, c, Ic)

    # ---- derived quantities ---------------------------------------------------------------------
    def inertia_about_origin(self):
        """I_o = I_c - m [c]x [c]x (parallel-axis theorem), 3x3 nested tuple."""
        S = skew(self.com)
        m = self.mass
        return tuple(
            tuple(self.inertia[r][k] - m * sum(S[r][j] * S[j][k] for j in range(3)) for k in range(3))
            for r in range(3)
        )

    def parameters(self) -> list:
        """[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about the frame origin."""
        m = self.mass
        h = [m * c for c in self.com]
        Io = self.inertia_about_origin()
        return [m, *h, Io[0][0], Io[0][1], Io[1][1], Io[0][2], Io[1][2], Io[2][2]]

    def transformed(self, a_from_b) -> "Inertia":
        """This inertia (given in frame b) expressed in frame a, for a pose ``a_from_b``."""
        symbolic = is_symbolic(a_from_b) or self.is_symbolic
        if symbolic:
            T = sp.Matrix(a_from_b)
            R = T[:3, :3]
            c = R * sp.Matrix(self.com) + T[:3, 3]
            Ic = R * sp.Matrix(self.inertia) * R.T
            return Inertia(self.mass, tuple(c), Ic.tolist())
        T = np.asarray(a_from_b, dtype=float)
        R = T[:3, :3]
        c = R @ np.array(self.com, dtype=float) + T[:3, 3]
        Ic = R @ np.array(self.inertia, dtype=float) @ R.T
        return Inertia(self.mass, tuple(c), 0.5 * (Ic + Ic.T))

    def __add__(self, other: "Inertia") -> "Inertia":
        """Inertia of two bodies rigidly joined (both expressed in the same frame)."""
        if not isinstance(other, Inertia):
            return NotImplemented
        symbolic = self.is_symbolic or other.is_symbolic
        m = self.mass + other.mass
        if not symbolic and float(m) == 0.0:
            return Inertia(0.0)
        c = tuple((self.mass * a + other.mass * b) / m for a, b in zip(self.com, other.com))
        # sum about the common origin, then shift back to the new centre of mass
        Io = [[a + b for a, b in zip(ra, rb)] for ra, rb in zip(self.inertia_about_origin(), other.inertia_about_origin())]
        S = skew(c)
        Ic = [[Io[r][k] + m * sum(S[r][j] * S[j][k] for j in range(3)) for k in range(3)] for r in range(3)]
        if symbolic:
            Ic = [[sp.simplify(e) for e in row] for row in Ic]
            c = tuple(sp.simplify(e) for e in c)
        else:
            I = np.array(Ic, dtype=float)
            Ic = 0.5 * (I + I.T)
        return Inertia(m, c, Ic)

    def subs(self, mapping) -> "Inertia":
        f = lambda e: sp.sympify(e).subs(mapping) if isinstance(e, sp.Basic) else e
        return Inertia(f(self.mass), tuple(f(c) for c in self.com), tuple(tuple(f(e) for e in r) for r in self.inertia))
