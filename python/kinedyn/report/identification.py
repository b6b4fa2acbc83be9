"""The identification report: one self-contained HTML page about an identification from a log
(``kinedyn identify ROBOT --data log.csv -o report.html``, :func:`identification_html`).

Sections: what was fitted (the log, its filtering, the estimator, cond(W)); the base parameters with
their standard deviations and relative standard deviations (and the errors when the true values are
known, for simulated data); the friction coefficients per joint; the armature of each geared joint,
or the base parameters it is grouped into; the per-joint noise and residual RMS; measured against
predicted torque and the residual per joint, on the fitted log and on the validation log (RMS and
R² per joint) when one is given; and, for a physically consistent fit, the smallest eigenvalue of
M(q) over the log's states for the consistent and the unconstrained estimates.

It shares the robot report's style and tables (:mod:`kinedyn.report.tables`); the plots are
drawn by plotly.js inlined from the plotly package, from the JSON block ``#kinedyn-identification``
which holds every number shown (nothing is fetched).
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .. import __version__
from .._ui.json import jsonable
from ..visual.web import plotly_script
from .tables import fmt, table
from .view import asset, json_script

if TYPE_CHECKING:
    from ..analysis.identification import Identification, Validation

__all__ = [
    "identification_html",
    "write_identification_html",
    "identification_data",
    "identification_report",
    "write_identification_report",
    "PLOT_POINTS",
]

#: at most this many samples of each log are plotted (evenly spaced; the tables use them all)
PLOT_POINTS = 1500

#: states of the log at which the mass matrices are checked (evenly spaced)
CHECK_STATES = 200


def _plot_data(check: Validation) -> dict:
    S = len(check.t)
    index = np.unique(np.linspace(0, S - 1, min(S, PLOT_POINTS)).round().astype(int))
    return {
        "source": check.source,
        "samples": int(S),
        "index": index.tolist(),
        "t": check.t[index].tolist(),
        "measured": check.measured[index].T.tolist(),
        "predicted": check.predicted[index].T.tolist(),
        "residual": check.residuals[index].T.tolist(),
        "rms": check.rms.tolist(),
        "r2": check.r2.tolist(),
    }


def _min_eigenvalues(result: Identification, q: np.ndarray) -> np.ndarray:
    return np.linalg.eigvalsh(result.mass_matrix(q)).min(axis=-1)


def identification_data(result: Identification, validate=None, **load_options) -> dict:
    """Every number of the report (JSON-friendly): the result's own (``to_dict``), the fit's and the
    validation's torques at the plotted samples, and the mass-matrix check of a consistent fit.
    ``validate``: a second log (anything :meth:`Identification.validate` takes)."""
    robot = result.nominal
    data = result.data
    d: dict = {"robot": robot.name, "joint_names": list(robot.joint_names), **jsonable(result.to_dict())}
    d["relative_std_percent"] = jsonable(result.relative_std)
    d["friction_terms"] = list(result.friction.terms)
    d["friction_known"] = bool(result.friction.known)
    d["rotors"] = [r.to_dict() for r in result.rotors]
    if data is not None:
        d["log"] = {
            "source": getattr(data, "source", "<data>"),
            "samples": int(len(data.t)),
            "rate_hz": getattr(data, "rate", None),
            "cutoff_hz": getattr(data, "cutoff", None),
            "decimation": getattr(data, "decimation", None),
        }
        d["fit"] = _plot_data(result.validate(data))
    if validate is not None:
        d["validation"] = _plot_data(result.validate(validate, **load_options))
    if result.consistent and data is not None:
        q = np.asarray(data.q)
        states = q[np.unique(np.linspace(0, len(q) - 1, min(len(q), CHECK_STATES)).round().astype(int))]
        check = {"states": int(len(states)), "consistent_min_eigenvalue": float(_min_eigenvalues(result, states).min())}
        if result.unconstrained is not None:
            eig = _min_eigenvalues(result.unconstrained, states)
            check.update(
                unconstrained_min_eigenvalue=float(eig.min()), unconstrained_indefinite_states=int(np.sum(eig <= 0))
            )
        d["mass_matrix_check"] = check
    return jsonable(d)


def _joint_of(name: str) -> int:
    return int(name.split(".")[0][len("joint") :]) - 1


def _sections(d: dict) -> list[str]:
    joints = d["joint_names"]
    out: list[str] = []
    # --- the fit
    log = d.get("log")
    how = "weighted" if d["weighted"] else "ordinary"
    lines = [
        f"{len(d['names'])} base parameters and {len(d.get('friction_names', []))} friction coefficients by {how} least squares",
        f"cond(W) = {fmt(d['condition_number'], 4)}",
    ]
    if d.get("consistent"):
        lines.append("physically consistent: every body's pseudo-inertia positive definite (an SDP through cvxpy)")
    if log is not None:
        filt = (
            f", low-pass cut-off {fmt(log['cutoff_hz'], 3)} Hz, decimated by {log['decimation']} to {fmt(log['rate_hz'], 4)} Hz"
            if log.get("cutoff_hz")
            else ""
        )
        lines.append(f"{log['samples']} samples of {html.escape(str(log['source']))}{filt}")
    sec = ["<section id='fit'><h2>The fit</h2><ul>", *(f"<li>{line}</li>" for line in lines), "</ul>"]
    if d.get("noise") is not None:
        sec.append(
            table(
                ["", *joints],
                [
                    ["noise σ (from the residuals)", *(fmt(v, 4) for v in d["noise"])],
                    ["residual RMS", *(fmt(v, 4) for v in d["residual_rms"])],
                ],
                cls="noise",
            )
        )
    if d.get("dropped"):
        sec.append(
            f"<p class='bad'>Not excited by the data (regressor columns at round-off level), left out: {html.escape(', '.join(d['dropped']))}.</p>"
        )
    sec.append("</section>")
    out.append("".join(sec))

    # --- parameters
    true = d.get("true_values")
    headers = ["base parameter", "estimate", "std", "std %"] + (
        ["true", "error", "error %"] if true is not None else []
    )
    rows = []
    for k, name in enumerate(d["names"]):
        row = [name, fmt(d["estimates"][k]), fmt(d["std"][k], 3), fmt(d["relative_std_percent"][k], 3)]
        if true is not None:
            err = d["estimates"][k] - true[k]
            row += [fmt(true[k]), fmt(err, 3), fmt(100 * abs(err) / max(abs(true[k]), 1e-300), 3)]
        rows.append(row)
    note = (
        "<p class='note'>std: from the covariance σ² (WᵀW)⁻¹ of the least-squares fit; std %: 100 std / |estimate| "
        "(above ~10 % the data do not identify the parameter well).</p>"
    )
    out.append(
        "<section id='parameters'><h2>Base parameters</h2>"
        + note
        + table(headers, rows, cls="parameters")
        + "</section>"
    )

    # --- friction and rotors
    sec = ["<section id='drives'><h2>Friction and rotor inertia</h2>"]
    terms = d["friction_terms"]
    if terms:
        frows = []
        by_joint: dict = {}
        for name, est, sd in zip(d["friction_names"], d["friction_estimates"], d["friction_std"]):
            by_joint.setdefault(_joint_of(name), {})[name.split(".", 1)[1]] = (est, sd)
        for j in sorted(by_joint):
            frows.append([joints[j], *(f"{fmt(by_joint[j][t][0], 5)} ± {fmt(by_joint[j][t][1], 2)}" for t in terms)])
        units = {"viscous": "viscous [N m s/rad]", "coulomb": "Coulomb [N m]", "offset": "offset [N m]"}
        sec.append(table(["joint", *(units[t] for t in terms)], frows, cls="friction"))
    elif d["friction_known"]:
        sec.append("<p class='note'>Friction taken from the model (subtracted, not estimated).</p>")
    else:
        sec.append("<p class='note'>No friction estimated (friction='none').</p>")
    if d["rotors"]:
        rrows = []
        for r in d["rotors"]:
            if r["armature"] is None:
                rrows.append(
                    [
                        r["joint"],
                        fmt(r["gear_ratio"], 5),
                        fmt(r["nominal_armature"], 4),
                        "grouped into " + ", ".join(r["grouped_into"]),
                        "–",
                    ]
                )
            else:
                rrows.append(
                    [
                        r["joint"],
                        fmt(r["gear_ratio"], 5),
                        fmt(r["nominal_armature"], 4),
                        f"{fmt(r['armature'], 5)} ± {fmt(r['std'], 2)}",
                        fmt(r["rotor_inertia"], 4),
                    ]
                )
        sec.append("<h3>Armature r² J_m of the geared joints</h3>")
        sec.append(
            table(
                ["joint", "gear ratio r", "model r² J_m [kg m²]", "identified r² J_m", "J_m = a / r² [kg m²]"],
                rrows,
                cls="rotors",
            )
        )
        sec.append(
            "<p class='note'>A grouped armature only acts together with the link parameters named: the data cannot "
            "separate it, so it has no estimate of its own (the group's estimate is in the table above).</p>"
        )
    else:
        sec.append(
            "<p class='note'>No joint of the model has a gear ratio or a rotor inertia: no armature estimated.</p>"
        )
    sec.append("</section>")
    out.append("".join(sec))

    # --- consistency check
    mc = d.get("mass_matrix_check")
    if mc is not None:
        crow = [
            [
                "consistent",
                fmt(mc["consistent_min_eigenvalue"], 4),
                "yes" if mc["consistent_min_eigenvalue"] > 0 else "no",
            ]
        ]
        if "unconstrained_min_eigenvalue" in mc:
            crow.append(
                [
                    "unconstrained",
                    fmt(mc["unconstrained_min_eigenvalue"], 4),
                    "yes"
                    if mc["unconstrained_indefinite_states"] == 0
                    else f"no, at {mc['unconstrained_indefinite_states']} states",
                ]
            )
        out.append(
            f"<section id='consistency'><h2>Mass matrix over the log</h2><p class='note'>The smallest eigenvalue of M(q) of each estimate "
            f"at {mc['states']} states of the log: only a positive-definite M can be simulated.</p>"
            + table(
                ["estimate", "min eigenvalue of M [kg m²]", "positive definite at every state"], crow, cls="mass-check"
            )
            + "</section>"
        )

    # --- torques
    for key, title in (("fit", "Torques on the fitted log"), ("validation", "Validation on another log")):
        p = d.get(key)
        if p is None:
            continue
        sec = [
            f"<section id='{key}-torques'><h2>{title}</h2>",
            f"<p class='note'>{html.escape(str(p['source']))}: {p['samples']} samples"
            + (f", {len(p['index'])} of them plotted" if len(p["index"]) < p["samples"] else "")
            + ".</p>",
            table(
                ["", *joints],
                [["torque RMS error", *(fmt(v, 4) for v in p["rms"])], ["R²", *(fmt(v, 7) for v in p["r2"])]],
                cls="scores",
            ),
        ]
        sec += [
            f"<div class='id-plot' id='{key}-joint{j + 1}' role='img' aria-label='{html.escape(joints[j])}: measured and predicted torque'></div>"
            for j in range(len(joints))
        ]
        sec.append("</section>")
        out.append("".join(sec))
    return out


_PLOTS_JS = """
(function () {
  const d = JSON.parse(document.getElementById("kinedyn-identification").textContent);
  if (!window.Plotly) return;
  for (const key of ["fit", "validation"]) {
    const p = d[key];
    if (!p) continue;
    d.joint_names.forEach((name, j) => {
      const el = document.getElementById(key + "-joint" + (j + 1));
      const traces = [
        {x: p.t, y: p.measured[j], name: "measured", mode: "lines", line: {width: 1.2, color: "#1f77b4"}},
        {x: p.t, y: p.predicted[j], name: "predicted", mode: "lines", line: {width: 1.2, dash: "dash", color: "#ff7f0e"}},
        {x: p.t, y: p.residual[j], name: "residual", mode: "lines", yaxis: "y2", line: {width: 1, color: "#d62728"}},
      ];
      const layout = {
        title: {text: name + ": RMS " + p.rms[j].toPrecision(3) + ", R² " + p.r2[j].toFixed(6), font: {size: 13}, y: 0.98},
        margin: {l: 60, r: 10, t: 50, b: 40}, height: 320, autosize: true,
        legend: {orientation: "h", x: 0, y: 1.0, yanchor: "bottom", font: {size: 11}},
        xaxis: {title: {text: "t [s]"}, anchor: "y2"}, yaxis: {title: {text: "τ [N m]"}, domain: [0.36, 1], anchor: "x"},
        yaxis2: {title: {text: "residual"}, domain: [0, 0.27], anchor: "x"},
      };
      window.Plotly.newPlot(el, traces, layout, {responsive: true, displaylogo: false});
    });
  }
})();
"""

_EXTRA_CSS = ".id-plot { width: 100%; min-height: 320px; } section ul { margin: 0.3em 0 0.6em 1.2em; }"


def identification_report(result: Identification, validate=None, *, title: str | None = None, **load_options) -> str:
    """The report as one HTML string (see the module docstring)."""
    d = identification_data(result, validate, **load_options)
    title = title or f"kinedyn identification: {d['robot']}"
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{html.escape(title)}</title>
<style>{asset("report.css")}{_EXTRA_CSS}</style></head>
<body><header><h1>Identification of {html.escape(d["robot"])}</h1><p>{len(d["joint_names"])} joints · kinedyn {html.escape(__version__)}</p></header>
<main>{"".join(_sections(d))}</main>
<footer>Generated by <code>kinedyn identify --data ... -o</code>. Self-contained: no network access, every script and style is in this file.</footer>
{json_script(d, "kinedyn-identification")}
{plotly_script()}
<script>{_PLOTS_JS}</script>
</body></html>
"""


def write_identification_report(
    result: Identification, path="identification.html", validate=None, **load_options
) -> Path:
    """Write :func:`identification_report` to ``path``; returns the path."""
    path = Path(path)
    path.write_text(identification_report(result, validate, **load_options), encoding="utf-8")
    return path


def identification_html(result: Identification, validate=None, **load_options) -> str:
    """The identification report of ``result`` (a :class:`kinedyn.analysis.Identification`) as one
    self-contained HTML string; ``validate``: a second log to check the fit on (anything
    :meth:`Identification.validate` takes, with its ``load_options``)."""
    return identification_report(result, validate, **load_options)


def write_identification_html(
    result: Identification, path="identification.html", validate=None, **load_options
) -> Path:
    """Write :func:`identification_html` to ``path``; returns the path."""
    return write_identification_report(result, path, validate, **load_options)
