"""Packages: the ament index (find packages and executables), create, build, doctor."""

from robot_lab.pkg.create import create_package
from robot_lab.pkg.index import (
    ament_prefixes,
    executables,
    find_executable,
    kit_prefix,
    package_prefix,
    package_share,
    packages,
)
from robot_lab.pkg.workspace import use_workspace, workspace_dir

__all__ = [
    'ament_prefixes',
    'create_package',
    'executables',
    'find_executable',
    'kit_prefix',
    'package_prefix',
    'package_share',
    'packages',
    'use_workspace',
    'workspace_dir',
]
