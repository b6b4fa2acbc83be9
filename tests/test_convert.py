"""Robots out and between formats: robot.to_urdf / to_mjcf, DH extraction, `kinedyn convert`.

Every conversion is checked by what the result computes, against the source: frame poses (every
frame of the source, by name), M and inverse dynamics at random states; MJCF against MuJoCo itself
(mj_fullM, qfrc_bias = C qd + g, body poses); URDF also against Pinocchio reading the written file."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp
from reference import PANDA, UR5, erd

import kinedyn as kd
from kinedyn._math import matmul, rot_axis, rpy_to_matrix, translation
from kinedyn.description.dh import DHRow, dh_from_robot
from kinedyn.description.export import default_visuals, quaternion_from_matrix, rpy_from_matrix
from kinedyn.description.geometry import Cylinder
from kinedyn.description.joint import Joint
from kinedyn.description.link import Link
from kinedyn.testing import random_robot

DH_BUILTINS = ["planar_2r", "elbow_3r", "cartesian_2p", "puma560", "stanford", "ur5"]


def _unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def with_posts(robot, seed):
    """``robot`` with a random post transform on every moving link (a frame off the joint axis, as a
    standard DH link has), so the writers' handling of ``post`` is exercised on trees too."""
    rng = np.random.default_rng(seed)
    links = [
        Link(
            l.name,
            l.parent,
            l.joint,
            l.placement,
            matmul(translation(*rng.uniform(-0.3, 0.3, 3)), rot_axis(_unit(rng), rng.uniform(-3, 3))),
            l.inertia,
        )
        if l.joint.is_moving
        else l
        for l in robot.links
    ]
    return robot.replace(links=links, name=f"{robot.name}_posts")


def same_robot(source, result, states=3, seed=0, armature_dropped=False, frames=None):
    """Largest differences (FK over the source's frames, M, inverse dynamics) at random states."""
    rng = np.random.default_rng(seed)
    names = frames or source.frame_names
    worst = {"fk": 0.0, "M": 0.0, "tau": 0.0}
    for _ in range(states):
        q, qd, qdd = (rng.uniform(-1.5, 1.5, source.n) for _ in range(3))
        worst["fk"] = max(worst["fk"], float(np.abs(source.frame_poses(q, names) - result.frame_poses(q, names)).max()))
        extra = np.diag(source.armature) if armature_dropped else 0.0
        worst["M"] = max(worst["M"], float(np.abs(source.mass_matrix(q) - result.mass_matrix(q) - extra).max()))
        tau_extra = source.armature * qdd if armature_dropped else 0.0
        worst["tau"] = max(
            worst["tau"],
            float(np.abs(source.inverse_dynamics(q, qd, qdd) - result.inverse_dynamics(q, qd, qdd) - tau_extra).max()),
        )
    return worst


def from_urdf_text(source, text):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)  # the source's own (Corke's PUMA data)
        return kd.Robot.from_urdf(text, gravity=source.gravity, tool=source.tool)


# ---------------------------------------------------------------------------------------- rotations
@pytest.mark.parametrize(
    "pitch", [math.pi / 2, -math.pi / 2, math.pi / 2 - 1e-9, -math.pi / 2 + 3e-13, 0.3, math.pi / 2 - 1e-5]
)
def test_rpy_is_exact_at_and_near_gimbal_lock(pitch):
    rng = np.random.default_rng(1)
    for _ in range(20):
        R = np.asarray(rpy_to_matrix(rng.uniform(-3, 3), pitch, rng.uniform(-3, 3)))[:3, :3]
        back = np.asarray(rpy_to_matrix(*rpy_from_matrix(R)))[:3, :3]
        assert np.abs(back - R).max() < 4e-16 * 8


def test_rpy_of_an_exact_gimbal_lock_matrix():
    # pitch exactly +-90 degrees, written with exact zeros: only yaw -+ roll is defined; any split must rebuild R
    for sign in (1.0, -1.0):
        for angle in (0.3, -2.5, math.pi):
            c, s = math.cos(angle), math.sin(angle)
            R = np.array([[0.0, -s, sign * c], [0.0, c, sign * s], [-sign, 0.0, 0.0]])
            back = np.asarray(rpy_to_matrix(*rpy_from_matrix(R)))[:3, :3]
            assert np.abs(back - R).max() < 1e-15


