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
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._lazy import LazyModule, sympy_instance
from .._math import is_symbolic
from .checks import number, real_array, vector

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = ["Inertia", "Consistency", "PhysicalConsistencyWarning", "INERTIA_POLICIES", "judge", "skew"]


class PhysicalConsistencyWarning(UserWarning):
    """Inertial data that no rigid body can have (a tensor that is not positive semi-definite, or
    principal moments that fail the triangle inequality), loaded anyway or repaired; the message
    names the link, the principal moments and, when repaired, the change."""


INERTIA_POLICIES = ("warn", "repair", "strict")

_WARNED: set = set()  # (link name, policy, Inertia) already reported: derived robots do not repeat it


def skew(v):
    """[v]x with [v]x w = v x w (works on floats and SymPy values)."""
    x, y, z = v
    return [[0, -z, y], [z, 0, -x], [-y, x, 0]]


def _mat3(value, what: str) -> tuple:
    try:
        rows = [list(r) for r in (value.tolist() if hasattr(value, "tolist") else value)]
    except TypeError:
        raise ValueError(f"{what} must be a 3x3 matrix, got {value!r}") from None
    if len(rows) != 3 or any(len(r) != 3 for r in rows):
        raise ValueError(f"{what} must be 3x3, got {len(rows)} rows of lengths {[len(r) for r in rows]}")
    return tuple(tuple(number(e, f"{what}[{i}][{j}]") for j, e in enumerate(r)) for i, r in enumerate(rows))


@dataclass(frozen=True)
class Consistency:
    """Physical consistency of a numeric inertia: ``moments`` are the principal moments about the
    centre of mass (ascending); ``positive``: the tensor is positive semi-definite; ``triangle``:
    each moment is at most the sum of the other two (true of every rigid body: the second moments
    of its mass distribution, ``(J_y + J_z - J_x) / 2`` etc., are >= 0). A tensor with a single
    non-zero moment (the planar textbook idealisation, only ``Izz`` given) counts as consistent."""

    moments: tuple
    positive: bool
    triangle: bool

    @property
    def ok(self) -> bool:
        return self.positive and self.triangle

    def describe(self) -> str:
        moments = ", ".join(f"{m:.6g}" for m in self.moments)
        if not self.positive:
            return f"inertia tensor is not positive semi-definite (eigenvalues {moments})"
        a, b, c = self.moments
        return (
            f"inertia tensor violates the triangle inequality of principal moments ({moments}: "
            f"{a:.6g} + {b:.6g} < {c:.6g})"
        )


