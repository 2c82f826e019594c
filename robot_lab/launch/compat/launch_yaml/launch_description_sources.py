"""launch_yaml.launch_description_sources.YAMLLaunchDescriptionSource."""

from __future__ import annotations

from robot_lab.launch.compat.launch.launch_description_sources import (
    FrontendLaunchDescriptionSource,
)

__all__ = ['YAMLLaunchDescriptionSource']


class YAMLLaunchDescriptionSource(FrontendLaunchDescriptionSource):
    pass
