"""MkDocs hook (mkdocs.yml `hooks:`): draw the figures with scripts/docs-figures before MkDocs
collects docs/, so `mkdocs build` and `mkdocs serve` never show a stale or missing figure."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parent / "docs-figures"
_drawn = False


def on_pre_build(config, **kwargs):
    global _drawn
    if _drawn:  # `mkdocs serve` rebuilds when docs/ changes: drawing again would loop
        return
    subprocess.run([sys.executable, str(SCRIPT), str(Path(config["docs_dir"]) / "figures")], check=True)
    _drawn = True
