"""launch.launch_description_sources: where an IncludeLaunchDescription reads its file."""

from __future__ import annotations

from typing import NoReturn, Protocol, runtime_checkable

from robot_lab.launch.action import Subs, subs
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.substitutions import SomeSubstitutions

__all__ = [
    'AnyLaunchDescriptionSource',
    'FrontendLaunchDescriptionSource',
    'LaunchDescriptionSource',
    'PythonLaunchDescriptionSource',
]


@runtime_checkable
class Located(Protocol):
    """A launch description source, whichever import path made it (launch_xml's or ours):
    a Python launch file imports these modules under their launch names, the kit under
    robot_lab's, so a class check would miss half of them."""

    location: Subs


class LaunchDescriptionSource:
    """A launch file location (substitutions allowed); the file is read when included."""

    def __init__(self, launch_file_path: SomeSubstitutions) -> None:
        self.location = subs(launch_file_path)


class PythonLaunchDescriptionSource(LaunchDescriptionSource):
    pass


class FrontendLaunchDescriptionSource(LaunchDescriptionSource):
    pass


class AnyLaunchDescriptionSource(LaunchDescriptionSource):
    pass


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch.launch_description_sources', name, __all__)
