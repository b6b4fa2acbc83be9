"""Closed loops in the files kinedyn reads and writes (docs/model-files.md, "Closed loops"):
the URDF ``<loop>`` extension, MJCF ``<equality>`` written by ``to_mjcf``, and the ``loops:``
section of a YAML/TOML robot file. MJCF's ``<connect>``/``<weld>`` are read by
:mod:`kinedyn.description.mjcf_loops`.

**URDF.** URDF describes a tree; a loop is a top-level element beside the joints, which URDF readers
that do not know it (urdfdom, ROS) skip::

    <loop name="pin" type="point">          <!-- type: point (origins meet) or weld (frames meet) -->
      <link1 link="coupler" xyz="0.4 0 0" rpy="0 0 0"/>
      <link2 link="rocker" xyz="0 0.3 0"/>
    </loop>

Each end names a link and a pose on it (``xyz``, and ``rpy`` as URDF's ``<origin>``: fixed-axis
roll-pitch-yaw; both default to zero). An end at the link's own frame is that link's frame; an end
elsewhere adds a frame ``<loop>_a`` (``_b``) on the link there. ``to_urdf`` writes each end as
the link of the same name (every kinedyn frame is a URDF link in the written file), so a loop
reads back between the frames it had.

The reference configuration, where the loops close on the branch the mechanism is assembled in, is
one more top-level element, a value per joint as SRDF's ``<group_state>`` lists them (a multi-DOF
joint's value is its block of q, numbers separated by spaces)::

    <reference_configuration>
      <joint name="shoulder" value="-0.5"/>
      <joint name="elbow" value="1.1"/>
    </reference_configuration>
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from .._math import matmul, rpy_to_matrix, translation
from .._ui.names import did_you_mean
from .link import Frame
from .loops import LOOP_KINDS, Loop

__all__ = [
    "urdf_loops",
    "urdf_loop_elements",
    "urdf_reference",
    "urdf_reference_element",
    "mjcf_loop_sites",
    "write_mjcf_loops",
    "loops_mapping",
    "unique_name",
]

_ENDS = (("link1", "a"), ("link2", "b"))


def unique_name(name: str, taken: set) -> str:
    """``name``, or ``name_2``, ``name_3``... the first not in ``taken`` (then added to it)."""
    out, k = name, 2
    while out in taken:
        out, k = f"{name}_{k}", k + 1
    taken.add(out)
    return out


# ------------------------------------------------------------------------------------------ URDF
def urdf_loops(root, src, link_names, floats) -> tuple:
    """``(frames, loops)`` of a URDF's ``<loop>`` elements; ``src`` names file and line in errors,
    ``floats(text, n, default, what, element, src)`` reads numbers as the URDF reader does."""
    frames, loops, seen = [], [], dict[str, ET.Element]()
    taken = set(link_names)
    for element in root.iterfind("loop"):
        name = element.get("name")
        if not name:
            raise src.error(element, "a <loop> has no name")
        if name in seen:
            raise src.error(element, f"loop '{name}' is defined twice (first at line {src.line(seen[name])})")
        seen[name] = element
        what = f"loop '{name}'"
        kind = element.get("type")
        if kind not in LOOP_KINDS:
            raise src.error(
                element,
                f"{what} has type {kind!r}: expected one of {', '.join(LOOP_KINDS)}{did_you_mean(str(kind), list(LOOP_KINDS))}",
            )
        ends = []
        for tag, letter in _ENDS:
            end = element.find(tag)
            if end is None or not end.get("link"):
                raise src.error(element, f"{what} has no <{tag} link=...>")
            link = end.get("link")
            if link not in link_names:
                raise src.error(
                    end, f"{what}: <{tag}> names link '{link}', which is no <link>{did_you_mean(link, link_names)}"
                )
            xyz = floats(end.get("xyz"), 3, (0, 0, 0), f"{what} <{tag}> xyz", end, src)
            rpy = floats(end.get("rpy"), 3, (0, 0, 0), f"{what} <{tag}> rpy", end, src)
            if not any(xyz) and not any(rpy):
                ends.append(link)
                continue
            frame = unique_name(f"{name}_{letter}", taken)
            frames.append(Frame(frame, link, matmul(translation(*xyz), rpy_to_matrix(*rpy))))
            ends.append(frame)
        try:
            loops.append(Loop(name, ends[0], ends[1], kind))
        except ValueError as e:
            raise src.error(element, str(e)) from None
    return frames, loops


def urdf_loop_elements(robot) -> list:
    """The ``<loop>`` elements of ``robot``'s loops, each end the URDF link of its frame."""
    out = []
    for loop in robot.loops:
        el = ET.Element("loop", name=loop.name, type=loop.kind)
        ET.SubElement(el, "link1", link=loop.frame_a)
        ET.SubElement(el, "link2", link=loop.frame_b)
        out.append(el)
    return out


