"""Nothing blocks forever, nothing eats the machine (issue 25).

Every path kinedyn reads, from the command line or named by a file (a robot file, an MJCF
``<include>``, a mesh and the material and images it names, a log), is opened only if it is a regular
file: a FIFO (which would wait for a writer forever), ``/dev/zero`` (endless) or a folder is refused
with a message naming it. Each read runs in a thread with a deadline, so a regression fails the test
instead of hanging it. Sizes are checked before the work: a mesh's declared triangles before it is
parsed, an .npz archive's inflated size from its headers.
"""

from __future__ import annotations

import io
import os
import threading
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

import kinedyn as kd  # noqa: E402
from kinedyn._ui.files import open_regular  # noqa: E402
from kinedyn.analysis.logs import LogError, load_log  # noqa: E402
from kinedyn.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ARM = ROOT / "examples" / "robots" / "tutorial_two_link.yaml"
URDF = ROOT / "examples" / "robots" / "planar_2r.urdf"


def within(seconds, fn, *args, **kwargs):
    """``fn(*args)``'s result or exception, or a failure if it is still running after ``seconds``."""
    box: dict = {}

    def run():
        try:
            box["value"] = fn(*args, **kwargs)
        except BaseException as e:  # noqa: BLE001 - handed to the test
            box["error"] = e

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(seconds)
    if t.is_alive():
        pytest.fail(f"{getattr(fn, '__name__', fn)} still blocked after {seconds} s")
    if "error" in box:
        raise box["error"]
    return box.get("value")


@pytest.fixture
def fifo(tmp_path):
    made = []

    def make(name):
        path = tmp_path / name
        os.mkfifo(path)
        made.append(path)
        return path

    yield make
    for path in made:  # a reader still waiting (a regression) is released by a writer that opens and closes
        try:
            fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
            os.close(fd)
        except OSError:
            pass


def test_open_regular_refuses_fifos_devices_and_folders(tmp_path, fifo):
    f = fifo("pipe.yaml")
    for path, kind in ((f, "FIFO"), ("/dev/zero", "character device"), (tmp_path, "folder")):
        with pytest.raises(ValueError, match=kind):
            within(10, open_regular, path, "robot file")
    (tmp_path / "ok.txt").write_text("fine")
    with within(10, open_regular, tmp_path / "ok.txt") as fh:
        assert fh.read() == b"fine"


@pytest.mark.parametrize("suffix", [".yaml", ".toml", ".urdf", ".xml"])
def test_a_robot_file_that_is_a_fifo(fifo, suffix):
    path = fifo(f"robot{suffix}")
    with pytest.raises(ValueError, match=r"robot\W.*FIFO"):
        within(20, kd.load, path)


def test_the_cli_refuses_a_fifo_robot_with_one_line(capsys, fifo):
    path = fifo("robot.urdf")
    code = within(20, main, ["info", str(path)])
    err = capsys.readouterr().err
    assert code == 1 and len(err.strip().splitlines()) == 1 and "FIFO" in err and str(path) in err


def test_an_mjcf_include_that_is_a_fifo_or_a_device(tmp_path, fifo):
    fifo("parts.xml")
    model = tmp_path / "model.xml"
    model.write_text('<mujoco>\n<include file="parts.xml"/><worldbody/></mujoco>')
    with pytest.raises(ValueError, match=r"model\.xml:2: <include>.*FIFO"):
        within(20, kd.load, model)
    (tmp_path / "sub").mkdir()
    model.write_text('<mujoco><include file="sub"/><worldbody/></mujoco>')
    with pytest.raises(ValueError, match="folder"):
        within(20, kd.load, model)


