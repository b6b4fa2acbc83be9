"""Robot files as they are in the wild (issue 26): kinedyn loads what the reference readers load
(urdfdom through Pinocchio for URDF, MuJoCo for MJCF), says in a warning what it reads differently,
and refuses where the reference refuses too. Each case is checked against the reference tool."""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.description.geometry import Mesh, resolve_mesh

pin = pytest.importorskip("pinocchio", reason="Pinocchio is the URDF oracle (the peers extra)")
mujoco = pytest.importorskip("mujoco", reason="MuJoCo is the MJCF oracle (the peers extra)")

INERTIAL = '<inertial><mass value="1.5"/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>'
LIMIT = '<limit lower="-1" upper="1" effort="5" velocity="2"/>'


def _urdf(geometry: str = "", limit: str = LIMIT, extra_joint: str = "") -> str:
    return (
        '<robot name="r">\n<link name="a"/>\n'
        f'<link name="b">{INERTIAL}{geometry}</link>\n'
        f'<joint name="j" type="revolute"><origin xyz="0.1 0 0"/><axis xyz="0 1 0"/><parent link="a"/><child link="b"/>{limit}</joint>\n'
        f"{extra_joint}</robot>"
    )


def _same_dynamics_as_pinocchio(robot, model, samples: int = 3):
    """M(q) and g(q) of the robot equal Pinocchio's at seeded random configurations."""
    data = model.createData()
    rng = np.random.default_rng(0)
    for _ in range(samples):
        q = rng.uniform(-1, 1, model.nq)
        np.testing.assert_allclose(robot.mass_matrix(q), pin.crba(model, data, q), atol=1e-12)
        np.testing.assert_allclose(robot.gravity_torque(q), pin.computeGeneralizedGravity(model, data, q), atol=1e-12)


