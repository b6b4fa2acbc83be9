"""Converting robots between formats (``kinedyn convert``), each conversion checked.

``convert(robot, path, to=None)`` writes ``robot`` as URDF (``.urdf``), MJCF (``.xml``, ``.mjcf``), a
robot file (``.yaml``, ``.yml``, ``.toml``: :func:`kinedyn.description.files.save`, a DH table when
the robot has one, a tree otherwise) or a DH robot file (``to="dh"``: the DH table
:func:`kinedyn.description.dh.dh_from_robot` finds, written as a YAML/TOML robot file), then reads
the written file back and compares it with the source at random states (:func:`check_conversion`):
the pose of every frame both have, the mass matrix and inverse dynamics. URDF files are read back by
kinedyn's URDF reader (URDF keeps no rotor inertia for it: the source's ``r² J_m`` is added back to
the result's M and tau, and said so); MJCF files by MuJoCo itself (``mj_fullM``, ``qfrc_bias``
against ``C qd + g``, body poses).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .description.dh import dh_from_robot
from .description.files import read_description
from .description.inertia import PhysicalConsistencyWarning

if TYPE_CHECKING:
    from ._typing import PathLike
    from .robot import Robot

__all__ = ["convert", "check_conversion", "Conversion", "FORMATS", "format_of"]

FORMATS = ("urdf", "mjcf", "yaml", "toml", "dh")
_BY_EXTENSION = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf", ".yaml": "yaml", ".yml": "yaml", ".toml": "toml"}


def format_of(path: PathLike, to: str | None = None) -> str:
    """The output format: ``to`` if given, else by the file's extension (ValueError if neither says)."""
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if to is not None:
        if to not in FORMATS:
            raise ValueError(f"unknown output format '{to}' (formats: {', '.join(FORMATS)})")
        if to == "dh" and ext not in (".yaml", ".yml", ".toml"):
            raise ValueError(
                f"a DH table is written as a robot file: '{os.fspath(path)}' must end in .yaml, .yml or .toml"
            )
        if to in ("yaml", "toml") and ext not in (".yaml", ".yml", ".toml"):
            raise ValueError(
                f"a {to} robot file must end in .{to}{' or .yml' if to == 'yaml' else ''}, not '{ext or '(no extension)'}'"
            )
        return to
    if ext not in _BY_EXTENSION:
        raise ValueError(
            f"cannot tell the format of '{os.fspath(path)}' from its extension '{ext}' "
            f"(known: {', '.join(sorted(_BY_EXTENSION))}); give --to {'|'.join(FORMATS)}"
        )
    return _BY_EXTENSION[ext]


@dataclass
class Conversion:
    """What :func:`convert` wrote and what its check found."""

    path: str
    format: str
    joints: int
    robot: str = ""  # the source's name
    checked: bool = False
    states: int = 0
    max_frame_error: float = 0.0  # largest entry of a 4x4 pose difference, over the compared frames
    max_mass_matrix_error: float = 0.0
    max_torque_error: float = 0.0
    frames_compared: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # what the format could not hold, what the check skipped

    @property
    def max_error(self) -> float:
        return max(self.max_frame_error, self.max_mass_matrix_error, self.max_torque_error)

    def summary(self) -> str:
        lines = [
            f"wrote {self.path} ({self.format}, {self.joints} joints){f' from robot {self.robot!r}' if self.robot else ''}"
        ]
        if self.checked:
            lines.append(
                f"checked by reading it back: {len(self.frames_compared)} frames, M and inverse dynamics at {self.states} random states: "
                f"max |FK error| {self.max_frame_error:.2e}, max |M error| {self.max_mass_matrix_error:.2e}, "
                f"max |tau error| {self.max_torque_error:.2e}"
            )
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


def _random_states(robot: Robot, states: int, seed: int):
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(robot.lower_limits), robot.lower_limits, -np.pi)
    hi = np.where(np.isfinite(robot.upper_limits), robot.upper_limits, np.pi)
    for _ in range(states):
        yield rng.uniform(lo, hi), rng.uniform(-1, 1, robot.n), rng.uniform(-1, 1, robot.n)