def _obj(folder: Path, mtl_line: str) -> Path:
    path = folder / "part.obj"
    path.write_text(f"{mtl_line}\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    return path


def test_a_meshs_side_files_that_are_fifos_or_not_materials(tmp_path, fifo):
    from kinedyn.visual.meshes import read_mesh

    fifo("pipe.mtl")
    (tmp_path / "m.mtl").write_text("newmtl red\nKd 1 0 0\nmap_Kd texture.png\n")
    fifo("texture.png")
    for line, words in (
        ("mtllib pipe.mtl", "FIFO"),
        ("mtllib m.mtl", "texture.png' not read"),  # the material is read, its texture (a FIFO) is not
        ("mtllib secret.yaml", "not a material or an image"),
    ):
        (tmp_path / "secret.yaml").write_text("x")
        path = _obj(tmp_path, line)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            parts = within(20, read_mesh, path)
        assert sum(p.triangles for p in parts) == 1  # the mesh is drawn, without what it named
        assert any(words in str(w.message) for w in caught), [str(w.message) for w in caught]
        path.unlink()


def test_a_mesh_that_is_a_fifo_is_a_stick_figure(tmp_path, fifo):
    fifo("link.stl")
    (tmp_path / "arm.urdf").write_text(
        URDF.read_text().replace(
            '<link name="link1">',
            '<link name="link1"><visual><geometry><mesh filename="link.stl"/></geometry></visual>',
        )
    )
    robot = kd.load(tmp_path / "arm.urdf")
    from kinedyn.visual.scene import robot_scene

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = within(20, robot_scene, robot)
    assert scene.drawn == 0 and any("not a regular file" in m and "stick figure" in m for m in scene.missing), (
        scene.missing
    )
    assert caught


def test_a_mesh_declaring_too_many_triangles_is_refused_before_parsing(tmp_path):
    from kinedyn.visual.meshes import MAX_MESH_TRIANGLES, counted_triangles, read_mesh

    stl = tmp_path / "big.stl"  # a binary STL whose header declares 50 M triangles, and holds 1
    stl.write_bytes(b"\0" * 80 + (50_000_000).to_bytes(4, "little") + b"\0" * 50)
    with pytest.raises(ValueError, match="declares 50,000,000 triangles"):
        read_mesh(stl)
    obj = tmp_path / "many.obj"
    obj.write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n" + b"f 1 2 3\n" * (MAX_MESH_TRIANGLES + 1))
    assert counted_triangles(obj.read_bytes(), ".obj") == MAX_MESH_TRIANGLES + 1
    with pytest.raises(ValueError, match="declares"):
        read_mesh(obj)
    ascii_stl = (
        b"solid x\n"
        + b"facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n" * 3
    )
    assert counted_triangles(ascii_stl, ".stl") == 3


def test_a_vertex_at_1e308_is_named_and_the_report_is_written(tmp_path, capsys):
    (tmp_path / "far.obj").write_text("v 0 0 0\nv 1e308 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "arm.urdf").write_text(
        URDF.read_text().replace(
            '<link name="link1">', '<link name="link1"><visual><geometry><mesh filename="far.obj"/></geometry></visual>'
        )
    )
    code = main(
        ["report", str(tmp_path / "arm.urdf"), "-o", str(tmp_path / "r.html"), "--t", "0.01", "--eom-joints", "0"]
    )
    err = capsys.readouterr().err
    assert code == 0, err
    page = (tmp_path / "r.html").read_text()  # the report says which mesh it could not draw, in the page
    assert "far.obj" in page and "1e+308" in page and "stick figure" in page


# ------------------------------------------------------------------ logs
def _log(n=2, rows=200):
    t = np.arange(rows) / 100.0
    return t, np.sin(np.outer(t, np.arange(1, n + 1))), np.cos(np.outer(t, np.arange(1, n + 1)))


def test_logs_that_are_fifos_devices_or_folders(tmp_path, fifo):
    for path, kind in ((fifo("log.csv"), "FIFO"), (Path("/dev/zero"), "character device"), (tmp_path, "folder")):
        with pytest.raises(LogError, match=kind):
            within(20, load_log, path, n=2)


def test_an_npz_bomb_is_refused_from_its_headers(tmp_path, monkeypatch):
    import kinedyn.analysis.logs as logs

    monkeypatch.setattr(logs, "MAX_LOG_BYTES", 2**20)  # the same rule, at a size a test can make
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        buf = io.BytesIO()
        np.save(buf, np.zeros(2**19))  # 4 MiB of zeros, a few KiB compressed
        z.writestr("t.npy", buf.getvalue())
    assert path.stat().st_size < 2**17
    with pytest.raises(LogError, match="inflates to 4 MiB"):
        load_log(path, n=2)


def test_broken_and_strange_logs_name_the_problem(tmp_path):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(LogError, match=r"bad\.npz: not a NumPy \.npz archive"):
        load_log(bad, n=2)
    t, q, tau = _log()
    np.savez(tmp_path / "complex.npz", t=t, q=q + 1j, tau=tau)
    with pytest.raises(LogError, match="array 'q' holds complex128 values"):
        load_log(tmp_path / "complex.npz", n=2)
    np.savez(tmp_path / "text.npz", t=t.astype(str), q=q, tau=tau)
    with pytest.raises(LogError, match="array 't' holds"):
        load_log(tmp_path / "text.npz", n=2)
    rows = "\n".join(",".join(f"{v:.17g}" for v in (t[i], *q[i], *tau[i])) for i in range(len(t)))
    (tmp_path / "bom.csv").write_bytes(b"\xef\xbb\xbft,q1,q2,tau1,tau2\n" + rows.encode())
    assert len(load_log(tmp_path / "bom.csv", n=2, cutoff=10.0)) > 0  # 't' found: the BOM is not in its name
    (tmp_path / "latin.csv").write_bytes(b"t,q1,q2,tau1,tau2\n0,0,0,0,\xe9\n")
    with pytest.raises(LogError, match=r"latin\.csv: line 2: the log is not UTF-8"):
        load_log(tmp_path / "latin.csv", n=2)


def test_a_log_too_short_to_filter_is_named(tmp_path):
    """Found by the fuzz suite's log cases: scipy's padding error named no file."""
    t, q, tau = _log(rows=12)  # more than identification needs (10), fewer than the filter (15)
    rows = "\n".join(",".join(f"{v:.17g}" for v in (t[i], *q[i], *tau[i])) for i in range(len(t)))
    (tmp_path / "short.csv").write_text("t,q1,q2,tau1,tau2\n" + rows + "\n")
    with pytest.raises(LogError, match=r"short\.csv: 12 samples are too few to filter"):
        load_log(tmp_path / "short.csv", n=2, cutoff=10.0, trim=0)


def test_a_line_with_a_different_count_of_values_is_named(tmp_path):
    path = tmp_path / "short.csv"
    path.write_text("t,q1,q2,tau1,tau2\n0,0,0,0,0\n0.01,0,0,0,0\n0.02,1,1,1\n0.03,0,0,0,0\n")
    with pytest.raises(LogError, match=r"short\.csv: line 4: 4 values, where the lines before have 5"):
        load_log(path, n=2)


def test_a_large_yaml_file_is_refused_on_its_size_before_parsing(tmp_path, monkeypatch):
    from kinedyn.description import file_reader, files

    path = tmp_path / "big.yaml"
    path.write_text("joints:\n" + "  - {a: 1}\n" * (file_reader.MAX_TEXT_BYTES // 10 + 1))
    monkeypatch.setattr(files, "parse_yaml", lambda *a: pytest.fail("parsed before the size was checked"))
    with pytest.raises(ValueError, match=r"big\.yaml: the file is larger than 1 MiB"):
        kd.load(path)


@pytest.mark.parametrize(
    "options, words",
    [
        ({"decimate": 0}, "decimate must be a whole number >= 1"),
        ({"decimate": -1}, "decimate must be a whole number >= 1"),
        ({"decimate": 1.5}, "decimate must be a whole number >= 1"),
        ({"trim": -1}, "trim must be a finite number >= 0"),
        ({"trim": float("nan")}, "trim must be a finite number >= 0"),
        ({"cutoff": 0}, "cutoff must be a positive frequency"),
    ],
)
def test_log_settings_are_checked_first(tmp_path, options, words):
    with pytest.raises(LogError, match=words):
        load_log(tmp_path / "never-read.csv", n=2, **options)


def test_a_urdf_over_16_mib_is_refused_without_reading_it_whole(tmp_path):
    from kinedyn.description.urdf import MAX_FILE_BYTES

    path = tmp_path / "big.urdf"
    path.write_bytes(b'<robot name="r">' + b" " * MAX_FILE_BYTES + b"</robot>")
    with pytest.raises(ValueError, match=r"big\.urdf: the file is larger than 16 MiB"):
        kd.load(path)


def test_a_binary_stl_is_read_in_its_own_layout_as_trimesh_reads_it(tmp_path):
    """The NumPy reader of binary STL (a fraction of trimesh's memory) gives trimesh's triangles and
    merged vertices; a length that disagrees with the count goes to trimesh, which refuses it."""
    import trimesh

    from kinedyn.visual.meshes import read_mesh

    rng = np.random.default_rng(3)
    corners = rng.random((40, 3, 3)).astype(np.float32)
    corners[20:] = corners[:20]  # shared corners, to merge
    corners[5, 0] = -0.0
    corners[6, 1] = [0.0, 0.0, 0.0]
    rec = np.zeros(40, dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = corners
    path = tmp_path / "part.stl"
    path.write_bytes(b"\0" * 80 + (40).to_bytes(4, "little") + rec.tobytes())
    (part,) = read_mesh(path)
    m = trimesh.Trimesh(**trimesh.exchange.stl.load_stl(open(path, "rb")), process=True)
    assert len(part.vertices) == len(m.vertices) and len(part.faces) == len(m.faces) == 40
    np.testing.assert_array_equal(part.vertices[part.faces], corners)
    path.write_bytes(path.read_bytes()[:-7])  # a count that disagrees with the length
    with pytest.raises(ValueError, match=r"part\.stl"):
        read_mesh(path)
