"""Random URDF trees (revolute, continuous, prismatic and fixed joints; arbitrary unit axes; rotated
joint and inertial origins) read by kinedyn and by Pinocchio: every frame pose, Jacobian and
dynamics quantity agrees. Pinocchio is an optional test extra (`pip install .[peers]`)."""

from __future__ import annotations

import numpy as np
import pytest

import kinedyn as kd

pin = pytest.importorskip("pinocchio", reason="Pinocchio (the `pin` package, test extra 'peers') is not installed")
pytest.importorskip("kinedyn._core", reason="the native module is not built")


def _fmt(v) -> str:
    return " ".join(f"{x:.17g}" for x in v)


def random_urdf(seed: int, n_moving: int = 7, n_fixed: int = 3) -> str:
    """A random tree as URDF text: each link hangs from a random earlier link."""
    rng = np.random.default_rng(seed)
    links = ["root"]
    parts = ['<robot name="random">', '<link name="root"/>']
    kinds = ["revolute", "continuous", "prismatic"] + ["fixed"] * 0
    order = ["moving"] * n_moving + ["fixed"] * n_fixed
    rng.shuffle(order[1:])  # the first link always moves
    for k, role in enumerate(order):
        name = f"L{k}"
        parent = links[int(rng.integers(0, len(links)))]
        kind = "fixed" if role == "fixed" else kinds[int(rng.integers(0, 3))]
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        a, b, c = rng.uniform(0.05, 0.4, 3)
        m = rng.uniform(0.3, 3.0)
        principal = np.array([b * b + c * c, a * a + c * c, a * a + b * b]) * m / 12
        parts.append(
            f'<link name="{name}"><inertial><origin xyz="{_fmt(rng.uniform(-0.2, 0.2, 3))}" rpy="{_fmt(rng.uniform(-3, 3, 3))}"/>'
            f'<mass value="{m:.17g}"/><inertia ixx="{principal[0]:.17g}" ixy="0" ixz="0" iyy="{principal[1]:.17g}" iyz="0" izz="{principal[2]:.17g}"/>'
            "</inertial></link>"
        )
        limit = '<limit lower="-2" upper="2" effort="100" velocity="3"/>' if kind in ("revolute", "prismatic") else ""
        axis_xml = f'<axis xyz="{_fmt(axis)}"/>' if kind != "fixed" else ""
        parts.append(
            f'<joint name="J{k}" type="{kind}"><parent link="{parent}"/><child link="{name}"/>'
            f'<origin xyz="{_fmt(rng.uniform(-0.4, 0.4, 3))}" rpy="{_fmt(rng.uniform(-3, 3, 3))}"/>{axis_xml}{limit}</joint>'
        )
        links.append(name)
    parts.append("</robot>")
    return "\n".join(parts)


def pair(seed):
    xml = random_urdf(seed)
    robot = kd.Robot.from_urdf(xml, gravity=(0.0, 0.0, -9.81))
    model = pin.buildModelFromXML(xml)
    # Pinocchio's joint order: map kinedyn's coordinates to Pinocchio's velocity order by name
    pin_names = [model.names[i] for i in range(1, model.njoints)]
    assert sorted(pin_names) == sorted(robot.joint_names) and model.nv == robot.n
    perm = np.array([robot.joint_names.index(nm) for nm in pin_names])
    return robot, model, model.createData(), perm


def pin_configuration(model, robot, q, perm):
    """Pinocchio's q: a continuous joint is stored as (cos, sin) of its angle."""
    out = np.zeros(model.nq)
    for k, j in enumerate(range(1, model.njoints)):
        x = q[perm[k]]
        i, nq = model.idx_qs[j], model.nqs[j]
        out[i : i + nq] = [np.cos(x), np.sin(x)] if nq == 2 else [x]
    return out


@pytest.mark.parametrize("seed", range(6))
def test_random_urdf_trees_agree_with_pinocchio(seed):
    robot, model, data, perm = pair(seed)
    rng = np.random.default_rng(100 + seed)
    for _ in range(3):
        q = rng.uniform(-2, 2, robot.n)
        qd = rng.normal(size=robot.n)
        qdd = rng.normal(size=robot.n)
        qp, qdp, qddp = pin_configuration(model, robot, q, perm), qd[perm], qdd[perm]
        # every URDF link is a frame in both
        pin.framesForwardKinematics(model, data, qp)
        for name in robot.frame_names:
            if not model.existFrame(name) or name == robot.base:
                continue
            fid = model.getFrameId(name)
            np.testing.assert_allclose(robot.pose(q, name), data.oMf[fid].homogeneous, atol=1e-10, err_msg=name)
            J = pin.computeFrameJacobian(model, data, qp, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(robot.jacobian(q, name)[:, perm], J, atol=1e-10, err_msg=name)
        tau = pin.rnea(model, data, qp, qdp, qddp)
        np.testing.assert_allclose(robot.inverse_dynamics(q, qd, qdd)[perm], tau, atol=1e-9)
        M = pin.crba(model, data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(robot.mass_matrix(q)[np.ix_(perm, perm)], M, atol=1e-9)
        C = pin.computeCoriolisMatrix(model, data, qp, qdp)
        np.testing.assert_allclose(robot.coriolis_matrix(q, qd)[np.ix_(perm, perm)], C, atol=1e-9)
        np.testing.assert_allclose(
            robot.gravity_torque(q)[perm], pin.computeGeneralizedGravity(model, data, qp), atol=1e-9
        )
        taus = rng.normal(size=robot.n)
        np.testing.assert_allclose(
            robot.forward_dynamics(q, qd, taus)[perm], pin.aba(model, data, qp, qdp, taus[perm]), atol=1e-9
        )
        # analytical derivatives (Pinocchio differentiates in its tangent space: d/dq for 1-dof joints)
        block = np.ix_(perm, perm)
        dq, dqd, _ = robot.inverse_dynamics_derivatives(q, qd, qdd)
        pq, pqd, _ = pin.computeRNEADerivatives(model, data, qp, qdp, qddp)
        np.testing.assert_allclose(dq[block], pq, atol=1e-8)
        np.testing.assert_allclose(dqd[block], pqd, atol=1e-8)
        aq, aqd, _ = robot.forward_dynamics_derivatives(q, qd, taus)
        bq, bqd, _ = pin.computeABADerivatives(model, data, qp, qdp, taus[perm])
        np.testing.assert_allclose(aq[block], bq, atol=1e-8 * max(1.0, np.abs(bq).max()))
        np.testing.assert_allclose(aqd[block], bqd, atol=1e-8 * max(1.0, np.abs(bqd).max()))


def test_the_generator_makes_trees_with_every_joint_kind():
    kinds = set()
    branching = False
    for seed in range(6):
        robot = kd.Robot.from_urdf(random_urdf(seed))
        kinds |= {l.joint.kind for l in robot.links}
        branching |= any(p < i - 1 for i, p in enumerate(robot.parents))
    assert kinds == {"revolute", "prismatic", "fixed"} and branching
