"""Rich display in Jupyter (IPython's ``_repr_html_`` / ``_repr_latex_`` / ``_repr_markdown_`` protocol).

The classes keep one-line ``_repr_*_`` methods that call these functions, so that a notebook shows:

- a :class:`kinedyn.Robot` as its joint table, total mass, gravity, tool frame and a small stick-figure
  drawing (inline SVG: no script, nothing fetched);
- :class:`kinedyn.symbolic.EquationsOfMotion` and each of its :class:`~kinedyn.symbolic.eom.Step`
  objects as typeset equations (MathML in HTML; LaTeX and Markdown through the symbolic engine's own
  printers ``to_latex`` / ``to_markdown`` / ``equation_mathml``, so velocities print as q̇, not qd);
- an :class:`~kinedyn.ik.solve.IKResult` as its table of solutions with their residuals;
- a :class:`~kinedyn.simulate.trajectory.Trajectory` as a plot of q(t) (inline SVG);
- a :class:`~kinedyn.analysis.properties.PropertiesReport` and an
  :class:`~kinedyn.analysis.identification.Identification` as tables.

Every number is printed with 6 significant digits (``_num``), the same as ``kinedyn``'s terminal tables.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence

import numpy as np

from ._ui.svg import svg_plot
from .configuration import default_configuration

__all__ = [
    "robot_html",
    "robot_markdown",
    "stick_figure_svg",
    "eom_html",
    "eom_latex",
    "eom_markdown",
    "step_html",
    "step_latex",
    "step_markdown",
    "ik_html",
    "ik_markdown",
    "trajectory_html",
    "properties_html",
    "identification_html",
]

_BOX = "font-family: system-ui, sans-serif; font-size: 13px; max-width: 100%; overflow-x: auto"
_MONO = "font-family: ui-monospace, 'DejaVu Sans Mono', monospace; text-align: right"


def _num(v, digits: int = 6) -> str:
    """A number with ``digits`` significant digits (a SymPy expression as its text)."""
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "∞" if x > 0 else "-∞"
    return f"{x:.{digits}g}"


def _table(
    headers: Sequence[str],
    rows: Iterable[Sequence],
    numeric_from: int = 1,
    cls: str = "",
    numeric_to: int | None = None,
) -> str:
    """An HTML table; columns ``numeric_from`` up to (not including) ``numeric_to`` hold numbers."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = []
    for row in rows:
        stop = len(row) if numeric_to is None else numeric_to
        cells = [
            f'<td style="{_MONO}">{html.escape(str(c))}</td>'
            if numeric_from <= k < stop
            else f"<td>{html.escape(str(c))}</td>"
            for k, c in enumerate(row)
        ]
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f'<table class="{cls}"><thead><tr>{head}</tr></thead><tbody>{"".join(body)}</tbody></table>'


