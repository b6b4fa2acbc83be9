"""``Description``: one robot as the parsers read it, checked and frozen.

Every reader returns one (:func:`kinedyn.description.urdf.description_from_urdf`,
:func:`kinedyn.description.mjcf.description_from_mjcf`, :func:`kinedyn.description.dh.description_from_dh`,
:func:`kinedyn.description.files.read_description`); :class:`kinedyn.Robot` is built from it by the
caller (``Robot(description)``), so the readers never reach up to the facade (docs/architecture.md,
the layers). Constructing a Description does every check the description alone can do: each inertia
judged by the inertia policy, the tree's shape, the mimic relations, the tool frame. A reader that
wants to add a file and line to those errors catches them here, before any Robot exists.

The fields are the ``Robot`` constructor's arguments, so ``dataclasses.replace(d, gravity=...)``
and ``Robot(links, ..., gravity=...)`` take the same names; ``tree``, ``nonphysical`` and
``mimic_map`` are derived from them on construction.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .checks import vector
from .link import KinematicTree, build_tree, judge_inertias
from .mimic import MimicMap, mimic_map
from .tool import default_tool

__all__ = ["Description"]


@dataclass(frozen=True, eq=False)
class Description:
    """The links (each with its joint and inertia), extra frames and everything else a robot is.

    ``inertia``: the policy for an inertia no rigid body can have (``"warn"``, ``"repair"``,
    ``"strict"``; docs/model-files.md); ``links`` holds the judged (repaired) links. ``mimic``:
    ``"reduce"`` or ``"independent"`` (:mod:`kinedyn.description.mimic`). ``tool``: a frame name;
    ``None`` picks one (a frame named "tool", else :func:`kinedyn.description.tool.default_tool`).
    """

    links: tuple
    frames: tuple = ()
    gravity: tuple = (0.0, 0.0, -9.81)
    base: str = "base"
    tool: str | None = None
    name: str = "robot"
    dh: tuple | None = None
    dh_convention: str | None = None
    source: str = ""
    inertia: str = "warn"
    visuals: tuple = ()
    collisions: tuple = ()
    mimic: str = "reduce"
    # derived on construction
    tree: KinematicTree = field(init=False, repr=False)
    nonphysical: dict = field(init=False, repr=False)
    mimic_map: MimicMap | None = field(init=False, repr=False)

    def __post_init__(self) -> None:
        put = object.__setattr__  # a frozen dataclass sets its own fields this way, once, here
        put(self, "visuals", tuple(self.visuals))
        put(self, "collisions", tuple(self.collisions))
        links, nonphysical = judge_inertias(self.links, self.inertia)
        put(self, "links", links)
        put(self, "nonphysical", nonphysical)
        put(self, "frames", tuple(self.frames))
        put(self, "gravity", vector(self.gravity, 3, "gravity"))
        put(self, "dh", tuple(self.dh) if self.dh is not None else None)
        tree = build_tree(links, self.frames, self.base)
        if tree.n == 0:
            raise ValueError(f"robot '{self.name}' has no moving joint")
        put(self, "tree", tree)
        # mimic joints (Joint.mimic): None when no joint follows another
        put(
            self,
            "mimic_map",
            mimic_map([b.joint for b in tree.bodies], [link.joint for link in links], self.mimic, self.name),
        )
        names = [f.name for f in tree.frames]
        tool = self.tool
        if tool is None:
            tool = "tool" if "tool" in names else default_tool(links, self.base)
        if tool not in names:
            raise ValueError(f"tool frame '{tool}' is not a frame of robot '{self.name}' (frames: {names})")
        put(self, "tool", tool)

    def arguments(self) -> dict[str, Any]:
        """The constructor's arguments (no derived fields): what ``dataclasses.replace`` starts from."""
        return {name: getattr(self, name) for name in _ARGUMENTS}


_ARGUMENTS = tuple(f for f in Description.__dataclass_fields__ if Description.__dataclass_fields__[f].init)
