"""robot_lab's launcher: launch files (XML, YAML, Python) -> one description -> supervisor.

This package is also callable: `robot_lab.launch(pkg_or_path, file=None, **args)` runs
`robot_lab.launch.api.launch`, so the notebook API and the subpackage share one name.
Importing it stays light (no rclpy); api is imported on first call.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robot_lab.launch.api import LaunchHandle

__all__ = ['describe_launch', 'launch_arguments', 'parse_launch_arguments']


class _CallableModule(ModuleType):
    """The module object of robot_lab.launch, made callable for `robot_lab.launch(...)`."""

    def __call__(self, pkg_or_path: str | Path, file: str | None = None,
                 **args: object) -> LaunchHandle:
        api = importlib.import_module('robot_lab.launch.api')  # by name: no import cycle
        handle: LaunchHandle = api.launch(pkg_or_path, file, **args)
        return handle

    def __getattr__(self, name: str) -> object:
        # describe_launch & co. live in resolve.py; load it only when asked for.
        if name in __all__:
            return getattr(importlib.import_module('robot_lab.launch.resolve'), name)
        raise AttributeError(f'module {self.__name__!r} has no attribute {name!r}')


sys.modules[__name__].__class__ = _CallableModule
