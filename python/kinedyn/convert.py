"""Converting robots between formats (``kinedyn convert``), each conversion checked.

``convert(robot, path, to=None)`` writes ``robot`` as URDF (``.urdf``), MJCF (``.xml``, ``.mjcf``), a
robot file (``.yaml``, ``.yml``, ``.toml``: :func:`kinedyn.description.files.save`, a DH table when
the robot has one, a tree otherwise) or a DH robot file (``to="dh"``: the DH table
:func:`kinedyn.description.dh.dh_from_robot` finds, written as a YAML/TOML robot file), then reads
the written file back and compares it with the source at random states (:func:`check_conversion`):
the pose of every frame both have, the mass matrix and inverse dynamics. URDF files are read back by
kinedyn's URDF reader (URDF keeps no rotor inertia for it: the source's ``r² J_m`` is added back to
the result's M and tau, and said so); MJCF files by MuJoCo itself (``mj_fullM``, ``qfrc_bias``
against ``C qd + g``, body poses), through the map between MuJoCo's coordinates and the source's
(:func:`mujoco_coordinates`: scalar-first quaternions, a free joint's linear velocity in world axes,
mimic followers kept by MuJoCo and tied by equalities). The states are drawn by the source's
``random_configuration`` (unit quaternions), and the file is written to a temporary file beside
``path`` and renamed only once its check has passed, so a file that failed its check is never left.
"""

from __future__ import annotations

import os
import shutil
import tempfile
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

__all__ = ["convert", "check_conversion", "Conversion", "ConversionError", "FORMATS", "format_of"]

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
    loops_compared: int = 0  # closed loops read back with their kind and both frames' poses compared
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
                f"checked by reading it back: {len(self.frames_compared)} frames, "
                + (f"{self.loops_compared} loop{'s' * (self.loops_compared > 1)}, " if self.loops_compared else "")
                + f"M and inverse dynamics at {self.states} random states: "
                f"max |FK error| {self.max_frame_error:.2e}, max |M error| {self.max_mass_matrix_error:.2e}, "
                f"max |tau error| {self.max_torque_error:.2e}"
            )
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


def _random_states(robot: Robot, states: int, seed: int):
    """Valid states: configurations from the robot's own sampler (unit quaternions, within finite
    limits), velocities and accelerations of nv entries."""
    rng = np.random.default_rng(seed)
    for _ in range(states):
        yield robot.random_configuration(rng), rng.uniform(-1, 1, robot.nv), rng.uniform(-1, 1, robot.nv)


class ConversionError(ValueError):
    """The written file failed its check (``convert(..., tolerance=...)``): nothing was written;
    ``result`` holds the differences found."""

    def __init__(self, message: str, result: Conversion):
        super().__init__(message)
        self.result = result


_EXTENSION = {"urdf": ".urdf", "mjcf": ".xml", "yaml": ".yaml", "toml": ".toml", "dh": ".yaml"}


def _temporary_beside(path: str, fmt: str) -> str:
    """A new empty file for writing ``path``'s content before its check: in the same folder, with
    the same extension (the format's when it has none: readers dispatch on it), so relative mesh paths
    stay right; in the system's
    temporary folder when ``path`` is a device such as /dev/null."""
    folder, name = os.path.split(os.path.abspath(path))
    ext = os.path.splitext(name)[1] or _EXTENSION[fmt]  # /dev/null --to urdf: the reader needs an extension
    regular = not os.path.exists(path) or os.path.isfile(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=ext, dir=folder if regular else None)
    os.close(fd)
    return tmp


def _put_in_place(tmp: str, path: str) -> None:
    if not os.path.exists(path) or os.path.isfile(path):
        os.replace(tmp, path)  # atomic on one file system: readers see the old file or the checked one
    else:  # a device (/dev/null, /dev/stdout): copy the content into it
        with open(tmp, "rb") as src, open(path, "wb") as dst:
            shutil.copyfileobj(src, dst)
        os.remove(tmp)


