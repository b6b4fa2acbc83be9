"""Symbolic base parameters against the numeric ones, and the size of the customised Newton-Euler model
(issue 4, follow-up items 3 and 4)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.description.dh import DHRow
from kinedyn.description.inertia import Inertia

warnings.filterwarnings("ignore", message=".*triangle inequality.*")


def _numeric_rank(robot, samples=60, seed=3):
    """Rank of the stacked numeric regressor by an SVD with a relative tolerance (independent of the
    pivoted QR inside robot.base_parameters())."""
    rng = np.random.default_rng(seed)
    q = robot.random_configuration(rng, size=samples)
    W = robot.regressor(q, rng.uniform(-2, 2, q.shape), rng.uniform(-4, 4, q.shape)).reshape(samples * robot.n, -1)
    scale = np.linalg.norm(W, axis=0)
    keep = scale > 1e-10 * scale.max()
    s = np.linalg.svd(W[:, keep] / scale[keep], compute_uv=False)
    return int(np.sum(s > 1e-9 * s[0]))


@pytest.mark.parametrize("name", ["puma560", "elbow_3r"])
def test_symbolic_and_numeric_base_parameter_counts_agree(name):
    """The PUMA's rotor inertias (numbers) used to count as a 37th 'parameter' in the symbolic grouping."""
    robot = getattr(kd.robots, name)()
    eom = robot.equations_of_motion(parameters="general", steps=False)
    theta = eom.base_parameters()
    numeric = len(robot.base_parameters().names)
    assert len(theta) == numeric == _numeric_rank(robot), (len(theta), numeric)
    # every grouped parameter is a combination of the general symbols only (no stray constant)
    for t in theta:
        assert all(term.free_symbols for term in sp.Add.make_args(t)), t


def _geared_2r():
    """A planar 2R arm whose drives have numeric rotor inertia: the known part of tau."""
    rod = lambda m, L: Inertia(m, (-L / 2, 0, 0), ((0, 0, 0), (0, m * L**2 / 12, 0), (0, 0, m * L**2 / 12)))
    rows = [
        DHRow(a=1.0, inertia=rod(2.0, 1.0), gear_ratio=10.0, rotor_inertia=1e-3),
        DHRow(a=0.5, inertia=rod(1.0, 0.5), gear_ratio=5.0, rotor_inertia=2e-3),
    ]
    return kd.Robot.from_dh(rows, gravity=(0, -9.81, 0), name="geared_2r")


def test_regressor_splits_off_the_known_rotor_inertia():
    robot = _geared_2r()
    eom = robot.equations_of_motion(parameters="general", steps=False)
    r = eom.regressor()
    Y, theta = r  # still unpacks as a pair
    qdd = eom.qdd
    # the rotor terms r^2 J_m qdd_k are known numbers, not parameters
    assert sp.expand(r.tau_known - sp.Matrix([0.1 * qdd[0], 0.05 * qdd[1]])).applyfunc(
        lambda e: sp.nsimplify(e, tolerance=1e-12)
    ) == sp.zeros(2, 1)
    assert len(theta) == len(robot.base_parameters().names)
    # Y Theta + tau_known == tau at random states and parameter values
    res = Y * theta + r.tau_known - (eom.tau - eom.friction)
    params = sorted(res.free_symbols - set(eom.q) - set(eom.qd) - set(eom.qdd), key=str)
    f = sp.lambdify([list(eom.q) + list(eom.qd) + list(eom.qdd), params], res)
    rng = np.random.default_rng(1)
    for _ in range(3):
        assert np.abs(np.asarray(f(rng.normal(size=6), rng.normal(size=len(params))), float)).max() < 1e-12


