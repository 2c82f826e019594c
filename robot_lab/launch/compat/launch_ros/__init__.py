"""launch_ros (robot_lab's stand-in): Node, PushROSNamespace, FindPackageShare, ..."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.compat_path import unsupported

from . import actions, event_handlers, events, parameter_descriptions, substitutions

__all__ = ['actions', 'event_handlers', 'events', 'parameter_descriptions', 'substitutions']


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros', name, __all__)
