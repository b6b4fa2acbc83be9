"""Seeing robots (issue 13 §1-§3): URDF <visual>/<collision>/<material>, mesh paths found and bounded,
solid links for robots without meshes; the report's 3-D view draws every mesh with plotly.js inlined
(file://, no request, no console error, mesh pixels that follow the sliders); the live viewer (viser on
localhost) does the same."""

from __future__ import annotations

import io
import os
import socket
import time

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

from reference import PANDA, UR5, erd  # noqa: E402

import kinedyn as kd  # noqa: E402
from kinedyn.description.geometry import Box, Cylinder, Mesh, MeshNotFound, Sphere, resolve_mesh  # noqa: E402
from kinedyn.report.html import default_configuration  # noqa: E402
from kinedyn.visual import MissingMeshWarning, robot_scene  # noqa: E402

trimesh = pytest.importorskip("trimesh", reason="the viz extra is not installed")

URDF = """<robot name="shapes">
  <material name="signal_red"><color rgba="0.8 0.1 0.1 1"/></material>
  <link name="base"/>
  <link name="arm">
    <visual><origin xyz="0 0 0.25" rpy="0 0 0"/><geometry><cylinder radius="0.05" length="0.5"/></geometry><material name="signal_red"/></visual>
    <visual><origin xyz="0.1 0 0.5"/><geometry><box size="0.2 0.1 0.05"/></geometry><material name="own"><color rgba="0 0 1 0.5"/></material></visual>
    <visual><geometry><mesh filename="{mesh}" scale="2 1 1"/></geometry></visual>
    <collision><geometry><sphere radius="0.3"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>
</robot>
"""


@pytest.fixture
def mesh_folder(tmp_path):
    """A ROS-like layout: pkg/urdf/robot.urdf next to pkg/meshes/cube.stl (a 0.1 m cube at x = 1)."""
    (tmp_path / "pkg" / "urdf").mkdir(parents=True)
    (tmp_path / "pkg" / "meshes").mkdir()
    cube = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    cube.apply_translation((1.0, 0.0, 0.0))
    cube.export(tmp_path / "pkg" / "meshes" / "cube.stl")
    return tmp_path


def write_urdf(folder, mesh: str):
    path = folder / "pkg" / "urdf" / "robot.urdf"
    path.write_text(URDF.replace("{mesh}", mesh))
    return path


# ------------------------------------------------------------------ §1 description
def test_urdf_visuals_materials_origins_and_collisions(mesh_folder):
    robot = kd.Robot.from_urdf(write_urdf(mesh_folder, "../meshes/cube.stl"))
    cyl, box, mesh = robot.visuals
    assert isinstance(cyl.shape, Cylinder) and cyl.shape.radius == 0.05 and cyl.shape.length == 0.5
    assert cyl.rgba == (0.8, 0.1, 0.1, 1.0) and cyl.material == "signal_red"  # the robot-level material
    np.testing.assert_allclose(cyl.origin[:3, 3], [0, 0, 0.25])
    assert isinstance(box.shape, Box) and box.shape.size == (0.2, 0.1, 0.05) and box.rgba == (0.0, 0.0, 1.0, 0.5)
    assert isinstance(mesh.shape, Mesh) and mesh.shape.scale == (2.0, 1.0, 1.0) and mesh.rgba is None
    assert mesh.where.endswith("robot.urdf:7")  # file:line of its <visual>
    (sphere,) = robot.collisions
    assert isinstance(sphere.shape, Sphere) and sphere.shape.radius == 0.3
    # the scene: the cube mesh read, scaled (x 2 along x: centre at x = 2, 0.2 wide), every shape drawn
    scene = robot_scene(robot)
    assert scene.shapes == scene.drawn == 3 and not scene.missing
    cube = [p.part for p in scene.parts if p.visual == 2]
    v = np.vstack([c.vertices for c in cube])
    np.testing.assert_allclose(v.min(axis=0), [1.9, -0.05, -0.05], atol=1e-6)
    np.testing.assert_allclose(v.max(axis=0), [2.1, 0.05, 0.05], atol=1e-6)
    # the box at its origin, the cylinder along z from 0 to 0.5
    boxv = np.vstack([p.part.vertices for p in scene.parts if p.visual == 1])
    np.testing.assert_allclose(boxv.min(axis=0), [0.0, -0.05, 0.475], atol=1e-6)
    cylv = np.vstack([p.part.vertices for p in scene.parts if p.visual == 0])
    np.testing.assert_allclose([cylv[:, 2].min(), cylv[:, 2].max()], [0.0, 0.5], atol=1e-6)
    assert robot_scene(robot, "collision").drawn == 1


