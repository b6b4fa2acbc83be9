"""MJCF (MuJoCo's XML) -> :class:`kinedyn.Robot`.

Reads the kinematic and inertial parts of a MuJoCo model (MuJoCo's "XML Reference"):

- ``<mujoco model>``; ``<compiler angle="degree|radian" eulerseq autolimits meshdir assetdir
  inertiafromgeom inertiagrouprange boundmass boundinertia balanceinertia settotalmass>`` (MuJoCo's
  defaults: degrees, ``xyz``, autolimits on, inertia from geoms when a body has no ``<inertial>``); ``<option gravity>`` and
  ``<option><flag gravity="disable">``.
- ``<default>`` classes (the top one is ``main``, and several top-level ``<default>`` blocks all add
  to it, as MuJoCo merges them; nested classes inherit; an element's ``class``, else
  the ``childclass`` of the nearest enclosing body or frame, else ``main``) for ``joint``, ``geom``,
  ``site`` and ``mesh``.
- ``<worldbody>`` and nested ``<body name pos quat|axisangle|euler|xyaxes|zaxis childclass>``
  (quaternions in MuJoCo's (w, x, y, z) order), and ``<frame>`` groups.
- ``<joint type="hinge|slide|ball|free" axis pos range limited ref armature damping frictionloss>``
  and ``<freejoint>``: hinge -> revolute, slide -> prismatic, ball -> spherical, free -> floating.
  The joint's ``pos`` and ``axis`` are in the body frame; a body with several joints becomes a chain
  of massless links (named ``BODY/JOINT``), one per joint, composed in file order as MuJoCo does, the
  last carrying the body's name and inertia. A hinge at ``pos`` p moves its body by
  ``Tr(p) Rot(axis, q - ref) Tr(-p)``, which is a kinedyn link with ``placement = body_pose Tr(p)`` and
  ``post = Tr(-p)``; ``ref`` becomes the joint's offset ``-ref``, so kinedyn's ``q`` is MuJoCo's
  ``qpos``. ``armature`` -> rotor inertia (gear ratio 1), ``damping`` -> viscous, ``frictionloss``
  -> Coulomb friction. A free joint puts its body at ``qpos`` in the world: the body's own ``pos``
  and ``quat`` are only MuJoCo's initial ``qpos0``, so kinedyn's placement of it is the identity.
- ``<inertial pos quat mass diaginertia|fullinertia>``; a body without one gets its inertia from its
  geoms (box, sphere, capsule, cylinder, ellipsoid: solid, of ``density`` (default 1000) or the
  geom's ``mass``); a mesh geom's inertia is not computed (give the body an ``<inertial>``).
- Geoms (``box sphere cylinder capsule ellipsoid mesh``, with ``size``, ``fromto``, ``pos``,
  orientation, ``rgba``/``material``) -> ``robot.visuals`` (those of groups 0-2, which MuJoCo's
  viewer shows) and ``robot.collisions`` (those with ``contype`` or ``conaffinity`` set);
  MuJoCo's capsules and ellipsoids are drawn as the cylinders and spheres nearest them.
- ``<site name pos orientation>`` -> named frames on its body (``site:NAME`` when a body has the name).
- ``<include file>``: relative to the including file's folder, which it may not leave; nested at
  most ``MAX_INCLUDE_DEPTH`` deep.

``<equality><connect>`` and ``<weld>`` are closed loops (:mod:`kinedyn.description.mjcf_loops`).

Not modelled, and named in one warning when present: actuators, tendons, equality constraints
other than a linear joint equality (read as a mimic joint: ``mjcf_xml.with_joint_equalities``), a
weld or connect, and the softness of these,
contact pairs and exclusions, sensors, keyframes, plugins (``<extension>``, a body's ``<plugin>``),
fluid forces (``<option density viscosity wind>``), joint springs (``stiffness``, ``springdamper``),
``gravcomp``, friction and armature of ball and free joints, a ball joint's range (a cone); every
``<option>`` attribute is listed in :mod:`kinedyn.description.mjcf_settings`. Lights, cameras, textures and the ``<visual>``
settings are presentation and are skipped silently. ``<replicate>``, ``<attach>``, ``<composite>``,
``<flexcomp>``, mocap bodies, ``shellinertia`` and ``<compiler coordinate="global">`` are refused (they make bodies kinedyn cannot
read here).

The base of the robot is MuJoCo's world body, named ``world``; bodies without a joint are welded to
their parent (fixed joints); a model without any joint loads with nq = 0, as MuJoCo loads it.
Names are kept per element kind, as MuJoCo keeps them: two bodies (or joints, geoms, sites) of one
name are refused, a site and a body may share one (the site's frame is then ``site:NAME``). Unnamed bodies and joints get MuJoCo's numbering: ``body{id}``,
``joint{id}``.

Security, as the URDF loader: the XML may not declare entities; nesting, file size and includes are
bounded; every problem is a ValueError naming the file, the line, the element and the attribute.
"""

