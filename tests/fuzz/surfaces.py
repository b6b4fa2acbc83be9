"""Fuzz cases for the surfaces of issue 25: MJCF files and their includes, mesh files and the files
they name, logs, the live viewer's address, and the command line's output paths.

Each kind has a strategy (:func:`surface_cases`) and a runner (:func:`run_surface`) that classifies
the outcome with the worker's classes, plus one of its own: ``data_loss``, an output that overwrote
(or was allowed to be) a file the command reads. Special files are made in the case's folder: a FIFO
(``fifo.xml``, ``fifo.mtl``, ``fifo.csv``), a folder, a regular material ``m.mtl``; a loader that
opens a FIFO blocks, and the harness reports a hang.
"""

from __future__ import annotations

import io
import os
import warnings

import numpy as np
from hypothesis import strategies as st

from .strategies import Case, _short, op_bytes, op_lines, op_replace_number, op_truncate

SURFACE_KINDS = ("mjcf", "mesh", "log", "viewer", "output")

MJCF_SEEDS = {
    "cart_pole": (
        '<mujoco model="cart_pole"><default><joint damping="0.25"/></default><worldbody>\n'
        '<body name="cart"><joint name="slider" type="slide" axis="1 0 0"/><geom type="box" size="0.2 0.1 0.05"/>\n'
        '<body name="pole" pos="0 0 0.05"><joint name="hinge" axis="0 1 0"/>\n'
        '<geom type="capsule" fromto="0 0 0 0 0 0.8" size="0.02" mass="0.3"/></body></body></worldbody></mujoco>\n'
    ),
    "two_link": (
        '<mujoco model="arm"><worldbody><body name="l1" pos="0 0 0.1"><joint name="j1" axis="0 0 1"/>\n'
        '<geom type="cylinder" size="0.03 0.2" pos="0.2 0 0" euler="0 90 0" density="800"/>\n'
        '<body name="l2" pos="0.4 0 0"><joint name="j2" axis="0 0 1" range="-1.5 1.5"/>\n'
        '<inertial pos="0.15 0 0" mass="0.7" diaginertia="0.001 0.004 0.004"/></body></body></worldbody></mujoco>\n'
    ),
}
MJCF_SPECIALS = (
    '<include file="fifo.xml"/>',
    '<include file="folder"/>',
    '<include file="/dev/zero"/>',
    '<include file="../outside.xml"/>',
    '<include file="fuzzcase.xml"/>',
    '<geom type="capsule" fromto="0 0 0 0 0 1" size="1e-300"/>',
    '<geom type="sphere" size="0.1" mass="4e300"/>',
    '<geom type="box" size="1e200 1e200 1e200"/>',
)

OBJ = "mtllib m.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
ASCII_STL = (
    "solid s\n"
    + (
        "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
        "facet normal 0 1 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 1 0 0\nendloop\nendfacet\n"
    )
    + "endsolid s\n"
)


def _binary_stl(count: int | None = None) -> bytes:
    tri = np.array([[0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0]], dtype="<f4").tobytes() + b"\0\0"
    body = tri * 2
    return b"\0" * 80 + (2 if count is None else count).to_bytes(4, "little") + body


def _log_csv(rows: int = 300) -> str:
    t = np.arange(rows) / 100.0
    q = np.c_[np.sin(t), np.cos(2 * t)]
    tau = np.c_[np.cos(t), np.sin(3 * t)]
    lines = ["t,q1,q2,tau1,tau2"] + [",".join(f"{v:.9g}" for v in (t[i], *q[i], *tau[i])) for i in range(rows)]
    return "\n".join(lines) + "\n"


def _log_npz(variant: str) -> bytes:
    t = np.arange(300) / 100.0
    arrays = {"t": t, "q1": np.sin(t), "q2": np.cos(t), "tau1": np.cos(t), "tau2": np.sin(t)}
    if variant == "complex":
        arrays["q1"] = arrays["q1"] + 1j
    elif variant == "strings":
        arrays["t"] = t.astype(str)
    elif variant == "2-d":
        arrays = {"t": t, "q": np.c_[np.sin(t), np.cos(t)], "tau": np.c_[np.cos(t), np.sin(t)]}
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


TEXT_OPS = (op_replace_number, op_replace_number, op_truncate, op_bytes, op_lines)


def _mutate(draw, data, kind: str, ops, count=None):
    done = []
    for _ in range(count if count is not None else draw(st.integers(1, 3), label="mutations")):
        op = draw(st.sampled_from(ops))
        try:
            new, desc = op(draw, data, kind)
        except (TypeError, AttributeError, KeyError, IndexError, ValueError, RecursionError):
            new, desc = data, None
        if desc is not None:
            data = new
            done.append(desc)
    return data, done


def _insert_special(draw, data, kind):
    text = data if isinstance(data, str) else data.decode("utf-8", "replace")
    special = draw(st.sampled_from(MJCF_SPECIALS))
    at = text.find("<worldbody>")
    if at < 0:
        return data, None
    if special.startswith("<geom"):
        at = text.find("</body>")
        if at < 0:
            return data, None
        return text[:at] + special + text[at:], f"inserted {special}"
    return text[:at] + special + text[at:], f"inserted {special}"


