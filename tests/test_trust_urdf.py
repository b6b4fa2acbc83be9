"""Trust at the URDF boundary (issue 11, sections 2-4): loading is linear and bounded, every bad file
is a ValueError naming file, line and field (once), description values are checked however a robot
is built, and the inertia policy loads real robots whose tensors no rigid body can have."""

from __future__ import annotations

import math
import re
import time
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from reference import erd

import kinedyn as kd
from kinedyn import Inertia, Joint, Link
from kinedyn.description import inertia as inertia_module
from kinedyn.description.urdf import MAX_DEPTH
from kinedyn.robot_files import robot_from_urdf

BODY = '<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'


def chain_urdf(moving: int, fixed_after: int = 0, wide: int = 0) -> str:
    """base -> `moving` revolute links -> `fixed_after` fixed links; plus `wide` revolute children of base."""
    links, joints, parent = ['<link name="base"/>'], [], "base"
    for i in range(moving):
        links.append(f'<link name="m{i}">{BODY}</link>')
        joints.append(
            f'<joint name="jm{i}" type="revolute"><parent link="{parent}"/><child link="m{i}"/>'
            f'<origin xyz="0 0 0.1" rpy="0 0.1 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>'
        )
        parent = f"m{i}"
    for i in range(fixed_after):
        links.append(f'<link name="f{i}">{BODY}</link>')
        joints.append(
            f'<joint name="jf{i}" type="fixed"><parent link="{parent}"/><child link="f{i}"/><origin xyz="0 0 0.1"/></joint>'
        )
        parent = f"f{i}"
    for i in range(wide):
        links.append(f'<link name="w{i}">{BODY}</link>')
        joints.append(f'<joint name="jw{i}" type="continuous"><parent link="base"/><child link="w{i}"/></joint>')
    return '<robot name="gen">\n' + "\n".join(links + joints) + "\n</robot>\n"


# ------------------------------------------------------------------------ 2. bounded, linear loading
def test_2000_fixed_links_after_the_last_joint_load_quickly():
    """The default-tool search was cubic: 56 s for this file. Generous bound (the load takes ~1 s)."""
    xml = chain_urdf(1, 2000)
    start = time.perf_counter()
    robot = robot_from_urdf(xml)
    assert time.perf_counter() - start < 10.0
    assert robot.n == 1 and robot.tool == "f1999"
    assert robot.tree.bodies[0].inertia.mass == pytest.approx(1 + 0.0 + 2000 * 1.0)


def _reference_default_tool(links, base):
    """The default tool by brute force (quadratic), for names that are no tool name: the end of the
    longest chain -- the deepest moving link (most moving joints down from the base; the later one in
    the file of equal ones), then the later link it carries through fixed joints."""
    by_name = {l.name: l for l in links}

    def chain(name):  # the links from `name` up to the base
        out = []
        while name in by_name:
            out.append(by_name[name])
            name = by_name[name].parent
        return out

    depth = {l.name: sum(x.joint.is_moving for x in chain(l.name)) for l in links}
    moving = [l.name for l in links if l.joint.is_moving]
    if not moving:
        return base
    deepest = max(moving, key=lambda name: (depth[name], moving.index(name)))
    carried = [l.name for l in links if next((x.name for x in chain(l.name) if x.joint.is_moving), None) == deepest]
    return carried[-1]


@st.composite
def random_trees(draw):
    """A random URDF tree: each new link hangs from a random earlier one, by a fixed or moving joint."""
    n = draw(st.integers(1, 25))
    links, joints = ['<link name="root"/>'], []
    names = ["root"]
    any_moving = False
    for i in range(n):
        parent = names[draw(st.integers(0, len(names) - 1))]
        moving = draw(st.booleans()) or (i == n - 1 and not any_moving)
        any_moving |= moving
        links.append(f'<link name="l{i}"/>')
        kind = "revolute" if moving else "fixed"
        joints.append(
            f'<joint name="j{i}" type="{kind}"><parent link="{parent}"/><child link="l{i}"/>'
            f'<limit lower="-1" upper="1"/></joint>'
        )
        names.append(f"l{i}")
    return "<robot name='t'>" + "".join(links + joints) + "</robot>"


