"""The Gradescope autograder (issue 19, item 7): the zip `robot-lab grade
--gradescope-autograder` writes, unpacked into a simulated /autograder (a temp folder,
AUTOGRADER_ROOT), run by its own run_autograder against a student's package with the kit
already installed (this venv standing in for /autograder/venv); results.json is Gradescope's
schema with the same checks and points as `robot-lab grade`. setup.sh is not run here (it
installs from PyPI in Gradescope's image); it is checked for syntax and what it installs."""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from conftest import REPO, run_cli

pytestmark = pytest.mark.timeout(900)
DATA = REPO / 'tests' / 'data' / 'class_ch6'


@pytest.fixture(scope='module')
def autograder(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    work = tmp_path_factory.mktemp('gradescope')
    archive = work / 'autograder.zip'
    made = run_cli('grade', '--gradescope-autograder', str(archive), '--lab', 'ch6-lab1')
    assert made.returncode == 0, made.stdout + made.stderr
    root = work / 'autograder'  # stands for /autograder
    with zipfile.ZipFile(archive) as zf:
        zf.extractall(root / 'source')
        modes = {i.filename: i.external_attr >> 16 for i in zf.infolist()}
    for script in ('setup.sh', 'run_autograder'):  # zipfile drops the mode bits
        (root / 'source' / script).chmod(0o755)
    # What a student uploads: the package's files (Gradescope puts them in submission/).
    shutil.copytree(DATA / 'reference', root / 'submission')
    env = dict(os.environ, AUTOGRADER_ROOT=str(root),
               ROBOT_LAB_AUTOGRADER_PYTHON=sys.executable)
    run = subprocess.run([str(root / 'source' / 'run_autograder')], capture_output=True,
                         text=True, env=env, timeout=800, check=False)
    return {'archive': archive, 'root': root, 'run': run, 'modes': modes, 'made': made}


def test_the_zip_has_what_gradescope_runs(autograder: dict[str, object]) -> None:
    made, modes, root = autograder['made'], autograder['modes'], autograder['root']
    assert isinstance(modes, dict) and isinstance(root, Path)
    assert isinstance(made, subprocess.CompletedProcess)
    assert 'Configure Autograder' in made.stdout
    for script in ('setup.sh', 'run_autograder'):
        assert modes[script] & stat.S_IXUSR, script
    assert 'rubric-ch6-lab1.yaml' in modes
    assert 'kit/setup.py' in modes
    assert 'kit/robot_lab/grading/package/rubrics/ch6-lab1.yaml' in modes
    assert not any('__pycache__' in name for name in modes)
    setup = (root / 'source' / 'setup.sh').read_text()
    assert "pip install '/autograder/source/kit[kit]'" in setup
    assert subprocess.run(['bash', '-n', str(root / 'source' / 'setup.sh')],
                          check=False).returncode == 0


def test_run_autograder_writes_gradescope_results(autograder: dict[str, object]) -> None:
    run, root = autograder['run'], autograder['root']
    assert isinstance(run, subprocess.CompletedProcess) and isinstance(root, Path)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    data = json.loads((root / 'results' / 'results.json').read_text())
    assert data['score'] == 13
    assert [t['number'] for t in data['tests']] == [
        'builds', 'launch_file', 'sensor_publishes', 'controller_commands', 'actuator_logs',
        'params_file', 'params_used', 'readme']
    assert sum(t['max_score'] for t in data['tests']) == 13
    assert all(t['status'] == 'passed' for t in data['tests'])
    assert data['tests'][0]['name'] == 'The package builds with colcon'
    assert data['output_format'] == 'md' and data['visibility'] == 'visible'
    assert '/distance' in data['tests'][2]['output']  # the same feedback as the class run
    # Before the job, the instructor's log (run_autograder's output) says how it is fenced.
    assert 'containment: each job in its own namespaces' in run.stdout, run.stdout[-2000:]


def test_a_broken_submission_gets_its_points_not_a_crash(tmp_path: Path,
                                                          autograder: dict[str, object]) -> None:
    """A submission with no package: results.json still written, score 0, the reason."""
    root = autograder['root']
    assert isinstance(root, Path)
    other = tmp_path / 'autograder'
    shutil.copytree(root / 'source', other / 'source')
    (other / 'submission').mkdir(parents=True)
    (other / 'submission' / 'answer.py').write_text('print("hello")\n')
    # In a container that refuses namespaces (Docker's seccomp profile), as the layer's
    # switch makes this machine: the job still runs, and the log says the container is
    # the sandbox and why, never silently.
    env = dict(os.environ, AUTOGRADER_ROOT=str(other),
               ROBOT_LAB_AUTOGRADER_PYTHON=sys.executable, ROBOT_LAB_DISABLE='namespaces')
    run = subprocess.run([str(other / 'source' / 'run_autograder')], capture_output=True,
                         text=True, env=env, timeout=300, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    data = json.loads((other / 'results' / 'results.json').read_text())
    assert data['score'] == 0
    assert 'package' in json.dumps(data).lower()
    assert ('containment: the container is the sandbox: namespaces are unavailable in it '
            '(namespaces switched off (ROBOT_LAB_DISABLE=namespaces))') in run.stdout


def test_the_autograder_names_its_containment_without_namespaces(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from robot_lab.grading.package.containment import NO_SANDBOX_VAR, namespace_problem
    from robot_lab.grading.package.gradescope import autograder_containment
    from robot_lab.grading.package.rubric import Limits

    monkeypatch.setenv('ROBOT_LAB_DISABLE', 'namespaces')
    monkeypatch.setenv(NO_SANDBOX_VAR, '')  # restored by monkeypatch: the call sets it
    namespace_problem.cache_clear()
    try:
        line = autograder_containment(Limits(processes=64))
    finally:
        namespace_problem.cache_clear()
    assert line.startswith('containment: the container is the sandbox: namespaces are '
                           'unavailable in it (namespaces switched off'), line
    assert '64 processes' in line and 'runs as ' in line
    assert os.environ[NO_SANDBOX_VAR] == '1'  # the job does not try unshare
