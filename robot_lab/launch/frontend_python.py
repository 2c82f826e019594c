"""Python launch files: run `generate_launch_description()` against robot_lab's launch API.

The file imports `launch`/`launch_ros`; compat_path.py makes robot_lab's facade (compat/)
importable under those names for the duration.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
from pathlib import Path

from robot_lab.errors import LaunchError
from robot_lab.launch.action import LaunchDescriptionStep, as_step, python_error
from robot_lab.launch.compat_path import compat_api, real_launch_installed

__all__ = ['load_python_launch_file']


def load_python_launch_file(path: Path) -> LaunchDescriptionStep:
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
            raise python_error(err, f'launch file {path.name}') from None
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
            raise python_error(err, 'generate_launch_description()') from None
        try:
            step = as_step(description)
        except TypeError as err:
            raise LaunchError(
                f'generate_launch_description() returned {type(description).__name__}, '
                f'not a LaunchDescription ({err})', file=path,
                fix='return launch.LaunchDescription([...])'
                + (' (a real ROS 2 `launch` is installed: run it with `ros2 launch`)'
                   if real_launch_installed() else '')) from None
    assert isinstance(step, LaunchDescriptionStep)
    step.locate(path, None)
    return step