@settings(max_examples=60, deadline=None)
@given(random_trees())
def test_default_tool_is_the_end_of_the_longest_chain(xml):
    robot = robot_from_urdf(xml)
    assert robot.tool == _reference_default_tool(list(robot.links), robot.base)


@pytest.mark.parametrize(
    "name, tool",
    [
        ("ur_description/urdf/ur5_robot.urdf", "tool0"),  # REP 199's name
        ("panda_description/urdf/panda.urdf", "panda_hand_tcp"),  # not a finger (issue 13 §5)
        ("talos_data/robots/talos_full_v2.urdf", "wrist_right_ft_tool_link"),  # not a sole
        ("romeo_description/urdf/romeo.urdf", "RThumb3Link"),
    ],
)  # no tool name: longest chain
def test_default_tool_of_real_robots(name, tool):
    robot = robot_from_urdf(erd(*name.split("/")))
    assert robot.tool == tool


BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE robot [
  <!ENTITY a "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa">
  <!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">
  <!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">
  <!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">
  <!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;">
  <!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;">
]>
<robot name="&f;"><link name="base"/></robot>
"""


@pytest.mark.parametrize(
    "xml, message",
    [
        (BILLION_LAUGHS, r"<URDF string>:2: a DOCTYPE with declarations"),
        (
            '<?xml version="1.0"?>\n<!DOCTYPE robot SYSTEM "file:///etc/passwd">\n<robot name="&x;"/>',
            r":2: a DOCTYPE .* external DTD",
        ),
        (
            "<robot>" + "<a>" * (MAX_DEPTH + 5) + "</a>" * (MAX_DEPTH + 5) + "</robot>",
            rf"<URDF string>:1: elements nested deeper than {MAX_DEPTH}",
        ),
        ("<robot name='&undefined;'/>", r"malformed XML at line 1, column \d+: undefined entity"),
    ],
)
def test_xml_that_could_expand_or_nest_without_bound_is_refused_quickly(xml, message):
    start = time.perf_counter()
    with pytest.raises(ValueError, match=message):
        robot_from_urdf(xml)
    assert time.perf_counter() - start < 2.0


def test_a_million_nested_elements_fail_fast():
    xml = "<robot>" + "<a>" * 1_000_000 + "</a>" * 1_000_000 + "</robot>"
    start = time.perf_counter()
    with pytest.raises(ValueError, match="nested deeper"):
        robot_from_urdf(xml)
    assert time.perf_counter() - start < 2.0


def test_plain_doctype_and_namespaces_are_accepted():
    body = '<link name="base"/><link name="a"/><joint name="j" type="revolute"><parent link="base"/><child link="a"/><limit lower="-1" upper="1"/></joint>'
    assert robot_from_urdf(f'<?xml version="1.0"?>\n<!DOCTYPE robot>\n<robot name="r">{body}</robot>').n == 1
    assert robot_from_urdf(f'<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">{body}</robot>').n == 1


def test_file_encoding_declaration_is_honoured(tmp_path):
    path = tmp_path / "latin.urdf"
    xml = (
        '<?xml version="1.0" encoding="ISO-8859-1"?>\n<robot name="r\xe9"><link name="base"/><link name="a"/>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="a"/><limit lower="-1" upper="1"/></joint></robot>'
    )
    path.write_bytes(xml.encode("latin-1"))
    assert robot_from_urdf(path).name == "r\xe9"


# --------------------------------------------------------- 3. every bad file: one ValueError, file, line, field
def _joint_file(joint_inner: str = "", link_inner: str = "", kind: str = "revolute") -> str:
    """A two-link file; the joint's element starts on line 4, the link 'a' on line 3."""
    return (
        '<?xml version="1.0"?>\n<robot name="r">\n'
        f'<link name="a">{link_inner}</link>\n'
        f'<joint name="j" type="{kind}"><parent link="base"/><child link="a"/>{joint_inner}</joint>\n'
        '<link name="base"/>\n</robot>\n'
    )


