"""`colcon test` on a fresh `ros2 pkg create --build-type ament_python` package gives what
Jazzy gives (3 tests, 1 skipped: ament_copyright's), fails on a flake8 mistake, and the
kit's ament_copyright answers as ament_lint's does.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from conftest import BIN, venv_env

APACHE = """\
# Copyright 2025 Ada Lovelace
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.
"""


def terminal(script: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    env = venv_env()
    return subprocess.run(['bash', '-c', script], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=timeout, check=False)


def copyright_cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(BIN / 'ament_copyright'), *args], cwd=cwd, capture_output=True,
                          text=True, timeout=60, check=False)


def test_fresh_package_passes_then_a_lint_mistake_fails(tmp_path: Path) -> None:
    (tmp_path / 'src').mkdir()
    made = terminal('ros2 pkg create --build-type ament_python --license Apache-2.0 '
                    '--node-name my_node my_package --destination-directory src', tmp_path)
    assert made.returncode == 0, made.stderr
    run = terminal('colcon build && colcon test && colcon test-result --verbose', tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert 'Summary: 3 tests, 0 errors, 0 failures, 1 skipped' in run.stdout
    log = (tmp_path / 'log' / 'latest_test' / 'my_package' / 'stdout_stderr.log').read_text()
    assert '2 passed, 1 skipped' in log
    # Jazzy's own warnings on Ubuntu 24.04 (setuptools 68, flake8-import-order 0.18), no
    # other; from Python 3.12 (24.04's), flake8's fork in a threaded pytest warns as well
    # (upstream silences it package by package: ros2/ros2cli#1033).
    warned = re.findall(r'^\s+\S+: (\w+Warning): (.*)$', log, re.MULTILINE)
    forked = [w for w in warned if w[0] == 'DeprecationWarning'
              and re.fullmatch(r'This process \(pid=\d+\) is multi-threaded, use of fork\(\) '
                               r'may lead to deadlocks in the child\.', w[1])]
    assert not forked or sys.version_info >= (3, 12), log
    warned = [w for w in warned if w not in forked]
    assert warned == [('DeprecationWarning', warned[0][1])], log
    assert warned[0][1].startswith('pkg_resources is deprecated as an API'), log

    node = tmp_path / 'src' / 'my_package' / 'my_package' / 'my_node.py'
    node.write_text('import os\n' + node.read_text())  # F401, and I100 order for flake8
    again = terminal('colcon test --packages-select my_package; '
                     'colcon test-result --verbose', tmp_path)
    assert again.returncode == 1, again.stdout
    assert 'Summary: 3 tests, 0 errors, 1 failure, 1 skipped' in again.stdout
    assert 'test_flake8' in again.stdout
    log = (tmp_path / 'log' / 'latest_test' / 'my_package' / 'stdout_stderr.log').read_text()
    assert "F401 'os' imported but unused" in log


def test_ament_copyright_reports_as_upstream(tmp_path: Path) -> None:
    pkg = tmp_path / 'pkg'
    (pkg / 'pkg').mkdir(parents=True)
    (pkg / 'package.xml').write_text('<package/>')
    (pkg / 'setup.py').write_text('print(1)\n')  # a package's setup.py is not checked
    (pkg / 'pkg' / '__init__.py').write_text('')
    (pkg / 'pkg' / 'node.py').write_text('print("hi")\n')
    bare = copyright_cli('.', cwd=pkg)
    assert bare.returncode == 1
    assert bare.stderr.splitlines() == ['pkg/node.py: could not find copyright notice',
                                        '1 errors, checked 2 files']

    (pkg / 'pkg' / 'node.py').write_text('#!/usr/bin/env python3\n' + APACHE + '\nprint(1)\n')
    verbose = copyright_cli('.', '--verbose', cwd=pkg)
    assert verbose.returncode == 0, verbose.stderr
    assert verbose.stdout.splitlines() == [
        'pkg/__init__.py: file empty',
        'pkg/node.py: copyright=Ada Lovelace (2025), license=apache2',
        'No problems found, checked 2 files']

    (pkg / 'pkg' / 'other.py').write_text('# Copyright 2024 Me\n# All rights mine.\n')
    unknown = copyright_cli('pkg', cwd=pkg)
    assert unknown.returncode == 1
    assert 'pkg/other.py: copyright=Me (2024), license=<unknown>' in unknown.stderr

    added = copyright_cli('pkg', '--add-missing', 'Grace Hopper', 'mit', cwd=pkg)
    assert added.returncode == 0, added.stderr
    assert copyright_cli('pkg/other.py', cwd=pkg).returncode == 1  # has one: left alone
    (pkg / 'pkg' / 'other.py').unlink()
    (pkg / 'pkg' / 'more.py').write_text('x = 1\n')
    copyright_cli('pkg', '--add-missing', 'Grace Hopper', 'mit', cwd=pkg)
    assert (pkg / 'pkg' / 'more.py').read_text().startswith('# Copyright ')
    assert copyright_cli('pkg', cwd=pkg).returncode == 0

    listed = copyright_cli('--list-licenses', cwd=pkg)
    assert 'apache2: Apache License, Version 2.0' in listed.stdout.splitlines()


def test_repository_root_needs_license_and_contributing(tmp_path: Path) -> None:
    (tmp_path / '.git').mkdir()
    result = copyright_cli('.', cwd=tmp_path)
    assert result.returncode == 1
    assert 'CONTRIBUTING.md: file not found' in result.stderr
    assert 'LICENSE: file not found' in result.stderr
    made = subprocess.run([str(BIN / 'robot-lab'), 'pkg', 'create', '--license', 'Apache-2.0',
                           'lic_pkg'], cwd=tmp_path, capture_output=True, text=True, check=False)
    assert made.returncode == 0, made.stderr
    (tmp_path / 'LICENSE').write_text((tmp_path / 'lic_pkg' / 'LICENSE').read_text())
    (tmp_path / 'CONTRIBUTING.md').write_text('Contributions are Apache-2.0.\n')
    ok = copyright_cli('LICENSE', 'CONTRIBUTING.md', '--verbose', cwd=tmp_path)
    assert 'LICENSE: apache2' in ok.stdout, ok.stdout + ok.stderr  # ros2 pkg create's text


def test_tests_pass_check_is_optional_and_judges_colcon_test(tmp_path: Path) -> None:
    from robot_lab.grading.package.checks.tests_pass import tests_pass
    from robot_lab.grading.package.rubric import RubricCheck, load_rubric, rubric_path
    from robot_lab.grading.package.state import JobState

    shipped = rubric_path('ch6-lab1')
    assert 'tests_pass' not in load_rubric(shipped).ids  # off by default
    text = shipped.read_text().replace('  # - id: tests_pass', '  - id: tests_pass')
    for key in ('name', 'points', 'timeout_seconds'):
        text = text.replace(f'  #   {key}:', f'    {key}:')
    (tmp_path / 'on.yaml').write_text(text)
    rubric = load_rubric(tmp_path / 'on.yaml')
    assert rubric.check('tests_pass') is not None

    ws = tmp_path / 'ws'
    (ws / 'src').mkdir(parents=True)
    made = terminal('ros2 pkg create --build-type ament_python --node-name my_node my_package '
                    '--destination-directory src && colcon build', ws)
    assert made.returncode == 0, made.stdout + made.stderr
    state = JobState(rubric, package=ws / 'src' / 'my_package', package_name='my_package',
                     built=True)
    check = RubricCheck('tests_pass', 'tests', 1.0, {'timeout_seconds': 180})
    verdict = tests_pass(state, check)
    assert verdict.earned is True, verdict
    assert verdict.observed == '3 tests, 0 errors, 0 failures, 1 skipped'

    node = ws / 'src' / 'my_package' / 'my_package' / 'my_node.py'
    node.write_text(node.read_text().replace('def main():', 'def main( ):'))  # E201
    verdict = tests_pass(state, check)
    assert verdict.earned is False
    assert '1 failure,' in verdict.observed and 'test_flake8' in verdict.observed
    assert 'colcon test-result --verbose' in verdict.fix