def convert(
    robot: Robot,
    path: PathLike,
    to: str | None = None,
    *,
    convention: str = "standard",
    check: bool = True,
    states: int = 5,
    seed: int = 0,
    tolerance: float | None = None,
) -> Conversion:
    """Write ``robot`` to ``path`` in format ``to`` (default: by extension; see the module docstring)
    and, with ``check``, read it back and compare (:func:`check_conversion`). ``convention``: of the
    DH table for ``to="dh"``. The file is written beside ``path`` first and moved there only when
    its check ran without error and, with ``tolerance``, found no difference of ``tolerance`` or
    more (else :class:`ConversionError`, and ``path`` is left as it was)."""
    fmt = format_of(path, to)
    path = os.fspath(path)
    tmp = _temporary_beside(path, fmt)
    try:
        result = _write(robot, path, tmp, fmt, convention)
        if check:
            if robot.is_symbolic:
                result.notes.append(f"not checked: the robot has symbolic parameters {sorted(map(str, robot.symbols))}")
            else:
                check_conversion(robot, tmp, fmt, result, states=states, seed=seed)
        if tolerance is not None and result.checked and not result.max_error < tolerance:
            raise ConversionError(
                f"the file written for {path} differs from robot '{robot.name}' by {result.max_error:.3g} "
                f"(more than {tolerance:g}); nothing was written",
                result,
            )
        _put_in_place(tmp, path)
    except BaseException as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        if isinstance(e, ValueError) and not isinstance(e, ConversionError) and path not in str(e):
            raise ValueError(f"{e} (converting to {path}: nothing was written)") from e
        raise
    return result


def _write(robot: Robot, path: str, target: str, fmt: str, convention: str) -> Conversion:
    """Write ``robot`` to the file ``target`` in format ``fmt``; the Conversion names ``path``."""
    notes: list[str] = []
    if fmt == "urdf":
        robot.to_urdf(target)
        if np.any(robot.armature) and not robot.is_symbolic:
            notes.append(
                "URDF has no rotor inertia: gear ratios and rotor inertias are in Drake's <transmission> extension, "
                "which kinedyn's URDF reader does not read (the check adds r^2 J_m back)"
            )
        if not robot.is_symbolic and not np.allclose(np.asarray(robot.gravity, dtype=float), (0.0, 0.0, -9.81)):
            notes.append(f"URDF holds no gravity: give gravity={list(map(float, robot.gravity))} when loading it")
    elif fmt == "mjcf":
        robot.to_mjcf(target)
    elif fmt == "dh":
        found = dh_from_robot(robot, convention)
        found.robot.save(target)
        dh_names = {f"link{i + 1}" for i in range(robot.n)} | {"tool"}
        clashing = [n for n in found.source_frames if n in dh_names]
        if clashing:
            notes.append(
                f"in the DH file, {', '.join(clashing)} are the DH table's own frames (the source's frames of those names are not kept)"
            )
    else:
        robot.save(target)
    return Conversion(path, "DH " + convention if fmt == "dh" else fmt, robot.n, robot.name, notes=notes)


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
    _check_loops(source, back, result, states, seed)
    ours, theirs = source.description.reference_configuration, back.description.reference_configuration
    if ours != theirs:  # the assembly mode (docs/closed-loops.md): every writer but to_mjcf keeps it
        raise ValueError(f"the written file reads back with reference configuration {theirs}, not the source's {ours}")
    result.checked, result.states = True, states
    return result


