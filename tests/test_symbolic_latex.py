"""LaTeX that a real TeX engine compiles (issue 12 §4): ``kinedyn derive --format latex`` writes a
complete document and ``eom.to_latex()`` an ``align*`` fragment; both go through pdflatex here for
every built-in robot and the seed's mechanisms, and the log must show no error and no line running
into the margin.

The bound on overfull boxes: none wider than ``OVERFULL_PT`` = 1 pt. The page has 2 cm margins; an
equation that pokes 1 pt out is invisible, anything more is a line that does not fit, which the
breaker (kinedyn.symbolic.latex) exists to prevent. Every document compiled here today has none at
all; the 1 pt slack only absorbs TeX's rounding.
"""

from __future__ import annotations

import inspect
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.cli import main
from kinedyn.robots import examples as robot_examples
from kinedyn.symbolic import examples
from kinedyn.symbolic.eom import EquationsOfMotion
from kinedyn.symbolic.latex import equation_rows, expression_lines, latex_text

PDFLATEX = shutil.which("pdflatex")
needs_tex = pytest.mark.skipif(PDFLATEX is None, reason="pdflatex is not installed (CI installs texlive-latex-base)")
OVERFULL_PT = 1.0

FRAGMENT_DOCUMENT = (
    "\\documentclass{article}\n\\usepackage[a4paper,margin=2cm]{geometry}\n\\usepackage{amsmath}\n"
    "\\allowdisplaybreaks\n\\begin{document}\n%s\n\\end{document}\n"
)


