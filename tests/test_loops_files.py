"""Closed loops in robot files: MJCF <equality><connect>/<weld> read as MuJoCo defines them (MuJoCo
as the oracle: its constraint residuals efc_pos against kinedyn's frame poses), the URDF <loop>
extension, the YAML/TOML `loops:` section, the writers and `kinedyn convert` keeping them, and the
errors that name file, line and element."""

from __future__ import annotations

import ast
import re
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.convert import convert

MJCF = """<mujoco model="loops"><compiler angle="radian"/>
<worldbody>
 <body name="crank" pos="0 0 0.1" euler="0.1 0.2 0.3"><joint name="j1" axis="0 0 1" ref="0.3"/>
   <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/>
   <body name="coupler" pos="0.2 0 0"><joint name="j2" axis="0 0 1" pos="0.01 0 0" ref="-0.2"/>
     <geom type="capsule" fromto="0 0 0 0.4 0.1 0" size="0.01"/>
     <site name="c_end" pos="0.4 0.1 0" euler="0.3 0 0.1"/>
   </body>
 </body>
 <frame pos="0.3 0 0.1" euler="0.1 0.2 0.3">
  <body name="rocker" pos="0.05 0 0"><joint name="j3" type="ball"/>
   <geom type="capsule" fromto="0 0 0 0 0.3 0" size="0.01"/>
   <site name="r_end" pos="0 0.3 0"/>
  </body>
 </frame>
 <body name="float" pos="0.5 0.5 0.5" quat="0.9 0.1 0.2 0.3"><freejoint name="f"/><geom size="0.1"/></body>
</worldbody>
<equality>
 <connect name="pin" body1="coupler" body2="rocker" anchor="0.4 0.1 0"/>
 <connect name="site_pin" site1="c_end" site2="r_end"/>
 <weld name="glue" body1="float" body2="rocker" anchor="0.1 0 0"/>
 <weld body1="float" relpose="0.1 0.2 0.3 0.5 0.5 0.5 0.5" anchor="0 0.1 0"/>
 <weld name="site_glue" site1="c_end" site2="r_end"/>
 <connect name="to_world" body1="crank" anchor="0.1 0.02 0"/>
</equality></mujoco>"""


def residual(robot, q, loop) -> np.ndarray:
    """frame_a's origin minus frame_b's (world axes); for a weld then the vector part of the unit
    quaternion of R_b^T R_a (w >= 0), MuJoCo's rotation residual of a weld."""
    A, B = robot.frame_poses(q, [loop.frame_a, loop.frame_b])
    out = A[:3, 3] - B[:3, 3]
    if loop.kind == "weld":
        R = B[:3, :3].T @ A[:3, :3]
        w = np.sqrt(max(1.0 + np.trace(R), 0.0)) / 2
        v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (4 * w)
        out = np.r_[out, v]
    return out


def load_mjcf(text):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return kd.Robot.from_mjcf(text)


def q_from_qpos(robot, model, qpos, mujoco) -> np.ndarray:
    """kinedyn's q of MuJoCo's qpos: quaternions (w, x, y, z) -> (x, y, z, w)."""
    q = []
    for name in robot.joint_names:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        a, kind = model.jnt_qposadr[j], model.jnt_type[j]
        if kind == mujoco.mjtJoint.mjJNT_FREE:
            q += [*qpos[a : a + 3], *qpos[a + 4 : a + 7], qpos[a + 3]]
        elif kind == mujoco.mjtJoint.mjJNT_BALL:
            q += [*qpos[a + 1 : a + 4], qpos[a]]
        else:
            q.append(qpos[a])
    return np.array(q)


