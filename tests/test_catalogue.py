"""The built-in catalogue: every robot builds, its DH tree matches a hand-written DH product,
standard == modified DH of the same arm, the UR5 DH model equals example-robot-data's URDF after
the documented base/tool offsets, overrides work."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from reference import UR5, all_frame_poses, erd, frame_pose, pose, random_q, rotation

import kinedyn as kd
from kinedyn.robots import industrial

X, Y, Z = np.eye(3)


def rot(axis, angle) -> np.ndarray:
    return pose(rotation(axis, angle))


def trans(x, y, z) -> np.ndarray:
    return pose(None, [x, y, z])


def standard_dh_tool(rows, q, kinds) -> np.ndarray:
    """Product of Rz(theta) Tz(d) Tx(a) Rx(alpha), written out here (Spong eq. 3.10)."""
    T = np.eye(4)
    for (theta, d, a, alpha), qi, kind in zip(rows, q, kinds):
        theta, d = (theta + qi, d) if kind == "revolute" else (theta, d + qi)
        T = T @ rot(Z, theta) @ trans(0, 0, d) @ trans(a, 0, 0) @ rot(X, alpha)
    return T


def modified_dh_tool(rows, q, kinds) -> np.ndarray:
    """Product of Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i) (Craig eq. 3.6)."""
    T = np.eye(4)
    for (alpha, a, theta, d), qi, kind in zip(rows, q, kinds):
        theta, d = (theta + qi, d) if kind == "revolute" else (theta, d + qi)
        T = T @ rot(X, alpha) @ trans(a, 0, 0) @ rot(Z, theta) @ trans(0, 0, d)
    return T


@pytest.mark.parametrize("name", kd.robots.names())
def test_builtin_builds_with_a_cited_source(name):
    robot = kd.robots.get(name)
    factory = kd.robots.CATALOGUE[name]
    assert robot.n >= 2 and robot.source
    assert factory.__doc__


@pytest.mark.parametrize("name", kd.robots.names())
def test_builtin_tree_matches_its_dh_table(name):
    robot = kd.robots.get(name)
    rows = [(float(r.theta), float(r.d), float(r.a), float(r.alpha)) for r in robot.dh]
    kinds = [r.kind for r in robot.dh]
    # the tool transform, fixed to the last link (the identity, or the Stanford arm's published transl(0, 0, 0.263))
    tool = [np.asarray(f.placement, dtype=float) for f in robot.frames if f.name == robot.tool][0]
    rng = np.random.default_rng(7)
    for _ in range(3):
        q = random_q(robot, rng)
        np.testing.assert_allclose(frame_pose(robot, q), standard_dh_tool(rows, q, kinds) @ tool, atol=1e-12)


def test_unknown_builtin():
    with pytest.raises(ValueError, match="unknown built-in robot 'nope'"):
        kd.robots.get("nope")


# ------------------------------------------------------------------------ standard vs modified
def test_puma_standard_equals_modified_dh():
    """PUMA 560 rewritten by hand in Craig's modified convention (alpha_{i-1}, a_{i-1}, theta_i, d_i)."""
    std = kd.robots.puma560()
    a2, a3, d3, d4 = 0.4318, 0.0203, 0.15005, 0.4318
    h = math.pi / 2
    modified = [(0, 0, 0, 0), (h, 0, 0, 0), (0, a2, 0, d3), (-h, a3, 0, d4), (h, 0, 0, 0), (-h, 0, 0, 0)]
    rows = [dict(alpha=al, a=a, theta=th, d=d) for al, a, th, d in modified]
    mod = kd.Robot.from_dh(rows, convention="modified")  # standard's last Tx(a6) Rx(alpha6) is identity
    rng = np.random.default_rng(11)
    for _ in range(5):
        q = rng.uniform(-math.pi, math.pi, 6)
        np.testing.assert_allclose(frame_pose(mod, q), frame_pose(std, q), atol=1e-12)
        np.testing.assert_allclose(frame_pose(mod, q), modified_dh_tool(modified, q, ["revolute"] * 6), atol=1e-12)


