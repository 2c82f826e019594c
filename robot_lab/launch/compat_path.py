"""The `launch`/`launch_ros` facade importable while Python launch code runs.

`launch` and `launch_ros` are not on PyPI. While a Python launch file is loaded (or an
OpaqueFunction runs), the directory compat/ (robot_lab's `launch`, `launch_ros`,
`launch_xml`, `launch_yaml`) is put first on sys.path, unless a real `launch` is
importable (a ROS install is never shadowed). `ament_index_python` (a real wheel) reads
AMENT_PREFIX_PATH, so it gets the kit's prefix.
"""

from __future__ import annotations

import importlib.machinery
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from robot_lab.errors import LaunchError

__all__ = ['COMPAT_DIR', 'COMPOSABLE_FIX', 'compat_api', 'real_launch_installed', 'unsupported']

COMPAT_DIR = Path(__file__).with_name('compat')
_COMPAT_MODULES = ('launch', 'launch_ros', 'launch_xml', 'launch_yaml')


def real_launch_installed() -> bool:
    """True if a real ros2/launch package (not ours, not a bare `launch/` folder) imports."""
    loaded = sys.modules.get('launch')
    if loaded is not None:
        origin = getattr(loaded, '__file__', None)
        return origin is not None and not origin.startswith(str(COMPAT_DIR))
    paths = [p for p in sys.path if Path(p or '.').resolve() != COMPAT_DIR.resolve()]
    spec = importlib.machinery.PathFinder.find_spec('launch', paths)
    return spec is not None and spec.origin is not None and spec.origin != 'namespace'


@contextmanager
def compat_api() -> Iterator[None]:
    """robot_lab's launch API importable as `launch`, `launch_ros` for the duration."""
    from robot_lab.env import ros_environment

    saved_path = list(sys.path)
    saved_ament = os.environ.get('AMENT_PREFIX_PATH')
    if not real_launch_installed():
        sys.path.insert(0, str(COMPAT_DIR))
        for name in _COMPAT_MODULES:  # a bare `launch/` folder of the CWD imported earlier
            module = sys.modules.get(name)
            if module is not None and getattr(module, '__file__', None) is None:
                del sys.modules[name]
    os.environ['AMENT_PREFIX_PATH'] = ros_environment()['AMENT_PREFIX_PATH']
    try:
        yield
    finally:
        sys.path[:] = saved_path
        if saved_ament is None:
            os.environ.pop('AMENT_PREFIX_PATH', None)
        else:
            os.environ['AMENT_PREFIX_PATH'] = saved_ament


def unsupported(module: str, name: str, available: Sequence[str] = ()) -> Exception:
    """What `from launch.actions import X` gets for an X robot_lab does not provide.

    One LaunchError at the launch file's import line (no raw ImportError/AttributeError);
    dunder lookups stay AttributeErrors so Python's own protocols keep working.
    """
    if name.startswith('__'):
        return AttributeError(f'module {module!r} has no attribute {name!r}')
    from robot_lab.launch.action import caller_line

    file, line = caller_line()
    return LaunchError(
        f"{module}.{name} is not supported by robot_lab's launcher",
        file=file, line=line,
        fix=COMPOSABLE_FIX if 'Composable' in name or 'Container' in name else
        'run this file with a full ROS 2 install (ros2 launch), or do without it'
        + (f'; {module} here has: {", ".join(sorted(available))}' if available else ''))


COMPOSABLE_FIX = (
    'composable nodes need rclcpp_components containers, which are C++ and not on PyPI: '
    'start each component as its own Node(package=..., executable=...) instead')