# ------------------------------------------------------------------------------------------ MJCF
def test_mjcf_connects_and_welds_read_as_loops_of_the_right_kind():
    robot = load_mjcf(MJCF)
    got = [(lp.name, lp.frame_a, lp.frame_b, lp.kind, lp.rows) for lp in robot.loops]
    assert got == [
        ("pin", "pin_a", "pin_b", "point", 3),
        ("site_pin", "c_end", "r_end", "point", 3),
        ("glue", "glue_a", "glue_b", "weld", 6),
        ("equality3", "equality3_a", "equality3_b", "weld", 6),
        ("site_glue", "c_end", "r_end", "weld", 6),
        ("to_world", "to_world_a", "to_world_b", "point", 3),
    ]
    frames = {f.name: f.link for f in robot.frames}
    assert frames["pin_a"] == "coupler" and frames["pin_b"] == "rocker" and frames["to_world_b"] is None


def test_mjcf_loops_match_mujocos_constraint_residuals_at_qpos0_and_anywhere():
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo is the oracle of the MJCF reading")
    robot = load_mjcf(MJCF)
    model = mujoco.MjModel.from_xml_string(MJCF)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(7)
    for trial in range(6):
        qpos = model.qpos0.copy()
        if trial:  # a random state: every joint moved
            for j in range(model.njnt):
                a, kind = model.jnt_qposadr[j], model.jnt_type[j]
                if kind == mujoco.mjtJoint.mjJNT_FREE:
                    qpos[a : a + 3] += rng.normal(size=3)
                    qpos[a + 3 : a + 7] = (v := rng.normal(size=4)) / np.linalg.norm(v)
                elif kind == mujoco.mjtJoint.mjJNT_BALL:
                    qpos[a : a + 4] = (v := rng.normal(size=4)) / np.linalg.norm(v)
                else:
                    qpos[a] += rng.normal()
        data.qpos[:] = qpos
        mujoco.mj_forward(model, data)
        q = q_from_qpos(robot, model, qpos, mujoco)
        theirs = data.efc_pos[: data.ne]
        ours = np.concatenate([residual(robot, q, lp) for lp in robot.loops])
        assert theirs.shape == ours.shape
        for k, lp in enumerate(robot.loops):  # a quaternion's sign is free: compare each rotation up to it
            rows = slice(sum(x.rows for x in robot.loops[:k]), sum(x.rows for x in robot.loops[: k + 1]))
            a, b = ours[rows], theirs[rows]
            if lp.kind == "weld" and not np.allclose(a[3:], b[3:], atol=1e-9):
                b = np.r_[b[:3], -b[3:]]
            np.testing.assert_allclose(a, b, atol=1e-9, err_msg=f"loop {lp.name}, trial {trial}")
        if trial == 0:  # the body forms close at qpos0, as MuJoCo's compiler assumes
            for lp in robot.loops:
                if lp.name in ("pin", "glue", "to_world"):
                    assert np.abs(residual(robot, q, lp)).max() < 1e-12, lp.name


def test_weld_with_torquescale_zero_is_a_point_and_inactive_equalities_are_named():
    text = MJCF.replace('<weld name="glue"', '<weld name="glue" torquescale="0"').replace(
        '<connect name="to_world"', '<connect name="to_world" active="false"'
    )
    with pytest.warns(UserWarning) as caught:
        robot = kd.Robot.from_mjcf(text)
    message = " ".join(str(w.message) for w in caught)
    assert "inactive <equality><connect 'to_world'>" in message
    assert "softness of 5 <equality> loops" in message
    kinds = {lp.name: lp.kind for lp in robot.loops}
    assert kinds["glue"] == "point" and "to_world" not in kinds


