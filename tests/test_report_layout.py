"""The report fits any robot (issue 13 §5): in a real headless Chromium at 1000 px and 1400 px wide, the
page is no wider than the window and every card's content stays inside its card (or inside a scroll box
inside it), for every built-in and for the UR5, Panda and Talos URDFs; slider labels do not run into the
sliders; the joint plot's legend names every joint; gravity prints as a vector."""

from __future__ import annotations

import os
import re
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

from reference import PANDA, UR5, erd  # noqa: E402

import kinedyn as kd  # noqa: E402
from kinedyn.cli import main  # noqa: E402
from kinedyn.report.html import svg_plot  # noqa: E402

TALOS = ("talos_data", "robots", "talos_full_v2.urdf")
WIDTHS = (1000, 1400)

# For every element of a card: the nearest ancestor inside the card that clips it (a scroll box), and
# whether the element's box, or its clipper's box, lies within the card. Reports what sticks out.
OVERFLOWS = """() => {
  const out = [];
  for (const card of document.querySelectorAll('main > section')) {
    const c = card.getBoundingClientRect();
    for (const el of card.querySelectorAll('*')) {
      let clip = null;
      for (let a = el.parentElement; a && a !== card; a = a.parentElement) {
        if (getComputedStyle(a).overflowX !== 'visible') { clip = a; break; }
      }
      if (clip) continue;  // drawn inside a scroll box, which is checked itself
      const r = el.getBoundingClientRect();
      if (r.width === 0 && r.height === 0) continue;
      if (r.left < c.left - 0.5 || r.right > c.right + 0.5) {
        out.push(`${card.id}: <${el.tagName.toLowerCase()} class="${el.className && el.className.baseVal !== undefined ? el.className.baseVal : el.className}"> `
                 + `${Math.round(r.left)}..${Math.round(r.right)} outside the card ${Math.round(c.left)}..${Math.round(c.right)}: `
                 + (el.textContent || '').slice(0, 40));
      }
    }
  }
  return out;
}"""

# slider rows: the joint name, the slider and the value do not overlap, and the name is shown whole
SLIDER_OVERLAPS = """() => {
  const out = [];
  for (const row of document.querySelectorAll('#kinedyn-sliders label')) {
    const parts = Array.from(row.children).map(e => [e, e.getBoundingClientRect()]);
    const name = row.firstChild.nodeType === 3 ? row.firstChild : null;
    let boxes = parts;
    if (name) { const rg = document.createRange(); rg.selectNodeContents(name); boxes = [[name, rg.getBoundingClientRect()], ...parts]; }
    for (let i = 0; i < boxes.length; i++) for (let j = i + 1; j < boxes.length; j++) {
      const a = boxes[i][1], b = boxes[j][1];
      const overlap = Math.min(a.right, b.right) - Math.max(a.left, b.left) > 0.5 && Math.min(a.bottom, b.bottom) - Math.max(a.top, b.top) > 0.5;
      if (overlap) out.push(row.textContent.trim().slice(0, 30));
    }
    for (const [e, r] of parts) if (e.scrollWidth > e.clientWidth + 1 && e.tagName !== 'INPUT') out.push('cut: ' + e.textContent);
  }
  return out;
}"""


def _subjects():
    out = [(name, [name]) for name in kd.robots.CATALOGUE]
    out += [("ur5_urdf", UR5), ("panda_urdf", PANDA), ("talos_urdf", TALOS)]
    return out


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """name -> (path, seconds to write it) for every subject, built lazily."""
    folder = tmp_path_factory.mktemp("layout")
    made: dict = {}

    def get(name, spec):
        if name not in made:
            path = folder / f"{name}.html"
            source = spec[0] if len(spec) == 1 else erd(*spec)
            start = time.perf_counter()
            assert main(["report", source, "-o", str(path), "--t", "0.5"]) == 0
            made[name] = (path, time.perf_counter() - start)
        return made[name]

    return get


# after the window changes size: every plotly figure laid out again for its new box (what its own
# `responsive` handler does a moment later; awaited here, so the check never races it), then a frame drawn
RELAYOUT = """async () => {
  const plots = Array.from(document.querySelectorAll('.js-plotly-plot')).filter(gd => gd.offsetParent !== null);
  await Promise.all(plots.map(gd => window.Plotly.Plots.resize(gd)));
  await new Promise(done => requestAnimationFrame(() => requestAnimationFrame(done)));
}"""