def _check_loops(source: Robot, back: Robot, result: Conversion, states: int, seed: int) -> None:
    """The written file's loops are the source's: the same names and kinds, and each loop's two
    frames where the source's are at random states (a loop end may read back as a frame of another
    name: to_mjcf puts a site on a link)."""
    ours, theirs = [(lp.name, lp.kind) for lp in source.loops], [(lp.name, lp.kind) for lp in back.loops]
    if ours != theirs:
        raise ValueError(f"the written file reads back with loops {theirs}, not the source's {ours}")
    if not ours:
        return
    for q, _, _ in _random_states(source, states, seed):
        for a, b in zip(source.loops, back.loops):
            error = np.abs(source.frame_poses(q, [a.frame_a, a.frame_b]) - back.frame_poses(q, [b.frame_a, b.frame_b]))
            result.max_frame_error = max(result.max_frame_error, float(error.max()))
    result.loops_compared = len(ours)


def mujoco_coordinates(source: Robot, model) -> tuple | None:
    """How the MuJoCo model ``model`` of a file written by ``to_mjcf`` moves with ``source``:
    ``(qpos, A, a_bias)`` with ``qpos(q)`` MuJoCo's configuration at the source's ``q``,
    ``A(q)`` the (model.nv, source.nv) matrix with ``qvel = A v``, and ``a_bias(q, v)`` = ``dA/dt v``,
    so that the source's ``M = A^T M_mj A`` and ``C v + g = A^T (qfrc_bias + M_mj dA/dt v)``
    (the kinetic energy and the power of a force are the same in both coordinates). None when a
    joint has no such map here (a planar joint, written as two slides and a hinge).

    MuJoCo's conventions (MJCF reference, joint and freejoint): quaternions scalar first
    (w, x, y, z); a free joint's linear velocity in world axes and its angular velocity in the
    body's; a ball joint's angular velocity in the body's (as kinedyn's, docs/conventions.md). A
    mimic follower keeps its coordinate in MuJoCo: the full coordinates are ``q_full = expand(q)``
    and ``v_full = G v`` (kinedyn.description.mimic)."""
    import importlib

    mujoco = importlib.import_module("mujoco")
    mimic = source.description.mimic_map
    joints = [b.joint for b in source.tree.bodies if b.joint.is_moving]
    if any(j.kind == "planar" for j in joints):
        return None
    layout = []  # (kind, full q index, full v index, MuJoCo qpos address, MuJoCo dof address)
    iq = iv = 0
    for j in joints:
        k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j.name)
        if k < 0:
            raise ValueError(f"MuJoCo's model of the written file has no joint '{j.name}'")
        layout.append((j.kind, iq, iv, int(model.jnt_qposadr[k]), int(model.jnt_dofadr[k])))
        iq, iv = iq + j.nq, iv + j.nv
    G = mimic.G if mimic is not None else np.eye(source.nv)

    def full_q(q):
        return mimic.expand_q(np.asarray(q, dtype=float)) if mimic is not None else np.asarray(q, dtype=float)

    def qpos(q):
        qf, out = full_q(q), np.zeros(model.nq)
        for kind, i, _, a, _ in layout:
            if kind in ("revolute", "prismatic"):
                out[a] = qf[i]
            elif kind == "spherical":
                out[a : a + 4] = np.roll(qf[i : i + 4], 1)  # (x, y, z, w) -> (w, x, y, z)
            else:  # floating
                out[a : a + 3] = qf[i : i + 3]
                out[a + 3 : a + 7] = np.roll(qf[i + 3 : i + 7], 1)
        return out

    def rotation(qf, i):  # the free-flyer's rotation from its unit quaternion (x, y, z, w)
        x, y, z, w = qf[i + 3 : i + 7]
        return np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )

    def A(q):
        qf, T = full_q(q), np.zeros((model.nv, G.shape[0]))
        for kind, i, v, _, d in layout:
            n = {"revolute": 1, "prismatic": 1, "spherical": 3, "floating": 6}[kind]
            T[d : d + n, v : v + n] = np.eye(n)
            if kind == "floating":  # linear velocity: body axes (kinedyn) -> world axes (MuJoCo)
                T[d : d + 3, v : v + 3] = rotation(qf, i)
        return T @ G

    def a_bias(q, v):
        qf, vf, out = full_q(q), G @ np.asarray(v, dtype=float), np.zeros(model.nv)
        for kind, i, iv_, _, d in layout:
            if kind == "floating":  # d/dt (R v_lin) at fixed v_lin = R (ω × v_lin), ω in body axes
                out[d : d + 3] = rotation(qf, i) @ np.cross(vf[iv_ + 3 : iv_ + 6], vf[iv_ : iv_ + 3])
        return out

    return qpos, A, a_bias