def test_default_class_can_switch_equalities_off_and_tendon_equalities_are_named():
    text = MJCF.replace("<worldbody>", '<default><equality active="false"/></default><worldbody>')
    with pytest.warns(UserWarning, match="inactive"):
        assert kd.Robot.from_mjcf(text).loops == ()
    text = MJCF.replace(
        "</equality>",
        '<tendon tendon1="t"/></equality><tendon><fixed name="t"><joint joint="j1" coef="1"/></fixed></tendon>',
    )
    with pytest.warns(UserWarning, match=r"<equality><tendon> \(1 element \(not modelled\)\)"):
        kd.Robot.from_mjcf(text)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            'body2="rocker" anchor',
            'body2="rockr" anchor',
            r"string>:19: <connect> connect 'pin': body2='rockr' names no <body>.*rocker",
        ),
        (
            'site1="c_end" site2="r_end"/>\n <weld',
            'site1="c_nd" site2="r_end"/>\n <weld',
            r"string>:20: <connect> .*site1='c_nd' names no <site>",
        ),
        (
            '<connect name="pin" body1="coupler" body2="rocker" anchor="0.4 0.1 0"/>',
            '<connect name="pin" body1="coupler"/>',
            "needs body1 and anchor, or site1 and site2",
        ),
        ('anchor="0.1 0 0"/>', 'anchor="0.1 0"/>', "attribute 'anchor' must be 3 numbers"),
        ('name="site_glue"', 'name="pin"', "the name 'pin' is given to two <equality> elements"),
        ('body2="rocker" anchor="0.1', 'body2="float" anchor="0.1', "body1 and body2 are both 'float'"),
    ],
)
def test_mjcf_loop_errors_name_the_line_and_element(old, new, message):
    assert old in MJCF
    with pytest.raises(ValueError, match=message):
        load_mjcf(MJCF.replace(old, new))


# ------------------------------------------------------------------------------------------ URDF
FOUR_BAR_URDF = """<?xml version="1.0"?>
<robot name="four_bar">
  <link name="ground"/>
  <link name="crank"><inertial><origin xyz="0.05 0 0"/><mass value="0.2"/>
    <inertia ixx="1e-5" ixy="0" ixz="0" iyy="2e-4" iyz="0" izz="2e-4"/></inertial></link>
  <link name="coupler"><inertial><origin xyz="0.175 0 0"/><mass value="0.5"/>
    <inertia ixx="1e-5" ixy="0" ixz="0" iyy="5e-3" iyz="0" izz="5e-3"/></inertial></link>
  <link name="rocker"><inertial><origin xyz="0.15 0 0"/><mass value="0.4"/>
    <inertia ixx="1e-5" ixy="0" ixz="0" iyy="3e-3" iyz="0" izz="3e-3"/></inertial></link>
  <joint name="crank_joint" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/></joint>
  <joint name="coupler_joint" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="rocker_joint" type="continuous"><parent link="ground"/><child link="rocker"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/></joint>
  <loop name="pin" type="point">
    <link1 link="coupler" xyz="0.35 0 0"/>
    <link2 link="rocker" xyz="0.3 0 0" rpy="0 0 0.1"/>
  </loop>
  <loop name="glued" type="weld"><link1 link="rocker"/><link2 link="ground"/></loop>
</robot>
"""


def test_urdf_loop_extension_reads_frames_on_the_links():
    robot = kd.Robot.from_urdf(FOUR_BAR_URDF)
    assert [(lp.name, lp.frame_a, lp.frame_b, lp.kind) for lp in robot.loops] == [
        ("pin", "pin_a", "pin_b", "point"),
        ("glued", "rocker", "ground", "weld"),
    ]
    frames = {f.name: f for f in robot.frames}
    assert frames["pin_a"].link == "coupler" and frames["pin_b"].link == "rocker"
    np.testing.assert_allclose(np.asarray(frames["pin_a"].placement)[:3, 3], [0.35, 0, 0])
    R = np.asarray(frames["pin_b"].placement)[:3, :3]
    np.testing.assert_allclose(R[:2, :2], [[np.cos(0.1), -np.sin(0.1)], [np.sin(0.1), np.cos(0.1)]], atol=1e-15)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            '<link2 link="rocker" xyz',
            '<link2 link="roker" xyz',
            r"<URDF string>:17: loop 'pin': <link2> names link 'roker'.*did you mean 'rocker'",
        ),
        ('type="point">', 'type="pin">', r"<URDF string>:15: loop 'pin' has type 'pin': expected one of point, weld"),
        ('<link1 link="coupler" xyz="0.35 0 0"/>', "", r":15: loop 'pin' has no <link1 link=...>"),
        ('xyz="0.35 0 0"', 'xyz="0.35 0"', r":16: loop 'pin' <link1> xyz must be 3 numbers"),
        ('name="glued"', 'name="pin"', r":19: loop 'pin' is defined twice \(first at line 15\)"),
        ('<link2 link="ground"/>', '<link2 link="rocker"/>', r":19: loop 'glued' closes frame 'rocker' on itself"),
    ],
)
def test_urdf_loop_errors_name_the_line(old, new, message):
    assert old in FOUR_BAR_URDF
    with pytest.raises(ValueError, match=message):
        kd.Robot.from_urdf(FOUR_BAR_URDF.replace(old, new))