@pytest.mark.parametrize("name, spec", _subjects(), ids=[s[0] for s in _subjects()])
def test_report_fits_its_cards_at_1000_and_1400_px(browser, reports, name, spec, tmp_path):
    # one load per report (a page holds 4.8 MB of plotly.js: its load was most of this test's time),
    # laid out first in the wide window, then in the window narrowed to the small width, as a person
    # narrowing it sees it: the narrow layout is the one where content pushes out of its card
    path, _ = reports(name, spec)
    shots = os.environ.get("KINEDYN_LAYOUT_SCREENSHOTS")
    widths = sorted(WIDTHS, reverse=True)
    context = browser.new_context(viewport={"width": widths[0], "height": 900})
    page = context.new_page()
    errors: list = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(path.resolve().as_uri())
    page.wait_for_load_state("load")
    for width in widths:
        if page.viewport_size["width"] != width:
            page.set_viewport_size({"width": width, "height": 900})
            page.evaluate(RELAYOUT)
        scroll_width = page.evaluate("document.documentElement.scrollWidth")
        assert scroll_width <= width, f"{name} at {width} px: the page is {scroll_width} px wide"
        assert page.evaluate(OVERFLOWS) == [], f"{name} at {width} px"
        assert page.evaluate(SLIDER_OVERLAPS) == [], f"{name} at {width} px: slider labels overlap"
        # every equation box either fits or scrolls inside the card (one evaluation for all boxes: a
        # round trip per box cost seconds on a page of 40 equations)
        unfit = page.evaluate(
            "() => Array.from(document.querySelectorAll('.eq'))"
            ".filter(e => !(e.scrollWidth <= e.clientWidth || getComputedStyle(e).overflowX === 'auto'))"
            ".map(e => e.textContent.slice(0, 40))"
        )
        assert unfit == [], f"{name} at {width} px: equation boxes that neither fit nor scroll: {unfit}"
        if shots:
            Path(shots).mkdir(parents=True, exist_ok=True)
            page.screenshot(path=f"{shots}/{name}-{width}.png", full_page=True)
        assert errors == []
    context.close()


def test_talos_report_is_quick_and_its_big_tables_scroll(browser, reports):
    path, seconds = reports("talos_urdf", TALOS)
    # the generous bound of issue 13 §5 (60 s); measured ~3 s on an idle machine
    assert seconds < 60, seconds
    context = browser.new_context(viewport={"width": 1000, "height": 900})
    page = context.new_page()
    page.goto(path.resolve().as_uri())
    for cls in ("joints", "jacobian", "mass-matrix"):
        table = page.locator(f"table.{cls}")
        assert table.count() == 1
        scroller = table.locator("xpath=..")
        box = scroller.bounding_box()
        # the 44-column table scrolls inside its box, which stays within the card and a screen high
        assert scroller.evaluate("e => getComputedStyle(e).overflowX") == "auto"
        assert box["width"] <= 1000 and box["height"] <= 900
    context.close()


def test_joint_plot_legend_names_every_joint():
    """The 6-joint legend dropped q6 (fixed 95-px slots, past the right edge of the plot)."""
    t = np.linspace(0, 1, 5)
    for names in (
        ["q1", "q2", "q3", "q4", "q5", "q6"],
        [f"panda_joint{k}" for k in range(1, 10)],
        [f"arm_left_{k}_joint" for k in range(44)],
    ):
        svg = svg_plot(t, [(nm, t * k) for k, nm in enumerate(names)], "joint positions", "t", "q")
        width = float(re.search(r'width="(\d+)"', svg).group(1))
        labels = re.findall(r'<text x="([\d.]+)" y="[\d.]+" font-size="11" fill="#243238">([^<]*)</text>', svg)
        assert [lab for _, lab in labels] == names
        for x, lab in labels:  # each label starts inside the plot and (at ~6.6 px a character) ends inside it
            assert float(x) + 6.6 * len(lab) <= width, (lab, x)


def test_legend_in_the_browser_has_one_entry_per_joint(browser, reports):
    path, _ = reports("puma560", ["puma560"])
    context = browser.new_context(viewport={"width": 1000, "height": 900})
    page = context.new_page()
    page.goto(path.resolve().as_uri())
    plot = page.locator("svg[aria-label='joint positions']")
    svg_box = plot.bounding_box()
    entries = plot.locator("text[fill='#243238'][font-size='11']")
    assert entries.count() == 6
    for k in range(6):
        box = entries.nth(k).bounding_box()
        assert entries.nth(k).text_content() == f"q{k + 1}"
        assert svg_box["x"] <= box["x"] and box["x"] + box["width"] <= svg_box["x"] + svg_box["width"]
    context.close()


