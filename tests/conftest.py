"""Fixtures shared by test files: a headless Chromium for the tests that look at the report as a
browser shows it; and the Hypothesis profile (KINEDYN_HYPOTHESIS=ci in .ci/run: the same examples
on every CI run, so a red CI names a change, not a draw; local runs draw fresh examples, and
scripts/fuzz explores further)."""

from __future__ import annotations

import os
import shutil

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True)
settings.load_profile(os.environ.get("KINEDYN_HYPOTHESIS", "default"))


def chromium_path():
    """The Chromium (or Chrome) on PATH, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.fixture(scope="session")
def browser():
    """One headless Chromium (Playwright) for the session; skips where Playwright or Chromium is missing
    (.ci/run installs both)."""
    sync_api = pytest.importorskip("playwright.sync_api", reason="Playwright (test extra) is not installed")
    exe = chromium_path()
    if exe is None:
        pytest.skip("no Chromium on this machine (.ci/run installs Debian's chromium package where apt can)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(
            executable_path=exe,
            args=[
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
            ],
        )
        yield b
        b.close()
