"""`kinedyn report` for robots with floating, spherical and planar joints (issue 14 §1): q (nq) is
shown block by block, velocities per degree of freedom (nv), the 3-D viewer runs the same forward
kinematics on those blocks, and what does not apply says so on the page."""

from __future__ import annotations

import json
import os
import re

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
from kinedyn.cli import main  # noqa: E402
from kinedyn.report.html import build_report, collect, coordinate_labels, velocity_labels  # noqa: E402
from kinedyn.testing import example_robot_data_dir, random_robot  # noqa: E402


def _block(page: str, element_id: str) -> dict:
    m = re.search(rf'<script type="application/json" id="{element_id}">(.*?)</script>', page, re.S)
    return json.loads(m.group(1))


def _section(page: str, section_id: str) -> str:
    start = page.index(f"<section id='{section_id}'>")
    return page[start : page.index("</section>", start)]


@pytest.fixture(scope="module")
def every_kind():
    robot = random_robot(5, n=4, floating=True, spherical=0.4, planar=0.3, friction=False)
    assert [j.kind for j in robot.joints] == ["floating", "prismatic", "spherical", "planar"]
    return robot


@pytest.fixture(scope="module")
def every_kind_page(every_kind):
    rng = np.random.default_rng(3)
    q = every_kind.random_configuration(rng)
    qd = rng.uniform(-0.5, 0.5, every_kind.nv)
    return q, qd, build_report(every_kind, q, qd, t_end=0.3)


def test_report_of_every_joint_kind_shows_q_by_block_and_velocities_by_degree_of_freedom(every_kind, every_kind_page):
    robot = every_kind
    q, qd, page = every_kind_page
    d = _block(page, "kinedyn-data")
    assert (d["nq"], d["nv"]) == (robot.nq, robot.nv) == (16, 13)
    np.testing.assert_array_equal(d["q"], q)
    assert d["coordinate_labels"][:7] == ["j1.x", "j1.y", "j1.z", "j1.qx", "j1.qy", "j1.qz", "j1.qw"]
    assert d["velocity_labels"][3:6] == ["j1.ωx", "j1.ωy", "j1.ωz"] and d["velocity_labels"][-3:] == [
        "j4.vx",
        "j4.vy",
        "j4.ω",
    ]
    assert len(d["coordinate_labels"]) == robot.nq and len(d["velocity_labels"]) == robot.nv
    # the joints table says where each joint sits in q and qd
    description = _section(page, "description")
    assert "q[0:7] = (x, y, z, qx, qy, qz, qw)" in description and "q̇[0:6] = (vx, vy, vz, ωx, ωy, ωz)" in description
    assert "q[12:16] = (x, y, cos θ, sin θ)" in description and "id='multi-dof-note'" in description
    # the numbers are the library's at the manifold's q: Jacobian (nv columns named per DOF), M, g
    np.testing.assert_allclose(d["jacobian"], robot.jacobian(q), atol=1e-12)
    np.testing.assert_allclose(d["mass_matrix"], robot.mass_matrix(q), atol=1e-12)
    np.testing.assert_allclose(d["gravity_torque"], robot.gravity_torque(q), atol=1e-12)
    view = _section(page, "view")
    assert "<th>j1.ωz</th>" in view and "Configuration by joint" in view and "id='sliders-note'" in view
    # every property holds, dM/dt taken on the manifold (q + t qd would not even have nq entries)
    assert all(p["ok"] for p in d["properties"]), d["properties"]
    assert any("along q ⊕ t q̇" in p["measure"] for p in d["properties"])
    # the simulation's samples are configurations (unit quaternions), plotted per kind of entry
    sim = np.array(d["simulation"]["q"])
    assert sim.shape[1] == robot.nq and np.allclose(np.linalg.norm(sim[:, 3:7], axis=1), 1.0)
    dynamics = _section(page, "dynamics")
    for title in ("joint positions", "positions of the multi-DOF joints", "orientations of the multi-DOF joints"):
        assert f'aria-label="{title}' in dynamics
    assert "id='free-fall-note'" in dynamics
    # the equations: skipped for size, saying how to get them
    assert "--eom-joints 13" in _section(page, "equations") and "ZYX Euler angles" in _section(page, "equations")
    # the viewer's model: each body's block of q, a slider per 1-DOF coordinate and per position
    model = _block(page, "kinedyn-model")
    assert [b["q"] for b in model["bodies"]] == [0, 7, 8, 12]
    assert [s["name"] for s in model["sliders"]] == ["j1.x", "j1.y", "j1.z", "j2", "j4.x", "j4.y"]


def test_a_configuration_that_is_not_unit_is_refused(every_kind):
    q = every_kind.neutral()
    q[6] = 2.0
    with pytest.raises(ValueError, match="joint 'j1'.*quaternion"):
        collect(every_kind, q)
    with pytest.raises(ValueError, match="q needs 16 values and qd 13"):
        collect(every_kind, every_kind.neutral()[:-1])


