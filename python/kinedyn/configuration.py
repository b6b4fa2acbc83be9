"""Configuration spaces: ``q`` (length nq) and velocities ``v`` (length nv) of joints that are not
plain angles, and the operations that replace ``q + v dt`` and ``q1 - q0`` on them.

Conventions (Pinocchio's, so that numbers move between the two unchanged; docs/conventions.md):
``q`` is the joints' blocks in body order (``robot.tree.bodies``), ``v`` likewise;

| kind | q block | v block | q ⊕ v |
|------|---------|---------|-------|
| revolute, prismatic | the angle / displacement (1) | its rate (1) | q + v |
| spherical | unit quaternion (qx, qy, qz, qw) (4) | angular velocity, child frame (3) | R(q) Exp(ω) |
| floating | (x, y, z, qx, qy, qz, qw) (7) | [linear; angular], child frame (6) | M(q) Exp(v) in SE(3) |
| planar | (x, y, cos θ, sin θ) (4) | (vx, vy, ω), child frame (3) | M(q) Exp(v) in SE(2) |

``integrate(q, v, dt) = q ⊕ (v dt)`` multiplies the joint's pose by the group exponential on the
right (the velocity is expressed in the moving frame), ``difference(q0, q1) = Log(M(q0)⁻¹ M(q1))``
is its inverse: ``difference(q0, integrate(q0, v)) == v`` for every rotation angle |ω| < π.

Sources of the formulas (derived again here, not transcribed): Solà, Deray & Atchuthan, "A micro Lie
theory for state estimation in robotics" (2018), §§ 4–5 and appendices A–C (SO(3) by quaternions,
SE(2), SE(3), their left Jacobians V); Murray, Li & Sastry, *A Mathematical Introduction to Robotic
Manipulation* (1994), §2.3 eq. 2.36 (the exponential of a twist) and Prop. 2.9; Shoemake, "Uniform
random rotations", *Graphics Gems III* (1992) for random quaternions.

Everything here is NumPy and vectorised: ``q`` may be (nq,) or a batch (..., nq), ``v`` (nv,) or
(..., nv), broadcast against each other. ``integrate`` and ``difference`` are the core's
(``kinedyn._core.lie_integrate`` / ``lie_difference``, which need no model), and so are their
Jacobians (``lie_integrate_jacobians`` / ``lie_difference_jacobians``) and the quaternion helpers
(:mod:`kinedyn.lie`).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ._core import lie_difference, lie_difference_jacobians, lie_integrate, lie_integrate_jacobians
from .description.joint import Joint
from .lie import (
    exp3,
    log3,
    quaternion_multiply,
    quaternion_rotate,
    quaternion_to_matrix,
    vector_norm,
)

if TYPE_CHECKING:
    from ._typing import ArrayLike, SeedLike
    from .robot import Robot

__all__ = [
    "ConfigurationSpace",
    "UNIT_TOLERANCE",
    "space",
    "neutral",
    "integrate",
    "difference",
    "interpolate",
    "random_configuration",
    "normalize",
    "check_configuration",
    "default_configuration",
    "integrate_jacobians",
    "difference_jacobians",
    "quaternion_multiply",
    "quaternion_rotate",
    "quaternion_to_matrix",
    "exp3",
    "log3",
    "COORDINATE_NAMES",
]

#: How far from 1 the norm of a quaternion or of a planar joint's (cos θ, sin θ) may be before
#: :func:`check_configuration` refuses it (normalise with :func:`normalize` / ``robot.normalize(q)``).
UNIT_TOLERANCE = 1e-6

_Q_NAMES = {
    "revolute": ("angle",),
    "prismatic": ("displacement",),
    "spherical": ("qx", "qy", "qz", "qw"),
    "floating": ("x", "y", "z", "qx", "qy", "qz", "qw"),
    "planar": ("x", "y", "cos theta", "sin theta"),
}
#: The names of a joint kind's q coordinates, in order (docs/conventions.md).
COORDINATE_NAMES = _Q_NAMES


@dataclass(frozen=True)
class _Block:
    joint: Joint
    iq: int  # first index of the joint's block in q
    iv: int  # first index of the joint's block in v


class ConfigurationSpace:
    """The configuration space of a sequence of moving joints (a robot's, in body order): sizes, and
    every operation vectorised over the joints of one kind and over a batch of states."""

    def __init__(self, joints: Sequence[Joint]):
        blocks, iq, iv = [], 0, 0
        for joint in joints:
            if not isinstance(joint, Joint):
                raise ValueError(f"a configuration space is made of Joint objects, got {type(joint).__name__}")
            if joint.kind == "fixed":
                continue
            blocks.append(_Block(joint, iq, iv))
            iq, iv = iq + joint.nq, iv + joint.nv
        self.blocks: tuple = tuple(blocks)
        self.nq, self.nv = iq, iv
        # each joint's block as the core names it (lie::Block::from_name): "" for a 1-DOF joint
        self._block_names = [
            b.joint.kind if b.joint.kind in ("floating", "spherical", "planar") else "" for b in blocks
        ]
        self._scalar_q = np.array([b.iq for b in blocks if b.joint.nq == 1], dtype=np.intp)
        # where the unit-norm parts sit: quaternions (k, 4) and planar (cos, sin) pairs (k, 2), with their joints
        self._unit_parts = []
        for b in blocks:
            if b.joint.kind in ("floating", "spherical"):
                start = b.iq + (3 if b.joint.kind == "floating" else 0)
                self._unit_parts.append((b, np.arange(start, start + 4), "quaternion"))
            elif b.joint.kind == "planar":
                self._unit_parts.append((b, np.arange(b.iq + 2, b.iq + 4), "(cos theta, sin theta) pair"))

    @classmethod
    def of(cls, robot: Robot) -> ConfigurationSpace:
        """The configuration space of ``robot`` (built once per robot and remembered)."""
        found = _SPACES.get(robot)
        if found is None:
            found = _SPACES[robot] = cls(list(robot.joints))  # the coordinates' joints (no reduced mimic followers)
        return found

    # ------------------------------------------------------------------------------ arguments
    def _array(self, x, size: int, name: str, what: str) -> np.ndarray:
        try:
            a = np.asarray(x)
            if a.dtype.kind not in "fiubO":  # complex numbers would lose their imaginary part, text is no number
                raise TypeError(f"an array of dtype {a.dtype}")
            a = a.astype(float, copy=False)
        except (TypeError, ValueError) as e:
            raise TypeError(f"{name} must be real numbers, got {e}") from None
        if a.ndim == 0 or a.shape[-1] != size:
            raise ValueError(f"{name} must have {size} entries ({what}) along its last axis, got shape {a.shape}")
        return a

    def _velocity(self, v, name: str = "v") -> np.ndarray:
        a = self._array(v, self.nv, name, "nv: one per degree of freedom")
        if not np.all(np.isfinite(a)):
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
            raise ValueError(f"{name}{list(bad)} is {a[bad]}: a velocity must be finite")
        return a

    def check(self, q, name: str = "q") -> np.ndarray:
        """``q`` as a float array after the checks of :func:`check_configuration`."""
        a = self._array(q, self.nq, name, "nq: a free-flyer takes 7, a spherical or planar joint 4")
        if not np.all(np.isfinite(a)):
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
            raise ValueError(
                f"{name}{list(bad)} ({self._describe(bad[-1])}) is {a[bad]}: a configuration must be finite{self._at(bad[:-1])}"
            )
        for block, columns, what in self._unit_parts:
            norm = vector_norm(a[..., columns])
            off = np.abs(norm - 1.0) > UNIT_TOLERANCE
            if np.any(off):
                state = tuple(int(i) for i in np.argwhere(np.atleast_1d(off))[0]) if a.ndim > 1 else ()
                values = a[state + (slice(None),)][columns] if a.ndim > 1 else a[columns]
                joint = block.joint
                names = ", ".join(_Q_NAMES[joint.kind][i - block.iq] for i in columns)
                raise ValueError(
                    f"{name}[{columns[0]}:{columns[-1] + 1}] of {joint.kind} joint '{joint.name}' is the {what} "
                    f"({names}) = {tuple(float(x) for x in values)} of norm {float(np.sqrt(np.sum(values**2))):.9g}, not 1 to within "
                    f"{UNIT_TOLERANCE:g}{self._at(state)}: normalise it (robot.normalize(q) divides each by its norm"
                    + ("; q and -q are the same rotation" if what == "quaternion" else "")
                    + ")"
                )
        return a

    def _describe(self, index: int) -> str:
        for b in self.blocks:
            if b.iq <= index < b.iq + b.joint.nq:
                return f"{_Q_NAMES[b.joint.kind][index - b.iq]} of {b.joint.kind} joint '{b.joint.name}'"
        return "?"

    @staticmethod
    def _at(state: tuple) -> str:
        if not state:
            return ""
        return f" at state {state[0] if len(state) == 1 else state} of the batch"

    # ------------------------------------------------------------------------------ operations
    def neutral(self) -> np.ndarray:
        """The identity of every joint: zeros, quaternions (0, 0, 0, 1), planar (0, 0, 1, 0)."""
        q = np.zeros(self.nq)
        for b in self.blocks:
            if b.joint.kind == "floating":
                q[b.iq + 6] = 1.0
            elif b.joint.kind == "spherical":
                q[b.iq + 3] = 1.0
            elif b.joint.kind == "planar":
                q[b.iq + 2] = 1.0
        return q

    def integrate(self, q, v, dt=1.0) -> np.ndarray:
        """q ⊕ (v dt): each joint's pose times the exponential of its velocity (module docstring)."""
        q = self.check(q)
        v = self._velocity(v)
        dt = np.asarray(dt, dtype=float)
        if not np.all(np.isfinite(dt)):
            raise ValueError(f"dt must be finite, got {dt}")
        vdt = v * (dt[..., None] if dt.ndim else dt)
        shape = np.broadcast_shapes(q.shape[:-1], vdt.shape[:-1])
        q = np.broadcast_to(q, shape + (self.nq,))
        vdt = np.broadcast_to(vdt, shape + (self.nv,))
        # the core's q ⊕ v per joint block (crates/kinedyn-core/src/lie.rs)
        out = lie_integrate(self._block_names, np.ascontiguousarray(q), np.ascontiguousarray(vdt))
        if not np.all(np.isfinite(out)):  # a step of 1e300: its norm overflows, the exponential is NaN
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(out))[0])
            raise ValueError(
                f"q ⊕ v dt is not finite at {self._describe(bad[-1])}{self._at(bad[:-1])}: the step v dt "
                f"(largest |v dt| {float(np.max(np.abs(vdt))):.3g}) is beyond what float64 holds"
            )
        return out

    def difference(self, q0, q1) -> np.ndarray:
        """v with q0 ⊕ v = q1: Log(M(q0)⁻¹ M(q1)) per joint, q1 - q0 for 1-DOF joints; rotations the
        short way (angle in [0, π]; q and -q are the same rotation)."""
        # the core's Log(M0⁻¹ M1) per joint block (crates/kinedyn-core/src/lie.rs)
        return lie_difference(self._block_names, *self._pair(q0, q1))

    def _pair(self, q0, q1) -> tuple:
        """``q0``, ``q1`` checked and broadcast against each other, C-contiguous (for the core)."""
        q0, q1 = self.check(q0, "q0"), self.check(q1, "q1")
        shape = np.broadcast_shapes(q0.shape[:-1], q1.shape[:-1])
        return tuple(np.ascontiguousarray(np.broadcast_to(q, shape + (self.nq,))) for q in (q0, q1))

    def interpolate(self, q0, q1, t) -> np.ndarray:
        """q0 ⊕ t · difference(q0, q1): the geodesic from q0 (t = 0) to q1 (t = 1) in each joint's group;
        ``t`` a number or an array of them (one configuration each). t = 1 returns q1 itself."""
        t = np.asarray(t)
        if t.dtype.kind not in "fiub":  # a complex t would lose its imaginary part, text is no number
            raise TypeError(f"t must be real numbers, got an array of dtype {t.dtype}")
        t = t.astype(float)
        if not np.all(np.isfinite(t)):
            raise ValueError(f"t must be finite, got {t}")
        q0, q1 = self.check(q0, "q0"), self.check(q1, "q1")
        tv = t[..., None]
        out = self.integrate(q0, tv * self.difference(q0, q1))
        # at t = 1 exactly, q1 (not -q1's quaternion sign, nor its last rounding)
        return np.where(tv == 1.0, np.broadcast_to(q1, out.shape), out)

    def integrate_jacobians(self, q, v, dt=1.0) -> tuple:
        """(∂(q ⊕ v dt)/∂q, ∂(q ⊕ v dt)/∂v), each (nv, nv) or (..., nv, nv), in the tangent spaces
        (perturbations on the right, as Pinocchio's ``dIntegrate`` ARG0 and ARG1): block diagonal,
        Ad(Exp(v dt))⁻¹ and Jr(v dt) dt per multi-DOF joint, 1 and dt for 1-DOF joints (the core's
        ``lie::integrate_jacobians_block``)."""
        q = self.check(q)
        v = self._velocity(v)
        dt = np.asarray(dt, dtype=float)
        if dt.ndim or not np.isfinite(dt):
            raise ValueError(f"dt must be one finite number, got {dt}")
        shape = np.broadcast_shapes(q.shape[:-1], v.shape[:-1])
        v = np.ascontiguousarray(np.broadcast_to(v, shape + (self.nv,)))
        return lie_integrate_jacobians(self._block_names, v, float(dt))

    def difference_jacobians(self, q0, q1) -> tuple:
        """(∂ difference/∂q0, ∂ difference/∂q1), each (nv, nv) or (..., nv, nv), in the tangent spaces
        (as Pinocchio's ``dDifference`` ARG0 and ARG1): -Jl⁻¹(d) and Jr⁻¹(d) per multi-DOF joint,
        d = difference(q0, q1); -1 and 1 for 1-DOF joints (the core's ``lie::difference_jacobians_block``)."""
        return lie_difference_jacobians(self._block_names, *self._pair(q0, q1))

    def normalize(self, q) -> np.ndarray:
        """``q`` with each quaternion and planar (cos, sin) pair divided by its norm (a copy)."""
        a = self._array(q, self.nq, "q", "nq")
        if not np.all(np.isfinite(a)):  # NaN, inf, and None (which NumPy reads as NaN)
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
            raise ValueError(f"q{list(bad)} ({self._describe(bad[-1])}) is {a[bad]}: a configuration must be finite")
        out = np.array(a, dtype=float)
        for block, columns, what in self._unit_parts:
            norm = vector_norm(out[..., columns])
            if not np.all(norm > 1e-12) or not np.all(np.isfinite(norm)):
                raise ValueError(
                    f"q[{columns[0]}:{columns[-1] + 1}] of joint '{block.joint.name}': a {what} of norm "
                    f"{np.min(norm) if np.all(np.isfinite(norm)) else 'nan/inf'} cannot be normalised"
                )
            out[..., columns] = out[..., columns] / norm[..., None]
        return out

    def random(self, rng: SeedLike = None, size: int | None = None) -> np.ndarray:
        """Random configurations: 1-DOF joints uniform within their limits (an infinite side replaced
        by ±π for revolute, ±1 for prismatic joints); quaternions uniform over rotations (Shoemake
        1992); free-flyer and planar positions uniform in the joint's limits when finite, else in
        [-1, 1]; planar angles uniform in [-π, π)."""
        if size is not None and not (isinstance(size, (int, np.integer)) and not isinstance(size, bool) and size >= 0):
            raise ValueError(f"size must be a whole number of configurations >= 0 (or None for one), got {size!r}")
        rng = np.random.default_rng(rng)
        lead = () if size is None else (int(size),)
        out = np.broadcast_to(self.neutral(), lead + (self.nq,)).copy()
        scalar = [b for b in self.blocks if b.joint.nq == 1]
        if scalar:
            # the same draws as before multi-DOF joints existed (one uniform call over the 1-DOF joints)
            lo, hi = _sampling_range([b.joint for b in scalar])
            out[..., self._scalar_q] = rng.uniform(lo, hi, size=lead + (len(scalar),))
        for b in self.blocks:
            kind = b.joint.kind
            if kind in ("floating", "planar"):
                k = 3 if kind == "floating" else 2
                lo, hi = _sampling_range([b.joint], position=True)
                out[..., b.iq : b.iq + k] = rng.uniform(lo[0], hi[0], size=lead + (k,))
                if kind == "planar":
                    theta = rng.uniform(-np.pi, np.pi, size=lead)
                    out[..., b.iq + 2], out[..., b.iq + 3] = np.cos(theta), np.sin(theta)
            if kind in ("floating", "spherical"):
                start = b.iq + (3 if kind == "floating" else 0)
                out[..., start : start + 4] = _uniform_quaternions(rng, lead)
        return out


