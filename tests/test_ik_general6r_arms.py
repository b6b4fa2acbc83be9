"""Every branch of 6R arms whose consecutive axes all meet or are parallel but whose wrist is not
spherical (issue 28): Kinova JACO 2 and Gen3 lite, FANUC CRX-10iA, Yaskawa HC10, Rokae xMate CR7.
No closed form of kinedyn's special structures fits them, and the 12 x 12 matrix polynomial of the
general-6R elimination is singular at every value of its variable; the extended formulation
(crates/kinedyn-core/src/ik/general6r.rs) solves them. The oracle is ssik's generated solver for
each arm (``ssik.prebuilt``): every ssik branch must be among kinedyn's, and every kinedyn branch
must reproduce the target. The geometry is the one ssik bakes from the makers' URDFs (joint origins
in the parent frame, axes, the tool), so that both sides solve the same arm; that they do is
checked, not assumed: each ssik branch must reproduce the target on kinedyn's model."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import kinedyn as kd

pytest.importorskip("kinedyn._core", reason="the native module is not built")

# per joint: origin xyz (m) and rpy (rad) in the parent link's frame, the axis; the last row is
# the tool's origin (ssik 8.2, ssik/prebuilt/<maker>/<arm>_ik.py: the makers' URDFs at q = 0)
ARMS = {
    "jaco2": (
        ((0, 0, 0.15675), (0, -0, 0), (0, 0, -1)),
        (
            (0, 0.0016000000000000001, 0.11874999999999997),
            (0, -0, 0),
            (0, -0.99999999999999978, -2.2204460492503131e-16),
        ),
        (
            (0, -9.1072982488782372e-17, -0.40999999999999986),
            (0, -0, 0),
            (0, 0.99999999999999978, 2.2204460492503131e-16),
        ),
        ((0, -0.011399999999999952, 0.20729999999999996), (0, -0, 0), (0, 0, -0.99999999999999956)),
        ((0, 0.037029999999999987, 0.064139999999999975), (0, -0, 0), (0, -0.86602560567665765, -0.49999965031225513)),
        ((0, 0.037031895297038021, 0.06413890574923467), (0, -0, 0), (0, 5.7948116731649987e-17, -0.99999999999999944)),
        (
            (0, -1.3877787807814457e-17, 0.15999999999999992),
            (3.0913548211494083e-32, -1.3922224420598452e-16, -1.5707963267948963),
            None,
        ),
    ),
    "gen3_lite": (
        ((0, 0, 0.12825), (0, -0, 0), (0, 0, 1)),
        (
            (0, -0.029999999999999999, 0.11500000000000002),
            (0, -0, 0),
            (0, -0.99999999999325373, -3.6732051033465739e-06),
        ),
        (
            (0, -1.0284974289384574e-06, 0.27999999999811104),
            (0, -0, 0),
            (0, 0.99999999999325373, -3.6732051033465735e-06),
        ),
        ((0, 0.020000514248579543, 0.13999992653495341), (0, -0, 0), (0, -3.6174412303802821e-22, 0.99999999999999989)),
        (
            (0.028500000000000001, 0, 0.10499999999999998),
            (0, -0, 0),
            (0.99999999999325373, 1.3287603588489162e-27, -3.6732051033465735e-06),
        ),
        (
            (0.028500385686343579, 0, 0.10499989531294618),
            (0, -0, 0),
            (6.177235058912196e-23, -3.6174412303802816e-22, 0.99999999999999978),
        ),
        ((0, 0, 0), (4.8528882421341511e-22, -6.1772350586264815e-23, 8.3250181953388809e-45), None),
    ),
    "crx10ia": (
        ((0, 0, 0.245), (0, -0, 0), (0, 0, 1)),
        ((0, 0, 0), (0, -0, 0), (0, 1, 0)),
        ((0, 0, 0.54000000000000004), (0, -0, 0), (0, -1, 0)),
        ((0, 0, 0), (0, -0, 0), (-1, 0, 0)),
        ((0.54000000000000004, 0, 0), (0, -0, 0), (0, -1, 0)),
        ((0, -0.14999999999999999, 0), (0, -0, 0), (-1, 0, 0)),
        ((0.16000000000000003, 0, 0), (0, -0, 0), None),
    ),
    "hc10": (
        ((0, 0, 0.27500000000000002), (0, -0, 0), (0, 0, 1)),
        ((0, 0, 0), (0, -0, 0), (0, 1, 0)),
        ((0, 0, 0.69999999999999996), (0, -0, 0), (0, -1, 0)),
        ((0, 0, -0.5), (0, -0, 0), (0, 0, 1)),
        ((0, 0.16200000000000001, 0), (0, -0, 0), (0, -1, 0)),
        ((0, 0, 0), (0, -0, 0), (0, 0, 1)),
        ((0, 0, 0), (0, -0, 0), None),
    ),
    "xmatecr7": (
        ((0, 0, 0), (0, -0, 0), (0, 0, 1)),
        ((0, 0, 0.29599999999999999), (0, -0, 0), (0, 1, 0)),
        ((0, 0, 0.49000000000000005), (0, -0, 0), (0, -1, 0)),
        ((0, 0, 0.35999999999999988), (0, -0, 0), (0, 0, 1)),
        ((0, -0.151, 0), (0, -0, 0), (0, -1, 0)),
        ((0, 0, 0.12650000000000006), (0, -0, 0), (0, 0, 1)),
        ((0, 0, 0), (0, -0, 0), None),
    ),
}
MODULES = {
    "jaco2": "kinova.jaco2_ik",
    "gen3_lite": "kinova.gen3_lite_ik",
    "crx10ia": "fanuc.crx10ia_ik",
    "hc10": "yaskawa.hc10_ik",
    "xmatecr7": "rokae.xmatecr7_ik",
}
INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'


def arm(name: str) -> kd.Robot:
    """The arm as a URDF string: a chain of revolute joints (limits wide open), then the tool."""
    rows = ARMS[name]
    links = "".join(f'<link name="l{i}">{INERTIAL}</link>' for i in range(len(rows) + 1))
    joints = []
    for i, (xyz, rpy, axis) in enumerate(rows):
        origin = f'<origin xyz="{" ".join(map(repr, xyz))}" rpy="{" ".join(map(repr, rpy))}"/>'
        kind = "fixed" if axis is None else "revolute"
        extra = "" if axis is None else f'<axis xyz="{" ".join(map(repr, axis))}"/>'
        extra += "" if axis is None else '<limit lower="-10" upper="10" effort="1" velocity="1"/>'
        joints.append(
            f'<joint name="j{i + 1}" type="{kind}"><parent link="l{i}"/><child link="l{i + 1}"/>{origin}{extra}</joint>'
        )
    xml = f'<robot name="{name}">{links}{"".join(joints)}</robot>'
    return kd.Robot.from_urdf(xml.encode(), tool=f"l{len(rows)}")


def wrapped_equal(a, b, tol=1e-6) -> bool:
    d = np.asarray(a) - np.asarray(b)
    return bool(np.all(np.abs((d + np.pi) % (2 * np.pi) - np.pi) < tol))


def has_ssik() -> bool:
    """ssik (pip install ssik) is an optional oracle: without it only kinedyn's own checks run."""
    try:
        importlib.import_module("ssik.prebuilt")
    except ImportError:
        return False
    return True


