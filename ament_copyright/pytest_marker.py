"""The `copyright` pytest marker, as ament_copyright registers it (a pytest11 plugin)."""

from __future__ import annotations

from typing import Any


def pytest_configure(config: Any) -> None:
    config.addinivalue_line(
        'markers',
        'copyright: marks tests checking for a copyright statement in non-empty source files')
