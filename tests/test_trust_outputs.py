"""No run loses data (issue 25, "Data").

Every option that writes a file refuses a file the command reads by another name (a hard link or a
symbolic link to the robot file or to a log), compared by device and inode; and every writer writes
atomically (kinedyn._ui.files.replacing: a temporary file beside the destination, fsync, rename), so
a run that fails or is interrupted midway leaves the old file as it was and no temporary file.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
import kinedyn.cli as cli  # noqa: E402
from kinedyn._ui import files  # noqa: E402
from kinedyn.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ARM = ROOT / "examples" / "robots" / "tutorial_two_link.yaml"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def one_line_error(code, err, *words):
    assert code == cli.EXIT_ERROR, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in lines[0], (w, lines[0])


def output_options():
    """(command, flag) of every option that names a file to write, from the parser itself."""
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    return [
        (name, a.option_strings[-1] if a.option_strings else a.metavar)
        for name, p in sub.choices.items()
        for a in p._actions
        if isinstance(a, cli.OutputPath)
    ]


@pytest.fixture
def no_work(monkeypatch):
    """Every command's work replaced by a failure: the refusal must come before the work starts."""
    build = cli.build_parser

    def parser(*args, **kwargs):
        p = build(*args, **kwargs)
        sub = next(a for a in p._actions if a.dest == "command")
        for c in sub.choices.values():
            c.set_defaults(func=lambda args: pytest.fail("the command started its work"))
        return p

    monkeypatch.setattr(cli, "build_parser", parser)


def _links(tmp_path, source: Path, suffix: str):
    """A hard link and a symbolic link to ``source``, and a symbolic link to the hard link, each
    named with ``suffix`` (the extension the writing option expects)."""
    hard = tmp_path / f"hard{suffix}"
    soft = tmp_path / f"soft{suffix}"
    chain = tmp_path / f"chain{suffix}"
    for p in (hard, soft, chain):
        p.unlink(missing_ok=True)
    os.link(source, hard)
    soft.symlink_to(source)
    chain.symlink_to(hard.name)
    return [hard, soft, chain]


SUFFIX = {"--csv": ".csv", "--npz": ".npz", "--plot": ".png", "--animate": ".gif", "--excite": ".csv"}


def test_every_output_refuses_the_robot_file_by_another_name(capsys, tmp_path, no_work):
    robot = tmp_path / "arm.yaml"
    robot.write_bytes(ARM.read_bytes())
    before = robot.read_bytes()
    options = output_options()
    assert {("report", "--output"), ("derive", "--output"), ("simulate", "--csv"), ("convert", "OUT")} <= set(options)
    for command, flag in options:
        for link in _links(tmp_path, robot, SUFFIX.get(flag, ".yaml" if command == "convert" else ".html")):
            argv = [command, robot, *([flag, link] if flag.startswith("-") else [link])]
            code, _, err = run(capsys, *argv)
            one_line_error(code, err, "robot file this command reads", str(link))
            assert robot.read_bytes() == before and not robot.is_symlink()


def test_outputs_refuse_the_logs_the_command_reads(capsys, tmp_path, no_work):
    log = tmp_path / "log.csv"
    log.write_text("t,q1,q2,tau1,tau2\n0,0,0,0,0\n")
    other = tmp_path / "other.csv"
    other.write_bytes(log.read_bytes())
    before = log.read_bytes()
    for data_flag in ("--data", "--validate"):
        extra = ["--data", other] if data_flag == "--validate" else []
        for flag, suffix in (("--plot", ".png"), ("--output", ".html"), ("--excite", ".csv")):
            for link in _links(tmp_path, log, suffix):
                code, _, err = run(capsys, "identify", "planar_2r", *extra, data_flag, log, flag, link)
                one_line_error(code, err, data_flag, str(link))
    assert log.read_bytes() == before


def test_two_outputs_that_are_one_file_by_a_hard_link(capsys, tmp_path, no_work):
    a = tmp_path / "a.csv"
    a.write_text("old")
    os.link(a, tmp_path / "b.npz")
    code, _, err = run(capsys, "simulate", "planar_2r", "--csv", a, "--npz", tmp_path / "b.npz")
    one_line_error(code, err, "--npz", "--csv")


def test_a_real_run_through_a_hard_link_leaves_the_robot_file(capsys, tmp_path):
    """Not only the check: the whole command, run, refuses and the robot file keeps its bytes."""
    robot = tmp_path / "arm.yaml"
    robot.write_bytes(ARM.read_bytes())
    os.link(robot, tmp_path / "eom.txt")
    code, _, err = run(capsys, "derive", robot, "-o", tmp_path / "eom.txt")
    one_line_error(code, err, "-o/--output", "robot file")
    assert robot.read_bytes() == ARM.read_bytes()


