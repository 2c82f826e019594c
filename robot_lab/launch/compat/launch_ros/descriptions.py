"""launch_ros.descriptions: the parameter descriptions under their newer home."""

from __future__ import annotations

from robot_lab.launch.compat.launch_ros.parameter_descriptions import (
    Parameter,
    ParameterFile,
    ParameterValue,
)

__all__ = ['Parameter', 'ParameterFile', 'ParameterValue']
