"""``import kinedyn`` and numeric commands do not load the heavy libraries that only symbolic or
visual features use (issue 23, "Start fast"): SymPy (about 0.3 s), SciPy, plotly, trimesh and rich
load when a feature needs them. A test of what is imported, never of time (benches/bench_import.py
measures the time beside ``import pinocchio``). Each check runs in a fresh interpreter."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import kinedyn as kd

HEAVY = ("sympy", "scipy", "plotly", "trimesh", "matplotlib", "pandas", "jinja2", "yaml")


def loaded_after(code: str) -> list[str]:
    """The heavy libraries in sys.modules after ``code`` ran in a fresh interpreter."""
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join([str(Path(kd.__file__).parents[1]), os.environ.get("PYTHONPATH", "")]),
    )
    probe = f"{code}\nimport json, sys\nprint(json.dumps([m for m in {HEAVY + ('rich',)!r} if m in sys.modules]))"
    done = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_import_kinedyn_loads_no_heavy_library():
    assert loaded_after("import kinedyn") == []


def test_numeric_work_on_a_built_in_loads_no_symbolic_or_visual_library():
    code = """
import numpy as np
import kinedyn as kd
robot = kd.robots.get("ur5")
robot.forward_kinematics(np.zeros(robot.n))
robot.jacobian(np.zeros(robot.n))
robot.mass_matrix(np.zeros(robot.n))
"""
    assert loaded_after(code) == []


def test_kinedyn_fk_loads_only_what_it_prints_with():
    # the command line prints its tables with rich; SymPy and the rest stay out
    code = """
import contextlib, io
from kinedyn.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    assert main(["fk", "ur5", "--q", "0.1", "0.2", "0.3", "0", "0", "0"]) == 0
"""
    assert set(loaded_after(code)) <= {"rich"}


def test_symbolic_work_still_loads_sympy_on_first_use():
    code = """
import kinedyn as kd
eom = kd.robots.get("planar_2r", symbolic=True).equations_of_motion()
assert kd.LagrangianSystem.__name__ == "LagrangianSystem"
"""
    assert "sympy" in loaded_after(code)
