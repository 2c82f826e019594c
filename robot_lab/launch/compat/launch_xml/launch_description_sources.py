"""launch_xml.launch_description_sources.XMLLaunchDescriptionSource."""

from __future__ import annotations

from robot_lab.launch.compat.launch.launch_description_sources import (
    FrontendLaunchDescriptionSource,
)

__all__ = ['XMLLaunchDescriptionSource']


class XMLLaunchDescriptionSource(FrontendLaunchDescriptionSource):
    pass
