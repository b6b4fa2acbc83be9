"""Rich display in notebooks (issue 13 §4): a notebook is executed in a real Jupyter kernel (nbclient,
ipykernel) and the display data of each cell is checked: the MIME types present, and the content (the
joint names, the numbers of a known call, q̇ rather than qd in the equations).

The same calls are made here, in the test's process, to know the numbers the kernel must show."""

from __future__ import annotations

import html
import re
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")
nbformat = pytest.importorskip("nbformat", reason="nbformat (test extra) is not installed")
nbclient = pytest.importorskip("nbclient", reason="nbclient (test extra) is not installed")
pytest.importorskip("ipykernel", reason="ipykernel (test extra) is not installed")

import kinedyn as kd  # noqa: E402
from kinedyn import analysis  # noqa: E402

CELLS = {
    "robot": "import numpy as np\nimport kinedyn as kd\nfrom kinedyn import analysis\nrobot = kd.robots.puma560()\nrobot",
    "eom": "eom = kd.robots.planar_2r().equations_of_motion()\neom",
    "step": "eom.steps[2]",
    "ik": "result = robot.inverse_kinematics(robot.pose(np.full(6, 0.3)))\nresult",
    "trajectory": "traj = kd.simulate(kd.robots.elbow_3r(), (0.0, 0.5), np.r_[0.5, -0.7, 0.5, 0, 0, 0])\ntraj",
    "properties": "analysis.check_properties(kd.robots.planar_2r(), samples=20, T=0.2)",
    "identification": (
        "r2 = kd.robots.planar_2r()\n"
        "ident = analysis.identify(r2, analysis.simulate_measurements(r2, analysis.excitation(r2, harmonics=3, period=2.0, seed=1), rate=50.0))\n"
        "ident"
    ),
    # robot.show() in a kernel returns at once (a script blocks until Ctrl-C) with its server running
    "viewer": (
        "import urllib.request\nviewer = kd.robots.planar_2r().show(port=8765)\n"
        "status = urllib.request.urlopen(viewer.url, timeout=60).status\nviewer.close()\n(status, viewer.url)"
    ),
}


@pytest.fixture(scope="module")
def outputs(tmp_path_factory, monkeypatch_module):
    """cell name -> the display data (mime type -> content) of its result, from a real kernel."""
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(source) for source in CELLS.values()]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    # the kernel imports the kinedyn under test (the wheel in CI, python/ here)
    monkeypatch_module.setenv("PYTHONPATH", str(Path(kd.__file__).parents[1]))
    client = nbclient.NotebookClient(
        nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(tmp_path_factory.mktemp("nb"))}}
    )
    client.execute()
    out = {}
    for name, cell in zip(CELLS, nb.cells):
        results = [o for o in cell.outputs if o.output_type == "execute_result"]
        errors = [o for o in cell.outputs if o.output_type == "error"]
        assert not errors, (name, errors)
        assert len(results) == 1, (name, cell.outputs)
        out[name] = results[0]["data"]
    return out


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