@pytest.mark.parametrize(
    "xml, message",
    [
        ('<cylinder radius="0.1"/>', "has no 'length' attribute"),
        ("<mesh/>", "<mesh> needs a filename"),
        ("<cone/>", "holds none of"),
    ],
)
def test_bad_visuals_name_file_line_and_link(xml, message):
    text = (
        f'<robot name="r">\n<link name="a"/>\n<link name="b"><visual><geometry>{xml}</geometry></visual></link>\n'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit lower="-1" upper="1"/></joint></robot>'
    )
    with pytest.raises(ValueError, match=message) as e:
        kd.Robot.from_urdf(text)
    assert "<URDF string>:3" in str(e.value) and "link 'b'" in str(e.value)


def test_mesh_paths_resolve_in_order_and_stay_inside(mesh_folder, monkeypatch):
    base = str(mesh_folder / "pkg" / "urdf")
    cube = (mesh_folder / "pkg" / "meshes" / "cube.stl").resolve()
    # package:// through the URDF's parents (a folder named like the package), and ROS_PACKAGE_PATH
    assert resolve_mesh("package://pkg/meshes/cube.stl", base).resolve() == cube
    elsewhere = mesh_folder / "ros" / "pkg" / "meshes"
    elsewhere.mkdir(parents=True)
    (elsewhere / "cube.stl").write_bytes(cube.read_bytes())
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(mesh_folder / "ros"))
    assert (
        resolve_mesh("package://pkg/meshes/cube.stl", base).resolve() == (elsewhere / "cube.stl").resolve()
    )  # ROS_PACKAGE_PATH first
    # relative: the URDF's folder, then its parents
    assert resolve_mesh("meshes/cube.stl", base).resolve() == cube
    # a package path may not climb out of its package; a file that is not a mesh is never read
    with pytest.raises(ValueError, match="without '..'"):
        resolve_mesh("package://pkg/../../etc/passwd.stl", base)
    with pytest.raises(ValueError, match="not a mesh file name"):
        resolve_mesh("/etc/passwd", base)
    os.symlink("/etc/hostname", mesh_folder / "pkg" / "meshes" / "link.stl")
    with pytest.raises(MeshNotFound):
        resolve_mesh("package://pkg/meshes/link.stl", base)  # a mesh name pointing at another file
    with pytest.raises(MeshNotFound, match="nothere.stl"):
        resolve_mesh("package://pkg/meshes/nothere.stl", base)


def test_example_robot_data_meshes_are_found():
    robot = kd.Robot.from_urdf(erd(*PANDA))
    scene = robot_scene(robot)
    assert scene.shapes == len(robot.visuals) == 11
    assert scene.drawn == scene.shapes and not scene.missing  # no mesh dropped
    assert {p.visual for p in scene.parts} == set(range(11))
    assert scene.triangles <= 1.05 * 120_000  # decimated to the budget (the files hold ~600k)


def test_missing_or_oversized_mesh_is_a_warning_naming_the_file(mesh_folder, monkeypatch):
    robot = kd.Robot.from_urdf(write_urdf(mesh_folder, "../meshes/missing.stl"))
    with pytest.warns(MissingMeshWarning, match=r"missing\.stl.*stick figure"):
        scene = robot_scene(robot)
    assert scene.shapes == 3 and scene.drawn == 2 and len(scene.missing) == 1
    from kinedyn.visual import meshes

    monkeypatch.setattr(meshes, "MAX_MESH_BYTES", 100)
    robot = kd.Robot.from_urdf(write_urdf(mesh_folder, "../meshes/cube.stl"))
    with pytest.warns(MissingMeshWarning, match=r"cube\.stl' is .* MiB, more than"):
        scene = robot_scene(robot)
    assert scene.drawn == 2


