"""A real headless Chromium for tests outside tests/browser: Debian's, through Playwright's
`executable_path`, found and started as tests/browser/browser_lab.py does (never a download).
A test that needs it is skipped where there is none."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest
from browser.browser_lab import CHROMIUM_ARGS, chromium, free_port

__all__ = ['free_port', 'headless_chromium']


@contextmanager
def headless_chromium() -> Iterator[Any]:
    """A Playwright browser, closed at the end."""
    executable = chromium()
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:  # pragma: no cover - the test extra installs it
        sync_playwright = None
    if executable is None or sync_playwright is None:
        pytest.skip('needs Debian chromium and playwright (apt-get install -y chromium)')
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        try:
            yield browser
        finally:
            browser.close()