def _md_table(headers: Sequence[str], rows: Iterable[Sequence]) -> str:
    esc = lambda s: str(s).replace("|", "\\|")
    out = ["| " + " | ".join(esc(h) for h in headers) + " |", "|" + "---|" * len(headers)]
    out += ["| " + " | ".join(esc(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def _box(cls: str, content: str) -> str:
    return f'<div class="kinedyn {cls}" style="{_BOX}">{content}</div>'


# ------------------------------------------------------------------ Robot
def _joint_rows(robot) -> list[list]:
    rows = []
    for j in robot.joints:
        unit = "rad" if j.kind == "revolute" else "m"
        limits = f"[{_num(j.lower, 5)}, {_num(j.upper, 5)}] {unit}"
        rows.append([j.name, j.kind, " ".join(_num(a, 4) for a in j.axis), limits])
    return rows


def _total_mass(robot) -> str:
    masses = [b.inertia.mass for b in robot.tree.bodies]
    try:
        return f"{_num(sum(float(m) for m in masses))} kg"
    except (TypeError, ValueError):  # symbolic masses
        return f"{sum(masses)} kg"


def _gravity(robot) -> str:
    return "(" + ", ".join(_num(g) for g in robot.gravity) + ") m/s²"


def stick_figure_svg(robot, q=None, size: int = 220) -> str | None:
    """The robot at ``q`` (default: the report's generic configuration) as a small inline SVG drawing: a line
    from each link frame to its parent's and to each extra frame, seen from the front-right and above
    the base (up = against gravity), the tool frame in red. None for a robot whose geometry is symbolic."""
    try:
        if q is None:  # the report's generic pose (0.5, -0.7, ... rad): the structure shows, unlike at a singular q = 0
            q = default_configuration(robot)
        q = np.asarray(q, dtype=float)
        poses = np.asarray(robot.frame_poses(q), dtype=float)
    except (TypeError, ValueError, AttributeError):
        return None
    names = robot.frame_names
    at = {name: poses[k, :3, 3] for k, name in enumerate(names)}
    edges = [(link.parent or robot.base, link.name) for link in robot.links] + [
        (f.link or robot.base, f.name) for f in robot.frames
    ]
    edges = [(a, b) for a, b in edges if a in at and b in at]
    g = np.asarray(robot.gravity, dtype=float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    side = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
    side /= np.linalg.norm(side)
    front = np.cross(side, up)
    towards = 0.8 * front - 0.6 * side + 0.45 * up  # the viewer's direction, from the robot
    towards /= np.linalg.norm(towards)
    right = np.cross(up, towards)
    right /= np.linalg.norm(right)
    screen_up = np.cross(towards, right)
    pts = np.array([[p @ right, p @ screen_up] for p in at.values()])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = max(float(np.max(hi - lo)), 1e-9)
    pad = 16
    scale = (size - 2 * pad) / span
    centre = (lo + hi) / 2

    def xy(p) -> tuple:
        u = np.array([p @ right, p @ screen_up]) - centre
        return size / 2 + scale * u[0], size / 2 - scale * u[1]

    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}" role="img" '
        f'aria-label="{html.escape(robot.name)} at q" style="background:#fafaf7;border:1px solid #ddd">'
    ]
    for a, b in edges:
        (x1, y1), (x2, y2) = xy(at[a]), xy(at[b])
        out.append(
            f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" stroke="#5f6b73" stroke-width="3" stroke-linecap="round"/>'
        )
    for name, p in at.items():
        x, y = xy(p)
        colour, r = (
            ("#d62728", 4.5) if name == robot.tool else (("#243238", 3.5) if name == robot.base else ("#ff7f0e", 2.5))
        )
        out.append(
            f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{r}" fill="{colour}"><title>{html.escape(name)}</title></circle>'
        )
    out.append("</svg>")
    return "".join(out)


def robot_html(robot) -> str:
    """A robot in a notebook: a summary line, its joint table and a stick figure beside it."""
    summary = (
        f"<b>{html.escape(robot.name)}</b>: {robot.n} joints, total moving mass {html.escape(_total_mass(robot))}, "
        f"gravity {html.escape(_gravity(robot))}, tool frame <code>{html.escape(robot.tool)}</code>"
    )
    if robot.source:
        summary += f"<br><small>{html.escape(str(robot.source))}</small>"
    table = _table(["joint", "type", "axis", "limits"], _joint_rows(robot), numeric_from=2, cls="kinedyn-joints")
    if robot.n > 12:  # a humanoid's joint table scrolls inside its box
        table = f'<div style="max-height: 24em; overflow-y: auto">{table}</div>'
    picture = stick_figure_svg(robot)
    figure = f'<div style="flex: 0 0 auto">{picture}</div>' if picture else ""
    return _box(
        "kinedyn-robot",
        f"<p>{summary}</p><div style='display: flex; gap: 16px; align-items: flex-start; flex-wrap: wrap'>"
        f"<div style='flex: 1 1 auto; min-width: 0; overflow-x: auto'>{table}</div>{figure}</div>",
    )


def robot_markdown(robot) -> str:
    return (
        f"**{robot.name}**: {robot.n} joints, total moving mass {_total_mass(robot)}, gravity {_gravity(robot)}, "
        f"tool frame `{robot.tool}`\n\n" + _md_table(["joint", "type", "axis", "limits"], _joint_rows(robot))
    )


# ------------------------------------------------------------------ equations of motion
def _eq_box(math_element: str) -> str:
    return f'<div style="overflow-x: auto; max-width: 100%">{math_element}</div>'


def eom_html(eom) -> str:
    """The result M, C, g, tau typeset (MathML), and every step of the derivation under a fold."""
    head = (
        f"<p><b>Equations of motion{' of ' + html.escape(eom.name) if eom.name else ''}</b> ({html.escape(str(eom.method))}): "
        "M(q) q̈ + C(q, q̇) q̇ + g(q) = τ</p>"
    )
    result = "".join(_eq_box(eom.equation_mathml(lhs, value)) for lhs, value in eom.result_equations())
    steps = eom.steps
    folded = ""
    if steps:
        inner = "".join(
            step_html(step, k, mathml=[eom.equation_mathml(lhs, value) for lhs, value in step.equations])
            for k, step in enumerate(steps, start=1)
        )
        folded = f"<details><summary>{len(steps)} steps of the derivation</summary>{inner}</details>"
    return _box("kinedyn-eom", head + result + folded)


def eom_latex(eom) -> str:
    """The result as a LaTeX ``align*`` block (the symbolic engine's ``to_latex``, without the steps)."""
    return eom.to_latex(steps=False)


def eom_markdown(eom) -> str:
    return eom.to_markdown()


def step_html(step, number: int | None = None, mathml: Sequence[str] = ()) -> str:
    """A step of a derivation: its title, sentence and equations; ``mathml`` holds one rendered
    ``<math>`` element per equation (the symbolic engine renders them, so that q̇ prints with its dot)."""
    title = f"Step {number}: {step.title}" if number else step.title
    parts = [f"<p><b>{html.escape(title)}</b></p>"]
    if step.text:
        parts.append(f"<p>{html.escape(step.text)}</p>")
    parts += [_eq_box(element) for element in mathml]
    return "".join(parts) if number else _box("kinedyn-step", "".join(parts))


def step_latex(step, names: dict | None = None) -> str:
    """A step as display LaTeX; ``names``: LaTeX names of symbols (q̇ as ``\\dot{q}``)."""
    return "$$\\begin{gathered}" + step.to_latex(names) + "\\end{gathered}$$"


def step_markdown(step, names: dict | None = None) -> str:
    import sympy as sp  # only a step of symbolic equations comes here; sympy is already loaded then

    out = [f"**{step.title}**", ""]
    if step.text:
        out += [step.text, ""]
    for lhs, value in step.equations:
        out += ["$$", f"{lhs} = {sp.latex(value, symbol_names=names or {})}", "$$", ""]
    return "\n".join(out)


# ------------------------------------------------------------------ inverse kinematics
def _ik_rows(result) -> tuple:
    n = result.solutions.shape[1] if result.solutions.ndim == 2 else 0
    headers = ["#", *[f"q{k + 1}" for k in range(n)], "|dp| [m]", "|dR| [rad]"]
    rows = [
        [str(i + 1), *(_num(v) for v in q), _num(result.position_error[i], 3), _num(result.orientation_error[i], 3)]
        for i, q in enumerate(result.solutions)
    ]
    return headers, rows


def _ik_summary(result) -> str:
    verdict = "success" if result.success else "no solution within tolerance"
    extra = []
    if result.reachable is False:
        extra.append("out of reach")
    if result.singular:
        extra.append("on a singularity")
    if result.message and not result.success:
        extra.append(result.message)
    return f"{len(result.solutions)} solution(s), {verdict}; solver {result.solver}" + (
        "; " + "; ".join(extra) if extra else ""
    )


def ik_html(result) -> str:
    headers, rows = _ik_rows(result)
    table = _table(headers, rows, cls="kinedyn-ik") if rows else ""
    return _box("kinedyn-ik", f"<p><b>IKResult</b>: {html.escape(_ik_summary(result))} (nearest q0 first)</p>{table}")


def ik_markdown(result) -> str:
    headers, rows = _ik_rows(result)
    return f"**IKResult**: {_ik_summary(result)} (nearest q0 first)\n\n" + (_md_table(headers, rows) if rows else "")


# ------------------------------------------------------------------ simulation
def trajectory_html(traj) -> str:
    """q(t) as an inline SVG plot (the first trajectory of a batch), with a summary line."""
    q = traj.q[0] if traj.batch is not None else traj.q
    names = traj.names
    batch = f", batch of {traj.batch} (the first is plotted)" if traj.batch is not None else ""
    head = (
        f"<p><b>Trajectory</b> of {html.escape(str(getattr(traj.system, 'name', '?')))}: {len(traj)} samples, "
        f"t = {_num(traj.t[0])} … {_num(traj.t[-1])} s, method {html.escape(str(traj.method))}{html.escape(batch)}</p>"
    )
    if len(traj) < 2:
        return _box("kinedyn-trajectory", head)
    every = max(1, math.ceil(len(traj) / 400))  # at most ~400 points a line: a light notebook
    keep = (
        np.r_[np.arange(0, len(traj), every), len(traj) - 1]
        if (len(traj) - 1) % every
        else np.arange(0, len(traj), every)
    )
    plot = svg_plot(
        traj.t[keep], [(nm, q[keep, k]) for k, nm in enumerate(names)], "joint positions", "t [s]", "q [rad or m]"
    )
    return _box("kinedyn-trajectory", head + plot)


# ------------------------------------------------------------------ analysis
def properties_html(report) -> str:
    rows = [
        [c.name, _num(c.residual, 3), _num(c.tolerance, 3), "holds" if c.passed else "FAILS", c.detail]
        for c in report.checks
    ]
    verdict = "all hold" if report.passed else "some FAIL"
    return _box(
        "kinedyn-properties",
        f"<p><b>Properties of {html.escape(report.robot)}</b> over {report.samples} sampled states: {verdict}</p>"
        + _table(
            ["property", "residual", "tolerance", "", "measured"],
            rows,
            numeric_from=1,
            numeric_to=3,
            cls="kinedyn-properties",
        ),
    )


def identification_html(ident) -> str:
    headers = ["base parameter", "estimate", "std"]
    true = ident.true_values
    if true is not None:
        headers += ["true", "error"]
    rows = []
    for k, name in enumerate(ident.names):
        row = [name, _num(ident.estimates[k]), _num(ident.std[k], 3)]
        if true is not None:
            row += [_num(true[k]), _num(ident.estimates[k] - true[k], 3)]
        rows.append(row)
    kind = "weighted" if ident.weighted else "ordinary"
    head = (
        f"<p><b>Identification</b>: {len(ident.names)} base parameters by {kind} least squares, cond(W) = {_num(ident.condition_number, 4)}; "
        f"residual RMS per joint ({', '.join(_num(r, 3) for r in np.atleast_1d(ident.residual_rms))})</p>"
    )
    return _box("kinedyn-identification", head + _table(headers, rows, cls="kinedyn-identification"))
