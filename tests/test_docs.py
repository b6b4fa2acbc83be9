"""Every ```python block of README.md and docs/*.md runs (blocks of one page share a namespace,
in order, so a page reads as one session). A block whose first line is `# doctest: skip-run`
is only compiled."""

from __future__ import annotations

import os
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
