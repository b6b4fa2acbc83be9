"""Terminal tables keep every number whole at 80 columns and when piped (issue 13 §5): rich used to cut
``2.44929e-21`` to ``2.44929…``. The commands run as child processes with their output piped (and
COLUMNS=80, or no COLUMNS at all); the tables are parsed back and compared with the library's numbers."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")

from reference import erd  # noqa: E402

import kinedyn as kd  # noqa: E402
from kinedyn._ui.terminal import NUMBER, fit_table  # noqa: E402


def run_piped(*argv, columns="80") -> str:
    env = {**os.environ, "PYTHONPATH": str(Path(kd.__file__).parents[1])}
    env.pop("COLUMNS", None)
    if columns is not None:
        env["COLUMNS"] = columns
    out = subprocess.run([sys.executable, "-m", "kinedyn", *argv], capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    return out.stdout


def parse_tables(text: str) -> dict:
    """title -> {row label: {column header: cell}} for every rich table in ``text``; the parts of a table
    split into blocks of columns ("<title> (columns a-b of n)") are joined back under <title>."""
    tables: dict = {}
    lines = text.splitlines()
    k = 0
    while k < len(lines):
        if lines[k].startswith("┏") and k > 0:
            title = re.sub(r" \(columns? \d+(-\d+)? of \d+\)$", "", lines[k - 1].strip())
            k += 1
            headers: list = []
            while lines[k].startswith("┃"):
                cells = [c.strip() for c in lines[k].strip("┃").split("┃")]
                headers = cells if not headers else [a + b for a, b in zip(headers, cells)]  # a folded header
                k += 1
            k += 1  # ┡━━ rule
            table = tables.setdefault(title, {})
            while k < len(lines) and lines[k].startswith("│"):
                cells = [c.strip() for c in lines[k].strip("│").split("│")]
                assert len(cells) == len(headers), lines[k]
                table.setdefault(cells[0], {}).update(dict(zip(headers[1:], cells[1:])))
                k += 1
        k += 1
    return tables


def as_matrix(table: dict, rows, cols) -> np.ndarray:
    for row in rows:
        for col in cols:
            cell = table[row][col]
            assert NUMBER.fullmatch(cell) and "…" not in cell, cell
    return np.array([[float(table[row][col]) for col in cols] for row in rows])


@pytest.mark.parametrize("columns", ["80", None])
def test_jacobian_table_keeps_every_digit_at_80_columns(columns):
    """The UR5 URDF's Jacobian at its home pose (-pi/2 at the shoulder and wrist 1) holds round-off values
    like 5.55112e-17 under 19-character joint names: wider than 80 columns."""
    path = erd("ur_description", "urdf", "ur5_robot.urdf")
    robot = kd.Robot.from_urdf(path)
    q = [0.3, -np.pi / 2, 0.5, -np.pi / 2, 0.7, 0.2]
    text = run_piped("jacobian", path, "--q", *map(repr, q), columns=columns)
    assert "…" not in text
    assert all(len(line) <= 80 for line in text.splitlines() if line[:1] in "│┃┏└┡")
    J = as_matrix(parse_tables(text)["Jacobian"], ["vx", "vy", "vz", "wx", "wy", "wz"], robot.joint_names)
    expected = robot.jacobian(q)
    assert np.any((np.abs(expected) > 0) & (np.abs(expected) < 1e-15))  # the tiny values this is about
    np.testing.assert_allclose(J, expected, rtol=5e-6, atol=0)  # 6 significant digits: tiny values too


def test_mass_matrix_with_long_joint_names_splits_into_whole_columns():
    """The UR5 URDF's 19-character joint names make M(q) wider than 80 columns: it is printed in blocks of
    whole columns, each with the row labels, not squeezed (M[5, 0] = 2.41617e-20 was cut to 2.4161…)."""
    path = erd("ur_description", "urdf", "ur5_robot.urdf")
    robot = kd.Robot.from_urdf(path)
    text = run_piped("dynamics", path)
    assert "…" not in text
    assert "(columns 1-" in text
    assert all(len(line) <= 80 for line in text.splitlines() if line[:1] in "│┃┏└┡")
    tables = parse_tables(text)
    M = as_matrix(tables["M(q), mass matrix"], robot.joint_names, robot.joint_names)
    np.testing.assert_allclose(M, robot.mass_matrix(np.zeros(6)), rtol=5e-6, atol=1e-300)


def test_fit_table_splits_only_what_does_not_fit():
    from rich.console import Console
    from rich.table import Table

    c = Console(width=40, file=open(os.devnull, "w"))
    t = Table(title="T")
    t.add_column("")
    for k in range(6):
        t.add_column(f"c{k}", justify="right")
    t.add_row("row", *(f"{v:.6g}" for v in [2.44929e-21, -1.5, 3.0, 1e300, -7.25e-9, 0.0]))
    parts = fit_table(t, 40, c)
    assert [p.title for p in parts] == ["T (columns 1-3 of 6)", "T (columns 4-6 of 6)"]
    with c.capture() as cap:
        for p in parts:
            c.print(p)
    out = cap.get()
    for value in ["2.44929e-21", "-1.5", "1e+300", "-7.25e-09"]:
        assert value in out
    assert all(len(line) <= 40 for line in out.splitlines())
    small = Table()
    small.add_column("")
    small.add_column("x")
    small.add_row("a", "1")
    assert fit_table(small, 40, c) == [small]