def urdf_reference(root, src, joints: dict, floats) -> dict | None:
    """The ``<reference_configuration>`` element's ``{joint: value}`` (None without one); ``joints``:
    the moving joints' ``{name: nq}``."""
    elements = root.findall("reference_configuration")
    if not elements:
        return None
    if len(elements) > 1:
        raise src.error(elements[1], "a second <reference_configuration> (a robot has one)")
    out: dict = {}
    for end in elements[0]:
        name = end.get("name")
        if end.tag != "joint" or not name:
            raise src.error(end, f"<reference_configuration> holds <joint name value/> elements, got <{end.tag}>")
        if name not in joints:
            raise src.error(
                end,
                f"<reference_configuration> names joint '{name}', which is no moving <joint>{did_you_mean(name, list(joints))}",
            )
        if name in out:
            raise src.error(end, f"<reference_configuration> states joint '{name}' twice")
        n = joints[name]
        values = floats(end.get("value"), n, None, f"the reference value of joint '{name}'", end, src)
        if values is None:
            raise src.error(end, f"<reference_configuration>: joint '{name}' has no value")
        out[name] = values[0] if n == 1 else values
    return out


def urdf_reference_element(robot) -> list:
    """``[<reference_configuration>]`` of ``robot``'s reference configuration, or ``[]``."""
    reference = getattr(robot, "description", robot).reference_configuration
    if not reference:
        return []
    el = ET.Element("reference_configuration")
    for name, value in reference.items():
        values = value if isinstance(value, tuple) else (value,)
        ET.SubElement(el, "joint", name=name, value=" ".join(repr(float(v)) for v in values))
    return [el]


# ------------------------------------------------------------------------------------------ MJCF
def mjcf_loop_sites(robot, drawn) -> set:
    """The extra frames ``to_mjcf`` writes as sites rather than bodies: loop ends that carry no
    geometry (``drawn``: the frames visuals and collisions hang on); a site keeps the frame's name
    when read back, and MuJoCo's site-form equality holds it wherever it is at qpos0."""
    ends = {name for loop in robot.loops for name in (loop.frame_a, loop.frame_b)}
    return {f.name for f in robot.frames if f.name in ends and f.name not in drawn}


def write_mjcf_loops(robot, root, bodies: dict, sites: set, mj_pose) -> None:
    """Sites at the loop ends and an ``<equality><connect|weld site1 site2>`` per loop (MuJoCo's
    XML reference, equality/connect and equality/weld: with sites, the constraint pulls the two
    sites' origins, or frames, together whatever their pose at qpos0). ``sites``: the extra frames
    written as sites (:func:`mjcf_loop_sites`), placed on their link's body; another loop end (a
    link, or a frame written as a body) gets a site ``<loop>_a`` (``_b``) at its origin."""
    if not robot.loops:
        return
    frames = {f.name: f for f in robot.frames}
    taken = set(sites) | {f.name for f in robot.frames} | {link.name for link in robot.links} | {robot.base}
    for name in sorted(sites, key=list(frames).index):
        frame = frames[name]
        site = ET.SubElement(bodies[frame.link or robot.base], "site", name=name)
        mj_pose(site, np.asarray(frame.placement, dtype=float))
    equality = root.find("equality")
    if equality is None:
        equality = ET.SubElement(root, "equality")
    for loop in robot.loops:
        ends = []
        for end, letter in ((loop.frame_a, "a"), (loop.frame_b, "b")):
            if end not in sites:
                end = unique_name(f"{loop.name}_{letter}", taken)
                ET.SubElement(bodies[loop.frame_a if letter == "a" else loop.frame_b], "site", name=end)
            ends.append(end)
        tag = "connect" if loop.kind == "point" else "weld"
        ET.SubElement(equality, tag, name=loop.name, site1=ends[0], site2=ends[1])


# ------------------------------------------------------------------------------------------ YAML/TOML
def loops_mapping(loops) -> list:
    """The ``loops:`` section of a robot file."""
    return [{"name": lp.name, "frame_a": lp.frame_a, "frame_b": lp.frame_b, "kind": lp.kind} for lp in loops]
