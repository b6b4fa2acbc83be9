"""Configuration spaces (kinedyn.configuration): neutral, integrate, difference, interpolate, random
configurations and the checks of q, on robots with floating, spherical, planar, revolute and prismatic
joints built from Links (the numeric engine refuses multi-DOF joints for now: nothing here uses it).

Oracles: Pinocchio (``pin``, an optional test extra) on the same joints in the same order; a
50-digit mpmath evaluation of SE(2)'s log (Pinocchio's planar ``difference`` loses digits at small
angles: up to 2.5e-9 at θ = 1e-9, measured); the kinematic equations ṗ = R v, q̇uat = ½ quat ⊗ (ω, 0)
by finite differences; Shoemake's distribution checked through the rotation angle's law.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import kinedyn as kd
from kinedyn import Joint, Link
from kinedyn import configuration as cfg

KINDS = [
    ("root", "floating"),
    ("ball", "spherical"),
    ("slide_plane", "planar"),
    ("elbow", "revolute"),
    ("rail", "prismatic"),
]
Q_SLICES = {
    "root": slice(0, 7),
    "ball": slice(7, 11),
    "slide_plane": slice(11, 15),
    "elbow": slice(15, 16),
    "rail": slice(16, 17),
}
V_SLICES = {
    "root": slice(0, 6),
    "ball": slice(6, 9),
    "slide_plane": slice(9, 12),
    "elbow": slice(12, 13),
    "rail": slice(13, 14),
}


def mixed_robot() -> kd.Robot:
    """A chain of every joint kind, with a fixed joint in the middle (merged: no block in q)."""
    links, parent = [], None
    for i, (name, kind) in enumerate(KINDS):
        links.append(
            Link(
                f"l{i}",
                parent,
                Joint(name, kind=kind, axis=(1.0, 0, 0) if kind == "prismatic" else (0, 0, 1.0)),
                placement=np.eye(4),
            )
        )
        parent = f"l{i}"
        if i == 2:
            links.append(Link("bracket", parent, Joint("weld", kind="fixed")))
            parent = "bracket"
    return kd.Robot(links, name="mixed")


ROBOT = mixed_robot()


@pytest.fixture(scope="module")
def pin_model():
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip install pin) is an optional test oracle")
    model, parent = pin.Model(), 0
    joint_models = {
        "floating": pin.JointModelFreeFlyer(),
        "spherical": pin.JointModelSpherical(),
        "planar": pin.JointModelPlanar(),
        "revolute": pin.JointModelRZ(),
        "prismatic": pin.JointModelPX(),
    }
    for name, kind in KINDS:
        parent = model.addJoint(parent, joint_models[kind], pin.SE3.Identity(), name)
    return pin, model


def random_velocity(rng, scale):
    return rng.normal(size=ROBOT.nv) * scale


def with_rotation_angles(v, angle):
    """v with the free-flyer's and the spherical joint's rotation vectors scaled to length ``angle``,
    and the planar angle set to ``angle``."""
    v = v.copy()
    for s in (slice(3, 6), V_SLICES["ball"]):
        v[s] *= angle / np.linalg.norm(v[s])
    v[11] = angle
    return v


def same_rotation_up_to_sign(a, b, atol):
    """Quaternion blocks equal up to their sign (q and -q are one rotation), the rest equal."""
    a, b = np.array(a), np.array(b)
    for s in (slice(3, 7), Q_SLICES["ball"]):
        if np.dot(a[s], b[s]) < 0:
            b[s] = -b[s]
    np.testing.assert_allclose(a, b, atol=atol, rtol=0)


# ------------------------------------------------------------------------------- sizes, neutral
def test_sizes_and_neutral(pin_model):
    pin, model = pin_model
    assert (ROBOT.nq, ROBOT.nv) == (model.nq, model.nv) == (17, 14)
    np.testing.assert_array_equal(ROBOT.neutral(), pin.neutral(model))
    # the fixed joint has no block; 1-DOF robots keep the zero configuration
    assert [b.joint.name for b in cfg.space(ROBOT).blocks] == [name for name, _ in KINDS]
    np.testing.assert_array_equal(kd.robots.planar_2r().neutral(), np.zeros(2))


# ------------------------------------------------------------------------- against Pinocchio
@pytest.mark.parametrize("scale", [1e-9, 1e-4, 0.1, 1.0, 3.0])
def test_integrate_matches_pinocchio(pin_model, scale):
    pin, model = pin_model
    rng = np.random.default_rng(int(scale * 1e9) % 2**32)
    for _ in range(100):
        q, v = ROBOT.random_configuration(rng), random_velocity(rng, scale)
        np.testing.assert_allclose(ROBOT.integrate(q, v), pin.integrate(model, q, v), atol=1e-12, rtol=0)
        np.testing.assert_allclose(ROBOT.integrate(q, v, 0.25), pin.integrate(model, q, 0.25 * v), atol=1e-12, rtol=0)


@pytest.mark.parametrize("scale", [1e-9, 1e-4, 0.1, 1.0, 3.0])
def test_difference_matches_pinocchio(pin_model, scale):
    """Free-flyer, spherical and 1-DOF blocks to 1e-12; the planar block to 1e-14 against a 50-digit
    evaluation (and to Pinocchio within the error of Pinocchio's own SE(2) log)."""
    pin, model = pin_model
    rng = np.random.default_rng(7 + int(scale * 1e9) % 2**32)
    planar = V_SLICES["slide_plane"]
    for _ in range(100):
        q0 = ROBOT.random_configuration(rng)
        q1 = ROBOT.integrate(q0, random_velocity(rng, scale)) if scale < 3 else ROBOT.random_configuration(rng)
        mine, theirs = ROBOT.difference(q0, q1), pin.difference(model, q0, q1)
        rest = np.r_[0:9, 12:14]
        np.testing.assert_allclose(mine[rest], theirs[rest], atol=1e-12, rtol=0)
        np.testing.assert_allclose(
            mine[planar],
            se2_log_50_digits(q0[Q_SLICES["slide_plane"]], q1[Q_SLICES["slide_plane"]]),
            atol=1e-14,
            rtol=0,
        )
        np.testing.assert_allclose(mine[planar], theirs[planar], atol=1e-8, rtol=0)


def se2_log_50_digits(q0, q1):
    """Log(M0⁻¹ M1) of SE(2), with 50 digits: θ the relative angle, (vx, vy) = V(θ)⁻¹ R0ᵀ (p1 - p0),
    V(θ) = [[sin θ/θ, -(1 - cos θ)/θ], [(1 - cos θ)/θ, sin θ/θ]] inverted numerically (mpmath)."""
    import mpmath as mp

    with mp.workdps(50):
        x0, y0, c0, s0 = (mp.mpf(float(x)) for x in q0)
        x1, y1, c1, s1 = (mp.mpf(float(x)) for x in q1)
        theta = mp.atan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
        dx, dy = x1 - x0, y1 - y0
        p = mp.matrix([c0 * dx + s0 * dy, -s0 * dx + c0 * dy])
        a = mp.sin(theta) / theta if theta != 0 else mp.mpf(1)
        b = (1 - mp.cos(theta)) / theta if theta != 0 else mp.mpf(0)
        u = mp.lu_solve(mp.matrix([[a, -b], [b, a]]), p)
        return np.array([float(u[0]), float(u[1]), float(theta)])


def test_interpolate_matches_pinocchio(pin_model):
    pin, model = pin_model
    rng = np.random.default_rng(3)
    for _ in range(100):
        q0, q1, t = ROBOT.random_configuration(rng), ROBOT.random_configuration(rng), rng.uniform(-0.5, 1.5)
        mine, theirs = ROBOT.interpolate(q0, q1, t), pin.interpolate(model, q0, q1, t)
        planar = Q_SLICES["slide_plane"]
        # the planar block within the error of Pinocchio's SE(2) log (see test_difference_matches_pinocchio)
        np.testing.assert_allclose(mine[planar], theirs[planar], atol=1e-8, rtol=0)
        mine[planar] = theirs[planar]
        same_rotation_up_to_sign(mine, theirs, atol=1e-12)
    # the ends are the configurations themselves
    np.testing.assert_array_equal(ROBOT.interpolate(q0, q1, 1.0), q1)
    np.testing.assert_allclose(ROBOT.interpolate(q0, q1, 0.0), q0, atol=1e-15)


# --------------------------------------------------------------------- identities of the groups
@pytest.mark.parametrize("scale", [1e-12, 1e-6, 1e-2, 1.0, 3.0])
def test_difference_undoes_integrate(scale):
    rng = np.random.default_rng(11)
    q = ROBOT.random_configuration(rng, size=200)
    v = rng.normal(size=(200, ROBOT.nv)) * scale
    # keep every rotation angle below π: past it the short way round is another velocity
    for s in (slice(3, 6), V_SLICES["ball"]):
        norm = np.linalg.norm(v[:, s], axis=1, keepdims=True)
        v[:, s] *= np.minimum(1.0, 3.0 / np.maximum(norm, 1e-300))
    v[:, 11] = np.clip(v[:, 11], -3.0, 3.0)
    np.testing.assert_allclose(ROBOT.difference(q, ROBOT.integrate(q, v)), v, atol=2e-14 * max(scale, 1), rtol=0)


@pytest.mark.parametrize("gap", [1e-2, 1e-6, 1e-9, 1e-12])
def test_near_pi_rotations_round_trip(gap):
    """Rotation angles π - gap: log3 by atan2 keeps every digit where acos(trace) would lose half."""
    rng = np.random.default_rng(5)
    for _ in range(100):
        q = ROBOT.random_configuration(rng)
        v = with_rotation_angles(random_velocity(rng, 1.0), math.pi - gap)
        np.testing.assert_allclose(ROBOT.difference(q, ROBOT.integrate(q, v)), v, atol=1e-13, rtol=0)


def test_rotation_by_exactly_pi(pin_model):
    """At π the rotation vector's sign is a choice (ω and -ω are the same rotation): difference gives an
    angle of π and a velocity that integrates back to q1."""
    pin, model = pin_model
    rng = np.random.default_rng(6)
    for _ in range(50):
        q0 = ROBOT.random_configuration(rng)
        q1 = ROBOT.integrate(q0, with_rotation_angles(random_velocity(rng, 1.0), math.pi))
        v = ROBOT.difference(q0, q1)
        for s in (slice(3, 6), V_SLICES["ball"]):
            assert abs(np.linalg.norm(v[s]) - math.pi) < 1e-12
        assert abs(abs(v[11]) - math.pi) < 1e-12
        same_rotation_up_to_sign(ROBOT.integrate(q0, v), q1, atol=1e-12)
        same_rotation_up_to_sign(pin.integrate(model, q0, v), q1, atol=1e-12)


def test_antipodal_quaternions_are_the_same_configuration():
    rng = np.random.default_rng(8)
    for _ in range(50):
        q0, q1 = ROBOT.random_configuration(rng), ROBOT.random_configuration(rng)
        flipped = q1.copy()
        flipped[3:7] *= -1
        flipped[Q_SLICES["ball"]] *= -1
        np.testing.assert_allclose(ROBOT.difference(q0, flipped), ROBOT.difference(q0, q1), atol=1e-13, rtol=0)
        np.testing.assert_allclose(ROBOT.difference(q1, flipped), np.zeros(ROBOT.nv), atol=1e-15)
        # the short way: no rotation angle beyond π
        v = ROBOT.difference(q0, flipped)
        assert np.linalg.norm(v[3:6]) <= math.pi + 1e-12 and np.linalg.norm(v[V_SLICES["ball"]]) <= math.pi + 1e-12


def test_velocity_is_in_the_child_frame_by_finite_differences():
    """d/dt integrate(q, v, t) at t = 0 against the kinematic equations written out here:
    free-flyer ṗ = R(quat) v_linear, q̇uat = ½ quat ⊗ (ω, 0) (body-frame ω); planar (ẋ, ẏ) = R(θ)(vx, vy),
    (ċ, ṡ) = ω (-s, c); 1-DOF q̇ = v."""
    rng = np.random.default_rng(9)
    h = 1e-6
    for _ in range(20):
        q, v = ROBOT.random_configuration(rng), random_velocity(rng, 1.0)
        numeric = (ROBOT.integrate(q, v, h) - ROBOT.integrate(q, v, -h)) / (2 * h)
        expected = np.zeros(ROBOT.nq)
        quat = q[3:7]
        expected[0:3] = cfg.quaternion_to_matrix(quat) @ v[0:3]
        expected[3:7] = 0.5 * cfg.quaternion_multiply(quat, np.r_[v[3:6], 0.0])
        expected[7:11] = 0.5 * cfg.quaternion_multiply(q[7:11], np.r_[v[6:9], 0.0])
        c, s = q[13], q[14]
        expected[11:13] = [c * v[9] - s * v[10], s * v[9] + c * v[10]]
        expected[13:15] = v[11] * np.array([-s, c])
        expected[15:17] = v[12:14]
        np.testing.assert_allclose(numeric, expected, atol=1e-8, rtol=0)


def test_exp3_log3_against_rotation_matrices():
    """exp3 is Rodrigues' rotation (Murray, Li & Sastry eq. 2.14) and log3 inverts it."""
    rng = np.random.default_rng(10)
    for omega in rng.normal(size=(50, 3)):
        theta = np.linalg.norm(omega)
        k = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]]) / theta
        rodrigues = np.eye(3) + math.sin(theta) * k + (1 - math.cos(theta)) * k @ k
        np.testing.assert_allclose(cfg.quaternion_to_matrix(cfg.exp3(omega)), rodrigues, atol=1e-14)
        if theta < math.pi:
            np.testing.assert_allclose(cfg.log3(cfg.exp3(omega)), omega, atol=1e-14)
    np.testing.assert_array_equal(cfg.exp3(np.zeros(3)), [0, 0, 0, 1])
    np.testing.assert_array_equal(cfg.log3(np.array([0, 0, 0, -1.0])), np.zeros(3))


