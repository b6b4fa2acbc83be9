"""The identification report: one self-contained HTML page about an identification from a log
(``kinedyn identify ROBOT --data log.csv -o report.html``, :func:`identification_html`).

Sections: what was fitted (the log, its filtering, the estimator, cond(W)); the base parameters with
their standard deviations and relative standard deviations (and the errors when the true values are
known, for simulated data); the friction coefficients per joint; the armature of each geared joint,
or the base parameters it is grouped into; the per-joint noise and residual RMS; measured against
predicted torque and the residual per joint, on the fitted log and on the validation log (RMS and
R² per joint) when one is given; for a physically consistent fit, the smallest eigenvalue of
M(q) over the log's states for the consistent and the unconstrained estimates; and for IDIM-IV or
DIDIM, the iterations (how many, converged or not, what had to change) and each base parameter
beside its OLS and WLS estimates.

It shares the robot report's style, tables and templates (templates/identification.html.j2); the plots are
drawn by plotly.js inlined from the plotly package (assets/identification.js), from the JSON block ``#kinedyn-identification``
which holds every number shown (nothing is fetched).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from markupsafe import Markup

from .._ui.files import write_text
from .._ui.json import jsonable
from .._version import __version__
from ..visual.page import asset, json_script
from ..visual.web import plotly_script
from .page import TEMPLATES, report_asset
from .tables import fmt

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

#: the estimators as a sentence names them
METHOD_NAMES = {
    "ols": "ordinary least squares",
    "wls": "weighted least squares",
    "irls": "iteratively reweighted least squares (Huber)",
    "iv": "instrumental variables (IDIM-IV)",
    "didim": "closed-loop output error (DIDIM)",
}

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
    d["friction_terms"] = list(result.friction.columns())
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


def _fit_lines(d: dict) -> list[str]:
    """What was fitted, one line each: the estimator and cond(W), consistency, the log and its filtering."""
    log = d.get("log")
    how = METHOD_NAMES.get(d.get("method", ""), "weighted least squares" if d["weighted"] else "ordinary least squares")
    lines = [
        f"{len(d['names'])} base parameters and {len(d.get('friction_names', []))} friction coefficients by {how}",
        f"cond(W) = {fmt(d['condition_number'], 4)}",
    ]
    if d.get("delay"):
        lines.append(f"torques {fmt(1e3 * d['delay'], 4)} ms behind the positions (aligned before the fit)")
    lines.extend(d.get("notes", []))
    for group in d.get("identifiability", {}).get("unseparable", []):
        lines.append(f"not separable by the data (only a combination is identified): {', '.join(group)}")
    if d.get("consistent"):
        lines.append("physically consistent: every body's pseudo-inertia positive definite (an SDP through cvxpy)")
    if log is not None:
        filt = (
            f", low-pass cut-off {fmt(log['cutoff_hz'], 3)} Hz, decimated by {log['decimation']} to {fmt(log['rate_hz'], 4)} Hz"
            if log.get("cutoff_hz")
            else ""
        )
        lines.append(f"{log['samples']} samples of {log['source']}{filt}")
    return lines


def _parameters(d: dict) -> tuple[list[str], list[list[str]]]:
    """The base parameters with std and std %, and the errors where the true values are known."""
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
    return headers, rows


def _friction(d: dict) -> tuple[list[str], list[list[str]] | None]:
    """Per joint, each estimated friction term as estimate ± std; None where no term was estimated."""
    terms = d["friction_terms"]
    if not terms:
        return [], None
    by_joint: dict = {}
    for name, est, sd in zip(d["friction_names"], d["friction_estimates"], d["friction_std"]):
        by_joint.setdefault(_joint_of(name), {})[name.split(".", 1)[1]] = (est, sd)
    rows = [
        [d["joint_names"][j], *(f"{fmt(by_joint[j][t][0], 5)} ± {fmt(by_joint[j][t][1], 2)}" for t in terms)]
        for j in sorted(by_joint)
    ]
    units = {
        "viscous": "viscous [N m s/rad]",
        "coulomb": "Coulomb [N m]",
        "coulomb+": "Coulomb, qd > 0 [N m]",
        "coulomb-": "Coulomb, qd < 0 [N m]",
        "stribeck": "static - Coulomb [N m]",
        "offset": "offset [N m]",
    }
    return ["joint", *(units[t] for t in terms)], rows


def _rotor_rows(d: dict) -> list[list[str]]:
    """Per geared joint: its gear ratio, the model's armature and the identified one (or its group)."""
    rows = []
    for r in d["rotors"]:
        head = [r["joint"], fmt(r["gear_ratio"], 5), fmt(r["nominal_armature"], 4)]
        if r["armature"] is None:
            rows.append([*head, "grouped into " + ", ".join(r["grouped_into"]), "–"])
        else:
            rows.append([*head, f"{fmt(r['armature'], 5)} ± {fmt(r['std'], 2)}", fmt(r["rotor_inertia"], 4)])
    return rows


