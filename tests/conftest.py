"""Fixtures shared by test files: a headless Chromium for the tests that look at the report as a
browser shows it."""

from __future__ import annotations

import shutil

import pytest


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
            args=["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync"],
        )
        yield b
        b.close()
