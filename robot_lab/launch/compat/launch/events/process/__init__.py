"""launch.events.process: what OnProcessStart/Exit/IO handlers receive."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.events import ProcessEvent, ProcessExited, ProcessIO, ProcessStarted

__all__ = ['ProcessExited', 'ProcessIO', 'ProcessStarted', 'RunningProcessEvent']

RunningProcessEvent = ProcessEvent


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch.events.process', name, __all__)
