"""launch_ros.substitutions: package lookups through robot_lab's ament index."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch import substitutions as core
from robot_lab.launch.action import subs
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.substitutions import SomeSubstitutions

__all__ = ['ExecutableInPackage', 'FindPackagePrefix', 'FindPackageShare']


class FindPackagePrefix(core.FindPackagePrefix):
    def __init__(self, package: SomeSubstitutions) -> None:
        super().__init__(subs(package))

    def find(self, package_name: str) -> str:
        """launch_ros's FindPackage.find: the path now, outside any launch context."""
        from robot_lab.pkg.index import package_prefix

        return str(package_prefix(package_name))


class FindPackageShare(core.FindPackageShare):
    def __init__(self, package: SomeSubstitutions) -> None:
        super().__init__(subs(package))

    def find(self, package_name: str) -> str:
        from robot_lab.pkg.index import package_share

        return str(package_share(package_name))


class ExecutableInPackage(core.ExecutableInPackage):
    def __init__(self, executable: SomeSubstitutions, package: SomeSubstitutions) -> None:
        super().__init__(subs(executable), subs(package))


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros.substitutions', name, __all__)