def test_quaternion_is_mujocos_w_x_y_z():
    rng = np.random.default_rng(2)
    for angle in [0.0, 1e-9, 1.0, math.pi - 1e-9, math.pi]:
        axis = _unit(rng)
        w, x, y, z = quaternion_from_matrix(np.asarray(rot_axis(axis, angle))[:3, :3])
        assert w >= 0
        # q = (cos a/2, sin a/2 axis), up to the sign fixed by w >= 0
        expected = np.array([math.cos(angle / 2), *(math.sin(angle / 2) * axis)])
        assert (
            np.abs(np.array([w, x, y, z]) - expected).max() < 1e-12
            or np.abs(np.array([w, x, y, z]) + expected).max() < 1e-12
        )


# ---------------------------------------------------------------------------------------- URDF
@pytest.mark.parametrize("name", DH_BUILTINS)
def test_dh_builtins_to_urdf_keep_kinematics_and_dynamics(name):
    source = kd.robots.get(name)
    text = source.to_urdf()
    back = from_urdf_text(source, text)
    err = same_robot(source, back, armature_dropped=True)
    assert err["fk"] < 1e-12 and err["M"] < 1e-12 and err["tau"] < 1e-10, err
    # URDF has no rotor inertia: the writer keeps it in Drake's <transmission> extension
    if np.any(source.armature):
        assert "drake:rotor_inertia" in text and 'xmlns:drake="http://drake.mit.edu"' in text
    # geometry where the DH robot has none: cylinders on the links
    assert back.visuals and all(v.frame in back.frame_names for v in back.visuals)


@pytest.mark.parametrize(
    "robot", [random_robot(3), with_posts(random_robot(4, branching=True, fixed=2), 4)], ids=lambda r: r.name
)
def test_random_trees_with_offsets_and_posts_to_urdf(robot):
    assert any(float(j.offset) for j in robot.joints)  # the folding of offsets is exercised
    back = from_urdf_text(robot, robot.to_urdf())
    err = same_robot(robot, back, armature_dropped=True)
    assert err["fk"] < 1e-12 and err["M"] < 1e-12 and err["tau"] < 1e-10, err
    assert [j.name for j in back.joints] == robot.joint_names
    np.testing.assert_array_equal(back.viscous, robot.viscous)
    np.testing.assert_array_equal(back.coulomb, robot.coulomb)


def test_urdf_written_is_what_pinocchio_reads():
    pin = pytest.importorskip("pinocchio")
    robot = with_posts(random_robot(5, branching=True), 5)
    model = pin.buildModelFromXML(robot.to_urdf())
    data = model.createData()
    rng = np.random.default_rng(5)
    # Pinocchio orders joints depth-first as kinedyn does; map by name to be safe
    order = [model.names[i] for i in range(1, model.njoints)]
    index = [robot.joint_names.index(n) for n in order]
    for _ in range(3):
        q = rng.uniform(-1, 1, robot.n)
        # a continuous joint's configuration in Pinocchio is (cos q, sin q)
        q_pin = np.concatenate(
            [[q[k]] if model.joints[i + 1].nq == 1 else [math.cos(q[k]), math.sin(q[k])] for i, k in enumerate(index)]
        )
        M = pin.crba(model, data, q_pin)
        M = np.triu(M) + np.triu(M, 1).T
        ours = robot.mass_matrix(q)[np.ix_(index, index)] - np.diag(robot.armature[index])
        assert np.abs(M - ours).max() < 1e-12


def test_urdf_writes_limits_continuous_dynamics_and_file(tmp_path):
    robot = kd.robots.get("ur5")
    joints = robot.joints
    path = tmp_path / "arm.urdf"
    text = robot.to_urdf(path)
    assert path.read_text() == text
    back = kd.load(path, tool=robot.tool)
    np.testing.assert_array_equal(back.lower_limits, robot.lower_limits)
    np.testing.assert_array_equal(back.upper_limits, robot.upper_limits)
    np.testing.assert_array_equal(back.effort_limits, robot.effort_limits)
    unlimited = kd.Robot.from_dh([(0, 0.1, 0.2, 0)])
    assert 'type="continuous"' in unlimited.to_urdf()
    assert all(j.kind in ("revolute", "prismatic") for j in joints)


