"""Renderings of the derivation (issue 4, follow-up items 1, 2 and 5): real MathML for both sides of
every equation, readable plain-text names, and the step-by-step Newton-Euler derivation."""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.symbolic import examples

warnings.filterwarnings("ignore", message=".*triangle inequality.*")

M = "{http://www.w3.org/1998/Math/MathML}"


@pytest.fixture(scope="module")
def planar():
    return kd.robots.planar_2r(symbolic=True).equations_of_motion()


@pytest.fixture(scope="module")
def planar_ne():
    return kd.robots.planar_2r(symbolic=True).equations_of_motion(method="newton_euler")


def _check_mathml(eom):
    root = ET.fromstring(eom.to_mathml())  # well-formed XML: one element, no HTML-only entities
    sections = root.findall("section")
    assert len(sections) == len(eom.steps) + 1
    for step, section in zip(eom.steps, sections):
        assert step.title in section.find("h3").text
        assert len(section.findall(f"{M}math")) == len(step.equations)
    assert len(sections[-1].findall(f"{M}math")) == 4  # D, C, g, tau
    for el in root.iter():
        if el.tag.startswith(M):
            assert "\\" not in (el.text or "") and "{" not in (el.text or ""), (
                el.tag,
                el.text,
            )  # no raw LaTeX anywhere
    return root


def test_mathml_is_real_mathml_for_both_sides(planar):
    root = _check_mathml(planar)
    maths = root.findall(f".//{M}math")
    # dL/dqd1: a fraction of partials over q with a dot, not an <mi> holding LaTeX
    lhs = [m.find(f"{M}mrow")[0] for m in maths]
    fracs = [x for x in lhs if x.tag == f"{M}mfrac"]
    assert len(fracs) == 2 * planar.n  # dL/dqd_k and dL/dq_k (d/dt dL/dqd_k is an mrow of two fractions)
    first = fracs[0]
    assert [t.text for t in first.iter(f"{M}mo")][:2] == ["∂", "∂"]
    assert first.find(f".//{M}mover") is not None and first.find(f".//{M}mover/{M}mo").text == "˙"
    # the velocities inside the right-hand sides are dotted too, and sympy's q1 has no stray 'qd'
    assert not [e for e in root.iter(f"{M}mi") if e.text in ("qd", "qdd")]
    assert len(root.findall(f".//{M}mover")) > 20


def test_mathml_of_a_lagrangian_system_and_of_newton_euler(planar_ne):
    _check_mathml(examples.remotely_driven_arm().equations_of_motion())
    _check_mathml(planar_ne)


def test_plain_text_names_are_readable(planar):
    text = str(planar)
    lines = [line.strip() for line in text.splitlines()]
    for k in (1, 2):
        assert any(line.startswith(f"dL/dqdot{k} = ") for line in lines)
        assert any(line.startswith(f"d/dt dL/dqdot{k} = ") for line in lines)
        assert any(line.startswith(f"dL/dq{k} = ") for line in lines)
        assert any(line.startswith(f"J_vc{k} = ") for line in lines) and any(
            line.startswith(f"J_w{k} = ") for line in lines
        )
    assert "dotq" not in text and "ddt" not in text and "mathcal" not in text
    assert any(line.startswith("C(q, qd) = ") for line in lines)
    assert any(line.startswith(("tau = ", "tau[1] = ")) for line in lines)  # a wide vector: entry by entry
    md = planar.to_markdown()
    assert md.count("$$") % 2 == 0
    # a long equation is an aligned block ("lhs &= ...", continued on "&\\quad ..." lines)
    assert re.search(r"\\frac\{d\}\{dt\}\\frac\{\\partial \\mathcal\{L\}\}\{\\partial \\dot\{q\}_\{1\}\} &?= ", md)
    assert re.search(r"\\frac\{\\partial \\mathcal\{L\}\}\{\\partial q_\{2\}\} &?= ", md) and re.search(
        r"C_\{\d+\}\(q, \\dot\{q\}\) &?= |C\(q, \\dot\{q\}\) &?= ", md
    )