# ------------------------------------------------------------------ atomic writes
def _leftovers(folder: Path, keep):
    return sorted(p.name for p in folder.iterdir() if p.name not in keep)


def test_replacing_leaves_the_old_file_when_the_write_fails(tmp_path):
    out = tmp_path / "out.txt"
    out.write_text("the good old content")
    with pytest.raises(RuntimeError, match="midway"):
        with files.replacing(out) as tmp:
            assert tmp.parent == out.parent and tmp.suffix == ".txt" and tmp != out
            tmp.write_text("half of the new")
            raise RuntimeError("midway")
    assert out.read_text() == "the good old content"
    assert _leftovers(tmp_path, {"out.txt"}) == []
    with pytest.raises(KeyboardInterrupt):  # Ctrl-C midway: the same
        with files.replacing(out) as tmp:
            tmp.write_text("half")
            raise KeyboardInterrupt
    assert out.read_text() == "the good old content" and _leftovers(tmp_path, {"out.txt"}) == []


def test_replacing_keeps_mode_links_and_devices(tmp_path):
    out = tmp_path / "out.txt"
    out.write_text("old")
    out.chmod(0o640)
    files.write_text(out, "new")
    assert out.read_text() == "new" and stat.S_IMODE(out.stat().st_mode) == 0o640
    link = tmp_path / "link.txt"
    link.symlink_to(out.name)
    files.write_text(link, "through the link")
    assert link.is_symlink() and out.read_text() == "through the link"
    files.write_text("/dev/null", "nothing")  # a device is written in place, never replaced
    new = tmp_path / "new.txt"
    files.write_text(new, "x")
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(new.stat().st_mode) == 0o666 & ~umask
    assert _leftovers(tmp_path, {"out.txt", "link.txt", "new.txt"}) == []


def _fail_fsync(monkeypatch):
    """Make the flush to disk fail: every byte of the new content is in the temporary file by then."""

    def boom(fd):
        raise OSError(5, "Input/output error (simulated)")

    monkeypatch.setattr(files.os, "fsync", boom)


def test_cli_writers_leave_the_old_file_when_the_write_fails(capsys, tmp_path, monkeypatch):
    old = "the good old content"
    targets = {
        ("derive", "-o"): tmp_path / "eom.txt",
        ("simulate", "--csv"): tmp_path / "s.csv",
        ("simulate", "--npz"): tmp_path / "s.npz",
        ("report", "-o"): tmp_path / "r.html",
    }
    extra = {"simulate": ["--t", "0.02"], "report": ["--t", "0.01", "--eom-joints", "0", "--no-tutorial"]}
    for path in targets.values():
        path.write_text(old)
    _fail_fsync(monkeypatch)
    for (command, flag), path in targets.items():
        code, _, err = run(capsys, command, "planar_2r", *extra.get(command, []), flag, path)
        assert code == cli.EXIT_ERROR and "simulated" in err, err
        assert path.read_text() == old, (command, flag)
    assert _leftovers(tmp_path, {p.name for p in targets.values()}) == []


def test_library_writers_leave_the_old_file_when_the_write_fails(tmp_path, monkeypatch):
    robot = kd.load(ARM)
    traj = kd.simulate(robot, 0.02, np.zeros(2 * robot.n), dt=0.01)
    writers = {
        "r.yaml": lambda p: robot.save(p),
        "r.urdf": lambda p: robot.to_urdf(p),
        "r.xml": lambda p: robot.to_mjcf(p),
        "t.csv": lambda p: traj.to_csv(p),
        "t.npz": lambda p: traj.to_npz(p),
    }
    old = "the good old content"
    for name in writers:
        (tmp_path / name).write_text(old)
    _fail_fsync(monkeypatch)
    for name, write in writers.items():
        with pytest.raises(OSError, match="simulated"):
            write(tmp_path / name)
        assert (tmp_path / name).read_text() == old, name
    assert _leftovers(tmp_path, set(writers)) == []


def test_library_writers_write_whole_files(tmp_path):
    robot = kd.load(ARM)
    robot.save(tmp_path / "r.yaml")
    assert kd.load(tmp_path / "r.yaml").n == robot.n
    traj = kd.simulate(robot, 0.02, np.zeros(2 * robot.n), dt=0.01)
    assert traj.to_npz(tmp_path / "t") == tmp_path / "t.npz"  # NumPy's rule: the name gets .npz
    assert np.allclose(np.load(tmp_path / "t.npz")["q"], traj.q)
    assert traj.to_csv(tmp_path / "t.csv").read_text().startswith("t,")
