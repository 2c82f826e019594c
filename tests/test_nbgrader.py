"""The kit's notebooks in nbgrader, unchanged: the real `nbgrader` commands on the real files.

An instructor copies a solution into an nbgrader course's `source/` and runs
generate_assignment, autograde and generate_feedback; a student presses Validate (`nbgrader
validate`). Every kernel here runs real nodes in a ROS domain of this test run's own.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import uuid
from pathlib import Path

import psutil
import pytest
from conftest import BIN, REPO, domain_at

from robot_lab.grading.release import release_course

EXERCISE = 'ex06_ros_bags'  # the quickest exercise to run
PASSED = 'Success! Your notebook passes all the tests.'
FAILED = 'VALIDATION FAILED ON'


def _nbgrader(*args: str, cwd: Path, workspace: Path, marker: str,
              timeout: float = 300) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    env.update({
        'PATH': f'{BIN}{os.pathsep}{env.get("PATH", "")}',  # nbgrader runs `alembic`
        # Lesson set-up picks domain base + lesson number; exercises (exNN) add 0.
        'ROBOT_LAB_NOTEBOOK_DOMAIN_BASE': str(domain_at(70)),
        'ROBOT_LAB_WORKSPACE': str(workspace),
        'ROBOT_LAB_NBGRADER_RUN': marker,
        'JUPYTER_DATA_DIR': str(cwd / '.jupyter-data'),
    })
    return subprocess.run([str(BIN / 'nbgrader'), *args], cwd=cwd, env=env, text=True,
                          capture_output=True, timeout=timeout, check=False)


def _left_running(marker: str) -> list[str]:
    found = []
    for proc in psutil.process_iter():
        try:
            if proc.environ().get('ROBOT_LAB_NBGRADER_RUN') == marker:
                found.append(f'{proc.pid} {" ".join(proc.cmdline())}')
        except psutil.Error:
            continue
    return found


def test_generate_autograde_and_feedback_in_an_nbgrader_course(tmp_path: Path) -> None:
    course = tmp_path / 'course'
    (course / 'source' / 'ex06').mkdir(parents=True)
    (course / 'nbgrader_config.py').write_text(
        f'c = get_config()\nc.CourseDirectory.root = {str(course)!r}\n'
        "c.CourseDirectory.course_id = 'robot_lab'\n")
    shutil.copy(REPO / 'solutions' / f'{EXERCISE}.ipynb', course / 'source' / 'ex06')
    marker = uuid.uuid4().hex
    run = {'cwd': course, 'workspace': tmp_path / 'ws', 'marker': marker}
    done = _nbgrader('generate_assignment', 'ex06', **run)
    assert done.returncode == 0, done.stderr[-2000:]
    released = (course / 'release' / 'ex06' / f'{EXERCISE}.ipynb').read_text()
    # nbgrader's release is the kit's exercise (which adds only its name for robot-lab grade)
    ours = (REPO / 'exercises' / f'{EXERCISE}.ipynb').read_text()
    assert 'BEGIN SOLUTION' not in released
    assert released.count('raise NotImplementedError()') == ours.count(
        'raise NotImplementedError()') > 0
    # alice hands in the answers, bob the notebook as released.
    for student, notebook in (('alice', course / 'source' / 'ex06' / f'{EXERCISE}.ipynb'),
                              ('bob', course / 'release' / 'ex06' / f'{EXERCISE}.ipynb')):
        (course / 'submitted' / student / 'ex06').mkdir(parents=True)
        shutil.copy(notebook, course / 'submitted' / student / 'ex06')
    done = _nbgrader('autograde', 'ex06', **run)
    assert done.returncode == 0, done.stderr[-2000:]
    done = _nbgrader('generate_feedback', 'ex06', **run)
    assert done.returncode == 0, done.stderr[-2000:]
    from nbgrader.api import Gradebook  # type: ignore[import-untyped]

    with Gradebook(f'sqlite:///{course / "gradebook.db"}') as gradebook:
        scores = {s: (gradebook.find_submission('ex06', s).score,
                      gradebook.find_submission('ex06', s).max_score) for s in ('alice', 'bob')}
    assert scores == {'alice': (10.0, 10.0), 'bob': (0.0, 10.0)}
    for student in ('alice', 'bob'):
        page = (course / 'feedback' / student / 'ex06' / f'{EXERCISE}.html').read_text()
        assert 'check-stats' in page
    assert _left_running(marker) == []


def _course_notebooks() -> list[str]:
    """Every notebook a student gets, in course order (exercises after the course)."""
    names = [f'notebooks/{p.name}' for p in sorted((REPO / 'notebooks').glob('*.ipynb'))]
    return names + [f'exercises/{p.name}' for p in sorted((REPO / 'solutions').glob('*.ipynb'))]


# Validating all of them runs the whole course twice (minutes): by default the quickest
# exercise; ROBOT_LAB_VALIDATE_ALL=1 validates every notebook (the lead's full run).
VALIDATED = (_course_notebooks() if os.environ.get('ROBOT_LAB_VALIDATE_ALL')
             else [f'exercises/{EXERCISE}.ipynb'])


@pytest.fixture(scope='module')
def copies(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The student's copy of the course next to its sources, and one workspace for both
    (the course's notebooks build on each other's packages, as nbval runs them)."""
    root = tmp_path_factory.mktemp('validate')
    with pytest.MonkeyPatch.context() as env:
        env.setenv('JUPYTER_DATA_DIR', str(root / '.jupyter-data'))
        release_course(root / 'student')
    return root


@pytest.mark.parametrize('rel', VALIDATED)
def test_validate_passes_on_the_source(copies: Path, rel: str) -> None:
    source = REPO / ('solutions' if rel.startswith('exercises/') else 'notebooks') / \
        Path(rel).name
    marker = uuid.uuid4().hex
    done = _nbgrader('validate', str(source), cwd=copies, workspace=copies / 'ws',
                     marker=marker)
    assert PASSED in done.stdout, done.stdout[-3000:]
    assert _left_running(marker) == []


@pytest.mark.parametrize('rel', VALIDATED)
def test_validate_fails_on_the_student_copy(copies: Path, rel: str) -> None:
    copy = copies / 'student' / rel
    answers = '"solution": true' in copy.read_text()
    marker = uuid.uuid4().hex
    done = _nbgrader('validate', str(copy), cwd=copies, workspace=copies / 'ws-student',
                     marker=marker)
    if answers:  # the checks notice the missing work, and say so cell by cell
        assert FAILED in done.stdout and 'The following cell failed' in done.stdout, \
            done.stdout[-3000:]
    else:
        assert PASSED in done.stdout, done.stdout[-3000:]
    assert 'DeadKernelError' not in done.stdout + done.stderr
    assert 'Kernel died' not in done.stdout + done.stderr
    assert _left_running(marker) == []