def test_robots_without_meshes_get_solid_links():
    """Every built-in: cylinders that reach every joint and the tool (DH: along d and a)."""
    for name in kd.robots.names():
        robot = kd.robots.get(name)
        scene = robot_scene(robot)
        assert scene.generated and scene.shapes == 0 and len(scene.parts) >= robot.n
        q = default_configuration(robot)
        poses = dict(zip(robot.frame_names, robot.frame_poses(q)))
        world = np.vstack([p.part.vertices @ poses[p.frame][:3, :3].T + poses[p.frame][:3, 3] for p in scene.parts])
        qs = robot.random_configuration(np.random.default_rng(1), size=32)
        reach = max(float(np.max(np.linalg.norm(robot.frame_poses(qs)[..., :3, 3], axis=-1))), 0.05)
        for point in [*robot.forward_kinematics(q)[:, :3, 3], robot.pose(q)[:3, 3]]:
            assert np.min(np.linalg.norm(world - point, axis=1)) < 0.12 * reach, (name, point)
    # prismatic joints: a rail on the parent as long as the travel (without limits: the robot's reach)
    cart = kd.robots.cartesian_2p()
    rails = [np.ptp(p.part.vertices, axis=0).max() for p in robot_scene(cart).parts if p.frame == "base"]
    assert max(rails) > 1.0, rails
    # standard DH: the puma's link 2 (a2 = 0.4318 along x, d = 0) is one cylinder along its x axis
    puma = kd.robots.puma560()
    parts = [p.part for p in robot_scene(puma).parts if p.frame == "link2" and p.part.rgba[0] < 0.9]
    spans = [np.ptp(p.vertices, axis=0) for p in parts]
    assert any(abs(s[0] - 0.4318) < 1e-3 and s[1] < 0.1 for s in spans), spans
    # link 3 (d3 = 0.15005, a3 = 0.0203): one cylinder along d (z of frame 2: y of link 3's frame),
    # then one along a (x of link 3's frame), not a slanted bar between the joints
    spans = [
        np.ptp(p.part.vertices, axis=0) for p in robot_scene(puma).parts if p.frame == "link3" and p.part.rgba[0] < 0.9
    ]
    assert any(abs(s[1] - 0.15005) < 1e-3 for s in spans) and any(abs(s[0] - 0.0203) < 1e-3 for s in spans), spans


# ------------------------------------------------------------------ §2 the report
@pytest.fixture(scope="module")
def panda_report(tmp_path_factory):
    from kinedyn.report.html import write_report

    robot = kd.Robot.from_urdf(erd(*PANDA))
    path = tmp_path_factory.mktemp("panda") / "panda.html"
    write_report(robot, path, t_end=0.5)
    return robot, path


def model_block(page: str) -> dict:
    import json
    import re

    m = re.search(r'<script type="application/json" id="kinedyn-model">(.*?)</script>', page, re.S)
    return json.loads(m.group(1))


def test_panda_report_sends_each_mesh_once_within_budget(panda_report):
    robot, path = panda_report
    page = path.read_text()
    assert path.stat().st_size < 15e6
    model = model_block(page)
    assert model["shapes"] == model["shapes_drawn"] == len(robot.visuals)
    assert {m["visual"] for m in model["meshes"]} == set(range(len(robot.visuals)))
    # vertices decode back to the scene's within the 16-bit quantum
    import base64

    scene = robot_scene(robot)
    m, sp = model["meshes"][3], scene.parts[3]
    u = np.frombuffer(base64.b64decode(m["vertices"]), dtype="<u2").reshape(-1, 3)
    np.testing.assert_allclose(np.asarray(m["lo"]) + u * np.asarray(m["step"]), sp.part.vertices, atol=2e-5)
    # no element that fetches anything (scripts are inline; their text is checked in Chromium below)
    import re

    markup = re.sub(r"<script([^>]*)>.*?</script>", r"<script\1></script>", page, flags=re.S)
    assert not re.search(r"<(script|img|iframe|link|source)[^>]+(src|href)=", markup, re.I)
    assert "<link" not in markup and "@import" not in markup and "url(http" not in markup


