"""``kinedyn check`` (kinedyn.analysis.check_properties) on robots with floating, spherical and planar
joints (issue 14 §1): q has nq entries and qd nv, so dM/dt is taken along q ⊕ t qd (robot.integrate)
and the inertia bounds are searched over the configuration manifold."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import kinedyn as kd
from kinedyn.analysis.bounds import ManifoldChart, robot_inertia_bounds
from kinedyn.analysis.properties import check_properties, mass_matrix_rate
from kinedyn.testing import example_robot_data_dir, random_robot


def _skew_residual(robot, Q, QD, Mdot):
    C = robot.coriolis_matrix(Q, QD)
    N = Mdot - 2 * C
    return float(np.abs(N + np.swapaxes(N, 1, 2)).max() / max(1.0, float(np.abs(Mdot).max())))


def _naive_step(robot, q, v, t):
    """The coordinates moved as if v were their rates, block by block: positions += t v_linear,
    a quaternion's vector part += t omega (then normalised), planar (cos, sin) turned by t omega."""
    q = np.array(q, dtype=float)
    iq = iv = 0
    for j in robot.joints:
        if j.kind == "floating":
            q[..., iq : iq + 3] += t * v[..., iv : iv + 3]
            quat = q[..., iq + 3 : iq + 7]
            quat[..., :3] += t * v[..., iv + 3 : iv + 6]
            quat /= np.linalg.norm(quat, axis=-1, keepdims=True)
        elif j.kind == "spherical":
            quat = q[..., iq : iq + 4]
            quat[..., :3] += t * v[..., iv : iv + 3]
            quat /= np.linalg.norm(quat, axis=-1, keepdims=True)
        elif j.kind == "planar":
            q[..., iq : iq + 2] += t * v[..., iv : iv + 2]
            angle = np.arctan2(q[..., iq + 3], q[..., iq + 2]) + t * v[..., iv + 2]
            q[..., iq + 2], q[..., iq + 3] = np.cos(angle), np.sin(angle)
        else:
            q[..., iq] += t * v[..., iv]
        iq, iv = iq + j.nq, iv + j.nv
    return q


def test_dM_dt_needs_the_manifold_derivative_on_a_floating_robot():
    """On a free-flyer carrying a spherical joint, dM/dt - 2C is skew with dM/dt along q ⊕ t qd
    (mass_matrix_rate), and NOT with the coordinates moved as if qd were their rates (the old
    M(q + t qd), made to fit nq != nv block by block): that derivative is wrong by O(1)."""
    robot = random_robot(2, n=4, floating=True, spherical=0.4, friction=False)
    assert [j.kind for j in robot.joints][:3] == ["floating", "revolute", "spherical"]
    rng = np.random.default_rng(0)
    Q = robot.random_configuration(rng, size=20)
    QD = rng.uniform(-2.0, 2.0, size=(20, robot.nv))
    h = 1e-6
    manifold = _skew_residual(robot, Q, QD, mass_matrix_rate(robot, Q, QD, h))
    naive_Mdot = (
        robot.mass_matrix(_naive_step(robot, Q, QD, h)) - robot.mass_matrix(_naive_step(robot, Q, QD, -h))
    ) / (2 * h)
    naive = _skew_residual(robot, Q, QD, naive_Mdot)
    assert manifold < 1e-8, manifold
    assert naive > 1e-2, naive
    # on 1-DOF joints the manifold step is the old q + t qd, digit for digit
    arm = random_robot(5, n=4, friction=False)
    q, qd = arm.random_configuration(rng, size=3), rng.normal(size=(3, arm.nv))
    np.testing.assert_array_equal(
        mass_matrix_rate(arm, q, qd, h), (arm.mass_matrix(q + h * qd) - arm.mass_matrix(q - h * qd)) / (2 * h)
    )