BIG = "1" + "0" * 400
BAD_FILES = {
    # name: (joint inner xml, link inner xml, expected line, expected text)
    "origin_nan": ('<origin xyz="nan 0 0"/>', "", 4, r"joint 'j' origin xyz must be 3 finite numbers"),
    "origin_inf_rpy": ('<origin rpy="0 inf 0"/>', "", 4, r"joint 'j' origin rpy must be 3 finite numbers"),
    "origin_1e200": (
        '<origin xyz="1e200 0 0"/>',
        "",
        4,
        r"joint 'j' origin xyz has 1e\+200, larger in magnitude than 1e\+100",
    ),
    "origin_two_numbers": ('<origin xyz="0 0"/>', "", 4, r"joint 'j' origin xyz must be 3 numbers, got 2"),
    "axis_nan": ('<axis xyz="0 0 nan"/>', "", 4, r"joint 'j' axis must be 3 finite numbers"),
    "axis_zero": ('<axis xyz="0 0 0"/>', "", 4, r"joint 'j': axis .* zero"),
    "axis_words": ('<axis xyz="x y z"/>', "", 4, r"joint 'j' axis must be 3 numbers, got 'x y z'"),
    "limit_nan": (
        '<limit lower="nan" upper="1"/>',
        "",
        4,
        r"joint 'j' <limit> attribute 'lower' must be 1 finite numbers",
    ),
    "limit_huge_integer": (
        f'<limit lower="-1" upper="{BIG}"/>',
        "",
        4,
        r"joint 'j' <limit> attribute 'upper' must be 1 finite",
    ),
    "limit_velocity_negative": (
        '<limit lower="-1" upper="1" velocity="-2"/>',
        "",
        4,
        r"joint 'j': velocity_limit is negative",
    ),
    "damping_nan": ('<dynamics damping="nan"/>', "", 4, r"joint 'j' <dynamics> attribute 'damping' must be 1 finite"),
    "friction_1e200": ('<dynamics friction="1e200"/>', "", 4, r"joint 'j' <dynamics> attribute 'friction' has 1e\+200"),
    "damping_negative": ('<dynamics damping="-1"/>', "", 4, r"joint 'j': viscous must be >= 0"),
    "mass_huge_integer": (
        "",
        f'<inertial><mass value="{BIG}"/></inertial>',
        3,
        r"link 'a' <inertial> <mass> attribute 'value' must be 1 finite",
    ),
    "mass_1e200": (
        "",
        '<inertial><mass value="1e200"/></inertial>',
        3,
        r"link 'a' <inertial> <mass> attribute 'value' has 1e\+200",
    ),
    "mass_missing_value": (
        "",
        "<inertial><mass/></inertial>",
        3,
        r"link 'a' <inertial> <mass> has no 'value' attribute",
    ),
    "mass_negative": ("", '<inertial><mass value="-1"/></inertial>', 3, r"link 'a' <inertial>: mass is negative"),
    "inertia_nan": (
        "",
        '<inertial><mass value="1"/><inertia ixx="nan"/></inertial>',
        3,
        r"link 'a' <inertial> <inertia> attribute 'ixx' must be 1 finite",
    ),
    "inertia_1e200": (
        "",
        '<inertial><mass value="1"/><inertia ixx="1e200" iyy="1" izz="1"/></inertial>',
        3,
        r"attribute 'ixx' has 1e\+200",
    ),
    "inertial_origin_inf": (
        "",
        '<inertial><origin xyz="0 0 -inf"/><mass value="1"/></inertial>',
        3,
        r"link 'a' <inertial> origin xyz must be 3 finite",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_FILES))
def test_bad_value_names_file_line_and_field_once(tmp_path, case):
    joint_inner, link_inner, line, text = BAD_FILES[case]
    path = tmp_path / f"{case}.urdf"
    path.write_text(_joint_file(joint_inner, link_inner))
    with pytest.raises(ValueError) as info:
        kd.load(path)
    message = str(info.value)
    assert type(info.value) is ValueError
    assert message.startswith(f"{path}:{line}: "), message
    assert message.count(str(path)) == 1 and message.count(f"{case}.urdf") == 1, message  # prefix not repeated
    assert re.search(text, message), message