def test_the_viewer_moves_every_joint_kind_as_the_library_does(browser, every_kind, every_kind_page, tmp_path):
    """viewer.js's forward kinematics on the q blocks (free-flyer, spherical, planar) equals
    robot.frame_poses at random configurations; the playback and sliders run without a console error."""
    robot = every_kind
    q, _, page = every_kind_page
    path = tmp_path / "every_kind.html"
    path.write_text(page, encoding="utf-8")
    context = browser.new_context(viewport={"width": 1000, "height": 900})
    tab = context.new_page()
    errors = []
    tab.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    tab.on("pageerror", lambda e: errors.append(str(e)))
    tab.goto(path.resolve().as_uri())
    tab.wait_for_function("window.kinedyn && window.kinedyn.ready()")
    # the new tables and notes fit their cards at 1000 px, slider labels stay clear (test_report_layout's checks)
    from test_report_layout import OVERFLOWS, SLIDER_OVERLAPS

    assert tab.evaluate("document.documentElement.scrollWidth") <= 1000
    assert tab.evaluate(OVERFLOWS) == [] and tab.evaluate(SLIDER_OVERLAPS) == []
    for qs in robot.random_configuration(np.random.default_rng(4), size=3):
        frames = tab.evaluate("(q) => window.kinedyn.fk(q).frames", qs.tolist())
        for name, pose in zip(robot.frame_names, robot.frame_poses(qs)):
            np.testing.assert_allclose(np.array(frames[name]).reshape(4, 4), pose, atol=1e-12, err_msg=name)
    # the q readout names the blocks' entries; a slider moves the base's z
    assert "j1.qw = " in tab.locator("#kinedyn-q").inner_text()
    sliders = tab.locator("#kinedyn-sliders input")
    assert sliders.count() == 6
    sliders.nth(2).fill("0.25")
    assert abs(tab.evaluate("window.kinedyn.q()[2]") - float(sliders.nth(2).input_value())) < 1e-12
    tab.locator("#kinedyn-time").fill("5")
    assert np.allclose(tab.evaluate("window.kinedyn.q()"), _block(page, "kinedyn-data")["simulation"]["q"][5])
    assert errors == []
    context.close()


@pytest.mark.parametrize(
    "urdf, joints",
    [("solo_description/robots/solo12.urdf", 13), ("hector_description/robots/quadrotor_base.urdf", 1)],
    ids=["solo12", "hector"],
)
def test_kinedyn_report_floating_base_on_real_robots(capsys, tmp_path, urdf, joints):
    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    path = os.path.join(root, urdf)
    out = tmp_path / "report.html"
    assert main(["report", path, "--floating-base", "-o", str(out), "--t", "0.2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    robot = kd.Robot.from_urdf(path, floating_base=True)
    assert (doc["nq"], doc["nv"]) == (robot.nq, robot.nv) and len(doc["joints"]) == joints
    assert all(p["ok"] for p in doc["properties"]), doc["properties"]
    page = out.read_text(encoding="utf-8")
    for section in ("view", "description", "equations", "dynamics"):
        assert f"<section id='{section}'>" in page
    assert f"{joints} joint{'s' if joints != 1 else ''} · nq = {robot.nq}, nv = {robot.nv}" in page
    assert coordinate_labels(robot)[:7] == ["root_joint." + e for e in ("x", "y", "z", "qx", "qy", "qz", "qw")]
    assert velocity_labels(robot)[6:] == robot.joint_names[1:]
    # a configuration given on the command line: nq numbers, the quaternion checked
    q = robot.random_configuration(1)
    assert main(["report", path, "--floating-base", "-o", str(out), "--t", "0.1", "--json", "--q", *map(str, q)]) == 0
    np.testing.assert_allclose(json.loads(capsys.readouterr().out)["q"], q)


def test_the_equations_of_a_small_multi_dof_robot_are_typeset_in_euler_angles():
    """A ball-jointed pendulum (nv = 3): the symbolic section derives the equations in the engine's
    ZYX Euler angles and says so, naming its coordinates (they are not the numeric q)."""
    ball = kd.Robot(
        [
            kd.Link(
                "bob",
                None,
                kd.Joint("shoulder", "spherical"),
                inertia=kd.Inertia(1.0, (0, 0, -0.3), np.diag([0.02, 0.03, 0.01])),
            )
        ],
        name="ball_pendulum",
    )
    page = build_report(ball, t_end=0.2)
    equations = _section(page, "equations")
    assert "(shoulder_yaw, shoulder_pitch, shoulder_roll)" in equations and "ZYX Euler angles" in equations
    assert equations.count("<math") >= 4
    d = _block(page, "kinedyn-data")
    assert (d["nq"], d["nv"]) == (4, 3) and all(p["ok"] for p in d["properties"])
