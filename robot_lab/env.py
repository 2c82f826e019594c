"""The environment robot_lab gives every ROS process it starts (or joins, in a kernel).

Two defaults, both overridable by what the user already set:
- ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST: DDS never sends a packet off loopback.
- FASTRTPS_DEFAULT_PROFILES_FILE: the kit's fast-discovery profile (see data/).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, MutableMapping
from pathlib import Path

__all__ = ['DISCOVERY_PROFILE', 'apply_ros_defaults', 'ros_environment']

DISCOVERY_PROFILE = Path(__file__).with_name('data') / 'fastdds_profile.xml'

_DEFAULTS: dict[str, str] = {
    'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
    # Unbuffered Python children, so `[sensor_node-1] ...` lines appear as they happen.
    'PYTHONUNBUFFERED': '1',
    # rcutils colourises only on a tty; launch output is piped, so keep it plain.
    'RCUTILS_COLORIZED_OUTPUT': os.environ.get('RCUTILS_COLORIZED_OUTPUT', '0'),
}


def _uses_fastdds(env: Mapping[str, str]) -> bool:
    return env.get('RMW_IMPLEMENTATION', 'rmw_fastrtps_cpp').startswith('rmw_fastrtps')


def apply_ros_defaults(env: MutableMapping[str, str] | None = None) -> MutableMapping[str, str]:
    """Fill in robot_lab's ROS defaults where `env` (default: os.environ) has none."""
    target: MutableMapping[str, str] = os.environ if env is None else env
    for key, value in _DEFAULTS.items():
        target.setdefault(key, value)
    if (
        _uses_fastdds(target)
        and 'FASTRTPS_DEFAULT_PROFILES_FILE' not in target
        and 'FASTDDS_DEFAULT_PROFILES_FILE' not in target
        and DISCOVERY_PROFILE.is_file()
    ):
        target['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(DISCOVERY_PROFILE)
    # The venv is an ament prefix too (message packages, ament_index_python).
    from robot_lab.pkg.index import ament_prefixes

    target['AMENT_PREFIX_PATH'] = os.pathsep.join(str(p) for p in ament_prefixes(target))
    return target


def ros_environment(extra: Mapping[str, str] | None = None) -> dict[str, str]:
    """A copy of os.environ with robot_lab's defaults and `extra` applied, for a child."""
    env = dict(os.environ)
    if extra:
        env.update(extra)
    apply_ros_defaults(env)
    return env
