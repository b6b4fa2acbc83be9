"""Generated Python / NumPy / C code equals the symbolic expressions at random states (issue 4)."""

from __future__ import annotations

import shutil
import warnings

import numpy as np
import pytest

import kinedyn as kd

warnings.filterwarnings("ignore", message=".*triangle inequality.*")
RNG = np.random.default_rng(7)
VALUES = dict(l1=1.3, l2=0.9, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13, g=9.81)


def _reference(eom, what, q, qd, qdd, values):
    sub = {s: values[s.name] for s in eom.parameters if s.name in values}
    sub.update(dict(zip(eom.q, q)))
    sub.update(dict(zip(eom.qd, qd)))
    sub.update(dict(zip(eom.qdd, qdd)))
    m = getattr(eom, what).xreplace(sub)
    arr = np.array(m.evalf(17).tolist(), dtype=float)
    return arr.ravel() if m.shape[1] == 1 else arr


def _call(f, what, q, qd, qdd):
    args = {"M": (q,), "C": (q, qd), "g": (q,), "tau": (q, qd, qdd)}[what]
    return getattr(f, what)(*args)


@pytest.fixture(scope="module")
def planar():
    return kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_compiled_equals_symbolic_single_and_batch(planar, backend):
    if backend == "c" and not shutil.which("cc"):
        pytest.skip("no C compiler")
    f = planar.compile(backend=backend, params=VALUES)
    assert f.backend == backend
    q, qd, qdd = RNG.normal(size=(3, 6, 2))
    for what in ("M", "C", "g", "tau"):
        batch = _call(f, what, q, qd, qdd)
        for k in range(len(q)):
            ref = _reference(planar, what, q[k], qd[k], qdd[k], VALUES)
            np.testing.assert_allclose(_call(f, what, q[k], qd[k], qdd[k]), ref, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(batch[k], ref, rtol=1e-12, atol=1e-12)


def test_parameters_left_symbolic_are_passed_at_call_time(planar):
    names = [s.name for s in planar.parameters]
    f = planar.compile(backend="numpy", p=[VALUES[n] for n in names])
    q, qd, qdd = RNG.normal(size=(3, 2))
    np.testing.assert_allclose(f.tau(q, qd, qdd), _reference(planar, "tau", q, qd, qdd, VALUES), rtol=1e-12)
    with pytest.raises(ValueError, match="still contain the parameters"):
        planar.compile(backend="numpy")


def test_generated_python_source_runs(planar):
    src = planar.to_code("python")
    assert "import math" in src and "def eom_tau(q, qd, qdd, p=())" in src
    ns: dict = {}
    exec(src, ns)
    names = [s.name for s in planar.parameters]
    p = [VALUES[n] for n in names]
    q, qd, qdd = RNG.normal(size=(3, 2))
    np.testing.assert_allclose(ns["eom_tau"](q, qd, qdd, p), _reference(planar, "tau", q, qd, qdd, VALUES), rtol=1e-12)
    np.testing.assert_allclose(np.array(ns["eom_M"](q, p)), _reference(planar, "M", q, qd, qdd, VALUES), rtol=1e-12)
    # common subexpressions were eliminated: cos(q2) is computed once in M
    body = src.split("def eom_M")[1].split("def ")[0]
    assert body.count("math.cos(q[1])") == 1


def test_c_source_is_plain_c(planar):
    src = planar.to_code("c", what=("tau",))
    assert src.startswith("#include <math.h>") and "void eom_tau(" in src and "void eom_tau_batch(long N" in src


def test_newton_euler_program_compiles_to_the_numeric_inverse_dynamics():
    """The PUMA's customised Newton-Euler model as C, against the symbolic Lagrange tau."""
    robot = kd.robots.puma560()
    ne = robot.equations_of_motion(method="newton_euler")
    f = ne.compile(what=("tau",), backend="c" if shutil.which("cc") else "numpy")
    lag = robot.equations_of_motion(steps=False)
    q, qd, qdd = RNG.normal(size=(3, 4, 6))
    out = f.tau(q, qd, qdd)
    for k in range(2):
        sub = {**dict(zip(lag.q, q[k])), **dict(zip(lag.qd, qd[k])), **dict(zip(lag.qdd, qdd[k]))}
        ref = np.array(lag.tau.xreplace(sub).evalf(17), dtype=float).ravel()
        np.testing.assert_allclose(out[k], ref, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(f.tau(q[k], qd[k], qdd[k]), ref, rtol=1e-10, atol=1e-10)


def test_bad_shapes_are_refused(planar):
    f = planar.compile(backend="c" if shutil.which("cc") else "numpy", params=VALUES)
    if f.backend == "c":
        with pytest.raises(ValueError, match="expected arrays of shape"):
            f.M(np.zeros(3))
    with pytest.raises(ValueError, match="language"):
        planar.to_code("fortran")


def _order_from_source(src: str, language: str):
    """(parameter names, joint names) as the generated file states them (module docstring or C comment)."""
    import ast
    import re

    header = ast.get_docstring(ast.parse(src)) if language != "c" else src.split("*/")[0]
    assert header, "the generated file has no header"
    params = re.findall(r"p\[(\d+)\] = (\w+)", header.split("p[k]:")[1])
    assert [int(k) for k, _ in params] == list(range(len(params)))
    joints = re.findall(r"q\[(\d+)\] = (\w+)", header.split("Joint vectors:")[1].split(";")[0])
    return [name for _, name in params], [name for _, name in joints]


@pytest.mark.parametrize("language", ["python", "numpy", "c"])
def test_generated_code_states_the_order_of_p(language):
    """Each generated file says which parameter sits at which index of p (only the C file used to):
    p is built here from that header alone, the code run, and the result compared with the numeric
    core (robot.mass_matrix / gravity_torque / inverse_dynamics of the same arm with numbers)."""
    values = dict(l1=1.3, l2=0.9, lc1=0.6, lc2=0.35, m1=2.0, m2=1.5, I1=0.21, I2=0.13, g=9.81)
    symbolic = kd.robots.planar_2r(symbolic=True)
    eom = symbolic.equations_of_motion(steps=False)
    src = eom.to_code(language)
    names, joints = _order_from_source(src, language)
    assert set(names) <= set(values) and len(names) == 8 and joints == ["q1", "q2"]  # l2 does not enter the dynamics
    # the same header in every function's docstring of the Python files
    if language != "c":
        assert src.count("p[0] = " + names[0]) >= 1 + len(("M", "C", "g", "tau"))
    p = [values[n] for n in names]
    numeric = symbolic.subs(values)
    q, qd, qdd = RNG.normal(size=(3, 2))
    if language == "c":
        # the C header documents the layout the compiled callables also use
        assert names == [s.name for s in eom.parameters]
        f = eom.compile(backend="c" if shutil.which("cc") else "numpy", p=p)
        M, g, tau = f.M(q), f.g(q), f.tau(q, qd, qdd)
    else:
        ns: dict = {}
        exec(src, ns)
        M, g, tau = (
            np.asarray(v, dtype=float) for v in (ns["eom_M"](q, p), ns["eom_g"](q, p), ns["eom_tau"](q, qd, qdd, p))
        )
    np.testing.assert_allclose(M, numeric.mass_matrix(q), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(g, numeric.gravity_torque(q), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(tau, numeric.inverse_dynamics(q, qd, qdd), rtol=1e-10, atol=1e-12)
