"""Packages: the ament index (find packages and executables), create, build, doctor."""

from robot_lab.pkg.index import (
    ament_prefixes,
    executables,
    find_executable,
    kit_prefix,
    package_prefix,
    package_share,
    packages,
)

__all__ = [
    'ament_prefixes',
    'executables',
    'find_executable',
    'kit_prefix',
    'package_prefix',
    'package_share',
    'packages',
]
