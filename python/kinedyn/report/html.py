"""``kinedyn report``: one self-contained HTML file about a robot that opens offline.

Sections: the joint and DH tables; an interactive 3-D view (the robot's meshes, or solid links, lit,
drawn by plotly.js inlined from the plotly package; assets/viewer.js runs the same forward kinematics
as kinedyn.Robot, so the joint sliders and the simulation's playback move the meshes); the tool pose, Jacobian and singular values;
the equations of motion typeset as MathML from the symbolic engine; the properties check (M symmetric
positive definite, dM/dt - 2C skew and dM/dt = C + C^T by finite differences, the regressor reproduces
tau, RNEA = M qdd + C qd + g); and plots (inline SVG) of a short free motion under gravity with its
energy. Every script and style is inlined; nothing is fetched. All numbers shown are also in the JSON
block ``#kinedyn-data`` (and ``kinedyn report --json``).

Robots with floating, spherical and planar joints: q (nq entries) is shown joint block by joint block
(position, unit quaternion x y z w; planar x, y, cos θ, sin θ), velocities, M, J and g per degree of
freedom (nv), dM/dt along q ⊕ t qd; the viewer moves each block, and what does not apply (sliders for
rotations, equations of a large robot) says so on the page.

The numbers are gathered by :func:`kinedyn.report.data.collect` into a :class:`ReportData`; this module
shapes them into rows, plots and equations, and the Jinja2 templates in ``templates/`` lay out the page
(autoescaped: every name from a robot file is text, never markup).
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from markupsafe import Markup

from .._ui.files import write_text
from .._ui.json import jsonable
from .._ui.progress import Steps
from .._ui.svg import svg_plot
from .._version import __version__
from ..configuration import default_configuration, log3
from ..symbolic.derive.cse import block_equations
from ..symbolic.render import latex_to_mathml, of_q
from ..symbolic.render import name as mathml_name
from ..tutorial import QUESTIONS, answer, render_html
from ..visual.page import asset, json_script, script_json, view_model
from ..visual.scene import MissingMeshWarning
from ..visual.web import plotly_script
from .data import (
    SIMULATION_BUDGET,
    ReportData,
    collect,
    coordinate_labels,
    coordinate_units,
    in_multi_dof_block,
    velocity_labels,
)
from .page import TEMPLATES
from .tables import fmt

__all__ = [
    "default_configuration",
    "collect",
    "ReportData",
    "build_report",
    "render_report",
    "write_report",
    "latex_to_mathml",
    "svg_plot",
    "script_json",
    "coordinate_labels",
    "velocity_labels",
    "SIMULATION_BUDGET",
]


def q_text(q, labels: Sequence[str], units: Sequence[str], named: Sequence[bool]) -> str:
    """q as the report writes it: "0.5 rad (28.6°), 0.2 m" for 1-DOF joints; the entries of a
    multi-DOF joint's block are named ("root_joint.z = 0.3 m, root_joint.qw = 1")."""
    parts = []
    for v, label, unit, named_entry in zip(q, labels, units, named):
        value = (
            f"{fmt(v)} rad ({fmt(math.degrees(v), 5)}°)"
            if unit == "rad"
            else (f"{fmt(v)} m" if unit == "m" else fmt(v))
        )
        parts.append(f"{label} = {value}" if named_entry else value)
    return ", ".join(parts)


# ------------------------------------------------------------------ rows of the tables
def _joint_table(d: ReportData, multi: bool) -> tuple[list[str], list[list[str]]]:
    """The joints table: kind, axis, offset, limits; with multi-DOF joints also where each sits in q and
    q̇ (a floating or spherical joint has no single axis, offset or limits)."""
    if not multi:
        headers = ["joint", "type", "axis", "offset", "limits"]
        rows = [
            [
                j["name"],
                j["type"],
                " ".join(fmt(a) for a in j["axis"]),
                fmt(j["offset"]),
                f"[{fmt(j['lower'])}, {fmt(j['upper'])}]",
            ]
            for j in d["joints"]
        ]
        return headers, rows
    rows = []
    for j in d["joints"]:
        q_block = (
            f"q[{j['q_index']}]"
            if j["nq"] == 1
            else f"q[{j['q_index']}:{j['q_index'] + j['nq']}] = ({', '.join(j['q_entries'])})"
        )
        v_block = (
            f"q̇[{j['v_index']}]"
            if j["nv"] == 1
            else f"q̇[{j['v_index']}:{j['v_index'] + j['nv']}] = ({', '.join(j['v_entries'])})"
        )
        if j["type"] in ("floating", "spherical"):
            axis_offset_limits = ["—", "—", "—"]
        elif j["type"] == "planar":
            axis_offset_limits = ["normal " + " ".join(fmt(a) for a in j["axis"]), "—", "—"]
        else:
            axis_offset_limits = [
                " ".join(fmt(a) for a in j["axis"]),
                fmt(j["offset"]),
                f"[{fmt(j['lower'])}, {fmt(j['upper'])}]",
            ]
        rows.append([j["name"], j["type"], *axis_offset_limits, q_block, v_block])
    return ["joint", "type", "axis", "offset", "limits", "in q", "in q̇"], rows