def test_three_link_standard_equals_modified_with_tool():
    """Elbow 3R: the modified table plus a tool Tx(a3) Rx(alpha3) gives the standard tool pose."""
    L1, L2, L3 = 0.7, 0.5, 0.3
    std = kd.Robot.from_dh([(0, L1, 0, math.pi / 2), (0, 0, L2, 0), (0.2, 0, L3, 0.4)])
    mod_rows = [(0, 0, 0, L1), (math.pi / 2, 0, 0, 0), (0, L2, 0.2, 0)]
    mod = kd.Robot.from_dh(
        [dict(alpha=al, a=a, theta=th, d=d) for al, a, th, d in mod_rows],
        convention="modified",
        tool=trans(L3, 0, 0) @ rot(X, 0.4),
    )
    for q in np.random.default_rng(2).uniform(-3, 3, (5, 3)):
        np.testing.assert_allclose(frame_pose(mod, q), frame_pose(std, q), atol=1e-12)


# ------------------------------------------------------------------------ UR5: URDF vs DH
def test_ur5_urdf_and_dh_agree_after_documented_offsets():
    urdf = kd.Robot.from_urdf(erd(*UR5))
    dh = kd.robots.ur5()
    assert urdf.joint_names == dh.joint_names
    A, B = industrial.UR5_URDF_BASE_FROM_DH_BASE, industrial.UR5_DH_TOOL_FROM_URDF_TOOL0
    rng = np.random.default_rng(4)
    for _ in range(10):
        q = random_q(dh, rng)
        np.testing.assert_allclose(frame_pose(urdf, q, "tool0"), A @ frame_pose(dh, q) @ B, atol=1e-9)
    # the URDF's "base" frame (ROS-Industrial's controller base) is the DH base
    np.testing.assert_allclose(all_frame_poses(urdf, np.zeros(6))["base"], A, atol=1e-12)


def test_ur5_inertial_data_matches_urdf_where_they_share_sources():
    """Masses agree with ur_description except the forearm (UR: 2.33 kg, URDF: 2.275 kg); the
    cylinder tensors of links 1-3 agree once both are expressed in world axes."""
    urdf = kd.Robot.from_urdf(erd(*UR5))
    dh = kd.robots.ur5()
    A = industrial.UR5_URDF_BASE_FROM_DH_BASE
    q = random_q(dh, np.random.default_rng(8))
    fu, fd = all_frame_poses(urdf, q), all_frame_poses(dh, q)
    for i, (lu, ld) in enumerate(zip(urdf.body_names, dh.body_names)):
        iu = next(l for l in urdf.links if l.name == lu).inertia
        idh = next(l for l in dh.links if l.name == ld).inertia
        if i != 2:
            assert idh.mass == pytest.approx(iu.mass)
        if i < 3:
            Ru, Rd = fu[lu][:3, :3], (A @ fd[ld])[:3, :3]
            world_u = Ru @ np.array(iu.inertia) @ Ru.T * (idh.mass / iu.mass)
            world_d = Rd @ np.array(idh.inertia) @ Rd.T
            np.testing.assert_allclose(world_d, world_u, rtol=1e-6, atol=1e-12)  # URDF rounds to ~10 digits


def test_ur5_published_values():
    dh = kd.robots.ur5()
    assert [float(r.d) for r in dh.dh] == [0.089159, 0, 0, 0.10915, 0.09465, 0.0823]
    assert [float(r.a) for r in dh.dh] == [0, -0.425, -0.39225, 0, 0, 0]
    assert [l.inertia.mass for l in dh.links] == [3.7, 8.393, 2.33, 1.219, 1.219, 0.1879]
    np.testing.assert_allclose(dh.upper_limits, 2 * math.pi)


