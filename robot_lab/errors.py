"""robot_lab's exceptions: each says what is wrong, where (file:line) and how to fix it."""

from __future__ import annotations

from pathlib import Path

__all__ = [
    'BagError',
    'ExecutableNotFoundError',
    'GraphError',
    'LaunchError',
    'PackageError',
    'PackageNotFoundError',
    'ParamFileError',
    'RobotLabError',
    'UrdfError',
]


class RobotLabError(Exception):
    """Base class: a one-line message, optionally located in a file.

    `str(err)` is the line the CLI prints: `file:line: message (fix)`.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | Path | None = None,
        line: int | None = None,
        fix: str | None = None,
    ) -> None:
        self.message = message
        self.file = str(file) if file is not None else None
        self.line = line
        self.fix = fix
        super().__init__(self.format())

    def format(self) -> str:
        where = ''
        if self.file is not None:
            where = self.file if self.line is None else f'{self.file}:{self.line}'
            where += ': '
        fix = f' — fix: {self.fix}' if self.fix else ''
        return f'{where}{self.message}{fix}'


class PackageNotFoundError(RobotLabError):
    """A ROS package is not in any prefix of AMENT_PREFIX_PATH (nor the kit's own)."""


class ExecutableNotFoundError(RobotLabError):
    """A package exists but has no such executable under lib/<pkg>."""


class PackageError(RobotLabError):
    """A package on disk is malformed (package.xml, setup.py, setup.cfg)."""


class ParamFileError(RobotLabError):
    """A parameter YAML file that rcl would refuse."""


class LaunchError(RobotLabError):
    """A launch file that cannot be parsed or resolved; nothing was started."""


class GraphError(RobotLabError):
    """A ROS graph query failed: unknown node/topic, timeout, refused parameter."""


class BagError(RobotLabError):
    """A rosbag2 folder or file that cannot be written, read or played."""


class UrdfError(RobotLabError):
    """A robot description (URDF) that urdfdom would refuse, or a joint tree that is not one."""
