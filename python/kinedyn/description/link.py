"""Links and frames of a robot description, and the kinematic tree compiled from them.

Description (what a user writes; numbers or SymPy symbols)::

    Link(name, parent, joint, placement, post, inertia)

    parent link frame --placement--> joint frame --joint motion(q + offset)--> --post--> link frame

``placement`` is the joint frame in the parent link's frame at q = 0 (URDF's ``<joint><origin>``),
``post`` a fixed transform from the moved joint frame to the link frame (identity for URDF; the
``Tx(a) Rx(alpha)`` part of a standard DH row), ``inertia`` is given in the link frame.

Compiled tree (what the engines read): fixed joints are merged into the moving link that carries
them, and every body's frame is its *joint* frame after motion ("body frame"), as in Featherstone's
and Pinocchio's models. Every link (fixed ones included) and every extra frame becomes a named frame
``(body index or -1 for the base, body_from_frame)``. Bodies are numbered depth-first in declaration
order, so ``parent[i] < i``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._lazy import LazyModule, sympy_instance
from .._math import identity, is_symbolic, matmul
from .checks import LARGEST
from .inertia import Inertia, judge
from .joint import Joint

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = ["Link", "Frame", "Body", "NamedFrame", "KinematicTree", "build_tree", "judge_inertias"]


def _pose(value, what: str):
    if is_symbolic(value):
        T = sp.Matrix(value)
    else:
        raw = np.asarray(value.tolist() if sympy_instance(value, "MatrixBase") else value)
        if (
            raw.dtype.kind == "c"
            or raw.dtype == object
            and any(isinstance(v, complex) or getattr(v, "is_real", True) is False for v in raw.flat)
        ):
            raise ValueError(f"{what} must be real, got complex values")
        try:
            T = raw.astype(float)
        except (TypeError, ValueError):
            raise ValueError(f"{what} must be a 4x4 array of numbers") from None
    if tuple(T.shape) != (4, 4):
        raise ValueError(f"{what} must be a 4x4 homogeneous transform, got shape {tuple(T.shape)}")
    if not is_symbolic(T):
        if not np.all(np.isfinite(T)):
            raise ValueError(f"{what} contains non-finite values")
        if np.abs(T).max() > LARGEST:
            raise ValueError(f"{what} has a translation larger in magnitude than {LARGEST:g}")
        R = T[:3, :3]
        if np.abs(R @ R.T - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0 or np.abs(T[3] - (0, 0, 0, 1)).max() > 1e-8:
            raise ValueError(f"{what} is not a rigid transform (rotation part not orthonormal or last row not 0 0 0 1)")
    return T


@dataclass(frozen=True)
class Link:
    name: str
    parent: str | None
    joint: Joint
    placement: Any = field(default_factory=identity)
    post: Any = field(default_factory=identity)
    inertia: Inertia = field(default_factory=Inertia)

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"a link's name must be a non-empty string, got {self.name!r}")
        if not isinstance(self.joint, Joint):
            raise ValueError(f"link '{self.name}': joint must be a Joint, got {type(self.joint).__name__}")
        object.__setattr__(self, "placement", _pose(self.placement, f"placement of link '{self.name}'"))
        object.__setattr__(self, "post", _pose(self.post, f"post transform of link '{self.name}'"))
        if self.inertia is None:
            object.__setattr__(self, "inertia", Inertia())
        if not isinstance(self.inertia, Inertia):
            raise ValueError(f"link '{self.name}': inertia must be an Inertia, got {type(self.inertia).__name__}")
        self.inertia.validate(f"link '{self.name}'")


@dataclass(frozen=True)
class Frame:
    """An extra named frame fixed to a link (``link=None`` means the base), e.g. a tool frame."""

    name: str
    link: str | None
    placement: Any = field(default_factory=identity)

    def __post_init__(self):
        object.__setattr__(self, "placement", _pose(self.placement, f"placement of frame '{self.name}'"))


@dataclass(frozen=True)
class Body:
    """A moving body of the compiled tree (one per joint coordinate)."""

    name: str  # the moving link's name
    joint: Joint
    parent: int  # parent body index, -1 = base
    placement: Any  # parent body frame -> joint frame at q = 0
    inertia: Inertia  # in the body (joint) frame, fixed children merged


@dataclass(frozen=True)
class NamedFrame:
    name: str
    body: int  # -1 = base
    placement: Any  # body frame -> this frame


@dataclass(frozen=True)
class KinematicTree:
    bodies: tuple
    frames: tuple
    base: str

    @property
    def n(self) -> int:
        return len(self.bodies)

    @property
    def parents(self) -> list:
        return [b.parent for b in self.bodies]

    def frame_index(self, name: str) -> int:
        for i, f in enumerate(self.frames):
            if f.name == name:
                return i
        raise KeyError(name)


def judge_inertias(links, policy: str) -> tuple:
    """``(links, nonphysical)``: each link's inertia judged by the inertia policy (``"warn"``,
    ``"repair"``, ``"strict"``: see :func:`kinedyn.description.inertia.judge`), repaired links
    replaced; ``nonphysical`` maps the name of each link kept with an inertia no rigid body has to
    its :class:`~kinedyn.description.inertia.Consistency` (for the errors of forward dynamics)."""
    out, nonphysical = [], {}
    for link in links:
        if not isinstance(link, Link):
            raise ValueError(f"a robot's links must be Link objects, got {type(link).__name__}")
        inertia = judge(link.inertia, policy, f"link '{link.name}'")
        if inertia is not link.inertia:
            link = Link(link.name, link.parent, link.joint, link.placement, link.post, inertia)
        check = inertia.consistency()
        if check is not None and not check.ok:
            nonphysical[link.name] = check
        out.append(link)
    return tuple(out), nonphysical


def build_tree(links, frames, base: str) -> KinematicTree:
    """Compile links into bodies (fixed joints merged) and named frames; check the tree's shape."""
    names = {base}  # a set: membership tests stay O(1) for robots of thousands of links
    for link in links:
        if link.name in names:
            raise ValueError(f"link name '{link.name}' is used twice")
        names.add(link.name)
    children: dict = {base: []}
    for link in links:
        children.setdefault(link.name, [])
    for link in links:
        parent = base if link.parent is None else link.parent
        if parent not in children:
            raise ValueError(f"link '{link.name}': its parent link '{parent}' does not exist")
        children[parent].append(link)

    bodies: list = []
    named: list = [NamedFrame(base, -1, identity())]
    # each entry: (link, body index that carries it, body_from_linkframe)
    carriers: dict = {base: (-1, identity())}
    stack = list(reversed(children[base]))
    seen = set()
    while stack:
        link = stack.pop()
        seen.add(link.name)
        parent_body, body_from_parent_frame = carriers[link.parent if link.parent is not None else base]
        if link.joint.is_moving:
            index = len(bodies)
            placement = matmul(body_from_parent_frame, link.placement)
            bodies.append(Body(link.name, link.joint, parent_body, placement, link.inertia.transformed(link.post)))
            carriers[link.name] = (index, link.post)
        else:
            # a fixed joint: the link is rigidly part of its parent's body
            body_from_link = matmul(body_from_parent_frame, link.placement, link.post)
            carriers[link.name] = (parent_body, body_from_link)
            if parent_body >= 0:
                b = bodies[parent_body]
                merged = b.inertia + link.inertia.transformed(body_from_link)
                bodies[parent_body] = Body(b.name, b.joint, b.parent, b.placement, merged)
        named.append(NamedFrame(link.name, *carriers[link.name]))
        stack.extend(reversed(children[link.name]))
    missing = [l.name for l in links if l.name not in seen]
    if missing:
        raise ValueError(
            f"links {missing} are not connected to the base '{base}': their parents form a cycle "
            "or the tree has a second root"
        )
    for frame in frames:
        owner = base if frame.link is None else frame.link
        if owner not in carriers:
            raise ValueError(f"frame '{frame.name}' is attached to unknown link '{owner}'")
        if frame.name in names:
            raise ValueError(f"frame name '{frame.name}' is already the name of a link or frame")
        names.add(frame.name)
        body, body_from_link = carriers[owner]
        named.append(NamedFrame(frame.name, body, matmul(body_from_link, frame.placement)))
    return KinematicTree(tuple(bodies), tuple(named), base)
