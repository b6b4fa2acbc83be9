"""Generated code (kinedyn.codegen, `kinedyn codegen`): the C of every algorithm for one robot,
compiled by the system's C compiler and loaded with ctypes, computes what the core computes."""

from __future__ import annotations

import ctypes
import dataclasses
import shutil
import subprocess

import numpy as np
import pytest

import kinedyn as kd
from kinedyn import cli, codegen


def exact_right_angles(T):
    """A transform with the cos(pi/2) = 6.1e-17 of its right angles made 0 (as the recording takes
    them): then the generated code has the core's numbers to the bit, not only to rounding."""
    if T is None:
        return None
    T = np.array(T, dtype=float)
    T[np.abs(T) < 1e-15] = 0.0
    return T


@pytest.fixture(scope="module")
def robot():
    """The UR5 with drives on every joint (viscous, direction-dependent Coulomb, rotor inertia), so
    that the friction selects and the armature are in the generated code too."""
    ur5 = kd.robots.ur5()
    links = []
    for k, link in enumerate(ur5.links):
        j = link.joint
        if j.is_moving:
            j = dataclasses.replace(
                j, viscous=0.1 * (k + 1), coulomb=0.2, coulomb_negative=0.35, rotor_inertia=2e-5, gear_ratio=50.0
            )
        placement, post = exact_right_angles(link.placement), exact_right_angles(link.post)
        links.append(dataclasses.replace(link, joint=j, placement=placement, post=post))
    return ur5.replace(links=links, dh=None, name="ur5 drives")


@pytest.fixture(scope="module")
def library(robot, tmp_path_factory):
    """Every algorithm of `robot` as C, compiled into a shared library (without contraction, as the
    header asks; unoptimised, which compiles the 13,000 lines several times faster than -O1) and loaded."""
    cc = shutil.which("cc")
    if cc is None:  # a C compiler is present wherever the Rust core builds
        pytest.skip("no C compiler (cc)")
    folder = tmp_path_factory.mktemp("codegen")
    source, lib = folder / "ur5.c", folder / "libur5.so"
    source.write_text(codegen.generate(robot, "all", "c"))
    subprocess.run(
        [cc, "-O0", "-shared", "-fPIC", "-ffp-contract=off", "-o", str(lib), str(source), "-lm"],
        check=True,
        capture_output=True,
    )
    return ctypes.CDLL(str(lib)), source.read_text()


def call(lib, name: str, x: np.ndarray, n_out: int) -> np.ndarray:
    f = getattr(lib, name)
    f.restype = None
    pointer = ctypes.POINTER(ctypes.c_double)
    x = np.ascontiguousarray(x, dtype=float)
    out = np.full(n_out, np.nan)
    f(x.ctypes.data_as(pointer), out.ctypes.data_as(pointer))
    return out


def expected(robot, q, qd, third) -> dict:
    """What the core computes at one state, per algorithm, in the generated functions' layout."""
    dq, dqd, _ = robot.inverse_dynamics_derivatives(q, qd, third)
    fq, fqd, ftau = robot.forward_dynamics_derivatives(q, qd, third)
    return {
        "rnea": robot.inverse_dynamics(q, qd, third),
        "crba": robot.mass_matrix(q).ravel(),
        "minv": robot.mass_matrix_inverse(q).ravel(),
        "aba": robot.forward_dynamics(q, qd, third),
        "gravity": robot.gravity_torque(q),
        "rnea_derivatives": np.concatenate([dq.ravel(), dqd.ravel()]),
        "aba_derivatives": np.concatenate([fq.ravel(), fqd.ravel(), ftau.ravel()]),
    }


def states(robot, count: int):
    rng = np.random.default_rng(3)
    for _ in range(count):
        yield rng.uniform(-3, 3, robot.n), rng.uniform(-2, 2, robot.n), rng.uniform(-2, 2, robot.n)


def inputs(name, q, qd, third):
    return q if name in ("crba", "minv", "gravity") else np.concatenate([q, qd, third])


def test_generated_c_equals_the_core(robot, library):
    """To the bit: the program makes the generic algorithm's operations in its order (folding and the
    rewrites are exact) and the file carries the core's sin_cos, so compiled without contraction the C
    gives the core's numbers exactly (docs/codegen.md promises it)."""
    lib, source = library
    for q, qd, third in states(robot, 3):
        want = expected(robot, q, qd, third)
        assert set(want) == set(codegen.ALGORITHMS)
        for name, w in want.items():
            got = call(lib, f"kinedyn_ur5_drives_{name}", inputs(name, q, qd, third), w.size)
            assert np.array_equal(got, w), (name, np.abs(got - w).max())
    # the header states the layout and the counts; the core's sin_cos is in the file
    assert "in (18): q in[0..6], qd in[6..12], qdd in[12..18]" in source
    assert "static inline void kinedyn_sin_cos" in source and "arithmetic floor" in source


