"""The report survives any name (issue 11, section 10).

Names of robots, links, joints and frames are data from a file; the report puts them into HTML text
(escaped by html.escape) and into JSON inside <script> elements (escaped by report.html.script_json).
These tests parse the page with html5lib, a parser that follows the HTML Standard's tokenizer, so a
name that opens a comment-like "<!--<script" state or closes the element early is seen as a real
browser sees it; the last test loads such a report in headless Chromium.
"""

from __future__ import annotations

import io
import json
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

html5lib = pytest.importorskip("html5lib")
pytest.importorskip("kinedyn._core", reason="the native module is not built")

from kinedyn._ui.json import jsonable  # noqa: E402
from kinedyn.report.html import build_report, collect, script_json  # noqa: E402
from kinedyn.robot_files import robot_from_mapping  # noqa: E402
from kinedyn.visual.page import asset, view_model  # noqa: E402

XHTML = "{http://www.w3.org/1999/xhtml}"

# pieces that each break a naive embedding in one way or another
HOSTILE = [
    "<!--<script>",
    "</script>",
    "<script>",
    "<!--",
    "-->",
    "]]>",
    "<![CDATA[",
    "</",
    "<",
    ">",
    "&",
    "&amp;",
    "&lt;",
    '"',
    "'",
    "`",
    "\\",
    "\\u003c",
    "\u2028",
    "\u2029",
    "\u00e9",
    "\u03c9",
    "\U0001f916",
    "{{",
    "}}",
    "${x}",
    "</title>",
    "<style>",
    "</style>",
    "<textarea>",
    "<plaintext>",
    "<!DOCTYPE",
    "<?xml",
    "\x00",
    "\t",
]
# text an HTML document can show as itself: no controls (NUL becomes U+FFFD, CR becomes LF) and no
# leading/trailing white space, which a table cell's text keeps but names do not need
printable = st.characters(blacklist_categories=("Cs", "Cc"))
shown_name = (
    st.lists(
        st.one_of(st.sampled_from([h for h in HOSTILE if h not in ("\x00", "\t")]), st.text(printable, max_size=6)),
        min_size=1,
        max_size=6,
    )
    .map("".join)
    .map(str.strip)
    .filter(bool)
)
any_name = (
    st.lists(st.one_of(st.sampled_from(HOSTILE), st.text(max_size=6)), min_size=1, max_size=6)
    .map("".join)
    .filter(str.strip)
)


def parse(page: str):
    return html5lib.parse(page, namespaceHTMLElements=True)


def scripts(doc) -> list:
    return list(doc.iter(f"{XHTML}script"))


def text_of(el) -> str:
    return "".join(el.itertext())


# ------------------------------------------------------------------ the embedding function alone
json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False) | any_name | st.text(),
    lambda children: (
        st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=8) | any_name, children, max_size=4)
    ),
    max_leaves=12,
)


@settings(max_examples=300, deadline=None)
@given(obj=json_values)
def test_script_json_survives_an_html5_parser(obj):
    """Whatever the object holds, the script element ends where it should, the element after it is
    still there, and the text parses back to the object."""
    text = script_json(obj)
    for bad in ("<", ">", "&", "\u2028", "\u2029"):
        assert bad not in text
    page = f'<!DOCTYPE html><html><head><title>t</title></head><body><script type="application/json" id="x">{text}</script><p id="after">after</p></body></html>'
    doc = parse(page)
    [script] = scripts(doc)
    assert script.get("id") == "x"
    assert script.text == text
    assert json.loads(script.text) == obj
    after = [p for p in doc.iter(f"{XHTML}p") if p.get("id") == "after"]
    assert len(after) == 1 and after[0].text == "after"


@pytest.mark.parametrize(
    "name", ["<!--<script>", "</script><p id=after>", "<!--<script></script>", "x]]>&amp;</SCRIPT >"]
)
def test_script_json_known_breakers(name):
    page = f'<!DOCTYPE html><html><body><script type="application/json">{script_json({"name": name})}</script><p id="after">a</p></body></html>'
    doc = parse(page)
    [script] = scripts(doc)
    assert json.loads(script.text) == {"name": name}
    assert [p.get("id") for p in doc.iter(f"{XHTML}p")] == ["after"]


