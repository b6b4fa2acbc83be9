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

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from .._lazy import LazyModule, sympy_instance
from .._math import is_symbolic
from .._ui.names import did_you_mean
from .checks import vector
from .link import KinematicTree, build_tree, judge_inertias
from .loops import check_loops, check_reference
from .mimic import MimicMap, mimic_map, reduced_coefficient
from .tool import default_tool

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)

__all__ = ["Description"]


@dataclass(frozen=True, eq=False)
class Description:
    """The links (each with its joint and inertia), extra frames and everything else a robot is.

    ``inertia``: the policy for an inertia no rigid body can have (``"warn"``, ``"repair"``,
    ``"strict"``; docs/model-files.md); ``links`` holds the judged (repaired) links. ``mimic``:
    ``"reduce"`` or ``"independent"`` (:mod:`kinedyn.description.mimic`). ``tool``: a frame name;
    ``None`` picks one (a frame named "tool", else :func:`kinedyn.description.tool.default_tool`).
    ``loops``: closed kinematic loops between two frames (:class:`~kinedyn.description.loops.Loop`).
    ``reference_configuration``: ``{joint name: value}``, where the loops close on the branch the
    mechanism is assembled in (its assembly mode; :func:`~kinedyn.description.loops.check_reference`);
    ``None`` when the description states none.
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
    loops: tuple = ()
    reference_configuration: dict | None = None
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
            raise ValueError(
                f"tool frame '{tool}' is not a frame of robot '{self.name}'{did_you_mean(tool, names)} (frames: {names})"
            )
        put(self, "tool", tool)
        put(self, "loops", check_loops(self.loops, names, self.name))
        joints = [b.joint for b in tree.bodies]
        put(self, "reference_configuration", check_reference(self.reference_configuration, joints, self.name))

    # ------------------------------------------------------------------ joints and frames
    @property
    def has_multi_dof_joints(self) -> bool:
        """Whether a joint is floating, spherical or planar (then nq may differ from nv)."""
        return any(b.joint.is_multi_dof for b in self.tree.bodies)

    def require_one_dof_joints(self, feature: str) -> None:
        """Raise a ValueError naming the joint when ``feature`` does not handle multi-DOF joints yet."""
        for b in self.tree.bodies:
            if b.joint.is_multi_dof:
                raise ValueError(
                    f"{feature} handles revolute and prismatic joints only; robot '{self.name}' has the "
                    f"{b.joint.kind} joint '{b.joint.name}' (nq={self.nq}, nv={self.nv})"
                )

    @property
    def mimic_joints(self) -> dict:
        """The reduced mimic followers: ``{follower: Mimic(leader, multiplier, offset)}`` with each
        leader an independent joint (chains resolved); empty without them or with mimic="independent"."""
        return {} if self.mimic_map is None else dict(self.mimic_map.relations)

    def require_no_mimic_joints(self, feature: str) -> None:
        """Raise a ValueError naming a follower when ``feature`` does not handle reduced mimic joints."""
        if self.mimic_map is not None:
            follower, relation = next(iter(self.mimic_map.relations.items()))
            raise ValueError(
                f"{feature} does not handle mimic joints yet; robot '{self.name}' has the follower joint '{follower}' "
                f"(mimics '{relation.leader}'): load it with mimic='independent', or lock the leader (robot.lock_joints)"
            )

    @property
    def body_names(self) -> list:
        """Names of the moving links, in joint order."""
        return [b.name for b in self.tree.bodies]

    @property
    def frame_names(self) -> list:
        return [f.name for f in self.tree.frames]

    @property
    def parents(self) -> list:
        return self.tree.parents

    # ------------------------------------------------------------------ per coordinate
    @property
    def nq(self) -> int:
        """Length of a configuration ``q`` (a free-flyer takes 7: position, then unit quaternion x, y, z, w)."""
        return sum(j.nq for j in self.joints)

    @property
    def nv(self) -> int:
        """Length of a velocity ``qd`` (a free-flyer takes 6: [linear; angular] in the base's own frame)."""
        return sum(j.nv for j in self.joints)

    @property
    def joints(self) -> tuple:
        """The joints of the coordinates, in q's order: every moving joint, less the mimic followers
        when they are reduced (:attr:`mimic_joints`)."""
        bodies = self.tree.bodies
        if self.mimic_map is None:
            return tuple(b.joint for b in bodies)
        return tuple(bodies[i].joint for i in self.mimic_map.independent)

    @property
    def joint_names(self) -> list:
        return [j.name for j in self.joints]

    def per_coordinate(self, value, size: str, multi=math.inf) -> np.ndarray:
        """``value(joint)`` for each q coordinate (``size="nq"``) or degree of freedom (``"nv"``);
        a multi-DOF joint's coordinates get ``multi`` (no limits, no drive data)."""
        out = []
        for j in self.joints:
            k = j.nq if size == "nq" else j.nv
            out.extend([multi] * k if j.is_multi_dof else [value(j)])
        return np.array(out, dtype=float)

    @property
    def lower_limits(self) -> np.ndarray:
        """Lower position limit per q coordinate (nq,); -inf for multi-DOF joints' coordinates."""
        return self.per_coordinate(lambda j: j.lower, "nq", -math.inf)

    @property
    def upper_limits(self) -> np.ndarray:
        """Upper position limit per q coordinate (nq,); inf for multi-DOF joints' coordinates."""
        return self.per_coordinate(lambda j: j.upper, "nq")

    @property
    def velocity_limits(self) -> np.ndarray:
        return self.per_coordinate(lambda j: j.velocity_limit, "nv")

    @property
    def effort_limits(self) -> np.ndarray:
        return self.per_coordinate(lambda j: j.effort_limit, "nv")

    @property
    def armature(self) -> np.ndarray:
        """Reflected rotor inertia r^2 J_m per degree of freedom (added to the diagonal of M)."""
        if self.mimic_map is not None:  # with the reduced mimic followers' (description/mimic.py)
            return reduced_coefficient(self, "armature")
        return self.per_coordinate(lambda j: float(j.armature), "nv", 0.0)

    @property
    def viscous(self) -> np.ndarray:
        """Viscous friction coefficient per degree of freedom: tau_f = viscous * qd + coulomb * sign(qd)
        (with direction-dependent Coulomb levels: :meth:`friction_torque`)."""
        if self.mimic_map is not None:  # with the reduced mimic followers' (description/mimic.py)
            return reduced_coefficient(self, "viscous")
        return self.per_coordinate(lambda j: float(j.viscous), "nv", 0.0)

    @property
    def coulomb(self) -> np.ndarray:
        """Coulomb friction level per degree of freedom for qd > 0 (the only level when friction is symmetric)."""
        if self.mimic_map is not None:  # with the reduced mimic followers' (description/mimic.py)
            return reduced_coefficient(self, "coulomb")
        return self.per_coordinate(lambda j: float(j.coulomb), "nv", 0.0)

    @property
    def coulomb_negative(self) -> np.ndarray:
        """Coulomb friction level per degree of freedom for qd < 0 (a magnitude; equals :attr:`coulomb` for
        symmetric friction)."""
        if self.mimic_map is not None:  # with the reduced mimic followers' (description/mimic.py)
            return reduced_coefficient(self, "coulomb_negative")
        return self.per_coordinate(lambda j: float(j.coulomb_levels[1]), "nv", 0.0)

    @property
    def is_symbolic(self) -> bool:
        return bool(self.symbols)

    @cached_property
    def symbols(self) -> set:
        """Free SymPy symbols in the description (empty for a numeric robot)."""
        free: set = set()

        def add(v):
            if sympy_instance(v, "MatrixBase"):
                free.update(v.free_symbols)
            elif sympy_instance(v, "Basic"):
                free.update(v.free_symbols)
            elif isinstance(v, (tuple, list)):
                for e in v:
                    add(e)

        add(self.gravity)
        for link in self.links:
            j = link.joint
            add([j.axis, j.offset, j.gear_ratio, j.rotor_inertia, j.viscous, j.coulomb, j.coulomb_negative])
            add([link.inertia.mass, link.inertia.com, link.inertia.inertia])
            if is_symbolic(link.placement):
                add(link.placement)
            if is_symbolic(link.post):
                add(link.post)
        for f in self.frames:
            if is_symbolic(f.placement):
                add(f.placement)
        return free

    def arguments(self) -> dict[str, Any]:
        """The constructor's arguments (no derived fields): what ``dataclasses.replace`` starts from."""
        return {name: getattr(self, name) for name in _ARGUMENTS}


_ARGUMENTS = tuple(f for f in Description.__dataclass_fields__ if Description.__dataclass_fields__[f].init)
