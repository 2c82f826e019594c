"""The environment robot_lab gives every ROS process it starts (or joins, in a kernel).

Defaults, each overridable by what the user already set:
- ROS_DOMAIN_ID: the user's own domain on this host (robot_lab/domain.py), so two
  students on one machine never see each other's nodes.
- ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST: DDS never sends a packet off loopback.
- FASTRTPS_DEFAULT_PROFILES_FILE: the kit's fast-discovery profile (see data/).
- CMAKE_C/CXX_COMPILER_LAUNCHER: the kit's ccache, when installed (compiler_cache.py).
- PATH: the venv's bin appended when missing (a child's `xacro`, `ros2`; ros_environment).

And the library path the ROS wheels need, so a Python child does not start twice: the
wheels' bootstrapper (a .pth file) re-executes the interpreter with LD_LIBRARY_PATH set
unless its marker says that was done.
"""

from __future__ import annotations

import functools
import importlib.util
import os
import sys
from collections.abc import Mapping, MutableMapping
from pathlib import Path

__all__ = ['DISCOVERY_PROFILE', 'apply_ros_defaults', 'ros_environment', 'switched_on']

DISCOVERY_PROFILE = Path(__file__).with_name('data') / 'fastdds_profile.xml'

_DEFAULTS: dict[str, str] = {
    'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
    # Unbuffered Python children, so `[sensor_node-1] ...` lines appear as they happen.
    'PYTHONUNBUFFERED': '1',
    # rcutils colourises only on a tty; launch output is piped, so keep it plain.
    'RCUTILS_COLORIZED_OUTPUT': os.environ.get('RCUTILS_COLORIZED_OUTPUT', '0'),
}


# Set by ros_wheels_bootstrapper once LD_LIBRARY_PATH holds the wheels' libraries.
_BOOTSTRAP_MARKER = '_ROS_WHEELS_BOOTSTRAP_COMPLETE'


@functools.cache
def _wheel_library_dirs() -> tuple[str, ...]:
    """The directories ros_wheels_bootstrapper puts on LD_LIBRARY_PATH (none without it)."""
    if 'ros_wheels_bootstrapper' not in sys.modules and (
        importlib.util.find_spec('ros_wheels_bootstrapper') is None
    ):
        return ()
    version = f'python{sys.version_info.major}.{sys.version_info.minor}'
    site_packages = Path(sys.prefix, 'lib', version, 'site-packages')  # where it looks
    libs = sorted(str(d.resolve()) for d in site_packages.glob('ros_*.libs') if d.is_dir())
    return (os.path.join(sys.prefix, 'lib'), *libs)


def _add_wheel_libraries(target: MutableMapping[str, str]) -> None:
    """Put the wheels' libraries on LD_LIBRARY_PATH (first, the user's entries kept after)."""
    dirs = _wheel_library_dirs()
    if not dirs:
        return
    have = [part for part in target.get('LD_LIBRARY_PATH', '').split(os.pathsep) if part]
    missing = [d for d in dirs if d not in have]
    if missing:
        target['LD_LIBRARY_PATH'] = os.pathsep.join([*missing, *have])
    target.setdefault(_BOOTSTRAP_MARKER, '1')


def _uses_fastdds(env: Mapping[str, str]) -> bool:
    return env.get('RMW_IMPLEMENTATION', 'rmw_fastrtps_cpp').startswith('rmw_fastrtps')


def apply_ros_defaults(env: MutableMapping[str, str] | None = None) -> MutableMapping[str, str]:
    """Fill in robot_lab's ROS defaults where `env` (default: os.environ) has none."""
    target: MutableMapping[str, str] = os.environ if env is None else env
    for key, value in _DEFAULTS.items():
        target.setdefault(key, value)
    from robot_lab.domain import fill_domain

    fill_domain(target)
    if (
        _uses_fastdds(target)
        and 'FASTRTPS_DEFAULT_PROFILES_FILE' not in target
        and 'FASTDDS_DEFAULT_PROFILES_FILE' not in target
        and DISCOVERY_PROFILE.is_file()
    ):
        target['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(DISCOVERY_PROFILE)
    # The venv is an ament prefix too (message packages, ament_index_python).
    from robot_lab.ament_prefix import ament_prefixes

    target['AMENT_PREFIX_PATH'] = os.pathsep.join(str(p) for p in ament_prefixes(target))
    _add_wheel_libraries(target)
    # colcon builds started from here (a notebook's `!colcon build`, robot_lab.build) compile
    # through the kit's warmed compiler cache when ccache is installed.
    from robot_lab.compiler_cache import apply_compiler_cache

    apply_compiler_cache(target)
    return target


def ros_environment(extra: Mapping[str, str] | None = None) -> dict[str, str]:
    """A copy of os.environ with robot_lab's defaults and `extra` applied, for a child."""
    env = dict(os.environ)
    if extra:
        env.update(extra)
    apply_ros_defaults(env)
    _add_venv_bin(env)
    return env


def _add_venv_bin(env: MutableMapping[str, str]) -> None:
    """Append the venv's bin (`ros2`, `xacro`, `colcon`) to PATH if it is not on it.

    A kernel started without the lesson's set-up may lack it, and a launch file's
    `xacro` step then fails with "file not found: xacro". Appended, never moved: a PATH
    that has it keeps its order, and the user's own programs still come first.
    """
    venv_bin = os.path.normpath(os.path.join(sys.prefix, 'bin'))
    path = env.get('PATH', os.defpath)
    if any(p and os.path.normpath(p) == venv_bin for p in path.split(os.pathsep)):
        return
    env['PATH'] = f'{path}{os.pathsep}{venv_bin}' if path else venv_bin


def switched_on(variable: str) -> bool:
    """Whether an on/off variable of the kit's (ROBOT_LAB_NO_DAEMON=1) is set: anything
    but unset, empty or 0 means on."""
    return os.environ.get(variable, '0') not in ('', '0')
