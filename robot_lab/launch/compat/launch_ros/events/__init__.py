"""launch_ros.events: the lifecycle events."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.compat_path import unsupported

from . import lifecycle

__all__ = ['lifecycle']


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros.events', name, __all__)
