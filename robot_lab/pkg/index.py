"""The ament resource index: which packages exist, where their share/ and lib/ are.

Real ROS finds packages through `AMENT_PREFIX_PATH`; so does robot_lab. Two more
prefixes are searched after the user's: the kit's own (so `robot_lab` is found even
from an editable install, which installs no data_files) and the venv itself, which
holds the message packages that came as wheels.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from pathlib import Path

from robot_lab.ament_prefix import ament_prefixes, kit_prefix
from robot_lab.errors import ExecutableNotFoundError, PackageNotFoundError
from robot_lab.pkg.kit_packages import KIT_EXECUTABLES, ensure_kit_package, install_executables

__all__ = [
    'ament_prefixes',
    'executables',
    'find_executable',
    'kit_prefix',
    'package_prefix',
    'package_share',
    'packages',
]

_MARKERS = Path('share', 'ament_index', 'resource_index', 'packages')


def packages(env: Mapping[str, str] | None = None) -> dict[str, Path]:
    """Every package in the index, mapped to the first prefix that has it."""
    result: dict[str, Path] = {}
    for prefix in ament_prefixes(env):
        markers = prefix / _MARKERS
        if markers.is_dir():
            for marker in sorted(markers.iterdir()):
                result.setdefault(marker.name, prefix)
    return result


def package_prefix(name: str, env: Mapping[str, str] | None = None) -> Path:
    """The install prefix of package `name`, as `ros2 pkg prefix` finds it."""
    prefixes = ament_prefixes(env)
    for prefix in prefixes:
        if (prefix / _MARKERS / name).is_file():
            if prefix == Path(sys.prefix):
                ensure_kit_package(name)  # a kit package older than its definitions: rebuilt
            return prefix
    # The tutorials' interface packages and turtlesim: built from their definitions on
    # first need when `./kit setup` has not built them.
    if ensure_kit_package(name) and (Path(sys.prefix) / _MARKERS / name).is_file():
        return Path(sys.prefix)
    searched = ', '.join(str(p) for p in prefixes) or '(none)'
    raise PackageNotFoundError(
        f"Package '{name}' not found (searched AMENT_PREFIX_PATH: {searched})",
        fix='build it with `robot-lab build` (or colcon build), then '
        '`source install/setup.bash` or robot_lab.use_workspace(...)',
    )


def package_share(name: str, env: Mapping[str, str] | None = None) -> Path:
    """`$(find-pkg-share name)`."""
    return package_prefix(name, env) / 'share' / name


def executables(name: str, env: Mapping[str, str] | None = None) -> list[str]:
    """The executables installed under <prefix>/lib/<name>, sorted."""
    libdir = package_prefix(name, env) / 'lib' / name
    if not libdir.is_dir():
        return []
    return sorted(
        p.name for p in libdir.iterdir() if p.is_file() and os.access(p, os.X_OK)
    )


def find_executable(package: str, executable: str, env: Mapping[str, str] | None = None) -> Path:
    """<prefix>/lib/<package>/<executable>, or an error listing what the package has."""
    libdir = package_prefix(package, env) / 'lib' / package
    path = libdir / executable
    if path.is_file() and os.access(path, os.X_OK):
        return path
    if executable in KIT_EXECUTABLES.get(package, {}):
        install_executables()
        if path.is_file():
            return path
    have = executables(package, env)
    listing = ', '.join(have) if have else 'none'
    raise ExecutableNotFoundError(
        f"executable '{executable}' not found on the libexec directory '{libdir}'",
        fix=f"package '{package}' has: {listing}",
    )