def _check_with_mujoco(source: Robot, path: str, result: Conversion, states: int, seed: int) -> Conversion:
    import importlib

    try:  # (through importlib: MuJoCo ships no type stubs, and the type checker need not know it)
        mujoco = importlib.import_module("mujoco")
    except ImportError:
        result.notes.append(
            "not checked: MuJoCo is not installed, so the file was not read back "
            "(pip install mujoco, or kinedyn's 'peers' extra, then run the conversion again)"
        )
        return result
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    mimic = source.description.mimic_map
    nq, nv = (mimic.nq_full, mimic.nv_full) if mimic is not None else (source.nq, source.nv)
    if model.nv != nv or model.nq != nq:  # a free joint and a ball have kinedyn's sizes (7, 6 and 4, 3)
        raise ValueError(
            f"MuJoCo reads the written file with nq={model.nq}, nv={model.nv}; the source has nq={nq}, nv={nv}"
            + (" with its mimic followers" if mimic is not None else "")
        )
    maps = mujoco_coordinates(source, model)
    if maps is None:
        result.notes.append("not checked: MuJoCo writes a planar joint as two slides and a hinge (no map here)")
        return result
    qpos, A, a_bias = maps
    # frames written as bodies (a loop end may be a site instead: its loop is compared below)
    names = [
        n
        for n in [l.name for l in source.links] + [f.name for f in source.frames]
        if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) >= 0
    ]
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in names]
    result.frames_compared = names
    M = np.zeros((model.nv, model.nv))
    for q, qd, _ in _random_states(source, states, seed):
        Aq = A(q)
        data.qpos[:], data.qvel[:] = qpos(q), Aq @ qd
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, M)
        poses = source.frame_poses(q, names)
        e_fk = max(
            float(np.abs(data.xpos[ids] - poses[:, :3, 3]).max(initial=0.0)),
            float(np.abs(data.xmat[ids].reshape(-1, 3, 3) - poses[:, :3, :3]).max(initial=0.0)),
        )
        result.max_frame_error = max(result.max_frame_error, e_fk)
        result.max_mass_matrix_error = max(
            result.max_mass_matrix_error, float(np.abs(Aq.T @ M @ Aq - source.mass_matrix(q)).max(initial=0.0))
        )
        bias = source.coriolis_matrix(q, qd) @ qd + source.gravity_torque(q)
        bias_mj = Aq.T @ (data.qfrc_bias + M @ a_bias(q, qd))
        result.max_torque_error = max(result.max_torque_error, float(np.abs(bias_mj - bias).max(initial=0.0)))
    if source.loops:  # kinedyn's MJCF reader reads MuJoCo's equalities as MuJoCo does (tests/test_loops_files.py)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # what MJCF holds that kinedyn does not model: the source had none
            back = source.from_description(read_description(path))
        _check_loops(source, back, result, states, seed)
    if source.description.reference_configuration:
        result.notes.append(
            "the reference configuration (the loops' assembly mode) is not written: kinedyn's MJCF reader keeps no keyframe"
        )
    result.notes.append(
        "read back by MuJoCo: M = mj_fullM, and qfrc_bias against C qd + g (MuJoCo keeps friction out of the bias)"
        + ("; mimic followers compared on the independent coordinates (G^T M G)" if mimic is not None else "")
    )
    result.checked, result.states = True, states
    return result