@pytest.fixture(params=sorted(ARMS), scope="module")
def robot(request):
    return arm(request.param)


def test_no_special_structure_fits_and_the_general_solver_takes_them(robot):
    assert kd.ik.analytic_structure(robot) == "general_6r"


def test_every_ssik_branch_is_found_and_every_branch_reproduces_the_target(robot):
    ssik_arm = importlib.import_module(f"ssik.prebuilt.{MODULES[robot.name]}") if has_ssik() else None
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(4):
        q = rng.uniform(-np.pi, np.pi, 6)
        target = robot.pose(q)
        result = robot.inverse_kinematics(target, respect_limits=False)
        assert result.solver == "analytic:general_6r", result.solver
        assert any(wrapped_equal(s, q) for s in result.solutions), (robot.name, q)
        for s in result.solutions:
            assert np.abs(robot.pose(s) - target).max() < 1e-9
        if ssik_arm is None:
            continue
        theirs = ssik_arm.solve(target, respect_limits=False, enumerate_windings=False)
        for s in theirs:
            s = np.asarray(s.q)
            assert np.abs(robot.pose(s) - target).max() < 1e-8, "ssik and kinedyn build different arms"
            assert any(wrapped_equal(s, ours) for ours in result.solutions), (robot.name, s, result.solutions)
            checked += 1
    if ssik_arm is not None:
        assert checked >= 4
