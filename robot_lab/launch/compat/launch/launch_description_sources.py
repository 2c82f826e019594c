"""launch.launch_description_sources: where an IncludeLaunchDescription reads its file."""

from __future__ import annotations

from typing import Any

from robot_lab.launch.compat_path import unsupported

from .substitutions import subs

__all__ = [
    'AnyLaunchDescriptionSource',
    'FrontendLaunchDescriptionSource',
    'LaunchDescriptionSource',
    'PythonLaunchDescriptionSource',
]


class LaunchDescriptionSource:
    """A launch file location (substitutions allowed); the file is read when included."""

    def __init__(self, launch_file_path: Any) -> None:
        self.location = subs(launch_file_path)


class PythonLaunchDescriptionSource(LaunchDescriptionSource):
    pass


class FrontendLaunchDescriptionSource(LaunchDescriptionSource):
    pass


class AnyLaunchDescriptionSource(LaunchDescriptionSource):
    pass


def __getattr__(name: str) -> Any:
    raise unsupported('launch.launch_description_sources', name, __all__)
