"""The cross-loader diff (docs/audit.md, "What each tool makes of a file"): one URDF loaded by
kinedyn, Pinocchio and MuJoCo (each with its defaults), compared on M(q), g(q) and the link frames
at sampled configurations, naming the joint and, where a known import behaviour explains it, the
link and the cause of every difference.

The peers are optional (the ``peers`` extra): a tool that is not installed, or that refuses the
file, is a row saying so. MuJoCo's URDF import is given the file without its meshes (MuJoCo cannot
resolve ``package://`` paths; primitive collision shapes are kept, since MuJoCo computes the
inertia of a link that has none from them). Joints are matched by name; mimic joints are compared
as independent joints (Pinocchio's default reader; MuJoCo imports no mimic).

Causes tried for a difference (each a variant of kinedyn's model that imitates one tool's known
import behaviour; the variant that removes the difference names the cause):

- MuJoCo gives a link without ``<inertial>`` the inertia of its collision shapes at 1000 kg/m^3
  (its compiler's ``inertiafromgeom="auto"``);
- MuJoCo's URDF import dropped the rotation of ``<inertial><origin rpy>`` (mujoco#3559), so a
  rotated inertial frame read without its rotation;
- Pinocchio's MJCF reader keeps its own gravity whatever ``<option gravity>`` says.
"""

from __future__ import annotations

import dataclasses
import os
import re
import tempfile
from dataclasses import dataclass, field

import numpy as np

from ..description.audit_facts import urdf_facts
from ..description.audit_shapes import Solid, combined, solid_of
from ..description.inertia import Inertia
from ..robot import Robot
from ..robot_files import load

__all__ = ["compare_loaders", "LoaderDiff", "Difference", "TOLERANCE"]

TOLERANCE = 1e-8  # relative to the largest entry of the quantity: above it, two loaders differ


@dataclass(frozen=True)
class Difference:
    """One tool against kinedyn on one quantity: the largest difference (relative), where it is
    (a joint or link), and the cause when a known import behaviour explains it."""

    tool: str
    quantity: str
    difference: float
    where: str = ""
    cause: str = ""

    @property
    def agrees(self) -> bool:
        return self.difference <= TOLERANCE

    def __str__(self) -> str:
        if self.agrees:
            return f"{self.tool}: {self.quantity} agrees (relative difference {self.difference:.1e})"
        cause = f": {self.cause}" if self.cause else ""
        return f"{self.tool}: {self.quantity} differs by {self.difference:.3g} (relative) at {self.where}{cause}"


@dataclass
class LoaderDiff:
    """The comparison of one file's loaders: ``rows`` (one :class:`Difference` per tool and
    quantity) and ``skipped`` (tool -> why it was not compared)."""

    source: str
    samples: int
    rows: list = field(default_factory=list)
    skipped: dict = field(default_factory=dict)

    @property
    def agree(self) -> bool:
        return all(r.agrees for r in self.rows)

    def to_dict(self) -> dict:
        return {
            "source": self.source,
            "samples": self.samples,
            "agree": self.agree,
            "rows": [dataclasses.asdict(r) | {"agrees": r.agrees} for r in self.rows],
            "skipped": dict(self.skipped),
        }

    def __str__(self) -> str:
        lines = [f"loaders of {self.source} at {self.samples} sampled configurations:"]
        lines += [f"  {r}" for r in self.rows]
        lines += [f"  {tool}: not compared ({why})" for tool, why in self.skipped.items()]
        return "\n".join(lines)


def compare_loaders(path, samples: int = 4, seed: int = 0) -> LoaderDiff:
    """Load the URDF or MJCF ``path`` with kinedyn, Pinocchio and MuJoCo and compare M(q), g(q) and
    the link frames at ``samples`` seeded configurations (see the module docstring; an MJCF file is
    read by MuJoCo as it is, and by Pinocchio's MJCF reader)."""
    path = os.fspath(path)
    mjcf = os.path.splitext(path)[1].lower() in (".xml", ".mjcf")
    robot = load(path) if mjcf else load(path, mimic="independent")
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(robot.lower_limits), robot.lower_limits, -np.pi)
    hi = np.where(np.isfinite(robot.upper_limits), robot.upper_limits, np.pi)
    Q = [lo + (hi - lo) * rng.random(robot.nq) for _ in range(samples)]
    result = LoaderDiff(path, samples)
    if robot.has_multi_dof_joints:
        result.skipped["all"] = "the file has multi-DOF joints; the diff compares 1-DOF joints"
        return result
    facts = None if mjcf else urdf_facts(path)
    for tool, peer in (("Pinocchio", _pinocchio), ("MuJoCo", _mujoco)):
        try:
            evaluate = peer(path, robot, mjcf)
        except ImportError as e:
            result.skipped[tool] = f"not installed ({e.name})"
            continue
        except Exception as e:  # the peer refuses the file: that is the finding  # noqa: BLE001
            result.skipped[tool] = f"it refuses the file: {' '.join(str(e).split())[:300]}"
            continue
        result.rows += _compare(tool, robot, evaluate, Q, facts)
    return result


