"""A robot's drawable scene: every visual shape as coloured triangles fixed to a frame of the robot.

:func:`robot_scene` reads the robot's ``visuals`` (or ``collisions``): meshes through
:mod:`kinedyn.visual.meshes` (found by :func:`kinedyn.description.geometry.resolve_mesh`), primitives
built directly; the triangles are decimated so the whole robot fits ``budget`` triangles. A mesh that
cannot be found or read is a :class:`MissingMeshWarning` naming the file, and is left out (the stick
figure, drawn by every view, still shows that link). A robot with no visual geometry at all gets solid
links: a cylinder at each joint along its axis and cylinders from each joint to the next, split along
DH's d (the joint axis) and a (the common normal) for a robot built from a DH table.

The scene holds each shape once, in its frame's coordinates; a view moves it with the frame's pose
from the forward kinematics (``Robot.frame_poses``), so an animation sends poses, not vertices.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..description.geometry import DEFAULT_RGBA, Box, Cylinder, Mesh, MeshNotFound, Sphere, Visual, resolve_mesh
from .meshes import Part, box, cylinder, decimate, read_mesh, sphere

__all__ = ["Scene", "ScenePart", "MissingMeshWarning", "robot_scene", "DEFAULT_BUDGET"]

DEFAULT_BUDGET = 120_000  # triangles of a whole robot in a view (the Panda's meshes have ~600k)
LINK_RGBA = (0.47, 0.56, 0.61, 1.0)
REVOLUTE_RGBA = (1.0, 0.6, 0.0, 1.0)
PRISMATIC_RGBA = (0.56, 0.14, 0.67, 1.0)


class MissingMeshWarning(UserWarning):
    """A mesh named by the robot description could not be found or read; that shape is not drawn."""


@dataclass(frozen=True)
class ScenePart:
    frame: str  # the robot frame it is fixed to
    part: Part  # triangles in that frame's coordinates
    visual: int  # index of the Visual it came from (-1: generated solid link geometry)


@dataclass
class Scene:
    parts: list[ScenePart] = field(default_factory=list)
    shapes: int = 0  # visuals in the description (of the kind asked for)
    drawn: int = 0  # of those, how many are in ``parts`` (each may give several parts: one per colour)
    missing: list[str] = field(default_factory=list)  # messages of the shapes left out
    generated: bool = False  # solid link geometry made from the kinematics (no visuals described)

    @property
    def frames(self) -> list[str]:
        return sorted({p.frame for p in self.parts})

    @property
    def triangles(self) -> int:
        return sum(p.part.triangles for p in self.parts)


def _shape_parts(visual: Visual) -> list[Part]:
    s = visual.shape
    if isinstance(s, Mesh):
        found = resolve_mesh(s.filename, s.base_dir)
        try:
            parts = read_mesh(found)
        except ValueError as e:  # named as the description names it (a page holds no path of this machine)
            raise ValueError(str(e).replace(f"'{found}'", f"'{s.filename}'")) from None
        return [p.transformed(visual.origin, s.scale) for p in parts]
    if isinstance(s, Box):
        return [box(s.size).transformed(visual.origin)]
    if isinstance(s, Cylinder):
        return [cylinder(s.radius, s.length).transformed(visual.origin)]
    if isinstance(s, Sphere):
        return [sphere(s.radius).transformed(visual.origin)]
    raise ValueError(f"unknown shape {s!r}")


def robot_scene(robot, geometry: str = "visual", budget: int = DEFAULT_BUDGET, solid_links: bool = True) -> Scene:
    """The scene of ``robot``: ``geometry`` "visual" (URDF ``<visual>``) or "collision"; at most about
    ``budget`` triangles in all. With no shape described, solid link geometry (``solid_links``)."""
    if geometry not in ("visual", "collision"):
        raise ValueError(f"geometry is 'visual' or 'collision', got {geometry!r}")
    visuals = list(getattr(robot, "visuals" if geometry == "visual" else "collisions", ()) or ())
    frames = set(robot.frame_names)
    scene = Scene(shapes=len(visuals))
    raw: list[tuple[str, Part, int]] = []
    for k, v in enumerate(visuals):
        if v.frame not in frames:
            scene.missing.append(f"{v.describe()} of link '{v.frame}', which is not a frame of the robot")
            continue
        try:
            parts = _shape_parts(v)
        except (MeshNotFound, ValueError) as e:
            message = f"{v.where + ': ' if v.where else ''}{e}; link '{v.frame}' is drawn as a stick figure"
            scene.missing.append(message)
            warnings.warn(message, MissingMeshWarning, stacklevel=2)
            continue
        scene.drawn += 1
        for p in parts:
            rgba = (
                v.rgba
                if v.rgba is not None
                and (p.rgba is None or isinstance(v.shape, (Box, Cylinder, Sphere)) or _is_plain(p.rgba))
                else p.rgba
            )
            raw.append((v.frame, Part(p.vertices, p.faces, rgba or DEFAULT_RGBA), k))
    if not visuals and solid_links:
        raw = [(f, p, -1) for f, p in solid_link_geometry(robot)]
        scene.generated = True
    total = sum(p.triangles for _, p, _ in raw)
    if total > budget:
        # each part keeps its share of the budget (at least a few dozen triangles)
        for i, (f, p, k) in enumerate(raw):
            raw[i] = (f, decimate(p, max(48, int(budget * p.triangles / total))), k)
    scene.parts = [ScenePart(f, p, k) for f, p, k in raw]
    return scene


def scene_bounds(robot, scene: Scene, q) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi): the box around the robot drawn at ``q`` (its shapes, frame origins and the base)."""
    poses = robot.frame_poses(np.asarray(q, dtype=float))
    by_name = dict(zip(robot.frame_names, poses))
    points = [np.zeros((1, 3)), poses[:, :3, 3]]
    points += [sp.part.vertices @ by_name[sp.frame][:3, :3].T + by_name[sp.frame][:3, 3] for sp in scene.parts]
    allp = np.vstack(points)
    return allp.min(axis=0), allp.max(axis=0)