def cells_of(table_html: str, cls: str) -> list:
    """The rows of the table with class ``cls`` as lists of cell texts."""
    table = re.search(rf'<table class="{cls}">(.*?)</table>', table_html, re.S).group(1)
    body = table.split("<tbody>")[1]
    return [
        [html.unescape(re.sub(r"<[^>]+>", "", c)) for c in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
        for row in re.findall(r"<tr>(.*?)</tr>", body, re.S)
    ]


def assert_dotted_rates(page: str) -> None:
    """Inside the typeset equations the velocities are q with a dot over it, never the symbol name qd."""
    maths = re.findall(r"<math.*?</math>", page, re.S)
    text = html.unescape(" ".join(re.sub(r"<[^>]+>", " ", m) for m in maths))
    assert maths and "qd" not in text
    assert "˙" in text or "\u0307" in text


def test_robot_shows_its_joint_table_mass_and_a_picture(outputs):
    data = outputs["robot"]
    assert {"text/html", "text/markdown", "text/plain"} <= set(data)
    page = data["text/html"]
    robot = kd.robots.puma560()
    rows = cells_of(page, "kinedyn-joints")
    assert [r[0] for r in rows] == robot.joint_names
    total = sum(float(b.inertia.mass) for b in robot.tree.bodies)
    assert f"total moving mass {total:.6g} kg" in page
    assert (
        "<svg" in page
        and "<line" in page
        and "<script" not in page
        and "http" not in page.replace('xmlns="http://www.w3.org/2000/svg"', "")
    )
    assert all(name in data["text/markdown"] for name in robot.joint_names)


def test_equations_of_motion_typeset_with_dotted_rates(outputs):
    data = outputs["eom"]
    assert {"text/html", "text/latex", "text/markdown"} <= set(data)
    eom = kd.robots.planar_2r().equations_of_motion()
    assert data["text/latex"] == eom.to_latex(steps=False)
    assert (
        r"\dot{q}_{1}" in data["text/latex"] and "qd_{1}" not in data["text/latex"] and "qd1" not in data["text/latex"]
    )
    page = data["text/html"]
    assert page.count("<math") >= 4 and "<details>" in page
    assert_dotted_rates(page)


def test_a_step_typesets_with_the_equations_names(outputs):
    data = outputs["step"]
    assert {"text/html", "text/latex", "text/markdown"} <= set(data)
    step = kd.robots.planar_2r().equations_of_motion().steps[2]
    assert step.title in html.unescape(data["text/html"])
    assert_dotted_rates(data["text/html"])
    assert r"\dot{q}_{1}" in data["text/latex"] and "qd_{1}" not in data["text/latex"]
    assert r"\dot{q}_{1}" in data["text/markdown"]


def test_ik_result_shows_the_solutions_of_the_call(outputs):
    data = outputs["ik"]
    assert {"text/html", "text/markdown"} <= set(data)
    robot = kd.robots.puma560()
    result = robot.inverse_kinematics(robot.pose(np.full(6, 0.3)))
    rows = cells_of(data["text/html"], "kinedyn-ik")
    assert len(rows) == len(result.solutions) >= 2
    shown = np.array([[float(c) for c in r[1:7]] for r in rows])
    np.testing.assert_allclose(shown, result.solutions, rtol=5e-6, atol=1e-12)


def test_trajectory_shows_a_plot_with_every_joint(outputs):
    data = outputs["trajectory"]
    page = data["text/html"]
    assert "<svg" in page and page.count("<polyline") == 3
    for name in kd.robots.elbow_3r().joint_names:
        assert f">{name}</text>" in page
    assert "samples" in page and "0.5 s" in page


def test_property_and_identification_results_are_tables(outputs):
    report = analysis.check_properties(kd.robots.planar_2r(), samples=20, T=0.2)
    rows = cells_of(outputs["properties"]["text/html"], "kinedyn-properties")
    assert [r[0] for r in rows] == [c.name for c in report.checks]
    np.testing.assert_allclose([float(r[1]) for r in rows], [c.residual for c in report.checks], rtol=5e-3, atol=1e-300)
    r2 = kd.robots.planar_2r()
    ident = analysis.identify(
        r2, analysis.simulate_measurements(r2, analysis.excitation(r2, harmonics=3, period=2.0, seed=1), rate=50.0)
    )
    rows = cells_of(outputs["identification"]["text/html"], "kinedyn-identification")
    assert [r[0] for r in rows] == list(ident.names)
    np.testing.assert_allclose([float(r[1]) for r in rows], ident.estimates, rtol=5e-6, atol=1e-12)


def test_the_live_viewer_returns_at_once_in_a_kernel_and_serves_its_page(outputs):
    status, url = eval(outputs["viewer"]["text/plain"])  # the tuple the cell returned: (200, 'http://localhost:PORT')
    assert status == 200 and re.fullmatch(r"http://localhost:\d+", url)