def _dh_rows(d: ReportData) -> list[list[str]] | None:
    """The DH table: the joint variable q_i in θ (revolute) or d (prismatic), the constants added."""
    if d["dh"] is None:
        return None
    rows = []
    for i, r in enumerate(d["dh"], 1):
        rev = r["type"] == "revolute"
        rows.append(
            [
                str(i),
                f"q{i}" + (f" + {fmt(r['theta'])}" if r["theta"] else "") if rev else fmt(r["theta"]),
                fmt(r["d"]) if rev else f"q{i}" + (f" + {fmt(r['d'])}" if r["d"] else ""),
                fmt(r["a"]),
                f"{fmt(math.degrees(r['alpha']))}°",
            ]
        )
    return rows


def _configuration_rows(q, d: ReportData) -> list[list[str]]:
    """Per joint: its block of q (named entries; a rotation also as angle and axis) and the names of its
    velocities."""
    rows = []
    for j in d["joints"]:
        block = np.asarray(q[j["q_index"] : j["q_index"] + j["nq"]], dtype=float)
        names = j.get("q_entries") or [j["name"]]
        values = ", ".join(f"{n} = {fmt(v)}" for n, v in zip(names, block)) if j["nq"] > 1 else fmt(block[0])
        if j["type"] in ("floating", "spherical"):
            r = log3(block[-4:])
            angle = float(np.linalg.norm(r))
            axis = r / angle if angle > 0 else np.array([0.0, 0.0, 1.0])
            values += f" (a rotation of {fmt(math.degrees(angle), 5)}° about ({', '.join(fmt(a, 4) for a in axis)}))"
        elif j["type"] == "planar":
            values += f" (θ = {fmt(math.degrees(math.atan2(block[3], block[2])), 5)}°)"
        velocities = ", ".join(j.get("v_entries") or [j["name"]])
        rows.append([j["name"], j["type"], values, velocities])
    return rows


def _property_rows(d: ReportData) -> list[list]:
    return [
        [
            p["property"],
            p["measure"],
            fmt(p["value"], 3),
            Markup("<span class='ok'>holds</span>" if p["ok"] else "<span class='bad'>FAILS</span>"),
        ]
        for p in d["properties"]
    ]


# ------------------------------------------------------------------ plots
def motion_plots(robot, t, qs, labels) -> list[str]:
    """The simulated coordinates: the 1-DOF joints' in one plot; with multi-DOF joints, their positions
    (m) and their unit quaternions / (cos θ, sin θ) pairs in two more."""
    units, named = coordinate_units(robot), in_multi_dof_block(robot)
    if not any(named):
        return [
            svg_plot(t, [(nm, qs[:, k]) for k, nm in enumerate(labels)], "joint positions", "t [s]", "q [rad or m]")
        ]
    plots = []
    joints = [k for k, m in enumerate(named) if not m]
    if joints:
        plots.append(svg_plot(t, [(labels[k], qs[:, k]) for k in joints], "joint positions", "t [s]", "q [rad or m]"))
    positions = [k for k, (m, u) in enumerate(zip(named, units)) if m and u == "m"]
    if positions:
        plots.append(
            svg_plot(
                t,
                [(labels[k], qs[:, k]) for k in positions],
                "positions of the multi-DOF joints",
                "t [s]",
                "position [m]",
            )
        )
    rotations = [k for k, (m, u) in enumerate(zip(named, units)) if m and not u]
    plots.append(
        svg_plot(
            t,
            [(labels[k], qs[:, k]) for k in rotations],
            "orientations of the multi-DOF joints",
            "t [s]",
            "quaternion (x, y, z, w) or (cos θ, sin θ)",
        )
    )
    return plots