def same_loops(a, b, states=4):
    """The same loops (name, kind) whose frames sit at the same poses at random states."""
    assert [(lp.name, lp.kind) for lp in a.loops] == [(lp.name, lp.kind) for lp in b.loops]
    rng = np.random.default_rng(3)
    for _ in range(states):
        q = a.random_configuration(rng)
        for la, lb in zip(a.loops, b.loops):
            np.testing.assert_allclose(
                a.frame_poses(q, [la.frame_a, la.frame_b]), b.frame_poses(q, [lb.frame_a, lb.frame_b]), atol=1e-12
            )


@pytest.mark.parametrize("fmt", ["urdf", "mjcf", "yaml", "toml"])
def test_every_writer_keeps_the_loops(fmt, tmp_path):
    robot = kd.Robot.from_urdf(FOUR_BAR_URDF)
    path = tmp_path / f"four_bar.{'xml' if fmt == 'mjcf' else fmt}"
    if fmt == "urdf":
        robot.to_urdf(path)
    elif fmt == "mjcf":
        robot.to_mjcf(path)
    else:
        robot.save(path)
    back = load_mjcf(str(path)) if fmt == "mjcf" else kd.load(path)
    same_loops(robot, back)
    if fmt != "mjcf":  # every frame is a link of the written URDF, or a frame of the robot file
        assert back.loops == robot.loops
    else:  # a loop end that is a link gets a site of its own
        assert [(lp.frame_a, lp.frame_b) for lp in back.loops] == [("pin_a", "pin_b"), ("glued_a", "glued_b")]


def test_mjcf_written_loops_are_what_mujoco_holds(tmp_path):
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo is the oracle of the MJCF writing")
    robot = kd.Robot.from_urdf(FOUR_BAR_URDF)
    model = mujoco.MjModel.from_xml_string(robot.to_mjcf())
    data = mujoco.MjData(model)
    q = robot.random_configuration(np.random.default_rng(5))
    data.qpos[:] = q
    mujoco.mj_forward(model, data)
    ours = np.concatenate([residual(robot, q, lp) for lp in robot.loops])
    theirs = data.efc_pos[: data.ne]
    if not np.allclose(ours[3:], theirs[3:], atol=1e-9):
        theirs = np.r_[theirs[:6], -theirs[6:]]
    np.testing.assert_allclose(ours, theirs, atol=1e-9)


def test_kinedyn_convert_keeps_the_loops_and_checks_them(tmp_path):
    robot = kd.Robot.from_urdf(FOUR_BAR_URDF)
    for ext in ("urdf", "xml", "yaml"):
        result = convert(robot, tmp_path / f"fb.{ext}")
        assert "2 loops, M and inverse dynamics" in result.summary(), result.summary()
        same_loops(robot, load_mjcf(str(tmp_path / "fb.xml")) if ext == "xml" else kd.load(tmp_path / f"fb.{ext}"))


# ------------------------------------------------------------------------------------------ YAML
YAML = """name: two_pins
links:
  - {name: a, joint: {name: ja, type: revolute}}
  - {name: b, parent: a, joint: {name: jb, type: revolute, origin: {xyz: [1, 0, 0]}}}
frames:
  - {name: tip, link: b, origin: {xyz: [1, 0, 0]}}
  - {name: pivot, origin: {xyz: [1.5, 0, 0]}}
loops:
  - {name: closure, frame_a: tip, frame_b: pivot, kind: point}
  - {name: held, frame_a: a, frame_b: base}
"""