def compile_tex(tmp_path: Path, name: str, tex: str) -> str:
    """pdflatex the document; returns the log after asserting a PDF, no error and no overfull line."""
    (tmp_path / f"{name}.tex").write_text(tex)
    run = subprocess.run(
        [PDFLATEX, "-halt-on-error", "-interaction=nonstopmode", f"{name}.tex"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    log = (tmp_path / f"{name}.log").read_text(errors="replace")
    errors = [line for line in log.splitlines() if line.startswith("!")]
    assert run.returncode == 0 and not errors, f"pdflatex failed on {name}: {errors or run.stdout[-2000:]}"
    assert (tmp_path / f"{name}.pdf").stat().st_size > 1000
    over = [float(x) for x in re.findall(r"Overfull \\hbox \(([\d.]+)pt too wide\)", log)]
    assert max(over, default=0.0) <= OVERFULL_PT, f"{name}: lines run into the margin by {sorted(over)[-5:]} pt"
    return log


def _symbolic_builtins():
    return [n for n, f in kd.robots.CATALOGUE.items() if "symbolic" in inspect.signature(f).parameters]


ROBOT_CASES = [(n, False) for n in kd.robots.CATALOGUE] + [(n, True) for n in _symbolic_builtins()]
MECHANISMS = [
    "remotely_driven_arm",
    "five_bar",
    "sphere_particle",
    "falling_particle",
    "simple_variational",
    "geared_link",
    "four_bar_linkage",
]
ROBOT_MECHANISMS = ["remotely_driven_arm_from_robot", "five_bar_from_chains"]  # from Robots: kinedyn.robots.examples


def test_every_builtin_and_mechanism_is_listed():
    """The parametrisations below cover kinedyn's built-in list and every LagrangianSystem example."""
    assert {n for n, _ in ROBOT_CASES} == set(kd.robots.CATALOGUE)
    makers = {
        n
        for n, f in inspect.getmembers(examples, inspect.isfunction)
        if f.__module__ == examples.__name__ and not n.startswith("_")
    }
    assert makers == set(MECHANISMS)
    from_robots = {
        n
        for n, f in inspect.getmembers(robot_examples, inspect.isfunction)
        if f.__module__ == robot_examples.__name__
        and not n.startswith("_")
        and n not in ("geared_link_robot", "five_bar_chains", "five_bar_robot", "four_bar_robot")
    }  # a Robot; two Robots; robots with loops (their LaTeX: tests/test_loops_equations.py)
    assert from_robots == set(ROBOT_MECHANISMS)


@needs_tex
@pytest.mark.parametrize("name,symbolic", ROBOT_CASES, ids=[f"{n}{'-symbolic' if s else ''}" for n, s in ROBOT_CASES])
def test_derive_latex_document_compiles(tmp_path, capsys, name, symbolic):
    out = tmp_path / "eom.tex"
    argv = ["derive", name, "--format", "latex", "-o", str(out)] + (["--symbolic"] if symbolic else [])
    assert main(argv) == 0
    tex = out.read_text()
    assert (
        tex.startswith("\\documentclass") and "\\usepackage{amsmath" in tex and tex.rstrip().endswith("\\end{document}")
    )
    compile_tex(tmp_path, "eom", tex)


@needs_tex
@pytest.mark.parametrize("maker", MECHANISMS + ROBOT_MECHANISMS)
def test_mechanism_document_and_fragment_compile(tmp_path, maker):
    made = getattr(examples if maker in MECHANISMS else robot_examples, maker)()
    eom = made if isinstance(made, EquationsOfMotion) else made.equations_of_motion()
    compile_tex(tmp_path, "doc", eom.to_latex_document())
    fragment = eom.to_latex()
    assert fragment.startswith("\\begin{align*}") and fragment.endswith("\\end{align*}")
    compile_tex(tmp_path, "fragment", FRAGMENT_DOCUMENT % fragment)


@needs_tex
def test_fragment_of_a_robot_compiles(tmp_path):
    eom = kd.robots.elbow_3r(symbolic=True).equations_of_motion()
    compile_tex(tmp_path, "fragment", FRAGMENT_DOCUMENT % eom.to_latex())
    compile_tex(tmp_path, "step", FRAGMENT_DOCUMENT % eom.steps[-1].to_latex())


def test_prose_is_escaped_for_text_mode():
    """Step titles hold ASCII math (r_ci, qd^T, tau_k): in \\text{} an underscore stopped pdflatex with
    "Missing $ inserted". Every special character is escaped; the math words become inline math."""
    s = latex_text("Joint torques tau_k = d/dt dL/dqd_k - dL/dq_k; 50% & #1 ~ {x} \\ planar_2r")
    outside = re.sub(r"\$[^$]*\$", "", s)
    assert not re.search(
        r"(?<!\\)[_^%&#~{}]", outside.replace("\\textasciitilde{}", "").replace("\\textbackslash{}", "")
    ), s
    assert r"\tau_{k}" in s and r"\dot{q}_{k}" in s
    assert latex_text("K = qd^T D(q) qd / 2") == r"$K = \dot{q}^{T} D\left(q\right) \dot{q}$ / 2"


def test_long_sums_are_broken_and_keep_their_value():
    """The breaker splits a long sum between terms and a long factor inside \\Bigl( ... \\Bigr); joined
    back, the lines hold every term once with its sign (nothing dropped or re-signed)."""
    x = sp.symbols("x1:30", real=True)
    a, b = sp.symbols("a b", positive=True)
    long_sum = sum(xi * sp.cos(xi) for xi in x)
    lines = expression_lines(long_sum, 200)
    assert len(lines) > 3 and all(w <= 200 for _, w in lines)
    assert all(t.startswith(("+", "-")) for t, _ in lines[1:])
    joined = " ".join(t for t, _ in lines)
    terms = [sp.latex(t) for t in long_sum.as_ordered_terms()]
    assert joined == " + ".join(terms)
    product = a * b * (long_sum - x[0] ** 2)
    plines = expression_lines(product, 200)
    assert plines[0][0].startswith(r"a b \Bigl(") and plines[-1][0].endswith(r"\Bigr)")
    rows = equation_rows("D(q)", sp.Matrix([[long_sum, 0], [0, a]]), 200)
    assert rows[0].startswith("D_{11}(q) &= ") and any(r.startswith("D_{22}(q) &= a") for r in rows)
    assert "the other entries" in rows[-1]


def test_velocity_symbols_print_with_a_dot_and_stay_identifiers():
    """One notation: eom.M/eom.C printed q̇₁ where they printed qd₁; the symbols' names follow SymPy's
    accent convention (qdot1), so sp.pretty and sp.latex (and kinedyn's MathML) draw the dot while str and the
    generated code keep a plain identifier."""
    from kinedyn.symbolic.system import LagrangianSystem, coordinates

    eom = kd.robots.planar_2r(symbolic=True).equations_of_motion(steps=False)
    v, a = eom.qd[0], eom.qdd[0]
    assert sp.pretty(v) == "q̇₁" and sp.pretty(a) == "q̈₁"
    assert sp.latex(v) == r"\dot{q}_{1}" and sp.latex(a) == r"\ddot{q}_{1}"
    assert str(v).isidentifier() and str(a).isidentifier()
    assert "q̇₁" in sp.pretty(eom.C) and "qd" not in sp.pretty(eom.C)
    from kinedyn.symbolic.render import rate_symbols, value_mathml

    assert "<mover" in value_mathml(eom.C, rate_symbols(eom.q, eom.qd, eom.qdd))
    for language in ("python", "numpy"):
        compile(eom.to_code(language), f"<{language}>", "exec")  # valid Python
    assert "qdot" not in eom.to_code("c").split("*/", 1)[1]  # the C body reads qd[k], never a symbol name
    (x,), (xd,) = coordinates("x")
    assert sp.pretty(xd) in ("ẋ", "x\u0307")  # precomposed or x + combining dot, by SymPy version
    written = LagrangianSystem([x], K="m*x_d**2/2 + m*xdot**2/2")  # the former name still reads as the velocity
    assert written.L.free_symbols & {xd} and sp.expand(written.L - sp.Symbol("m") * xd**2) == 0