@st.composite
def mjcf_cases(draw) -> Case:
    name = draw(st.sampled_from(sorted(MJCF_SEEDS)))
    data, ops = _mutate(draw, MJCF_SEEDS[name], "urdf", TEXT_OPS + (_insert_special, _insert_special))
    return Case(kind="mjcf", seed=name, ops=tuple(ops) or ("unchanged",), data=data, valid=not ops)


def _mtllib(draw, data, kind):
    text = data if isinstance(data, str) else data.decode("utf-8", "replace")
    new = draw(st.sampled_from(("fifo.mtl", "folder", "../m.mtl", "/dev/zero", "secret.yaml", "missing.mtl")))
    return text.replace("mtllib m.mtl", f"mtllib {new}"), f"mtllib -> {new}"


@st.composite
def mesh_cases(draw) -> Case:
    seed = draw(st.sampled_from(("obj", "ascii_stl", "binary_stl", "binary_stl_huge_count")))
    if seed == "obj":
        data, ext = OBJ, ".obj"
        data, ops = _mutate(draw, data, "urdf", TEXT_OPS + (_mtllib, _mtllib))
    elif seed == "ascii_stl":
        data, ops = _mutate(draw, ASCII_STL, "urdf", TEXT_OPS)
        ext = ".stl"
    else:
        count = draw(st.sampled_from((2, 0, 1, 3, 2**31, 2**32 - 1))) if seed == "binary_stl_huge_count" else None
        data, ops = _mutate(draw, _binary_stl(count), "urdf", (op_truncate, op_bytes), count=draw(st.integers(0, 2)))
        ops = ([f"declared count {count}"] if count is not None else []) + ops
        ext = ".stl"
    return Case(kind="mesh", seed=seed, ops=tuple(ops) or ("unchanged",), data=data, call=(ext,), valid=not ops)


@st.composite
def log_cases(draw) -> Case:
    seed = draw(st.sampled_from(("csv", "npz", "npz-2-d", "npz-complex", "npz-strings", "fifo", "folder", "dev-zero")))
    if seed == "csv":
        data, ops = _mutate(draw, _log_csv(), "yaml", TEXT_OPS + (op_bytes,))
        return Case(kind="log", seed=seed, ops=tuple(ops) or ("unchanged",), data=data, call=(".csv",), valid=not ops)
    if seed.startswith("npz"):
        variant = seed[4:] or "plain"
        data, ops = _mutate(draw, _log_npz(variant), "npz", (op_truncate, op_bytes), count=draw(st.integers(0, 2)))
        valid = not ops and variant in ("plain", "2-d")
        return Case(kind="log", seed=seed, ops=tuple(ops) or ("unchanged",), data=data, call=(".npz",), valid=valid)
    return Case(kind="log", seed=seed, ops=(f"the path is a {seed}",), data=b"", call=(seed,))


HOSTS = ("", "0.0.0.0", "::", "127.0.0.1", "localhost", "::1", "8.8.8.8", "no-such-host.invalid", "a" * 300, "x\0y")
HOSTS += ("256.1.1.1", "::ffff:127.0.0.1", "[::1]", "localhost:80", " ", "127.0.0.1 ", "\u2603.example", "-1")
PORTS = (-1, 0, 1, 65535, 65536, 70000, 2**31, 2**64, True, 1.5, "80", None, float("nan"))


@st.composite
def viewer_cases(draw) -> Case:
    host = draw(st.sampled_from(HOSTS + (None, 8080, b"localhost")))
    port = draw(st.sampled_from(PORTS))
    return Case(kind="viewer", seed="listen_address", ops=(f"host={_short(host)} port={port!r}",), call=(host, port))


# (a FIFO as an output is written as Unix tools write one: it waits for its reader, so it is not a case)
OUTPUT_VARIANTS = ("hard", "symlink", "chain", "same", "dotdot", "fresh", "devnull", "folder")


@st.composite
def output_cases(draw) -> Case:
    command = draw(st.sampled_from(("simulate --csv", "simulate --npz", "convert")))
    variant = draw(st.sampled_from(OUTPUT_VARIANTS))
    return Case(
        kind="output", seed=command, ops=(f"{command} -> {variant}",), call=(command, variant), valid=variant == "fresh"
    )


def surface_cases(kind: str):
    return {"mjcf": mjcf_cases, "mesh": mesh_cases, "log": log_cases, "viewer": viewer_cases, "output": output_cases}[
        kind
    ]()


# ============================================================================ running one
def _specials(folder: str) -> None:
    """The FIFOs, folder and regular side files a case may name, made once per folder."""
    for name in ("fifo.xml", "fifo.mtl", "fifo.csv"):
        path = os.path.join(folder, name)
        if not os.path.exists(path):
            os.mkfifo(path)
    os.makedirs(os.path.join(folder, "folder"), exist_ok=True)
    for name, text in (("m.mtl", "newmtl red\nKd 1 0 0\n"), ("secret.yaml", "x: 1\n")):
        with open(os.path.join(folder, name), "w") as f:
            f.write(text)


