"""`robot-lab doctor`: check a package the way an instructor would, before colcon does.

Every finding names the file and line to change and how. Nothing is executed: setup.py
and the node files are read with `ast`, package.xml with expat (for line numbers) and
catkin_pkg (the parser colcon itself uses), parameter files with rcl's rules
(robot_lab.params). Without a package, the environment is checked instead.
"""

from __future__ import annotations

import os
import platform
import sys
from collections.abc import Callable
from pathlib import Path

from robot_lab.pkg.doctor_findings import Check, Finding, PackageUnderCheck, Report
from robot_lab.pkg.doctor_package_xml import (
    check_dependencies,
    check_package_xml,
    check_param_files,
    check_resource,
)
from robot_lab.pkg.doctor_setup import check_setup_cfg, check_setup_py

__all__ = ['Check', 'Finding', 'Report', 'check_package', 'doctor']


_RULES: tuple[Callable[[PackageUnderCheck], None], ...] = (
    check_package_xml, check_setup_py, check_setup_cfg, check_resource,
    check_dependencies, check_param_files,
)


def check_package(path: str | os.PathLike[str]) -> Report:
    """Every package rule, on the package folder `path` (the one holding package.xml)."""
    folder = Path(path)
    if not folder.is_dir():
        from robot_lab.errors import PackageError

        raise PackageError(f'{folder} is not a folder', fix='give the package folder '
                           '(the one holding package.xml)')
    pkg = PackageUnderCheck(folder, folder.resolve().name)
    for rule in _RULES:
        rule(pkg)
    return Report(folder, pkg.findings)


# --- environment -----------------------------------------------------------------------


def _environment_checks() -> list[Check]:
    from robot_lab.domain import resolve
    from robot_lab.env import ros_environment
    from robot_lab.errors import RobotLabError

    checks: list[Check] = []
    try:
        choice = resolve()
        good = choice.domain in range(0, 102) or choice.domain in range(215, 233)
        checks.append(Check('ROS_DOMAIN_ID', good, str(choice),
                            fix='use a number from 0 to 101 or 215 to 232 (Fast DDS ports '
                            'of the others clash with Linux ephemeral ports or overflow)'))
        env = ros_environment()
    except RobotLabError as err:
        checks.append(Check('ROS_DOMAIN_ID', False, err.message, fix=err.fix))
        env = ros_environment({'ROS_DOMAIN_ID': '0'})
    version = sys.version_info
    checks.append(Check(
        'Python', version >= (3, 10) and sys.platform.startswith('linux'),
        f'{platform.python_version()} on {platform.system()} {platform.machine()}',
        fix='robot_lab needs Python >= 3.10 on Linux (the ROS 2 Jazzy wheels)',
    ))
    try:
        from importlib.metadata import PackageNotFoundError
        from importlib.metadata import version as dist_version

        import rclpy

        try:
            rclpy_version = dist_version('ros-jazzy-rclpy')
        except PackageNotFoundError:
            rclpy_version = 'unknown version'
        checks.append(Check('rclpy', True, f'imports ({rclpy_version}, {rclpy.__file__})'))
        from rclpy.utilities import get_rmw_implementation_identifier

        rmw = get_rmw_implementation_identifier()
        checks.append(Check('RMW implementation', True, rmw))
    except Exception as err:
        checks.append(Check('rclpy', False, f'cannot import rclpy: {err}',
                            fix="pip install 'robot_lab[kit]' in this venv"))
    discovery = env.get('ROS_AUTOMATIC_DISCOVERY_RANGE', '')
    checks.append(Check(
        'ROS_AUTOMATIC_DISCOVERY_RANGE', discovery == 'LOCALHOST', discovery or 'unset',
        fix='export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (keeps DDS on this machine)',
        severity='warning',
    ))
    if 'ROS_LOCALHOST_ONLY' in env:
        checks.append(Check('ROS_LOCALHOST_ONLY', False, 'set (deprecated in Jazzy)',
                            fix='unset it; ROS_AUTOMATIC_DISCOVERY_RANGE replaces it',
                            severity='warning'))
    colcon = Path(sys.prefix) / 'bin' / 'colcon'
    try:
        from importlib.metadata import version as dist_version

        colcon_version = dist_version('colcon-core')
    except Exception:
        colcon_version = ''
    checks.append(Check(
        'colcon', colcon.is_file() and bool(colcon_version),
        f'colcon-core {colcon_version} ({colcon})' if colcon_version else 'not installed',
        fix="pip install 'robot_lab[kit]' (colcon-core, colcon-ros, colcon-bash)",
    ))
    from robot_lab.shared_memory import deaf_processes

    # Listed only when one is found: the checklist stays as it was on a healthy host.
    for pid, command, ports in deaf_processes(int(env.get('ROS_DOMAIN_ID') or 0)):
        checks.append(Check(
            f'process {pid}', False,
            f'no longer hears new ROS participants (Fast DDS took over its shared-memory '
            f'port {", ".join(map(str, ports))}): {command[:80]}',
            fix='restart it (a notebook: Kernel > Restart Kernel; a launch: Ctrl-C, then '
                'launch again)'))
    from robot_lab.errors import PackageNotFoundError as MissingPackage
    from robot_lab.pkg.index import package_share

    try:
        share = package_share('robot_lab', env)
        checks.append(Check("kit package 'robot_lab'", True, f'found ({share})'))
    except MissingPackage:
        checks.append(Check("kit package 'robot_lab'", False, 'not in the ament index',
                            fix='reinstall the kit: pip install -e .'))
    return checks


def doctor(path: str | os.PathLike[str] | None = None) -> Report:
    """Check a package folder (findings with file:line and fix) or, without one, the
    environment (a checklist)."""
    if path is None:
        return Report(None, checks=_environment_checks())
    return check_package(path)