def test_yaml_loops_section(tmp_path):
    path = tmp_path / "r.yaml"
    path.write_text(YAML)
    robot = kd.load(path)
    assert [(lp.name, lp.frame_a, lp.frame_b, lp.kind) for lp in robot.loops] == [
        ("closure", "tip", "pivot", "point"),
        ("held", "a", "base", "point"),
    ]


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "frame_b: pivot",
            "frame_b: pivto",
            r"line 9: loops\[0\].frame_b: names no frame 'pivto'; did you mean 'pivot'",
        ),
        ("kind: point}", "kind: ball}", r"line 9: loops\[0\]: loop 'closure': kind must be one of"),
        (
            "{name: held, frame_a: a, frame_b: base}",
            "{name: held, frame_a: a}",
            r"line 10: loops\[1\]: a loop needs 'frame_b'",
        ),
        ("name: held", "name: closure", r"line 10: loops\[1\].name: two loops are named 'closure'"),
        ("frame_b: base}", "frame_b: base, rows: 3}", r"line 10: loops\[1\]: unknown key 'rows'"),
    ],
)
def test_yaml_loop_errors_name_the_line(tmp_path, old, new, message):
    assert old in YAML
    path = tmp_path / "r.yaml"
    path.write_text(YAML.replace(old, new))
    with pytest.raises(ValueError, match=message):
        kd.load(path)


# ------------------------------------------------------------------------------------------ info
def test_kinedyn_info_prints_the_loops(capsys, tmp_path, monkeypatch):
    from kinedyn.cli import main

    monkeypatch.setenv("COLUMNS", "200")
    path = tmp_path / "four_bar.urdf"
    path.write_text(FOUR_BAR_URDF)
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    rows = [line for line in out.splitlines() if "pin_a" in line or "glued" in line]
    assert len(rows) == 2 and "pin_b" in rows[0] and "point" in rows[0] and "3" in rows[0]
    assert "rocker" in rows[1] and "ground" in rows[1] and "weld" in rows[1] and "6" in rows[1]
    assert main(["info", str(path), "--json"]) == 0
    doc = __import__("json").loads(capsys.readouterr().out)
    assert doc["loops"][1] == {"name": "glued", "frame_a": "rocker", "frame_b": "ground", "kind": "weld", "rows": 6}


def test_loops_read_as_a_table():
    robot = kd.Robot.from_urdf(FOUR_BAR_URDF)
    assert repr(robot.loops[0]) == "Loop('pin': pin_a meets pin_b, point, 3 rows)"
    assert str(robot.loops[1]) == "Loop('glued': rocker meets ground, weld, 6 rows)"


# ------------------------------------------------------------------------------------------ examples
EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "robots"
# file -> degrees of freedom the closed mechanism keeps (nv less the rank of the loops' Jacobian)
MOBILITY = {
    "four_bar.yaml": 1,
    "five_bar.yaml": 2,
    "parallelogram_arm.urdf": 3,
    "pushrod_leg.urdf": 8,  # 6 of the trunk, hip, knee
    "delta.xml": 9,  # 3 translations of the platform, the spins of the 6 ball-jointed rods
}


def closed_configuration(path, robot) -> np.ndarray:
    """The configuration the file's comment says its loops close at."""
    found = re.search(r"Closed at q = (neutral|\[[^\]]*\])", path.read_text())
    assert found, f"{path.name} gives no 'Closed at q = ...' in a comment"
    return robot.neutral() if found.group(1) == "neutral" else np.array(ast.literal_eval(found.group(1)), dtype=float)


def loop_jacobian(robot, q) -> np.ndarray:
    """d(origin of frame_a - origin of frame_b)/dt = J qd, stacked over the (point) loops."""
    rows = []
    for lp in robot.loops:
        assert lp.kind == "point"
        rows.append(robot.jacobian(q, lp.frame_a)[:3] - robot.jacobian(q, lp.frame_b)[:3])
    return np.vstack(rows)


