"""Drawings of robots with closed loops (docs/closed-loops.md, "Drawings"): a slider per independent
coordinate, the other joints solved. The static pages (the report, an animation) hold configurations
solved when they were written (kinedyn.visual.loops); the live viewer solves as a slider moves."""

from __future__ import annotations

import json
import re
import socket
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.configuration import default_configuration

ROOT = Path(__file__).resolve().parents[1]
ROBOTS = ["four_bar.yaml", "five_bar.yaml"]


def freedom(robot, q) -> int:
    """nv - rank J: the mechanism's degrees of freedom at q, counted here independently of the page."""
    jac = robot.loop_jacobian(q)
    return robot.nv - int(np.linalg.matrix_rank(jac, tol=1e-9 * np.abs(jac).max()))


PAGES: dict = {}


def page_of(name: str, tmp_path_factory):
    """The robot's view model (what the report and an animation page embed: kinedyn.visual.page) and
    a page that runs the report's viewer.js on it without plotly.js (the sliders and the forward
    kinematics run; nothing is drawn: plotly's 3.5 MB took 14 s to load in a loaded CI)."""
    from kinedyn.visual.page import asset, json_script, view_model

    if name in PAGES:  # one page per robot for the whole module
        return PAGES[name]
    robot = kd.load(str(ROOT / "examples" / "robots" / name))
    q = default_configuration(robot)
    model = view_model(robot, q)
    path = tmp_path_factory.mktemp("loops") / (Path(name).stem + ".html")
    path.write_text(
        "<!DOCTYPE html><html><body><div id='kinedyn-view'></div><div id='kinedyn-sliders'></div>"
        "<button id='kinedyn-reset'></button><span id='kinedyn-tool'></span><p id='kinedyn-q'></p>"
        f"{json_script(model, 'kinedyn-model')}<script>{asset('viewer.js')}</script></body></html>"
    )
    block = re.search(r'<script type="application/json" id="kinedyn-model">(.*?)</script>', path.read_text(), re.S)
    PAGES[name] = robot, q, path, json.loads(block.group(1))
    return PAGES[name]


@pytest.fixture(scope="module", params=ROBOTS)
def page(request, tmp_path_factory):
    return page_of(request.param, tmp_path_factory)


def test_independent_joints_are_the_motors_and_fix_the_rest():
    """Nearest the base first: the four-bar's crank, the five-bar's two motors; as many as the
    mechanism's degrees of freedom; holding them, a perturbed start projects back to the same
    configuration."""
    for name, expected in [("four_bar.yaml", ["crank_joint"]), ("five_bar.yaml", ["q1", "q2"])]:
        robot = kd.load(str(ROOT / "examples" / "robots" / name))
        q = default_configuration(robot)
        assert robot.independent_joints(q) == expected
        assert len(expected) == freedom(robot, q)
        held = [robot.joint_names.index(j) for j in expected]  # 1-DOF joints: a joint's index is its entry of q
        start = q + 0.05
        start[held] = q[held]
        np.testing.assert_allclose(robot.project_configuration(start, hold=expected), q, atol=1e-9)


def test_page_holds_closed_configurations(page):
    """Every configuration the page holds closes the loop (< 1e-9, after its JSON round trip), holds
    each slider's joint at the slider's position, and the grid stays on one assembly branch (no jump
    between neighbours larger than 3 steps); a slider per independent coordinate."""
    robot, q, _, model = page
    loop = model["loop"]
    assert len(model["sliders"]) == len(loop["joints"]) == freedom(robot, q) == loop["free"]
    assert loop["joints"] == robot.independent_joints(q) and loop["mode"] == "grid"
    shape = [len(v) for v in loop["values"]]
    states = loop["states"][0]
    assert len(states) == int(np.prod(shape)) and loop["unreachable"] == 0
    grid = np.array(states, dtype=float).reshape(*shape, robot.nq)
    assert np.abs(robot.loop_residual(grid.reshape(-1, robot.nq))).max() < 1e-9
    for k, (entry, values) in enumerate(zip(loop["q"], loop["values"])):
        held = np.moveaxis(grid[..., entry], k, 0).reshape(len(values), -1)
        np.testing.assert_array_equal(held, np.repeat(np.array(values)[:, None], held.shape[1], axis=1))
        step = values[1] - values[0]
        assert np.abs(np.diff(grid, axis=k)).max() < 3 * step
    # the drawn configuration is the grid's reference position
    np.testing.assert_allclose(grid[tuple(loop["reference"])], q, atol=1e-12)
    assert "Nothing is interpolated" in loop["note"]


@pytest.fixture(scope="module")
def five_bar_page(tmp_path_factory):
    return page_of("five_bar.yaml", tmp_path_factory)


