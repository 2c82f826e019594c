"""launch_ros.events: the lifecycle events."""

from __future__ import annotations

from typing import Any

from robot_lab.launch.compat_path import unsupported

from . import lifecycle

__all__ = ['lifecycle']


def __getattr__(name: str) -> Any:
    raise unsupported('launch_ros.events', name, __all__)