@pytest.mark.parametrize("name", sorted(MOBILITY))
def test_example_loops_close_where_the_file_says_and_keep_the_mechanisms_mobility(name):
    path = EXAMPLES / name
    robot = load_mjcf(str(path)) if name.endswith(".xml") else kd.load(path)
    assert robot.loops, f"{name} declares no loop"
    q = closed_configuration(path, robot)
    assert q.shape == (robot.nq,)
    worst = max(np.abs(residual(robot, q, lp)).max() for lp in robot.loops)
    assert worst < 1e-12, f"{name}: the loops are open by {worst:.3g} at the configuration its comment gives"
    J = loop_jacobian(robot, q)
    assert robot.nv - np.linalg.matrix_rank(J, tol=1e-9) == MOBILITY[name]
    # a random configuration opens them: the check above is not empty
    assert max(np.abs(residual(robot, robot.random_configuration(1), lp)).max() for lp in robot.loops) > 1e-3


def test_five_bar_is_decoupled_as_spong_says_when_m3_l2_lc3_equals_m4_l1_lc4():
    """On the parallelogram's manifold (q3 = q1 - q2, q4 = q2 - q1) the kinetic energy in (q1, q2),
    G^T M G with qd = G (qd1, qd2), is diagonal and constant, and gravity's torque on q1 depends on q1
    alone (Spong 9.4, eq. 9.105-9.108); here checked numerically on the file's robot."""
    robot = kd.load(EXAMPLES / "five_bar.yaml")
    assert robot.joint_names == ["q1", "q4", "q2", "q3"]
    G = np.array([[1.0, 0.0], [-1.0, 1.0], [0.0, 1.0], [1.0, -1.0]])  # q = [q1, q4, q2, q3]
    reduced = []
    for q1, q2 in np.random.default_rng(11).uniform(-3, 3, size=(5, 2)):
        q = np.array([q1, q2 - q1, q2, q1 - q2])
        assert np.abs(residual(robot, q, robot.loops[0])).max() < 1e-12
        D = G.T @ robot.mass_matrix(q) @ G
        assert abs(D[0, 1]) < 1e-12
        reduced.append(np.diag(D))
        g = G.T @ robot.gravity_torque(q)
        shifted = G.T @ robot.gravity_torque(np.array([q1, q2 + 0.4 - q1, q2 + 0.4, q1 - q2 - 0.4]))
        assert abs(g[0] - shifted[0]) < 1e-12  # phi_1 depends on q1 only
    np.testing.assert_allclose(reduced, [reduced[0]] * 5, atol=1e-12)
    # and it is not decoupled once the condition breaks (a lighter counterweight)
    links = [
        replace(link, inertia=kd.Inertia(2.0, link.inertia.com, link.inertia.inertia)) if link.name == "link4" else link
        for link in robot.links
    ]
    lighter = robot.replace(links=links)
    q = np.array([0.3, 0.9, 1.2, -0.9])
    assert abs((G.T @ lighter.mass_matrix(q) @ G)[0, 1]) > 1e-3


def test_delta_platform_points_are_the_designed_parallelograms():
    """The anchors MuJoCo's compiler puts on the platform (where each rod's end is at qpos0) lie in
    the platform's plane, in pairs 6 cm apart about points 5 cm from its centre, 120 degrees apart."""
    robot = load_mjcf(str(EXAMPLES / "delta.xml"))
    frames = {f.name: f for f in robot.frames}
    points = {lp.name[:5]: np.asarray(frames[lp.frame_b].placement)[:3, 3] for lp in robot.loops}
    assert all(frames[lp.frame_b].link == "platform" for lp in robot.loops)
    ball = next(link for link in robot.links if link.name == "platform")  # rod 1a's end: the ball joint
    points["rod1a"] = np.asarray(ball.post, dtype=float)[:3, 3] * -1
    for i, phi in ((1, 0.0), (2, 2 * np.pi / 3), (3, 4 * np.pi / 3)):
        a, b = points[f"rod{i}a"], points[f"rod{i}b"]
        np.testing.assert_allclose([a[2], b[2]], 0.0, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(a - b), 0.06, atol=1e-9)
        np.testing.assert_allclose((a + b) / 2, 0.05 * np.array([np.cos(phi), np.sin(phi), 0.0]), atol=1e-9)


