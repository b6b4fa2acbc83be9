"""Inertia bounds ``lambda_min I <= M(q) <= lambda_max I`` (Spong eqs. 9.119-9.120) by a global
search over the configurations: :func:`global_inertia_bounds` for any ``M(q)`` with its gradient,
:func:`robot_inertia_bounds` over a robot's configuration space (a box of coordinates for 1-DOF
joints, the coordinates of :class:`ManifoldChart` with multi-DOF joints)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..configuration import exp3, quaternion_to_matrix
from ..property_checks import InertiaBounds, global_inertia_bounds

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = [
    "InertiaBounds",
    "global_inertia_bounds",
    "robot_inertia_bounds",
    "ManifoldChart",
    "joint_box",
    "configuration_box",
]


def joint_box(joint) -> tuple:
    """(lower, upper, periodic) of a 1-DOF joint's coordinate as random_configuration draws it: its
    finite limits, else [-pi, pi] (revolute, then periodic) or [-1, 1] (prismatic)."""
    lo, hi = float(joint.lower), float(joint.upper)
    span = np.pi if joint.kind == "revolute" else 1.0
    periodic = joint.kind == "revolute" and not np.isfinite(lo) and not np.isfinite(hi)
    if not np.isfinite(lo):
        lo = min(-span, hi - 2 * span) if np.isfinite(hi) else -span
    if not np.isfinite(hi):
        hi = max(span, lo + 2 * span)
    return lo, hi, periodic


def configuration_box(robot: Robot):
    """The box random_configuration draws from, for a robot of 1-DOF joints (:func:`joint_box` each)."""
    lo, hi, periodic = zip(*(joint_box(j) for j in robot.joints)) if robot.joints else ((), (), ())
    return np.array(lo, dtype=float), np.array(hi, dtype=float), np.array(periodic, dtype=bool)


def _right_jacobian_so3(r: np.ndarray) -> np.ndarray:
    """J_r(r) with Exp(r + d) = Exp(r) Exp(J_r(r) d + O(d^2)): I - a [r]x + b [r]x^2, a = (1 - cos t)/t^2,
    b = (t - sin t)/t^3, t = |r| (Sola, Deray & Atchuthan 2018, eq. 143); their series below t = 1e-3."""
    t = float(np.linalg.norm(r))
    if t < 1e-3:
        a, b = 0.5 - t * t / 24, 1 / 6 - t * t / 120
    else:
        a, b = (1 - np.cos(t)) / t**2, (t - np.sin(t)) / t**3
    K = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    return np.eye(3) - a * K + b * K @ K


def _shortest_rotation_vector(r: np.ndarray) -> np.ndarray:
    """The rotation vector of the same rotation as ``r`` with |r| <= pi."""
    t = float(np.linalg.norm(r))
    if t <= np.pi:
        return r
    t_short = (t + np.pi) % (2 * np.pi) - np.pi  # in [-pi, pi): the same rotation about r / |r|
    return r * (t_short / t)


class ManifoldChart:
    """Coordinates x of a robot's configurations for the inertia-bound search when it has multi-DOF
    joints, whose q (nq) is no box: a 1-DOF joint's x is its q; a free-flyer's x is its position
    (x, y, z) in the parent frame, then the rotation vector r of its rotation R = Exp(r); a spherical
    joint's x is r; a planar joint's x is (x, y, theta). The positions lie in the box
    random_configuration draws from (the joint's limits, else [-1, 1]); rotation vectors and angles
    are searched unbounded (a rotation vector reported with |r| <= pi). A multi-DOF joint on the fixed
    base (a floating base) is held at its identity: with velocities in the child's frame every body's
    velocity, hence M, does not depend on its configuration (the kinetic energy is left-invariant).

    :meth:`tangent` is the map T from dx to the velocity v (q(x + dx) = q(x) ⊕ T dx + O(dx^2)), so
    dM/dx_k = sum_j T_jk D_j M with D_j M the derivative along q ⊕ t e_j (robot.christoffel: c + c^T)."""

    def __init__(self, robot: Robot):
        self.robot = robot
        roots = {b.joint.name for b in robot.tree.bodies if b.parent < 0}
        self.blocks = []  # (joint, iq, iv, ix); ix None: held at its identity
        lower, upper, periodic = [], [], []
        iq = iv = ix = 0
        for j in robot.joints:
            held = j.is_multi_dof and j.name in roots
            self.blocks.append((j, iq, iv, None if held else ix))
            iq, iv = iq + j.nq, iv + j.nv
            if held:
                continue
            ix += j.nv
            if j.kind in ("floating", "planar"):
                k = 3 if j.kind == "floating" else 2
                lo, hi, _ = joint_box(j)  # the box random_configuration draws a position from
                lower += [lo] * k
                upper += [hi] * k
                periodic += [False] * k
            if j.is_multi_dof:
                k = 1 if j.kind == "planar" else 3
                lower += [-np.pi] * k
                upper += [np.pi] * k
                periodic += [True] * k
            else:  # 1-DOF: its own coordinate, in the box random_configuration draws from
                lo_j, hi_j, periodic_j = joint_box(j)
                lower.append(lo_j)
                upper.append(hi_j)
                periodic.append(periodic_j)
        self.lower, self.upper, self.periodic = np.array(lower), np.array(upper), np.array(periodic, dtype=bool)
        self.nq, self.nv, self.nx = iq, iv, ix
        self.neutral = robot.neutral()

    def configuration(self, x) -> np.ndarray:
        """q (nq,) of x (nx,), or (N, nq) of (N, nx)."""
        x = np.asarray(x, dtype=float)
        q = np.broadcast_to(self.neutral, x.shape[:-1] + (self.nq,)).copy()
        for j, iq, _iv, ix in self.blocks:
            if ix is None:
                continue
            if j.kind == "floating":
                q[..., iq : iq + 3] = x[..., ix : ix + 3]
                q[..., iq + 3 : iq + 7] = exp3(x[..., ix + 3 : ix + 6])
            elif j.kind == "spherical":
                q[..., iq : iq + 4] = exp3(x[..., ix : ix + 3])
            elif j.kind == "planar":
                q[..., iq : iq + 2] = x[..., ix : ix + 2]
                q[..., iq + 2], q[..., iq + 3] = np.cos(x[..., ix + 2]), np.sin(x[..., ix + 2])
            else:
                q[..., iq] = x[..., ix]
        return q

    def tangent(self, x) -> np.ndarray:
        """T (nv, nx) at one x: column k is the velocity v with q(x + t e_k) = q(x) ⊕ t v + O(t^2)."""
        x = np.asarray(x, dtype=float)
        T = np.zeros((self.nv, self.nx))
        for j, _iq, iv, ix in self.blocks:
            if ix is None:
                continue
            if j.kind == "floating":  # ⊕ [rho; 0] moves the position by R rho; ⊕ [0; w] turns R to R Exp(w)
                T[iv : iv + 3, ix : ix + 3] = quaternion_to_matrix(exp3(x[ix + 3 : ix + 6])).T
                T[iv + 3 : iv + 6, ix + 3 : ix + 6] = _right_jacobian_so3(x[ix + 3 : ix + 6])
            elif j.kind == "spherical":
                T[iv : iv + 3, ix : ix + 3] = _right_jacobian_so3(x[ix : ix + 3])
            elif j.kind == "planar":  # in SE(2): ⊕ (rho, 0) moves the position by R(theta) rho
                c, s_ = np.cos(x[ix + 2]), np.sin(x[ix + 2])
                T[iv : iv + 2, ix : ix + 2] = np.array([[c, s_], [-s_, c]])
                T[iv + 2, ix + 2] = 1.0
            else:
                T[iv, ix] = 1.0
        return T

    def wrap(self, x) -> np.ndarray:
        """The reported representative of x: angles in [-pi, pi), rotation vectors with |r| <= pi."""
        x = np.array(x, dtype=float)
        for j, _iq, _iv, ix in self.blocks:
            if ix is None:
                continue
            if j.kind == "floating":
                x[ix + 3 : ix + 6] = _shortest_rotation_vector(x[ix + 3 : ix + 6])
            elif j.kind == "spherical":
                x[ix : ix + 3] = _shortest_rotation_vector(x[ix : ix + 3])
            elif j.kind == "planar":
                x[ix + 2] = (x[ix + 2] + np.pi) % (2 * np.pi) - np.pi
            elif self.periodic[ix]:
                x[ix] = (x[ix] + np.pi) % (2 * np.pi) - np.pi
        return x

    def describe(self) -> str:
        parts = []
        for j, _iq, _iv, ix in self.blocks:
            if ix is None:
                parts.append(
                    f"{j.name}: held at its identity (M does not depend on a {j.kind} joint on the fixed base)"
                )
            elif j.kind in ("floating", "planar"):
                k = 3 if j.kind == "floating" else 2
                parts.append(
                    f"{j.name}: position in [{self.lower[ix]:.3g}, {self.upper[ix]:.3g}]^{k}, "
                    + ("every rotation" if j.kind == "floating" else "every angle")
                )
            elif j.kind == "spherical":
                parts.append(f"{j.name}: every rotation")
            elif self.periodic[ix]:
                parts.append(f"{j.name}: periodic")
            else:
                parts.append(f"{j.name}: [{self.lower[ix]:.3g}, {self.upper[ix]:.3g}]")
        if self.nx == 0:
            return "; ".join(parts)
        return (
            "; ".join(parts) + " (searched in coordinates of the manifold: positions, rotation vectors, angles; "
            "the configurations above are q, quaternions (x, y, z, w))"
        )


def robot_inertia_bounds(
    robot: Robot,
    samples: int,
    starts: int,
    seed: int,
    time_budget: float | None = None,
    progress: bool | None = False,
) -> InertiaBounds:
    """:func:`global_inertia_bounds` over the robot's configurations: over the box of its coordinates
    for 1-DOF joints, over the coordinates of :class:`ManifoldChart` with multi-DOF joints (whose
    configurations are then reported as q, nq numbers). dM/dq_i = c_i + c_i^T from the engine's
    Christoffel symbols (c[i, j, k] + c[i, k, j] = dM_kj/dq_i, Spong eq. 9.58; along q ⊕ t e_i).
    ``time_budget``, ``progress``: of the search (:func:`global_inertia_bounds`)."""

    def tangent_dM(q):
        c = np.asarray(robot.christoffel(q), dtype=float)
        return c + np.swapaxes(c, 1, 2)

    if not robot.has_multi_dof_joints:
        box_lo, box_hi, periodic = configuration_box(robot)
        return global_inertia_bounds(
            robot.mass_matrix,
            tangent_dM,
            box_lo,
            box_hi,
            periodic,
            samples=samples,
            starts=starts,
            seed=seed,
            time_budget=time_budget,
            progress=progress,
        )
    chart = ManifoldChart(robot)
    if chart.nx == 0:  # a floating body alone (a drone): M is one constant matrix
        q0 = chart.neutral
        eig = np.linalg.eigvalsh(robot.mass_matrix(q0))
        return InertiaBounds(
            float(eig[0]),
            q0,
            float(eig[-1]),
            q0,
            float(eig[0]),
            float(eig[-1]),
            1,
            0,
            chart.lower,
            chart.upper,
            chart.periodic,
            space=chart.describe() + ": M is constant, its extreme eigenvalues are the bounds",
        )

    def dM_dx(x):
        return np.einsum("jk,jab->kab", chart.tangent(x), tangent_dM(chart.configuration(x)))

    b = global_inertia_bounds(
        lambda x: robot.mass_matrix(chart.configuration(x)),
        dM_dx,
        chart.lower,
        chart.upper,
        chart.periodic,
        samples=samples,
        starts=starts,
        seed=seed,
        wrap=chart.wrap,
        time_budget=time_budget,
        progress=progress,
    )
    b.q_lambda_min = chart.configuration(b.q_lambda_min)
    b.q_lambda_max = chart.configuration(b.q_lambda_max)
    b.space = chart.describe()
    return b