@pytest.mark.parametrize(
    "xml, line, text",
    [
        (
            "<robot name='r'>\n<link name='a'/>\n<link name='a'/>\n</robot>",
            3,
            r"link 'a' is defined twice \(first at line 2\)",
        ),
        (
            "<robot name='r'>\n<link name='a'/>\n<link name='b'/>\n<joint name='j' type='ball'><parent link='a'/><child link='b'/></joint>\n</robot>",
            4,
            r"joint 'j' has type 'ball', which is not supported",
        ),
        (
            "<robot name='r'>\n<link name='a'/>\n<link name='b'/>\n<joint name='j' type='revolute'><child link='b'/></joint>\n</robot>",
            4,
            r"joint 'j' has no <parent link=...>",
        ),
        ("<robot name='r'>\n<link/>\n</robot>", 2, r"a <link> has no name"),
        (
            "<robot name='r'>\n<link name='a'/>\n<link name='b'/>\n<joint name='j'><parent link='a'/><child link='b'/></joint>\n</robot>",
            4,
            r"joint 'j' has no type attribute",
        ),
        (
            "<robot name='r'>\n<link name='a'/>\n<link name='b'/>\n<joint type='fixed'><parent link='a'/><child link='b'/></joint>\n</robot>",
            4,
            r"a <joint> has no name",
        ),
    ],
)
def test_structural_errors_name_the_line(xml, line, text):
    with pytest.raises(ValueError) as info:
        robot_from_urdf(xml)
    message = str(info.value)
    assert message.startswith(f"<URDF string>:{line}: "), message
    assert re.search(text, message), message


def test_a_cycle_of_thousands_of_links_is_reported_in_linear_time():
    n = 5000
    links = "".join(f'<link name="l{i}"/>' for i in range(n))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{(i + 1) % n}"/></joint>'
        for i in range(n)
    )
    start = time.perf_counter()
    with pytest.raises(
        ValueError, match=r"no root link: its joints form a cycle \(l1 <- l0 <- l4999 <- .* 4991 more .* <- l1\)"
    ):
        robot_from_urdf(f"<robot name='c'>{links}{joints}</robot>")
    assert time.perf_counter() - start < 5.0


def test_robot_level_errors_get_the_file_once(tmp_path):
    path = tmp_path / "still.urdf"
    path.write_text(
        "<robot name='still'><link name='a'/><link name='b'/>"
        "<joint name='j' type='fixed'><parent link='a'/><child link='b'/></joint></robot>"
    )
    with pytest.raises(ValueError) as info:
        kd.load(path, tool="nope")
    assert str(info.value).startswith(f"{path}: tool frame 'nope' is not a frame of robot 'still'")
    assert str(info.value).count(str(path)) == 1
    with pytest.raises(ValueError) as info:
        kd.load(path.with_name("missing.urdf"))
    assert str(info.value).count("missing.urdf") == 1