def _loaded(path, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = kd.load(path, **kwargs)
    return robot, [str(w.message) for w in caught]


# ----------------------------------------------------------------------------- URDF: degenerate shapes
@pytest.mark.parametrize(
    "shape, detail",
    [
        ('<sphere radius="0"/>', "radius 0 is not positive"),  # ARMAR-4 ships one
        ('<cylinder radius="0" length="0.1"/>', "radius 0 and length 0.1"),
        ('<box size="0.1 0 0.1"/>', "size '0.1 0 0.1' is not 3 positive numbers"),
        ('<box size="0.1 -1 0.1"/>', "size '0.1 -1 0.1' is not 3 positive numbers"),
        ('<mesh filename="a.stl" scale="1 0 1"/>', "scale '1 0 1' holds 0"),
    ],
)
def test_a_degenerate_shape_is_a_warning_and_no_shape_as_pinocchio_loads_the_file(tmp_path, shape, detail):
    geometry = f"<visual><geometry>{shape}</geometry></visual><collision><geometry>{shape}</geometry></collision>"
    path = tmp_path / "degenerate.urdf"
    path.write_text(_urdf(geometry))
    robot, messages = _loaded(path)
    assert robot.description.visuals == () and robot.description.collisions == ()
    tag = shape[1 : shape.index(" ")]
    for kind in ("visual", "collision"):
        expected = f"{path}:3: link 'b' <{kind}> <{tag}> is degenerate ({detail}"
        assert any(m.startswith(expected) and m.endswith("no shape is kept for it") for m in messages), messages
    model = pin.buildModelFromUrdf(str(path))  # the reference reads the same file
    _same_dynamics_as_pinocchio(robot, model)


def test_a_good_shape_beside_a_degenerate_one_is_kept(tmp_path):
    geometry = '<visual><geometry><sphere radius="0"/></geometry></visual><visual><geometry><sphere radius="0.2"/></geometry></visual>'
    path = tmp_path / "two.urdf"
    path.write_text(_urdf(geometry))
    robot, _ = _loaded(path)
    assert [v.shape.radius for v in robot.description.visuals] == [0.2]


# ----------------------------------------------------------------------------- URDF: limits and mimic
@pytest.mark.parametrize(
    "limit, lower, upper",
    [
        ('<limit lower="1" upper="-1" effort="5" velocity="2"/>', 1, -1),
        ('<limit lower="2" effort="5" velocity="2"/>', 2, 0),
    ],
)
def test_inverted_limits_load_without_position_limits_and_say_so(tmp_path, limit, lower, upper):
    path = tmp_path / "inverted.urdf"
    path.write_text(_urdf(limit=limit))
    robot, messages = _loaded(path)
    assert robot.lower_limits[0] == -np.inf and robot.upper_limits[0] == np.inf
    assert robot.effort_limits[0] == 5 and robot.velocity_limits[0] == 2
    assert any(m.startswith(f"{path}:4: joint 'j': <limit> lower {lower} is above upper {upper}") for m in messages)
    model = pin.buildModelFromUrdf(str(path))
    assert (model.lowerPositionLimit[0], model.upperPositionLimit[0]) == (lower, upper)  # Pinocchio keeps them
    _same_dynamics_as_pinocchio(robot, model)


def test_zero_effort_and_velocity_limits_and_an_empty_interval_load_as_given(tmp_path):
    path = tmp_path / "zero.urdf"
    path.write_text(_urdf(limit='<limit lower="0" upper="0" effort="0" velocity="0"/>'))
    robot, _ = _loaded(path)
    model = pin.buildModelFromUrdf(str(path))
    assert robot.effort_limits[0] == model.effortLimit[0] == 0
    assert robot.velocity_limits[0] == model.velocityLimit[0] == 0
    assert robot.lower_limits[0] == robot.upper_limits[0] == model.lowerPositionLimit[0] == 0


def test_a_mimic_multiplier_of_zero_leaves_the_joint_independent_as_pinocchio_reads_it(tmp_path):
    follower = (
        '<link name="c"/><joint name="k" type="revolute"><parent link="b"/><child link="c"/>'
        f'{LIMIT}<mimic joint="j" multiplier="0" offset="0.3"/></joint>\n'
    )
    path = tmp_path / "mimic0.urdf"
    path.write_text(_urdf(extra_joint=follower))
    robot, messages = _loaded(path)
    assert robot.nq == pin.buildModelFromUrdf(str(path)).nq == 2 and robot.mimic_joints == {}
    assert any(m.startswith(f"{path}:5: joint 'k': <mimic> multiplier 0") for m in messages), messages


def test_a_zero_axis_is_refused_as_mujoco_refuses_it(tmp_path):
    path = tmp_path / "axis.urdf"
    path.write_text(_urdf(limit=LIMIT + '<axis xyz="0 0 0"/>').replace('<axis xyz="0 1 0"/>', ""))
    with pytest.raises(ValueError, match=rf"^{re.escape(str(path))}:4: joint 'j': axis .* zero"):
        kd.load(path)


# ----------------------------------------------------------------------------- URDF: no moving joint
DRONE = """<robot name="drone">
<link name="body"><inertial><origin xyz="0.01 0 0"/><mass value="1.5"/>
  <inertia ixx="0.01" iyy="0.012" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="camera"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="mount" type="fixed"><origin xyz="0.1 0 -0.05"/><parent link="body"/><child link="camera"/></joint>
</robot>"""


def test_a_urdf_without_moving_joints_is_a_robot_with_no_degrees_of_freedom(tmp_path):
    path = tmp_path / "drone.urdf"
    path.write_text(DRONE)
    robot = kd.load(path)
    assert robot.nq == robot.nv == pin.buildModelFromUrdf(str(path)).nq == 0
    q = np.zeros(0)
    assert robot.mass_matrix(q).shape == (0, 0) and robot.mass_matrix(np.zeros((5, 0))).shape == (5, 0, 0)
    assert robot.gravity_torque(q).shape == robot.inverse_dynamics(q, q, q).shape == (0,)
    assert robot.forward_dynamics(q, q, q).shape == (0,) and robot.coriolis_matrix(q, q).shape == (0, 0)
    assert robot.jacobian(q, "camera").shape == (6, 0) and robot.regressor(q, q, q).shape == (0, 0)
    assert robot.kinetic_energy(q, q) == 0.0 and robot.neutral().shape == robot.random_configuration().shape == (0,)
    np.testing.assert_allclose(robot.pose(q, "camera")[:3, 3], [0.1, 0, -0.05])
    # floating_base=True makes the same body a free flyer, as Pinocchio's JointModelFreeFlyer root
    flying = kd.load(path, floating_base=True)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    assert flying.nq == model.nq == 7
    data = model.createData()
    q7 = pin.randomConfiguration(model, -np.ones(7), np.ones(7))
    np.testing.assert_allclose(flying.mass_matrix(q7), pin.crba(model, data, q7), atol=1e-12)


def test_batches_and_the_native_solver_answer_for_a_model_with_no_degrees_of_freedom(tmp_path):
    """A batch of runs splits its outputs into rows of zero numbers, and the core's IK has nothing to
    move: each gives an answer or a ValueError, never the binding's internal error."""
    from kinedyn import _core

    path = tmp_path / "drone.urdf"
    path.write_text(DRONE)
    robot = kd.load(path)
    runs = kd.simulate(robot, 0.01, np.zeros((3, 0)), dt=1e-3)
    assert runs.q.shape[0] == 3 and runs.q.shape[-1] == 0
    targets = np.tile(np.eye(4), (8, 1, 1))
    with pytest.raises(ValueError, match="no moving joint"):
        _core.solve_ik(
            robot._model, 0, targets, np.zeros((8, 0)), np.zeros(0), np.zeros(0), np.ones(6), 10, 1, 1e-6, 1e-6
        )


def test_the_cli_and_the_checks_answer_for_a_robot_with_no_degrees_of_freedom(tmp_path, capsys):
    from kinedyn.cli import main

    path = tmp_path / "drone.urdf"
    path.write_text(DRONE)
    for command in (["jacobian", str(path), "--frame", "camera"], ["simulate", str(path), "--t", "0.01"]):
        assert main(command) == 0, capsys.readouterr().err
    assert main(["check", str(path)]) != 0
    assert "no degrees of freedom" in capsys.readouterr().err
    assert main(["ik", str(path), "--xyz", "0.1", "0", "0"]) == 1
    assert "has no moving joint" in capsys.readouterr().err  # not the native core's panic
    assert main(["convert", str(path), str(tmp_path / "drone.xml")]) == 0, capsys.readouterr().err
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "drone.xml")).nq == 0
    assert main(["report", str(path), "-o", str(tmp_path / "drone.html"), "--t", "0.05"]) == 0, capsys.readouterr().err
    assert "Audit of the robot file" in (tmp_path / "drone.html").read_text()


