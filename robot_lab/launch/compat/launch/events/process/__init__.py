"""launch.events.process: what OnProcessStart/Exit/IO handlers receive."""

from __future__ import annotations

from typing import Any

from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.events import ProcessEvent, ProcessExited, ProcessIO, ProcessStarted

__all__ = ['ProcessExited', 'ProcessIO', 'ProcessStarted', 'RunningProcessEvent']

RunningProcessEvent = ProcessEvent


def __getattr__(name: str) -> Any:
    raise unsupported('launch.events.process', name, __all__)