# ------------------------------------------------------------------------------- the peers
def _pinocchio(path: str, robot: Robot, mjcf: bool):
    import pinocchio as pin  # type: ignore[import-untyped]  # the peers extra: imported only when the diff runs

    model = pin.buildModelFromMJCF(path) if mjcf else pin.buildModelFromUrdf(path)
    data = model.createData()
    ids = [model.getJointId(name) for name in robot.joint_names]
    if any(i >= model.njoints for i in ids):
        raise ValueError("its joints are not named as kinedyn's")
    vs = [model.joints[i].idx_v for i in ids]

    def evaluate(q):
        qp = pin.neutral(model)
        for i, value in zip(ids, q):
            joint = model.joints[i]
            if joint.nq == 2:  # a continuous joint: (cos, sin)
                qp[joint.idx_q : joint.idx_q + 2] = np.cos(value), np.sin(value)
            else:
                qp[joint.idx_q] = value
        M = pin.crba(model, data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        g = pin.computeGeneralizedGravity(model, data, qp)
        pin.framesForwardKinematics(model, data, qp)
        frames = {}
        for name in robot.frame_names:
            if model.existFrame(name):
                frames[name] = data.oMf[model.getFrameId(name)].homogeneous
        return M[np.ix_(vs, vs)], g[vs], frames

    return evaluate


def _mujoco(path: str, robot: Robot, mjcf: bool):
    import mujoco  # type: ignore[import-untyped]  # the peers extra: imported only when the diff runs

    if mjcf:
        model = mujoco.MjModel.from_xml_path(path)
    else:
        text = open(path, encoding="utf-8").read()
        # MuJoCo cannot resolve package:// paths: the file without its meshes (primitives kept)
        text = re.sub(r"<(visual|collision)\b[^>]*>(?:(?!</\1>).)*?<mesh\b.*?</\1>", "", text, flags=re.S)
        with tempfile.TemporaryDirectory() as folder:
            copy = os.path.join(folder, os.path.basename(path))
            with open(copy, "w", encoding="utf-8") as f:
                f.write(text)
            model = mujoco.MjModel.from_xml_path(copy)
    data = mujoco.MjData(model)
    joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in robot.joint_names]
    if min(joints, default=0) < 0:
        if not mjcf or model.njnt != robot.n:
            raise ValueError("its joints are not named as kinedyn's")
        joints = list(range(model.njnt))  # unnamed MJCF joints: kinedyn keeps MuJoCo's order
    qadr, vadr = [int(model.jnt_qposadr[j]) for j in joints], [int(model.jnt_dofadr[j]) for j in joints]

    def evaluate(q):
        data.qpos[:] = model.qpos0
        data.qpos[qadr] = q
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        M = np.zeros((model.nv, model.nv))
        try:
            mujoco.mj_fullM(model, data, M)  # MuJoCo >= 3.4
        except TypeError:
            mujoco.mj_fullM(model, M, data.qM)
        if not mjcf:
            M -= np.diag(model.dof_armature)  # MuJoCo's URDF import may add armature; URDF has none
        frames = {}
        for name in robot.frame_names:
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
            if b >= 0:
                T = np.eye(4)
                T[:3, :3], T[:3, 3] = data.xmat[b].reshape(3, 3), data.xpos[b]
                frames[name] = T
        return M[np.ix_(vadr, vadr)], data.qfrc_bias[vadr].copy(), frames

    return evaluate


# ------------------------------------------------------------------------------- comparing
def _mass_props(robot: Robot, q_all):
    return [(robot.mass_matrix(q), robot.gravity_torque(q)) for q in q_all]


