"""Description objects: Inertia (validation, transforms, merging checked against point clouds),
Joint validation, Link poses, tree building (fixed-joint merging, errors), lock_joints."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp
from reference import all_frame_poses, pose, rotation, rpy

import kinedyn as kd
from kinedyn import Frame, Inertia, Joint, Link


# ---------------------------------------------------------------- point clouds as an oracle
def cloud_inertia(masses, points):
    """Mass, centre of mass and inertia about it, summed point by point: I = sum m (|r|^2 E - r r^T)."""
    m = masses.sum()
    c = (masses[:, None] * points).sum(0) / m
    r = points - c
    I = sum(mi * (ri @ ri * np.eye(3) - np.outer(ri, ri)) for mi, ri in zip(masses, r))
    return m, c, I


def random_cloud(rng, n=7):
    return rng.uniform(0.1, 2.0, n), rng.normal(size=(n, 3))


def test_inertia_merge_matches_union_of_point_clouds():
    rng = np.random.default_rng(0)
    (ma, pa), (mb, pb) = random_cloud(rng), random_cloud(rng)
    A, B = (Inertia(*cloud_inertia(m, p)) for m, p in ((ma, pa), (mb, pb)))
    m, c, I = cloud_inertia(np.concatenate([ma, mb]), np.vstack([pa, pb]))
    merged = A + B
    assert merged.mass == pytest.approx(m)
    np.testing.assert_allclose(merged.com, c, atol=1e-12)
    np.testing.assert_allclose(np.array(merged.inertia), I, atol=1e-12)


def test_inertia_transformed_matches_moved_point_cloud():
    rng = np.random.default_rng(1)
    masses, points = random_cloud(rng)
    T = pose(rpy(0.3, -1.1, 2.0), [0.5, -0.2, 0.8])
    moved = (T[:3, :3] @ points.T).T + T[:3, 3]
    m, c, I = cloud_inertia(masses, moved)
    got = Inertia(*cloud_inertia(masses, points)).transformed(T)
    np.testing.assert_allclose(got.com, c, atol=1e-12)
    np.testing.assert_allclose(np.array(got.inertia), I, atol=1e-12)


def test_parameters_about_origin_match_point_cloud():
    rng = np.random.default_rng(2)
    masses, points = random_cloud(rng)
    inertia = Inertia(*cloud_inertia(masses, points))
    Io = sum(mi * (p @ p * np.eye(3) - np.outer(p, p)) for mi, p in zip(masses, points))
    h = (masses[:, None] * points).sum(0)
    expected = [masses.sum(), *h, Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]]
    np.testing.assert_allclose(inertia.parameters(), expected, atol=1e-12)
    back = Inertia.from_parameters(inertia.parameters())
    np.testing.assert_allclose(np.array(back.inertia), np.array(inertia.inertia), atol=1e-12)


def test_named_constructors():
    rod = Inertia.rod(3.0, 2.0)
    assert rod.com == (1.0, 0.0, 0.0) and rod.inertia[1][1] == pytest.approx(1.0)
    box = Inertia.box(12.0, (1.0, 2.0, 3.0))
    assert np.diag(np.array(box.inertia)).tolist() == pytest.approx([13.0, 10.0, 5.0])
    assert Inertia.from_urdf(1, 1, 0.1, 0.2, 2, 0.3, 2.5).inertia[2][1] == 0.3


# ---------------------------------------------------------------- Inertia validation
def test_negative_mass():
    with pytest.raises(ValueError, match="mass.*negative"):
        Inertia(-1.0)


def _one_link_robot(body, **kwargs):
    return kd.Robot([Link("a", None, Joint("j"), inertia=body)], **kwargs)


def test_non_psd_inertia():
    """An inertia is a value; whether a rigid body can have it is judged where a robot is assembled,
    by the inertia policy: strict raises, warn (the default) warns (docs/model-files.md)."""
    from kinedyn.description.inertia import _WARNED, PhysicalConsistencyWarning

    for bad in (
        Inertia(1.0, (0, 0, 0), np.diag([1.0, 1.0, -0.1])),
        Inertia.from_urdf(1.0, 1.0, 2.0, 0.0, 1.0, 0.0, 1.0),
    ):
        assert not bad.consistency().positive  # |ixy| > ixx, iyy in the second
        with pytest.raises(ValueError, match="link 'a': inertia tensor is not positive semi-definite"):
            _one_link_robot(bad, inertia="strict")
        _WARNED.clear()
        with pytest.warns(PhysicalConsistencyWarning, match="link 'a': inertia tensor is not positive semi-definite"):
            _one_link_robot(bad)


def test_triangle_inequality():
    from kinedyn.description.inertia import _WARNED, PhysicalConsistencyWarning

    _WARNED.clear()
    with pytest.warns(PhysicalConsistencyWarning, match="triangle inequality"):
        _one_link_robot(Inertia(1.0, (0, 0, 0), np.diag([1.0, 1.0, 3.0])), inertia="strict")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _one_link_robot(Inertia(1.0, (0, 0, 0), np.diag([1.0, 2.0, 3.0])))  # the equality case is a flat plate: allowed


def test_asymmetric_and_nonfinite_inertia():
    with pytest.raises(ValueError, match="not symmetric"):
        Inertia(1.0, (0, 0, 0), [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(ValueError, match="not finite"):
        Inertia(float("nan"))
    with pytest.raises(ValueError, match="3 coordinates"):
        Inertia(1.0, (0, 0))


def test_symbolic_inertia_skips_numeric_checks():
    m, l = sp.symbols("m l", positive=True)
    inertia = Inertia(m, (l / 2, 0, 0), np.diag([0, m * l**2 / 12, m * l**2 / 12]).tolist())
    assert inertia.is_symbolic and inertia.mass == m


# ---------------------------------------------------------------- Joint validation
@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(kind="ball"), "unknown kind 'ball'"),
        (dict(axis=(0, 0, 0)), "zero or non-finite length"),
        (dict(axis=(1, 0)), "3 components"),
        (dict(lower=1.0, upper=-1.0), "lower limit 1.0 exceeds upper limit -1.0"),
        (dict(velocity_limit=-1.0), "velocity_limit is negative"),
        (dict(effort_limit=-2.0), "effort_limit is negative"),
        (dict(rotor_inertia=-1e-3), "rotor_inertia must be >= 0"),
        (dict(viscous=-0.1), "viscous must be >= 0"),
        (dict(coulomb=-0.1), "coulomb must be >= 0"),
        (dict(lower=float("nan")), "lower is NaN"),
    ],
)
def test_joint_validation(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Joint("j", **kwargs)


def test_joint_normalises_axis_and_continuous():
    j = Joint("j", "continuous", (0, 3, 4), gear_ratio=10, rotor_inertia=2e-4)
    assert j.kind == "revolute" and j.axis == pytest.approx((0, 0.6, 0.8))
    assert j.armature == pytest.approx(100 * 2e-4)


def test_link_rejects_non_rigid_placement():
    with pytest.raises(ValueError, match="not a rigid transform"):
        Link("a", None, Joint("j"), np.diag([2.0, 1, 1, 1]))
    with pytest.raises(ValueError, match="4x4"):
        Link("a", None, Joint("j"), np.eye(3))


# ---------------------------------------------------------------- tree building
def _chain():
    """base -> l1 (revolute z) -> l2 (fixed, offset) -> l3 (revolute y) and l1 -> tip (fixed)."""
    T12 = pose(rpy(0.2, 0.1, -0.3), [0.4, 0.0, 0.1])
    return [
        Link(
            "l1",
            None,
            Joint("j1"),
            pose(None, [0, 0, 0.3]),
            inertia=Inertia(2.0, (0.1, 0, 0), np.diag([0.1, 0.2, 0.25])),
        ),
        Link("l2", "l1", Joint("f2", "fixed"), T12, inertia=Inertia(1.0, (0, 0.2, 0), np.diag([0.05, 0.05, 0.08]))),
        Link("l3", "l2", Joint("j3", axis=(0, 1, 0)), pose(None, [0.2, 0, 0]), inertia=Inertia(0.5, (0.1, 0, 0))),
        Link("tip", "l1", Joint("f4", "fixed"), pose(rpy(0, 0, 1.0), [0, 0.5, 0]), inertia=Inertia(0.25)),
    ]


def test_fixed_joints_merge_mass_and_com():
    links = _chain()
    robot = kd.Robot(links)
    assert robot.n == 2 and robot.body_names == ["l1", "l3"]
    body = robot.tree.bodies[0].inertia
    assert body.mass == pytest.approx(2.0 + 1.0 + 0.25)
    # centre of mass of l1 + l2 + tip, all in l1's frame
    T12 = np.asarray(links[1].placement)
    T14 = np.asarray(links[3].placement)
    com = (2.0 * np.array([0.1, 0, 0]) + 1.0 * (T12 @ [0, 0.2, 0, 1])[:3] + 0.25 * T14[:3, 3]) / 3.25
    np.testing.assert_allclose(body.com, com, atol=1e-12)


def test_fixed_links_become_frames():
    robot = kd.Robot(_chain())
    q = np.array([0.7, -0.4])
    poses = all_frame_poses(robot, q)
    # independent: world_from_l2 = Tz(0.3) Rz(q1) T12
    l1 = pose(None, [0, 0, 0.3]) @ pose(rotation([0, 0, 1], 0.7))
    np.testing.assert_allclose(poses["l2"], l1 @ np.asarray(_chain()[1].placement), atol=1e-12)
    assert set(robot.frame_names) == {"base", "l1", "l2", "l3", "tip"}


def test_tree_errors():
    j = Joint("j")
    with pytest.raises(ValueError, match="link name 'a' is used twice"):
        kd.Robot([Link("a", None, j), Link("a", None, Joint("k"))])
    with pytest.raises(ValueError, match="parent link 'ghost' does not exist"):
        kd.Robot([Link("a", "ghost", j)])
    with pytest.raises(ValueError, match="not connected to the base"):
        kd.Robot([Link("a", None, j), Link("b", "c", Joint("k")), Link("c", "b", Joint("m"))])
    with pytest.raises(ValueError, match="no moving joint"):
        kd.Robot([Link("a", None, Joint("f", "fixed"))])
    with pytest.raises(ValueError, match="attached to unknown link"):
        kd.Robot([Link("a", None, j)], [Frame("tool", "zzz")])


def test_lock_joints_keeps_pose_and_mass():
    robot = kd.Robot(_chain())
    locked = robot.lock_joints({"j3": 0.6})
    assert locked.n == 1
    q = np.array([0.3])
    np.testing.assert_allclose(all_frame_poses(locked, q)["l3"], all_frame_poses(robot, [0.3, 0.6])["l3"], atol=1e-12)
    assert locked.tree.bodies[0].inertia.mass == pytest.approx(3.75)
    with pytest.raises(ValueError, match="unknown joints"):
        robot.lock_joints({"nope": 0.0})


def test_dh_row_errors():
    with pytest.raises(ValueError, match="convention must be"):
        kd.Robot.from_dh([(0, 0, 1, 0)], convention="craig")
    with pytest.raises(ValueError, match="unknown keys"):
        kd.Robot.from_dh([dict(a=1.0, lenght=2.0)])
    with pytest.raises(ValueError, match="kind must be 'revolute' or 'prismatic'"):
        kd.Robot.from_dh([(0, 0, 1, 0, "fixed")])


def test_symbolic_robot_subs():
    robot = kd.robots.planar_2r(symbolic=True)
    assert {"l1", "l2", "m1"} <= {str(s) for s in robot.symbols}
    numeric = robot.subs({s: 1.0 for s in robot.symbols})
    assert not numeric.is_symbolic
    np.testing.assert_allclose(all_frame_poses(numeric, [0.0, 0.0])["tool"][:3, 3], [2.0, 0, 0], atol=1e-12)
    assert math.isclose(float(numeric.tree.bodies[0].inertia.mass), 1.0)


def test_subs_by_name_finds_symbols_with_assumptions():
    """The built-ins' symbols are positive; a name must still find them (Symbol("m1") alone would not)."""
    robot = kd.robots.planar_2r(symbolic=True)
    assert all(s.is_positive for s in robot.symbols)
    values = {s.name: 1.0 for s in robot.symbols}
    numeric = robot.subs(values)
    assert not numeric.is_symbolic
    assert robot.subs({"m1": 2.0}).symbols == robot.symbols - {s for s in robot.symbols if s.name == "m1"}
    eom = robot.equations_of_motion()
    assert "m1" not in {str(s) for s in eom.subs({"m1": 2.0}).parameters}
    np.testing.assert_allclose(
        np.array(eom.subs(values).M.subs({eom.q[1]: 0.3}), dtype=float), numeric.mass_matrix([0.0, 0.3])
    )


def test_subs_names_the_link_of_a_bad_value():
    robot = kd.robots.planar_2r(symbolic=True)
    values = {s.name: 1.0 for s in robot.symbols}
    with pytest.raises(ValueError, match="link 'link1'.*mass is not finite"):
        robot.subs({**values, "m1": float("nan")})


def test_planar_idealisation_does_not_warn():
    """Only Izz given (the planar textbook arm): one nonzero principal moment is accepted quietly."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Inertia(1.0, (0.5, 0, 0), np.diag([0.0, 0.0, 0.2]))