EXAMPLE_ROBOTS = Path(pin.__file__).parents[4] / "share" / "example-robot-data" / "robots"


@pytest.mark.skipif(not EXAMPLE_ROBOTS.is_dir(), reason="example-robot-data is not installed")
def test_example_robot_data_hector_has_no_moving_joint_and_talos_meshes_all_resolve():
    hector = EXAMPLE_ROBOTS / "hector_description" / "robots" / "quadrotor_base.urdf"
    assert kd.load(hector).nq == pin.buildModelFromUrdf(str(hector)).nq == 0
    # Talos writes its meshes as package:///example-robot-data/... (three slashes)
    talos = EXAMPLE_ROBOTS / "talos_data" / "robots" / "talos_full_v2.urdf"
    assert "package:///" in talos.read_text()
    robot = kd.load(talos)
    meshes = [v.shape for v in robot.description.visuals if isinstance(v.shape, Mesh)]
    assert all(resolve_mesh(m.filename, m.base_dir).is_file() for m in meshes)
    model = pin.buildModelFromUrdf(str(talos))
    visuals = pin.buildGeomFromUrdf(
        model, str(talos), pin.GeometryType.VISUAL, package_dirs=[str(EXAMPLE_ROBOTS.parents[1])]
    )
    assert len(robot.description.visuals) == visuals.ngeoms == 53


def test_package_urls_with_three_slashes_name_the_same_file(tmp_path):
    cube = tmp_path / "pkg" / "meshes" / "cube.stl"
    cube.parent.mkdir(parents=True)
    cube.write_bytes(b"solid c\nendsolid c\n")
    base = str(tmp_path / "pkg" / "urdf")
    os.makedirs(base)
    assert resolve_mesh("package:///pkg/meshes/cube.stl", base) == resolve_mesh("package://pkg/meshes/cube.stl", base)
    assert resolve_mesh(f"file://{cube}", base) == cube
    with pytest.raises(ValueError, match="without '..'"):
        resolve_mesh("package:///pkg/../../x.stl", base)


# ----------------------------------------------------------------------------- MJCF: name scopes
BODY = '<body name="x" pos="0 0 -0.3"><joint name="{joint}" axis="0 1 0"/><geom name="{geom}" size="0.1"/>{site}</body>'