from __future__ import annotations

import importlib
import math
import os
import warnings

import numpy as np

from .checks import caller_level
from .description import Description
from .geometry import Box, Cylinder, Mesh, Sphere, Visual
from .inertia import Inertia, PhysicalConsistencyWarning
from .joint import Joint
from .link import Frame, Link
from .mjcf_loops import equality_loops

__all__ = ["description_from_mjcf", "MAX_DEPTH", "MAX_INCLUDE_DEPTH", "MAX_FILE_BYTES"]

from .mjcf_settings import DEFAULTED, ModelSettings
from .mjcf_xml import (
    MAX_DEPTH,
    MAX_FILE_BYTES,
    MAX_INCLUDE_DEPTH,
    REFUSED,
    Sources,
    axis_angle,
    numbers,
    parse_model,
    pose,
    quat_matrix,
    short,
    solid_volume_and_moments,
    translation_of,
    with_joint_equalities,
    z_to,
)

_JOINT_KINDS = {"hinge": "revolute", "slide": "prismatic", "ball": "spherical", "free": "floating"}
_SHAPES = ("sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh", "plane", "hfield", "sdf")
# top-level sections with dynamics kinedyn does not model (named in the warning)
_UNMODELLED = ("actuator", "tendon", "equality", "contact", "sensor", "keyframe", "deformable", "extension")
# sections or elements kinedyn skips silently (presentation, bookkeeping)
_PRESENTATION = ("visual", "statistic", "size", "custom", "light", "camera", "asset")


# ============================================================================== entry point
def description_from_mjcf(path_or_string, *, tool: str | None = None, inertia: str = "warn", gravity=None):
    """The :class:`~kinedyn.description.description.Description` of an MJCF file path or an XML string
    (see the module docstring; ``kinedyn.Robot.from_mjcf`` builds the robot from it).

    A string holding ``<`` or a line break is parsed as XML, anything else is a path (an XML string
    may not ``<include>`` files). ``gravity``: overrides ``<option gravity>``. ``tool`` and
    ``inertia`` as :func:`kinedyn.description.urdf.description_from_urdf`.
    """
    src, root = parse_model(path_or_string)
    if root.tag != "mujoco":
        raise src.error(root, f"the root element is <{root.tag}>, expected <mujoco>")
    reader = _Reader(src, root)
    links, frames, visuals, collisions = reader.read()
    links = with_joint_equalities(root, src, links, reader.ignored)  # mimic joints, as to_mjcf writes them
    anchors, loops = equality_loops(reader)  # <connect> and <weld>: closed loops (mjcf_loops)
    name = root.get("model") or "mjcf_robot"
    source = src.label if src.base_dir is not None else "MJCF string"
    if gravity is None:
        gravity = reader.gravity
    if reader.ignored:
        shown = sorted(reader.ignored)
        warnings.warn(
            f"{src.label}: kinedyn does not model, and ignores: {'; '.join(shown[:20])}"
            + (f" and {len(shown) - 20} more" if len(shown) > 20 else ""),
            UserWarning,
            stacklevel=caller_level(),
        )
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", PhysicalConsistencyWarning)
            description = Description(
                tuple(links),
                tuple(frames) + tuple(anchors),
                gravity=gravity,
                base="world",
                tool=tool,
                name=name,
                source=source,
                inertia=inertia,
                visuals=visuals,
                collisions=collisions,
                loops=tuple(loops),
                reference_configuration=_qpos0(links) if loops else None,
            )
    except ValueError as e:
        raise ValueError(f"{src.label}: {e}") from None
    for w in caught:
        warnings.warn(f"{src.label}: {w.message}", w.category, stacklevel=caller_level())
    return description