def _relative(a, b) -> float:
    scale = max(float(np.abs(a).max(initial=0.0)), float(np.abs(b).max(initial=0.0)), 1e-12)
    return float(np.abs(a - b).max(initial=0.0)) / scale


def _compare(tool: str, robot: Robot, evaluate, Q, facts) -> list:
    theirs = [evaluate(q) for q in Q]
    ours = _mass_props(robot, Q)
    rows = []
    if facts is None:  # an MJCF file
        variants = _mjcf_variants(robot) if tool == "Pinocchio" else []
    else:
        variants = _variants(robot, facts, tool) if tool == "MuJoCo" else []
    for k, quantity in enumerate(("M(q)", "g(q)")):
        diffs = [_relative(o[k], t[k]) for o, t in zip(ours, theirs)]
        worst = int(np.argmax(diffs))
        d = diffs[worst]
        where, cause = "", ""
        if d > TOLERANCE:
            E = np.abs(ours[worst][k] - theirs[worst][k])
            j = int(np.unravel_index(np.argmax(E), E.shape)[0])
            where = f"joint '{robot.joint_names[j]}' (q = {np.array2string(Q[worst], precision=3)})"
            for why, variant in variants:
                mine = _mass_props(variant, [Q[worst]])[0][k]
                if _relative(mine, theirs[worst][k]) <= max(TOLERANCE, 1e-3 * d):
                    cause = why
                    break
        rows.append(Difference(tool, quantity, d, where, cause))
    # the frames both know
    worst_frame, largest = "", 0.0
    for q, (_, _, frames) in zip(Q, theirs):
        for name, T in frames.items():
            diff = float(np.abs(robot.pose(q, name) - T).max())
            if diff > largest:
                worst_frame, largest = name, diff
    rows.append(Difference(tool, "frames", largest, f"link '{worst_frame}'" if largest > TOLERANCE else ""))
    return rows


def _variants(robot: Robot, facts, tool: str) -> list:
    """(cause, kinedyn robot imitating it) for MuJoCo's known URDF import behaviours."""
    out = []
    by_name = {f.name: f for f in facts.links}
    links = list(robot.description.links)
    cache: dict = {}
    for k, link in enumerate(links):
        f = by_name.get(link.name)
        if f is None:
            continue
        if not f.has_inertial and f.shapes:
            solids = [solid_of(s, T, cache) for role, s, T, _ in f.shapes if role == "collision"]
            solids = [s for s in solids if isinstance(s, Solid)]
            if solids:
                shape = combined(solids)
                inertia = Inertia(1000.0 * shape.volume, shape.centre, 1000.0 * shape.moments)
                out.append(
                    (
                        f"MuJoCo gives link '{link.name}', which has no <inertial>, the inertia of its collision "
                        f"shapes at 1000 kg/m^3 ({inertia.mass:.4g} kg); kinedyn and Pinocchio read it massless",
                        _with(robot, links, k, inertia),
                    )
                )
        if f.has_inertial and any(abs(a) > 1e-9 for a in f.rpy):
            inertia = Inertia(f.mass, f.com, f.given)
            out.append(
                (
                    f"{tool} ignores the rotation of link '{link.name}''s inertial frame (rpy "
                    f"{' '.join(f'{a:g}' for a in f.rpy)}; mujoco#3559)",
                    _with(robot, links, k, inertia),
                )
            )
    return out


def _mjcf_variants(robot: Robot) -> list:
    """(cause, kinedyn robot imitating it) for Pinocchio's MJCF reader: it keeps its own gravity,
    (0, 0, -9.81), whatever ``<option gravity>`` says."""
    default = (0.0, 0.0, -9.81)
    if tuple(float(g) for g in robot.gravity) == default:
        return []
    return [
        (
            f"Pinocchio's MJCF reader ignores <option gravity> ({' '.join(f'{g:g}' for g in robot.gravity)}) and keeps 0 0 -9.81",
            Robot(dataclasses.replace(robot.description, gravity=default)),
        )
    ]


def _with(robot: Robot, links: list, k: int, inertia: Inertia) -> Robot:
    changed = list(links)
    changed[k] = dataclasses.replace(links[k], inertia=inertia)
    return Robot(dataclasses.replace(robot.description, links=tuple(changed)))