# ------------------------------------------------------------------------ PUMA, Stanford
def test_puma_published_inertias_are_kept_with_a_warning():
    """The tabulated link-3 tensor fails the triangle inequality: kept as published, with a warning."""
    from kinedyn.description import inertia
    from kinedyn.description.inertia import PhysicalConsistencyWarning

    assert industrial.PUMA560_INERTIAS[2] == (0.066, 0.086, 0.0125)
    inertia._WARNED.clear()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kd.robots.puma560()  # documented in its docstring: no warning for the catalogue robot
    inertia._WARNED.clear()
    with pytest.warns(PhysicalConsistencyWarning, match="link 'l3': inertia tensor violates the triangle inequality"):
        body = kd.Inertia(4.8, (0, 0, 0), np.diag(industrial.PUMA560_INERTIAS[2]))
        kd.Robot([kd.Link("l3", None, kd.Joint("j3"), inertia=body)])  # a user's robot with a copy warns


def test_puma_motor_and_friction_options():
    plain = kd.robots.puma560(motors=False)
    assert all(j.armature == 0 for j in plain.joints)
    robot = kd.robots.puma560(friction=True)
    jm, gear, b, (tp, tn) = industrial.PUMA560_MOTORS[0]
    j1 = robot.joints[0]
    assert j1.armature == pytest.approx(gear**2 * jm)
    assert j1.viscous == pytest.approx(b * gear**2)
    # Corke's model (RTB Link.friction): |G| Tc+ against qd > 0, |G| |Tc-| against qd < 0 (tn < 0)
    assert j1.coulomb == pytest.approx(abs(gear) * tp)
    assert j1.coulomb_negative == pytest.approx(abs(gear) * -tn)
    assert j1.coulomb_levels == (j1.coulomb, j1.coulomb_negative)
    mean = kd.robots.puma560(friction="symmetric").joints[0]
    assert mean.coulomb == pytest.approx(abs(gear) * (tp - tn) / 2) and mean.coulomb_negative is None
    assert kd.robots.puma560().joints[0].viscous == 0.0
    with pytest.raises(ValueError, match="friction must be True"):
        kd.robots.puma560(friction="yes")


def test_puma_limits_in_degrees():
    robot = kd.robots.puma560()
    np.testing.assert_allclose(np.degrees(robot.lower_limits), [-160, -45, -225, -110, -100, -266])
    np.testing.assert_allclose(np.degrees(robot.upper_limits), [160, 225, 45, 170, 100, 266])


def test_stanford_prismatic_boom():
    robot = kd.robots.stanford()
    assert [j.kind for j in robot.joints][2] == "prismatic"
    assert robot.lower_limits[2] == pytest.approx(12 * 0.0254)
    q = np.zeros(6)
    q[2] = 0.5
    lower = frame_pose(robot, q)
    q[2] = 0.7
    # sliding the boom 0.2 m moves the tool 0.2 m along z2
    assert np.linalg.norm(frame_pose(robot, q)[:3, 3] - lower[:3, 3]) == pytest.approx(0.2)


@pytest.mark.parametrize("factory", [kd.robots.puma560, kd.robots.stanford, kd.robots.ur5])
def test_overrides(factory):
    masses = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    robot = factory(masses=masses, gravity=(0, 0, -1.62))
    assert [l.inertia.mass for l in robot.links] == masses
    assert robot.gravity == (0.0, 0.0, -1.62)
    with pytest.raises(ValueError, match="masses needs 6 entries"):
        factory(masses=[1.0])


def test_length_overrides_change_kinematics():
    base = frame_pose(kd.robots.puma560(), np.zeros(6))
    longer = frame_pose(kd.robots.puma560(a2=0.5), np.zeros(6))
    assert longer[0, 3] - base[0, 3] == pytest.approx(0.5 - 0.4318)
    ur = frame_pose(kd.robots.ur5(d1=0.2), np.zeros(6))
    assert ur[2, 3] - frame_pose(kd.robots.ur5(), np.zeros(6))[2, 3] == pytest.approx(0.2 - 0.089159)


