"""Python launch files: run `generate_launch_description()` against robot_lab's launch API.

`launch` and `launch_ros` are not on PyPI. While a Python launch file is loaded, the
directory compat/ (robot_lab's `launch`, `launch_ros`, `launch_xml`, `launch_yaml`) is put
first on sys.path, unless a real `launch` is importable (a ROS install is never shadowed).
`ament_index_python` (a real wheel) reads AMENT_PREFIX_PATH, so it gets the kit's prefix.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from robot_lab.errors import LaunchError
from robot_lab.launch.describe import DescriptionStep, _as_step, _python_error

__all__ = ['COMPAT_DIR', 'compat_api', 'load_python_launch_file', 'real_launch_installed']

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


def load_python_launch_file(path: Path) -> DescriptionStep:
    """Execute the file and call its generate_launch_description(); nothing is started."""
    digest = hashlib.sha1(str(path).encode()).hexdigest()[:12]
    spec = importlib.util.spec_from_file_location(f'_robot_lab_launch_{digest}', path)
    if spec is None or spec.loader is None:
        raise LaunchError('cannot load Python launch file', file=path)
    module = importlib.util.module_from_spec(spec)
    with compat_api():
        try:
            spec.loader.exec_module(module)
        except SyntaxError as err:
            raise LaunchError(f'SyntaxError: {err.msg}', file=err.filename or path,
                              line=err.lineno) from None
        except LaunchError:
            raise
        except Exception as err:
            raise _python_error(err, f'launch file {path.name}') from None
        generate = getattr(module, 'generate_launch_description', None)
        if not callable(generate):
            raise LaunchError(
                f"launch file at '{path}' does not contain the required function "
                "'generate_launch_description()'", file=path,
                fix='define def generate_launch_description(): return LaunchDescription([...])')
        try:
            description = generate()
        except LaunchError:
            raise
        except Exception as err:
            raise _python_error(err, 'generate_launch_description()') from None
        try:
            step = _as_step(description)
        except TypeError as err:
            raise LaunchError(
                f'generate_launch_description() returned {type(description).__name__}, '
                f'not a LaunchDescription ({err})', file=path,
                fix='return launch.LaunchDescription([...])'
                + (' (a real ROS 2 `launch` is installed: run it with `ros2 launch`)'
                   if real_launch_installed() else '')) from None
    assert isinstance(step, DescriptionStep)
    step.locate(path, None)
    return step
