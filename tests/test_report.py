"""`kinedyn report`: the HTML file's numbers equal the library's, it needs no network, and in a real
headless Chromium (Debian's package, driven by Playwright) it loads from file:// with no request and no
console error, draws the 3-D view and typesets the equations."""

from __future__ import annotations

import html
import io
import json
import os
import re

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
from kinedyn.cli import main  # noqa: E402


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def data_block(page: str) -> dict:
    m = re.search(r'<script type="application/json" id="kinedyn-data">(.*?)</script>', page, re.S)
    return json.loads(m.group(1).replace("<\\/", "</"))


@pytest.fixture(scope="module")
def default_report(tmp_path_factory):
    """`kinedyn report` with no argument, run in an empty folder: report.html of the tutorial arm."""
    folder = tmp_path_factory.mktemp("report")
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        assert main(["report"]) == 0
    finally:
        os.chdir(cwd)
    return folder / "report.html"


def test_default_report_is_the_tutorial_arm(default_report):
    page = default_report.read_text()
    d = data_block(page)
    robot = kd.robots.planar_2r()
    q = np.array(d["q"])
    assert d["robot"] == "planar_2r"
    np.testing.assert_allclose(d["jacobian"], robot.jacobian(q), atol=1e-12)
    np.testing.assert_allclose(d["singular_values"], np.linalg.svd(robot.jacobian(q), compute_uv=False), atol=1e-12)
    np.testing.assert_allclose(d["mass_matrix"], robot.mass_matrix(q), atol=1e-12)
    assert all(p["ok"] for p in d["properties"]), d["properties"]
    assert "<math" in page and "kinedyn-view" in page


def test_default_report_works_the_tutorial(default_report):
    """The default robot is the tutorial's arm, so its report carries the tutorial worked step by step:
    every question, and a misprint verdict for exactly the printed answers the tutorial module finds wrong."""
    from kinedyn.report import tutorial

    page = default_report.read_text()
    section = page[page.index("<section id='tutorial'>") :]
    section = section[: section.index("</section>")]
    answers = tutorial.work()
    for a in answers:
        assert html.escape(a.title) in section, a.title
    misprints = [c.quantity for a in answers for c in a.misprints]
    assert misprints, "the seed tutorial has misprints"
    assert section.count("differs: misprint") == len(misprints)
    assert section.count("the printed value is wrong") == len(misprints)
    assert section.count("<math") >= 10


def test_report_needs_no_network(default_report):
    page = default_report.read_text()
    # plotly.js is inlined (its text names URLs of features the report does not use: map tiles, the
    # CDN it is also published on); the browser test below sees that nothing is requested
    plotly = re.search(r'<script id="plotly-js">(.*?)</script>', page, re.S)
    assert plotly and "Plotly" in plotly.group(1)
    page = page.replace(plotly.group(1), "")
    assert not re.search(r"<(script|img|iframe|link|source)[^>]+(src|href)=", page, re.I)
    assert "@import" not in page and "url(http" not in page
    # the only URLs are XML namespace names (never fetched)
    urls = set(re.findall(r"https?://[^\s\"'<>)]+", page))
    assert urls <= {"http://www.w3.org/1998/Math/MathML", "http://www.w3.org/2000/svg"}, urls


def test_report_json_and_options(capsys, tmp_path):
    out = tmp_path / "elbow.html"
    code, text, err = run(
        capsys, "report", "elbow_3r", "-o", str(out), "--q", "10", "20", "-30", "--deg", "--t", "0.5", "--json"
    )
    assert code == 0, err
    d = json.loads(text)
    robot = kd.robots.elbow_3r()
    q = np.radians([10, 20, -30])
    np.testing.assert_allclose(d["q"], q, atol=1e-15)
    np.testing.assert_allclose(d["tool_pose"], robot.pose(q), atol=1e-12)
    np.testing.assert_allclose(d["gravity_torque"], robot.gravity_torque(q), atol=1e-12)
    assert out.exists() and d["path"] == str(out.resolve())
    page_data = data_block(out.read_text())
    assert page_data["simulation"]["t"][-1] == pytest.approx(0.5)
    assert "id='tutorial'" not in out.read_text()  # only the tutorial's arm gets the worked tutorial
    code, _, _ = run(capsys, "report", "-o", str(tmp_path / "plain.html"), "--no-tutorial", "--t", "0.2")
    assert code == 0 and "id='tutorial'" not in (tmp_path / "plain.html").read_text()
    # a 6-joint arm: no symbolic equations by default, and the report says why
    code, text, err = run(capsys, "report", "puma560", "-o", str(tmp_path / "p.html"), "--t", "0.2")
    assert code == 0, err
    assert "up to 3 joints" in (tmp_path / "p.html").read_text()