# ------------------------------------------- 3. description-layer checks (Python construction, every route)
@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(offset=float("nan")), r"joint 'j': offset is not finite"),
        (dict(offset=1e200), r"joint 'j': offset is 1e\+200: larger in magnitude than 1e\+100"),
        (dict(offset=10**400), r"joint 'j': offset is too large \(401 digits"),
        (dict(offset=1 + 2j), r"joint 'j': offset must be a real number"),
        (dict(viscous=float("inf")), r"joint 'j': viscous is not finite"),
        (dict(coulomb=float("nan")), r"joint 'j': coulomb is not finite"),
        (dict(gear_ratio=0), r"joint 'j': gear_ratio must be non-zero"),
        (dict(gear_ratio=1e200), r"joint 'j': gear_ratio is 1e\+200"),
        (dict(rotor_inertia=float("nan")), r"joint 'j': rotor_inertia is not finite"),
        (dict(axis=(0, float("nan"), 1)), r"joint 'j': axis\[1\] is not finite"),
        (dict(axis=(0, 1e200, 1)), r"joint 'j': axis\[1\] is 1e\+200"),
        (dict(axis=[1, 2]), r"joint 'j': axis must have 3 components"),
        (dict(axis=5), r"joint 'j': axis must be 3 numbers"),
        (dict(lower=2.0, upper=1.0), r"joint 'j': lower limit 2.0 exceeds upper limit 1.0"),
        (dict(lower=10**400), r"joint 'j': lower is too large"),
        (dict(lower=math.inf), r"joint 'j': limits \[inf, inf\] admit no position"),
        (dict(upper=[1]), r"joint 'j': upper must be a real number"),
        (dict(effort_limit=float("nan")), r"joint 'j': effort_limit is NaN"),
    ],
)
def test_joint_values_are_checked_with_the_field_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Joint("j", **kwargs)


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Inertia(10**400), r"mass is too large"),
        (lambda: Inertia(1e200), r"mass is 1e\+200"),
        (lambda: Inertia(1.0, (0, 1e200, 0)), r"centre of mass\[1\] is 1e\+200"),
        (
            lambda: Inertia(1.0, (0, 0, 0), [[1, 0, 0], [0, float("nan"), 0], [0, 0, 1]]),
            r"inertia tensor\[1\]\[1\] is not finite",
        ),
        (lambda: Inertia(1.0, (0, 0, 0), np.eye(3) * 1e200), r"inertia tensor\[0\]\[0\] is 1e\+200"),
        (lambda: Inertia(1.0, (0, 0, 0), np.eye(3) + 1j), r"inertia tensor\[0\]\[0\] must be a real number"),
        (lambda: Inertia(1.0, (0, 0, 0), np.eye(2)), r"inertia tensor must be 3x3"),
        (
            lambda: Link("a", None, Joint("j"), np.diag([1, 1, 1, 1.0]) + np.pad([[0, 0, 0, 1e200]], ((0, 3), (0, 0)))),
            r"placement of link 'a' has a translation larger in magnitude than 1e\+100",
        ),
        (lambda: Link("a", None, "revolute"), r"link 'a': joint must be a Joint"),
        (lambda: Link("a", None, Joint("j"), np.eye(4) * (1 + 0j)), r"placement of link 'a' must be real, got complex"),
        (lambda: kd.Robot.from_dh([(0, 0, 1j, 0)]), r"DH row 1: a must be a real number"),
        (lambda: kd.Robot.from_dh([(0, 0, 1, 10**400)]), r"DH row 1: alpha is too large"),
        (lambda: kd.Robot.from_dh([(0, float("nan"), 1, 0)]), r"DH row 1: d is not finite"),
        (lambda: kd.Robot([Link("a", None, Joint("j"))], gravity=(0, 0, float("nan"))), r"gravity\[2\] is not finite"),
        (lambda: kd.Robot([Link("a", None, Joint("j"))], gravity=(0, 0, 1e200)), r"gravity\[2\] is 1e\+200"),
        (lambda: kd.Robot([Link("a", None, Joint("j"))], gravity=(0, 0)), r"gravity must have 3 components"),
        (lambda: kd.Robot([Link("a", None, Joint("j"))], inertia="lenient"), r"inertia policy must be one of"),
    ],
)
def test_description_values_are_checked_at_construction(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_symbolic_values_still_pass():
    import sympy as sp

    r, J = sp.symbols("r J_m", positive=True)
    joint = Joint("j", gear_ratio=r, rotor_inertia=J, offset=sp.pi / 2)
    assert joint.gear_ratio == r and joint.offset == pytest.approx(math.pi / 2)


@pytest.mark.parametrize("limits", [dict(lower=5.0), dict(upper=-5.0), dict(lower=0.5, upper=0.5), dict(lower=-1.0)])
def test_random_configuration_with_one_sided_limits(limits):
    """A one-sided limit (lower=5 with no upper) made random_configuration ask for low > high."""
    for kind in ("revolute", "prismatic"):
        robot = kd.Robot([Link("a", None, Joint("j", kind, **limits))])
        q = robot.random_configuration(0, size=200)
        assert np.all(q >= robot.lower_limits) and np.all(q <= robot.upper_limits)


# ------------------------------------------------------------------------ 4. inertia policy
TIAGO = ("tiago_description", "robots", "tiago.urdf")
ROMEO = ("romeo_description", "urdf", "romeo_laas_small.urdf")
ROMEO_GRIPPERS = {"l_gripper_joint": 0.0, "r_gripper_joint": 0.0}  # massless subtrees: M singular in any policy


@pytest.fixture(autouse=True)
def _fresh_reports():
    inertia_module._WARNED.clear()  # each (link, tensor) is reported once per process
    yield


def _warnings_of(load):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load()
    return robot, [w for w in caught if issubclass(w.category, kd.PhysicalConsistencyWarning)]


def test_tiago_loads_with_a_warning_naming_the_link_and_eigenvalues():
    path = erd(*TIAGO)
    robot, caught = _warnings_of(lambda: kd.load(path))
    messages = [str(w.message) for w in caught]
    assert robot.n == 48 and len(messages) == 2, messages
    assert messages[0].startswith(
        f"{path}:175: link 'base_antenna_left_link': inertia tensor is not positive semi-definite "
        "(eigenvalues -3.53486e-08, 3.50085e-08, 9.08701e-08)"
    )
    assert "base_antenna_right_link" in messages[1]
    assert set(robot.nonphysical) == {"base_antenna_left_link", "base_antenna_right_link"}
    assert issubclass(kd.PhysicalConsistencyWarning, Warning)


def test_romeo_loads_with_warnings_naming_its_links():
    path = erd(*ROMEO)
    robot, caught = _warnings_of(lambda: kd.Robot.from_urdf(path))
    named = {re.match(rf"{re.escape(path)}:\d+: link '(\w+)': ", str(w.message)).group(1) for w in caught}
    assert {"body", "LHipPitch_link", "RHipPitch_link"} <= named == set(robot.nonphysical)
    assert all(
        "not positive semi-definite (eigenvalues" in str(w.message) or "triangle inequality" in str(w.message)
        for w in caught
    )


@pytest.mark.parametrize("where", [TIAGO, ROMEO])
def test_strict_raises_naming_file_line_and_link(where):
    path = erd(*where)
    with pytest.raises(
        ValueError, match=rf"^{re.escape(path)}:\d+: link '\w+': inertia tensor is not positive semi-definite"
    ):
        kd.Robot.from_urdf(path, inertia="strict")


@pytest.mark.parametrize("where, locked", [(TIAGO, {}), (ROMEO, ROMEO_GRIPPERS)])
def test_repair_reports_the_change_and_passes_the_identities(where, locked):
    from kinedyn.testing import check_identities

    robot, caught = _warnings_of(lambda: kd.load(erd(*where), inertia="repair"))
    assert caught and all("repaired to the nearest physically consistent tensor" in str(w.message) for w in caught)
    assert all(re.search(r"link '\w+': .* change [\d.e+-]+ kg m\^2", str(w.message)) for w in caught)
    assert not robot.nonphysical
    for link in robot.links:
        assert link.inertia.consistency().ok, link.name
    robot = robot.lock_joints(locked) if locked else robot
    residuals = check_identities(robot, states=3)
    assert max(residuals.values()) < 1e-6, residuals


@pytest.mark.parametrize("where", [TIAGO, ROMEO])
def test_warned_robots_agree_with_pinocchio(where):
    """Kept as given, the tensors are those Pinocchio loads: same M and RNEA."""
    pin = pytest.importorskip("pinocchio")
    path = erd(*where)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        robot = kd.load(path)
    model = pin.buildModelFromUrdf(path)
    data = model.createData()
    # Pinocchio orders the joints differently and gives a continuous joint (cos, sin) coordinates
    ids = [model.getJointId(name) for name in robot.joint_names]
    assert model.nv == robot.n and all(j < model.njoints for j in ids)
    v_index = np.array([model.joints[j].idx_v for j in ids])

    def pin_q(q):
        out = pin.neutral(model)
        for j, x in zip(ids, q):
            joint = model.joints[j]
            out[joint.idx_q : joint.idx_q + joint.nq] = [math.cos(x), math.sin(x)] if joint.nq == 2 else [x]
        return out

    def pin_v(v):
        out = np.zeros(model.nv)
        out[v_index] = v
        return out

    rng = np.random.default_rng(4)
    viscous, coulomb = robot.viscous, robot.coulomb
    for _ in range(3):
        q, qd, qdd = robot.random_configuration(rng), rng.normal(size=robot.n), rng.normal(size=robot.n)
        M = pin.crba(model, data, pin_q(q))
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(robot.mass_matrix(q), M[np.ix_(v_index, v_index)], atol=1e-9)
        tau = robot.inverse_dynamics(q, qd, qdd) - viscous * qd - coulomb * np.sign(qd)
        np.testing.assert_allclose(tau, pin.rnea(model, data, pin_q(q), pin_v(qd), pin_v(qdd))[v_index], atol=1e-9)


def test_the_three_routes_share_the_policy(tmp_path):
    """URDF, Python construction and the Robot keyword: same judgement, same messages."""
    bad = Inertia(1.0, (0, 0, 0), np.diag([-0.1, 1.0, 1.0]))
    link = Link("a", None, Joint("j", axis=(1, 0, 0)), inertia=bad)
    with pytest.raises(
        ValueError, match=r"^link 'a': inertia tensor is not positive semi-definite \(eigenvalues -0.1, 1, 1\)"
    ):
        kd.Robot([link], inertia="strict")
    robot, caught = _warnings_of(lambda: kd.Robot([link]))
    assert len(caught) == 1 and str(caught[0].message).startswith(
        "link 'a': inertia tensor is not positive semi-definite"
    )
    repaired, caught = _warnings_of(lambda: kd.Robot([link], inertia="repair"))
    assert len(caught) == 1 and repaired.links[0].inertia.consistency().ok
    assert repaired.replace(name="copy").links[0].inertia == repaired.links[0].inertia  # the policy is kept


def test_forward_dynamics_names_the_nonphysical_link():
    bad = Inertia(1.0, (0, 0, 0), np.diag([-0.1, 1.0, 1.0]))  # D = Ixx < 0 about the x axis
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        robot = kd.Robot([Link("a", None, Joint("j", axis=(1, 0, 0)), inertia=bad)])
    for call in (lambda: robot.forward_dynamics([0.0], [0.0], [1.0]), lambda: robot.mass_matrix_inverse([0.0])):
        with pytest.raises(
            RuntimeError,
            match=r"joint 'j'.*(negative inertia about the axis|negative pivot, so M is indefinite).*link 'a' \(inertia tensor is not positive semi-definite.*inertia='repair'",
        ):
            call()
    # repaired: second moments (1.05, -0.05, -0.05) clipped to (1.05, 0, 0): principal moments (0, 1.05, 1.05)
    with pytest.warns(kd.PhysicalConsistencyWarning, match="repaired"):
        fine = kd.Robot([Link("a", None, Joint("j", axis=(0, 0, 1)), inertia=bad)], inertia="repair")
    np.testing.assert_allclose(fine.forward_dynamics([0.0], [0.0], [1.0]), [1 / 1.05])


def test_each_tensor_is_reported_once_per_process():
    bad = Inertia(1.0, (0, 0, 0), np.diag([-0.1, 1.0, 1.0]))
    robot, caught = _warnings_of(lambda: kd.Robot([Link("a", None, Joint("j"), inertia=bad)]))
    assert len(caught) == 1
    _, again = _warnings_of(lambda: robot.replace(name="copy"))
    assert again == []


# ---- the projection: onto the consistent set, idempotent, the identity on consistent tensors
def _tensor(moments, angles):
    from reference import rpy

    R = rpy(*angles)
    return R @ np.diag(moments) @ R.T


moments = st.lists(st.floats(-2.0, 5.0, allow_nan=False), min_size=3, max_size=3)
angles = st.lists(st.floats(-math.pi, math.pi), min_size=3, max_size=3)


@settings(max_examples=200, deadline=None)
@given(moments, angles, st.floats(0.0, 10.0))
def test_projection_lands_on_a_consistent_tensor_and_is_idempotent(m, a, mass):
    body = Inertia(mass, (0.1, 0.2, 0.3), _tensor(m, a))
    once = body.nearest_consistent()
    assert once.consistency().ok
    assert (once.mass, once.com) == (body.mass, body.com)
    twice = once.nearest_consistent()
    np.testing.assert_allclose(np.array(twice.inertia), np.array(once.inertia), atol=1e-12)
    if body.consistency().ok:
        assert once is body


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(0.0, 5.0), min_size=3, max_size=3), angles)
def test_projection_leaves_consistent_tensors_unchanged(sigma, a):
    """Tensors built from non-negative second moments are exactly the consistent ones."""
    s = np.array(sigma)
    lam = s.sum() - s  # I_i = sigma_j + sigma_k
    body = Inertia(1.0, (0, 0, 0), _tensor(lam, a))
    assert body.consistency().ok
    assert body.nearest_consistent() is body