def test_the_search_chart_moves_on_the_manifold():
    """ManifoldChart's tangent map T is the derivative of its configurations (by robot.difference
    of central differences), its wrap keeps the configuration, and M does not depend on the
    floating base's configuration, which the chart holds at the identity."""
    robot = random_robot(5, n=4, floating=True, spherical=0.4, planar=0.3, friction=False)
    assert {j.kind for j in robot.joints} >= {"floating", "spherical", "planar", "prismatic"}
    chart = ManifoldChart(robot)
    assert chart.nx == robot.nv - 6
    rng = np.random.default_rng(1)
    for _ in range(3):
        x = rng.uniform(chart.lower, chart.upper)
        x[chart.periodic] = rng.uniform(-3.0, 3.0, int(chart.periodic.sum()))  # rotation vectors past pi too
        h = 1e-6
        numeric = np.array(
            [
                robot.difference(chart.configuration(x - h * e), chart.configuration(x + h * e)) / (2 * h)
                for e in np.eye(chart.nx)
            ]
        ).T
        np.testing.assert_allclose(chart.tangent(x), numeric, atol=1e-8)
        np.testing.assert_allclose(
            robot.difference(chart.configuration(x), chart.configuration(chart.wrap(x))), 0.0, atol=1e-12
        )
    Q = robot.random_configuration(rng, size=5)
    moved = Q.copy()
    moved[:, :7] = robot.random_configuration(rng, size=5)[:, :7]
    np.testing.assert_allclose(robot.mass_matrix(moved), robot.mass_matrix(Q), atol=1e-12)


def test_inertia_bounds_over_the_manifold_are_attained_and_no_worse_than_uniform_samples():
    robot = random_robot(2, n=4, floating=True, spherical=0.4, friction=False)
    b = robot_inertia_bounds(robot, samples=48, starts=4, seed=0)
    for q, value, end in ((b.q_lambda_min, b.lambda_min, 0), (b.q_lambda_max, b.lambda_max, -1)):
        assert q.shape == (robot.nq,)
        robot.integrate(q, np.zeros(robot.nv))  # its quaternions are unit (integrate checks them)
        assert np.isclose(np.linalg.eigvalsh(robot.mass_matrix(q))[end], value, rtol=1e-12)
    # uniformly distributed rotations (not the chart's samples) find nothing beyond the bounds
    eig = np.linalg.eigvalsh(robot.mass_matrix(robot.random_configuration(np.random.default_rng(9), size=400)))
    assert b.lambda_min <= eig[:, 0].min() + 1e-12 and b.lambda_max >= eig[:, -1].max() - 1e-12


def test_check_properties_on_multi_dof_robots_and_a_lone_floating_body():
    robot = random_robot(5, n=4, floating=True, spherical=0.4, planar=0.3, friction=False)
    report = check_properties(robot, samples=20, T=0.5)
    assert report.passed, str(report)
    assert [c.status for c in report.checks] == [
        "sampled",
        "searched",
        "sampled",
        "sampled",
        "sampled",
        "sampled",
        "sampled",  # friction dissipates
        "simulated",
    ]
    assert "along q ⊕ t qd" in report["dM/dt - 2C"].detail
    assert "held at its identity" in report["inertia bounds"].detail
    # a drone: nothing but the free-flyer, M constant
    drone = kd.Robot(
        [
            kd.Link(
                "body",
                None,
                kd.Joint("root_joint", "floating"),
                inertia=kd.Inertia(1.5, (0, 0, 0.01), np.diag([0.02, 0.03, 0.04])),
            )
        ]
    )
    report = check_properties(drone, samples=10, T=0.2)
    assert report.passed, str(report)
    eig = np.linalg.eigvalsh(drone.mass_matrix(drone.neutral()))
    bounds = report["inertia bounds"].data
    assert (bounds["lambda_min"], bounds["lambda_max"]) == (eig[0], eig[-1])


def test_kinedyn_check_floating_base_on_solo12(capsys):
    from kinedyn.cli import main

    root = example_robot_data_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    path = os.path.join(root, "solo_description", "robots", "solo12.urdf")
    assert main(["check", path, "--floating-base", "--samples", "16", "--t", "0.3", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["passed"] and len(doc["checks"]) == 8  # with "friction dissipates"
    bounds = next(c for c in doc["checks"] if c["name"].startswith("inertia bounds"))
    assert len(bounds["q_lambda_min"]) == 19 and bounds["lambda_min"] > 0
    assert main(["check", path, "--floating-base", "--prove"]) != 0
    assert "--prove handles revolute and prismatic joints only" in capsys.readouterr().err
