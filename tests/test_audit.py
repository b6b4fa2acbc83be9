"""kinedyn audit (docs/audit.md): a model written here for every finding, each finding naming the
file, the line and the element; its fixes checked by another route (the loader's repair policy and
frame rotation); the example-robot-data files that exhibit some findings; the CLI and the report."""

from __future__ import annotations

import dataclasses
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.audit import audit
from kinedyn.description.inertia import Inertia

INERTIA = '<inertia ixx="{0}" iyy="{1}" izz="{2}" ixy="0" ixz="0" iyz="0"/>'
LIMIT = '<limit lower="-1" upper="1" effort="5" velocity="2"/>'


def _box_link(
    name: str, mass: float = 2.7, size: float = 0.1, com: str = "0 0 0", rpy: str = "0 0 0", moments=None
) -> str:
    """A link whose inertia is that of its collision box at aluminium's density unless told otherwise."""
    moments = moments or [mass * size * size / 6] * 3
    return (
        f'<link name="{name}">\n'
        f'  <inertial><origin xyz="{com}" rpy="{rpy}"/><mass value="{mass}"/>{INERTIA.format(*moments)}</inertial>\n'
        f'  <collision><geometry><box size="{size} {size} {size}"/></geometry></collision>\n'
        "</link>\n"
    )


def _robot(*parts: str) -> str:
    return '<robot name="r">\n<link name="base"/>\n' + "".join(parts) + "</robot>\n"


def _joint(name: str, parent: str, child: str, kind: str = "revolute", inner: str = LIMIT) -> str:
    return f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>{inner}</joint>\n'


def _fix_tensor(fix: str) -> dict:
    """The six entries of the <inertia .../> a fix writes."""
    attributes = fix.split("<inertia ")[1].split("/>")[0].split()
    return {k: float(v.strip('"')) for k, v in (a.split("=") for a in attributes)}


def _line_of(text: str, needle: str) -> int:
    return next(k + 1 for k, line in enumerate(text.splitlines()) if needle in line)