def test_urdf_refuses_spherical_and_symbolic_robots():
    ball = Link("ball", None, Joint("shoulder", "spherical"), np.eye(4), np.eye(4), kd.Inertia(1.0, inertia=np.eye(3)))
    arm = Link("arm", "ball", Joint("elbow"), np.eye(4), np.eye(4), kd.Inertia(1.0, inertia=np.eye(3)))
    robot = kd.Robot([ball, arm])
    with pytest.raises(ValueError, match="joint 'shoulder'.*spherical.*URDF has no spherical"):
        robot.to_urdf()
    l1 = sp.Symbol("l1")
    symbolic = kd.Robot.from_dh([(0, 0, l1, 0), (0, 0, 1.0, 0)])
    with pytest.raises(ValueError, match=r"symbolic parameters \['l1'\].*robot.subs"):
        symbolic.to_urdf()
    with pytest.raises(ValueError, match=r"symbolic parameters \['l1'\]"):
        symbolic.to_mjcf()


def test_urdf_warns_when_coulomb_friction_is_direction_dependent():
    robot = kd.Robot.from_dh([DHRow(a=1.0, coulomb=(0.3, 0.1), inertia=kd.Inertia(1.0, (0.5, 0, 0)))])
    with pytest.warns(UserWarning, match="joint 'q1' has 0.3 for qd > 0 and 0.1 for qd < 0; writing 0.3"):
        text = robot.to_urdf()
    assert 'friction="0.3"' in text


def test_massless_rotor_inertia_survives_a_fixed_child():
    # Corke's PUMA link 1 has no mass but a rotational inertia; merging a massless fixed frame into it
    # (the URDF writer's link frame, a tool flange) must keep that inertia
    rotor = kd.Inertia(0.0, inertia=np.diag([0.0, 0.0, 0.35]))
    merged = rotor + kd.Inertia(0.0)
    np.testing.assert_array_equal(np.array(merged.inertia), np.diag([0.0, 0.0, 0.35]))


def test_default_visuals_follow_the_dh_offsets():
    robot = kd.robots.get("puma560")
    shapes = default_visuals(robot)
    links = [v for v in shapes if v.rgba[2] < 0.78]  # grey link cylinders (joints are blue)
    total = sum(v.shape.length for v in links)
    # standard DH: each link runs d along the joint axis, then a across; the tool frame is at the last link
    expected = sum(abs(float(r.d)) + abs(float(r.a)) for r in robot.dh)
    assert total == pytest.approx(expected, rel=1e-12)
    assert all(isinstance(v.shape, Cylinder) for v in shapes)
    assert len([v for v in shapes if v not in links]) == robot.n  # one joint cylinder per joint


