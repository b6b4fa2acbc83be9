"""Large symbolic models in CSE form (kinedyn.symbolic.cse; issue 12 §5): every printed or generated form
of M, C, g evaluated at random states equals the numeric core (which computes them by its own
Newton-Euler/CRBA code in Rust): the CSE blocks themselves, the text `kinedyn derive` prints, its JSON,
the Python it generates, for the PUMA 560 and the UR5 with general inertias, and the Panda from its URDF.
Speed is measured in benches/bench_symbolic.py, not here."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
import sympy as sp
from reference import PANDA, erd

import kinedyn as kd
from kinedyn.cli import main
from kinedyn.symbolic.cse import closed_form, evaluate_block
from kinedyn.symbolic.lagrange import state_symbols
from kinedyn.symbolic.robot_eom import general_parameters


def _general_values(robot, syms):
    """{M1: m1, MX1: m1 cx1, ...}: the general symbols at the robot's own inertias (about each body origin)."""
    vals = {}
    for body_syms, body in zip(syms, robot.tree.bodies):
        for s, v in zip(body_syms, body.inertia.parameters()):
            vals[s] = float(v)
    return vals


def _numeric(robot, qv, qdv):
    return robot.mass_matrix(qv), robot.coriolis_matrix(qv, qdv), robot.gravity_torque(qv)


def _states(robot, count=3, seed=0):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-math.pi, math.pi, robot.n), rng.normal(size=robot.n)) for _ in range(count)]