@pytest.mark.parametrize(
    "world",
    [
        '<site name="x" pos="0.2 0 0"/>' + BODY.format(joint="j", geom="g", site=""),  # a site before the body
        BODY.format(joint="j", geom="g", site="") + '<site name="x" pos="0.2 0 0"/>',  # and after it
        BODY.format(joint="x", geom="x", site='<site name="x" pos="0.2 0 0"/>'),  # every kind named x
    ],
)
def test_mjcf_names_are_kept_per_element_kind_as_mujoco_keeps_them(world):
    xml = f"<mujoco><worldbody>{world}</worldbody></mujoco>"
    robot = kd.Robot.from_mjcf(xml)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[:] = 0.4
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(robot.pose([0.4], "x")[:3, 3], data.body("x").xpos, atol=1e-12)
    np.testing.assert_allclose(robot.pose([0.4], "site:x")[:3, 3], data.site("x").xpos, atol=1e-12)


@pytest.mark.parametrize("kind", ["mesh", "material"])
def test_asset_names_are_scoped_per_kind_too(kind):
    twice = f'<{kind} name="m" {"vertex" if kind == "mesh" else "rgba"}="{"0 0 0 1 0 0 0 1 0 0 0 1" if kind == "mesh" else "1 0 0 1"}"/>'
    xml = (
        f"<mujoco><asset>{twice}{twice}</asset><worldbody><body name='m'><joint name='m'/>"
        "<geom name='m' size='0.1'/></body></worldbody></mujoco>"
    )
    with pytest.raises(ValueError, match="repeated name"):
        mujoco.MjModel.from_xml_string(xml)
    with pytest.raises(ValueError, match=rf"<{kind}> the name 'm' is given to two <{kind}> elements"):
        kd.Robot.from_mjcf(xml)
    once = xml.replace(twice + twice, twice)  # a mesh, a material, a body, a joint and a geom all named m
    assert mujoco.MjModel.from_xml_string(once).nq == kd.Robot.from_mjcf(once).nq == 1


@pytest.mark.parametrize("kind", ["body", "joint", "geom", "site"])
def test_a_name_given_twice_within_one_kind_is_refused_as_mujoco_refuses_it(kind):
    names = {"body": ("x", "y", "j", "k", "g", "h"), "joint": ("a", "b", "j", "j", "g", "h")}
    names["geom"] = ("a", "b", "j", "k", "g", "g")
    a, b, j, k, g, h = names.get(kind, ("a", "b", "j", "k", "g", "h"))
    if kind == "body":
        a = b = "x"
    site = '<site name="s"/>' if kind == "site" else ""
    xml = (
        f'<mujoco><worldbody>{site}<body name="{a}"><joint name="{j}"/><geom name="{g}" size="0.1"/>{site}</body>\n'
        f'<body name="{b}"><joint name="{k}"/><geom name="{h}" size="0.1"/></body></worldbody></mujoco>'
    )
    with pytest.raises(ValueError, match="repeated name"):
        mujoco.MjModel.from_xml_string(xml)
    with pytest.raises(ValueError, match=rf"<{kind}> the name '\w' is given to two <{kind}> elements"):
        kd.Robot.from_mjcf(xml)


# ----------------------------------------------------------------------------- MJCF: defaults, options
def test_two_top_level_defaults_merge_into_main_as_mujoco_merges_them(tmp_path):
    # the Jaco arm gets its second top-level <default> from an included file
    (tmp_path / "more.xml").write_text('<mujoco><default><geom size="0.3"/><joint armature="0.5"/></default></mujoco>')
    (tmp_path / "arm.xml").write_text(
        '<mujoco><default><joint damping="2"/><default class="c"><geom size="0.2"/></default></default>'
        '<include file="more.xml"/>'
        '<worldbody><body name="a"><joint axis="0 1 0"/><geom pos="0.2 0 0"/>'
        '<body name="b" pos="0.4 0 0"><joint axis="0 1 0"/><geom class="c" pos="0.1 0 0"/></body></body></worldbody></mujoco>'
    )
    robot = kd.load(tmp_path / "arm.xml")
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "arm.xml"))
    np.testing.assert_allclose(robot.armature, model.dof_armature)  # from the second block
    np.testing.assert_allclose(robot.viscous, model.dof_damping)  # from the first
    data = mujoco.MjData(model)
    data.qpos[:] = [0.3, -0.7]
    mujoco.mj_forward(model, data)
    M = np.zeros((2, 2))
    try:
        mujoco.mj_fullM(model, data, M)  # MuJoCo >= 3.4 (m, d, dst)
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)  # earlier (m, dst, qM)
    np.testing.assert_allclose(robot.mass_matrix([0.3, -0.7]), M, atol=1e-9)
    with pytest.raises(ValueError, match="class 'c' is defined twice"):
        kd.Robot.from_mjcf(
            '<mujoco><default><default class="c"/></default><default><default class="c"/></default>'
            '<worldbody><body><joint/><geom size="1"/></body></worldbody></mujoco>'
        )