# ------------------------------------------------------------------ whole reports of robots with hostile names
def hostile_robot(robot_name, link1, link2, tool, joint1, joint2, base="base", frame="marker"):
    """A two-link arm (a tree description: every name is free text) with the given names and one
    extra frame."""
    inertia = {"ixx": 0.01, "iyy": 0.3, "izz": 0.3}
    return robot_from_mapping(
        {
            "name": robot_name,
            "source": robot_name,
            "gravity": [0, 0, -9.81],
            "base": base,
            "tool": tool,
            "links": [
                {
                    "name": link1,
                    "parent": base,
                    "joint": {"name": joint1, "type": "revolute", "axis": [0, 1, 0]},
                    "inertial": {"mass": 1.0, "com": [0.5, 0, 0], "inertia": inertia},
                },
                {
                    "name": link2,
                    "parent": link1,
                    "joint": {"name": joint2, "type": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [1, 0, 0]}},
                    "inertial": {"mass": 1.0, "com": [0.5, 0, 0], "inertia": inertia},
                },
                {
                    "name": tool,
                    "parent": link2,
                    "joint": {"name": f"{tool} fixed", "type": "fixed", "origin": {"xyz": [1, 0, 0]}},
                },
            ],
            "frames": [{"name": frame, "link": link1, "origin": {"xyz": [0.5, 0, 0.1]}}],
        }
    )


def check_report(robot, shown: bool):
    """Build the report of ``robot`` and check it with html5lib: four script elements (the two JSON
    blocks, plotly.js, then the viewer), each JSON block equal to what was embedded, the viewer's code intact, and
    (``shown``) the names visible as themselves in the header and the tables."""
    q = np.array([0.3, -0.4])
    data = collect(robot, q, t_end=0.05, eom_joints=0)
    expected_data = json.loads(json.dumps(jsonable({k: v for k, v in data.items() if not k.startswith("_")})))
    expected_model = json.loads(json.dumps(view_model(robot, q)))
    page = build_report(robot, q, data=data)
    # plotly.js (5 MB, the same in every report, no names in it) is taken out before html5lib, which
    # is pure Python, parses the page; its element stays, and is checked to be plotly's code
    from kinedyn.visual.web import plotly_script

    inlined = plotly_script()
    assert page.count(inlined) == 1
    page = page.replace(inlined, '<script id="plotly-js"></script>')
    doc = parse(page)
    found = scripts(doc)
    assert [s.get("id") for s in found] == ["kinedyn-model", "kinedyn-data", "plotly-js", None]
    assert json.loads(found[0].text) == expected_model
    assert json.loads(found[1].text) == expected_data
    assert found[3].text == asset("viewer.js")
    assert [e.get("id") for e in doc.iter(f"{XHTML}div") if e.get("id") == "kinedyn-view"] == ["kinedyn-view"]
    assert len(list(doc.iter(f"{XHTML}footer"))) == 1  # the page after the names is all there
    if shown:
        [h1] = doc.iter(f"{XHTML}h1")
        assert text_of(h1) == robot.name
        assert text_of(next(doc.iter(f"{XHTML}title"))) == f"kinedyn report: {robot.name}"
        tables = {t.get("class"): t for t in doc.iter(f"{XHTML}table")}
        first_cells = lambda cls: [
            text_of(tr.find(f"{XHTML}td")) for tr in tables[cls].iter(f"{XHTML}tr") if tr.find(f"{XHTML}td") is not None
        ]
        assert first_cells("joints") == robot.joint_names
        assert first_cells("bodies") == [b.name for b in robot.tree.bodies]
        assert first_cells("mass-matrix") == robot.joint_names
        jac_heads = [text_of(th) for th in tables["jacobian"].iter(f"{XHTML}th")]
        assert jac_heads[1:] == robot.joint_names


