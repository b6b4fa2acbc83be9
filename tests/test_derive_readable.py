"""What `kinedyn derive` and the documents print for a person (issue 23, "Output a person reads"):
right angles a file wrote with a few digits made exact (and said so), joint variables that read as
symbols, the compact (CSE) form for a 6-joint arm with numeric parameters, text without SymPy's
``Matrix([[...]])`` or ``1.0`` factors, one name (M) for the mass matrix, ``lc2`` as one symbol,
long sums wrapped in the report. Every printed form is checked against the numeric core; the
speed of these commands is measured in benches/bench_symbolic.py (--derive-only)."""

from __future__ import annotations

import math
import re
import shutil
import subprocess

import numpy as np
import pytest
import sympy as sp
from reference import UR5, erd

import kinedyn as kd
from kinedyn.cli import main
from kinedyn.description.snap import snap_right_angles, snap_rotation
from kinedyn.report.data import symbolic_equations
from kinedyn.symbolic.cse import evaluate_block
from kinedyn.symbolic.render.latex import sum_pieces
from kinedyn.symbolic.render.text import equation_text, tidy, whole_numbers

#: (roll, pitch, yaw) of the test arm's joints: right angles written with eight or nine digits, one
#: mixed with an arbitrary angle, one at gimbal lock, one with nothing to snap
RPY = [
    ("0 1.570796325 0", [("pitch", math.pi / 2)]),
    ("1.570796325 0 3.14159265", [("roll", math.pi / 2), ("yaw", math.pi)]),
    ("-1.57079633 0.3 0", [("roll", -math.pi / 2)]),
    ("0.4 1.570796325 0.2", [("pitch", math.pi / 2)]),  # locked: only roll - yaw = 0.2 matters, kept
    ("0.3 0.2 0.1", []),
]


def _urdf(tmp_path) -> str:
    links = ['<link name="base"/>']
    joints = []
    parent = "base"
    for k, (rpy, _) in enumerate(RPY, start=1):
        links.append(
            f'<link name="l{k}"><inertial><origin xyz="0.1 0.02 0.03"/><mass value="{1 + k / 2}"/>'
            f'<inertia ixx="0.02" iyy="0.03" izz="0.025" ixy="0.001" ixz="0" iyz="0.002"/></inertial></link>'
        )
        joints.append(
            f'<joint name="arm_joint_{k}" type="revolute"><parent link="{parent}"/><child link="l{k}"/>'
            f'<origin xyz="0.05 0.1 0.3" rpy="{rpy}"/><axis xyz="0 0 1"/>'
            f'<limit lower="-3" upper="3" effort="10" velocity="1"/></joint>'
        )
        parent = f"l{k}"
    path = tmp_path / "arm.urdf"
    path.write_text('<robot name="arm">' + "".join(links + joints) + "</robot>")
    return str(path)


