"""kinedyn.symbolic.pose / jacobian / jacobian_inverse / tool_velocity / joint_torques (issue 12 §1).

Checked two independent ways: against the numeric core (robot.pose, robot.jacobian: Rust, a
different code path) at random states for every built-in and the example robot files, and against
derivations written here by hand from the geometry (planar 2R, elbow arm)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from trig_zero import all_zero

import kinedyn as kd
from kinedyn import symbolic as ks

ROOT = Path(__file__).resolve().parents[1]
q1, q2, q3 = sp.symbols("q1 q2 q3", real=True)
c1, s1, c2, s2 = sp.cos(q1), sp.sin(q1), sp.cos(q2), sp.sin(q2)
c12, s12 = sp.cos(q1 + q2), sp.sin(q1 + q2)


def _zero(M) -> bool:
    return all_zero(M)


def _compare_numeric(
    robot,
    trials=3,
    seed=1,
    refs=(("world", None), ("world", (0.1, -0.2, 0.3)), ("local", (0.1, -0.2, 0.3)), ("spatial", None)),
):
    q = ks.joint_symbols(robot)
    rng = np.random.default_rng(seed)
    states = [robot.random_configuration(rng) for _ in range(trials)]
    fT = sp.lambdify(q, ks.pose(robot), "numpy")
    for x in states:
        assert np.allclose(np.array(fT(*x), dtype=float), robot.pose(x), rtol=0, atol=1e-10)
    for ref, point in refs:
        fJ = sp.lambdify(q, ks.jacobian(robot, reference=ref, point=point), "numpy")
        for x in states:
            assert np.allclose(
                np.array(fJ(*x), dtype=float), robot.jacobian(x, reference=ref, point=point), rtol=0, atol=1e-10
            ), (robot.name, ref, point)


@pytest.mark.parametrize("name", kd.robots.names())
def test_every_builtin_matches_the_numeric_core(name):
    _compare_numeric(getattr(kd.robots, name)())


@pytest.mark.parametrize("path", ["planar_2r.urdf", "elbow_arm.toml", "tutorial_two_link.yaml"])
def test_robot_files_and_urdf_match_the_numeric_core(path):
    robot = kd.load(ROOT / "examples" / "robots" / path)
    _compare_numeric(robot, refs=(("world", (0.2, 0.1, -0.3)), ("local", None), ("spatial", None)))


def test_other_frames_and_the_spatial_reference_with_a_point():
    robot = kd.robots.puma560()
    q = ks.joint_symbols(robot)
    x = robot.random_configuration(3)
    for frame in ["link2", "link4"]:
        for ref in ["world", "local", "spatial"]:
            J = ks.jacobian(robot, frame=frame, reference=ref, point=(0.05, 0.0, -0.1))
            num = robot.jacobian(x, frame=frame, reference=ref, point=(0.05, 0.0, -0.1))
            assert np.allclose(np.array(sp.lambdify(q, J)(*x), dtype=float), num, atol=1e-10), (frame, ref)
        T = sp.lambdify(q, ks.pose(robot, frame=frame))(*x)
        assert np.allclose(np.array(T, dtype=float), robot.pose(x, frame=frame), atol=1e-10)


def test_symbols_are_those_of_the_equations_of_motion():
    for robot in [kd.robots.planar_2r(symbolic=True), kd.robots.elbow_3r()]:
        eq = robot.equations_of_motion().q
        T = ks.pose(robot)
        # equal as SymPy compares symbols (name and assumptions), so eom.q substitutes into the pose;
        # not `is`: SymPy's symbol cache is an LRU that a long test run can evict
        assert list(ks.joint_symbols(robot)) == list(eq)
        assert {s for s in T.free_symbols if str(s).startswith("q")} <= set(eq)
        found = {s for s in T.free_symbols if str(s) in {str(x) for x in eq}}
        assert found and all(any(s == e for e in eq) for s in found)
        assert T.subs(dict(zip(eq, [0.1] * len(eq)))).free_symbols.isdisjoint(eq)


# ------------------------------------------------------------------ the planar 2R, derived by hand
def _planar_2r_by_hand(l1, l2):
    """Geometry: link 1 of length l1 at angle q1, link 2 of length l2 at angle q1 + q2, both about z."""
    p = sp.Matrix([l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0])
    R = sp.Matrix([[c12, -s12, 0], [s12, c12, 0], [0, 0, 1]])
    T = sp.Matrix(sp.BlockMatrix([[R, p], [sp.zeros(1, 3), sp.ones(1, 1)]]))
    # world: v = dp/dq (the origin's velocity), w = (0, 0, q1d + q2d)
    Jw = sp.Matrix.vstack(p.jacobian([q1, q2]), sp.Matrix([[0, 0], [0, 0], [1, 1]]))
    return T, Jw, R


def test_planar_2r_symbolic_by_hand():
    robot = kd.robots.planar_2r(symbolic=True)
    l1, l2 = sp.symbols("l1 l2", positive=True)
    T, Jworld, R = _planar_2r_by_hand(l1, l2)
    assert _zero(ks.pose(robot) - T)
    J = ks.jacobian(robot)
    assert _zero(J - Jworld)
    # local: both rows rotated into the tool's axes
    Jlocal = sp.Matrix.vstack(R.T * Jworld[:3, :], R.T * Jworld[3:, :])
    assert _zero(ks.jacobian(robot, reference="local") - Jlocal)
    # spatial: v at the base origin = v_o + p x w
    p = T[:3, 3]
    w = Jworld[3:, :]
    Jsp = sp.Matrix.vstack(Jworld[:3, :] + sp.Matrix.hstack(*[p.cross(w[:, j]) for j in range(2)]), w)
    assert _zero(ks.jacobian(robot, reference="spatial") - Jsp)
    # the book's form: sums of parameters times cos/sin of joint sums, nothing else
    assert J[1, 0] == l1 * c1 + l2 * c12
    assert J[1, 1] == l2 * c12


def test_planar_2r_point_is_a_centre_of_mass():
    robot = kd.robots.planar_2r(symbolic=True)
    l1, l2, lc2 = sp.Symbol("l1", positive=True), sp.Symbol("l2", positive=True), sp.Symbol("lc2")
    # the tool frame sits at the end of link 2; its centre of mass is lc2 from the elbow along x
    J = ks.jacobian(robot, point=(lc2 - l2, 0, 0))
    pc = sp.Matrix([l1 * c1 + lc2 * c12, l1 * s1 + lc2 * s12, 0])
    assert _zero(J[:3, :] - pc.jacobian([q1, q2]))


def test_planar_2r_symbolic_parameters_match_numbers():
    robot = kd.robots.planar_2r(symbolic=True)
    l1, l2 = sp.symbols("l1 l2", positive=True)
    f = sp.lambdify([q1, q2, l1, l2], ks.jacobian(robot, reference="local"))
    rng = np.random.default_rng(5)
    for _ in range(4):
        q, L = rng.uniform(-3, 3, 2), rng.uniform(0.5, 3, 2)
        num = kd.robots.planar_2r(l1=L[0], l2=L[1]).jacobian(q, reference="local")
        assert np.allclose(np.array(f(*q, *L), dtype=float), num, atol=1e-10)


# ------------------------------------------------------------------ the elbow arm, derived by hand
def test_elbow_arm_by_hand():
    robot = kd.robots.elbow_3r(symbolic=True)
    L1, L2, L3 = sp.symbols("L1 L2 L3", positive=True)
    c23, s23 = sp.cos(q2 + q3), sp.sin(q2 + q3)
    # joint 1 about the vertical z0, then the shoulder and elbow axes horizontal z1 = z2 = (s1, -c1, 0)
    # (the DH table: alpha1 = 90 deg, d1 = L1, a2 = L2, a3 = L3); the arm's plane is at angle q1
    o1 = sp.Matrix([0, 0, L1])
    o2 = o1 + L2 * sp.Matrix([c1 * c2, s1 * c2, s2])
    o3 = o2 + L3 * sp.Matrix([c1 * c23, s1 * c23, s23])
    z0, z1 = sp.Matrix([0, 0, 1]), sp.Matrix([s1, -c1, 0])
    # R = Rz(q1) Rx(90 deg) Rz(q2 + q3)
    R = sp.Matrix([[c1 * c23, -c1 * s23, s1], [s1 * c23, -s1 * s23, -c1], [s23, c23, 0]])
    T = ks.pose(robot)
    assert _zero(T[:3, 3] - o3)
    assert _zero(T[:3, :3] - R)
    # Spong (4.64): column i = [z_{i-1} x (o_n - o_{i-1}); z_{i-1}] for a revolute joint
    cols = [(z0, sp.zeros(3, 1)), (z1, o1), (z1, o2)]
    Jhand = sp.Matrix.hstack(*[sp.Matrix.vstack(z.cross(o3 - o), z) for z, o in cols])
    J = ks.jacobian(robot)
    assert _zero(J - Jhand)
    # the book's form: products of cos/sin of joint sums
    assert sp.expand(T[0, 3] - c1 * (L2 * c2 + L3 * c23)) == 0 and T[0, 3].is_Mul


# ------------------------------------------------------------------ inverse, J qd, J^T F
def test_inverse_of_the_planar_linear_block():
    robot = kd.robots.planar_2r(symbolic=True)
    l1, l2 = sp.symbols("l1 l2", positive=True)
    block = ks.jacobian(robot)[:2, :]
    inv, det, singular = ks.jacobian_inverse(block)
    # derived: det [[-l1 s1 - l2 s12, -l2 s12], [l1 c1 + l2 c12, l2 c12]]
    #   = -l1 l2 s1 c12 + l1 l2 c1 s12 = l1 l2 sin(q1 + q2 - q1) = l1 l2 s2
    assert sp.simplify(det - l1 * l2 * s2) == 0
    assert singular == [sp.Eq(s2, 0)]
    assert (inv * block).applyfunc(lambda e: sp.simplify(sp.expand_trig(e))) == sp.eye(2)
    adj = ks.jacobian_inverse(block).adjugate
    assert _zero(adj - sp.Matrix([[l2 * c12, l2 * s12], [-l1 * c1 - l2 * c12, -l1 * s1 - l2 * s12]]))
    f = sp.lambdify([q1, q2, l1, l2], inv)
    rng = np.random.default_rng(2)
    for _ in range(4):
        q, L = rng.uniform(-3, 3, 2), rng.uniform(0.5, 3, 2)
        num = kd.robots.planar_2r(l1=L[0], l2=L[1]).jacobian(q)[:2]
        assert np.allclose(np.array(f(*q, *L), dtype=float) @ num, np.eye(2), atol=1e-9)
        assert np.isclose(np.linalg.det(num), L[0] * L[1] * np.sin(q[1]))


def test_pseudo_inverse_of_a_wide_block():
    robot = kd.robots.planar_3r()
    q = ks.joint_symbols(robot)
    block = ks.jacobian(robot)[:2, :]
    pinv, det, _ = ks.jacobian_inverse(block)
    f = sp.lambdify(q, pinv)
    x = robot.random_configuration(4)
    num = robot.jacobian(x)[:2]
    assert np.allclose(np.array(f(*x), dtype=float), np.linalg.pinv(num), atol=1e-9)
    with pytest.raises(ValueError):
        ks.jacobian_inverse(sp.Matrix([[sp.cos(q[0]), 0], [sp.sin(q[0]), 0]]))


def test_tool_velocity_and_joint_torques():
    robot = kd.robots.elbow_3r()
    q = ks.joint_symbols(robot)
    qd = sp.symbols("qd1:4", real=True)
    F = sp.symbols("fx fy fz nx ny nz", real=True)
    J = ks.jacobian(robot)
    v = ks.tool_velocity(J, qd)
    tau = ks.joint_torques(J, F)
    fv, ft = sp.lambdify([*q, *qd], v), sp.lambdify([*q, *F], tau)
    rng = np.random.default_rng(3)
    for _ in range(3):
        x, xd, w = robot.random_configuration(rng), rng.normal(size=3), rng.normal(size=6)
        Jn = robot.jacobian(x)
        assert np.allclose(np.array(fv(*x, *xd), dtype=float).ravel(), robot.frame_velocity(x, xd), atol=1e-10)
        assert np.allclose(np.array(ft(*x, *w), dtype=float).ravel(), Jn.T @ w, atol=1e-10)


def test_abbreviations():
    robot = kd.robots.planar_2r(symbolic=True)
    l1, l2 = sp.symbols("l1 l2", positive=True)
    J = ks.jacobian(robot, abbreviations=True)
    c1s, c12s, s12s = (sp.Symbol(n, real=True) for n in ("c1", "c12", "s12"))
    assert J[1, 0] == l1 * c1s + l2 * c12s
    assert J[0, 1] == -l2 * s12s


def test_bad_arguments():
    robot = kd.robots.planar_2r()
    with pytest.raises(ValueError):
        ks.jacobian(robot, reference="body")
    with pytest.raises(ValueError):
        ks.jacobian(robot, point=(1, 2))
    with pytest.raises(Exception):
        ks.pose(robot, frame="nope")


# ------------------------------------------------------------------ CLI
def _cli(*args):
    # the kinedyn under test (the working tree's or the installed wheel's), not necessarily ROOT/python
    package_parent = str(Path(kd.__file__).resolve().parents[1])
    return subprocess.run(
        [sys.executable, "-m", "kinedyn", *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={"PYTHONPATH": package_parent, "PATH": "/usr/bin:/bin"},
    )


def test_cli_fk_and_jacobian_symbolic():
    out = _cli("fk", "planar_2r", "--symbolic", "--format", "json")
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    names = {"q1": q1, "q2": q2, "l1": sp.Symbol("l1"), "l2": sp.Symbol("l2")}
    T = sp.Matrix(sp.sympify(d["pose"], locals=names))
    # a built-in with symbolic parameters is shown in them (as kinedyn derive --symbolic)
    l1, l2 = names["l1"], names["l2"]
    assert _zero(T[:2, 3] - sp.Matrix([l1 * c1 + l2 * c12, l1 * s1 + l2 * s12]))
    out = _cli("fk", "elbow_3r", "--symbolic", "--set", "L1=3", "--format", "json")
    assert out.returncode == 0, out.stderr
    T = sp.Matrix(sp.sympify(json.loads(out.stdout)["pose"], locals={"q1": q1, "q2": q2, "q3": q3}))
    L2, L3 = sp.symbols("L2 L3")
    assert sp.expand(T[2, 3] - (3 + L2 * s2 + L3 * sp.sin(q2 + q3))) == 0
    out = _cli("jacobian", "examples/robots/two_link_symbolic.yaml", "--symbolic", "--format", "json")
    assert out.returncode == 0, out.stderr
    J = sp.Matrix(sp.sympify(json.loads(out.stdout)["jacobian"], locals=names))
    assert _zero(J[1, :] - sp.Matrix([[l1 * c1 + l2 * c12, l2 * c12]]))
    for fmt, needle in [("latex", r"\cos"), ("markdown", "$$"), ("text", "cos(q1 + q2)")]:
        out = _cli("jacobian", "planar_2r", "--symbolic", "--format", fmt)
        assert out.returncode == 0 and needle in out.stdout, (fmt, out.stdout, out.stderr)