@dataclass(frozen=True)
class Inertia:
    """Mass properties of a rigid body (see module docstring for frames).

    Construction checks the values (real, finite, at most ``LARGEST`` in magnitude, ``m >= 0``, a
    symmetric 3x3 tensor); whether a rigid body can have them (:meth:`consistency`) is judged where
    a robot is assembled, by its inertia policy (:func:`judge`)."""

    mass: Any = 0.0
    com: Any = (0.0, 0.0, 0.0)  # any 3-vector on input; a tuple once constructed
    inertia: Any = field(
        default=((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    )  # 3x3 array-like; nested tuples once constructed
    _symbolic: bool = field(default=False, init=False, repr=False, compare=False)  # set by __post_init__

    def __post_init__(self):
        object.__setattr__(self, "mass", number(self.mass, "mass"))
        com, tensor = real_array(self.com, (3,)), real_array(self.inertia, (3, 3))
        # plain numbers take the fast path; anything else is checked entry by entry
        slow = com is None or tensor is None
        com = vector(self.com, 3, "centre of mass", "coordinates") if com is None else tuple(com.tolist())
        tensor = _mat3(self.inertia, "inertia tensor") if tensor is None else tuple(map(tuple, tensor.tolist()))
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", tensor)
        object.__setattr__(self, "_symbolic", is_symbolic(self.mass) or (slow and is_symbolic(com, tensor)))
        self.validate()

    # ---- checks ---------------------------------------------------------------------------
    @property
    def is_symbolic(self) -> bool:
        return self._symbolic

    def validate(self, where: str = "") -> None:
        """The values of a numeric inertia: m >= 0 and a symmetric tensor (ValueError otherwise).
        Physical consistency is :meth:`consistency`'s."""
        where = f" of {where}" if where else ""
        if self.is_symbolic:
            return
        m = float(self.mass)
        if m < 0:
            raise ValueError(f"mass{where} is negative: {m}")
        I = np.array(self.inertia, dtype=float)
        if np.abs(I - I.T).max() > 1e-12 * max(1.0, np.abs(I).max()):
            raise ValueError(f"inertia tensor{where} is not symmetric:\n{I}")

    def consistency(self) -> Consistency | None:
        """The principal moments and whether a rigid body can have them (None when symbolic)."""
        if self.is_symbolic:
            return None
        I = np.array(self.inertia, dtype=float)
        eig = np.linalg.eigvalsh(0.5 * (I + I.T))
        tol = 1e-12 * max(1.0, float(np.abs(I).max()))
        positive = bool(eig[0] >= -tol)
        planar = eig[1] <= tol  # one non-zero moment: the planar idealisation
        triangle = bool(planar or eig[0] + eig[1] >= eig[2] - max(tol, 1e-9 * eig[2]))
        return Consistency(tuple(float(e) for e in eig), positive, triangle)

    def nearest_consistent(self) -> Inertia:
        """The nearest physically consistent inertia (same mass and centre of mass), or ``self``
        when it is consistent already.

        Projection (Wensing, Kim & Slotine, "Linear matrix inequalities for physically consistent
        inertial parameter identification", RA-L 2018): a tensor ``I`` is a rigid body's iff its
        second-moment matrix ``Sigma = tr(I)/2 E - I`` is positive semi-definite. ``Sigma`` shares
        ``I``'s principal axes, with moments ``sigma_x = (I_y + I_z - I_x) / 2`` etc.; negative
        ``sigma`` are set to 0 (the Frobenius-nearest PSD ``Sigma``) and ``I' = tr(Sigma') E -
        Sigma'``. Principal axes are kept, the result satisfies non-negativity and the triangle
        inequalities (with equality where a ``sigma`` was clipped: a flat body), and the map is
        idempotent."""
        check = self.consistency()
        if check is None or check.ok:
            return self
        I = np.array(self.inertia, dtype=float)
        lam, R = np.linalg.eigh(0.5 * (I + I.T))
        sigma = np.maximum(0.5 * (lam.sum() - 2 * lam), 0.0)  # sigma_i = (sum - 2 lam_i) / 2
        lam_new = sigma.sum() - sigma  # I_i = sigma_j + sigma_k
        tensor = (R * lam_new) @ R.T
        return Inertia(self.mass, self.com, 0.5 * (tensor + tensor.T))

    # ---- named constructors -------------------------------------------------------------------
    @classmethod
    def from_urdf(cls, mass, ixx, ixy, ixz, iyy, iyz, izz, com=(0.0, 0.0, 0.0)) -> Inertia:
        """URDF's ``<inertia ixx ixy ixz iyy iyz izz>`` (tensor entries about the centre of mass)."""
        return cls(mass, com, ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz)))

    @classmethod
    def point_mass(cls, mass, com=(0.0, 0.0, 0.0)) -> Inertia:
        return cls(mass, com)

    @classmethod
    def rod(cls, mass, length, axis: str = "x", com=None) -> Inertia:
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
    def box(cls, mass, size: Sequence, com=(0.0, 0.0, 0.0)) -> Inertia:
        """Solid uniform box with edge lengths (sx, sy, sz)."""
        sx, sy, sz = size
        k = mass / 12
        return cls(mass, com, ((k * (sy**2 + sz**2), 0, 0), (0, k * (sx**2 + sz**2), 0), (0, 0, k * (sx**2 + sy**2))))

    @classmethod
    def cylinder(cls, mass, radius, length, axis: str = "z", com=(0.0, 0.0, 0.0)) -> Inertia:
        """Solid uniform cylinder with its symmetry axis along ``axis``."""
        i = "xyz".index(axis)
        across = mass * (3 * radius**2 + length**2) / 12
        diag = [across, across, across]
        diag[i] = mass * radius**2 / 2
        return cls(mass, com, ((diag[0], 0, 0), (0, diag[1], 0), (0, 0, diag[2])))

    @classmethod
    def sphere(cls, mass, radius, com=(0.0, 0.0, 0.0)) -> Inertia:
        I = 2 * mass * radius**2 / 5
        return cls(mass, com, ((I, 0, 0), (0, I, 0), (0, 0, I)))

    @classmethod
    def from_parameters(cls, pi: Sequence) -> Inertia:
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
            tuple(self.inertia[r][k] - m * sum(S[r][j] * S[j][k] for j in range(3)) for k in range(3)) for r in range(3)
        )

    def parameters(self) -> list:
        """[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about the frame origin."""
        m = self.mass
        h = [m * c for c in self.com]
        Io = self.inertia_about_origin()
        return [m, *h, Io[0][0], Io[0][1], Io[1][1], Io[0][2], Io[1][2], Io[2][2]]

    def transformed(self, a_from_b) -> Inertia:
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

    def __add__(self, other: Inertia) -> Inertia:
        """Inertia of two bodies rigidly joined (both expressed in the same frame)."""
        if not isinstance(other, Inertia):
            return NotImplemented
        symbolic = self.is_symbolic or other.is_symbolic
        m = self.mass + other.mass
        if not symbolic and float(m) == 0.0:
            # massless bodies may still have rotational inertia (a rotor, Corke's PUMA link 1): the
            # tensors about the common origin add; with no mass the centre of mass is moot (origin)
            Io = np.array(self.inertia_about_origin(), dtype=float) + np.array(
                other.inertia_about_origin(), dtype=float
            )
            return Inertia(0.0, (0.0, 0.0, 0.0), 0.5 * (Io + Io.T))
        c = tuple((self.mass * a + other.mass * b) / m for a, b in zip(self.com, other.com))
        # sum about the common origin, then shift back to the new centre of mass
        Io = [
            [a + b for a, b in zip(ra, rb)] for ra, rb in zip(self.inertia_about_origin(), other.inertia_about_origin())
        ]
        S = skew(c)
        Ic = [[Io[r][k] + m * sum(S[r][j] * S[j][k] for j in range(3)) for k in range(3)] for r in range(3)]
        if symbolic:
            Ic = [[sp.simplify(e) for e in row] for row in Ic]
            c = tuple(sp.simplify(e) for e in c)
        else:
            I = np.array(Ic, dtype=float)
            Ic = 0.5 * (I + I.T)
        return Inertia(m, c, Ic)

    def subs(self, mapping) -> Inertia:
        f = lambda e: e.subs(mapping) if sympy_instance(e, "Basic") else e
        return Inertia(f(self.mass), tuple(f(c) for c in self.com), tuple(tuple(f(e) for e in r) for r in self.inertia))