# ============================================================================== the reader
def _qpos0(links) -> dict:
    """MuJoCo's reference configuration ``qpos0``, where its body-form equalities close (the loops'
    assembly mode, docs/closed-loops.md): each hinge and slide at its ``ref`` (its offset is ``-ref``,
    so kinedyn's ``q`` is MuJoCo's ``qpos``). Ball and free joints are left to the drawing's start."""
    return {
        link.joint.name: -float(link.joint.offset)
        for link in links
        if link.joint.kind in ("revolute", "prismatic") and link.joint.mimic is None
    }


class _Reader(ModelSettings):
    def __init__(self, src: Sources, root):
        self.src = src
        self.root = root
        self.ignored: set = set()
        self.compiler()
        self.defaults: dict = {}  # class name -> {element tag: {attribute: value}}
        self.gravity = self.option()
        for section in root.iterfind("default"):
            self.read_defaults(section, "main", {t: {} for t in DEFAULTED}, top=True)
        # MuJoCo keeps one name scope per element kind (a site and a body may share a name)
        self.scopes: dict = {"body": {}, "joint": {}, "geom": {}, "site": {}, "mesh": {}, "material": {}}
        self.materials, self.meshes = self.assets()
        self.names: set = {"world"}  # kinedyn's frames: bodies, the links of a body's joints, sites
        # a site whose name a body has, before or after it in the file, is the frame 'site:NAME'
        self.body_names = {b.get("name") for b in root.iter("body") if b.get("name")}
        self.site_names: list = []
        self.site_frames: dict = {}  # site name -> its frame's name (for <equality> site1/site2)
        self.reference: dict = {"world": np.eye(4)}  # body -> its world pose at MuJoCo's qpos0 (mjcf_loops)
        self.body_count = 0
        self.joint_count = 0

    def assets(self) -> tuple:
        materials, meshes = {}, {}
        for asset in self.root.iterfind("asset"):
            for m in asset.iterfind("material"):
                self.unique("material", m)
                if m.get("name") and m.get("rgba"):
                    materials[m.get("name")] = self.rgba(m, m.get("rgba"))
            for mesh in asset.iterfind("mesh"):
                self.unique("mesh", mesh)
                a = self.attributes(mesh, "main")
                file = a.get("file")
                name = a.get("name") or (os.path.splitext(os.path.basename(file))[0] if file else None)
                if not name:
                    raise self.src.error(mesh, "has neither 'name' nor 'file'")
                scale = numbers(mesh, "scale", self.src, 3, text=a.get("scale", "1 1 1"))
                meshes[name] = (file, scale, mesh)
        return materials, meshes

    def rgba(self, element, text: str) -> tuple:
        values = numbers(element, "rgba", self.src, 4, text=text)
        if any(not 0.0 <= v <= 1.0 for v in values):
            raise self.src.error(element, f"attribute 'rgba' must be 4 numbers between 0 and 1, got '{short(text)}'")
        return values

    # --------------------------------------------------------------------- orientation
    def angle(self, value: float) -> float:
        return math.radians(value) if self.degrees else value

    def rotation(self, element, a: dict) -> np.ndarray:
        """The orientation given by one of quat, axisangle, euler, xyaxes, zaxis (identity if none)."""
        given = [k for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis") if k in a]
        if len(given) > 1:
            raise self.src.error(element, f"gives its orientation twice ({', '.join(given)}); keep one")
        if not given:
            return np.eye(3)
        key = given[0]
        if key == "quat":
            q = np.array(numbers(element, key, self.src, 4, text=a[key]))
            norm = np.linalg.norm(q)
            if norm < 1e-12:
                raise self.src.error(element, f"attribute 'quat' is zero: '{a[key]}'")
            return quat_matrix(*(q / norm))
        if key == "axisangle":
            *axis, angle = numbers(element, key, self.src, 4, text=a[key])
            return axis_angle(self.unit(element, key, axis), self.angle(angle))
        if key == "euler":
            angles = numbers(element, key, self.src, 3, text=a[key])
            R = np.eye(3)
            for letter, angle in zip(self.eulerseq, angles):
                step = axis_angle(np.eye(3)["xyz".index(letter.lower())], self.angle(angle))
                # lower case: axes that move with the body (R = R1 R2 R3); upper case: fixed axes (R3 R2 R1)
                R = R @ step if letter.islower() else step @ R
            return R
        if key == "xyaxes":
            v = numbers(element, key, self.src, 6, text=a[key])
            x = self.unit(element, key, v[:3])
            y = np.array(v[3:]) - (np.array(v[3:]) @ x) * x
            y = self.unit(element, key, y)
            return np.column_stack([x, y, np.cross(x, y)])
        return z_to(self.unit(element, key, numbers(element, key, self.src, 3, text=a[key])))

    def unit(self, element, key: str, v) -> np.ndarray:
        v = np.asarray(v, dtype=float)
        norm = np.linalg.norm(v)
        if norm < 1e-12:
            raise self.src.error(element, f"attribute '{key}' has a zero-length vector")
        return v / norm

    def frame(self, element, a: dict) -> np.ndarray:
        p = numbers(element, "pos", self.src, 3, text=a["pos"]) if "pos" in a else (0.0, 0.0, 0.0)
        return pose(p, self.rotation(element, a))

    # --------------------------------------------------------------------- bodies
    def read(self):
        links: list = []
        frames: list = []
        visuals: list = []
        collisions: list = []
        self.links, self.frames, self.visuals, self.collisions = links, frames, visuals, collisions
        for child in self.root:
            if child.tag in _UNMODELLED and len(child):
                self.ignored.add(f"<{child.tag}> ({len(child)} elements)")
            elif child.tag in REFUSED:
                raise self.src.error(
                    child,
                    "is not read by kinedyn (it generates bodies); expand the model in MuJoCo and save it (mj_saveLastXML)",
                )
        worlds = list(self.root.iterfind("worldbody"))
        if not worlds:
            raise self.src.error(self.root, "has no <worldbody>")
        for world in worlds:
            self.children(world, "world", np.eye(4), "main", world=True)
        if self.settotalmass > 0:
            self.scale_to_total_mass()
        return links, frames, visuals, collisions

    def adjusted(self, inertia: Inertia) -> Inertia:
        """A body's inertia after MuJoCo's compiler options ``boundmass`` (a least mass),
        ``boundinertia`` (least principal moments) and ``balanceinertia`` (principal moments that
        break the triangle inequality replaced by their mean)."""
        if self.boundmass <= 0 and self.boundinertia <= 0 and not self.balanceinertia:
            return inertia
        mass = max(float(inertia.mass), self.boundmass)
        moments, axes = np.linalg.eigh(np.array(inertia.inertia, dtype=float))
        if self.balanceinertia and moments[0] + moments[1] < moments[2]:
            moments = np.full(3, moments.mean())
        moments = np.maximum(moments, self.boundinertia)
        return Inertia(mass, inertia.com, (axes * moments) @ axes.T)

    def scale_to_total_mass(self) -> None:
        """MuJoCo's ``settotalmass``: every body's mass and inertia scaled so that they add up to it."""
        total = sum(float(link.inertia.mass) for link in self.links)
        if total <= 0:
            raise ValueError(f"{self.src.label}: <compiler settotalmass> needs bodies with mass to scale")
        k = self.settotalmass / total
        self.links[:] = [
            Link(
                link.name,
                link.parent,
                link.joint,
                link.placement,
                link.post,
                Inertia(k * link.inertia.mass, link.inertia.com, k * np.array(link.inertia.inertia, dtype=float)),
            )
            for link in self.links
        ]

    def children(self, element, link: str, link_from_here: np.ndarray, childclass: str, world: bool = False) -> list:
        """The bodies, geoms, sites and frames inside ``element`` (a body or frame), whose poses are
        given in ``element``'s frame, ``link_from_here`` in the frame of the kinedyn link ``link``;
        returns the geoms (of nested frames too), for the body's inertia."""
        geoms = []
        for child in element:
            tag = child.tag
            if tag == "body":
                self.body(child, link, link_from_here, childclass, world)
            elif tag == "frame":
                a = child.attrib
                geoms += self.children(
                    child, link, link_from_here @ self.frame(child, a), a.get("childclass", childclass), world
                )
            elif tag == "geom":
                geoms.append(self.geom(child, link, link_from_here, childclass))
            elif tag == "site":
                self.site(child, link, link_from_here, childclass)
            elif tag == "plugin":
                self.ignored.add(
                    f"the plugin '{child.get('plugin') or child.get('instance', '')}' of '{link}' (its forces)"
                )
            elif tag in REFUSED:
                raise self.src.error(
                    child,
                    "is not read by kinedyn (it generates bodies); expand the model in MuJoCo and save it (mj_saveLastXML)",
                )
            elif tag in ("joint", "freejoint") and (world or element.tag == "frame"):
                raise self.src.error(child, "must be inside a <body> (not the world body or a <frame>)")
        return geoms

    def body(self, element, parent: str, parent_from_here: np.ndarray, childclass: str, parent_is_world: bool) -> None:
        self.body_count += 1
        name = element.get("name") or f"body{self.body_count}"
        a = element.attrib
        childclass = a.get("childclass", childclass)
        if childclass not in self.defaults and childclass != "main":
            raise self.src.error(element, f"childclass='{childclass}' names no <default> class")
        what = f"body '{name}'"
        self.unique("body", element)
        self.claim(name, element, what)
        if a.get("gravcomp") not in (None, "0"):
            self.ignored.add(f"gravcomp of {what}")
        if a.get("mocap") == "true":
            raise self.src.error(element, f"{what} is a mocap body, which kinedyn does not read")
        parent_from_body = parent_from_here @ self.frame(element, a)
        # at qpos0 every hinge and slide is at its ref (no motion) and a free body where the file puts it
        self.reference[name] = self.reference[parent] @ parent_from_body
        joints = [j for j in element if j.tag in ("joint", "freejoint")]
        # the chain of links: one per joint (the last one is the body), or one welded link
        link_parent, placement = parent, parent_from_body
        if not joints:
            fixed = Joint(f"{name}_weld", "fixed")
            self.links.append(Link(name, parent, fixed, parent_from_body))
        for k, j in enumerate(joints):
            joint, pos = self.joint(j, childclass, name, len(joints), parent_is_world and link_parent == "world")
            link_name = name if k == len(joints) - 1 else f"{name}/{joint.name}"
            if link_name != name:
                self.claim(link_name, j, f"the link of joint '{joint.name}'")
            if joint.kind == "floating":
                # MuJoCo places a free body at qpos in the world; its pos/quat are only qpos0
                joint_frame, post = np.eye(4), np.eye(4)
            else:
                joint_frame, post = placement @ translation_of(pos), translation_of(-np.asarray(pos))
            try:
                self.links.append(Link(link_name, link_parent, joint, joint_frame, post))
            except ValueError as e:
                raise self.src.error(j, str(e)) from None
            link_parent, placement = link_name, np.eye(4)
        index = len(self.links) - 1  # the link that carries the body
        # the body's geoms, sites and child bodies, in the body's own frame
        geoms = self.children(element, name, np.eye(4), childclass)
        body_inertia = self.adjusted(self.inertia(element, name, geoms))
        last = self.links[index]
        self.links[index] = Link(last.name, last.parent, last.joint, last.placement, last.post, body_inertia)

    def unique(self, kind: str, element) -> None:
        """A name given twice to elements of one kind is refused, as MuJoCo refuses it ("repeated
        name"); elements of different kinds may share a name."""
        name = element.get("name")
        if not name:
            return
        first = self.scopes[kind].get(name)
        if first is not None:
            raise self.src.error(
                element,
                f"the name '{name}' is given to two <{kind}> elements (the first at {self.src.at(first)}); MuJoCo refuses it too",
            )
        self.scopes[kind][name] = element

    def claim(self, name: str, element, what: str) -> None:
        if name in self.names:
            raise self.src.error(element, f"{what}: the name '{name}' is used twice")
        self.names.add(name)

    def joint(self, element, childclass: str, body: str, count: int, top_level: bool):
        self.joint_count += 1
        self.unique("joint", element)
        # <freejoint> takes no default class (MuJoCo's reference); <joint> does
        a = dict(element.attrib) if element.tag == "freejoint" else self.attributes(element, childclass)
        name = a.get("name") or f"joint{self.joint_count - 1}"
        kind = "free" if element.tag == "freejoint" else a.get("type", "hinge")
        what = f"joint '{name}'"
        if kind not in _JOINT_KINDS:
            raise self.src.error(
                element, f"{what}: attribute 'type' is '{short(kind)}', expected one of {', '.join(_JOINT_KINDS)}"
            )
        if kind == "free" and a.get("align") == "true":
            self.ignored.add(
                f"align='true' of the free {what} (kinedyn's q is its body frame's pose, not MuJoCo's aligned qpos)"
            )
        if kind == "free" and not (top_level and count == 1):
            raise self.src.error(
                element, f"{what}: a free joint must be the only joint of a body whose parent is the world body"
            )
        axis = numbers(element, "axis", self.src, 3, text=a.get("axis", "0 0 1"))
        pos = numbers(element, "pos", self.src, 3, text=a.get("pos", "0 0 0"))
        scalars = {}
        for attribute in ("armature", "damping", "frictionloss", "ref", "stiffness"):
            scalars[attribute] = (
                numbers(element, attribute, self.src, 1, text=a[attribute])[0] if attribute in a else 0.0
            )
        if scalars["stiffness"] != 0:
            self.ignored.add(f"the spring (stiffness) of {what}")
        if any(v > 0 for v in numbers(element, "springdamper", self.src, 2, text=a.get("springdamper", "0 0"))):
            # MuJoCo's compiler turns (time constant, damping ratio) into a stiffness and a damping
            self.ignored.add(f"the spring and damper (springdamper) of {what}")
        angular = kind == "hinge"
        options: dict = {}
        if kind in ("hinge", "slide"):
            options["offset"] = -(self.angle(scalars["ref"]) if angular else scalars["ref"])
            options["rotor_inertia"] = scalars["armature"]
            # <option><flag damper|frictionloss="disable"> drop these forces in MuJoCo
            options["viscous"] = scalars["damping"] if self.damping_on else 0.0
            options["coulomb"] = scalars["frictionloss"] if self.frictionloss_on else 0.0
            limited = a.get("limited", "auto")
            if limited not in ("true", "false", "auto"):
                raise self.src.error(
                    element, f"{what}: attribute 'limited' must be true, false or auto, got '{short(limited)}'"
                )
            if limited == "auto" and not self.autolimits and "range" in a:
                raise self.src.error(
                    element, f"{what}: has a range but limited='auto' with autolimits off (MuJoCo refuses it too)"
                )
            if limited == "true" or (limited == "auto" and "range" in a):
                lower, upper = numbers(element, "range", self.src, 2, text=a.get("range", "0 0"))
                if lower > upper:
                    raise self.src.error(
                        element, f"{what}: attribute 'range' has lower {lower:g} above upper {upper:g}"
                    )
                if angular:
                    lower, upper = self.angle(lower), self.angle(upper)
                options["lower"], options["upper"] = lower, upper
        else:
            if scalars["ref"] != 0:
                raise self.src.error(element, f"{what}: a {kind} joint takes no 'ref'")
            for attribute in ("armature", "damping", "frictionloss"):
                if scalars[attribute] != 0:
                    self.ignored.add(f"{attribute} of the {kind} joint '{name}'")
            if kind == "ball" and "range" in a and a.get("limited", "auto") != "false":
                self.ignored.add(f"the range (a cone) of the ball joint '{name}'")
        try:
            joint = Joint(name, _JOINT_KINDS[kind], axis, **options)
        except ValueError as e:
            raise self.src.error(element, str(e)) from None
        return joint, pos

    # --------------------------------------------------------------------- geoms, sites, inertia
    def site(self, element, link: str, link_from_here: np.ndarray, childclass: str) -> None:
        a = self.attributes(element, childclass)
        name = a.get("name")
        if not name:
            return
        self.unique("site", element)
        self.site_names.append(name)
        frame_name = name if name not in self.names and name not in self.body_names else f"site:{name}"
        self.claim(frame_name, element, f"site '{name}'")
        self.site_frames[name] = frame_name
        pose = self.frame(element, a)
        if "fromto" in a:  # a site, like a geom, may sit at the middle of a segment, z along it
            if a.get("type", "sphere") not in ("capsule", "cylinder", "box", "ellipsoid"):
                raise self.src.error(
                    element,
                    f"site '{name}': 'fromto' is for capsules, cylinders, boxes and ellipsoids, not a {a.get('type', 'sphere')}",
                )
            pose = self.segment(element, a["fromto"])[0]
        self.frames.append(Frame(frame_name, None if link == "world" else link, link_from_here @ pose))

    def segment(self, element, text: str) -> tuple:
        """(pose at the middle of ``fromto``, its z axis along it, from the second end towards the
        first as MuJoCo's compiler orients it; the segment's length)."""
        ends = np.array(numbers(element, "fromto", self.src, 6, text=text))
        d = ends[:3] - ends[3:]
        length = float(np.linalg.norm(d))
        if length < 1e-12:
            raise self.src.error(element, "attribute 'fromto' has two equal ends")
        return pose((ends[:3] + ends[3:]) / 2, z_to(d / length)), length

    def geom(self, element, link: str, link_from_here: np.ndarray, childclass: str) -> dict:
        """The geom's shape, pose (in the link) and mass properties; its visual/collision is recorded."""
        a = self.attributes(element, childclass)
        self.unique("geom", element)
        kind = a.get("type", "sphere")
        what = f"geom '{a['name']}'" if a.get("name") else "geom"
        if kind not in _SHAPES:
            raise self.src.error(
                element, f"{what}: attribute 'type' is '{short(kind)}', expected one of {', '.join(_SHAPES)}"
            )
        size = list(numbers(element, "size", self.src, text=a["size"], at_most=3)) if "size" in a else []
        size += [0.0] * (3 - len(size))
        pose = self.frame(element, a)
        if "fromto" in a:
            if kind not in ("capsule", "cylinder", "box", "ellipsoid"):
                raise self.src.error(
                    element, f"{what}: 'fromto' is for capsules, cylinders, boxes and ellipsoids, not a {kind}"
                )
            pose, length = self.segment(element, a["fromto"])
            if kind in ("capsule", "cylinder"):
                size[1] = length / 2
            else:  # MuJoCo: a box's or ellipsoid's cross-section is square/round, of size[0]
                size[1], size[2] = size[0], length / 2
        needed = {"sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3, "box": 3}.get(kind, 0)
        if any(s <= 0 for s in size[:needed]):
            raise self.src.error(
                element,
                f"{what}: a {kind} needs {needed} positive size number{'s' if needed > 1 else ''}, got size='{a.get('size', '')}'",
            )
        group = int(numbers(element, "group", self.src, 1, text=a.get("group", "0"))[0])
        shape = self.shape(element, kind, size, a, what)
        where = self.src.at(element)
        in_link = link_from_here @ pose
        if shape is not None:
            rgba = None
            if "rgba" in a:
                rgba = self.rgba(element, a["rgba"])
            elif a.get("material") in self.materials:
                rgba = self.materials[a["material"]]
            elif kind != "mesh":
                rgba = (0.5, 0.5, 0.5, 1.0)
            shown, drawn_pose = shape
            item = Visual(link, shown, in_link @ drawn_pose, rgba, a.get("material"), where)
            if 0 <= group <= 2:
                self.visuals.append(item)
            if a.get("contype", "1") != "0" or a.get("conaffinity", "1") != "0":
                self.collisions.append(item)
        return {"element": element, "kind": kind, "size": size, "pose": in_link, "a": a, "what": what, "group": group}

    def shape(self, element, kind: str, size: list, a: dict, what: str):
        """(kinedyn shape, its pose in the geom frame), or None for shapes kinedyn does not draw."""
        if kind == "box":
            return Box(tuple(2 * s for s in size)), np.eye(4)
        if kind == "sphere":
            return Sphere(size[0]), np.eye(4)
        if kind in ("cylinder", "capsule"):
            # a capsule is drawn as the cylinder of its full length
            return Cylinder(size[0], 2 * size[1] + (2 * size[0] if kind == "capsule" else 0.0)), np.eye(4)
        if kind == "ellipsoid":
            return Sphere(max(size)), np.eye(4)
        if kind == "mesh":
            name = a.get("mesh")
            if name not in self.meshes:
                raise self.src.error(element, f"{what}: mesh='{name}' names no <asset><mesh>")
            file, scale, _ = self.meshes[name]
            if file is None:  # a mesh of inline vertices: not drawn
                return None
            if self.meshdir is None:
                return Mesh(file, tuple(scale), None), np.eye(4)
            return Mesh(os.path.join(self.meshdir, file), tuple(scale), self.meshdir), np.eye(4)
        return None

    def inertia(self, element, name: str, geoms: list) -> Inertia:
        """The body's inertia in its frame: ``<inertial>``, or its geoms' (MuJoCo's inertiafromgeom)."""
        inertial = element.find("inertial")
        if inertial is not None and self.inertiafromgeom != "true":
            return self.inertial(inertial, name)
        if inertial is None and self.inertiafromgeom == "false":
            return Inertia()
        total = Inertia()
        lo, hi = self.groups
        for g in geoms:
            if not lo <= g["group"] <= hi or g["kind"] in ("plane", "hfield", "sdf"):
                continue
            total = total + self.geom_inertia(g, name)
        return total

    def inertial(self, element, body: str) -> Inertia:
        a = element.attrib
        for required in ("pos", "mass"):
            if required not in a:
                raise self.src.error(element, f"of body '{body}' has no '{required}' attribute (MuJoCo requires it)")
        mass = numbers(element, "mass", self.src, 1)[0]
        if mass < 0:
            raise self.src.error(element, f"of body '{body}': attribute 'mass' is negative ({mass:g})")
        if "diaginertia" in a and "fullinertia" in a:
            raise self.src.error(element, f"of body '{body}' gives both 'diaginertia' and 'fullinertia'; keep one")
        if "fullinertia" in a:
            if any(k in a for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis")):
                raise self.src.error(
                    element, f"of body '{body}': 'fullinertia' takes no orientation (MuJoCo refuses it too)"
                )
            ixx, iyy, izz, ixy, ixz, iyz = numbers(element, "fullinertia", self.src, 6)
        elif "diaginertia" in a:
            ixx, iyy, izz = numbers(element, "diaginertia", self.src, 3)
            ixy = ixz = iyz = 0.0
        else:
            raise self.src.error(element, f"of body '{body}' has neither 'diaginertia' nor 'fullinertia'")
        pose = self.frame(element, a)  # its errors name the file and line already
        try:
            return Inertia.from_urdf(mass, ixx, ixy, ixz, iyy, iyz, izz).transformed(pose)
        except ValueError as e:
            raise self.src.error(element, f"of body '{body}': {e}") from None

    def geom_inertia(self, g: dict, body: str) -> Inertia:
        """A solid geom's mass properties (MuJoCo's: volume times density, or the geom's ``mass``)."""
        kind, (s0, s1, s2), a, element = g["kind"], g["size"], g["a"], g["element"]
        what = f"{g['what']} of body '{body}'"
        if kind == "mesh":
            raise self.src.error(
                element,
                f"{what}: kinedyn does not compute a mesh's inertia; give body '{body}' an <inertial> (MuJoCo's compiled model shows it: model.body_inertia)",
            )
        try:
            volume, unit = solid_volume_and_moments(kind, s0, s1, s2)
        except ValueError as e:  # a capsule of radius 1e-300: its volume underflows to 0
            raise self.src.error(element, f"{what}: {e}; give sizes a robot has, or the body an <inertial>") from None
        if "mass" in a:
            mass = numbers(element, "mass", self.src, 1, text=a["mass"])[0]
        else:
            mass = volume * numbers(element, "density", self.src, 1, text=a.get("density", "1000"))[0]
        if mass < 0:
            raise self.src.error(element, f"{what}: its mass is negative ({mass:g})")
        if a.get("shellinertia") == "true":
            raise self.src.error(
                element, f"{what}: shellinertia is not read by kinedyn; give body '{body}' an <inertial>"
            )
        body_inertia = Inertia(mass, (0.0, 0.0, 0.0), np.diag([mass * u for u in unit]))
        return body_inertia.transformed(g["pose"])


def __getattr__(name: str):
    # robot_from_mjcf built a Robot from this layer; it lives above the description now
    # (kinedyn.robot_files), loaded by name so that the description never imports the facade
    if name == "robot_from_mjcf":
        warnings.warn(
            "kinedyn.description.mjcf.robot_from_mjcf moved: use kinedyn.Robot.from_mjcf "
            "(or description_from_mjcf for the description alone)",
            DeprecationWarning,
            stacklevel=2,
        )
        return importlib.import_module("kinedyn.robot_files").robot_from_mjcf
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
