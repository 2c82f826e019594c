"""Every supported Python, every shell (README: *Supported platforms*, *Terminals*).

setup.py's setuptools range is one that colcon builds and tests with on Python 3.10-3.13:
setuptools 80+ refuses `colcon build --symlink-install` (--editable, colcon-core #696) and
72-79 leave `colcon test` without tests (tests_require is gone). And a terminal that only
ran `source .venv/bin/activate`, as the README says, has what `.venv/setup.bash` gives.
"""

from __future__ import annotations

import ast
import importlib.metadata
import os
import subprocess
import sys
from pathlib import Path

import pytest
from packaging.markers import default_environment
from packaging.requirements import Requirement
from packaging.version import Version

pytestmark = pytest.mark.no_ros  # files and shells: no ROS graph

REPO = Path(__file__).resolve().parents[1]
SUPPORTED = ('3.10', '3.11', '3.12', '3.13')
# Versions colcon fails with (see above), and Ubuntu 24.04's, which Jazzy's colcon uses.
BROKEN = ('72.0', '75.8.2', '79.0.1', '80.0', '84.0')
WORKS = '68.1.2'


def _install_requires() -> list[Requirement]:
    """setup.py's install_requires, read as written (a literal list)."""
    tree = ast.parse((REPO / 'setup.py').read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.keyword) and node.arg == 'install_requires':
            return [Requirement(text) for text in ast.literal_eval(node.value)]
    raise AssertionError('setup.py has no install_requires')


def _setuptools_for(python: str) -> list[Requirement]:
    environment = {key: str(value) for key, value in default_environment().items()}
    environment.update(python_version=python, python_full_version=f'{python}.0')
    return [req for req in _install_requires() if req.name == 'setuptools'
            and (req.marker is None or req.marker.evaluate(environment))]


@pytest.mark.parametrize('python', SUPPORTED)
def test_setuptools_is_pinned_to_what_colcon_works_with(python: str) -> None:
    wanted = _setuptools_for(python)
    assert wanted, f'setup.py leaves setuptools free on Python {python}'
    for version in (*BROKEN, WORKS):
        admitted = all(req.specifier.contains(version, prereleases=True) for req in wanted)
        assert admitted is (version == WORKS), (
            f'on Python {python}, setup.py {"admits" if admitted else "refuses"} '
            f'setuptools {version}: {", ".join(map(str, wanted))}')


def test_this_venv_has_the_pinned_setuptools() -> None:
    installed = importlib.metadata.version('setuptools')
    python = '{}.{}'.format(*sys.version_info[:2])
    assert all(req.specifier.contains(installed) for req in _setuptools_for(python)), installed
    assert Version(installed) < Version('72')


def test_bin_activate_gives_a_shell_what_setup_bash_gives() -> None:
    """What a student's own terminal has after the README's one line, from a login's bare
    environment (tests/test_custom_interfaces.py builds the tutorial's package in one)."""
    bare = {'HOME': os.environ['HOME'], 'PATH': '/usr/local/bin:/usr/bin:/bin'}
    show = 'echo "$AMENT_PREFIX_PATH|$CMAKE_PREFIX_PATH|$(command -v colcon)"'
    activate, setup = Path(sys.prefix) / 'bin' / 'activate', Path(sys.prefix) / 'setup.bash'
    seen = [subprocess.run(['bash', '-c', script], env=bare, capture_output=True, text=True,
                           timeout=60, check=True).stdout
            for script in (f'source {activate} && {show}',
                           f'source {activate} && source {setup} && {show}')]
    assert seen[0] == seen[1] == f'{sys.prefix}|{sys.prefix}|{sys.prefix}/bin/colcon\n'


def _kit(*args: str, **env: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(REPO / 'kit'), *args], cwd=REPO, capture_output=True, text=True,
                          env={**os.environ, **env}, timeout=240, check=False)


def test_kit_runs_the_python_it_is_given_or_none() -> None:
    refused = _kit('setup', '--python', '3.9')
    assert refused.returncode == 1
    assert 'error: PYTHON=3.9 is not a CPython 3.10-3.13 that runs here' in refused.stderr
    # --python anywhere among test's arguments; ROBOT_LAB_VENV names its venv (this one).
    collected = _kit('test', tests_path := 'tests/test_python_versions.py', '-k', 'colcon_works',
                     '--python', sys.executable, '--co', '-q', '-n', '0',
                     ROBOT_LAB_VENV=sys.prefix)
    assert collected.returncode == 0, collected.stdout[-2000:] + collected.stderr[-2000:]
    assert [line for line in collected.stdout.splitlines() if '::' in line] == [
        f'{tests_path}::test_setuptools_is_pinned_to_what_colcon_works_with[{v}]'
        for v in SUPPORTED]