# ----------------------------------------------------------------------------------------------
# the customised Newton-Euler model: grouped parameters and the U-form of the moment
def test_puma_customised_model_operation_counts():
    """K&D's customised model with grouped parameters: under 600 operations with 60 general symbolic
    inertias (was 655 before grouping), well under 400 with the PUMA's numbers (was 456)."""
    from kinedyn.symbolic.robot_eom import general_parameters, newton_euler_eom

    robot = kd.robots.puma560()
    general = newton_euler_eom(robot, parameters=general_parameters(robot)).op_count()
    numeric = robot.equations_of_motion(method="newton_euler").op_count()
    assert general["total"] < 600, general
    assert numeric["total"] < 400, numeric


def _coordinate_axis_tree(seed):
    """A random tree whose joints turn or slide along signed coordinate axes (the grouping rules apply),
    plus one oblique revolute axis (left ungrouped), with random placements and inertias."""
    from kinedyn._math import homogeneous
    from kinedyn.description.joint import Joint
    from kinedyn.description.link import Link
    from kinedyn.testing import _rotation, random_inertia

    rng = np.random.default_rng(seed)
    links, names = [], []
    for i in range(5):
        k = int(rng.integers(0, 3))
        axis = [0.0, 0.0, 0.0]
        axis[k] = float(rng.choice([-1.0, 1.0]))
        if i == 3:
            axis = list(np.array([1.0, 2.0, 2.0]) / 3.0)
        kind = "prismatic" if i in (1, 4) else "revolute"
        joint = Joint(f"j{i + 1}", kind, tuple(axis), offset=float(rng.uniform(-0.5, 0.5)))
        parent = None if i == 0 else names[int(rng.integers(0, i))]
        links.append(
            Link(
                f"link{i + 1}",
                parent,
                joint,
                homogeneous(_rotation(rng), rng.uniform(-0.5, 0.5, 3)),
                np.eye(4),
                random_inertia(rng),
            )
        )
        names.append(f"link{i + 1}")
    return kd.Robot(links, [], gravity=(0.0, -9.81, 0.0), name=f"axes_tree_{seed}")


@pytest.mark.parametrize("seed", [0, 1])
def test_grouped_model_equals_ungrouped_and_numeric(seed):
    """Grouping moves parameters between links by K&D's rules; tau must not change: the grouped program
    (general symbols, then the robot's own values) equals the ungrouped one and the numeric RNEA."""
    from kinedyn.symbolic.lagrange import state_symbols
    from kinedyn.symbolic.newton_euler import newton_euler_program
    from kinedyn.symbolic.robot_eom import general_parameters

    robot = _coordinate_axis_tree(seed)
    q, qd, qdd = state_symbols(robot)
    rng = np.random.default_rng(seed)
    values = {}
    general = general_parameters(robot)
    for syms, b in zip(general, robot.tree.bodies):
        values.update(zip(syms, [float(v) for v in b.inertia.parameters()]))
    state = dict(zip(q + qd + qdd, rng.normal(size=3 * robot.n)))
    state.update(values)
    taus = []
    for group in (True, False):
        prog = newton_euler_program(robot, q, qd, qdd, parameters=general, group=group)
        env = {}
        for sym, expr in prog.assignments:
            env[sym] = float(expr.xreplace(state).xreplace(env))
        taus.append(np.array([float(sp.sympify(t).xreplace(state).xreplace(env)) for t in prog.outputs["tau"]]))
        if group:
            grouped = {str(s): e for s, e in prog.assignments if prog.tags[s][0] == "parameters"}
    assert sum(name[:2] in ("MX", "MY", "MZ", "MR") for name in grouped) >= 2 and any(
        "XR" in name for name in grouped
    ), sorted(grouped)
    np.testing.assert_allclose(taus[0], taus[1], rtol=1e-10, atol=1e-10)
    try:
        from kinedyn import _core  # noqa: F401
    except ImportError:
        return
    x = [np.array([state[s] for s in v]) for v in (q, qd, qdd)]
    np.testing.assert_allclose(
        taus[0]
        + [float(b.joint.viscous) * v + float(b.joint.coulomb) * np.sign(v) for b, v in zip(robot.tree.bodies, x[1])],
        robot.inverse_dynamics(*x),
        rtol=1e-10,
        atol=1e-10,
    )