CASES = {
    # code: (file text, element, the text on the element's line)
    "inertia-not-positive": (
        _robot(_box_link("a", moments=[-0.1, 1, 1]), _joint("j", "base", "a")),
        "link 'a'",
        '<link name="a">',
    ),
    "inertia-triangle": (
        _robot(_box_link("a", moments=[0.1, 0.1, 0.5]), _joint("j", "base", "a")),
        "link 'a'",
        '<link name="a">',
    ),
    "rotated-inertia": (_robot(_box_link("a", rpy="0 0.3 0"), _joint("j", "base", "a")), "link 'a'", '<link name="a">'),
    "massless": (_robot('<link name="a"/>\n', _joint("j", "base", "a")), "link 'a'", '<link name="a"/>'),
    "point-mass": (_robot(_box_link("a", moments=[0, 0, 0]), _joint("j", "base", "a")), "link 'a'", '<link name="a">'),
    "density": (_robot(_box_link("a", mass=100.0), _joint("j", "base", "a")), "link 'a'", '<link name="a">'),
    "com-outside": (_robot(_box_link("a", com="0.5 0 0"), _joint("j", "base", "a")), "link 'a'", '<link name="a">'),
    "inertia-vs-shape": (
        _robot(_box_link("a", moments=[4500.0] * 3), _joint("j", "base", "a")),  # kg mm^2 written as kg m^2
        "link 'a'",
        '<link name="a">',
    ),
    "limits-missing": (_robot(_box_link("a"), _joint("j", "base", "a", inner="")), "joint 'j'", '<joint name="j"'),
    "limits-incomplete": (
        _robot(_box_link("a"), _joint("j", "base", "a", inner='<limit lower="-1" upper="1"/>')),
        "joint 'j'",
        '<joint name="j"',
    ),
    "limits-inverted": (
        _robot(_box_link("a"), _joint("j", "base", "a", inner='<limit lower="1" upper="-1" effort="1" velocity="1"/>')),
        "joint 'j'",
        '<joint name="j"',
    ),
    "limits-empty": (
        _robot(_box_link("a"), _joint("j", "base", "a", inner='<limit lower="0" upper="0" effort="1" velocity="1"/>')),
        "joint 'j'",
        '<joint name="j"',
    ),
    "zero-effort": (
        _robot(_box_link("a"), _joint("j", "base", "a", inner='<limit lower="-1" upper="1" effort="0" velocity="1"/>')),
        "joint 'j'",
        '<joint name="j"',
    ),
    "zero-velocity": (
        _robot(_box_link("a"), _joint("j", "base", "a", kind="continuous", inner='<limit effort="1" velocity="0"/>')),
        "joint 'j'",
        '<joint name="j"',
    ),
    "mimic-unknown": (
        _robot(_box_link("a"), _joint("j", "base", "a", inner=LIMIT + '<mimic joint="nope"/>')),
        "joint 'j'",
        '<joint name="j"',
    ),
    "mimic-fixed": (
        _robot(
            _box_link("a"),
            _box_link("b"),
            _joint("f", "base", "a", "fixed", ""),
            _joint("j", "a", "b", inner=LIMIT + '<mimic joint="f"/>'),
        ),
        "joint 'j'",
        '<joint name="j"',
    ),
    "mimic-chain": (
        _robot(
            _box_link("a"),
            _box_link("b"),
            _box_link("c"),
            _joint("k", "base", "a"),
            _joint("l", "a", "b", inner=LIMIT + '<mimic joint="k"/>'),
            _joint("m", "b", "c", inner=LIMIT + '<mimic joint="l" multiplier="2"/>'),
        ),
        "joint 'm'",
        '<joint name="m"',
    ),
    "mimic-cycle": (
        _robot(
            _box_link("a"),
            _box_link("b"),
            _joint("k", "base", "a", inner=LIMIT + '<mimic joint="l"/>'),
            _joint("l", "a", "b", inner=LIMIT + '<mimic joint="k"/>'),
        ),
        "joint 'k'",
        '<joint name="k"',
    ),
    "mimic-zero": (
        _robot(
            _box_link("a"),
            _box_link("b"),
            _joint("k", "base", "a"),
            _joint("l", "a", "b", inner=LIMIT + '<mimic joint="k" multiplier="0"/>'),
        ),
        "joint 'l'",
        '<joint name="l"',
    ),
    "name-twice": (
        _robot(_box_link("a"), _box_link("a").replace("<link", "<link ", 1), _joint("j", "base", "a")),
        "link 'a'",
        '<link  name="a">',
    ),
    "unknown-link": (_robot(_box_link("a"), _joint("j", "base", "ghost")), "joint 'j'", '<joint name="j"'),
    "two-parents": (
        _robot(
            _box_link("a"), _box_link("b"), _joint("j", "base", "b"), _joint("k", "a", "b"), _joint("l", "base", "a")
        ),
        "link 'b'",
        '<joint name="k"',
    ),
    "disconnected": (
        _robot(_box_link("a"), _box_link("lost"), _joint("j", "base", "a")),
        "link 'lost'",
        '<link name="lost">',
    ),
    "cycle": (
        _robot(
            _box_link("a"),
            _box_link("b"),
            _box_link("c"),
            _joint("j", "base", "a"),
            _joint("k", "b", "c"),
            _joint("l", "c", "b"),
        ),
        "joint",
        "",
    ),
}
SEVERITY = {
    "rotated-inertia": "warning",
    "massless": "warning",
    "point-mass": "warning",
    "density": "warning",
    "com-outside": "warning",
    "inertia-vs-shape": "warning",
    "limits-empty": "warning",
    "zero-effort": "warning",
    "zero-velocity": "warning",
    "mimic-chain": "warning",
    "mimic-zero": "warning",
}


@pytest.mark.parametrize("code", sorted(CASES))
def test_each_finding_names_the_file_the_line_and_the_element(tmp_path, code):
    text, element, needle = CASES[code]
    path = tmp_path / f"{code}.urdf"
    path.write_text(text)
    result = audit(path)
    found = [f for f in result.findings if f.code == code]
    assert found, f"no {code} in {[str(f) for f in result.findings]}"
    f = found[0]
    assert f.file == str(path) and f.element.startswith(element)
    if needle:
        assert f.line == _line_of(text, needle), str(f)
    assert f.severity == SEVERITY.get(code, "error")
    assert str(f).startswith(f"{path}:{f.line}: {f.severity}: {f.element}: ")
    assert result.ok == (f.severity != "error" and not result.errors)


