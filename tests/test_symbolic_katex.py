"""The LaTeX that Markdown viewers render with KaTeX (GitHub, MkDocs, Jupyter): every $$ block of
``eom.to_markdown()``, every row of the ``eom.to_latex()`` fragment and every $$ block of the
tutorial's Markdown is accepted by KaTeX (markdown-katex bundles a KaTeX command-line build).
KaTeX once rejected 5 of the 35 lines of the planar arm's derivation: step titles with ``r_ci``,
``qd^T``, ``tau_k`` inside ``\\text{}``. The tutorial's names are LaTeX (``J^{-1}``,
``\\frac{\\partial L}{\\partial \\dot{\\theta}_{1}}``), not ``\\text{J\\^{}-1}`` labels."""

from __future__ import annotations

import re

import pytest

import kinedyn as kd
from kinedyn.report import tutorial
from kinedyn.symbolic import examples

katex = pytest.importorskip("markdown_katex.wrapper", reason="markdown-katex (the [test] extra) is not installed")


def _blocks(md: str):
    return [b.strip() for b in re.findall(r"\$\$\n(.*?)\n\$\$", md, re.S)]


def _katex_ok(tex: str) -> bool:
    try:
        html = katex.tex2html(tex, {"display-mode": True})
    except Exception:  # KatexError: KaTeX refused the input
        return False
    return "katex-error" not in html


def _render_all(snippets):
    """Every snippet through KaTeX: all at once (one gathered block; one KaTeX run is ~1 s), and one
    by one only to name the ones it refuses."""
    if _katex_ok("\\begin{gathered}" + " \\\\ ".join(snippets) + "\\end{gathered}"):
        return
    bad = []
    for tex in snippets:
        try:
            html = katex.tex2html(tex, {"display-mode": True})
        except Exception as exc:  # KatexError: KaTeX refused the input
            bad.append((tex[:160], str(exc)[:200]))
            continue
        if "katex-error" in html:
            bad.append((tex[:160], "katex-error element"))
    assert not bad, bad


@pytest.fixture(scope="module")
def planar():
    return kd.robots.planar_2r(symbolic=True).equations_of_motion()


def test_markdown_and_fragment_render_in_katex(planar):
    md_blocks = _blocks(planar.to_markdown())
    rows = [r.rstrip("\\").strip() for r in planar.to_latex().splitlines()[1:-1]]
    assert len(md_blocks) > 20 and len(rows) > 30
    titles = [r for r in rows if r.startswith(r"&\text{")]
    assert len(titles) == len(planar.steps) + 1
    _render_all(
        md_blocks
        + ["\\begin{aligned}" + r + "\\end{aligned}" for r in titles]
        + [planar.to_latex().replace("align*", "aligned")]
    )


def test_mechanism_markdown_renders_in_katex():
    eom = examples.sphere_particle().equations_of_motion()
    _render_all(_blocks(eom.to_markdown()) + [eom.to_latex().replace("align*", "aligned")])


def test_tutorial_markdown_uses_the_books_notation_and_renders():
    md = tutorial.render_markdown(tutorial.work())
    blocks = _blocks(md)
    assert len(blocks) > 20
    joined = "\n".join(blocks)
    for raw in (r"\text{J", r"\^{}", "thetadot", "dL/d", "J^-1"):
        assert raw not in joined, raw
    assert (
        "J^{-1} = " in joined
        and r"\frac{\partial L}{\partial \dot{\theta}_{1}}" in joined
        and r"\dot{\theta}_{1}" in joined
    )
    _render_all(blocks)


def test_tutorial_html_draws_dots_and_stretchy_brackets():
    html = tutorial.render_html(tutorial.work(["1b", "3"]))
    maths = re.findall(r"<math.*?</math>", html, re.S)
    assert maths and not any("thetadot" in m or "<mtext>" in m for m in maths)
    assert sum("<mover" in m for m in maths) > 10 and '<mo stretchy="true">[</mo>' in html
    assert "<msup><mi>J</mi><mrow><mo>-</mo><mn>1</mn></mrow></msup>" in html