def judge(inertia: Inertia, policy: str, what: str) -> Inertia:
    """Apply an inertia policy to one link's inertia (``what`` names the link in messages).

    ``"warn"``: kept as given, with a :class:`PhysicalConsistencyWarning` naming the link and the
    principal moments; ``"repair"``: replaced by :meth:`Inertia.nearest_consistent`, with a warning
    giving the old and new moments and the size of the change (Frobenius norm of the tensor
    difference); ``"strict"``: a tensor that is not positive semi-definite is a ValueError, a
    triangle-inequality violation (published tables such as the PUMA 560's) a warning. Each
    (link, tensor) is reported once per process."""
    if policy not in INERTIA_POLICIES:
        raise ValueError(f"inertia policy must be one of {INERTIA_POLICIES}, got {policy!r}")
    check = inertia.consistency()
    if check is None or check.ok:
        return inertia
    if policy == "strict" and not check.positive:
        raise ValueError(
            f"{what}: {check.describe()}; no rigid body has this inertia (check the signs of the products "
            "of inertia: URDF's ixy is the tensor entry); load with inertia='warn' or 'repair' to accept it"
        )
    key = (what, policy, inertia)
    if policy == "repair":
        repaired = inertia.nearest_consistent()
        if key not in _WARNED:
            change = float(np.linalg.norm(np.array(repaired.inertia) - np.array(inertia.inertia)))
            repaired_check = repaired.consistency()
            assert repaired_check is not None  # a repaired inertia is numeric, so it has a consistency
            new = ", ".join(f"{m:.6g}" for m in repaired_check.moments)
            warnings.warn(
                f"{what}: {check.describe()}; repaired to the nearest physically consistent tensor "
                f"(principal moments {new}; change {change:.3g} kg m^2 in Frobenius norm)",
                PhysicalConsistencyWarning,
                stacklevel=3,
            )
            _WARNED.add(key)
        return repaired
    if key not in _WARNED:
        hint = (
            ""
            if policy == "strict" or check.positive
            else (
                "; forward dynamics, M^-1 and simulation may fail (inertia='repair' projects it onto a consistent one)"
            )
        )
        warnings.warn(
            f"{what}: {check.describe()}: no rigid body has this inertia, kept as given{hint}",
            PhysicalConsistencyWarning,
            stacklevel=3,
        )
        _WARNED.add(key)
    return inertia