def _closed_loop(d: dict) -> tuple[list[str], list[list[str]]] | None:
    """IV / DIDIM: how the iterations went (one line each), and each base parameter by OLS, by the
    weighted least squares the iterations started from, and by the closed-loop estimator, with the
    change from OLS in the estimator's own standard deviations (closed-loop data bias OLS: a change
    of many std is that bias removed, or the instruments' trouble, which the notes name)."""
    loop = d.get("closed_loop")
    if loop is None:
        return None
    how = METHOD_NAMES[d["method"]]
    its = d.get("iterations", 0)
    state = (
        f"converged: the last iteration moved the estimate by {fmt(100 * loop['last_change'], 3)} % "
        f"(tolerance {fmt(100 * loop['tolerance'], 3)} %)"
        if loop["converged"]
        else f"not converged: the last iteration still moved the estimate by {fmt(100 * loop['last_change'], 3)} % "
        f"(tolerance {fmt(100 * loop['tolerance'], 3)} %)"
    )
    lines = [
        f"{how}: {its} simulation{'s' if its != 1 else ''} of the identified model under the experiment's controller, "
        "started from weighted least squares",
        state,
        *d.get("notes", []),
    ]
    rows = []
    for k, nm in enumerate(d["names"]):
        est, ols, std = d["estimates"][k], loop["ols"][k], d["std"][k]
        rows.append(
            [
                nm,
                fmt(ols, 6),
                fmt(loop["start"][k], 6),
                fmt(est, 6),
                fmt(est - ols, 3),
                fmt((est - ols) / std, 3) if std and np.isfinite(std) else "-",
            ]
        )
    return lines, rows


def _mass_check_rows(d: dict) -> list[list[str]] | None:
    """The smallest eigenvalue of M(q) over the log for the consistent and the unconstrained estimates."""
    mc = d.get("mass_matrix_check")
    if mc is None:
        return None
    rows = [
        ["consistent", fmt(mc["consistent_min_eigenvalue"], 4), "yes" if mc["consistent_min_eigenvalue"] > 0 else "no"]
    ]
    if "unconstrained_min_eigenvalue" in mc:
        bad = mc["unconstrained_indefinite_states"]
        rows.append(
            ["unconstrained", fmt(mc["unconstrained_min_eigenvalue"], 4), "yes" if bad == 0 else f"no, at {bad} states"]
        )
    return rows


_EXTRA_CSS = ".id-plot { width: 100%; min-height: 320px; } section ul { margin: 0.3em 0 0.6em 1.2em; }"


def identification_report(result: Identification, validate=None, *, title: str | None = None, **load_options) -> str:
    """The report as one HTML string (see the module docstring)."""
    d = identification_data(result, validate, **load_options)
    parameter_headers, parameter_rows = _parameters(d)
    friction_headers, friction_rows = _friction(d)
    return TEMPLATES.get_template("identification.html.j2").render(
        d=d,
        title=title or f"kinedyn identification: {d['robot']}",
        version=__version__,
        css=Markup(asset("page.css")),
        extra_css=Markup(_EXTRA_CSS),
        fit_lines=_fit_lines(d),
        parameter_headers=parameter_headers,
        parameter_rows=parameter_rows,
        friction_headers=friction_headers,
        friction_rows=friction_rows,
        rotor_rows=_rotor_rows(d),
        mass_check_rows=_mass_check_rows(d),
        closed_loop=_closed_loop(d),
        method_label=d["method"].upper(),
        torque_sections=[
            (k, t)
            for k, t in (("fit", "Torques on the fitted log"), ("validation", "Validation on another log"))
            if d.get(k) is not None
        ],
        data_json=Markup(json_script(d, "kinedyn-identification")),
        plotly=Markup(plotly_script()),
        plots_js=Markup(report_asset("identification.js")),
    )


def write_identification_report(
    result: Identification, path="identification.html", validate=None, **load_options
) -> Path:
    """Write :func:`identification_report` to ``path``; returns the path."""
    path = Path(path)
    write_text(path, identification_report(result, validate, **load_options))  # atomic (kinedyn._ui.files)
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