def test_a_site_named_as_a_body_is_the_loop_end_site_colon_name():
    text = MJCF.replace('<site name="r_end"', '<site name="rocker"').replace('site2="r_end"', 'site2="rocker"')
    robot = load_mjcf(text)
    assert {lp.name: lp.frame_b for lp in robot.loops}["site_pin"] == "site:rocker"


def test_convert_check_refuses_a_file_that_lost_the_loops(tmp_path):
    from kinedyn.convert import Conversion, check_conversion

    robot = kd.Robot.from_urdf(FOUR_BAR_URDF)
    path = tmp_path / "lost.urdf"
    robot.replace(loops=()).to_urdf(path)
    with pytest.raises(ValueError, match=r"reads back with loops \[\], not the source's \[\('pin', 'point'\)"):
        check_conversion(robot, str(path), "urdf", Conversion(str(path), "urdf", robot.n))


def test_a_loop_on_the_base_of_a_floating_robot_keeps_the_base_in_the_urdf(tmp_path):
    text = (EXAMPLES / "pushrod_leg.urdf").read_text()
    text = text.replace('<link name="world"/>', "").replace(
        '<joint name="root" type="floating"><parent link="world"/><child link="trunk"/></joint>', ""
    )
    free = kd.Robot.from_urdf(text, floating_base=True)  # the trunk on Pinocchio's free-flyer from 'universe'
    robot = free.add_loop("foot", "universe", name="planted")
    path = tmp_path / "planted.urdf"
    robot.to_urdf(path)  # not written trunk-as-root: the loop needs the fixed frame 'universe'
    back = kd.load(path)
    assert back.base == "universe" and back.joint_names == robot.joint_names
    same_loops(robot, back)


