"""Direction-dependent Coulomb friction (Corke's PUMA 560 model: Tc = [Tc+, Tc-] per joint): the
description (Joint, DHRow, robot files), the native RNEA/ABA, friction_torque, the symbolic
equations of motion and simulation, each checked against the two published levels or by physics
(a joint spinning freely against Coulomb friction alone decelerates at level / inertia, and stops)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.robots import industrial

pytest.importorskip("kinedyn._core", reason="the native module is not built")


def test_joint_levels_symmetric_api_and_errors():
    j = kd.Joint("j", coulomb=(0.4, 0.7))
    assert (j.coulomb, j.coulomb_negative, j.coulomb_levels) == (0.4, 0.7, (0.4, 0.7))
    assert kd.Joint("j", coulomb=0.4, coulomb_negative=0.7) == j
    # the symmetric case is unchanged: one level, no second field
    s = kd.Joint("j", coulomb=0.3)
    assert s.coulomb_negative is None and s.coulomb_levels == (0.3, 0.3) and s.coulomb_is_symmetric
    assert kd.Joint("j", coulomb=(0.3, 0.3)) == s  # two equal levels are the symmetric joint
    assert (j.coulomb_torque(2.0), j.coulomb_torque(-2.0), j.coulomb_torque(0.0)) == (0.4, -0.7, 0.0)
    with pytest.raises(
        ValueError,
        match=r"joint 'j': coulomb_negative must be >= 0, got -0.435 \(a level, not a signed torque: Corke's",
    ):
        kd.Joint("j", coulomb=(0.395, -0.435))
    with pytest.raises(ValueError, match=r"joint 'j': coulomb must be one level or a pair"):
        kd.Joint("j", coulomb=(0.1, 0.2, 0.3))
    with pytest.raises(ValueError, match="give the negative-direction Coulomb level once"):
        kd.Joint("j", coulomb=(0.1, 0.2), coulomb_negative=0.2)
    with pytest.raises(ValueError, match="coulomb_negative"):
        kd.Joint("j", coulomb_negative=float("nan"))
    row = kd.DHRow(a=1.0, coulomb=(0.1, 0.2))
    assert (row.coulomb, row.coulomb_negative) == (0.1, 0.2)


def puma_levels():
    """(|G| Tc+, |G| |Tc-|) per joint from the published motor table (RTB's Link.friction)."""
    return (
        np.array([abs(g) * tc[0] for _, g, _, tc in industrial.PUMA560_MOTORS]),
        np.array([abs(g) * -tc[1] for _, g, _, tc in industrial.PUMA560_MOTORS]),
    )


def test_puma_rnea_gives_each_direction_its_published_level():
    robot = kd.robots.puma560(friction=True)
    positive, negative = puma_levels()
    viscous = np.array([b * g**2 for _, g, b, _ in industrial.PUMA560_MOTORS])
    q = robot.random_configuration(np.random.default_rng(3))
    for i in range(6):
        for v in (0.7, -0.7):
            qd = np.zeros(6)
            qd[i] = v
            friction = robot.inverse_dynamics(q, qd, np.zeros(6)) - robot.bias_torque(q, qd)
            level = positive[i] if v > 0 else -negative[i]
            expected = np.zeros(6)
            expected[i] = viscous[i] * v + level
            np.testing.assert_allclose(friction, expected, atol=1e-9, err_msg=f"joint {i + 1}, qd = {v}")
            np.testing.assert_allclose(robot.friction_torque(qd), expected, atol=1e-12)
    assert not np.allclose(positive, negative)  # the model really is asymmetric
    # RTB's friction(qd) = -|G| (B |G| qd + Tc±) is minus kinedyn's friction_torque
    qd = np.array([0.5, -0.2, 0.1, -1.0, 1.0, -1.0])
    rtb = np.array(
        [
            -abs(g) * (b * abs(g) * w + (tc[0] if w > 0 else tc[1]))
            for (_, g, b, tc), w in zip(industrial.PUMA560_MOTORS, qd)
        ]
    )
    np.testing.assert_allclose(robot.friction_torque(qd), -rtb, rtol=1e-12)


def test_forward_dynamics_inverts_inverse_dynamics_with_asymmetric_friction():
    robot = kd.robots.puma560(friction=True)
    rng = np.random.default_rng(5)
    q = robot.random_configuration(rng, size=5)
    qd = rng.normal(size=(5, 6))
    qdd = rng.normal(size=(5, 6))
    tau = robot.inverse_dynamics(q, qd, qdd)
    np.testing.assert_allclose(robot.forward_dynamics(q, qd, tau), qdd, atol=1e-8)
    np.testing.assert_allclose(
        tau,
        np.einsum("kij,kj->ki", robot.mass_matrix(q), qdd) + robot.bias_torque(q, qd) + robot.friction_torque(qd),
        atol=1e-9,
    )


def test_native_model_rejects_bad_negative_levels():
    from kinedyn import _core

    robot = kd.robots.planar_2r()
    joint = dict(
        name="j",
        kind="revolute",
        placement=np.eye(4),
        axis=np.array([0, 0, 1.0]),
        inertia=np.array([1.0, 0, 0, 0, 0.1, 0, 0.1, 0, 0, 0.1]),
    )
    gravity = np.array([0, 0, -9.81])
    with pytest.raises(ValueError, match="joint 'j' .joint 0.: coulomb_negative is -1"):
        _core.Model([{**joint, "coulomb_negative": -1.0}], gravity)
    with pytest.raises(ValueError, match="joint 'ball' .joint 0.: a spherical joint takes no coulomb_negative"):
        _core.Model([{**joint, "name": "ball", "kind": "spherical", "coulomb_negative": 1.0}], gravity)
    assert robot.n == 2


def one_link(positive, negative, inertia=0.5):
    """A rotor turning about z without gravity: M = inertia, friction levels (positive, negative)."""
    body = kd.Inertia(1.0, (0, 0, 0), np.diag([0.3, 0.3, inertia]))
    return kd.Robot.from_dh([kd.DHRow(inertia=body, coulomb=(positive, negative))], gravity=(0.0, 0.0, 0.0))


@pytest.mark.parametrize("method", ["rk4", "implicit"])
def test_a_spinning_joint_decelerates_at_each_level_and_dissipates_energy(method):
    """qd(t) = qd0 - sign(qd0) level / I t until it stops at t = I |qd0| / level; kinetic energy
    only falls, and the energy balance counts the friction as dissipated (D > 0)."""
    c_pos, c_neg, inertia, v0 = 0.2, 0.5, 0.5, 1.0
    robot = one_link(c_pos, c_neg, inertia)
    for sign, level in ((1.0, c_pos), (-1.0, c_neg)):
        traj = kd.simulate(robot, 3.0, np.array([0.0, sign * v0]), method=method, dt=1e-3)
        t, qd = traj.t, traj.qd[:, 0]
        stop = inertia * v0 / level
        moving = t < stop - 0.01
        np.testing.assert_allclose(qd[moving], sign * (v0 - level / inertia * t[moving]), atol=2e-3)
        # the implicit step sticks (friction stops a joint, it does not reverse it); explicit RK4
        # chatters about rest by at most one step's velocity change, max level / I * dt
        chatter = 0.0 if method == "implicit" else max(c_pos, c_neg) / inertia * 1e-3 * (1 + 1e-9)
        assert np.all(np.abs(qd[t > stop + 0.01]) <= chatter + 1e-12), (
            f"{method}: the joint must stop (qd0 {sign * v0})"
        )
        K = 0.5 * inertia * qd[t < stop] ** 2
        assert np.all(np.diff(K) < 0)
        balance = traj.energy_balance()
        assert balance["dissipated"][-1] == pytest.approx(0.5 * inertia * v0**2, rel=2e-2)
        assert np.all(np.diff(balance["dissipated"][t < stop]) > 0)  # friction only takes energy out while moving


def test_symbolic_equations_carry_both_levels():
    robot = one_link(0.2, 0.5)
    eom = robot.equations_of_motion()
    qd = eom.qd[0]
    f = eom.friction[0]
    assert (
        float(f.subs(qd, 3)) == pytest.approx(0.2)
        and float(f.subs(qd, -3)) == pytest.approx(-0.5)
        and f.subs(qd, 0) == 0
    )
    # tau evaluated at both signs equals the numeric RNEA
    puma = kd.robots.puma560(friction=True)
    e = puma.equations_of_motion(method="newton_euler")
    tau = e.tau
    rng = np.random.default_rng(9)
    q, qd_v, qdd = puma.random_configuration(rng), rng.normal(size=6), rng.normal(size=6)
    qd_v[:3] = [0.4, -0.4, 0.3]
    values = dict(zip(list(e.q) + list(e.qd) + list(e.qdd), list(q) + list(qd_v) + list(qdd)))
    numeric = np.array([float(x.evalf(subs=values)) for x in tau])
    np.testing.assert_allclose(numeric, puma.inverse_dynamics(q, qd_v, qdd), rtol=1e-9, atol=1e-9)
    # generated code (NumPy backend) for a batch of rates of both signs
    compiled = e.compile(("friction",), backend="numpy")
    rates = rng.normal(size=(20, 6))
    np.testing.assert_allclose(compiled.friction(rates), puma.friction_torque(rates), atol=1e-12)


@pytest.mark.parametrize("ext", ["yaml", "toml"])
def test_robot_files_hold_both_levels(ext, tmp_path):
    robot = kd.robots.puma560(friction=True)
    path = tmp_path / f"puma.{ext}"
    robot.save(path)
    again = kd.load(path)
    np.testing.assert_array_equal(again.coulomb, robot.coulomb)
    np.testing.assert_array_equal(again.coulomb_negative, robot.coulomb_negative)
    symmetric = kd.robots.puma560(friction="symmetric")
    symmetric.save(path)
    assert "coulomb: [" not in path.read_text() and "coulomb = [" not in path.read_text()
    assert all(j.coulomb_negative is None for j in kd.load(path).joints)


def test_robot_file_errors_name_the_field(tmp_path):
    text = "name: r\njoints:\n  - {a: 1.0, coulomb: [0.4, -0.3]}\n"
    path = tmp_path / "r.yaml"
    path.write_text(text)
    with pytest.raises(
        ValueError, match=r"r\.yaml.*joints row 1\.coulomb\[1\].*a Coulomb level is a magnitude >= 0, got -0\.3"
    ):
        kd.load(path)
    path.write_text("name: r\njoints:\n  - {a: 1.0, coulomb: [0.4, 0.3, 0.1]}\n")
    with pytest.raises(ValueError, match=r"joints row 1\.coulomb.*two levels, got 3 values"):
        kd.load(path)
    path.write_text("name: r\njoints:\n  - {a: 1.0, coulomb: [0.4, 0.3]}\n")
    assert kd.load(path).joints[0].coulomb_levels == (0.4, 0.3)


def test_removing_friction_takes_both_levels():
    """dataclasses.replace(joint, coulomb=0.0) keeps an explicit negative level (documented):
    clearing both is coulomb=0.0, coulomb_negative=None."""
    j = kd.robots.puma560(friction=True).joints[0]
    assert dataclasses.replace(j, coulomb=0.0).coulomb_levels[1] > 0
    assert dataclasses.replace(j, coulomb=0.0, coulomb_negative=None).coulomb_levels == (0.0, 0.0)


def test_cli_info_shows_both_levels(capsys, tmp_path):
    import json

    from kinedyn.cli import main

    path = tmp_path / "r.yaml"
    path.write_text("name: r\njoints:\n  - {a: 1.0, coulomb: [0.4, 0.3]}\n  - {a: 1.0, coulomb: 0.2}\n")
    assert main(["info", str(path), "--json"]) == 0
    joints = json.loads(capsys.readouterr().out)["joints"]
    assert [(j["coulomb"], j["coulomb_negative"]) for j in joints] == [(0.4, 0.3), (0.2, 0.2)]