@pytest.mark.parametrize(
    "argv, message",
    [
        (["report", "planar_2r", "--q", "1", "2", "3"], "needs 2 values"),
        (["report", "no_such_robot"], "neither a built-in"),
        (["report", "planar_2r", "--t", "-1"], "argument --t: must be a positive number"),
        (["report", "planar_2r", "-o", "/no/such/folder/r.html"], "does not exist"),
    ],
)
def test_report_bad_input(capsys, argv, message):
    code, _, err = run(capsys, *argv)
    assert code == 1 and message in err


# ------------------------------------------------------------------ in a real browser
def nonblank(png: bytes) -> float:
    """Fraction of pixels that differ from the image's most common colour."""
    from PIL import Image

    im = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).reshape(-1, 3)
    colours, counts = np.unique(im, axis=0, return_counts=True)
    background = colours[np.argmax(counts)]
    return float(np.mean(np.any(np.abs(im.astype(int) - background) > 24, axis=1)))


def test_report_in_headless_chromium(browser, default_report, tmp_path):
    context = browser.new_context(viewport={"width": 1280, "height": 1000})  # a fresh, empty profile
    page = context.new_page()
    requests, errors = [], []
    page.on("request", lambda r: requests.append(r.url))
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    url = default_report.resolve().as_uri()
    page.goto(url)
    page.wait_for_load_state("load")
    assert requests == [url], requests  # the file itself and nothing else
    assert errors == []

    page.wait_for_function("window.kinedyn && window.kinedyn.ready()")
    page.evaluate("window.kinedyn.ready()")
    # the 3-D view is drawn: it has a picture (axes, arm, joints), not a blank area
    canvas = page.locator("#kinedyn-view")
    shot = canvas.screenshot()
    assert nonblank(shot) > 0.01
    # the equations are typeset MathML with a real size on the page, and not blank
    maths = page.locator("#equations math")
    assert maths.count() >= 4
    box = maths.first.bounding_box()
    assert box["width"] > 100 and box["height"] > 20
    assert nonblank(page.locator("#equations").screenshot()) > 0.01
    page.screenshot(
        path=os.environ.get("KINEDYN_REPORT_SCREENSHOT", str(tmp_path / "report.png")), full_page=True
    )  # for a person to look at

    # its numbers equal the library's: the Jacobian table and the viewer's own forward kinematics
    robot = kd.robots.planar_2r()
    d = data_block(default_report.read_text())
    q = np.array(d["q"])
    cells = page.locator("table.jacobian tbody tr").all()
    shown = np.array([[float(c.inner_text()) for c in row.locator("td.num").all()] for row in cells])
    np.testing.assert_allclose(shown, robot.jacobian(q), rtol=5e-6, atol=1e-6)
    tool = page.evaluate(
        "(q) => { const T = window.kinedyn.fk(q).frames['tool']; return [T[3], T[7], T[11]]; }", [0.3, 1.2]
    )
    np.testing.assert_allclose(tool, robot.pose([0.3, 1.2])[:3, 3], atol=1e-12)
    # moving a slider moves the arm: the readout is the library's FK at the new q
    slider = page.locator("#kinedyn-sliders input").first
    slider.fill("1")
    q1 = float(slider.input_value())  # the value after the slider's step
    assert abs(q1 - 1.0) < 0.01
    text = page.locator("#kinedyn-tool").inner_text()
    xyz = [float(v) for v in re.findall(r"-?\d+\.\d+", text)]
    np.testing.assert_allclose(xyz, robot.pose([q1, q[1]])[:3, 3], atol=1e-4)
    assert errors == [] and requests == [url]
    context.close()


def test_elbow_report_in_headless_chromium(browser, tmp_path):
    path = tmp_path / "elbow.html"
    assert main(["report", "elbow_3r", "-o", str(path), "--t", "0.5"]) == 0
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    page = context.new_page()
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(path.resolve().as_uri())
    page.wait_for_function("window.kinedyn && window.kinedyn.ready()")
    page.evaluate("window.kinedyn.ready()")
    robot = kd.robots.elbow_3r()
    for q in ([0.1, 0.2, 0.3], [2.0, -1.0, 0.5]):
        T = np.array(page.evaluate("(q) => window.kinedyn.fk(q).frames['tool']", q)).reshape(4, 4)
        np.testing.assert_allclose(T, robot.pose(q), atol=1e-12)
    assert nonblank(page.locator("#kinedyn-view").screenshot()) > 0.01
    assert errors == []
    context.close()
