"""launch.events: the events a launch file can name (Shutdown to emit, the rest to read)."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.events import ExecutionComplete, Shutdown, matches_action

from . import process

__all__ = ['ExecutionComplete', 'Shutdown', 'matches_action', 'process']


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch.events', name, __all__)