def _sampling_range(joints, position: bool = False) -> tuple:
    lo = np.array([j.lower for j in joints], dtype=float)
    hi = np.array([j.upper for j in joints], dtype=float)
    for i, j in enumerate(joints):
        # an infinite side is replaced by one span beyond the finite side (or -span..span): a one-sided
        # limit such as lower=5 (upper inf) must not give lo > hi
        span = math.pi if (j.kind == "revolute" and not position) else 1.0
        if not math.isfinite(lo[i]):
            lo[i] = min(-span, hi[i] - 2 * span) if math.isfinite(hi[i]) else -span
        if not math.isfinite(hi[i]):
            hi[i] = max(span, lo[i] + 2 * span)
    return lo, hi


def _uniform_quaternions(rng: np.random.Generator, lead: tuple) -> np.ndarray:
    # Shoemake (1992): with u1, u2, u3 uniform in [0, 1), (√(1-u1) sin 2πu2, √(1-u1) cos 2πu2,
    # √u1 sin 2πu3, √u1 cos 2πu3) is uniform on the unit 3-sphere, hence over rotations
    u = rng.random(lead + (3,))
    a, b = np.sqrt(1.0 - u[..., 0]), np.sqrt(u[..., 0])
    t2, t3 = 2 * np.pi * u[..., 1], 2 * np.pi * u[..., 2]
    return np.stack([a * np.sin(t2), a * np.cos(t2), b * np.sin(t3), b * np.cos(t3)], axis=-1)


