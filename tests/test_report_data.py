"""The report's numbers as data (kinedyn.report.data.ReportData) and the names that moved with it:
the dict-like reading of earlier versions, the JSON block built from it, the old import paths."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
from kinedyn._ui.json import jsonable  # noqa: E402
from kinedyn.report import ReportData, build_report, collect  # noqa: E402


@pytest.fixture(scope="module")
def arm():
    robot = kd.robots.planar_2r()
    return robot, collect(robot, [0.3, -0.4], t_end=0.05, eom_joints=2, name="planar_2r")


def test_collect_gives_report_data_read_like_the_dict_it_replaces(arm):
    robot, data = arm
    assert isinstance(data, ReportData)
    public = data.to_dict()
    assert list(data) == list(public) and len(data) == len(public)
    assert dict(data.items()) == public
    assert data["rank"] == data.rank == 2 and data.get("nope") is None
    assert "simulation" in data and "eom" not in data and "_eom" not in data
    assert not [k for k in data if k.startswith("_")]
    np.testing.assert_allclose(data["mass_matrix"], robot.mass_matrix([0.3, -0.4]))
    assert data["dynamics"] is True  # every build has the numeric dynamics; the key stays for --json readers
    assert data.eom is not None and data.eom.n == 2  # the symbolic equations: an attribute, not JSON


def test_the_page_embeds_exactly_the_public_numbers(arm):
    robot, data = arm
    page = build_report(robot, data=data)
    m = re.search(r'<script type="application/json" id="kinedyn-data">(.*?)</script>', page, re.S)
    assert json.loads(m.group(1)) == json.loads(json.dumps(jsonable(data.to_dict())))
    assert "<math" in page  # the equations from data.eom


def test_a_configuration_not_finite_is_refused():
    robot = kd.robots.planar_2r()
    with pytest.raises(ValueError, match="finite"):
        collect(robot, [np.nan, 0.0], t_end=0.05, eom_joints=0)


def test_moved_names_keep_their_old_import_paths():
    import kinedyn.configuration as configuration
    import kinedyn.report.html as html
    import kinedyn.report.tutorial as old_tutorial
    import kinedyn.tutorial as tutorial
    from kinedyn._ui.svg import svg_plot

    assert html.default_configuration is configuration.default_configuration
    assert html.svg_plot is svg_plot
    assert old_tutorial.elbow_ik is tutorial.elbow_ik and old_tutorial.answer is tutorial.answer
    robot = kd.robots.elbow_3r()
    np.testing.assert_allclose(configuration.default_configuration(robot), [0.5, -0.7, 0.5])
