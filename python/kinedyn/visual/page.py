"""A robot's 3-D view in a self-contained page (the report's and an animation's): what assets/viewer.js reads: the model it runs the forward kinematics
of, and the safe embedding of JSON and of the inlined assets in the page."""

from __future__ import annotations

import html
import json
import math
import re
import warnings
from importlib import resources

import numpy as np

from ..coordinates import coordinate_labels, coordinate_units, in_multi_dof_block
from ..description.joint import planar_basis
from ..description.mimic import body_coordinates
from .loops import loop_sliders
from .scene import DEFAULT_BUDGET, MissingMeshWarning, robot_scene, scene_bounds
from .web import encode_scene, plotly_script

__all__ = ["view_model", "asset", "script_json", "json_script"]


def view_model(robot, q, geometry: str = "visual", budget: int | None = None) -> dict:
    """What the inline viewer needs to run the forward kinematics itself and draw the meshes (each
    once, in its frame's coordinates: kinedyn.visual.web)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MissingMeshWarning)  # said in the report instead (model["missing"])
        scene = robot_scene(robot, geometry, DEFAULT_BUDGET if budget is None else budget)
    tree = robot.tree
    # where each joint's block starts in q: a multi-DOF joint's q[start:start + nq] moves its body as a
    # whole (viewer.js: position, then a unit quaternion; planar x, y, cos, sin)
    starts, start = {}, 0
    for j in robot.joints:
        starts[j.name] = start
        start += j.nq
    bodies = []
    for b in tree.bodies:
        body = {
            "parent": int(b.parent),
            "name": b.joint.name,
            "kind": b.joint.kind,
            "axis": [float(a) for a in b.joint.axis],
            "offset": float(b.joint.offset),
            "placement": np.asarray(b.placement, dtype=float).ravel().tolist(),
        }
        if b.joint.name in starts:
            body["q"] = starts[b.joint.name]
        if b.joint.kind == "planar":  # the plane's in-plane axes (x along e1, y along e2; the rotation about e1 x e2)
            e1, e2 = planar_basis(np.asarray(b.joint.axis, dtype=float))
            body["e1"], body["e2"] = e1.tolist(), e2.tolist()
        bodies.append(body)
    if robot.mimic_joints:  # each body's coordinate: q[q] for its own, scale * q[q] + shift for a mimic follower
        names = robot.joint_names
        for body, coordinate in zip(bodies, body_coordinates(robot)):
            body.update(coordinate)
            body["q"] = starts[names[coordinate["q"]]]  # body_coordinates numbers the joints; q numbers their entries
    # a slider per 1-DOF coordinate and per position entry of a floating or planar joint (a rotation
    # has none: it is shown at q and moves in the playback)
    labels, units = coordinate_labels(robot), coordinate_units(robot)
    sliders = []
    for k, (label, unit, lo, hi) in enumerate(zip(labels, units, robot.lower_limits, robot.upper_limits)):
        if unit:
            sliders.append(
                {
                    "name": label,
                    "q": k,
                    "revolute": unit == "rad",
                    "lower": float(lo) if math.isfinite(lo) else None,
                    "upper": float(hi) if math.isfinite(hi) else None,
                }
            )
    frames = [
        {"name": f.name, "body": int(f.body), "placement": np.asarray(f.placement, dtype=float).ravel().tolist()}
        for f in tree.frames
    ]
    # size of the scene: the farthest frame origin over q and a few random configurations
    qs = np.vstack([q, robot.random_configuration(np.random.default_rng(1), size=64)])
    origins = np.vstack([np.zeros((1, 3)), robot.frame_poses(qs)[..., :3, 3].reshape(-1, 3)])
    reach = max(float(np.max(np.linalg.norm(origins, axis=-1))), 1e-3)
    # closed loops: a slider per independent coordinate instead, stepping through configurations
    # solved here (kinedyn.visual.loops; viewer.js reads model.loop)
    loop = loop_sliders(robot, q, reach)
    if loop is not None:
        sliders = [
            {"name": name, "q": e, "revolute": revolute, "loop": k}
            for k, (name, e, revolute) in enumerate(zip(loop["joints"], loop["q"], loop["revolute"]))
        ]
    # the cube the view shows: around every frame origin of those configurations, with a margin for the meshes
    lo, hi = origins.min(axis=0), origins.max(axis=0)
    half = float(np.max(hi - lo)) / 2 + 0.12 * reach
    # the camera looks at the robot as it stands at q: the box of its shapes (and frame origins)
    focus_lo, focus_hi = scene_bounds(robot, scene, q)
    gravity = np.asarray(robot.gravity, dtype=float)
    up = -gravity / np.linalg.norm(gravity) if np.linalg.norm(gravity) > 0 else np.array([0.0, 0.0, 1.0])
    axes = np.array([np.asarray(robot.pose(q, name)[:3, 2]) for name in robot.body_names])
    planar = (
        len(axes) > 0  # a robot with no moving joint has no joint axis to look along
        and all(j.kind == "revolute" for j in robot.joints)
        and np.allclose(np.abs(axes @ axes[0]), 1.0, atol=1e-9)
        and abs(axes[0] @ up) < 1e-9
    )
    if planar:  # look along the common joint axis: the arm is drawn as in the textbook's figure
        view_from = axes[0]
    else:  # an isometric view from the front-right, above the base
        side = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
        side /= np.linalg.norm(side)
        front = np.cross(side, up)
        view_from = 0.8 * front - 0.6 * side + 0.45 * up
    return {
        "bodies": bodies,
        "frames": frames,
        "joint_names": robot.joint_names,
        "joint_kinds": [j.kind for j in robot.joints],
        "coordinate_labels": labels,
        "coordinate_units": units,
        "coordinate_named": in_multi_dof_block(robot),
        "sliders": sliders,
        "loop": loop,
        "lower": [float(x) if math.isfinite(x) else None for x in robot.lower_limits],
        "upper": [float(x) if math.isfinite(x) else None for x in robot.upper_limits],
        "q": [float(x) for x in q],
        "tool": robot.tool,
        "reach": reach,
        "center": ((lo + hi) / 2).tolist(),
        "half": half,
        "focus": {"center": ((focus_lo + focus_hi) / 2).tolist(), "size": float(np.linalg.norm(focus_hi - focus_lo))},
        "up": up.tolist(),
        "view_from": np.asarray(view_from, dtype=float).tolist(),
        "planar": bool(planar),  # drawn as the textbook's figure: orthographic, along the joint axes
        "meshes": encode_scene(scene),
        "geometry": geometry,
        "shapes": scene.shapes,  # visuals described
        "shapes_drawn": scene.drawn,  # of those, read and drawn (the rest are in "missing")
        "missing": scene.missing,
        "generated": scene.generated,  # solid links made from the kinematics (no visuals described)
        "label_joints": scene.generated and robot.n <= 8,
    }


def asset(name: str) -> str:
    # one step per joinpath: Python 3.10's Traversable.joinpath takes a single name
    return resources.files("kinedyn.visual").joinpath("assets").joinpath(name).read_text(encoding="utf-8")


# Characters that may not appear raw in JSON embedded in a <script> element, with their JSON escapes.
# Inside a script element the HTML tokenizer looks for "</script" and also enters its "escaped" states
# on "<!--" (after which "<script" makes it ignore the next "</script>": the rest of the page becomes
# script text), so no "<" may reach it; ">" and "&" are escaped too so that the text means the same in
# an XHTML/XML parser, and U+2028/U+2029 because they end a line in JavaScript before ES2019
# (HTML Standard 4.12.1.3 "Restrictions for contents of script elements"; the same set as Django's
# json_script and Go's html/template).
_SCRIPT_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}
_SCRIPT_UNSAFE = re.compile("[<>&\u2028\u2029]")


def script_json(obj) -> str:
    """``obj`` as JSON text that is safe as the content of an HTML ``<script>`` element, whatever
    strings it holds: the characters above become JSON's ``\\uXXXX`` escapes (valid only inside JSON
    strings, which is the only place JSON text can hold them), so ``JSON.parse`` returns ``obj``."""
    text = json.dumps(obj, allow_nan=False)
    return _SCRIPT_UNSAFE.sub(lambda m: _SCRIPT_ESCAPES[m.group(0)], text)


def json_script(obj, element_id: str) -> str:
    """A ``<script type="application/json">`` block holding ``obj`` (read back by viewer.js)."""
    return f'<script type="application/json" id="{html.escape(element_id)}">{script_json(obj)}</script>'


def animation_page(robot, t, q, title: str = "") -> str:
    """A self-contained HTML page that plays the motion ``q`` (S, n) at times ``t`` (S,) of ``robot``
    with its meshes (the report's 3-D view: each mesh once, then joint values per frame)."""
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    if q.ndim != 2 or q.shape != (len(t), robot.nq):
        raise ValueError(f"animation_page needs q of shape ({len(t)}, {robot.nq}), got {q.shape}")
    model = view_model(robot, q[0])
    data = {"simulation": {"t": t.tolist(), "q": q.tolist()}}
    name = html.escape(title or robot.name)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{name}: motion</title><style>{asset("page.css")}</style></head>
<body><main><section id='view'><h2>{name}</h2><div class='grid'><div>
<div id="kinedyn-view" role="img" aria-label="3-D view of the motion"></div>
<div id='kinedyn-playback' hidden><button id='kinedyn-play' type='button'>▶ play</button> <input id='kinedyn-time' type='range' aria-label='time'> <span id='kinedyn-clock'></span></div>
<p class='note'>Drag to rotate, scroll to zoom. Written by kinedyn (Trajectory.animate); self-contained, nothing is fetched.</p>
</div><div><h3>Joints</h3><div id='kinedyn-sliders'></div><p><button id='kinedyn-reset' type='button'>reset</button> <span id='kinedyn-tool'></span></p>
<p class='note' id='kinedyn-q'></p></div></div></section></main>
{json_script(model, "kinedyn-model")}
{json_script(data, "kinedyn-data")}
{plotly_script()}
<script>{asset("viewer.js")}</script>
</body></html>
"""