@pytest.mark.parametrize("name", ["puma560", "ur5", "stanford"])  # stanford: a prismatic joint
def test_cse_blocks_equal_the_numeric_core_with_general_inertias(name):
    robot = kd.robots.get(name)
    q, qd, qdd = state_symbols(robot)
    syms = general_parameters(robot)
    cf = closed_form(robot, q, qd, qdd, parameters=syms)
    params = _general_values(robot, syms)
    assert params and all(s in params for b in syms for s in b)
    n = robot.n
    for qv, qdv in _states(robot):
        vals = {**params, **dict(zip(q, qv)), **dict(zip(qd, qdv))}
        M = np.array(evaluate_block(cf["M"], vals), dtype=float).reshape(n, n)
        C = np.array(evaluate_block(cf["C"], vals), dtype=float).reshape(n, n)
        g = np.array(evaluate_block(cf["g"], vals), dtype=float)
        Mn, Cn, gn = _numeric(robot, qv, qdv)
        np.testing.assert_allclose(M, Mn, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(C, Cn, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(g, gn, rtol=1e-9, atol=1e-9)
    # CSE form: named intermediate variables x1, x2, ... beside the model's own (C2, S2, WP3x_a2 ...)
    assert any(re.fullmatch(r"x\d+", str(s)) for s, _ in cf["M"].assignments)


def test_cse_form_equals_the_expanded_equations_symbolically_for_a_small_arm():
    """The elbow arm with symbolic parameters: the CSE blocks, substituted back, are the expanded M, C, g."""
    robot = kd.robots.elbow_3r(symbolic=True)
    expanded = robot.equations_of_motion(form="expanded")
    cse = robot.equations_of_motion(form="cse")
    assert expanded.final_equations is None and cse.final_equations is not None
    cf = cse.closed_form()
    rng = np.random.default_rng(3)
    state = list(cse.q) + list(cse.qd)
    for _ in range(2):
        vals = {
            s: float(v) for s, v in zip(state + cse.parameters, rng.uniform(0.3, 1.5, len(state) + len(cse.parameters)))
        }
        for key in ("M", "C", "g"):
            got = np.array(evaluate_block(cf[key], vals), dtype=float)
            want = np.array(getattr(expanded, key).xreplace(vals), dtype=float).ravel()
            np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-12)
    assert [str(s) for s in cse.parameters] == [str(s) for s in expanded.parameters]


def _evaluate_printed(lines, values):
    """Evaluate 'name = expression' lines in order; returns the environment by name."""
    env = {str(k): v for k, v in values.items()}
    for line in lines:
        lhs, rhs = line.split(" = ", 1)
        env[lhs.strip()] = float(
            sp.sympify(rhs, locals={k: sp.Symbol(k) for k in _names(rhs)}).subs(
                {sp.Symbol(k): v for k, v in env.items() if k in rhs}
            )
        )
    return env


def _names(rhs):
    return set(re.findall(r"[A-Za-z_][A-Za-z_0-9]*", rhs)) - {"sin", "cos", "sign"}


def test_derive_text_of_the_puma_with_general_inertias_evaluates_to_the_numeric_core(capsys, tmp_path):
    """`kinedyn derive puma560 --general --method newton_euler`: the printed CSE form (x1 = ..., M11 = ...)
    read back line by line and evaluated equals the numeric core."""
    robot = kd.robots.puma560()
    out = tmp_path / "puma.txt"
    assert main(["derive", "puma560", "--general", "--method", "newton_euler", "-o", str(out)]) == 0
    text = out.read_text()
    start = text.index("Step", text.index("Inertia matrix M(q)") - 40)
    block = text[start : text.index("\nResult:")]
    lines = [ln.strip() for ln in block.splitlines() if ln.startswith("  ") and " = " in ln]
    assert any(re.match(r"x\d+ = ", ln) for ln in lines), "no CSE variables printed"
    q, qd, _ = state_symbols(robot)
    params = _general_values(robot, general_parameters(robot))
    ((qv, qdv),) = _states(robot, 1, seed=5)
    env = _evaluate_printed(lines, {**params, **dict(zip(q, qv)), **dict(zip(qd, qdv))})
    Mn, Cn, gn = _numeric(robot, qv, qdv)
    n = robot.n
    M = np.array([[env.get(f"M{r + 1}{c + 1}", 0.0) for c in range(n)] for r in range(n)])
    C = np.array([[env.get(f"C{r + 1}{c + 1}", 0.0) for c in range(n)] for r in range(n)])
    g = np.array([env.get(f"g{r + 1}", 0.0) for r in range(n)])
    np.testing.assert_allclose(M, Mn, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(C, Cn, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(g, gn, rtol=1e-8, atol=1e-9)
    # the result reads as matrices of those names, printed as a grid (not SymPy's Matrix([[...]]))
    assert re.search(r"^M\(q\) = \[M31 +M32 +M33", text, re.M) and "Matrix(" not in text


@pytest.mark.parametrize("name,method", [("puma560", "newton_euler"), ("ur5", "lagrange")])
def test_derive_generated_python_equals_the_numeric_core(name, method, tmp_path):
    """`kinedyn derive NAME --general --format python`: exec the file, call eom_M/eom_C/eom_g with
    p in eom.parameters order."""
    robot = kd.robots.get(name)
    out = tmp_path / "eom.py"
    assert main(["derive", name, "--general", "--method", method, "--format", "python", "-o", str(out)]) == 0
    ns: dict = {}
    exec(compile(out.read_text(), str(out), "exec"), ns)
    eom = robot.equations_of_motion(method=method, parameters="general", steps=False)
    assert eom.closed_form is not None
    values = {str(k): v for k, v in _general_values(robot, general_parameters(robot)).items()}
    p = [values[str(s)] for s in eom.parameters]
    for qv, qdv in _states(robot, 2, seed=7):
        Mn, Cn, gn = _numeric(robot, qv, qdv)
        np.testing.assert_allclose(np.array(ns["eom_M"](qv, p)), Mn, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(np.array(ns["eom_C"](qv, qdv, p)), Cn, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(np.array(ns["eom_g"](qv, p)), gn, rtol=1e-9, atol=1e-9)


def test_derive_json_in_cse_form_evaluates_to_the_numeric_core(capsys):
    robot = kd.robots.puma560()
    assert main(["derive", "puma560", "--general", "--method", "newton_euler", "--format", "c", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["form"] == "cse"
    q, qd, _ = state_symbols(robot)
    params = _general_values(robot, general_parameters(robot))
    ((qv, qdv),) = _states(robot, 1, seed=11)
    base = {**params, **dict(zip(q, qv)), **dict(zip(qd, qdv))}
    Mn, Cn, gn = _numeric(robot, qv, qdv)
    for key, want in (("M", Mn), ("g", gn), ("C", Cn)):
        env = _evaluate_printed([f"{a} = {b}" for a, b in doc["intermediates"][key]], base)
        flat = [e for row in doc[key] for e in row] if key != "g" else doc[key]
        vals = {sp.Symbol(k): v for k, v in env.items()}
        got = np.array([float(sp.sympify(e, locals={k: sp.Symbol(k) for k in _names(e)}).subs(vals)) for e in flat])
        np.testing.assert_allclose(got, np.ravel(want), rtol=1e-8, atol=1e-9)


def test_symbolic_panda_closed_form_equals_the_numeric_core():
    """The Panda (7 joints, from example-robot-data's URDF, its numeric parameters): closed-form M, C, g."""
    robot = kd.Robot.from_urdf(erd(*PANDA)).lock_joints({"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0})
    assert robot.n == 7
    eom = robot.equations_of_motion(method="newton_euler", steps=False)
    assert eom.closed_form is not None  # large: CSE form chosen automatically
    cf = eom.closed_form()
    for qv, qdv in _states(robot, 3, seed=13):
        vals = {**dict(zip(eom.q, qv)), **dict(zip(eom.qd, qdv))}
        Mn, Cn, gn = _numeric(robot, qv, qdv)
        np.testing.assert_allclose(
            np.array(evaluate_block(cf["M"], vals), dtype=float).reshape(7, 7), Mn, rtol=1e-8, atol=1e-10
        )
        np.testing.assert_allclose(
            np.array(evaluate_block(cf["C"], vals), dtype=float).reshape(7, 7), Cn, rtol=1e-8, atol=1e-10
        )
        np.testing.assert_allclose(np.array(evaluate_block(cf["g"], vals), dtype=float), gn, rtol=1e-8, atol=1e-9)
    # and the compiled code built from the same blocks
    f = eom.compile(what=("M", "g"), backend="numpy")
    qv, _ = _states(robot, 1, seed=17)[0]
    np.testing.assert_allclose(f.M(qv), robot.mass_matrix(qv), rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(f.g(qv), robot.gravity_torque(qv), rtol=1e-8, atol=1e-9)


def test_form_is_checked():
    with pytest.raises(ValueError, match="form must be"):
        kd.robots.planar_2r().equations_of_motion(form="short")