SWIMMER = '<mujoco>{option}<worldbody><body name="a"><joint axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.05"/></body></worldbody></mujoco>'


@pytest.mark.parametrize(
    "option, named",
    [
        ('<option density="1000" viscosity="0.1"/>', "density='1000', viscosity='0.1'"),
        ('<option wind="0 1 0"/>', "wind='0 1 0'"),
        ('<option viscosity="0.0009"/>', "viscosity='0.0009'"),
    ],
)
def test_mujocos_fluid_forces_are_named_as_not_modelled(option, named):
    xml = SWIMMER.format(option=option)
    with pytest.warns(UserWarning, match=rf"does not model, and ignores: fluid forces \(<option {named}>"):
        kd.Robot.from_mjcf(xml)
    # MuJoCo applies them: a turning body in a fluid feels a passive torque kinedyn leaves out
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qvel[:] = 3.0
    mujoco.mj_forward(model, data)
    if "density" in option or "viscosity" in option:
        assert abs(data.qfrc_passive[0]) > 0


PYBULLET_SWIMMER = None
try:
    import pybullet_data

    PYBULLET_SWIMMER = Path(pybullet_data.getDataPath()) / "mjcf" / "swimmer.xml"
except ImportError:  # pragma: no cover - the peers extra
    pass


@pytest.mark.skipif(PYBULLET_SWIMMER is None or not PYBULLET_SWIMMER.is_file(), reason="pybullet_data is not installed")
def test_the_gym_swimmer_says_its_fluid_forces_are_not_modelled():
    with pytest.warns(UserWarning, match=r"fluid forces \(<option density='4000', viscosity='0.1'>"):
        robot = kd.load(PYBULLET_SWIMMER)
    # MuJoCo 3+ refuses this old file's <option collision>; its joints are hinges and slides, one coordinate each
    text = PYBULLET_SWIMMER.read_text()
    assert robot.nq == text.count("<joint") - text.count("<joint ", text.index("<default"), text.index("</default>"))


@pytest.mark.parametrize(
    "xml",
    [
        '<mujoco><compiler alignfree="true"/><worldbody><body><freejoint/><geom size="0.1" pos="0.1 0 0"/></body></worldbody></mujoco>',
        '<mujoco><worldbody><body><freejoint align="true"/><geom size="0.1" pos="0.1 0 0"/></body></worldbody></mujoco>',
    ],
)
def test_aligned_free_bodies_are_named_as_read_differently(xml):
    with pytest.warns(UserWarning, match="aligned qpos"):
        kd.Robot.from_mjcf(xml)
    mujoco.MjModel.from_xml_string(xml)  # MuJoCo reads both forms


def test_no_fluid_warning_when_the_fluid_is_off():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kd.Robot.from_mjcf(SWIMMER.format(option='<option density="0" viscosity="0" timestep="0.001"/>'))


@pytest.mark.parametrize("flag", ['<flag damper="disable"/>', "", '<flag frictionloss="disable"/>'])
def test_option_flags_that_drop_passive_forces_are_honoured(flag):
    xml = (
        f"<mujoco><option>{flag}</option><worldbody><body><joint axis='0 1 0' damping='3' frictionloss='0.5'/>"
        "<geom size='0.1' pos='0.2 0 0'/></body></worldbody></mujoco>"
    )
    robot = kd.Robot.from_mjcf(xml)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qvel[:] = 2.0
    mujoco.mj_forward(model, data)
    # MuJoCo's damping is a passive force; kinedyn's viscous friction torque is its negative
    np.testing.assert_allclose(robot.viscous * 2.0, -data.qfrc_passive, atol=1e-12)
    assert robot.coulomb[0] == (0.0 if "frictionloss" in flag else 0.5)
    if "frictionloss" in flag:  # MuJoCo's frictionloss is a constraint row: none is made
        assert data.nefc == 0
