"""The CMake side of the ROS wheels: what `colcon build` of an ament_cmake package needs.

The `ros-jazzy-*` wheels install ament_cmake and the rosidl generators under the venv's
share/, so CMake finds them as it finds any prefix on PATH. One thing in them is wrong for
this machine: each message package's exported `<pkg>__rosidl_generator_py` target names the
wheel builder's Python and NumPy include folders (`/opt/python/cp311-cp311/include/...`),
and CMake refuses a target whose include folder does not exist. `fix_wheel_cmake()`
rewrites those two paths to this interpreter's, in place, idempotently: the documented
path fix-up the kit runs at install and before every interface build.
"""

from __future__ import annotations

import os
import re
import shutil
import sys
import sysconfig
from dataclasses import dataclass
from pathlib import Path

from robot_lab.errors import PackageError

__all__ = ['BuildTools', 'build_tools', 'fix_wheel_cmake', 'python_include_dir']

# The manylinux build image's interpreters: /opt/python/cp311-cp311/...
_BUILDER_INCLUDE = re.compile(r'/opt/python/cp3\d+-cp3\d+\d*/include/python3\.\d+t?')
_BUILDER_NUMPY = re.compile(
    r'/opt/python/cp3\d+-cp3\d+\d*/lib/python3\.\d+t?/site-packages/numpy/(?:_core|core)/include'
)
_APT_LINE = 'sudo apt-get install build-essential python3-dev'


def python_include_dir() -> Path:
    """Where this interpreter's Python.h lives (the rosidl Python extensions include it)."""
    return Path(sysconfig.get_paths()['include'])


def _numpy_include_dir() -> Path | None:
    try:
        import numpy
    except ImportError:
        return None
    return Path(numpy.get_include())


def fix_wheel_cmake(prefix: Path | None = None) -> list[Path]:
    """Point the wheels' exported CMake targets at this machine's Python and NumPy headers.

    Returns the files changed (none when already fixed). A file the user cannot write is
    reported as one error naming it and the command that fixes it.
    """
    root = Path(sys.prefix if prefix is None else prefix) / 'share'
    include = str(python_include_dir())
    numpy = _numpy_include_dir()
    changed: list[Path] = []
    if not root.is_dir():
        return changed
    for path in sorted(root.glob('*/cmake/*.cmake')):
        try:
            text = path.read_text()
        except (OSError, UnicodeDecodeError):
            continue
        if '/opt/python/' not in text:
            continue
        fixed = _BUILDER_INCLUDE.sub(include, text)
        if numpy is not None:
            fixed = _BUILDER_NUMPY.sub(str(numpy), fixed)
        if fixed == text:
            continue
        try:
            tmp = path.with_name(path.name + f'.{os.getpid()}.tmp')
            tmp.write_text(fixed)
            tmp.replace(path)
        except OSError as exc:
            raise PackageError(
                f"cannot fix the wheel's CMake file {path}: {exc.strerror}",
                fix='run `robot-lab build --kit` once as the user who installed the kit',
            ) from exc
        changed.append(path)
    return changed


@dataclass(frozen=True)
class BuildTools:
    """The programs an ament_cmake build runs: CMake (from PyPI) and the system compilers."""

    cmake: Path
    c_compiler: Path
    cxx_compiler: Path


def _which(names: tuple[str, ...], env_var: str) -> Path | None:
    wanted = os.environ.get(env_var)
    for name in ((wanted,) if wanted else ()) + names:
        found = shutil.which(name)
        if found:
            return Path(found)
    return None


def build_tools() -> BuildTools:
    """CMake, a C and a C++ compiler and Python.h, or one line saying what to install."""
    venv_cmake = Path(sys.prefix) / 'bin' / 'cmake'
    cmake = venv_cmake if venv_cmake.is_file() else _which(('cmake',), 'CMAKE_COMMAND')
    if cmake is None:
        raise PackageError(
            'CMake is not installed (ament_cmake packages need it)',
            fix="pip install 'cmake>=3.22,<3.31' in the kit's venv",
        )
    cc = _which(('cc', 'gcc', 'clang'), 'CC')
    cxx = _which(('c++', 'g++', 'clang++'), 'CXX')
    if cc is None or cxx is None:
        raise PackageError(
            'no C/C++ compiler found (rosidl compiles the message type support)',
            fix=_APT_LINE + ' (Fedora: sudo dnf install gcc-c++ python3-devel)',
        )
    if not (python_include_dir() / 'Python.h').is_file():
        raise PackageError(
            f'Python.h is missing from {python_include_dir()} (the Python message '
            'bindings include it)',
            fix=_APT_LINE + ' (or install your Python with its headers)',
        )
    return BuildTools(cmake=cmake, c_compiler=cc, cxx_compiler=cxx)