# ------------------------------------------------------------------ MathML
#: the widest line of an equation, in points of 10 pt type (latex.width's estimate): at the page's
#: 18 px mathematics about 850 px, the width of the report's column
EQUATION_WIDTH = 360.0


def _equation(eom, lhs, value) -> Markup:
    """One equation as display MathML from the symbolic engine (EquationsOfMotion.equation_mathml:
    SymPy's presentation printer, names built as MathML)."""
    m = eom.equation_mathml(lhs, value, width=EQUATION_WIDTH)  # a long sum wraps over several lines
    # matrices: brackets drawn by CSS (class bm), which needs no stretchy glyphs in the reader's fonts
    m = re.sub(r"<mrow><mo>\[</mo><mtable>(.*?)</mtable><mo>\]</mo></mrow>", r'<mtable class="bm">\1</mtable>', m)
    return Markup(f'<div class="eq">{m}</div>')


def _equations(eom) -> dict:
    """What the equations section shows: in CSE form the entry names with their values, then per block
    (M, C, g) its entries and intermediate variables; else M, C, g and one line per joint torque; then the
    derivation's remaining steps."""
    out: dict = {"final": [], "blocks": [], "steps": []}
    steps = getattr(eom, "steps", None) or []
    if getattr(eom, "final_equations", None) is not None:  # CSE form: entry names, their values, then the variables
        out["final"] = [_equation(eom, lhs, value) for lhs, value in eom.final_equations()]
        cf = eom.closed_form()
        for key in ("M", "C", "g"):
            entries, intermediates = block_equations(cf[key])
            out["blocks"].append(
                {
                    "title": cf[key].title,
                    "entries": [_equation(eom, lhs, value) for lhs, value in entries],
                    "intermediates": [_equation(eom, lhs, value) for lhs, value in intermediates],
                }
            )
        steps = [s for s in steps if s.title not in {b.title for b in cf.blocks.values()}]
    else:
        out["plain"] = [
            _equation(eom, lhs, value)
            for lhs, value in [(of_q("M"), eom.M), (of_q("C", rates=True), eom.C), (of_q("g"), eom.g)]
        ]
        # one line per joint: the torques are long
        out["plain"] += [
            _equation(eom, mathml_name(f"\\tau_{{{k + 1}}}", f"tau_{k + 1}", "tau", str(k + 1)), eom.tau[k])
            for k in range(eom.n)
        ]
    out["steps"] = [
        {"title": s.title, "text": s.text, "equations": [_equation(eom, lhs, value) for lhs, value in s.equations]}
        for s in steps
    ]
    return out


# ------------------------------------------------------------------ the page
def build_report(
    robot,
    q=None,
    qd=None,
    *,
    name: str | None = None,
    t_end: float = 3.0,
    eom_joints: int = 3,
    data: ReportData | None = None,
    tutorial: bool = False,
    progress: bool | None = False,
    time_budget: float | None = SIMULATION_BUDGET,
    geometry: str = "visual",
) -> str:
    """The report as one HTML string (see the module docstring); ``tutorial``: add the seed
    tutorial's questions worked step by step (its arm is the default robot, planar_2r).
    ``geometry``: the 3-D view draws the "visual" shapes of the description, or the "collision" ones.
    ``progress``: a progress bar of the steps on stderr (None: on a terminal)."""
    total = (0 if data is not None else 4) + 2 + (len(QUESTIONS) if tutorial else 0)
    with Steps("report", total, progress) as steps:
        if data is None:
            data = collect(
                robot,
                q,
                qd,
                name=name,
                t_end=t_end,
                eom_joints=eom_joints,
                time_budget=time_budget,
                progress=progress,
                steps=steps,
            )
        return render_report(robot, data, tutorial=tutorial, steps=steps, geometry=geometry)


