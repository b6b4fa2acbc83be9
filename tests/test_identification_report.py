"""The identification report (issue 16 §2, §4: plots and a report section; ``kinedyn identify ROBOT
--data log.csv -o report.html``): written, parsed back with html5lib, its numbers those of the
result, and drawn by a headless Chromium without errors, inside its cards."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinedyn as kd
import kinedyn.analysis as an

html5lib = pytest.importorskip("html5lib")
XHTML = "{http://www.w3.org/1999/xhtml}"


def _log(true, seed):
    ref = an.excitation(true, harmonics=4, period=5.0, amplitude=1.0, seed=seed)
    t = np.arange(6000) / 1000.0  # 6 s at 1 kHz
    q, qd, qdd = ref(t)
    tau = true.inverse_dynamics(q, qd, qdd) + 0.3 * qd + 0.5 * np.sign(qd)
    tau += np.random.default_rng(seed).normal(scale=0.01, size=tau.shape)
    q = np.round(q / 1e-4) * 1e-4
    return {"t": t, "q1": q[:, 0], "q2": q[:, 1], "tau1": tau[:, 0], "tau2": tau[:, 1]}


def _write(path, cols):
    np.savetxt(path, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols), comments="")
    return path


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The CLI's report of a consistent fit with validation, and the same fit through the API."""
    from kinedyn.cli import main

    folder = tmp_path_factory.mktemp("idreport")
    true = kd.robots.planar_2r(m1=1.2, m2=0.9)
    fit_csv, other_csv = _write(folder / "log.csv", _log(true, 1)), _write(folder / "other.csv", _log(true, 2))
    out = folder / "identification.html"
    assert (
        main(
            [
                "identify",
                "planar_2r",
                "--data",
                str(fit_csv),
                "--validate",
                str(other_csv),
                "--consistent",
                "-o",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    result = an.identify(kd.robots.planar_2r(), str(fit_csv), consistent=True)
    return out, result, fit_csv, other_csv


def test_report_parses_and_holds_the_results_numbers(written):
    from kinedyn.visual.web import plotly_script

    out, result, fit_csv, other_csv = written
    page = out.read_text(encoding="utf-8")
    # plotly.js (MBs, the same in every report) is taken out before html5lib (pure Python) parses the page
    inlined = plotly_script()
    assert page.count(inlined) == 1
    doc = html5lib.parse(page.replace(inlined, '<script id="plotly-js"></script>'), namespaceHTMLElements=True)
    scripts = list(doc.iter(f"{XHTML}script"))
    assert [s.get("id") for s in scripts] == ["kinedyn-identification", "plotly-js", None]
    d = json.loads(scripts[0].text)
    np.testing.assert_allclose(d["estimates"], result.estimates, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(d["std"], result.std, rtol=1e-9)
    np.testing.assert_allclose(d["friction_estimates"], result.friction_estimates, rtol=1e-6, atol=1e-9)
    # the plotted torques: the log's measured ones and the model's prediction at the plotted samples
    for key, log in (("fit", an.load_log(fit_csv)), ("validation", an.load_log(other_csv))):
        check = result.validate(log)
        idx = np.asarray(d[key]["index"])
        assert d[key]["samples"] == len(log) and idx[0] == 0 and idx[-1] == len(log) - 1
        np.testing.assert_allclose(np.asarray(d[key]["t"]), log.t[idx])
        np.testing.assert_allclose(np.asarray(d[key]["measured"]).T, check.measured[idx], rtol=1e-12)
        np.testing.assert_allclose(np.asarray(d[key]["predicted"]).T, check.predicted[idx], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(np.asarray(d[key]["residual"]).T, check.residuals[idx], rtol=1e-5, atol=1e-8)
        np.testing.assert_allclose(d[key]["rms"], check.rms, rtol=1e-5)
        np.testing.assert_allclose(d[key]["r2"], check.r2, rtol=1e-9)
    mc = d["mass_matrix_check"]
    states = result.data.q[np.unique(np.linspace(0, len(result.data.q) - 1, mc["states"]).round().astype(int))]
    assert mc["consistent_min_eigenvalue"] == pytest.approx(
        np.linalg.eigvalsh(result.mass_matrix(states)).min(), rel=1e-6
    )
    assert mc["unconstrained_min_eigenvalue"] == pytest.approx(
        np.linalg.eigvalsh(result.unconstrained.mass_matrix(states)).min(), rel=1e-6
    )
    # the tables show the same
    tables = {t.get("class"): t for t in doc.iter(f"{XHTML}table")}
    cells = lambda cls, k: [
        "".join(tr.findall(f"{XHTML}td")[k].itertext())
        for tr in tables[cls].iter(f"{XHTML}tr")
        if tr.find(f"{XHTML}td") is not None
    ]
    assert cells("parameters", 0) == list(result.names)
    np.testing.assert_allclose([float(v) for v in cells("parameters", 1)], result.estimates, rtol=1e-5, atol=1e-12)
    assert cells("friction", 0) == result.nominal.joint_names
    viscous = [float(v.split("±")[0]) for v in cells("friction", 1)]
    np.testing.assert_allclose(viscous, result.friction_estimates[0::2], rtol=1e-4)
    assert len([e for e in doc.iter(f"{XHTML}div") if (e.get("class") or "") == "id-plot"]) == 4


def test_result_methods_and_simulated_data(tmp_path):
    """identification_html / write_identification_html / plot() with no log (the fitted data) work for simulated
    Measurements too; the older Identification.to_html / write_html still work and warn."""
    from kinedyn.report import identification_html, write_identification_html

    robot = kd.robots.planar_2r()
    data = an.simulate_measurements(robot, an.excitation(robot, harmonics=3, period=4.0), T=4.0, rate=50.0, noise=0.01)
    result = an.identify(robot, data)
    path = write_identification_html(result, tmp_path / "sim.html")
    page = path.read_text(encoding="utf-8")
    assert page == identification_html(result)
    with pytest.warns(DeprecationWarning, match="identification_html"):
        assert result.to_html() == page
    with pytest.warns(DeprecationWarning, match="write_identification_html"):
        assert result.write_html(tmp_path / "old.html").read_text(encoding="utf-8") == page
    assert "error %" in page  # true values known: errors shown
    assert len(result.plot().axes) == 4


def test_report_draws_in_chromium(browser, written):
    from test_report_layout import OVERFLOWS

    out = written[0]
    page = browser.new_page(viewport={"width": 1000, "height": 900})
    errors: list = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(out.resolve().as_uri())
    page.wait_for_load_state("load")
    assert errors == []
    assert page.evaluate("document.querySelectorAll('.id-plot .main-svg').length") >= 4  # every joint's plot drawn
    assert page.evaluate("document.documentElement.scrollWidth") <= 1000
    assert page.evaluate(OVERFLOWS) == []
    page.close()