def test_symbolic_five_bar_is_the_numeric_one_with_its_numbers():
    """five_bar_symbolic.yaml (for the equations) and five_bar.yaml (numbers) are one mechanism: with
    the numeric file's lengths, masses and inertias about z, the same closure and the same reduced
    dynamics in (q1, q2)."""
    symbolic = kd.load(EXAMPLES / "five_bar_symbolic.yaml")
    numeric = kd.load(EXAMPLES / "five_bar.yaml")
    values = {"l1": 0.2, "l2": 0.5, "lc1": 0.1, "lc2": 0.25, "lc3": 0.35, "lc4": 0.5, "g": 9.81}
    values |= {"m1": 1.0, "m2": 2.5, "m3": 2.0, "m4": 3.5}
    values |= {f"I{k + 1}": numeric.links[k].inertia.inertia[2][2] for k in range(4)}  # about z, file order
    assert [link.name for link in numeric.links] == ["link1", "link2", "link3", "link4"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # I about z alone: no rigid body, but a planar one's
        robot = symbolic.subs({s: values[s.name] for s in symbolic.symbols})
    q = closed_configuration(EXAMPLES / "five_bar_symbolic.yaml", robot)
    assert np.abs(residual(robot, q, robot.loops[0])).max() < 1e-12
    G = np.array([[1.0, 0.0], [-1.0, 1.0], [0.0, 1.0], [1.0, -1.0]])
    for q1, q2 in np.random.default_rng(2).uniform(-3, 3, size=(3, 2)):
        q = np.array([q1, q2 - q1, q2, q1 - q2])
        np.testing.assert_allclose(G.T @ robot.mass_matrix(q) @ G, G.T @ numeric.mass_matrix(q) @ G, atol=1e-12)
        np.testing.assert_allclose(G.T @ robot.gravity_torque(q), G.T @ numeric.gravity_torque(q), atol=1e-12)


# ------------------------------------------------------------------------------------------ audit
def test_audit_names_the_loops_open_at_the_files_reference_as_mujoco_finds_them():
    """MJCF: the loops the audit finds open at qpos0 are those MuJoCo's constraint residuals say
    are, by the same distance; a URDF's loop open at q = 0 is an info finding with its line."""
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo is the oracle")
    text = MJCF.replace('<freejoint name="f"/>', '<joint name="f" type="ball"/>')  # no free body: checked
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    robot = load_mjcf(text)
    rows = np.cumsum([0] + [lp.rows for lp in robot.loops])
    gaps = {lp.name: float(np.linalg.norm(data.efc_pos[rows[k] : rows[k] + 3])) for k, lp in enumerate(robot.loops)}
    found = {f.element: f for f in kd.audit(text, geometry=False).findings if f.code == "loop-open"}
    assert set(found) == {f"loop '{name}'" for name, gap in gaps.items() if gap > 1e-9}
    for name, gap in gaps.items():
        if gap > 1e-9:
            finding = found[f"loop '{name}'"]
            assert finding.severity == "warning" and finding.line is not None
            np.testing.assert_allclose(finding.data["gap"], gap, rtol=1e-12)
    urdf = {f.element: f for f in kd.audit(FOUR_BAR_URDF, geometry=False).findings if f.code == "loop-open"}
    assert urdf["loop 'pin'"].severity == "info" and urdf["loop 'pin'"].line == 15
    np.testing.assert_allclose(
        urdf["loop 'pin'"].data["gap"], (0.4 + 0.3) - (0.1 + 0.35), rtol=1e-12
    )  # pin_b, pin_a along x
    closed = kd.audit(str(EXAMPLES / "parallelogram_arm.urdf"), geometry=False)
    assert not [f for f in closed.findings if f.code == "loop-open"]


def test_mjcf_anchor_frames_are_mujocos_compiled_anchors():
    """Each loop's two frames sit where MuJoCo's compiled model puts the equality's two ends
    (eq_data, filled by mj_setConst at qpos0; site_xpos/site_xmat for the site form), at a random state."""
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo is the oracle of the MJCF reading")
    robot = load_mjcf(MJCF)
    model = mujoco.MjModel.from_xml_string(MJCF)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(4)
    qpos = model.qpos0.copy()
    qpos[[model.jnt_qposadr[j] for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]] += 0.7
    ball = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "j3")]
    qpos[ball : ball + 4] = (v := rng.normal(size=4)) / np.linalg.norm(v)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    q = q_from_qpos(robot, model, qpos, mujoco)

    def quat_matrix(w):
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, w)
        return R.reshape(3, 3)

    for k, lp in enumerate(robot.loops):
        A, B = robot.frame_poses(q, [lp.frame_a, lp.frame_b])
        e = model.eq_data[k]
        b1, b2 = model.eq_obj1id[k], model.eq_obj2id[k]
        if model.eq_objtype[k] == mujoco.mjtObj.mjOBJ_SITE:
            ends = [(data.site_xpos[b], data.site_xmat[b].reshape(3, 3)) for b in (b1, b2)]
        else:
            X = [(data.xpos[b], data.xmat[b].reshape(3, 3)) for b in (b1, b2)]
            if model.eq_type[k] == mujoco.mjtEq.mjEQ_CONNECT:
                ends = [(X[0][0] + X[0][1] @ e[0:3], None), (X[1][0] + X[1][1] @ e[3:6], None)]
            else:  # weld: body1's point and axes from relpose (eq_data[3:10]), body2's point eq_data[0:3]
                ends = [
                    (X[0][0] + X[0][1] @ e[3:6], X[0][1] @ quat_matrix(e[6:10])),
                    (X[1][0] + X[1][1] @ e[0:3], X[1][1]),
                ]
        for T, (p, R) in zip((A, B), ends):
            np.testing.assert_allclose(T[:3, 3], p, atol=1e-12, err_msg=lp.name)
            if lp.kind == "weld" and model.eq_type[k] == mujoco.mjtEq.mjEQ_WELD:
                np.testing.assert_allclose(T[:3, :3], R, atol=1e-12, err_msg=lp.name)