_SPACES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


# ---------------------------------------------------------------------- functions of a robot
def space(robot: Robot) -> ConfigurationSpace:
    """The :class:`ConfigurationSpace` of ``robot``'s moving joints, in body order."""
    return ConfigurationSpace.of(robot)


def neutral(robot: Robot) -> np.ndarray:
    """The neutral configuration (nq,): zeros, identity quaternions (0, 0, 0, 1), planar (0, 0, 1, 0)."""
    return space(robot).neutral()


def integrate(robot: Robot, q: ArrayLike, v: ArrayLike, dt: ArrayLike = 1.0) -> np.ndarray:
    """q ⊕ v dt: (nq,) or a batch (N, nq) (see the module docstring for each joint kind)."""
    return space(robot).integrate(q, v, dt)


def difference(robot: Robot, q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
    """v (nv,) or (N, nv) with integrate(q0, v) = q1, the short way round for rotations."""
    return space(robot).difference(q0, q1)


def interpolate(robot: Robot, q0: ArrayLike, q1: ArrayLike, t: ArrayLike) -> np.ndarray:
    """q0 ⊕ t · difference(q0, q1): the geodesic between two configurations."""
    return space(robot).interpolate(q0, q1, t)


def random_configuration(robot: Robot, rng: SeedLike = None, size: int | None = None) -> np.ndarray:
    """Random configurations (nq,) or (size, nq): see :meth:`ConfigurationSpace.random`."""
    return space(robot).random(rng, size)


def normalize(robot: Robot, q: ArrayLike) -> np.ndarray:
    """``q`` with its quaternions and planar (cos, sin) pairs made unit."""
    return space(robot).normalize(q)


def check_configuration(robot: Robot, q: ArrayLike) -> np.ndarray:
    """``q`` as a float array if it is a configuration of ``robot``, else a ValueError naming the joint
    and block: the length is not nq, a number is NaN or infinite, or a quaternion or planar
    (cos θ, sin θ) pair has a norm further than :data:`UNIT_TOLERANCE` (1e-6) from 1."""
    return space(robot).check(q)


def integrate_jacobians(robot: Robot, q: ArrayLike, v: ArrayLike, dt: float = 1.0) -> tuple:
    """(∂(q ⊕ v dt)/∂q, ∂(q ⊕ v dt)/∂v): see :meth:`ConfigurationSpace.integrate_jacobians`."""
    return space(robot).integrate_jacobians(q, v, dt)


def difference_jacobians(robot: Robot, q0: ArrayLike, q1: ArrayLike) -> tuple:
    """(∂ difference/∂q0, ∂ difference/∂q1): see :meth:`ConfigurationSpace.difference_jacobians`."""
    return space(robot).difference_jacobians(q0, q1)


def default_configuration(robot: Robot) -> np.ndarray:
    """A generic (non-singular) configuration: 0.5, -0.7, 0.5, -0.7, ... rad (m for prismatic joints,
    x 0.2), clipped to the joint limits; a multi-DOF joint keeps its neutral block (identity rotation).
    The report, the viewer and the notebook drawings start here, where the structure shows (q = 0 is
    often singular). A robot with closed loops gets that configuration projected onto its loops
    (``robot.project_configuration``: the nearest closed one, least-norm Gauss-Newton steps), so that
    every drawing shows the chain closed; where no closed configuration is near it, the open one.
    The projection starts from the description's reference configuration where it states one (the
    mechanism's assembly mode: the projection of the generic configuration may land on another
    branch, a five-bar's crossed linkage for its parallelogram), its joints at their stated values
    and the others at the generic ones. (docs/closed-loops.md, "Motion")"""
    q, start = robot.neutral(), 0
    for i, j in enumerate(robot.joints):
        if not j.is_multi_dof:
            q[start] = (0.5 if i % 2 == 0 else -0.7) * (1.0 if j.kind == "revolute" else 0.2)
        start += j.nq
    q = np.clip(q, robot.lower_limits, robot.upper_limits)
    reference = getattr(getattr(robot, "description", None), "reference_configuration", None)
    if reference and getattr(robot, "loops", ()):
        start = 0
        for j in robot.joints:  # a reduced mimic follower is no coordinate: its stated value is implied
            if j.name in reference:
                q[start : start + j.nq] = reference[j.name]
            start += j.nq
        q = robot.normalize(q)  # a stated quaternion rounded in the file
    if getattr(robot, "loops", ()):
        try:
            q = np.asarray(robot.project_configuration(q), dtype=float)
        except ValueError:  # no closed configuration near this one (or loops the core cannot hold): drawn open
            pass
    return q