# --------------------------------------------------------------------------------------- batches
def test_batches_equal_row_by_row():
    rng = np.random.default_rng(12)
    q0, q1 = ROBOT.random_configuration(rng, size=7), ROBOT.random_configuration(rng, size=7)
    v, t = rng.normal(size=(7, ROBOT.nv)), rng.uniform(size=7)
    assert q0.shape == (7, ROBOT.nq)
    np.testing.assert_array_equal(ROBOT.integrate(q0, v), np.array([ROBOT.integrate(a, b) for a, b in zip(q0, v)]))
    np.testing.assert_array_equal(ROBOT.difference(q0, q1), np.array([ROBOT.difference(a, b) for a, b in zip(q0, q1)]))
    np.testing.assert_array_equal(
        ROBOT.interpolate(q0, q1, t), np.array([ROBOT.interpolate(a, b, s) for a, b, s in zip(q0, q1, t)])
    )
    # one configuration against a batch of velocities, and a batch of time steps
    np.testing.assert_array_equal(ROBOT.integrate(q0[0], v), np.array([ROBOT.integrate(q0[0], b) for b in v]))
    np.testing.assert_array_equal(
        ROBOT.integrate(q0[0], v[0], t), np.array([ROBOT.integrate(q0[0], v[0], s) for s in t])
    )
    # a path: one pair of ends, many t
    assert ROBOT.interpolate(q0[0], q1[0], np.linspace(0, 1, 5)).shape == (5, ROBOT.nq)
    assert ROBOT.random_configuration(0, size=0).shape == (0, ROBOT.nq)


