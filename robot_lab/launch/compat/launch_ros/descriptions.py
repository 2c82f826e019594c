"""launch_ros.descriptions: the parameter descriptions under their newer home."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.compat.launch_ros.parameter_descriptions import (
    Parameter,
    ParameterFile,
    ParameterValue,
)
from robot_lab.launch.compat_path import unsupported

__all__ = ['Parameter', 'ParameterFile', 'ParameterValue']


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros.descriptions', name, __all__)