def _expand(eom, value):
    """A step's expression with every intermediate variable of the derivation substituted back."""
    env = {}
    for step in eom.steps:
        for lhs, v in step.equations:
            sym = sp.Symbol(lhs.text, real=True)
            if not isinstance(v, sp.MatrixBase):
                env.setdefault(sym, v)
    out = sp.sympify(value)
    for _ in range(60):
        new = out.xreplace(env)
        if new == out:
            return out
        out = new
    raise AssertionError("intermediate variables do not resolve")


def test_newton_euler_steps_show_the_recursion(planar_ne):
    eom = planar_ne
    titles = [s.title for s in eom.steps]
    assert titles[0] == "Grouped inertial parameters"
    for j in (1, 2):
        assert f"Forward recursion, link {j}: w, wd, vd, vdc" in titles
        assert f"Backward recursion, link {j}: f, n, tau" in titles
    names = [lhs.text for s in eom.steps for lhs, _ in s.equations]
    for j in (1, 2):
        for v in (f"w{j}", f"wd{j}", f"vd{j}", f"vdc{j}", f"F{j}", f"N{j}", f"f{j}", f"n{j}", f"tau_{j}"):
            assert v in names, v
    # the torques of the steps, expanded through their intermediate variables, equal eom.tau
    taus = {lhs.text: v for s in eom.steps for lhs, v in s.equations if lhs.text.startswith("tau_")}
    tau = sp.Matrix([_expand(eom, taus[f"tau_{k}"]) for k in (1, 2)])
    assert (tau - eom.tau).applyfunc(lambda e: sp.expand(sp.expand_trig(e))) == sp.zeros(2, 1)


def test_newton_euler_centre_of_mass_acceleration_is_the_textbook_one(planar_ne):
    """vdc_2 (body axes, gravity folded in as vd_0 = -g) rotated to the base equals d^2 r_c2/dt^2 - g of
    the centre of mass written by hand."""
    eom = planar_ne
    q1, q2 = eom.q
    qd1, qd2 = eom.qd
    qdd1, qdd2 = eom.qdd
    l1, lc2, g = sp.symbols("l1 lc2 g", positive=True)
    t = sp.Symbol("t")
    a1, a2 = sp.Function("a1")(t), sp.Function("a2")(t)
    rc2 = sp.Matrix([l1 * sp.cos(a1) + lc2 * sp.cos(a1 + a2), l1 * sp.sin(a1) + lc2 * sp.sin(a1 + a2), 0])
    acc = (
        rc2.diff(t, 2)
        .subs({a1.diff(t, 2): qdd1, a2.diff(t, 2): qdd2})
        .subs({a1.diff(t): qd1, a2.diff(t): qd2})
        .subs({a1: q1, a2: q2})
    )
    expected = acc + sp.Matrix([0, g, 0])  # minus gravity (0, -g, 0)
    vdc = {lhs.text: v for s in eom.steps for lhs, v in s.equations}["vdc2"]
    R = sp.Matrix([[sp.cos(q1 + q2), -sp.sin(q1 + q2), 0], [sp.sin(q1 + q2), sp.cos(q1 + q2), 0], [0, 0, 1]])
    got = R * vdc.applyfunc(lambda e: _expand(eom, e))
    rng = np.random.default_rng(5)
    values = dict(zip([q1, q2, qd1, qd2, qdd1, qdd2, l1, lc2, g], rng.uniform(0.3, 1.5, 9)))
    np.testing.assert_allclose(
        np.array(got.xreplace(values), float), np.array(expected.xreplace(values), float), rtol=1e-12
    )


def test_derive_newton_euler_markdown_shows_the_steps(capsys):
    from kinedyn.cli import main

    assert main(["derive", "planar_2r", "--method", "newton_euler", "--format", "markdown"]) == 0
    out = capsys.readouterr().out
    assert "## Step 1: Forward recursion, link 1" in out and "Backward recursion, link 1" in out
    assert "\\dot{\\omega}_{2} = " in out and "\\dot{v}_{c2} = " in out