# ------------------------------------------------------------------------ random configurations
def test_random_configurations_are_valid_and_reproducible():
    q = ROBOT.random_configuration(1, size=500)
    np.testing.assert_array_equal(q, ROBOT.random_configuration(1, size=500))
    np.testing.assert_allclose(np.linalg.norm(q[:, 3:7], axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(q[:, Q_SLICES["ball"]], axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(np.hypot(q[:, 13], q[:, 14]), 1.0, atol=1e-15)
    assert np.all(np.abs(q[:, 0:3]) <= 1) and np.all(np.abs(q[:, 11:13]) <= 1)
    assert np.all(np.abs(q[:, 15]) <= math.pi) and np.all(np.abs(q[:, 16]) <= 1)
    cfg.check_configuration(ROBOT, q)  # every row passes the checks


def test_random_rotations_are_uniform():
    """Uniform rotations have angle θ with density (1 - cos θ)/π on [0, π] (Haar measure of SO(3)):
    Kolmogorov-Smirnov against its CDF (θ - sin θ)/π."""
    from scipy import stats

    q = ROBOT.random_configuration(2, size=4000)
    for s in (slice(3, 7), Q_SLICES["ball"]):
        theta = 2 * np.arccos(np.clip(np.abs(q[:, s][:, 3]), 0, 1))
        assert stats.kstest(theta, lambda t: (t - np.sin(t)) / math.pi).pvalue > 1e-3
    # planar angles uniform on the circle
    angle = np.arctan2(q[:, 14], q[:, 13])
    assert stats.kstest(angle, stats.uniform(-math.pi, 2 * math.pi).cdf).pvalue > 1e-3


def test_random_configuration_of_one_dof_robots_is_unchanged():
    """The draws of 1-DOF robots are those of before (one uniform call over the joints' ranges), so
    seeded states elsewhere in the suite stay what they were."""
    robot = kd.Robot(
        [
            Link("a", None, Joint("j1", lower=-0.5, upper=2.0)),
            Link("b", "a", Joint("j2", kind="prismatic", lower=5.0)),
            Link("c", "b", Joint("j3")),
        ]
    )
    lo, hi = np.array([-0.5, 5.0, -math.pi]), np.array([2.0, 7.0, math.pi])
    np.testing.assert_array_equal(
        robot.random_configuration(4, size=6), np.random.default_rng(4).uniform(lo, hi, size=(6, 3))
    )
    np.testing.assert_array_equal(robot.random_configuration(4), np.random.default_rng(4).uniform(lo, hi, size=3))


def test_floating_position_respects_finite_limits():
    robot = kd.Robot([Link("a", None, Joint("root", kind="floating", lower=2.0, upper=3.0))])
    q = robot.random_configuration(0, size=200)
    assert np.all((q[:, :3] >= 2.0) & (q[:, :3] <= 3.0))


# --------------------------------------------------------------------------------- bad input
def test_non_unit_quaternion_is_refused_naming_the_joint():
    q = ROBOT.neutral()
    q[7:11] = [0.1, 0.0, 0.0, 1.0]
    with pytest.raises(
        ValueError,
        match=r"q\[7:11\] of spherical joint 'ball' is the quaternion \(qx, qy, qz, qw\).*"
        r"not 1 to within 1e-06.*robot\.normalize\(q\)",
    ):
        ROBOT.integrate(q, np.zeros(ROBOT.nv))
    fixed = ROBOT.normalize(q)
    np.testing.assert_allclose(fixed[7:11], np.array([0.1, 0, 0, 1]) / math.hypot(0.1, 1), atol=1e-16)
    ROBOT.integrate(fixed, np.zeros(ROBOT.nv))
    # within the tolerance passes; just beyond it does not
    q = ROBOT.neutral()
    q[6] = 1 + 0.9e-6
    cfg.check_configuration(ROBOT, q)
    q[6] = 1 + 1.1e-6
    with pytest.raises(ValueError, match=r"q\[3:7\] of floating joint 'root'"):
        cfg.check_configuration(ROBOT, q)


def test_planar_pair_and_batch_state_are_named():
    q = ROBOT.random_configuration(0, size=4)
    q[2, 13:15] = [1.0, 1.0]
    with pytest.raises(
        ValueError,
        match=r"q1\[13:15\] of planar joint 'slide_plane' is the \(cos theta, sin theta\) pair.* at state 2 of the batch",
    ):
        ROBOT.difference(q[0], q)


def test_length_and_non_finite_numbers_are_refused():
    with pytest.raises(ValueError, match=r"q must have 17 entries \(nq.*got shape \(14,\)"):
        ROBOT.integrate(np.zeros(14), np.zeros(14))
    with pytest.raises(ValueError, match=r"v must have 14 entries"):
        ROBOT.integrate(ROBOT.neutral(), np.zeros(17))
    q = ROBOT.neutral()
    q[16] = np.nan
    with pytest.raises(ValueError, match=r"q1\[16\] \(displacement of prismatic joint 'rail'\) is nan"):
        ROBOT.difference(ROBOT.neutral(), q)
    with pytest.raises(ValueError, match=r"v\[2\] is inf"):
        ROBOT.integrate(ROBOT.neutral(), np.r_[0, 0, np.inf, np.zeros(11)])
    with pytest.raises(ValueError, match=r"dt must be finite"):
        ROBOT.integrate(ROBOT.neutral(), np.zeros(14), np.nan)
    zero = ROBOT.neutral()
    zero[3:7] = 0
    with pytest.raises(ValueError, match=r"joint 'root': a quaternion of norm 0.* cannot be normalised"):
        ROBOT.normalize(zero)
    with pytest.raises(ValueError, match=r"size must be a whole number"):
        ROBOT.random_configuration(0, size=-1)
    with pytest.raises(TypeError, match=r"v must be real numbers, got an array of dtype complex128"):
        ROBOT.integrate(ROBOT.neutral(), np.zeros(14) + 1j)
    with pytest.raises(TypeError, match=r"q0 must be real numbers"):
        ROBOT.difference(["a"] * 17, ROBOT.neutral())


# ---------------------------------------------------------------- the Rust core's shared vectors
def test_python_reproduces_the_vectors_shared_with_the_rust_core():
    """crates/kinedyn-core/src/lie.rs tests its SO(3)/SE(3)/SE(2) functions on vectors written by the
    NumPy module it replaced (tests/lie_oracle.py); the configuration space, now on the core's
    operations, reads them back through the bindings (tests/test_lie_core.py holds the two together)."""
    import re
    from pathlib import Path

    source = (Path(__file__).parents[1] / "crates" / "kinedyn-core" / "src" / "lie.rs").read_text(encoding="utf-8")
    shared = source[source.index("// BEGIN SHARED VECTORS") : source.index("// END SHARED VECTORS")]
    kinds = {"Scalar": "revolute", "Spherical": "spherical", "FreeFlyer": "floating", "Planar": "planar"}

    def numbers(text):
        return np.array([float(x) for x in text.split(",") if x.strip()])

    integrate_part, difference_part = shared.split("const DIFFERENCE_VECTORS")
    rows = re.findall(
        r"\(\s*Block::(\w+),\s*&\[([^\]]*)\],\s*&\[([^\]]*)\],\s*([-+.\deE]+),\s*&\[([^\]]*)\],?\s*\)", integrate_part
    )
    assert len(rows) == 16
    for kind, q, v, dt, expected in rows:
        space = cfg.ConfigurationSpace([Joint("j", kind=kinds[kind])])
        np.testing.assert_allclose(
            space.integrate(numbers(q), numbers(v), float(dt)), numbers(expected), atol=1e-15, rtol=0
        )
    rows = re.findall(r"\(\s*Block::(\w+),\s*&\[([^\]]*)\],\s*&\[([^\]]*)\],\s*&\[([^\]]*)\],?\s*\)", difference_part)
    assert len(rows) == 16
    for kind, q0, q1, expected in rows:
        space = cfg.ConfigurationSpace([Joint("j", kind=kinds[kind])])
        np.testing.assert_allclose(space.difference(numbers(q0), numbers(q1)), numbers(expected), atol=1e-15, rtol=0)


def test_mujoco_conversion_of_docs_conventions():
    """docs/conventions.md: MuJoCo's free joint is (x, y, z, qw, qx, qy, qz) with world-frame linear and
    body-frame angular velocity, its ball joint (qw, qx, qy, qz) with body-frame angular velocity.
    mj_integratePos over a short step and kinedyn's integrate of the converted state must agree to first
    order (taking MuJoCo's linear velocity as body-frame instead would be off by O(1))."""
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo (pip install mujoco) is an optional test oracle")
    model = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body name='b'><freejoint/><geom size='.1' mass='1'/>"
        "<body name='c'><joint type='ball'/><geom size='.1' mass='1' pos='0 0 .3'/></body></body></worldbody></mujoco>"
    )
    robot = kd.Robot([Link("b", None, Joint("free", kind="floating")), Link("c", "b", Joint("ball", kind="spherical"))])
    assert (model.nq, model.nv) == (robot.nq, robot.nv)

    def to_kinedyn(qpos, qvel):
        q = np.r_[qpos[0:3], qpos[4:7], qpos[3], qpos[8:11], qpos[7]]
        rotation = cfg.quaternion_to_matrix(q[3:7])
        return q, np.r_[rotation.T @ qvel[0:3], qvel[3:9]]

    rng = np.random.default_rng(13)
    dt = 1e-7
    for _ in range(20):
        qpos = rng.normal(size=model.nq)
        qpos[3:7] /= np.linalg.norm(qpos[3:7])
        qpos[7:11] /= np.linalg.norm(qpos[7:11])
        qvel = rng.normal(size=model.nv)
        after = qpos.copy()
        mujoco.mj_integratePos(model, after, qvel, dt)
        q, v = to_kinedyn(qpos, qvel)
        q_after, _ = to_kinedyn(after, qvel)
        rate = (robot.integrate(q, v, dt) - q) / dt
        np.testing.assert_allclose(rate, (q_after - q) / dt, atol=1e-5, rtol=0)


# ------------------------------------------------------------------ Jacobians of the operations
def tangent_columns(f, x, perturb, h=1e-6):
    """Central differences of f along each tangent direction of x: (f(x ⊕ h e_i) ⊖ f(x ⊕ -h e_i)) / 2h,
    measured in the tangent space at f(x) (so that the columns are in the same coordinates as v)."""
    here = f(x)
    columns = [
        (ROBOT.difference(here, f(perturb(x, h * e))) - ROBOT.difference(here, f(perturb(x, -h * e)))) / (2 * h)
        for e in np.eye(ROBOT.nv)
    ]
    return np.array(columns).T


@pytest.mark.parametrize("scale", [1e-3, 0.3, 2.0])
def test_integrate_jacobians_by_finite_differences(scale):
    rng = np.random.default_rng(14)
    for _ in range(10):
        q, v = ROBOT.random_configuration(rng), random_velocity(rng, scale)
        d_q, d_v = cfg.integrate_jacobians(ROBOT, q, v, 0.5)
        np.testing.assert_allclose(
            d_q, tangent_columns(lambda x: ROBOT.integrate(x, v, 0.5), q, ROBOT.integrate), atol=1e-8, rtol=0
        )
        np.testing.assert_allclose(
            d_v, tangent_columns(lambda w: ROBOT.integrate(q, w, 0.5), v, lambda w, e: w + e), atol=1e-8, rtol=0
        )


@pytest.mark.parametrize("scale", [1e-3, 0.3, 2.0])
def test_difference_jacobians_by_finite_differences(scale):
    rng = np.random.default_rng(15)
    for _ in range(10):
        q0 = ROBOT.random_configuration(rng)
        q1 = ROBOT.integrate(q0, random_velocity(rng, scale))
        d_q0, d_q1 = cfg.difference_jacobians(ROBOT, q0, q1)
        h = 1e-6
        for jacobian, moved in ((d_q0, 0), (d_q1, 1)):
            columns = []
            for e in np.eye(ROBOT.nv):
                ends = [[q0, q1], [q0, q1]]
                ends[0][moved] = ROBOT.integrate(ends[0][moved], h * e)
                ends[1][moved] = ROBOT.integrate(ends[1][moved], -h * e)
                columns.append((ROBOT.difference(*ends[0]) - ROBOT.difference(*ends[1])) / (2 * h))
            np.testing.assert_allclose(jacobian, np.array(columns).T, atol=1e-8, rtol=0)


@pytest.mark.parametrize("scale", [1e-9, 1e-3, 0.3, 2.0])
def test_jacobians_match_pinocchio(pin_model, scale):
    """dIntegrate and dDifference (ARG0, ARG1). Tolerance 1e-8: Pinocchio's own series switch near a
    rotation angle of 1e-3 is off by up to 1e-9 there (kinedyn's SO(3) block matches a 40-digit
    evaluation to 1e-16: test_so3_difference_jacobian_to_40_digits)."""
    pin, model = pin_model
    rng = np.random.default_rng(16)
    for _ in range(30):
        q0, v = ROBOT.random_configuration(rng), random_velocity(rng, scale)
        q1 = ROBOT.integrate(q0, v)
        d_q, d_v = cfg.integrate_jacobians(ROBOT, q0, v)
        np.testing.assert_allclose(d_q, pin.dIntegrate(model, q0, v, pin.ARG0), atol=1e-8, rtol=0)
        np.testing.assert_allclose(d_v, pin.dIntegrate(model, q0, v, pin.ARG1), atol=1e-8, rtol=0)
        d_q0, d_q1 = cfg.difference_jacobians(ROBOT, q0, q1)
        np.testing.assert_allclose(d_q0, pin.dDifference(model, q0, q1, pin.ARG0), atol=1e-8, rtol=0)
        np.testing.assert_allclose(d_q1, pin.dDifference(model, q0, q1, pin.ARG1), atol=1e-8, rtol=0)
    # batches: one call, the rows' matrices
    qs, vs = ROBOT.random_configuration(rng, size=3), rng.normal(size=(3, ROBOT.nv)) * scale
    d_q, d_v = cfg.integrate_jacobians(ROBOT, qs, vs)
    assert d_q.shape == d_v.shape == (3, ROBOT.nv, ROBOT.nv)
    for k in range(3):
        np.testing.assert_allclose(d_v[k], cfg.integrate_jacobians(ROBOT, qs[k], vs[k])[1], atol=1e-14, rtol=0)


@pytest.mark.parametrize("theta", [1e-6, 1e-3, 3e-2, 1.0, 3.0])
def test_so3_difference_jacobian_to_40_digits(theta):
    """∂ difference/∂q0 of a spherical joint is -Jl⁻¹(d) = -(I - ½[d]× + (1/θ² - (1 + cos θ)/(2θ sin θ)) [d]×²),
    evaluated with 40 digits (mpmath) at the computed d."""
    import mpmath as mp

    space = cfg.ConfigurationSpace([Joint("ball", kind="spherical")])
    rng = np.random.default_rng(17)
    for _ in range(20):
        q0 = space.random(rng)
        w = rng.normal(size=3)
        q1 = space.integrate(q0, w * theta / np.linalg.norm(w))
        d = space.difference(q0, q1)
        with mp.workdps(40):
            x = [mp.mpf(float(c)) for c in d]
            t = mp.sqrt(sum(c * c for c in x))
            skew = mp.matrix([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])
            coefficient = 1 / t**2 - (1 + mp.cos(t)) / (2 * t * mp.sin(t))
            expected = np.array((-(mp.eye(3) - skew / 2 + coefficient * skew * skew)).tolist(), dtype=float)
        np.testing.assert_allclose(space.difference_jacobians(q0, q1)[0], expected, atol=1e-15, rtol=1e-15)


@pytest.mark.parametrize("theta", [1e-6, 1e-3, 0.99e-2, 1.01e-2, 0.49, 0.51, 3.0])
def test_velocity_jacobian_is_the_series_of_the_adjoint(theta):
    """∂(q ⊕ v)/∂v = Jr(v) = Σₖ (-ad_v)ᵏ/(k+1)!, summed with 40 digits from the 6x6 (SE(3)) and 3x3
    (SE(2)) ad matrices written out here: no closed form shared with the code. Angles on both sides of
    the code's switches to Taylor series (1e-2, 0.5) check those branches to 1e-15."""
    import mpmath as mp

    def series(ad):
        with mp.workdps(40):
            ad = mp.matrix(ad) * -1
            total, term = mp.eye(ad.rows), mp.eye(ad.rows)
            for k in range(1, 80):
                term = term * ad / (k + 1)
                total += term
            return np.array(total.tolist(), dtype=float)

    def skew(w):
        return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])

    rng = np.random.default_rng(18)
    for _ in range(10):
        q, v = ROBOT.random_configuration(rng), random_velocity(rng, 1.0)
        v = with_rotation_angles(v, theta)
        _, d_v = cfg.integrate_jacobians(ROBOT, q, v)
        rho, omega = v[0:3], v[3:6]
        ad = np.block([[skew(omega), skew(rho)], [np.zeros((3, 3)), skew(omega)]])  # [ρ; ω]: ad = [[ω×, ρ×], [0, ω×]]
        np.testing.assert_allclose(d_v[0:6, 0:6], series(ad), atol=1e-15 * max(1, np.abs(v).max() ** 2), rtol=0)
        ad = skew(v[6:9])  # SO(3): ad = ω×
        np.testing.assert_allclose(d_v[6:9, 6:9], series(ad), atol=1e-15, rtol=0)
        (vx, vy, w) = v[9:12]
        ad = np.array([[0, -w, vy], [w, 0, -vx], [0, 0, 0]])  # SE(2): [[ω J, -J ρ], [0, 0]]
        np.testing.assert_allclose(d_v[9:12, 9:12], series(ad), atol=1e-15 * max(1, np.abs(v).max() ** 2), rtol=0)


