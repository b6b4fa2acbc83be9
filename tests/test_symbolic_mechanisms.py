"""Mechanisms built from robots (issue 12 §7): a drive map q = A p applied to a robot's equations
(the remotely driven arm of Spong §9.4) and a closed chain assembled from two serial robots and the
loop closure (the five-bar), each checked against the hand-written bodies and the numeric core."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from trig_zero import all_zero

import kinedyn as kd
from kinedyn.robots import examples as rex
from kinedyn.symbolic import examples as ex
from kinedyn.symbolic.mechanisms import (
    change_coordinates,
    closed_chain,
    closed_chain_system,
    decoupling_condition,
    loop_closure,
)

RNG = np.random.default_rng(41)


def _by_name(values):
    return {sp.Symbol(k, positive=True): v for k, v in values.items()}


def _random_values(names, **given):
    out = {n: float(RNG.uniform(0.5, 2.0)) for n in names.split()}
    out.update(given)
    return out


def _same(a: sp.Matrix, b: sp.Matrix) -> bool:
    return all_zero(a - b)


# ----------------------------------------------------------------------------- change of coordinates
def test_remotely_driven_arm_from_robot_equals_the_hand_written_bodies():
    from_robot = rex.remotely_driven_arm_from_robot()
    by_hand = ex.remotely_driven_arm().equations_of_motion()
    assert [s.name for s in from_robot.q] == ["p1", "p2"] and list(from_robot.qd) == list(by_hand.qd)
    assert _same(from_robot.M, by_hand.M)
    assert _same(from_robot.C, by_hand.C)
    assert _same(from_robot.g, by_hand.g)
    # Spong §9.4.3: no Coriolis term pd1 pd2, only centrifugal ones
    pd1, pd2 = from_robot.qd
    for e in (from_robot.C * from_robot.qd).applyfunc(sp.expand):
        assert sp.Poly(e, pd1, pd2).coeff_monomial(pd1 * pd2) == 0


@pytest.mark.parametrize(
    "arm, A",
    [
        ("planar_2r", [[1, 0], [-1, 1]]),
        ("planar_3r", [[1, 0, 0], [-1, 1, 0], [2, -1, 1]]),
        ("planar_3r", [[0, 1, 0], [1, 0, 1], [1, 1, -1]]),
    ],
    ids=["remote-drive", "triangular", "mixing"],
)
def test_change_of_coordinates_against_the_numeric_core(arm, A):
    """tau_p(p, pd, pdd) == A^T tau_q(A p, A pd, A pdd) and C_p == A^T C_q A, D_p == A^T D_q A with
    tau_q, C_q, D_q from the numeric core (RNEA, Coriolis matrix, CRBA)."""
    factory = getattr(kd.robots, arm)
    symbolic = factory(symbolic=True)
    eom = change_coordinates(symbolic.equations_of_motion(steps=False), A)
    values = {s.name: float(RNG.uniform(0.5, 2.0)) for s in symbolic.symbols}
    robot = symbolic.subs(values)
    A = np.array(A, dtype=float)
    subs = _by_name(values)
    n = eom.n
    tau = sp.lambdify([list(eom.q), list(eom.qd), list(eom.qdd)], eom.tau.xreplace(subs))
    C = sp.lambdify([list(eom.q), list(eom.qd)], eom.C.xreplace(subs))
    D = sp.lambdify([list(eom.q)], eom.M.xreplace(subs))
    for _ in range(5):
        p, pd, pdd = RNG.uniform(-np.pi, np.pi, n), RNG.normal(size=n), RNG.normal(size=n)
        q, qd, qdd = A @ p, A @ pd, A @ pdd
        np.testing.assert_allclose(np.ravel(tau(p, pd, pdd)), A.T @ robot.inverse_dynamics(q, qd, qdd), atol=1e-10)
        np.testing.assert_allclose(np.asarray(C(p, pd), float), A.T @ robot.coriolis_matrix(q, qd) @ A, atol=1e-10)
        np.testing.assert_allclose(np.asarray(D(p), float), A.T @ robot.mass_matrix(q) @ A, atol=1e-10)
    # the Christoffel symbols are those of D_p (Spong 9.58), symmetric in i, j
    c = eom.christoffel
    for i in range(n):
        for j in range(n):
            for k in range(n):
                assert sp.expand(c[i][j][k] - c[j][i][k]) == 0


def test_change_of_coordinates_rejects_bad_maps():
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    q1 = eom.q[0]
    with pytest.raises(ValueError, match="singular"):
        change_coordinates(eom, [[1, 1], [2, 2]])
    with pytest.raises(ValueError, match="shape"):
        change_coordinates(eom, [[1, 0, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match="constant"):
        change_coordinates(eom, [[1, 0], [q1, 1]])
    with pytest.raises(ValueError, match="already symbols"):
        change_coordinates(eom, [[1, 0], [-1, 1]], coordinates="l1 l2")


# ----------------------------------------------------------------------------- five-bar from two chains
FIVE_BAR_PARAMS = "l1 l2 lc1 lc2 lc3 lc4 m1 m2 m3 m4 I1 I2 I3 I4 g"


def test_five_bar_from_chains_equals_the_hand_written_bodies():
    reduced = rex.five_bar_from_chains()
    by_hand = ex.five_bar().equations_of_motion()
    assert [s.name for s in reduced.q] == ["q1", "q2"]
    assert _same(reduced.M, by_hand.M)
    assert _same(reduced.C, by_hand.C)
    assert _same(reduced.g, by_hand.g)


def _tree_projection(chains, values, q_red):
    """D and g of the closed chain from the numeric core: the trees' M and g at the tree
    configuration, projected on the constraint manifold with the null space of the closure Jacobian
    (by central differences of the two tool positions), parametrised by the independent q1, q2."""
    a, b = (c.subs(values) for c in chains)
    q1, q2 = q_red
    theta = np.array([q1, q2 - q1, q2, q1 - q2])  # (q1, phi4, q2, phi3) on the parallelogram branch

    def closure(th):
        return a.pose(th[:2])[:2, 3] - b.pose(th[2:])[:2, 3]

    assert np.abs(closure(theta)).max() < 1e-12
    h = 1e-6
    Aphi = np.column_stack([(closure(theta + h * e) - closure(theta - h * e)) / (2 * h) for e in np.eye(4)])
    independent, dependent = [0, 2], [1, 3]
    J = np.zeros((4, 2))
    J[independent] = np.eye(2)
    J[dependent] = -np.linalg.solve(Aphi[:, dependent], Aphi[:, independent])
    D_tree = np.zeros((4, 4))
    D_tree[:2, :2], D_tree[2:, 2:] = a.mass_matrix(theta[:2]), b.mass_matrix(theta[2:])
    g_tree = np.r_[a.gravity_torque(theta[:2]), b.gravity_torque(theta[2:])]
    return J.T @ D_tree @ J, J.T @ g_tree


def test_five_bar_reduced_dynamics_equal_the_numeric_projection_of_the_trees():
    reduced = rex.five_bar_from_chains()
    chains = rex.five_bar_chains()
    values = _random_values(FIVE_BAR_PARAMS)
    subs = _by_name(values)
    D = sp.lambdify([list(reduced.q)], reduced.M.xreplace(subs))
    g = sp.lambdify([list(reduced.q)], reduced.g.xreplace(subs))
    for _ in range(5):
        q = RNG.uniform(-np.pi, np.pi, 2)
        D_num, g_num = _tree_projection(chains, values, q)
        np.testing.assert_allclose(np.asarray(D(q), float), D_num, rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(np.ravel(g(q)), g_num, rtol=1e-7, atol=1e-9)


def test_five_bar_decoupling_condition_solved():
    reduced = rex.five_bar_from_chains()
    m3, m4, l1, l2, lc3, lc4 = sp.symbols("m3 m4 l1 l2 lc3 lc4", positive=True)
    conditions, solution = decoupling_condition(reduced, solve_for="m3")
    assert len(conditions) == 1
    assert (
        sp.expand((conditions[0].lhs - conditions[0].rhs) ** 2 - (m3 * l2 * lc3 - m4 * l1 * lc4) ** 2) == 0
    )  # m3 l2 lc3 = m4 l1 lc4
    assert sp.simplify(solution[m3] - m4 * l1 * lc4 / (l2 * lc3)) == 0
    assert (
        decoupling_condition(reduced, solve_for="m3", constant=True)[1] == solution
    )  # the diagonal is constant anyway
    decoupled = reduced.subs({m3: solution[m3]})
    assert decoupled.M[0, 1].simplify() == 0 and not decoupled.M.free_symbols & set(reduced.q)
    assert decoupled.C.applyfunc(sp.simplify) == sp.zeros(2, 2)
    # numerically, from the trees: with m3 from the solution the projected D is diagonal; off it, not
    chains = rex.five_bar_chains()
    values = _random_values(FIVE_BAR_PARAMS)
    values["m3"] = float(solution[m3].xreplace(_by_name(values)))
    q = RNG.uniform(-1.0, 1.0, 2)
    D_num, _ = _tree_projection(chains, values, q)
    assert abs(D_num[0, 1]) < 1e-9 * abs(D_num).max()
    values["m3"] *= 1.3
    assert abs(_tree_projection(chains, values, q)[0][0, 1]) > 1e-3


def test_five_bar_constrained_tree_system_moves_as_the_reduced_equations():
    """The other route: the two trees plus the holonomic closure as one constrained
    LagrangianSystem (4 coordinates, 2 constraints, solved by the KKT system); on the manifold its
    accelerations are J times the reduced equations' (J constant on the parallelogram branch)."""
    chains = rex.five_bar_chains()
    closure = loop_closure(*chains)
    assert len(closure) == 2
    system = closed_chain_system(chains, closure)
    reduced = rex.five_bar_from_chains()
    values = _random_values(FIVE_BAR_PARAMS)
    accelerations = system.numeric_accelerations(values)
    subs = _by_name(values)
    D = sp.lambdify([list(reduced.q)], reduced.M.xreplace(subs))
    h = sp.lambdify([list(reduced.q), list(reduced.qd)], (reduced.C * reduced.qd + reduced.g).xreplace(subs))
    J = np.array([[1, 0], [-1, 1], [0, 1], [1, -1]], dtype=float)
    assert [s.name for s in system.q] == ["q1", "phi4", "q2", "phi3"]
    for _ in range(4):
        q, qd = RNG.uniform(-np.pi, np.pi, 2), RNG.normal(size=2)
        qdd = np.linalg.solve(np.asarray(D(q), float), -np.ravel(h(q, qd)))
        tree_qdd, lam = accelerations(0.0, J @ q, J @ qd)
        np.testing.assert_allclose(tree_qdd, J @ qdd, rtol=1e-8, atol=1e-10)
        assert np.abs(lam).max() > 1e-6