def convert(
    robot: Robot,
    path: PathLike,
    to: str | None = None,
    *,
    convention: str = "standard",
    check: bool = True,
    states: int = 5,
    seed: int = 0,
) -> Conversion:
    """Write ``robot`` to ``path`` in format ``to`` (default: by extension; see the module docstring)
    and, with ``check``, read it back and compare (:func:`check_conversion`). ``convention``: of the
    DH table for ``to="dh"``."""
    fmt = format_of(path, to)
    path = os.fspath(path)
    notes: list[str] = []
    source = robot
    if fmt == "urdf":
        robot.to_urdf(path)
        if np.any(robot.armature) and not robot.is_symbolic:
            notes.append(
                "URDF has no rotor inertia: gear ratios and rotor inertias are in Drake's <transmission> extension, "
                "which kinedyn's URDF reader does not read (the check adds r^2 J_m back)"
            )
        if not robot.is_symbolic and not np.allclose(np.asarray(robot.gravity, dtype=float), (0.0, 0.0, -9.81)):
            notes.append(f"URDF holds no gravity: give gravity={list(map(float, robot.gravity))} when loading it")
    elif fmt == "mjcf":
        robot.to_mjcf(path)
    elif fmt == "dh":
        found = dh_from_robot(robot, convention)
        found.robot.save(path)
        dh_names = {f"link{i + 1}" for i in range(robot.n)} | {"tool"}
        clashing = [n for n in found.source_frames if n in dh_names]
        if clashing:
            notes.append(
                f"in the DH file, {', '.join(clashing)} are the DH table's own frames (the source's frames of those names are not kept)"
            )
    else:
        robot.save(path)
    result = Conversion(path, "DH " + convention if fmt == "dh" else fmt, source.n, source.name, notes=notes)
    if not check:
        return result
    if source.is_symbolic:
        result.notes.append(f"not checked: the robot has symbolic parameters {sorted(map(str, source.symbols))}")
        return result
    check_conversion(source, path, fmt, result, states=states, seed=seed)
    return result


def check_conversion(
    source: Robot, path: str, fmt: str, result: Conversion, *, states: int = 5, seed: int = 0
) -> Conversion:
    """Read ``path`` back and fill ``result`` with the largest differences from ``source``."""
    if fmt == "mjcf":
        return _check_with_mujoco(source, path, result, states, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicalConsistencyWarning)  # the source's own inertias, warned about already
        read = read_description(path, gravity=source.gravity) if fmt == "urdf" else read_description(path)
    back = source.from_description(read)  # a robot of the source's class (capabilities never import Robot)
    if back.joint_names != source.joint_names:
        raise ValueError(
            f"the written file reads back with joints {back.joint_names}, not the source's {source.joint_names}"
        )
    armature = np.diag(source.armature) if fmt == "urdf" else 0.0
    frames = [n for n in source.frame_names if n in back.frame_names and n != source.base]
    if fmt == "dh":  # DH link frames are the DH table's own, not the source's frames of the same name
        frames = [n for n in frames if not (n == "tool" or (n.startswith("link") and n[4:].isdigit()))]
    result.frames_compared = frames
    for q, qd, qdd in _random_states(source, states, seed):
        e_fk = float(np.abs(source.pose(q) - back.pose(q, back.tool)).max(initial=0.0)) if fmt == "dh" else 0.0
        if frames:
            e_fk = max(
                e_fk, float(np.abs(source.frame_poses(q, frames) - back.frame_poses(q, frames)).max(initial=0.0))
            )
        result.max_frame_error = max(result.max_frame_error, e_fk)
        result.max_mass_matrix_error = max(
            result.max_mass_matrix_error,
            float(np.abs(source.mass_matrix(q) - back.mass_matrix(q) - armature).max(initial=0.0)),
        )
        tau_extra = source.armature * qdd if fmt == "urdf" else 0.0
        result.max_torque_error = max(
            result.max_torque_error,
            float(
                np.abs(source.inverse_dynamics(q, qd, qdd) - back.inverse_dynamics(q, qd, qdd) - tau_extra).max(
                    initial=0.0
                )
            ),
        )
    if fmt == "dh":
        result.frames_compared = ["tool (the source's tool)"] + frames
    result.checked, result.states = True, states
    return result


def _check_with_mujoco(source: Robot, path: str, result: Conversion, states: int, seed: int) -> Conversion:
    import importlib

    try:  # (through importlib: MuJoCo ships no type stubs, and the type checker need not know it)
        mujoco = importlib.import_module("mujoco")
    except ImportError:
        result.notes.append("not checked: MuJoCo is not installed (pip install mujoco)")
        return result
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    if model.nv != source.n or model.nq != source.nq:
        raise ValueError(
            f"MuJoCo reads the written file with nq={model.nq}, nv={model.nv}; the source has nq={source.nq}, nv={source.n}"
        )
    names = [l.name for l in source.links] + [f.name for f in source.frames]
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in names]
    result.frames_compared = names
    M = np.zeros((model.nv, model.nv))
    for q, qd, _ in _random_states(source, states, seed):
        data.qpos[:], data.qvel[:] = q, qd
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, M)
        poses = source.frame_poses(q, names)
        e_fk = max(
            float(np.abs(data.xpos[ids] - poses[:, :3, 3]).max(initial=0.0)),
            float(np.abs(data.xmat[ids].reshape(-1, 3, 3) - poses[:, :3, :3]).max(initial=0.0)),
        )
        result.max_frame_error = max(result.max_frame_error, e_fk)
        result.max_mass_matrix_error = max(
            result.max_mass_matrix_error, float(np.abs(M - source.mass_matrix(q)).max(initial=0.0))
        )
        bias = source.coriolis_matrix(q, qd) @ qd + source.gravity_torque(q)
        result.max_torque_error = max(result.max_torque_error, float(np.abs(data.qfrc_bias - bias).max(initial=0.0)))
    result.notes.append(
        "read back by MuJoCo: M = mj_fullM, and qfrc_bias against C qd + g (MuJoCo keeps friction out of the bias)"
    )
    result.checked, result.states = True, states
    return result
