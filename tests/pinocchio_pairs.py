"""Pairs of a kinedyn Robot and a Pinocchio model of the same mechanism, with the map between their
coordinates (joint order, continuous joints' (cos, sin), multi-DOF blocks), for the oracle tests."""

from __future__ import annotations

import numpy as np


class PinPair:
    """``robot`` and Pinocchio ``model`` with ``to_pin_q(q)``, ``perm`` (kinedyn's velocity index of
    each of Pinocchio's), and ``from_pin_q``; joints matched by name."""

    def __init__(self, robot, model):
        import pinocchio as pin  # noqa: F401  (the caller made sure it exists)

        self.robot, self.model, self.data = robot, model, model.createData()
        names = [model.names[j] for j in range(1, model.njoints)]
        assert sorted(names) == sorted(robot.joint_names), (names, robot.joint_names)
        q_at = np.cumsum([0] + [j.nq for j in robot.joints])
        v_at = np.cumsum([0] + [j.nv for j in robot.joints])
        self.blocks = []  # (pin idx_q, pin nq, kinedyn q start, kinedyn nq, kinedyn's joint offset)
        perm = []
        for j in range(1, model.njoints):
            k = robot.joint_names.index(model.names[j])
            nv = robot.joints[k].nv
            assert model.nvs[j] == nv, (model.names[j], model.nvs[j], nv)
            offset = 0.0 if robot.joints[k].is_multi_dof else float(robot.joints[k].offset)
            self.blocks.append((model.idx_qs[j], model.nqs[j], q_at[k], robot.joints[k].nq, offset))
            perm.extend(range(v_at[k], v_at[k] + nv))
        self.perm = np.array(perm, dtype=int)

    def to_pin_q(self, q):
        out = np.zeros(self.model.nq)
        for i, nq, k, knq, offset in self.blocks:
            if nq == knq:
                out[i : i + nq] = q[k : k + nq]
                out[i] += offset  # a 1-DOF joint's offset (0 for multi-DOF blocks)
            else:  # Pinocchio's unbounded revolute: (cos, sin) of the angle
                assert (nq, knq) == (2, 1)
                out[i : i + 2] = np.cos(q[k] + offset), np.sin(q[k] + offset)
        return out

    def random_state(self, rng):
        """A random (q, v, a) of the robot: unit quaternions and (cos, sin) pairs, angles in [-pi, pi]."""
        robot = self.robot
        q = []
        for j in robot.joints:
            if j.kind == "floating":
                quat = rng.normal(size=4)
                q.extend([*rng.uniform(-1, 1, 3), *(quat / np.linalg.norm(quat))])
            elif j.kind == "spherical":
                quat = rng.normal(size=4)
                q.extend(quat / np.linalg.norm(quat))
            elif j.kind == "planar":
                th = rng.uniform(-np.pi, np.pi)
                q.extend([*rng.uniform(-1, 1, 2), np.cos(th), np.sin(th)])
            else:
                lo, hi = j.lower, j.upper
                lo, hi = (lo, hi) if np.isfinite(lo) and np.isfinite(hi) and lo < hi else (-np.pi, np.pi)
                q.append(rng.uniform(lo, hi))
        return np.array(q), rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def pinocchio_model(robot):
    """Pinocchio's model of a kinedyn robot built joint by joint (no file in between): every joint
    kind, placement and inertia of ``robot.tree`` (planar joints must have the normal z)."""
    import pinocchio as pin

    model = pin.Model()
    model.gravity.linear = np.asarray(robot.gravity, dtype=float)
    ids = []
    for body in robot.tree.bodies:
        j = body.joint
        axis = np.asarray(j.axis, dtype=float)
        if j.kind == "floating":
            jm = pin.JointModelFreeFlyer()
        elif j.kind == "spherical":
            jm = pin.JointModelSpherical()
        elif j.kind == "planar":
            assert np.allclose(axis, (0, 0, 1)), "Pinocchio's planar joint moves in its frame's xy plane"
            jm = pin.JointModelPlanar()
        elif j.kind == "revolute":
            jm = pin.JointModelRevoluteUnaligned(axis)
        else:
            jm = pin.JointModelPrismaticUnaligned(axis)
        T = np.asarray(body.placement, dtype=float)
        parent = 0 if body.parent < 0 else ids[body.parent]
        jid = model.addJoint(parent, jm, pin.SE3(T[:3, :3], T[:3, 3]), j.name)
        inertia = body.inertia
        model.appendBodyToJoint(
            jid,
            pin.Inertia(
                float(inertia.mass), np.array(inertia.com, dtype=float), np.array(inertia.inertia, dtype=float)
            ),
            pin.SE3.Identity(),
        )
        ids.append(jid)
    model.armature = np.asarray(robot.armature, dtype=float)  # reflected rotor inertia (Pinocchio 3 adds it to M)
    return model