def _is_plain(rgba) -> bool:
    """A mesh colour that only says "no colour" (white or default grey), so the URDF material wins."""
    return rgba is None or all(c >= 0.99 for c in rgba[:3])


# ------------------------------------------------------------------------------ solid links
def _segment(start, end, radius: float) -> Part | None:
    """A cylinder from ``start`` to ``end`` (3-vectors) of ``radius``; None for a zero length."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    d = end - start
    length = float(np.linalg.norm(d))
    if length < 1e-9:
        return None
    z = d / length
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.c_[x, np.cross(z, x), z]
    T[:3, 3] = (start + end) / 2
    return cylinder(radius, length, sections=16).transformed(T)


def _carriage(axis: np.ndarray, size: float) -> Part:
    """A cube of side ``size`` with one edge along ``axis`` (the block of a prismatic joint)."""
    z = axis / np.linalg.norm(axis)
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.c_[x, np.cross(z, x), z]
    return box((size, size, 1.4 * size)).transformed(T)


def _split(p: np.ndarray, axis: np.ndarray, first: bool) -> list[np.ndarray]:
    """Corner points of the path to ``p``: along ``axis`` first (DH standard: d then a) or last
    (modified: a then d); the straight line when the split would not be a right angle."""
    along = float(p @ axis) * axis
    corner = along if first else p - along
    if np.linalg.norm(corner) < 1e-9 or np.linalg.norm(p - corner) < 1e-9:
        return [p]
    return [corner, p]


def solid_link_geometry(robot) -> list[tuple[str, Part]]:
    """Cylinders for a robot without visuals: one along each joint axis at the joint, and links from
    each body's joint to the joints and frames it carries (DH robots: along d, then a)."""
    tree = robot.tree
    qs = np.vstack(
        [robot.neutral(), robot.random_configuration(np.random.default_rng(1), size=32)]
    )  # nq entries with multi-DOF joints
    reach = max(float(np.max(np.linalg.norm(robot.frame_poses(qs)[..., :3, 3], axis=-1))), 0.05)
    r = 0.03 * reach
    out: list[tuple[str, Part]] = []
    standard = getattr(robot, "dh_convention", None) == "standard"
    modified = getattr(robot, "dh_convention", None) == "modified"

    def body_pose_frame(b: int) -> tuple[str, np.ndarray]:
        """(a frame name fixed to body b, body_from_that_frame) — the body's own link frame when it has one."""
        for f in tree.frames:
            if f.body == b:
                return f.name, np.asarray(f.placement, dtype=float)
        raise ValueError(f"body {b} has no frame")

    # for every body (and the base, -1): the points it carries in its own frame
    carried: dict = {}
    for i, b in enumerate(tree.bodies):
        carried.setdefault(b.parent, []).append((np.asarray(b.placement, dtype=float)[:3, 3], i))
    for f in tree.frames:
        carried.setdefault(f.body, []).append((np.asarray(f.placement, dtype=float)[:3, 3], None))
    for owner, points in carried.items():
        if owner < 0:
            frame, link_from_body = tree.base, np.eye(4)
            own_axis = np.array([0.0, 0.0, 1.0])
        else:
            frame, body_from_frame = body_pose_frame(owner)
            link_from_body = np.linalg.inv(body_from_frame)
            own_axis = np.asarray(tree.bodies[owner].joint.axis, dtype=float)
        seen: list[np.ndarray] = []
        for p, child in points:
            if np.linalg.norm(p) < 1e-9 or any(np.linalg.norm(p - s) < 1e-6 for s in seen):
                continue
            seen.append(p)
            if standard and owner >= 0:
                corners = _split(p, own_axis / np.linalg.norm(own_axis), first=True)
            elif modified and child is not None:
                child_axis = np.asarray(tree.bodies[child].placement, dtype=float)[:3, :3] @ np.asarray(
                    tree.bodies[child].joint.axis, dtype=float
                )
                corners = _split(p, child_axis / np.linalg.norm(child_axis), first=False)
            else:
                corners = [p]
            start = np.zeros(3)
            for c in corners:
                seg = _segment(start, c, r)
                if seg is not None:
                    out.append((frame, seg.transformed(link_from_body)))
                start = c
    # joints: a short, wider cylinder along each joint axis
    for i, b in enumerate(tree.bodies):
        if b.joint.is_multi_dof:  # no single axis to draw along (a floating base, a ball joint)
            continue
        frame, body_from_frame = body_pose_frame(i)
        axis = np.asarray(b.joint.axis, dtype=float)
        axis /= np.linalg.norm(axis)
        part = (
            _segment(-1.6 * r * axis, 1.6 * r * axis, 1.7 * r)
            if b.joint.kind == "revolute"
            else _carriage(axis, 2.2 * r)
        )
        if part is not None:
            rgba = REVOLUTE_RGBA if b.joint.kind == "revolute" else PRISMATIC_RGBA
            out.append((frame, Part(part.vertices, part.faces, rgba).transformed(np.linalg.inv(body_from_frame))))
    # prismatic joints: a rail fixed to the parent along the joint's travel (its limits, or the
    # robot's reach), on which the joint's block slides
    for b in tree.bodies:
        if b.joint.kind != "prismatic":
            continue
        lo, hi = (
            float(b.joint.lower),
            float(b.joint.upper),
        )  # this body's joint (robot.lower_limits has no mimic followers)
        lo, hi = (lo if np.isfinite(lo) else -0.5 * reach), (hi if np.isfinite(hi) else 0.5 * reach)
        offset = float(b.joint.offset)
        placement = np.asarray(b.placement, dtype=float)
        axis = placement[:3, :3] @ (np.asarray(b.joint.axis, dtype=float) / np.linalg.norm(b.joint.axis))
        rail = _segment(placement[:3, 3] + (lo + offset) * axis, placement[:3, 3] + (hi + offset) * axis, 0.6 * r)
        if rail is not None:
            if b.parent < 0:
                frame, to_frame = tree.base, np.eye(4)
            else:
                frame, body_from_frame = body_pose_frame(b.parent)
                to_frame = np.linalg.inv(body_from_frame)
            out.append((frame, Part(rail.vertices, rail.faces, (0.36, 0.40, 0.43, 1.0)).transformed(to_frame)))
    # a pedestal under the base
    g = np.asarray(robot.gravity, dtype=float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    pedestal = _segment(-0.06 * reach * up, np.zeros(3), 2.5 * r)
    if pedestal is not None:
        out.append((tree.base, Part(pedestal.vertices, pedestal.faces, (0.3, 0.33, 0.35, 1.0))))
    return [(f, Part(p.vertices, p.faces, p.rgba or LINK_RGBA)) for f, p in out]