# ------------------------------------------------------------------------ with the numeric core
def test_integrate_moves_every_body_with_the_cores_velocity():
    """The numeric core's body velocities (frame_velocity, reference="local") are the rates of change
    of the bodies' poses along integrate(q, v t): q ⊕ v and the core's Jacobians read v in the same
    frames, for every joint kind, on a chain with offsets between the joints."""
    rng = np.random.default_rng(19)
    links, parent = [], None
    for i, (name, kind) in enumerate(KINDS):
        placement = np.eye(4)
        placement[:3, 3] = rng.normal(size=3) * 0.3
        axis = (1.0, 0, 0) if kind == "prismatic" else (0, 0, 1.0)
        links.append(
            Link(
                f"l{i}",
                parent,
                Joint(name, kind=kind, axis=axis),
                placement=placement,
                inertia=kd.Inertia.box(1.0, (0.1, 0.2, 0.3)),
            )
        )
        parent = f"l{i}"
    robot = kd.Robot(links, name="mixed")
    h = 1e-6
    for _ in range(5):
        q, v = robot.random_configuration(rng), rng.normal(size=robot.nv)
        ahead, behind = robot.integrate(q, v, h), robot.integrate(q, v, -h)
        for body in robot.body_names:
            T, T_ahead, T_behind = robot.pose(q, body), robot.pose(ahead, body), robot.pose(behind, body)
            R = T[:3, :3]
            linear = R.T @ (T_ahead[:3, 3] - T_behind[:3, 3]) / (2 * h)
            spin = R.T @ (T_ahead[:3, :3] - T_behind[:3, :3]) / (2 * h)  # [ω]× in the body's axes
            angular = np.array([spin[2, 1], spin[0, 2], spin[1, 0]])
            np.testing.assert_allclose(
                np.r_[linear, angular], robot.frame_velocity(q, v, body, reference="local"), atol=1e-7
            )