def test_page_sliders_in_chromium(browser, five_bar_page):
    """In Chromium, the five-bar's viewer.js: one slider per independent coordinate; two positions
    of them show closed configurations with each slider's joint at its position (the other joints
    solved). (The four-bar's page runs the same script; its grid is checked above. Screenshots of
    the reports: docs/closed-loops.md, "Drawings".)"""
    robot, q, path, model = five_bar_page
    loop = model["loop"]
    context = browser.new_context(viewport={"width": 800, "height": 600})
    tab = context.new_page()
    errors = []
    tab.on("pageerror", lambda e: errors.append(str(e)))
    tab.goto(path.resolve().as_uri())
    tab.wait_for_function("window.kinedyn", timeout=60000)
    inputs = tab.locator("#kinedyn-sliders input")
    assert inputs.count() == freedom(robot, q)
    assert "Closed loops" in tab.locator("#kinedyn-loop-sliders").inner_text()
    seen = [q]
    for fractions in ([0.2, 0.75], [0.8, 0.4]):
        at = [int(f * (len(v) - 1)) for f, v in zip(fractions, loop["values"])]
        for k, index in enumerate(at):
            inputs.nth(k).fill(str(index))
        shown = np.array(tab.evaluate("window.kinedyn.q()"))
        assert np.abs(robot.loop_residual(shown)).max() < 1e-9
        for k, entry in enumerate(loop["q"]):
            assert shown[entry] == loop["values"][k][at[k]]
        assert not any(np.allclose(shown, s) for s in seen)  # the solved joints moved too
        seen.append(shown)
    # the tool readout follows the library's forward kinematics of the configuration shown
    tool = robot.frame_poses(shown, [robot.tool])[0][:3, 3]
    assert tab.locator("#kinedyn-tool").inner_text() == "tool at (" + ", ".join(f"{v:.4f}" for v in tool) + ") m"
    assert errors == [], errors
    context.close()


def test_sweeps_of_three_sliders_in_chromium(browser, tmp_path_factory):
    """Three independent coordinates (the parallelogram arm: yaw, shoulder, elbow drive): a 1-D
    sweep per slider from the drawn configuration; moving one slider puts the others back there,
    every configuration shown is closed, and a slider's joint is at its position."""
    robot, q, path, model = page_of("parallelogram_arm.urdf", tmp_path_factory)
    loop = model["loop"]
    assert loop["mode"] == "sweeps" and loop["joints"] == [
        "yaw",
        "shoulder",
        "elbow_drive",
    ] == robot.independent_joints(q)
    held = [s for states in loop["states"] for s in states if s is not None]
    assert len(held) == loop["positions"] and np.abs(robot.loop_residual(np.array(held))).max() < 1e-9
    context = browser.new_context(viewport={"width": 800, "height": 600})
    tab = context.new_page()
    errors = []
    tab.on("pageerror", lambda e: errors.append(str(e)))
    tab.goto(path.resolve().as_uri())
    tab.wait_for_function("window.kinedyn", timeout=60000)
    inputs = tab.locator("#kinedyn-sliders input")
    assert inputs.count() == 3 == freedom(robot, q)
    inputs.nth(0).fill("10")
    inputs.nth(2).fill("100")  # the elbow drive: the yaw goes back to the drawn configuration's
    shown = np.array(tab.evaluate("window.kinedyn.q()"))
    entries = loop["q"]
    assert shown[entries[2]] == loop["values"][2][100] and shown[entries[0]] == pytest.approx(q[entries[0]], abs=1e-12)
    assert int(inputs.nth(0).input_value()) == loop["reference"][0]
    assert np.abs(robot.loop_residual(shown)).max() < 1e-9
    assert errors == [], errors
    context.close()


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_live_viewer_solves_the_loop_as_a_slider_moves():
    """The live viewer of the five-bar: a slider per motor; moving one solves the other joints
    (closed, the other motor held), and a robot without loops keeps a slider per joint."""
    pytest.importorskip("viser", reason="the viz extra is not installed")
    robot = kd.load(str(ROOT / "examples" / "robots" / "five_bar.yaml"))
    viewer = robot.show(block=False, port=free_port(), verbose=False)
    try:
        q0 = viewer.q.copy()
        assert [s.label for s in viewer._sliders] == ["q1", "q2"]
        viewer._sliders[1].value = 1.0  # as a user moving q2's slider
        q = viewer.q
        assert np.abs(robot.loop_residual(q)).max() < 1e-9
        assert q[2] == pytest.approx(1.0, abs=1e-12) and q[0] == pytest.approx(q0[0], abs=1e-12)
        assert abs(q[3] - q0[3]) > 0.1  # a solved joint followed
        # still the drawn configuration's assembly branch (the file's reference: the parallelogram,
        # q = [q1, q4, q2, q3] with q3 = q1 - q2, q4 = q2 - q1)
        assert q[3] == pytest.approx(q[0] - q[2], abs=1e-9) and q[1] == pytest.approx(q[2] - q[0], abs=1e-9)
    finally:
        viewer.close()