def _write(folder: str, name: str, data) -> str:
    path = os.path.join(folder, name)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode("utf-8", "surrogatepass"))
    return path


def run_surface(case: Case, folder: str):
    from . import worker

    _specials(folder)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return {
                "mjcf": _run_mjcf,
                "mesh": _run_mesh,
                "log": _run_log,
                "viewer": _run_viewer,
                "output": _run_output,
            }[case.kind](case, folder, worker)
    except MemoryError as e:
        return worker.MEMORY, worker._describe(e)


def _named(e, name: str, w):
    return (w.CLEAN if name in str(e) else w.NO_FILENAME), w._describe(e)


def _run_mjcf(case, folder, w):
    return w.run_file(Case(kind="mjcf", seed=case.seed, ops=case.ops, data=case.data), folder)


def _run_mesh(case, folder, w):
    from kinedyn.visual.meshes import read_mesh

    path = _write(folder, w.FILE_NAME + case.call[0], case.data)
    try:
        parts = read_mesh(path)
    except ValueError as e:
        return _named(e, w.FILE_NAME, w)
    except BaseException as e:
        return w.BAD_EXCEPTION, w._describe(e)
    if not all(np.all(np.isfinite(p.vertices)) for p in parts):
        return w.NONFINITE, "a mesh with non-finite vertices was read"
    return w.SUCCESS, f"{sum(p.triangles for p in parts)} triangles"


def _run_log(case, folder, w):
    from kinedyn.analysis.logs import load_log

    what = case.call[0]
    if what == "fifo":
        path, name = os.path.join(folder, "fifo.csv"), "fifo.csv"
    elif what == "folder":
        path, name = os.path.join(folder, "folder"), "folder"
    elif what == "dev-zero":
        path, name = "/dev/zero", "/dev/zero"
    else:
        path, name = _write(folder, w.FILE_NAME + what, case.data), w.FILE_NAME
    try:
        log = load_log(path, n=2)
    except ValueError as e:
        return _named(e, name, w)
    except BaseException as e:
        return w.BAD_EXCEPTION, w._describe(e)
    arrays = (log.t, log.q, log.qd, log.qdd, log.tau)
    if not all(np.all(np.isfinite(a)) for a in arrays):
        return w.NONFINITE, "a log with non-finite samples was accepted"
    return w.SUCCESS, f"{len(log)} samples"


def _run_viewer(case, folder, w):
    from kinedyn.visual.serving import listen_address

    host, port = case.call
    try:
        address = listen_address(host, port)
    except ValueError as e:
        return w.CLEAN, w._describe(e)
    except BaseException as e:
        return w.BAD_EXCEPTION, w._describe(e)
    if "http://:" in address.url:
        return w.BAD_INPUT_ACCEPTED, f"a URL without a host: {address.url}"
    return w.SUCCESS, address.url


ROBOT_YAML = "name: fuzz_arm\nconvention: standard\njoints:\n  - {a: 1.0, mass: 1}\n  - {a: 0.8, mass: 0.5}\n"


def _run_output(case, folder, w):
    import contextlib

    from kinedyn.cli import main

    command, variant = case.call
    here = os.path.join(folder, f"out-{case.index}-{os.getpid()}")
    os.makedirs(here, exist_ok=True)
    robot = _write(here, "robot.yaml", ROBOT_YAML)
    ext = {"simulate --csv": ".csv", "simulate --npz": ".npz", "convert": ".yaml"}[command]
    out = os.path.join(here, f"out{ext}")
    for p in (out,):
        if os.path.lexists(p):
            os.remove(p)
    if variant == "hard":
        os.link(robot, out)
    elif variant == "symlink":
        os.symlink(robot, out)
    elif variant == "chain":
        os.link(robot, os.path.join(here, "h.yaml"))
        os.symlink("h.yaml", out)
    elif variant == "same":
        out = robot
    elif variant == "dotdot":
        out = os.path.join(here, "..", os.path.basename(here), "robot.yaml")
    elif variant == "devnull":
        out = "/dev/null"
    elif variant == "folder":
        out = os.path.join(folder, "folder")
    argv = {
        "simulate --csv": ["simulate", robot, "--t", "0.01", "--csv", out],
        "simulate --npz": ["simulate", robot, "--t", "0.01", "--npz", out],
        "convert": ["convert", robot, out, "--no-check"],
    }[command]
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
        code = main(argv)
    with open(robot) as f:
        intact = f.read() == ROBOT_YAML
    if not intact:
        return w.DATA_LOSS, f"the robot file was overwritten (exit {code}): {sink.getvalue()[-300:]}"
    alias = variant in ("hard", "symlink", "chain", "same", "dotdot")
    if alias and code != 1:
        return w.DATA_LOSS, f"an output that is the robot file was accepted (exit {code})"
    if code not in (0, 1):
        return w.BAD_EXCEPTION, f"exit {code}: {sink.getvalue()[-300:]}"
    return (w.SUCCESS if code == 0 else w.CLEAN), sink.getvalue().strip()[-200:]
