"""launch_ros (robot_lab's stand-in): Node, PushROSNamespace, FindPackageShare, ..."""

from __future__ import annotations

from . import actions, parameter_descriptions, substitutions

__all__ = ['actions', 'parameter_descriptions', 'substitutions']