def test_snapping_moves_exactly_the_angles_within_the_tolerance(tmp_path):
    robot = kd.load(_urdf(tmp_path))
    tol = 1e-6
    snapped, moved = snap_right_angles(robot.description, tol)
    want = [(f"joint 'arm_joint_{k}' placement", axis, value) for k, (_, s) in enumerate(RPY, 1) for axis, value in s]
    assert sorted((m.where, m.axis) for m in moved) == sorted((w, a) for w, a, _ in want)
    for m in moved:
        assert m.snapped == pytest.approx(dict(((w, a), v) for w, a, v in want)[(m.where, m.axis)], abs=1e-15)
        assert 1e-10 < m.change <= tol
    for before, after in zip(robot.description.links, snapped.links):
        R0, R1 = np.asarray(before.placement)[:3, :3], np.asarray(after.placement)[:3, :3]
        assert np.max(np.abs(R1 - R0)) <= 3 * tol
        np.testing.assert_allclose(R1 @ R1.T, np.eye(3), atol=1e-15)  # still a rotation
        np.testing.assert_array_equal(np.asarray(after.placement)[:3, 3], np.asarray(before.placement)[:3, 3])
    # the exact right angles give exact zeros and ones (what the symbolic engine reads as integers)
    R = np.asarray(snapped.links[0].placement)[:3, :3]
    np.testing.assert_array_equal(R, [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    assert np.asarray(robot.description.links[0].placement)[0, 0] != 0.0  # the file's: cos(1.570796325)
    # a tolerance below the files' errors moves nothing
    assert snap_right_angles(robot.description, 1e-10)[1] == []
    assert snap_right_angles(robot.description, 0)[1] == []


def test_the_snapped_model_equals_the_files_to_the_tolerance(tmp_path):
    """Mass matrix, gravity and tool pose of the snapped robot against the file's, at random states: they
    differ (the model did change) by no more than the rotation error allows."""
    robot = kd.load(_urdf(tmp_path))
    tol = 1e-6
    snapped = kd.Robot(snap_right_angles(robot.description, tol)[0])
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(5):
        q = rng.uniform(-math.pi, math.pi, robot.n)
        M0, M1 = robot.mass_matrix(q), snapped.mass_matrix(q)
        g0, g1 = robot.gravity_torque(q), snapped.gravity_torque(q)
        T0, T1 = robot.pose(q), snapped.pose(q)
        # each placement's rotation moved by at most 3 tol: a product of five, over lengths of about 0.3 m
        np.testing.assert_allclose(M1, M0, atol=50 * tol * np.max(np.abs(M0)))
        np.testing.assert_allclose(g1, g0, atol=50 * tol * np.max(np.abs(g0)))
        np.testing.assert_allclose(T1, T0, atol=50 * tol)
        worst = max(worst, float(np.max(np.abs(M1 - M0))))
    assert worst > 0.0


def test_snap_rotation_at_gimbal_lock_keeps_the_free_combination():
    """pitch within the tolerance of pi/2: only roll - yaw is defined; an arbitrary one is kept, and the
    result still equals the input to the tolerance."""

    def rot(axis, a):  # URDF's fixed-axis rotations, written out here
        c, s = math.cos(a), math.sin(a)
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        R = np.eye(3)
        R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
        return R

    R = rot(2, 0.25) @ rot(1, math.pi / 2 - 2e-9) @ rot(0, 0.9)
    out, moved = snap_rotation(R, 1e-6)
    assert [a for a, _, _ in moved] == ["pitch"]
    assert np.max(np.abs(out - R)) <= 3e-6
    assert out[2, 0] == -1.0 and out[0, 0] == 0.0 and out[1, 0] == 0.0


def test_derive_of_a_file_with_near_right_angles_prints_no_round_off(capsys, tmp_path):
    """The issue's case: `kinedyn derive ur5_robot.urdf --format latex`; its right angles (1.57079632679)
    gave hundreds of pages of 1e-12 terms and joint symbols such as shoulder_{pan joint}."""
    path = erd(*UR5)
    out = tmp_path / "ur5.tex"
    assert main(["derive", path, "--format", "latex", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    text = out.read_text()
    assert "note:" in err and "multiple of pi/2" in err
    assert "multiple of pi/2" in text  # the document says so too
    equations = "".join(re.findall(r"\\begin\{align\*\}(.*?)\\end\{align\*\}", text, re.S))
    assert equations and not re.search(r"10\^\{-\d+\}|\de-\d", equations), "round-off terms printed"
    assert "shoulder_{" not in text and r"\texttt{shoulder\_pan\_joint}" in text and "q_{1}" in text
    assert len(text) < 100_000
    # what was printed is the file's robot to the tolerance: the CSE blocks against the numeric core
    robot = kd.load(path)
    eom = robot.equations_of_motion(snap_angles=1e-6)
    assert eom.notes and eom.closed_form is not None
    cf = eom.closed_form()
    rng = np.random.default_rng(0)
    for _ in range(2):
        q = rng.uniform(-math.pi, math.pi, robot.n)
        values = dict(zip(eom.q, q))
        M = np.array(evaluate_block(cf["M"], values), dtype=float).reshape(robot.n, robot.n)
        g = np.array(evaluate_block(cf["g"], values), dtype=float)
        np.testing.assert_allclose(M, robot.mass_matrix(q), rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(g, robot.gravity_torque(q), rtol=1e-7, atol=1e-8)
    # without snapping the note is gone
    assert main(["derive", path, "--format", "text", "--snap-angles", "0", "-o", str(tmp_path / "u.txt")]) == 0
    assert "note:" not in capsys.readouterr().err


def _pdflatex(tmp_path, text: str):
    if shutil.which("pdflatex") is None:
        pytest.skip("pdflatex is not installed")
    (tmp_path / "doc.tex").write_text(text)
    run = subprocess.run(
        ["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stdout[-2000:]


def test_numeric_puma_prints_in_the_compact_form_of_general(tmp_path, capsys):
    """`derive puma560 --format latex` (numeric parameters) in CSE form, no larger than twice the
    `--general` document (it was 805 kB against 55 kB), compiling with pdflatex, its blocks equal to the
    numeric core."""
    numeric, general = tmp_path / "n.tex", tmp_path / "g.tex"
    assert main(["derive", "puma560", "--format", "latex", "-o", str(numeric)]) == 0
    assert main(["derive", "puma560", "--format", "latex", "--general", "-o", str(general)]) == 0
    text = numeric.read_text()
    assert len(text) <= 2 * len(general.read_text())
    assert re.search(r"^x_\{\d+\} &= ", text, re.M) or "x_{" in text  # named intermediates
    robot = kd.robots.puma560()
    eom = robot.equations_of_motion()
    assert eom.closed_form is not None
    cf = eom.closed_form()
    q = np.array([0.3, -0.7, 1.1, 0.4, -0.9, 0.2])
    qd = np.array([0.5, -0.2, 0.8, -1.0, 0.3, 0.6])
    values = {**dict(zip(eom.q, q)), **dict(zip(eom.qd, qd))}
    for key, want in (("M", robot.mass_matrix(q)), ("C", robot.coriolis_matrix(q, qd)), ("g", robot.gravity_torque(q))):
        got = np.array(evaluate_block(cf[key], values), dtype=float).reshape(np.shape(want))
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-10)
    _pdflatex(tmp_path, text)


def test_text_output_is_readable_and_equal_in_value():
    eom = kd.robots.planar_2r().equations_of_motion()
    text = str(eom)
    assert "Matrix(" not in text
    assert not re.search(r"(?<![\d.])1\.0\*|1\.00000000000000|(?<![\d.])3\.0\b", text), "float 1.0 / 3.0 printed"
    assert "3*cos(q2) + 3" in text
    assert re.search(r"^M\(q\) = \[", text, re.M) and "D(q)" not in text
    rng = np.random.default_rng(1)
    syms = [*eom.q, *eom.qd, *eom.qdd]
    rates = [*eom.qdd, *eom.qd]
    for step in eom.steps:
        for _, value in step.equations:
            before = sp.Matrix([value]) if not isinstance(value, sp.MatrixBase) else value
            after = tidy(before, rates)
            at = dict(zip(syms, rng.normal(size=len(syms))))
            a = np.array(before.xreplace(at), dtype=float)
            b = np.array(after.xreplace(at), dtype=float)
            np.testing.assert_allclose(b, a, rtol=1e-13, atol=1e-13)


def test_whole_numbers_changes_only_whole_floats():
    x = sp.Symbol("x")
    e = sp.Float(1.0) * sp.cos(x) + sp.Float(2.5) * x - sp.Float(3.0)
    assert whole_numbers(e) == sp.cos(x) + sp.Float(2.5) * x - 3
    assert equation_text("v", sp.Matrix([[sp.Float(1.0) * x, 0], [0, sp.Float(2.0)]])) == ["v = [x  0]", "    [0  2]"]


def test_tutorial_text_has_no_raw_matrices_float_ones_or_minus_separators(capsys):
    assert main(["tutorial", "--question", "1b"]) == 0
    out = capsys.readouterr().out
    assert "Matrix(" not in out and "[[1, 0], [0, 1]]" in out
    assert main(["tutorial", "--question", "challenge"]) == 0
    out = capsys.readouterr().out
    assert "1.0⋅" not in out and "-1.0" not in out.split("Jacobian")[-1].split("det J_v")[0]
    assert main(["tutorial", "--question", "3"]) == 0
    out = capsys.readouterr().out
    steps = [line for line in out.splitlines() if re.match(r"Step \d+: ", line)]
    assert steps and not any(" - " in line.split(": ", 1)[1] and "=" not in line for line in steps)
    assert not any(re.search(r"\) - [A-Z]", line) for line in steps)


def test_one_name_for_the_mass_matrix_and_lc_as_one_symbol(tmp_path):
    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion()
    doc = eom.to_latex_document()
    assert "D(q)" not in doc and "D_{" not in doc and r"M(q)\ddot{q}" in doc and "M(q) &= " in doc
    assert "lc_{" not in doc and "l_{c2}" in doc
    md = eom.to_markdown()
    assert "D(q)" not in md and "l_{c2}" in md
    mathml = eom.to_mathml()
    assert "<mi>lc</mi>" not in mathml and "<mi>c</mi><mn>2</mn>" in mathml
    _pdflatex(tmp_path, doc)


def test_long_sums_wrap_in_the_report():
    """The report's MathML lays a long torque out over several rows (browsers do not break MathML lines),
    and the rows add up to the equation."""
    from kinedyn.report.html import EQUATION_WIDTH

    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion()
    tau1 = eom.tau[0]
    pieces = sum_pieces(tau1, EQUATION_WIDTH)
    assert len(pieces) > 1 and sp.expand(sp.Add(*pieces) - tau1) == 0
    html = eom.equation_mathml("tau_1", tau1, width=EQUATION_WIDTH)
    assert html.count("<mtr>") == len(pieces) and "columnalign" in html
    short = eom.equation_mathml("g", eom.g[1], width=EQUATION_WIDTH)
    assert "<mtr>" not in short


def test_the_report_snaps_and_says_so(tmp_path):
    """The report's equations section derives with the same snapping as `kinedyn derive`, and its note
    says so."""
    robot = kd.load(_urdf(tmp_path))
    eom, note = symbolic_equations(robot, "arm", max_joints=robot.n)
    assert eom.notes and "multiple of pi/2" in note and note.startswith("with this robot's numbers (")
