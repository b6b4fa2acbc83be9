"""Every ```python block of README.md and docs/*.md runs (blocks of one page share a namespace,
in order, so a page reads as one session). A block whose first line is `# doctest: skip-run`
is only compiled."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def blocks(page: Path) -> list:
    return BLOCK.findall(page.read_text()) if page.exists() else []


@pytest.mark.parametrize("page", [p for p in PAGES if blocks(p)], ids=lambda p: p.name)
def test_code_blocks_run(page, tmp_path, monkeypatch):
    pytest.importorskip("kinedyn._core", reason="the native module is not built")
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)  # files written by examples land in a scratch folder
    namespace: dict = {"__name__": "__docs__"}
    for k, code in enumerate(blocks(page)):
        compiled = compile(code, f"{page.name}[block {k + 1}]", "exec")
        if code.startswith("# doctest: skip-run"):
            continue
        exec(compiled, namespace)


INLINE_CALL = re.compile(r"`((?:kd|Inertia)\.[A-Za-z_][\w.]*)\(([^`]*)\)`")


def _inline_calls() -> list:
    # from-pinocchio.md's `Inertia.` is Pinocchio's class, set beside kinedyn's
    return [
        (page.name, m.group(1), m.group(2))
        for page in PAGES
        if page.exists()
        for m in INLINE_CALL.finditer(page.read_text())
        if not (page.name == "from-pinocchio.md" and m.group(1).startswith("Inertia."))
    ]


def test_inline_calls_match_the_signatures():
    """A call written in running text (`Inertia.box(m, a, b, c)`, `kd.load("arm.urdf")`) binds to the
    signature of what it names: the same number of positional arguments and known keywords (a trailing
    `...` stands for more arguments). docs/seed-notes.md once documented Inertia.box(m, a, b, c) for
    Inertia.box(mass, size)."""
    import ast
    import inspect

    import kinedyn as kd

    calls = _inline_calls()
    assert len(calls) >= 10
    bad = []
    for page, name, args in calls:
        parts = name.split(".")
        obj = kd if parts[0] == "kd" else kd.Inertia
        owner = None
        for part in parts[1:]:
            owner, obj = obj, getattr(obj, part)
        fn = obj.__init__ if inspect.isclass(obj) else obj
        sig = inspect.signature(fn)
        if args.strip() == "...":  # "some arguments": nothing to check
            continue
        text = re.sub(r"=\s*(?=[,)\]]|$)", "=...", args)  # `d=,` written as a placeholder
        more = re.search(r",\s*\.\.\.\s*$", text) is not None  # a trailing `...`: "and more"
        if more:
            text = re.sub(r",\s*\.\.\.\s*$", "", text)
        call = ast.parse(f"f({text})", mode="eval").body
        assert isinstance(call, ast.Call)
        positional = list(call.args)
        extra = (
            1
            if (
                inspect.isclass(obj)
                or (inspect.isclass(owner) and inspect.isfunction(inspect.getattr_static(owner, parts[-1])))
            )
            else 0
        )
        try:
            bound = sig.bind_partial if more else sig.bind
            bound(*([None] * (len(positional) + extra)), **{k.arg: None for k in call.keywords if k.arg})
        except TypeError as e:
            bad.append(f"{page}: {name}({args}): {e}")
    assert not bad, "\n".join(bad)