def nonblank_diff(a: bytes, b: bytes) -> float:
    """Fraction of pixels that differ between two screenshots of the same deterministic rendering."""
    from PIL import Image

    x = np.asarray(Image.open(io.BytesIO(a)).convert("RGB")).astype(int)
    y = np.asarray(Image.open(io.BytesIO(b)).convert("RGB")).astype(int)
    return float(np.mean(np.any(np.abs(x - y) > 8, axis=-1)))


def watch(page, allowed_prefix: str):
    requests, errors = [], []
    page.on("request", lambda r: requests.append(r.url))
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    return requests, errors


def test_panda_report_draws_the_meshes_in_chromium(browser, panda_report):
    robot, path = panda_report
    context = browser.new_context(viewport={"width": 1280, "height": 1000})
    page = context.new_page()
    requests, errors = watch(page, "file:")
    url = path.resolve().as_uri()
    page.goto(url)
    page.wait_for_function("window.kinedyn && window.kinedyn.ready()", timeout=60000)
    page.evaluate("window.kinedyn.ready()")
    view = page.locator("#kinedyn-view")
    time.sleep(0.5)
    shown = view.screenshot()
    # every visual reached the page's traces: none silently dropped
    assert page.evaluate("window.kinedyn.drawnVisuals()") == list(range(len(robot.visuals)))
    # mesh pixels over a large part of the view: hide the mesh traces and compare
    page.evaluate("""() => { const v = document.getElementById('kinedyn-view');
        const idx = v.data.map((t, i) => t.type === 'mesh3d' ? i : -1).filter((i) => i >= 0);
        return Plotly.restyle(v, {visible: false}, idx); }""")
    time.sleep(0.5)
    hidden = view.screenshot()
    if os.environ.get("KINEDYN_VISUAL_SCREENSHOTS"):  # for a person to look at
        for name, png in (("panda-report.png", shown), ("panda-report-no-meshes.png", hidden)):
            open(os.path.join(os.environ["KINEDYN_VISUAL_SCREENSHOTS"], name), "wb").write(png)
    assert nonblank_diff(shown, hidden) > 0.06
    page.evaluate("""() => { const v = document.getElementById('kinedyn-view');
        const idx = v.data.map((t, i) => t.type === 'mesh3d' ? i : -1).filter((i) => i >= 0);
        return Plotly.restyle(v, {visible: true}, idx); }""")
    # a slider moves the meshes, the tool pose table and the q text
    slider = page.locator("#kinedyn-sliders input").nth(1)
    slider.fill("0.9")
    page.evaluate("window.kinedyn.ready()")
    time.sleep(0.5)
    moved = view.screenshot()
    assert nonblank_diff(shown, moved) > 0.01
    q = np.array(page.evaluate("window.kinedyn.q()"))
    assert abs(q[1] - 0.9) < 0.01
    cells = [float(c.inner_text()) for c in page.locator("table.pose tbody td.num").all()]
    np.testing.assert_allclose(np.reshape(cells, (4, 4)), robot.pose(q), atol=2e-6)
    assert f"{q[1]:.6g} rad" in page.locator("#kinedyn-q").inner_text()
    # playback of the simulation moves the arm too
    page.locator("#kinedyn-time").fill("100")
    page.evaluate("window.kinedyn.ready()")
    assert not np.allclose(page.evaluate("window.kinedyn.q()"), q)
    assert requests == [url], requests
    assert errors == [], errors
    context.close()


