"""Mimic joints (URDF ``<mimic>``): a follower joint's coordinate is a fixed affine function of its
leader's, ``q_f = multiplier * q_leader + offset`` (:class:`kinedyn.description.joint.Mimic`).

A robot with mimic joints has two coordinate sets. The *full* one has a coordinate for every moving
joint (what the native core computes with); the *reduced* one (``Robot(..., mimic="reduce")``, the
default, as Pinocchio 3's ``buildModelFromUrdf(path, mimic=True)``) has only the independent joints'.
They are related by constant maps::

    v_full = G v            (G: nv_full x nv; a column per independent coordinate: 1 at its own
                             row, ``multiplier`` at each of its followers' rows)
    q_full = expand(q)      (the independent blocks copied, each follower's entry
                             ``multiplier * q[leader] + offset``)

built by index ranges from each joint's ``nq`` and ``nv`` so that multi-DOF blocks (floating,
spherical, planar joints, which can neither lead nor follow) are copied whole. A follower of a
follower is resolved to the first leader (the relations compose: ``m2 (m1 q + o1) + o2``); a cycle
of followers is an error. How the dynamics reduce with G: :mod:`kinedyn.native.mimic`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["MimicMap", "mimic_map", "MIMIC_MODES"]

MIMIC_MODES = ("reduce", "independent")


@dataclass(frozen=True, eq=False)
class MimicMap:
    """The constant maps between reduced and full coordinates of one robot (see the module)."""

    #: follower joint name -> its relation to an independent leader (chains resolved)
    relations: dict
    #: indices (in body order) of the bodies whose joints are independent, and of the followers
    independent: tuple
    followers: tuple
    nq_full: int
    nv_full: int
    nq: int
    nv: int
    #: full-q indices of the independent coordinates, in reduced order (len nq)
    q_keep: np.ndarray
    #: full-q index of each follower, reduced-q index of its leader, multiplier, offset
    q_follow: np.ndarray
    q_lead: np.ndarray
    multiplier: np.ndarray
    offset: np.ndarray
    #: v_full = G v, (nv_full, nv)
    G: np.ndarray = field(repr=False)
    #: q_full = q @ Gq_T + b: the same map on configurations, (nq, nq_full) and (nq_full,) (exact:
    #: each full entry is one reduced entry times 1 or a multiplier, plus zeros and an offset)
    Gq_T: np.ndarray = field(repr=False)
    b: np.ndarray = field(repr=False)

    def expand_q(self, q: np.ndarray) -> np.ndarray:
        """Full configuration(s) from reduced one(s): (..., nq) -> (..., nq_full)."""
        return q @ self.Gq_T + self.b

    def expand_v(self, v: np.ndarray) -> np.ndarray:
        """Full velocities (or accelerations) from reduced ones: ``G v``, (..., nv) -> (..., nv_full)."""
        return v @ self.G.T

    def reduce_force(self, tau: np.ndarray) -> np.ndarray:
        """Generalised forces on the reduced coordinates: ``G^T tau``, (..., nv_full) -> (..., nv)
        (the principle of virtual work: tau_r . dq_r = tau . G dq_r for every dq_r)."""
        return tau @ self.G

    def follower_names(self) -> list:
        return list(self.relations)


def _sizes(joints) -> tuple:
    iq, iv, q0, v0 = [], [], 0, 0
    for j in joints:
        iq.append(q0)
        iv.append(v0)
        q0 += j.nq
        v0 += j.nv
    return iq, iv, q0, v0


def mimic_map(joints: Sequence, all_joints: Sequence, mode: str = "reduce", robot: str = "robot") -> MimicMap | None:
    """The coordinate maps of a robot whose moving joints (in body order) are ``joints``;
    ``all_joints`` includes the fixed ones (for the error naming a fixed leader). None when no
    joint follows another or ``mode == "independent"`` (mimic relations are then ignored, without
    checking them: the way to load a file whose ``<mimic>`` names a joint it does not have).

    ValueError naming the follower when its leader is missing, fixed, multi-DOF, or when followers
    form a cycle."""
    if mode not in MIMIC_MODES:
        raise ValueError(f"mimic must be one of {list(MIMIC_MODES)}, got {mode!r}")
    if mode == "independent" or not any(j.mimic is not None for j in joints):
        return None
    index = {j.name: i for i, j in enumerate(joints)}
    kinds = {j.name: j.kind for j in all_joints}
    for j in joints:
        m = j.mimic
        if m is None:
            continue
        what = f"robot '{robot}': joint '{j.name}' mimics joint '{m.leader}'"
        if m.leader not in index:
            if m.leader in kinds:
                raise ValueError(f"{what}, which is {kinds[m.leader]}: a leader must be a revolute or prismatic joint")
            raise ValueError(
                f"{what}, which the robot does not have (joints: {list(index)}); "
                "load it with mimic='independent' to keep the follower as an independent joint"
            )
        leader = joints[index[m.leader]]
        if leader.kind not in ("revolute", "prismatic"):
            raise ValueError(f"{what}, which is {leader.kind}: a leader must be a revolute or prismatic joint")
    relations: dict = {}
    for j in joints:
        if j.mimic is None:
            continue
        relation, seen = j.mimic, [j.name]
        while joints[index[relation.leader]].mimic is not None:  # a follower of a follower
            if relation.leader in seen:
                raise ValueError(f"robot '{robot}': mimic joints form a cycle: {' -> '.join(seen + [relation.leader])}")
            seen.append(relation.leader)
            relation = joints[index[relation.leader]].mimic.then(relation)
        relations[j.name] = relation
    independent = tuple(i for i, j in enumerate(joints) if j.name not in relations)
    followers = tuple(i for i, j in enumerate(joints) if j.name in relations)
    iq, iv, nq_full, nv_full = _sizes(joints)
    riq, riv, nq, nv = _sizes([joints[i] for i in independent])
    reduced_q = dict(zip(independent, riq))
    reduced_v = dict(zip(independent, riv))
    q_keep = np.concatenate([np.arange(iq[i], iq[i] + joints[i].nq) for i in independent]).astype(np.int64)
    G = np.zeros((nv_full, nv))
    for i in independent:
        G[iv[i] : iv[i] + joints[i].nv, reduced_v[i] : reduced_v[i] + joints[i].nv] = np.eye(joints[i].nv)
    q_lead, mult, off = [], [], []
    for f in followers:
        relation = relations[joints[f].name]
        leader = index[relation.leader]
        q_lead.append(reduced_q[leader])
        mult.append(relation.multiplier)
        off.append(relation.offset)
        G[iv[f], reduced_v[leader]] = relation.multiplier
    q_follow = np.array([iq[f] for f in followers], dtype=np.int64)
    Gq_T, b = np.zeros((nq, nq_full)), np.zeros(nq_full)
    Gq_T[np.arange(nq), q_keep] = 1.0
    Gq_T[q_lead, q_follow] = mult
    b[q_follow] = off
    return MimicMap(
        relations=relations,
        independent=independent,
        followers=followers,
        nq_full=nq_full,
        nv_full=nv_full,
        nq=nq,
        nv=nv,
        q_keep=q_keep,
        q_follow=q_follow,
        q_lead=np.array(q_lead, dtype=np.int64),
        multiplier=np.array(mult),
        offset=np.array(off),
        G=G,
        Gq_T=Gq_T,
        b=b,
    )


def reduced_coefficient(description, name: str) -> np.ndarray:
    """A drive coefficient of a robot with reduced mimic joints, followers included, per degree of
    freedom of the independent joints (a leader ``k`` is 1-DOF): the followers' friction and rotor inertia act on ``G qd`` and come back
    through ``G^T``; each full coordinate lies in one column of G, so ``G^T diag(a) G`` is diagonal:

    - ``armature`` and ``viscous``: ``a_k + sum_f m_f^2 a_f`` over the followers f of k (multiplier m_f);
    - Coulomb levels: a follower with ``m_f > 0`` adds ``m_f c_f`` of the same direction's level, one
      with ``m_f < 0`` moves the other way and adds ``|m_f|`` times its opposite level: ``coulomb``
      (qd > 0) gets ``|m_f| (c_f+ if m_f > 0 else c_f-)``, ``coulomb_negative`` the reverse.

    so that ``robot.friction_torque(qd) == G^T friction_full(G qd)`` (``description``: the robot's
    :class:`~kinedyn.description.description.Description`) and ``M_r`` has ``armature`` on
    its diagonal, as without mimic joints."""
    m = description.mimic_map
    joints = [b.joint for b in description.tree.bodies]

    def own(j, key):
        return float(j.coulomb_levels[1] if key == "coulomb_negative" else getattr(j, key))

    values: list = []  # per reduced degree of freedom (a multi-DOF joint has no drive data: zeros)
    start = {}
    for j in description.joints:
        start[j.name] = len(values)
        values.extend([0.0] * j.nv if j.is_multi_dof else [own(j, name)])
    out = np.array(values)
    for follower in (joints[i] for i in m.followers):
        relation = m.relations[follower.name]
        mult = relation.multiplier
        if name in ("armature", "viscous"):
            out[start[relation.leader]] += mult * mult * own(follower, name)
        else:
            same = (name == "coulomb") == (mult > 0)
            out[start[relation.leader]] += abs(mult) * own(follower, "coulomb" if same else "coulomb_negative")
    return out


def lock_followers(relations: dict, values: dict, given: dict) -> dict:
    """``Robot.lock_joints`` with reduced mimic joints: ``values`` (leader name -> locked value) with
    every follower of a locked leader added, at ``given[follower]`` when the caller named it with a
    value, else at ``multiplier * value + offset``. A follower named without its leader is an error
    (it moves with its leader: lock the leader, or load the robot with mimic="independent")."""
    values = dict(values)
    for follower in given:
        leader = relations[follower].leader
        if leader not in values:
            raise ValueError(
                f"lock_joints: joint '{follower}' follows joint '{leader}' (mimic); lock '{leader}' too "
                "(its followers are locked with it), or load the robot with mimic='independent'"
            )
    for follower, relation in relations.items():
        if relation.leader in values:
            value = given.get(follower)
            if value is None:
                value = relation.multiplier * values[relation.leader] + relation.offset
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise ValueError(
                    f"lock_joints: the value of joint '{follower}' must be a number, got {value!r}"
                ) from None
            if not np.isfinite(v):
                raise ValueError(f"lock_joints: the value of joint '{follower}' must be finite, got {v}")
            values[follower] = v
    return values


def body_coordinates(robot) -> list:
    """Per moving body of a robot with reduced mimic joints: ``{"q": k, "scale": m, "shift": o}``, its
    joint's coordinate being ``m * q[k] + o`` (1 and 0 for an independent joint, k its own index); for
    viewers that run the forward kinematics themselves (the report's viewer.js). 1-DOF joints only."""
    m = robot._mimic
    names = robot.joint_names
    out = []
    for b in robot.tree.bodies:
        relation = m.relations.get(b.joint.name)
        if relation is None:
            out.append({"q": names.index(b.joint.name), "scale": 1.0, "shift": 0.0})
        else:
            out.append({"q": names.index(relation.leader), "scale": relation.multiplier, "shift": relation.offset})
    return out
