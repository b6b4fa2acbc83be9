"""The audit's loop check (docs/audit.md, ``loop-open``): a closed loop whose two frames do not meet
at the file's reference configuration.

The reference configuration is the pose the file is written in: ``q = 0`` for a URDF, a robot file
or a description built in Python; MuJoCo's ``qpos0`` for MJCF (every hinge and slide at its ``ref``,
balls at the identity), where a body-form ``<connect>``/``<weld>`` closes by definition and only a
site-form one, or a weld with its own ``relpose``, can be open (MuJoCo then pulls its two ends
together when a simulation starts: the model jumps). A model with a free joint is not checked here (its reference pose is the file's body pose,
which the description does not keep). Forward kinematics at that configuration is a product of the
tree's fixed placements and each 1-DOF joint's motion by its offset (LaValle 13.4: the closure
residual of the loop, here only its size).
"""

from __future__ import annotations

import math
import os
import warnings

import numpy as np

from .._math import rot_axis, translation
from .._ui.files import open_regular
from .description import Description
from .files import read_description
from .mjcf import description_from_mjcf
from .mjcf_xml import MAX_FILE_BYTES, parse_model
from .urdf import description_from_urdf, read_urdf_xml

__all__ = ["loop_findings", "OPEN_TOLERANCE"]

#: a loop is open at its reference when its frames are farther apart than this [m, or rad for a weld]
OPEN_TOLERANCE = 1e-6


def loop_findings(facts, source, kind: str) -> None:
    """Add a ``loop-open`` finding to ``facts`` for each loop of ``source`` (a Description, or the
    text or path of a ``kind`` = ``"urdf"``, ``"mjcf"`` or ``"file"`` robot file) that is open at the
    reference configuration; nothing when the loader refuses the file (the other checks say why)."""
    if not isinstance(source, Description) and not _mentions_loops(source, kind):
        return  # most files: no second load of the robot
    lines: dict = {}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the loader's warnings are its own
            if isinstance(source, Description):
                description = source
            elif kind == "urdf":
                description = description_from_urdf(source)
                src, root = read_urdf_xml(source)
                lines = {e.get("name"): (src.label, src.line(e)) for e in root.iterfind("loop")}
            elif kind == "mjcf":
                description = description_from_mjcf(source)
                lines = _mjcf_lines(source)
            else:
                description = read_description(source)
    except ValueError:
        return
    if not description.loops or description.is_symbolic:
        return
    mjcf = kind == "mjcf" and not isinstance(source, Description)
    if mjcf and any(b.joint.kind == "floating" for b in description.tree.bodies):
        return
    poses = _reference_poses(description, mjcf)
    for loop in description.loops:
        A, B = poses[loop.frame_a], poses[loop.frame_b]
        gap = float(np.linalg.norm(A[:3, 3] - B[:3, 3]))
        R = B[:3, :3].T @ A[:3, :3]
        angle = math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2))) if loop.kind == "weld" else 0.0
        if gap <= OPEN_TOLERANCE and angle <= OPEN_TOLERANCE:
            continue
        file, line = lines.get(loop.name, (description.source or description.name, None))
        where = "MuJoCo's qpos0 (every hinge and slide at its ref)" if mjcf else "q = 0"
        apart = f"{gap:.3g} m" + (f" and {angle:.3g} rad" if angle > OPEN_TOLERANCE else "")
        if mjcf:
            message = (
                f"its frames '{loop.frame_a}' and '{loop.frame_b}' are {apart} apart at {where}: MuJoCo pulls "
                "them together when a simulation starts, so the model jumps there"
            )
            fix = "place the sites (or the weld's relpose) where they meet in the model as written, or start from a closed keyframe"
        else:
            message = f"its frames '{loop.frame_a}' and '{loop.frame_b}' are {apart} apart at {where}, the pose the file is written in"
            fix = "nothing, if the mechanism cannot be assembled there; else check the frames' poses on their links"
        facts.add(
            "warning" if mjcf else "info",
            "loop-open",
            f"loop '{loop.name}'",
            file,
            line,
            message,
            fix,
            gap=gap,
            angle=angle,
        )


def _mentions_loops(source, kind: str) -> bool:
    """Whether the file's text holds the element or key of a loop (a cheap test before loading it)."""
    text = os.fspath(source)
    if "<" not in text and "\n" not in text:
        try:
            with open_regular(text, "robot file") as f:
                text = f.read(MAX_FILE_BYTES + 1).decode("utf-8", errors="replace")
        except (OSError, ValueError):
            return False
    words = {"urdf": ("<loop",), "mjcf": ("<connect", "<weld", "<include")}.get(kind, ("loops",))
    return any(w in text for w in words)


def _mjcf_lines(source) -> dict:
    """loop name -> (file, line) of its ``<connect>``/``<weld>`` (unnamed: ``equality<k>``, the reader's names)."""
    src, root = parse_model(source)
    out, index = {}, -1
    for section in root.iterfind("equality"):
        for element in section:
            index += 1
            out[element.get("name") or f"equality{index}"] = src.where.get(id(element), (src.label, None))
    return out


def _reference_poses(description: Description, mjcf: bool) -> dict:
    """World pose of every frame at the reference configuration: a 1-DOF joint moved by ``q + offset``
    with ``q = 0`` (``q = ref = -offset`` in MJCF: no motion), a multi-DOF joint at its neutral."""
    tree = description.tree
    world: list = []
    for body in tree.bodies:
        joint = body.joint
        parent = np.eye(4) if body.parent < 0 else world[body.parent]
        x = 0.0 if mjcf else float(joint.offset) + (float(joint.mimic.offset) if joint.mimic is not None else 0.0)
        motion = np.eye(4)
        if joint.kind == "revolute" and x:
            motion = np.asarray(rot_axis([float(a) for a in joint.axis], x), dtype=float)
        elif joint.kind == "prismatic" and x:
            motion = np.asarray(translation(*(float(a) * x for a in joint.axis)), dtype=float)
        world.append(parent @ np.asarray(body.placement, dtype=float) @ motion)
    return {
        f.name: (np.eye(4) if f.body < 0 else world[f.body]) @ np.asarray(f.placement, dtype=float) for f in tree.frames
    }


def source_kind(path: str) -> str:
    """``"urdf"``, ``"mjcf"`` or ``"file"`` (a YAML/TOML robot file) by the path's extension."""
    ext = os.path.splitext(path)[1].lower()
    return {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf"}.get(ext, "file")
