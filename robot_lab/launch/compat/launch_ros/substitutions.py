"""launch_ros.substitutions: package lookups through robot_lab's ament index."""

from __future__ import annotations

from typing import Any

from robot_lab.launch import substitutions as core
from robot_lab.launch.compat.launch.substitutions import subs

__all__ = ['ExecutableInPackage', 'FindPackagePrefix', 'FindPackageShare']


class FindPackageShare(core.FindPackageShare):
    def __init__(self, package: Any) -> None:
        super().__init__(subs(package))


class FindPackagePrefix(core.FindPackagePrefix):
    def __init__(self, package: Any) -> None:
        super().__init__(subs(package))


class ExecutableInPackage(core.ExecutableInPackage):
    def __init__(self, executable: Any, package: Any) -> None:
        super().__init__(subs(executable), subs(package))