@pytest.mark.parametrize("name", ["planar_2r", "planar_3r", "elbow_3r", "cartesian_2p"])
def test_symbolic_builtins_carry_symbols_and_agree_with_numbers(name):
    """symbolic=True keeps exact angles (sympy.pi / 2) and substitutes back to the numeric robot."""
    import inspect

    factory = kd.robots.CATALOGUE[name]
    symbolic = factory(symbolic=True)
    assert symbolic.is_symbolic
    numeric = factory()
    values = {p.name: p.default for p in inspect.signature(factory).parameters.values() if isinstance(p.default, float)}
    if name == "planar_2r":  # derived defaults: centre of mass at mid-length, I = m l^2 / 12
        values.update(lc1=1.0, lc2=1.5, I1=4 / 12, I2=9 / 12)
    substituted = symbolic.subs({s: values[s.name] for s in symbolic.symbols})
    assert not substituted.is_symbolic
    q = numeric.random_configuration(np.random.default_rng(1))
    np.testing.assert_allclose(substituted.pose(q), numeric.pose(q), atol=1e-12)
    np.testing.assert_allclose(substituted.inertial_parameters(), numeric.inertial_parameters(), atol=1e-12)


def test_stanford_follows_the_published_model():
    """Corke's mdl_stanford.m (the table the docstring cites) has d6 = 0 and the 0.263 m wrist-to-tool
    distance in tool = transl(0, 0, 0.263); link 6's centre of mass (0, 0, 1.554) is measured from the
    wrist centre. The built-in once moved 0.263 into d6 and kept the centre of mass relative to the moved
    frame (M, g, C off by up to 0.65, 1.25, 0.50). Here the published model is built from the table's own
    numbers (transcribed below) and compared: tool pose, M, g, C at random states."""
    from kinedyn.description.dh import DHRow
    from kinedyn.description.inertia import Inertia

    table = [  # theta, d, a, alpha, kind ; m ; r ; I diag ; Jm
        (0.0, 0.412, 0.0, -math.pi / 2, "revolute", 9.29, (0, 0.0175, -0.1105), (0.276, 0.255, 0.071), 0.953),
        (0.0, 0.154, 0.0, math.pi / 2, "revolute", 5.01, (0, -1.054, 0), (0.108, 0.018, 0.100), 2.193),
        (-math.pi / 2, 0.0, 0.0, 0.0, "prismatic", 4.25, (0, 0, -6.447), (2.51, 2.51, 0.006), 0.782),
        (0.0, 0.0, 0.0, -math.pi / 2, "revolute", 1.08, (0, 0.092, -0.054), (0.002, 0.001, 0.001), 0.106),
        (0.0, 0.0, 0.0, math.pi / 2, "revolute", 0.630, (0, 0.566, 0.003), (0.003, 0.0004, 0.0), 0.097),
        (0.0, 0.0, 0.0, 0.0, "revolute", 0.51, (0, 0, 1.554), (0.013, 0.013, 0.0003), 0.020),
    ]
    rows = [
        DHRow(theta=th, d=d, a=a, alpha=al, kind=kind, inertia=Inertia(m, r, np.diag(I)), rotor_inertia=jm)
        for th, d, a, al, kind, m, r, I, jm in table
    ]
    tool = np.eye(4)
    tool[2, 3] = 0.263
    published = kd.Robot.from_dh(rows, gravity=(0, 0, -9.81), tool=tool)
    robot = kd.robots.stanford()
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = rng.uniform(-1.5, 1.5, 6)
        q[2] = rng.uniform(0.4, 1.2)
        qd = rng.uniform(-1, 1, 6)
        np.testing.assert_allclose(robot.pose(q), published.pose(q), atol=1e-12)
        np.testing.assert_allclose(robot.mass_matrix(q), published.mass_matrix(q), atol=1e-10)
        np.testing.assert_allclose(robot.gravity_torque(q), published.gravity_torque(q), atol=1e-10)
        np.testing.assert_allclose(robot.coriolis_matrix(q, qd), published.coriolis_matrix(q, qd), atol=1e-10)