names = st.lists(shown_name, min_size=7, max_size=7, unique=True).filter(lambda v: "base" not in v)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(names=names)
def test_report_with_hostile_names_parses_back(names):
    robot_name, link1, link2, tool, joint1, joint2, frame = names
    check_report(hostile_robot(robot_name, link1, link2, tool, joint1, joint2, frame=frame), shown=True)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(
    names=st.lists(any_name, min_size=7, max_size=7, unique=True).filter(
        lambda v: "base" not in v and len({n.strip() for n in v}) == 7
    )
)
def test_report_json_survives_any_name(names):
    """Control characters and white space too: the JSON blocks (what the viewer reads) still parse
    back equal, whatever the HTML text shows of such characters."""
    robot_name, link1, link2, tool, joint1, joint2, frame = names
    try:
        robot = hostile_robot(robot_name, link1, link2, tool, joint1, joint2, frame=frame)
    except ValueError:  # a loader may refuse a name (e.g. one with a NUL); refusing is fine here
        return
    check_report(robot, shown=False)


THE_BREAKER = "<!--<script>"


def test_the_reported_breaker(tmp_path):
    """The example of the issue: a link named '<!--<script>' (and the other names as bad)."""
    robot = hostile_robot(
        THE_BREAKER + " robot",
        THE_BREAKER,
        "</script><b>2",
        "tool]]>&",
        "q1 <!--",
        "q2 \u2028 </SCRIPT",
        frame="<script>x",
    )
    check_report(robot, shown=True)


# ------------------------------------------------------------------ in a real browser (tests/conftest.py's browser)
def nonblank(png: bytes) -> float:
    """Fraction of pixels that differ from the image's most common colour."""
    from PIL import Image

    im = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).reshape(-1, 3)
    colours, counts = np.unique(im, axis=0, return_counts=True)
    return float(np.mean(np.any(np.abs(im.astype(int) - colours[np.argmax(counts)]) > 24, axis=1)))


def test_report_with_a_hostile_name_in_chromium(browser, tmp_path):
    """The 3-D view draws, the viewer's forward kinematics runs, a slider moves the arm, the slider
    labels show the hostile joint names as text, and no script error is logged."""
    joint1, joint2 = "q1 <!--<script>", "q2 </script><img src=x onerror=alert(1)>"
    robot = hostile_robot("<!--<script> arm", THE_BREAKER, "</script>", "tool & <b>", joint1, joint2, frame="-->\u2028")
    path = tmp_path / "hostile.html"
    path.write_text(build_report(robot, [0.3, -0.4], t_end=0.1, eom_joints=2), encoding="utf-8")
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    page = context.new_page()
    errors, dialogs = [], []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("dialog", lambda d: (dialogs.append(d.message), d.dismiss()))
    page.goto(path.resolve().as_uri())
    page.wait_for_load_state("load")
    page.wait_for_function("window.kinedyn && window.kinedyn.ready()")
    page.evaluate("window.kinedyn.ready()")
    assert errors == [] and dialogs == []
    assert (
        page.evaluate("document.getElementById('kinedyn-data') !== null && document.querySelectorAll('script').length")
        == 4
    )
    assert nonblank(page.locator("#kinedyn-view").screenshot()) > 0.01
    for q in ([0.1, 0.2], [2.0, -1.0]):
        T = np.array(page.evaluate("(q) => window.kinedyn.fk(q).frames['tool & <b>']", q)).reshape(4, 4)
        np.testing.assert_allclose(T, robot.pose(q), atol=1e-12)
    labels = page.locator("#kinedyn-sliders .jn").all_inner_texts()
    assert labels == [joint1, joint2]
    slider = page.locator("#kinedyn-sliders input").first
    slider.fill("1")
    q1 = float(slider.input_value())
    xyz = [float(v) for v in re.findall(r"-?\d+\.\d+", page.locator("#kinedyn-tool").inner_text())]
    np.testing.assert_allclose(xyz, robot.pose([q1, -0.4])[:3, 3], atol=1e-4)
    assert page.locator("h1").inner_text() == robot.name
    assert errors == [] and dialogs == []
    context.close()