def test_closed_chain_rejects_a_branch_that_does_not_close_the_loop():
    chains = rex.five_bar_chains()
    closure = loop_closure(*chains)
    q1, phi4, q2, phi3 = sp.symbols("q1 phi4 q2 phi3", real=True)
    with pytest.raises(ValueError, match="does not close the loop"):
        closed_chain(chains, closure, independent=[q1, q2], solution={phi4: q2 - q1, phi3: q2 - q1})
    with pytest.raises(ValueError, match="every dependent coordinate"):
        closed_chain(chains, closure, independent=[q1, q2], solution={phi4: q2 - q1})
    with pytest.raises(ValueError, match="not a coordinate"):
        closed_chain(chains, closure, independent=["q1", "x"], solution={phi4: q2 - q1, phi3: q1 - q2})


# ----------------------------------------------------------------------------- LagrangianSystem.change_coordinates
def test_lagrangian_system_change_of_coordinates_back_to_joint_angles():
    """The hand-written remotely driven arm (absolute angles p) taken back to joint angles
    (p = A^-1 q, p1 = q1, p2 = q1 + q2) is the planar elbow Robot's model; forces map by A^T."""
    remote = ex.remotely_driven_arm()
    joint = remote.change_coordinates([[1, 0], [1, 1]], coordinates="q1 q2")
    eom = joint.equations_of_motion()
    arm = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    assert [c.name for c in joint.q] == ["q1", "q2"] and [c.name for c in joint.qd] == ["qdot1", "qdot2"]
    rename = dict(zip(arm.q, eom.q)) | dict(zip(arm.qd, eom.qd))
    assert _same(eom.M, arm.M.xreplace(rename))
    assert _same(eom.C, arm.C.xreplace(rename))
    assert _same(eom.g, arm.g.xreplace(rename))
    u1, u2 = remote.u
    assert list(joint.u) == [u1 + u2, u2]  # A^T u