def test_projection_of_tiago_antenna():
    """eigenvalues (-3.53e-8, 3.50e-8, 9.09e-8): second moments (8.05e-8, 1.05e-8, -4.55e-8) -> the last
    clipped to 0, moments (sigma_2, sigma_1, sigma_1 + sigma_2): a flat body, principal axes kept."""
    lam = np.array([-3.53485625e-08, 3.50084598e-08, 9.08701027e-08])
    body = Inertia(0.1, (0, 0, 0), _tensor(lam, (0.3, -0.2, 1.0)))
    fixed = body.nearest_consistent().consistency()
    sigma = 0.5 * (lam.sum() - 2 * lam)
    expected = np.sort([sigma[1] + 0, sigma[0] + 0, sigma[0] + sigma[1]])
    np.testing.assert_allclose(fixed.moments, expected, rtol=1e-6)
    assert fixed.ok


# ------------------------------------------------ mutated real URDFs: a robot or one clean ValueError
TOKENS = [
    "nan",
    "inf",
    "-inf",
    "1e200",
    "1" * 400,
    "-1",
    "0",
    "x",
    "",
    "1 2",
    "1e-320",
    "&amp;",
    "<",
    '"',
    "revolute",
    "fixed",
    "floating",
    "panda_link0",
    "\u00e9",
    "<link name='z'/>",
    "</robot>",
    "<!DOCTYPE r [<!ENTITY a 'b'>]>",
    "<a>" * 200,
]


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_mutated_panda_loads_or_fails_with_one_clean_value_error(data):
    text = open(erd("panda_description", "urdf", "panda.urdf")).read()
    for _ in range(data.draw(st.integers(1, 4))):
        pos = data.draw(st.integers(0, len(text) - 1))
        op = data.draw(st.sampled_from(["attribute", "insert", "delete", "duplicate"]))
        if op == "attribute":  # replace the next quoted value
            q = text.find('"', pos)
            q2 = text.find('"', q + 1)
            if q >= 0 and q2 >= 0:
                text = text[: q + 1] + data.draw(st.sampled_from(TOKENS)) + text[q2:]
        elif op == "insert":
            text = text[:pos] + data.draw(st.sampled_from(TOKENS)) + text[pos:]
        elif op == "delete":
            text = text[:pos] + text[pos + data.draw(st.integers(1, 200)) :]
        else:
            start = data.draw(st.integers(0, len(text) - 1))
            text = text[:pos] + text[start : start + data.draw(st.integers(1, 300))] + text[pos:]
    began = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
            robot = robot_from_urdf(text)
    except ValueError as e:
        assert type(e) is ValueError
        assert str(e).count("<URDF string>") == 1, str(e)
    else:  # what loads gives finite numbers
        q = robot.random_configuration(0)
        assert np.all(np.isfinite(robot.mass_matrix(q))) and np.all(np.isfinite(robot.pose(q)))
    assert time.perf_counter() - began < 5.0


@pytest.mark.parametrize("method", ["rk4", "implicit"])
def test_a_simulation_stopped_by_a_nonphysical_body_names_it(method):
    bad = Inertia(1.0, (0, 0, 0), np.diag([-0.1, 1.0, 1.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kd.PhysicalConsistencyWarning)
        robot = kd.Robot([Link("a", None, Joint("j", axis=(1, 0, 0)), inertia=bad)])
    from kinedyn.simulate.core import SimulationError

    with pytest.raises(
        SimulationError,
        match=r"stopped at t = 0 s.*link 'a' \(inertia tensor is not positive semi-definite.*inertia='repair'",
    ):
        kd.simulate(robot, 0.1, np.zeros(2), method=method)