def test_gravity_prints_as_a_vector(reports):
    path, _ = reports("planar_2r", ["planar_2r"])
    page = path.read_text()
    assert "['0'" not in page
    g = kd.robots.planar_2r().gravity
    assert re.search(r"gravity g = \(" + ", ".join(re.escape(f"{v:g}") for v in g) + r"\) m/s²", page), re.findall(
        r"gravity[^<]*", page
    )


def test_report_frame_option_and_the_pandas_default_tool(tmp_path, capsys):
    """Issue 13 §5: the Panda's report showed a finger's Jacobian; its default tool is now panda_hand_tcp,
    and --frame shows another frame."""
    import json

    path = erd(*PANDA)
    robot = kd.Robot.from_urdf(path)
    for argv, frame in (
        (["report", path], "panda_hand_tcp"),
        (["report", path, "--frame", "panda_link7"], "panda_link7"),
    ):
        assert main([*argv, "-o", str(tmp_path / "p.html"), "--t", "0.1", "--json"]) == 0
        d = json.loads(capsys.readouterr().out)
        assert d["tool"] == frame
        np.testing.assert_allclose(d["jacobian"], robot.jacobian(np.array(d["q"]), frame), atol=1e-12)
    assert main(["report", path, "--frame", "no_such_frame", "-o", str(tmp_path / "p.html")]) == 1
    assert "tool frame 'no_such_frame' is not a frame of robot 'panda'" in capsys.readouterr().err


def test_panda_ik_moves_the_arm_not_the_fingers():
    robot = kd.Robot.from_urdf(erd(*PANDA), mimic="independent")  # IK refuses reduced mimic joints (test_mimic.py)
    q_target = np.array([0.3, -0.5, 0.2, -2.0, 0.1, 1.8, 0.4, 0.02, 0.03])
    q0 = np.array([0.0, -0.3, 0.0, -1.8, 0.0, 1.5, 0.3, 0.01, 0.01])
    result = robot.inverse_kinematics(robot.pose(q_target), q0=q0)
    assert result.success
    np.testing.assert_allclose(result.q[7:], q0[7:], atol=1e-12)  # the fingers do not move the tool
    np.testing.assert_allclose(robot.pose(result.q), robot.pose(q_target), atol=1e-6)


def test_talos_report_with_default_options_finishes_in_under_60_s(tmp_path):
    start = time.perf_counter()
    assert main(["report", erd(*TALOS), "-o", str(tmp_path / "talos.html")]) == 0
    assert time.perf_counter() - start < 60  # issue 13 §5's bound; ~3-10 s here under load


def _page_json(page: str, element_id: str) -> dict:
    import json

    m = re.search(rf'<script type="application/json" id="{element_id}">(.*?)</script>', page, re.S)
    return json.loads(m.group(1).replace("<\\/", "</"))


def test_report_collision_option_draws_the_collision_shapes(tmp_path):
    """`kinedyn report --collision`: the 3-D view draws the <collision> shapes (one sphere) instead of
    the <visual> ones (two boxes)."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text("""<robot name="arm">
  <link name="base"/>
  <link name="l1">
    <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.1 0.1 0.5"/></geometry></visual>
    <visual><origin xyz="0 0 0.5"/><geometry><box size="0.2 0.2 0.2"/></geometry></visual>
    <collision><geometry><sphere radius="0.3"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>""")
    drawn = {}
    for flag in ([], ["--collision"]):
        out = tmp_path / f"r{len(flag)}.html"
        assert main(["report", str(urdf), "-o", str(out), "--t", "0.1", *flag]) == 0
        model = _page_json(out.read_text(), "kinedyn-model")
        drawn[bool(flag)] = (model["geometry"], model["shapes"], model["shapes_drawn"])
    assert drawn == {False: ("visual", 2, 2), True: ("collision", 1, 1)}


def test_report_of_a_changed_tutorial_arm_leaves_out_the_tutorial(tmp_path, reports):
    """The tutorial's numbers are the standard arm's: `report planar_2r --set l1=2` is another arm, so its
    report has no tutorial section (the plain default report has one: tests/test_report.py)."""
    out = tmp_path / "r.html"
    assert main(["report", "planar_2r", "--set", "l1=2", "-o", str(out), "--t", "0.1"]) == 0
    page = out.read_text()
    assert "<section id='tutorial'>" not in page
    path, _ = reports("planar_2r", ["planar_2r"])  # the same command without --set (made once for the module)
    assert "<section id='tutorial'>" in path.read_text()