def test_lagrangian_system_change_of_coordinates_keeps_constraints():
    """The particle on the sphere in scaled, mixed coordinates still moves on the sphere."""
    from scipy.integrate import solve_ivp

    A = np.array([[2.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 3.0]])
    system = ex.sphere_particle().change_coordinates(sp.Matrix(A).applyfunc(sp.nsimplify))
    assert len(system.holonomic) == 1
    q0 = np.array([1.0, 0.0, 0.0])
    v0 = np.array([0.0, 0.6, 0.8])
    p0, pd0 = np.linalg.solve(A, q0), np.linalg.solve(A, v0)
    sol = solve_ivp(system.numeric(), (0, 3.0), np.r_[p0, pd0], rtol=1e-10, atol=1e-12)
    Q = A @ sol.y[:3]
    np.testing.assert_allclose(np.linalg.norm(Q, axis=0), 1.0, atol=1e-7)  # on the sphere
    np.testing.assert_allclose(np.cross(q0, v0) @ Q, 0.0, atol=1e-7)  # on the great circle through q0 along v0
    np.testing.assert_allclose(np.linalg.norm(A @ sol.y[3:], axis=0), 1.0, rtol=1e-7)  # at constant speed
    assert np.ptp(Q[0]) > 1.0  # it travelled
    with pytest.raises(ValueError, match="singular"):
        ex.sphere_particle().change_coordinates([[1, 0, 0], [0, 1, 0], [1, 1, 0]])
