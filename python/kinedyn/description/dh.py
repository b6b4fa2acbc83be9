"""Denavit-Hartenberg tables -> links.

Conventions (docs/conventions.md):
- ``"standard"`` (Spong, Corke): A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i); joint i moves about
  / along z_{i-1}; link frame i is DH frame i (at the far end of link i).
- ``"modified"`` (Craig): A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i); each row holds
  (alpha_{i-1}, a_{i-1}, theta_i, d_i); link frame i sits on joint i's axis.
For a revolute joint ``theta`` is the joint offset (joint angle = q + theta); for a prismatic joint
``d`` is (joint displacement = q + d). Inertias are given in link frame i.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._lazy import LazyModule, sympy_instance
from .._math import identity, matmul, pose_inverse, rot_axis, rot_x, rot_z, translation
from .checks import number
from .description import Description
from .inertia import Inertia
from .joint import Joint
from .link import Frame, Link

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = ["DHRow", "links_from_dh", "description_from_dh", "dh_from_robot", "DHExtraction", "MasslessRobotWarning"]


class MasslessRobotWarning(UserWarning):
    """A DH table whose rows carry no mass, inertia or rotor inertia: M(q) = 0, so the robot serves
    kinematics (FK, Jacobians, IK) but not dynamics; said when it is built, not at the first
    forward-dynamics error."""


def _is_zero(value) -> bool:
    try:
        return float(value) == 0.0
    except TypeError:  # a symbolic parameter: not known to be zero
        return False


def _massless(links) -> bool:
    """No link has mass, rotational inertia or rotor inertia (numerically zero)."""
    return all(
        _is_zero(link.inertia.mass)
        and all(_is_zero(x) for row in np.asarray(link.inertia.inertia, dtype=object) for x in row)
        and _is_zero(link.joint.rotor_inertia)
        for link in links
    )


@dataclass(frozen=True)
class DHRow:
    theta: Any = 0.0
    d: Any = 0.0
    a: Any = 0.0
    alpha: Any = 0.0
    kind: str = "revolute"
    name: str | None = None
    inertia: Inertia = field(default_factory=Inertia)
    lower: float = -math.inf
    upper: float = math.inf
    velocity_limit: float = math.inf
    effort_limit: float = math.inf
    gear_ratio: Any = 1.0
    rotor_inertia: Any = 0.0
    viscous: Any = 0.0
    coulomb: Any = 0.0  # one level, or (positive, negative) levels: see Joint
    coulomb_negative: Any = None

    def __post_init__(self):
        # coulomb=(positive, negative) is stored as the two fields, as Joint stores it
        if isinstance(self.coulomb, (tuple, list)):
            if len(self.coulomb) != 2 or self.coulomb_negative is not None:
                raise ValueError(
                    f"DH row '{self.name}': coulomb must be one level or a pair (positive, negative), given once; got {self.coulomb!r}"
                )
            object.__setattr__(self, "coulomb_negative", self.coulomb[1])
            object.__setattr__(self, "coulomb", self.coulomb[0])

    @classmethod
    def from_mapping(cls, row: dict, index: int) -> DHRow:
        known = {f.name for f in fields(cls)}
        row = dict(row)
        if "type" in row:
            row["kind"] = row.pop("type")
        if "qlim" in row:
            row["lower"], row["upper"] = row.pop("qlim")
        if "offset" in row:  # an explicit joint offset adds to theta (revolute) or d (prismatic)
            off = row.pop("offset")
            key = "d" if row.get("kind", "revolute") == "prismatic" else "theta"
            row[key] = row.get(key, 0.0) + off
        unknown = set(row) - known
        if unknown:
            raise ValueError(f"DH row {index + 1}: unknown keys {sorted(unknown)} (known: {sorted(known)})")
        return cls(**row)


def _row(row, index: int) -> DHRow:
    if isinstance(row, DHRow):
        return row
    if isinstance(row, dict):
        return DHRow.from_mapping(row, index)
    values = list(row)
    if len(values) not in (4, 5):
        raise ValueError(
            f"DH row {index + 1}: expected (theta, d, a, alpha[, kind]) or a mapping, got {len(values)} values"
        )
    return DHRow(*values)


def links_from_dh(rows, convention: str = "standard"):
    """One Link per DH row; joint i is named ``q{i}`` unless the row names it."""
    if convention not in ("standard", "modified"):
        raise ValueError(f"DH convention must be 'standard' or 'modified', got '{convention}'")
    rows = [_row(r, i) for i, r in enumerate(rows)]
    if not rows:
        raise ValueError("a DH table needs at least one row")
    links = []
    parent = None
    for i, r in enumerate(rows, start=1):
        if r.kind not in ("revolute", "prismatic"):
            raise ValueError(f"DH row {i}: kind must be 'revolute' or 'prismatic', got '{r.kind}'")
        # real, finite, sane numbers (or symbols) before they enter the transforms; exact SymPy
        # numbers (pi / 2) stay exact, so symbolic DH robots keep their exact zeros
        checked = {key: number(getattr(r, key), f"DH row {i}: {key}") for key in ("theta", "d", "a", "alpha")}
        r = replace(r, **{k: v for k, v in checked.items() if not sympy_instance(getattr(r, k), "Basic")})
        revolute = r.kind == "revolute"
        joint = Joint(
            name=r.name or f"q{i}",
            kind=r.kind,
            axis=(0.0, 0.0, 1.0),
            offset=r.theta if revolute else r.d,
            lower=r.lower,
            upper=r.upper,
            velocity_limit=r.velocity_limit,
            effort_limit=r.effort_limit,
            gear_ratio=r.gear_ratio,
            rotor_inertia=r.rotor_inertia,
            viscous=r.viscous,
            coulomb=r.coulomb,
            coulomb_negative=r.coulomb_negative,
        )
        if convention == "standard":
            # Rz(theta) Tz(d) | Tx(a) Rx(alpha): the joint moves first, the rest is fixed to link i
            placement = translation(0, 0, 0) if revolute else rot_z(r.theta)
            post = (
                matmul(translation(0, 0, r.d), translation(r.a, 0, 0), rot_x(r.alpha))
                if revolute
                else matmul(translation(r.a, 0, 0), rot_x(r.alpha))
            )
        else:
            # Rx(alpha_{i-1}) Tx(a_{i-1}) | Rz(theta_i) Tz(d_i): fixed part first, then the joint
            placement = matmul(
                rot_x(r.alpha), translation(r.a, 0, 0), translation(0, 0, r.d) if revolute else rot_z(r.theta)
            )
            post = translation(0, 0, 0)
        name = f"link{i}"
        links.append(Link(name, parent, joint, placement, post, r.inertia))
        parent = name
    return links, rows


# ------------------------------------------------------------------------------------------------
# Robot -> DH table (the reverse direction): where a chain admits a DH description
def description_from_dh(
    rows,
    convention: str = "standard",
    *,
    gravity=(0.0, 0.0, -9.81),
    base_pose=None,
    tool=None,
    name: str = "dh_robot",
    source: str = "",
    inertia: str = "warn",
) -> Description:
    """The description of a serial arm from a DH table (what :meth:`kinedyn.Robot.from_dh` builds).

    ``rows``: DHRow objects, mappings with keys theta/d/a/alpha/kind/inertia/limits..., or tuples
    ``(theta, d, a, alpha[, kind])``. ``base_pose``: the 4x4 pose of DH frame 0 in the world.
    ``tool``: the 4x4 pose of the tool in the last link frame (a frame named "tool" is always added;
    identity if not given). ``inertia``: the inertia policy (docs/model-files.md).
    """
    links, dh_rows = links_from_dh(rows, convention)
    if base_pose is not None:
        first = links[0]
        links[0] = Link(first.name, None, first.joint, matmul(base_pose, first.placement), first.post, first.inertia)
    frames = (Frame("tool", links[-1].name, identity() if tool is None else tool),)
    if links and _massless(links):
        warnings.warn(
            f"robot '{name}': no DH row gives a mass, an inertia or a rotor inertia, so M(q) = 0: fine for "
            "kinematics (FK, Jacobians, IK), but the dynamics (forward dynamics, simulation) need them: give each "
            "row an inertia, e.g. DHRow(a=0.5, inertia=kd.Inertia.rod(2.0, 0.5)) or {'a': 0.5, 'inertia': ...}",
            MasslessRobotWarning,
            stacklevel=3,
        )
    return Description(
        tuple(links),
        frames,
        gravity=gravity,
        name=name,
        dh=dh_rows,
        dh_convention=convention,
        source=source,
        inertia=inertia,
    )


@dataclass(frozen=True)
class DHExtraction:
    """What :func:`dh_from_robot` found: the DH ``rows``, their ``convention``, ``base_pose`` (DH frame
    0 in the source's base frame), ``tool`` (the source's tool frame in the last DH frame) and
    ``robot``, the DH robot built from them (``Robot.from_dh``) carrying the source's inertias and
    drive data, with every named frame of the source that does not clash with a DH name
    (``link1`` ... ``linkN``, ``tool``) as an extra frame. ``source_frames`` maps every named frame of
    the source (clashing ones included) to ``(DH frame name, its pose in that frame)``."""

    rows: tuple
    convention: str
    base_pose: Any
    tool: Any
    robot: Any
    source_frames: dict = field(default_factory=dict)


def _common_normal(p1, u1, p2, u2, eps: float):
    """Feet (f1 on line 1, f2 on line 2) and unit direction x of the common normal of the lines
    p + s u, or None when they are parallel. Intersecting lines: f1 == f2, x = ±u1 × u2."""

    w = np.cross(u1, u2)
    if np.linalg.norm(w) < eps:
        return None
    n = w / np.linalg.norm(w)
    dist = float((p2 - p1) @ n)
    # p1 + s u1 + dist n = p2 + t u2: two unknowns, three equations (consistent by construction)
    A = np.column_stack([u1, -u2])
    s, t = np.linalg.lstsq(A, p2 - p1 - dist * n, rcond=None)[0]
    f1, f2 = p1 + s * u1, p2 + t * u2
    if abs(dist) < eps:
        return f1, f1, n
    return f1, f2, n * math.copysign(1.0, dist)


def _frame(origin, x, z):

    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, origin
    return T


def _perpendicular(v, z, fallback):
    """The unit part of v perpendicular to z, or of ``fallback`` when v has none."""

    for c in (v, fallback, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        p = c - (c @ z) * z
        if np.linalg.norm(p) > 1e-9:
            return p / np.linalg.norm(p)
    raise AssertionError("unreachable: x and y cannot both be parallel to a unit z")


def dh_from_robot(robot, convention: str = "standard", *, tolerance: float = 1e-9) -> DHExtraction:
    """The DH table of a serial chain of revolute and prismatic joints (fixed links allowed: they
    are merged), with the base and tool transforms it needs, such that
    ``base_pose · A_1(q_1) ... A_n(q_n) · tool`` is the source's tool pose for every q.

    The DH frames are built from the joint axes at q = 0 (Spong §3.2, Craig §3.4): z along each
    joint axis, x along the common normal of consecutive axes (the cross product of intersecting
    axes; for parallel axes the normal through the previous frame's origin, so that d = 0), and
    the parameters read off consecutive frames; a joint's position at q = 0 becomes the row's
    theta (revolute) or d (prismatic) offset, so the DH robot's q is the source's q. Standard DH
    frame 0 lies on the first axis at the foot of the base origin, frame n at the tool origin
    (z_n = z_{n-1}); modified DH frame 0 is frame 1 at q = 0. Inertias (about each link's
    centre of mass) and drive data (limits, gear ratio, rotor inertia, friction) are carried over.

    ValueError naming the joint where the robot is no such chain: a branch (two moving joints on
    one link), a floating, spherical or planar joint, symbolic parameters. ``tolerance``: axes
    closer to parallel (|u1 × u2|), and lines closer (m), count as parallel / intersecting."""

    if convention not in ("standard", "modified"):
        raise ValueError(f"DH convention must be 'standard' or 'modified', got '{convention}'")
    if robot.is_symbolic:
        raise ValueError(
            f"dh_from_robot: robot '{robot.name}' has symbolic parameters {sorted(map(str, robot.symbols))}: substitute numbers first (robot.subs)"
        )
    bodies = robot.tree.bodies
    for i, b in enumerate(bodies):
        if b.joint.kind not in ("revolute", "prismatic"):
            raise ValueError(
                f"dh_from_robot: joint '{b.joint.name}' is {b.joint.kind}; a DH row holds one revolute or prismatic joint"
            )
        if b.parent != i - 1:
            other = next(c.joint.name for c in bodies if c.parent == b.parent)
            where = f"link '{bodies[b.parent].name}'" if b.parent >= 0 else f"the base '{robot.base}'"
            raise ValueError(
                f"dh_from_robot: joint '{b.joint.name}' branches off {where}, which also carries joint '{other}'; "
                "a DH table describes a serial chain (lock one branch first: robot.lock_joints([...]))"
            )
    n = len(bodies)
    # world poses of the body frames at q = 0 (each joint at its offset): W_B_i = W_B_parent P_i M(offset_i)
    world_body: list = []
    for b in bodies:
        axis = [float(a) for a in b.joint.axis]
        off = float(b.joint.offset)
        motion = rot_axis(axis, off) if b.joint.kind == "revolute" else translation(*(a * off for a in axis))
        parent = world_body[b.parent] if b.parent >= 0 else np.eye(4)
        world_body.append(parent @ np.asarray(b.placement, dtype=float) @ np.asarray(motion, dtype=float))
    u = [W[:3, :3] @ np.array([float(a) for a in b.joint.axis]) for W, b in zip(world_body, bodies)]
    p = [W[:3, 3] for W in world_body]
    named = {f.name: f for f in robot.tree.frames}

    def world_frame(name):
        f = named[name]
        return (world_body[f.body] if f.body >= 0 else np.eye(4)) @ np.asarray(f.placement, dtype=float)

    world_tool = world_frame(robot.tool)
    eps = tolerance
    frames = []  # world poses of DH frames 0..n at q = 0
    if convention == "standard":
        # frame 0: z0 on axis 1, origin at the foot of the base origin, x0 from the base's x
        o0 = p[0] + (-p[0] @ u[0]) * u[0]
        frames.append(_frame(o0, _perpendicular(np.array([1.0, 0.0, 0.0]), u[0], np.array([0.0, 1.0, 0.0])), u[0]))
        for i in range(1, n):  # frame i: z_i on axis i+1, x_i the common normal from axis i to axis i+1
            prev = frames[-1]
            normal = _common_normal(p[i - 1], u[i - 1], p[i], u[i], eps)
            if normal is None:  # parallel: the normal through the previous origin (d_i = 0)
                foot = p[i] + ((prev[:3, 3] - p[i]) @ u[i]) * u[i]
                x = _perpendicular(foot - prev[:3, 3], u[i - 1], prev[:3, 0])
                origin = foot
            else:
                _, origin, x = normal
            frames.append(_frame(origin, x, u[i]))
        prev = frames[-1]
        # frame n: z_n = z_{n-1}, at the tool origin, x_n its direction off the last axis
        x = _perpendicular(world_tool[:3, 3] - prev[:3, 3], u[n - 1], prev[:3, 0])
        frames.append(_frame(world_tool[:3, 3], x, u[n - 1]))
    else:
        frame_of: list = [None] * (n + 1)
        for i in range(n):  # frame i+1 on axis i+1: x along the common normal to axis i+2
            if i == 0:
                start = p[0]
            else:  # where the previous x axis meets this axis (d = 0 for parallel axes)
                pr = frame_of[i]
                start = p[i] + ((pr[:3, 3] - p[i]) @ u[i]) * u[i]
            if i + 1 < n:
                normal = _common_normal(p[i], u[i], p[i + 1], u[i + 1], eps)
                if normal is None:
                    foot_next = p[i + 1] + ((start - p[i + 1]) @ u[i + 1]) * u[i + 1]
                    origin, x = (
                        start,
                        _perpendicular(foot_next - start, u[i], frame_of[i][:3, 0] if i else world_body[0][:3, 0]),
                    )
                else:
                    origin, _, x = normal
            else:  # last frame: on the last axis at the foot of the tool origin, x toward the tool
                origin = p[i] + ((world_tool[:3, 3] - p[i]) @ u[i]) * u[i]
                x = _perpendicular(world_tool[:3, 3] - origin, u[i], frame_of[i][:3, 0] if i else world_body[0][:3, 0])
            frame_of[i + 1] = _frame(origin, x, u[i])
        frame_of[0] = frame_of[1]
        frames = frame_of

    rows = []
    for i in range(1, n + 1):
        F0, F1 = frames[i - 1], frames[i]
        x0, z0, o0 = F0[:3, 0], F0[:3, 2], F0[:3, 3]
        x1, z1, o1 = F1[:3, 0], F1[:3, 2], F1[:3, 3]
        step = o1 - o0
        if convention == "standard":  # A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha): along z_{i-1}, then x_i
            theta = math.atan2(float(np.cross(x0, x1) @ z0), float(x0 @ x1))
            d, a = float(step @ z0), float(step @ x1)
            alpha = math.atan2(float(np.cross(z0, z1) @ x1), float(z0 @ z1))
        else:  # A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i): along x_{i-1}, then z_i
            alpha = math.atan2(float(np.cross(z0, z1) @ x0), float(z0 @ z1))
            a, d = float(step @ x0), float(step @ z1)
            theta = math.atan2(float(np.cross(x0, x1) @ z1), float(x0 @ x1))
        b = bodies[i - 1]
        j = b.joint
        # link i's inertia moves from its body frame into DH frame i (both fixed to link i)
        inertia = b.inertia.transformed(np.asarray(pose_inverse(F1), dtype=float) @ world_body[i - 1])
        rows.append(
            DHRow(
                theta + 0.0,
                d + 0.0,
                a + 0.0,
                alpha + 0.0,
                j.kind,
                j.name,
                inertia,
                j.lower,
                j.upper,
                j.velocity_limit,
                j.effort_limit,
                j.gear_ratio,
                j.rotor_inertia,
                j.viscous,
                j.coulomb,
                j.coulomb_negative,
            )
        )
    base_pose = frames[0]
    tool = np.asarray(pose_inverse(frames[n]), dtype=float) @ world_tool
    description = description_from_dh(
        rows,
        convention,
        gravity=robot.gravity,
        base_pose=base_pose,
        tool=tool,
        name=robot.name,
        source=robot.source,
        inertia=robot.inertia_policy if robot.inertia_policy != "strict" else "strict",
    )
    taken = {f.name for f in description.tree.frames}
    extra, source_frames = [], {}
    for f in robot.tree.frames[1:]:
        owner = None if f.body < 0 else f"link{f.body + 1}"
        owner_world = np.eye(4) if f.body < 0 else frames[f.body + 1]
        placement = np.asarray(pose_inverse(owner_world), dtype=float) @ world_frame(f.name)
        source_frames[f.name] = (owner or description.base, placement)
        if f.name not in taken:
            extra.append(Frame(f.name, owner, placement))
    if extra:
        description = replace(description, frames=description.frames + tuple(extra))
    # a robot of the input's own class, built from the description (this layer never imports Robot)
    dh_robot = robot.from_description(description)
    return DHExtraction(tuple(rows), convention, base_pose, tool, dh_robot, source_frames)