# ------------------------------------------------------------------ §3 the live viewer
def settled_screenshot(page, timeout: float = 40.0) -> bytes:
    """A screenshot once the picture stops changing (viser streams the meshes and fades them in)."""
    last = page.screenshot()
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        time.sleep(1.0)
        shot = page.screenshot()
        if nonblank_diff(shot, last) == 0.0:
            return shot
        last = shot
    return last


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_live_viewer_of_the_panda(browser):
    pytest.importorskip("viser", reason="the viz extra is not installed")
    robot = kd.Robot.from_urdf(erd(*PANDA))
    viewer = robot.show(block=False, port=free_port(), verbose=False)
    try:
        assert viewer.scene.drawn == len(robot.visuals) and len(viewer._mesh_handles) == len(viewer.scene.parts)
        context = browser.new_context(viewport={"width": 720, "height": 480})
        page = context.new_page()
        requests, errors = watch(page, viewer.url)
        page.goto(viewer.url)
        page.wait_for_selector("canvas", timeout=60000)
        shown = settled_screenshot(page)
        for h in viewer._mesh_handles:
            h.visible = False
        hidden = settled_screenshot(page)
        if os.environ.get("KINEDYN_VISUAL_SCREENSHOTS"):  # for a person to look at
            for name, png in (("panda-viewer.png", shown), ("panda-viewer-no-meshes.png", hidden)):
                open(os.path.join(os.environ["KINEDYN_VISUAL_SCREENSHOTS"], name), "wb").write(png)
        assert nonblank_diff(shown, hidden) > 0.03
        for h in viewer._mesh_handles:
            h.visible = True
        viewer._sliders[1].value = 0.9  # as a user moving the slider: the callback moves the robot
        moved = settled_screenshot(page)
        assert viewer.q[1] == pytest.approx(0.9)
        assert nonblank_diff(shown, moved) > 0.01
        hosts = {u.split("/")[2] for u in requests if "://" in u and not u.startswith(("data:", "blob:"))}
        assert hosts == {viewer.url.split("/")[2]}, hosts
        assert errors == [], errors
        context.close()
    finally:
        viewer.close()


def test_trajectory_show_plays_back(tmp_path):
    pytest.importorskip("viser", reason="the viz extra is not installed")
    robot = kd.robots.planar_2r()
    traj = kd.simulate.simulate(robot, (0.0, 0.5), np.r_[0.5, -0.5, 0.0, 0.0], dt=1e-3)
    viewer = traj.show(block=False, port=free_port(), verbose=False)
    try:
        viewer.show_time(0.25)
        k = int(np.searchsorted(traj.t, 0.25, side="right") - 1)
        np.testing.assert_allclose(viewer.q, traj.q[k])
        viewer.play(speed=5.0)
        time.sleep(1.0)
        np.testing.assert_allclose(viewer.q, traj.q[-1])
    finally:
        viewer.close()


def test_view_command(capsys):
    pytest.importorskip("viser", reason="the viz extra is not installed")
    from kinedyn.cli import main

    assert (
        main(
            ["view", "puma560", "--q", "0", "30", "0", "0", "0", "0", "--deg", "--no-wait", "--port", str(free_port())]
        )
        == 0
    )
    assert "http://localhost:" in capsys.readouterr().out


def test_html_animations_are_offline(tmp_path, browser):
    """Trajectory.animate(.html): a robot's is the mesh view (each mesh once, joint values per frame),
    any other system's is matplotlib's player without its CDN stylesheet; neither fetches anything."""
    import matplotlib

    matplotlib.use("Agg")
    from kinedyn.simulate.systems import MechanicalSystem

    robot = kd.Robot.from_urdf(erd(*UR5))
    traj = kd.simulate.simulate(robot, (0.0, 0.4), np.zeros(2 * robot.n), dt=1e-3)
    path = traj.animate(tmp_path / "ur5.html", fps=25)
    page = path.read_text()
    assert 'id="kinedyn-model"' in page and page.count('"vertices"') == len(model_block(page)["meshes"])
    assert model_block(page)["shapes_drawn"] == len(robot.visuals)
    pendulum = MechanicalSystem(
        1,
        lambda q: np.eye(1),
        lambda q, qd: np.array([9.81 * np.sin(q[0])]),
        points=lambda q: np.array([[0.0, 0.0], [np.sin(q[0]), -np.cos(q[0])]]),
        name="pendulum",
    )
    swing = kd.simulate.simulate(pendulum, (0.0, 0.2), np.array([0.5, 0.0]), dt=1e-2)
    other = swing.animate(tmp_path / "pendulum.html", fps=10).read_text()
    assert "font-awesome" not in other and "<link" not in other and "\u25b6" in other
    context = browser.new_context()
    for p in (path, tmp_path / "pendulum.html"):
        tab = context.new_page()
        requests, errors = watch(tab, "file:")
        tab.goto(p.resolve().as_uri())
        tab.wait_for_load_state("load")
        if p == path:
            tab.wait_for_function("window.kinedyn && window.kinedyn.ready()", timeout=60000)
            tab.evaluate("window.kinedyn.ready()")
            assert tab.evaluate("window.kinedyn.drawnVisuals()") == list(range(len(robot.visuals)))
        assert requests == [p.resolve().as_uri()], requests
        assert errors == [], errors
    context.close()