def render_report(robot, data: ReportData, *, tutorial: bool = False, steps=None, geometry: str = "visual") -> str:
    """The page of ``data`` (collected from ``robot``): the templates filled in. ``steps``: a
    :class:`kinedyn._ui.progress.Steps` to advance (2 steps, and one per tutorial question)."""
    own = steps is None
    steps = Steps("report", 2 + (len(QUESTIONS) if tutorial else 0), False) if own else steps
    try:
        return _render(robot, data, tutorial, steps, geometry)
    finally:
        if own:
            steps.close()


def missing_shapes_summary(name: str, model: dict, geometry: str) -> str:
    """One line for the terminal: how many shapes the report left out and why (the extra to install
    when the reason is a missing mesh reader, else the first reason)."""
    missing = model["missing"]
    head = f"the report draws {model['shapes_drawn']} of the {model['shapes']} {geometry} shapes of robot '{name}'"
    if any("needs trimesh" in m for m in missing):
        return f"{head}: reading mesh files needs the viz extra (pip install 'kinedyn[viz]'); the links are drawn as a stick figure"
    more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
    return f"{head}: {missing[0]}{more}"


def _render(robot, d: ReportData, tutorial: bool, steps, geometry: str) -> str:
    steps.step("3-D view and tables")
    q = np.asarray(d["q"])
    multi = robot.has_multi_dof_joints
    q_labels = d["coordinate_labels"] or coordinate_labels(robot)
    v_labels = d["velocity_labels"] or velocity_labels(robot)
    model = view_model(robot, q, geometry=geometry)
    if model["generated"]:
        looks = "No visual geometry is described, so the links are drawn as solids along the kinematics (joints orange when revolute, violet when prismatic)."
    else:
        looks = f"{model['shapes_drawn']} of the {model['shapes']} {geometry} shapes of the description are drawn."
        if model["missing"]:  # said where the user looks first (the terminal): kinedyn.visual.scene's reasons
            warnings.warn(missing_shapes_summary(robot.name, model, geometry), MissingMeshWarning, stacklevel=3)
    joint_headers, joint_rows = _joint_table(d, multi)

    steps.step("equations (MathML)")
    equations = _equations(d.eom) if d.eom is not None else None

    s = d["simulation"]
    t = np.asarray(s["t"])
    plots = motion_plots(robot, t, np.asarray(s["q"]), q_labels)
    plots.append(
        svg_plot(
            t, [("kinetic K", s["K"]), ("potential P", s["P"]), ("total H", s["H"])], "energy", "t [s]", "energy [J]"
        )
    )

    tutorial_html = ""
    if tutorial:
        answers = []
        for question in QUESTIONS:
            steps.step(f"tutorial {question}")
            answers.append(answer(question))
        tutorial_html = render_html(answers)

    return TEMPLATES.get_template("report.html.j2").render(
        d=d,
        multi=multi,
        version=__version__,
        css=Markup(asset("page.css")),
        viewer_js=Markup(asset("viewer.js")),
        plotly=Markup(plotly_script()),
        model_json=Markup(json_script(model, "kinedyn-model")),
        data_json=Markup(json_script(jsonable(d.to_dict()), "kinedyn-data")),
        model=model,
        looks=looks,
        q_text=q_text(q, q_labels, coordinate_units(robot), in_multi_dof_block(robot)),
        v_labels=v_labels,
        joint_headers=joint_headers,
        joint_rows=joint_rows,
        dh_rows=_dh_rows(d),
        mass_rows=[[b["link"], fmt(b["mass"]), " ".join(fmt(c) for c in b["com"])] for b in d["bodies"]],
        audit_rows=[
            [f["severity"], f["line"] or "", f["element"], f["message"], f["fix"]]
            for f in (d.audit or {}).get("findings", [])
        ],
        sigma_names=[f"σ{k + 1}" for k in range(len(d["singular_values"]))],
        configuration_rows=_configuration_rows(q, d) if multi else None,
        rotations=[j["name"] for j in d["joints"] if j["type"] in ("floating", "spherical", "planar")],
        equations=equations,
        property_rows=_property_rows(d),
        plots=[Markup(p) for p in plots],
        floating=any(j.kind == "floating" for j in robot.joints),
        tutorial_html=Markup(tutorial_html),
    )


def write_report(robot, path="report.html", q=None, qd=None, **kwargs) -> Path:
    """Write the report to ``path``; returns the path."""
    path = Path(path)
    write_text(path, build_report(robot, q, qd, **kwargs))  # atomic (kinedyn._ui.files)
    return path