def test_a_consistent_robot_has_no_findings(tmp_path):
    # boxes of aluminium with their own inertia, limits, a mimic joint following a leader
    text = _robot(
        _box_link("a"),
        _box_link("b", com="0.01 0 0"),
        _joint("j", "base", "a"),
        _joint("k", "a", "b", inner=LIMIT + '<mimic joint="j" multiplier="-1"/>'),
    )
    path = tmp_path / "clean.urdf"
    path.write_text(text)
    result = audit(path)
    assert result.findings == [] and result.ok
    assert kd.load(path).audit().findings == []


def test_the_repaired_tensor_is_what_the_repair_policy_loads(tmp_path):
    text, _, _ = CASES["inertia-triangle"]
    path = tmp_path / "triangle.urdf"
    path.write_text(text)
    finding = next(f for f in audit(path).errors if f.code == "inertia-triangle")
    repaired = np.array(finding.data["repaired"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        loaded = kd.load(path, inertia="repair")
    np.testing.assert_allclose(np.array(loaded.links[0].inertia.inertia), repaired, atol=1e-12)
    check = Inertia(2.7, (0, 0, 0), repaired).consistency()
    assert check.ok and math.isclose(sum(check.moments[:2]), check.moments[2], rel_tol=1e-9)  # on the boundary
    # and the fix written in the message reads back as that tensor
    entries = _fix_tensor(finding.fix)
    assert [entries[k] for k in ("ixx", "iyy", "izz")] == pytest.approx(np.diag(repaired), rel=1e-5)


def test_the_fix_of_a_rotated_inconsistent_inertia_is_written_in_the_files_frame(tmp_path):
    original = _robot(_box_link("a", rpy="0.2 0.3 -0.1", moments=[0.1, 0.1, 0.5]), _joint("j", "base", "a"))
    path = tmp_path / "rotated_triangle.urdf"
    path.write_text(original)
    finding = next(f for f in audit(path).errors if f.code == "inertia-triangle")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        repaired = np.array(kd.load(path, inertia="repair").links[0].inertia.inertia)
    # the file with the fix pasted in (its <origin rpy> kept) loads, strictly, as the repaired tensor
    fixed = original.replace(
        INERTIA.format(0.1, 0.1, 0.5), "<inertia " + finding.fix.split("<inertia ")[1].split("/>")[0] + "/>"
    )
    path.write_text(fixed)
    loaded = np.array(kd.load(path, inertia="strict").links[0].inertia.inertia)
    np.testing.assert_allclose(loaded, repaired, atol=1e-6 * np.abs(repaired).max())


def test_the_rotated_inertia_fix_is_the_tensor_the_loader_uses(tmp_path):
    text = _robot(_box_link("a", rpy="0.2 0.3 -0.1", moments=[0.01, 0.02, 0.025]), _joint("j", "base", "a"))
    path = tmp_path / "rotated.urdf"
    path.write_text(text)
    finding = next(f for f in audit(path).findings if f.code == "rotated-inertia")
    entries = _fix_tensor(finding.fix)
    loaded = np.array(kd.load(path).links[0].inertia.inertia)
    for key, (r, c) in {
        "ixx": (0, 0),
        "ixy": (0, 1),
        "ixz": (0, 2),
        "iyy": (1, 1),
        "iyz": (1, 2),
        "izz": (2, 2),
    }.items():
        assert entries[key] == pytest.approx(loaded[r, c], rel=1e-5, abs=1e-12)


def test_units_a_mesh_in_millimetres_read_as_metres(tmp_path):
    pytest.importorskip("trimesh", reason="meshes are measured with trimesh (the viz extra)")
    import trimesh

    trimesh.creation.box(extents=(100.0, 100.0, 100.0)).export(tmp_path / "cube.stl")  # 100 mm, written in mm
    text = _robot(
        '<link name="a"><inertial><mass value="2.7"/>' + INERTIA.format(0.0045, 0.0045, 0.0045) + "</inertial>\n"
        '<collision><geometry><mesh filename="cube.stl"/></geometry></collision></link>\n',
        _joint("j", "base", "a"),
    )
    path = tmp_path / "mm.urdf"
    path.write_text(text)
    codes = {f.code: f for f in audit(path).findings}
    assert "units-mesh" in codes and 'scale="0.001 0.001 0.001"' in codes["units-mesh"].fix
    assert "millimetres" in codes["density"].message
    assert codes["units-mesh"].line == _line_of(text, "<collision>")
    # scaled as the fix says, the same mesh is a 0.1 m cube of aluminium: no finding
    path.write_text(text.replace('filename="cube.stl"', 'filename="cube.stl" scale="0.001 0.001 0.001"'))
    assert audit(path).findings == []


def test_files_urdfdom_refuses_are_errors_and_pinocchio_refuses_them_too(tmp_path):
    pin = pytest.importorskip("pinocchio")
    for code in ("limits-missing", "limits-incomplete"):
        path = tmp_path / f"{code}.urdf"
        path.write_text(CASES[code][0])
        with pytest.raises(ValueError):
            pin.buildModelFromUrdf(str(path))
        assert any(f.code == code and f.severity == "error" for f in audit(path).findings)


def test_the_audit_reports_files_the_loader_refuses_all_at_once(tmp_path):
    text = _robot(
        _box_link("a"), _box_link("a"), _box_link("lost"), _joint("j", "base", "a"), _joint("j", "a", "ghost")
    )
    path = tmp_path / "broken.urdf"
    path.write_text(text)
    with pytest.raises(ValueError):
        kd.load(path)
    codes = sorted(f.code for f in audit(path).errors)
    assert codes == ["disconnected", "name-twice", "name-twice", "unknown-link"]


def test_mjcf_findings_name_the_body_line(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(
        "<mujoco>\n<worldbody>\n"
        '<body name="a">\n<joint name="j" range="0 0"/>\n'
        '<inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.5"/>\n</body>\n'
        "</worldbody>\n</mujoco>\n"
    )
    result = audit(path)
    triangle = next(f for f in result.errors if f.code == "inertia-triangle")
    assert (triangle.file, triangle.line, triangle.element) == (str(path), 3, "link 'a'")
    empty = next(f for f in result.findings if f.code == "limits-empty")
    assert (empty.line, empty.element) == (4, "joint 'j'")
    assert not any(f.code == "limits-missing" for f in result.findings)  # MJCF joints need no range


def test_mjcf_links_between_the_joints_of_one_body_are_not_massless_links(tmp_path):
    path = tmp_path / "two_joints.xml"
    path.write_text(
        '<mujoco>\n<worldbody>\n<body name="a">\n<joint axis="1 0 0"/>\n<joint name="k" axis="0 1 0"/>\n'
        '<geom type="box" size="0.05 0.05 0.05" density="2700"/>\n</body>\n<body>\n<joint/>\n</body>\n</worldbody>\n</mujoco>\n'
    )
    result = audit(path)
    (massless,) = [f for f in result.findings if f.code == "massless"]  # the second, unnamed body
    assert (massless.element, massless.line) == ("link 'body2'", 8)
    assert kd.load(path).joint_names[0] == "joint0"  # the unnamed joint's name, as the audit numbers it


def test_a_robot_built_in_python_is_audited_from_its_description():
    robot = kd.robots.get("planar_2r")
    result = robot.audit()
    assert result.source and result.ok and all(f.line is None for f in result.findings)
    # an inertia no rigid body has, given in Python, is found in the description
    links = list(robot.description.links)
    links[0] = dataclasses.replace(links[0], inertia=Inertia(1.0, (0.1, 0, 0), np.diag([0.1, 0.1, 0.5])))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        bad = kd.Robot(dataclasses.replace(robot.description, links=tuple(links), source=""))
    (finding,) = bad.audit().errors
    assert finding.code == "inertia-triangle" and finding.element == f"link '{links[0].name}'" and finding.line is None


EXAMPLE_ROBOTS = None
try:
    import pinocchio as _pin

    EXAMPLE_ROBOTS = Path(_pin.__file__).parents[4] / "share" / "example-robot-data" / "robots"
except ImportError:  # pragma: no cover - the peers extra
    pass


@pytest.mark.skipif(EXAMPLE_ROBOTS is None or not EXAMPLE_ROBOTS.is_dir(), reason="example-robot-data is not installed")
def test_example_robot_data_files_that_exhibit_findings():
    romeo = EXAMPLE_ROBOTS / "romeo_description" / "urdf" / "romeo_small.urdf"
    flagged = {f.element[6:-1] for f in audit(romeo, geometry=False).errors if f.code.startswith("inertia")}
    # the loader's inertia policy names the same links (another route to the same verdict): the links
    # whose inertia the "repair" policy changes (its warnings are said once per process, so not those)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        raw = kd.load(romeo)
    repaired = kd.load(romeo, inertia="repair")
    before, after = raw.inertial_parameters().reshape(-1, 10), repaired.inertial_parameters().reshape(-1, 10)
    warned = {name for name, a, b in zip(raw.body_names, before, after) if not np.allclose(a, b)}
    assert flagged == warned and len(flagged) == 2
    pendulum = audit(EXAMPLE_ROBOTS / "double_pendulum_description" / "urdf" / "double_pendulum.urdf", geometry=False)
    assert {f.code for f in pendulum.findings} == {"limits-empty", "zero-effort", "zero-velocity"}
    alex = audit(EXAMPLE_ROBOTS / "alex_description" / "urdf" / "alex_psyonic_hands.urdf", geometry=False)
    assert any(f.code == "mimic-unknown" and "index_q1" in f.message for f in alex.errors)


def test_cli_table_json_and_strict(tmp_path, capsys):
    from kinedyn.cli import main

    path = tmp_path / "bad.urdf"
    path.write_text(CASES["inertia-triangle"][0])
    assert main(["audit", str(path)]) == 0
    out = capsys.readouterr().out
    assert "1 errors" in out and "line 3" in out and "link 'a'" in out  # the table wraps long findings
    assert main(["audit", str(path), "--strict"]) == 2
    capsys.readouterr()
    assert main(["audit", str(path), "--json", "--no-geometry"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["counts"]["error"] == 1 and document["findings"][0]["line"] == 3
    clean = tmp_path / "clean.urdf"
    clean.write_text(_robot(_box_link("a"), _joint("j", "base", "a")))
    assert main(["audit", str(clean), "--strict"]) == 0
    assert main(["audit", str(tmp_path / "missing.urdf")]) == 1


def test_the_report_has_an_audit_section(tmp_path):
    from kinedyn.report.data import collect
    from kinedyn.report.html import render_report

    path = tmp_path / "bad.urdf"
    path.write_text(CASES["limits-inverted"][0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = kd.load(path)
    data = collect(robot, t_end=0.05, eom_joints=0)
    assert data.to_dict()["audit"]["counts"]["error"] == 1
    page = render_report(robot, data)
    assert "<h3 id='audit'>Audit of the robot file</h3>" in page and "lower limit 1 is above upper limit -1" in page


# ----------------------------------------------------------------------------- what each tool makes of a file
TRIP = """<robot name="trip">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.1 0 0" rpy="0.4 0.7 0"/><mass value="2"/>
    <inertia ixx="0.03" iyy="0.05" izz="0.07" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b">{inertial}<collision><origin xyz="0 0 0.1"/><geometry><box size="0.1 0.1 0.2"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 1 0"/>{limit}</joint>
  <joint name="j2" type="continuous"><origin xyz="0.3 0 0"/><parent link="a"/><child link="b"/><axis xyz="1 0 0"/></joint>
</robot>"""


def test_the_cross_loader_diff_names_the_link_and_the_cause(tmp_path):
    pytest.importorskip("pinocchio")
    pytest.importorskip("mujoco")
    from kinedyn.analysis.loaders import compare_loaders

    path = tmp_path / "trip.urdf"
    path.write_text(TRIP.format(inertial="", limit=LIMIT))  # link b: collision shape, no <inertial>
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        diff = compare_loaders(path, samples=3)
    rows = {(r.tool, r.quantity): r for r in diff.rows}
    assert all(rows[("Pinocchio", q)].agrees for q in ("M(q)", "g(q)", "frames"))
    assert rows[("MuJoCo", "frames")].agrees and not diff.agree
    for q in ("M(q)", "g(q)"):
        r = rows[("MuJoCo", q)]
        assert r.difference > 0.1 and "link 'b'" in r.cause and "1000 kg/m^3 (2 kg)" in r.cause, str(r)
    # the cause checked by another route: the file with that inertia written in agrees with MuJoCo
    box = Inertia.box(2.0, (0.1, 0.1, 0.2))
    I = np.array(box.inertia)
    written = (
        f'<inertial><origin xyz="0 0 0.1"/><mass value="2"/>{INERTIA.format(I[0, 0], I[1, 1], I[2, 2])}</inertial>'
    )
    path.write_text(TRIP.format(inertial=written, limit=LIMIT))
    assert compare_loaders(path, samples=3).agree


def test_a_file_a_peer_refuses_is_a_row_saying_why(tmp_path, capsys):
    pytest.importorskip("mujoco")
    from kinedyn.cli import main

    path = tmp_path / "trip.urdf"
    path.write_text(TRIP.format(inertial="", limit=LIMIT).replace('izz="0.07"', 'izz="0.09"'))  # 0.03 + 0.05 < 0.09
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["audit", str(path), "--compare", "--json", "--samples", "2"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert "A + B >= C" in document["loaders"]["skipped"]["MuJoCo"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["audit", str(path), "--compare", "--strict", "--samples", "2"]) == 2


def test_a_damaged_file_is_audited_not_crashed_on():
    """Attribute values replaced by words, NaN, huge or empty numbers (seeded): the audit reports
    them as findings; only XML that is not well-formed stops it, with a ValueError naming the place."""
    import random
    import re

    base = _robot(
        _box_link("a", rpy="0 0.1 0"),
        _box_link("b"),
        _joint("j", "base", "a"),
        _joint("k", "a", "b", inner=LIMIT + '<mimic joint="j"/>'),
    )
    rng = random.Random(0)
    for _ in range(150):
        text = base
        for _ in range(3):
            m = rng.choice(list(re.finditer(r'"[^"]*"', text)))
            text = (
                text[: m.start()]
                + rng.choice(['""', '"nan"', '"x y z"', '"1e308"', '"-1"', '"0"', '"0 0"', '"inf"'])
                + text[m.end() :]
            )
        result = audit(text)
        assert all(f.severity in ("error", "warning", "info") and f.element for f in result.findings)
    with pytest.raises(ValueError, match="malformed XML"):
        audit(base.replace("<robot", "<robot <"))


def test_an_mjcf_file_is_compared_as_mujoco_and_pinocchio_read_it(tmp_path):
    pytest.importorskip("pinocchio")
    pytest.importorskip("mujoco")
    from kinedyn.analysis.loaders import compare_loaders

    path = tmp_path / "arm.xml"
    path.write_text(
        '<mujoco><option gravity="0.5 0 -9"/><worldbody><body name="a"><joint name="j1" axis="0 1 0" armature="0.1" ref="10"/>'
        '<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.04"/><body name="b" pos="0.3 0 0"><joint name="j2" axis="1 0 1"/>'
        '<geom type="box" size="0.1 0.02 0.03" pos="0.1 0 0"/></body></body></worldbody></mujoco>'
    )
    rows = {(r.tool, r.quantity): r for r in compare_loaders(path, samples=3).rows}
    assert all(rows[("MuJoCo", q)].agrees for q in ("M(q)", "g(q)", "frames"))
    assert rows[("Pinocchio", "M(q)")].agrees and rows[("Pinocchio", "frames")].agrees
    gravity = rows[("Pinocchio", "g(q)")]
    assert not gravity.agrees and "ignores <option gravity> (0.5 0 -9)" in gravity.cause