def test_robot_files_name_meshes_and_shapes(tmp_path):
    """YAML visuals: (link, mesh|box|cylinder|sphere, scale, origin, color) on a DH robot's links; a
    mesh path relative to the file; saved and loaded again; bad entries name the entry."""
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(tmp_path / "cube.stl")
    (tmp_path / "arm.yaml").write_text("""name: arm
joints:
  - {a: 0.5}
  - {a: 0.4}
visuals:
  - {link: link1, box: [0.5, 0.08, 0.08], origin: {xyz: [-0.25, 0, 0]}, color: [0.2, 0.4, 0.8, 1]}
  - {link: link2, mesh: cube.stl, scale: [4, 0.8, 0.8], origin: {xyz: [-0.2, 0, 0]}}
  - {link: tool, cylinder: {radius: 0.02, length: 0.1}}
""")
    robot = kd.load(tmp_path / "arm.yaml")
    scene = robot_scene(robot)
    assert scene.shapes == scene.drawn == 3 and not scene.generated
    mesh = np.vstack([p.part.vertices for p in scene.parts if p.visual == 1])
    np.testing.assert_allclose(mesh.min(axis=0), [-0.4, -0.04, -0.04], atol=1e-6)
    assert [p.part.rgba for p in scene.parts if p.visual == 0] == [(0.2, 0.4, 0.8, 1.0)]
    robot.save(tmp_path / "again.yaml")
    again = kd.load(tmp_path / "again.yaml")
    assert len(again.visuals) == 3 and robot_scene(again).drawn == 3
    text = (tmp_path / "arm.yaml").read_text()
    for bad, message in [
        ("box: [0.5, 0.08, 0.08]", "visuals\\[0\\].*exactly one of"),
        ("link: link2", "names links \\['nope'\\]"),
    ]:
        (tmp_path / "bad.yaml").write_text(text.replace(bad, bad + ", sphere: 1" if "box" in bad else "link: nope"))
        with pytest.raises(ValueError, match=message):
            kd.load(tmp_path / "bad.yaml")


def test_live_viewer_of_a_floating_robot():
    """A free-flyer, spherical and planar robot in the live viewer: q has nq entries, a slider per
    1-DOF joint moves its own entry of q (not the quaternion's), the tool follows the library's pose."""
    pytest.importorskip("viser", reason="the viz extra is not installed")
    from kinedyn.testing import random_robot

    robot = random_robot(seed=0, n=6, floating=True, spherical=0.3, planar=0.3)  # every joint kind
    q = robot.random_configuration(1)
    viewer = robot.show(q, block=False, port=free_port(), verbose=False)
    try:
        one_dof = [k for k, j in enumerate(robot.joints) if not j.is_multi_dof]
        starts = np.cumsum([0] + [j.nq for j in robot.joints])[:-1]
        assert viewer._slider_coordinates == [int(starts[k]) for k in one_dof] and len(viewer._sliders) == len(one_dof)
        k, i = len(viewer._sliders) - 1, viewer._slider_coordinates[-1]
        viewer._sliders[k].value = 0.3  # as a user moving the last slider
        expected = q.copy()
        expected[i] = 0.3
        np.testing.assert_array_equal(viewer.q, expected)
        tool = robot.frame_poses(expected)[robot.frame_names.index(robot.tool)]
        np.testing.assert_allclose(viewer._tool.position, tool[:3, 3], atol=1e-12)
        with pytest.raises(ValueError, match=f"q needs {robot.nq} finite values"):
            viewer.set_q(np.zeros(robot.nv))
    finally:
        viewer.close()
