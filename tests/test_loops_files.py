"""Closed loops in robot files: MJCF <equality><connect>/<weld> read as MuJoCo defines them (MuJoCo
as the oracle: its constraint residuals efc_pos against kinedyn's frame poses), the URDF <loop>
extension, the YAML/TOML `loops:` section, the writers and `kinedyn convert` keeping them, and the
errors that name file, line and element."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import kinedyn as kd

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