def test_generated_rust_equals_the_core(robot, tmp_path):
    """The Rust module, compiled by rustc into a library with a C-callable wrapper, to the bit too."""
    rustc = shutil.which("rustc")
    if rustc is None:  # present wherever the Rust core builds
        pytest.skip("no Rust compiler (rustc)")
    names = ("rnea", "aba", "gravity")  # trigonometry, divisions and friction selects; ~1 s to compile
    (tmp_path / "arm.rs").write_text(codegen.generate(robot, names, "rust", name="arm"))
    wrappers = "\n".join(
        f'#[no_mangle]\npub unsafe extern "C" fn {a}(x: *const f64, nx: usize, o: *mut f64, no: usize) {{\n'
        f"    arm::kinedyn_arm_{a}(std::slice::from_raw_parts(x, nx), std::slice::from_raw_parts_mut(o, no));\n}}"
        for a in names
    )
    (tmp_path / "lib.rs").write_text(f'#[path = "arm.rs"]\nmod arm;\n{wrappers}\n')
    lib_path = tmp_path / "libarm.so"
    subprocess.run(
        [rustc, "--edition", "2021", "--crate-type", "cdylib", "-C", "opt-level=0", "-o", str(lib_path), "lib.rs"],
        check=True,
        capture_output=True,
        cwd=tmp_path,
    )
    lib = ctypes.CDLL(str(lib_path))
    pointer = ctypes.POINTER(ctypes.c_double)
    for q, qd, third in states(robot, 2):
        want = expected(robot, q, qd, third)
        for name in names:
            x, w = np.ascontiguousarray(inputs(name, q, qd, third)), want[name]
            got = np.full(w.size, np.nan)
            f = getattr(lib, name)
            f.restype = None
            f(x.ctypes.data_as(pointer), ctypes.c_size_t(x.size), got.ctypes.data_as(pointer), ctypes.c_size_t(w.size))
            assert np.array_equal(got, w), (name, np.abs(got - w).max())


def test_generated_code_equals_the_core_to_rounding_on_right_angles(tmp_path):
    """The built-in UR5 as it is, cos(pi/2) = 6.1e-17 in its placements: the recording takes those
    as 0 (fewer operations), so the C equals the core to rounding."""
    cc = shutil.which("cc")
    if cc is None:  # a C compiler is present wherever the Rust core builds
        pytest.skip("no C compiler (cc)")
    ur5 = kd.robots.ur5()
    source, lib_path = tmp_path / "ur5.c", tmp_path / "libur5.so"
    source.write_text(codegen.generate(ur5, "rnea,crba", "c"))
    subprocess.run([cc, "-O0", "-shared", "-fPIC", "-o", str(lib_path), str(source), "-lm"], check=True)
    lib = ctypes.CDLL(str(lib_path))
    for q, qd, third in states(ur5, 3):
        for name, want in (("rnea", ur5.inverse_dynamics(q, qd, third)), ("crba", ur5.mass_matrix(q).ravel())):
            got = call(lib, f"kinedyn_ur5_{name}", inputs(name, q, qd, third), want.size)
            assert np.abs(got - want).max() <= 1e-14 * np.abs(want).max(), name


def test_folding_and_the_pass_shrink_the_programs(robot):
    """The optimised program has fewer operations than the recording, and the UR5's axis-aligned
    structure keeps its RNEA far below a naive count (Featherstone's RNEA is ~200 flops per joint)."""
    for name in ("rnea", "aba"):
        c = codegen.operation_counts(robot, name)
        recorded, optimized = c["recorded"], c["optimized"]
        assert optimized["add_mul"] + optimized["neg"] < recorded["add_mul"] + recorded["neg"], name
        # one sin_cos per joint angle at most (the UR5's last link is symmetric about its axis: its
        # angle does not enter the RNEA at all, and the folding finds that)
        assert 0 < optimized["sincos"] <= robot.n
    assert codegen.operation_counts(robot, "rnea")["optimized"]["add_mul"] < 150 * robot.n


def test_codegen_command(tmp_path, capsys):
    out = tmp_path / "ur5.rs"
    code = cli.main(["codegen", "ur5", "--algorithms", "rnea,gravity", "--lang", "rust", "-o", str(out)])
    assert code == 0
    text = out.read_text()
    assert "pub fn kinedyn_ur5_rnea(input: &[f64], out: &mut [f64])" in text
    assert "pub fn kinedyn_ur5_gravity" in text and "kinedyn_ur5_aba" not in text
    code = cli.main(["codegen", "ur5", "--algorithms", "rnea,nope"])
    err = capsys.readouterr().err
    assert code == cli.EXIT_ERROR and "unknown algorithm 'nope'" in err