# ---------------------------------------------------------------------------------------- MJCF
def repaired(name):
    """A built-in whose published inertias no rigid body has (Stanford's link 5), projected onto physical ones."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        return kd.robots.get(name).replace(inertia="repair")


def mujoco_state(model_text, q, qd):
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_string(model_text)
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:] = q, qd
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    return mujoco, m, d, M


@pytest.mark.parametrize(
    "robot",
    [
        kd.robots.get("elbow_3r"),
        repaired("stanford"),
        kd.robots.get("planar_2r"),
        random_robot(6, branching=True),
        with_posts(random_robot(7, branching=True, fixed=2), 7),
    ],
    ids=lambda r: r.name,
)
def test_mjcf_agrees_with_mujoco(robot, tmp_path):
    path = tmp_path / "robot.xml"
    text = robot.to_mjcf(path)
    assert path.read_text() == text
    rng = np.random.default_rng(8)
    for _ in range(3):
        q, qd = rng.uniform(-1.5, 1.5, robot.n), rng.uniform(-1.5, 1.5, robot.n)
        mujoco, m, d, M = mujoco_state(path.read_text(), q, qd)
        assert [m.joint(i).name for i in range(m.njnt)] == robot.joint_names
        # a thin rod's zero principal moment is written as MIN_MOMENT (1e-12 kg m^2): planar_2r's M moves by 2e-12
        assert np.abs(M - robot.mass_matrix(q)).max() < 1e-9
        assert np.abs(d.qfrc_bias - (robot.coriolis_matrix(q, qd) @ qd + robot.gravity_torque(q))).max() < 1e-9
        names = [l.name for l in robot.links] + [f.name for f in robot.frames]
        ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n) for n in names]
        poses = robot.frame_poses(q, names)
        assert np.abs(d.xpos[ids] - poses[:, :3, 3]).max() < 1e-9
        assert np.abs(d.xmat[ids].reshape(-1, 3, 3) - poses[:, :3, :3]).max() < 1e-9
    # drive data: armature r^2 J_m, damping, frictionloss
    np.testing.assert_allclose(m.dof_armature, robot.armature, rtol=1e-15)
    np.testing.assert_allclose(m.dof_damping, robot.viscous, rtol=1e-15)
    np.testing.assert_allclose(m.dof_frictionloss, robot.coulomb, rtol=1e-15)
    np.testing.assert_allclose(m.opt.gravity, robot.gravity)


def test_mjcf_refuses_what_mujoco_cannot_hold():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        puma = kd.robots.get("puma560")
    with pytest.raises(ValueError, match="link 'link1' has rotational inertia without mass"):
        puma.to_mjcf()


# ---------------------------------------------------------------------------------------- URDF -> DH
def _erd_robot(parts):
    return kd.Robot.from_urdf(erd(*parts))


def dh_sources():
    yield from (kd.robots.get(n) for n in ["planar_2r", "elbow_3r", "cartesian_2p", "puma560", "stanford", "ur5"])
    yield from (random_robot(seed, n=6, prismatic=0.3) for seed in range(3))


def check_dh_extraction(source, convention, states=3):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        found = dh_from_robot(source, convention)
    dh = found.robot
    assert dh.dh_convention == convention and len(found.rows) == source.n
    rng = np.random.default_rng(11)
    for _ in range(states):
        q, qd, qdd = (rng.uniform(-2.5, 2.5, source.n) for _ in range(3))
        # every frame of the source, through the DH frame it hangs from
        names = [n for n in source.frame_names if n != source.base]
        ours = source.frame_poses(q, names)
        owners = dh.frame_poses(q, [found.source_frames[n][0] for n in names])
        theirs = owners @ np.array([found.source_frames[n][1] for n in names])
        assert np.abs(ours - theirs).max() < 1e-12
        assert np.abs(source.pose(q) - dh.pose(q, "tool")).max() < 1e-12
        assert np.abs(source.mass_matrix(q) - dh.mass_matrix(q)).max() < 1e-11
        assert np.abs(source.inverse_dynamics(q, qd, qdd) - dh.inverse_dynamics(q, qd, qdd)).max() < 1e-10
    return found


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_from_builtins_and_random_chains(convention):
    for source in dh_sources():
        check_dh_extraction(source, convention)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_from_ur5_and_panda_urdfs(convention):
    ur5 = _erd_robot(UR5)
    check_dh_extraction(ur5, convention)
    panda = _erd_robot(PANDA)
    with pytest.raises(
        ValueError, match="joint 'panda_finger_joint2' branches off link 'panda_link7'.*joint 'panda_finger_joint1'"
    ):
        dh_from_robot(panda, convention)
    found = check_dh_extraction(panda.lock_joints(["panda_finger_joint1", "panda_finger_joint2"]), convention)
    if convention == "modified":
        # the Panda is published in Craig's DH (Franka's documentation): a = 0.0825 at joints 4 and 5,
        # d = 0.333, 0.316, 0.384 on joints 1, 3, 5; alpha = +-90 degrees throughout but alpha_0
        rows = found.rows
        assert [round(abs(r.a), 6) for r in rows] == [0.0, 0.0, 0.0, 0.0825, 0.0825, 0.0, 0.088]
        assert [round(abs(r.alpha), 9) for r in rows] == [0.0] + [round(math.pi / 2, 9)] * 6


def test_dh_from_chains_with_parallel_and_intersecting_axes():
    # parallel axes (planar_3r, elbow_3r's joints 2 and 3), intersecting (puma's wrist), collinear
    # (a prismatic joint along the revolute axis before it)
    collinear = kd.Robot.from_dh(
        [(0.3, 0.2, 0.0, 0.0), (0.0, 0.4, 0.0, 0.0, "prismatic"), (0.2, 0.0, 0.5, 0.7)], name="collinear"
    )
    stacked = kd.Robot(
        [  # parallel z axes whose joint origins climb: the d = 0 choice puts the heights into d_1 only
            Link(
                f"l{i}",
                f"l{i - 1}" if i else None,
                Joint(f"j{i}"),
                translation(0.3, 0.1 * i, 0.2),
                np.eye(4),
                kd.Inertia(1.0, (0.1, 0, 0), np.eye(3) * 0.01),
            )
            for i in range(3)
        ],
        name="stacked",
    )
    found = check_dh_extraction(stacked, "standard")
    assert found.rows[1].d == 0.0  # (row 3 climbs to the tool frame, by the tool origin choice)
    for source in (kd.robots.get("planar_3r"), collinear):
        for convention in ("standard", "modified"):
            found = check_dh_extraction(source, convention)
            if source.name == "planar_3r":  # parallel axes: the common normal through the previous origin, d = 0
                assert [r.d for r in found.rows] == [0.0, 0.0, 0.0]
                lengths = [
                    float(r.a) for r in source.dh
                ]  # Craig's rows hold a_{i-1}: the last length is in the tool transform
                expected = lengths if convention == "standard" else [0.0] + lengths[:-1]
                assert [abs(r.a) for r in found.rows] == pytest.approx(expected, abs=1e-15)


def test_dh_from_robot_names_what_stops_it():
    with pytest.raises(ValueError, match="joint 'j5' branches off link 'link2'.*joint 'j4'"):
        dh_from_robot(random_robot(0, branching=True))
    ball = Link("ball", None, Joint("shoulder", "spherical"), np.eye(4), np.eye(4), kd.Inertia(1.0, inertia=np.eye(3)))
    with pytest.raises(ValueError, match="joint 'shoulder' is spherical"):
        dh_from_robot(kd.Robot([ball]))
    with pytest.raises(ValueError, match="convention must be 'standard' or 'modified'"):
        dh_from_robot(kd.robots.get("planar_2r"), "craig")


# ---------------------------------------------------------------------------------------- kinedyn convert
def convert_cli(capsys, *argv):
    from kinedyn.cli import main

    code = main(["convert", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


def _read_back_errors(out: str):
    """The three maxima the CLI printed (FK, M, tau)."""
    import re

    return [float(x) for x in re.findall(r"max \|\w+ error\| ([0-9.e+-]+)", out)]


@pytest.mark.parametrize("name", ["elbow_3r", "puma560", "stanford"])
def test_cli_converts_dh_builtins_to_urdf_mjcf_yaml(capsys, tmp_path, name):
    for out, extra in (
        ("r.urdf", []),
        ("r.xml", ["--inertia", "repair"]),
        ("r.yaml", []),
        ("r.toml", ["--to", "dh", "--convention", "modified"]),
    ):
        if name == "puma560" and out == "r.xml":  # a massless link with rotor inertia: MuJoCo cannot hold it
            code, _, err = convert_cli(capsys, name, tmp_path / out, *extra)
            assert code == 1 and "link 'link1' has rotational inertia without mass" in err
            continue
        code, text, err = convert_cli(capsys, name, tmp_path / out, *extra)
        assert code == 0, err
        assert f"wrote {tmp_path / out}" in text and "checked by reading it back" in text
        errors = _read_back_errors(text)
        assert len(errors) == 3 and max(errors) < 1e-9, text
    # the robot file, loaded, is the robot (independently of the CLI's own check)
    source = kd.robots.get(name)
    err = same_robot(source, kd.load(tmp_path / "r.yaml"))
    assert max(err.values()) < 1e-12


def test_cli_round_trips_example_robot_data_through_yaml_and_urdf(capsys, tmp_path):
    # UR5 and the Panda (fixed joints, a branch: the two fingers) -> YAML -> URDF, each step checked
    for parts in (UR5, PANDA):
        path = erd(*parts)
        code, text, err = convert_cli(capsys, path, tmp_path / "r.yaml")
        assert code == 0 and max(_read_back_errors(text)) < 1e-9, err + text
        code, text, err = convert_cli(capsys, tmp_path / "r.yaml", tmp_path / "r.urdf")
        assert code == 0 and max(_read_back_errors(text)) < 1e-9, err + text
        source, result = kd.load(path), kd.load(tmp_path / "r.urdf")
        assert result.joint_names == source.joint_names
        err = same_robot(source, result, frames=[n for n in source.frame_names if n != source.base])
        assert max(err.values()) < 1e-12, err
        assert len(result.visuals) == len(source.visuals)  # the meshes travel (absolute paths)


def test_cli_convert_to_dh_needs_a_serial_chain(capsys, tmp_path):
    panda = erd(*PANDA)
    code, _, err = convert_cli(capsys, panda, tmp_path / "p.yaml", "--to", "dh")
    assert code == 1 and "joint 'panda_finger_joint2' branches off link 'panda_link7'" in err
    code, text, err = convert_cli(
        capsys,
        panda,
        tmp_path / "p.yaml",
        "--to",
        "dh",
        "--lock",
        "panda_finger_joint1",
        "--lock",
        "panda_finger_joint2",
    )
    assert code == 0 and "(DH standard, 7 joints)" in text and max(_read_back_errors(text)) < 1e-9, err
    dh = kd.load(tmp_path / "p.yaml")
    assert dh.dh is not None and len(dh.dh) == 7


def test_cli_convert_says_what_is_wrong(capsys, tmp_path):
    code, _, err = convert_cli(capsys, "planar_2r", tmp_path / "r.txt")
    assert code == 1 and "cannot tell the format of" in err and "--to" in err
    code, _, err = convert_cli(capsys, "planar_2r", tmp_path / "r.urdf", "--to", "dh")
    assert code == 1 and "must end in .yaml, .yml or .toml" in err
    (tmp_path / "a.urdf").write_text(kd.robots.get("planar_2r").to_urdf())
    code, _, err = convert_cli(capsys, tmp_path / "a.urdf", tmp_path / "a.urdf")
    assert code == 1 and "OUT:" in err and "is the robot file this command reads" in err


def test_convert_check_catches_a_wrong_writer(capsys, tmp_path, monkeypatch):
    # the check is real: a writer that drops the joint offsets is caught and the CLI fails
    from kinedyn.description import export

    source = tmp_path / "random.yaml"
    random_robot(3).save(source)  # joint offsets in (-0.5, 0.5)
    code, text, err = convert_cli(capsys, source, tmp_path / "good.urdf")
    assert code == 0, err
    monkeypatch.setattr(export, "_motion", lambda joint, x: np.eye(4))
    code, text, err = convert_cli(capsys, source, tmp_path / "p.urdf")
    assert code == 1 and f"differs from {source}" in err


# ---------------------------------------------------------------------------------------- multi-DOF joints
def legged():
    box = kd.Inertia.box(2.0, (0.4, 0.2, 0.1))
    rod = kd.Inertia.cylinder(0.5, 0.03, 0.3, com=(0, 0, -0.15))
    return kd.Robot(
        [
            Link("trunk", None, Joint("root_joint", "floating"), np.eye(4), np.eye(4), box),
            Link("hip", "trunk", Joint("hip_ball", "spherical"), translation(0.2, 0.1, 0), np.eye(4), rod),
            Link(
                "knee",
                "hip",
                Joint("knee", axis=(0, 1, 0), lower=-2, upper=0.1),
                translation(0, 0, -0.3),
                np.eye(4),
                rod,
            ),
            Link("slider", "trunk", Joint("rail", "planar"), translation(-0.2, 0, 0), np.eye(4), rod),
        ],
        name="legged",
    )


def test_floating_spherical_and_planar_joints_in_urdf_and_mjcf():
    import xml.etree.ElementTree as ET

    robot = legged()
    with pytest.raises(ValueError, match="joint 'hip_ball'.*spherical"):
        robot.to_urdf()
    no_ball = robot.replace(links=[l for l in robot.links if l.name not in ("hip", "knee")], tool="slider")
    # the free-flying trunk becomes the URDF root (read back with floating_base=True) ...
    root = ET.fromstring(no_ball.to_urdf())
    assert [l.get("name") for l in root.findall("link")][0] == "trunk"
    assert [(j.get("name"), j.get("type")) for j in root.findall("joint")] == [("rail", "planar")]
    # ... or stays a URDF floating joint below the base
    root = ET.fromstring(no_ball.to_urdf(floating_base_as_root=False))
    assert [(j.get("name"), j.get("type")) for j in root.findall("joint")] == [
        ("root_joint", "floating"),
        ("rail", "planar"),
    ]
    # MJCF holds them all: free (nq 7, nv 6), ball (4, 3), hinge, planar as slide x, slide y, hinge
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_string(robot.to_mjcf())
    kinds = [int(m.jnt_type[i]) for i in range(m.njnt)]
    J = mujoco.mjtJoint
    assert kinds == [J.mjJNT_FREE, J.mjJNT_BALL, J.mjJNT_HINGE, J.mjJNT_SLIDE, J.mjJNT_SLIDE, J.mjJNT_HINGE]
    assert (m.nq, m.nv) == (7 + 4 + 1 + 3, 6 + 3 + 1 + 3)
    np.testing.assert_allclose(m.body("trunk").mass, 2.0)
