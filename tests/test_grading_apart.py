"""Grading keeps students apart and its totals honest.

- `robot-lab grade` runs every notebook in a fresh folder and a domain leased from the
  host's registry (never the instructor's, never a user's, never 0..N-1);
- under nbgrader's autograder (NBGRADER_EXECUTION=autograde) a lesson's set-up gives the
  kernel a new workspace and a leased domain, both gone when it ends;
- a folder holding a student's exercise twice (an nbgrader course) is refused in one line;
  a refused notebook is a "not graded" row and a line on stderr; the grader ran, so exit 0
  (one rule for notebooks and labs).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from conftest import BIN, JOB_POOLS, run_cli

from robot_lab.domain import JOB_POOL_VARIABLE, job_pool
from robot_lab.grading.notebook.batch import grade_many

ANSWER = ("import os, pathlib\n"
          "### BEGIN SOLUTION\n"
          "pathlib.Path(os.environ['ROBOT_LAB_WORKSPACE'], 'answer.txt').write_text('42')\n"
          "### END SOLUTION\n")
CHECK = ("import os, pathlib\n"
         "assert pathlib.Path(os.environ['ROBOT_LAB_WORKSPACE'], 'answer.txt').exists(), "
         "'no answer.txt in your workspace'\n")


def _cell(source: str, grade_id: str, *, solution: bool = False, points: int = 0) -> object:
    cell = nbformat.v4.new_code_cell(source)
    cell.metadata['nbgrader'] = {'grade': bool(points), 'solution': solution,
                                 'locked': not solution, 'grade_id': grade_id,
                                 'schema_version': 3, **({'points': points} if points else {})}
    return cell


def _write(path: Path, cells: list[object]) -> Path:
    nb = nbformat.v4.new_notebook()
    nb.metadata['kernelspec'] = {'name': 'python3', 'language': 'python',
                               'display_name': 'Python 3'}
    nb.cells = cells
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(nbformat.writes(nb) + '\n')
    return path


@pytest.fixture
def registry(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A registry of this test's own, where a user already holds the first job domain (of
    the part of 215-232 kept for this module: tests/conftest.py)."""
    monkeypatch.setenv(JOB_POOL_VARIABLE, JOB_POOLS['grading_apart'])
    path = tmp_path / 'registry' / 'domains.json'
    path.parent.mkdir()
    path.write_text(json.dumps({'users': {'4242': {'domain': job_pool()[0], 'name': 'u'}},
                                'leases': {}}))
    monkeypatch.setenv('ROBOT_LAB_DOMAIN_REGISTRY', str(path))
    monkeypatch.setenv('ROBOT_LAB_USER_DOMAINS', f'{job_pool()[0]}-{job_pool()[0]}')
    return path


def test_each_notebook_gets_a_leased_domain_and_a_fresh_folder(tmp_path: Path,
                                                              registry: Path) -> None:
    solutions = tmp_path / 'solutions'
    _write(solutions / 'tiny.ipynb', [_cell(ANSWER, 'answer', solution=True),
                                      _cell(CHECK, 'check', points=1)])
    alice = _write(tmp_path / 'class' / 'alice' / 'tiny.ipynb',
                   [_cell(ANSWER, 'answer', solution=True), _cell(CHECK, 'check', points=1)])
    # bob deleted the answer cell: graded after alice, he must not find her file.
    bob = _write(tmp_path / 'class' / 'bob' / 'tiny.ipynb', [_cell(CHECK, 'check', points=1)])
    one_by_one = grade_many([alice, bob], jobs=1, solutions_dir=solutions, cell_timeout=30)
    assert [(r.student, r.score) for r in one_by_one] == [('alice', 1), ('bob', 0)]
    assert 'no answer.txt' in one_by_one[1].checks[0].message
    at_once = grade_many([alice, bob], jobs=2, solutions_dir=solutions, cell_timeout=30)
    assert [(r.student, r.score) for r in at_once] == [('alice', 1), ('bob', 0)]
    domains = [r.domain for r in at_once]
    assert len(set(domains)) == 2, domains  # one each, at the same time
    taken = job_pool()[0]  # a user's: never graded in
    for r in [*one_by_one, *at_once]:
        assert r.domain in job_pool() and r.domain != taken, r.domain
    assert json.loads(registry.read_text())['leases'] == {}  # all given back


SETUP = """
import sys
from robot_lab.grading import setup
lesson = setup('ex04_parameters')
print(lesson.domain_id, lesson.workspace, flush=True)
sys.stdin.readline()
"""


def test_autograded_kernels_get_their_own_domain_and_workspace(tmp_path: Path,
                                                              registry: Path) -> None:
    instructor = tmp_path / 'robot_lab_ws'
    env = dict(os.environ, NBGRADER_EXECUTION='autograde', ROS_DOMAIN_ID='5',
               ROBOT_LAB_WORKSPACE=str(instructor))
    env.pop('ROBOT_LAB_NOTEBOOK_DOMAIN_BASE', None)
    kernels = [subprocess.Popen([str(BIN / 'python'), '-c', SETUP], env=env, text=True,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE)
               for _ in range(2)]
    seen = []
    for kernel in kernels:
        assert kernel.stdout is not None
        domain, workspace = kernel.stdout.readline().split()
        seen.append((int(domain), Path(workspace)))
    leases = json.loads(registry.read_text())['leases']
    for kernel in kernels:
        kernel.communicate('\n', timeout=30)
        assert kernel.returncode == 0
    (d1, w1), (d2, w2) = seen
    assert d1 != d2 and {d1, d2} <= set(job_pool()[1:]), seen
    assert sorted(int(d) for d in leases) == sorted([d1, d2])
    assert w1 != w2 and instructor not in (w1, w2)
    assert not w1.exists() and not w2.exists()  # removed with the kernel
    assert json.loads(registry.read_text())['leases'] == {}


def test_copies_of_a_student_or_a_course_folder_are_refused(tmp_path: Path) -> None:
    course = tmp_path / 'course'
    (course / 'source' / 'tiny').mkdir(parents=True)
    (course / 'nbgrader_config.py').write_text('c = get_config()\n')
    solutions = tmp_path / 'solutions'
    _write(solutions / 'tiny.ipynb', [_cell(CHECK, 'check', points=1)])
    for folder in ('submitted', 'autograded'):
        _write(course / folder / 'alice' / 'tiny' / 'tiny.ipynb', [_cell(CHECK, 'check', points=1)])
    done = run_cli('grade', str(course), '--solutions', str(solutions))
    assert done.returncode == 1 and done.stdout == ''
    [line] = done.stderr.splitlines()
    assert 'nbgrader course folder' in line and f'{course}/submitted' in line
    done = run_cli('grade', str(course / 'submitted'), str(course / 'autograded'),
                   '--solutions', str(solutions))
    assert done.returncode == 1 and done.stdout == ''
    [line] = done.stderr.splitlines()
    assert 'alice has two copies of tiny' in line


def test_a_refused_notebook_is_a_not_graded_row_and_exit_0(tmp_path: Path) -> None:
    solutions = tmp_path / 'solutions'
    _write(solutions / 'tiny.ipynb', [_cell(CHECK, 'check', points=1)])
    _write(tmp_path / 'class' / 'dave' / 'mine.ipynb', [_cell(CHECK, 'check', points=1)])
    done = run_cli('grade', str(tmp_path / 'class'), '--solutions', str(solutions),
                   '-o', str(tmp_path / 'out'))
    assert done.returncode == 0, done.stderr
    assert 'could not grade' in done.stderr and 'mine.ipynb' in done.stderr
    rows = (tmp_path / 'out' / 'grades.csv').read_text().splitlines()
    assert rows[1].startswith('dave,not graded,'), rows


if __name__ == '__main__':  # pragma: no cover
    sys.exit(pytest.main([__file__, '-q']))


PATH_CHECK = ("import os, pathlib, robot_lab\n"
              "robot_lab.load_param_file(pathlib.Path(os.environ['ROBOT_LAB_WORKSPACE'], "
              "'config', 'robot_params.yaml'))\n")


def test_feedback_pages_list_each_check_once_wrapped_without_machine_paths(
        tmp_path: Path) -> None:
    solutions = tmp_path / 'solutions'
    cells = [_cell(CHECK, 'check', points=1), _cell(PATH_CHECK, 'check-params', points=2)]
    _write(solutions / 'tiny.ipynb', cells)
    _write(tmp_path / 'class' / 'erin' / 'tiny.ipynb', cells)
    done = run_cli('grade', str(tmp_path / 'class'), '--solutions', str(solutions),
                   '-o', str(tmp_path / 'out'), timeout=120)
    assert done.returncode == 0, done.stderr
    page = (tmp_path / 'out' / 'feedback' / 'erin.html').read_text()
    markdown = (tmp_path / 'out' / 'feedback' / 'erin.md').read_text()
    assert markdown.count('check-params') == 1 and markdown.count('## check —') == 1
    assert markdown.count('## ') == 2  # one section per check, no table repeating them
    assert 'white-space:pre-wrap' in page  # long lines wrap
    assert '~/robot_lab_ws/config/robot_params.yaml' in page  # the student's path
    for leak in ('/tmp/', str(Path(__file__).resolve().parent.parent), 'Traceback'):
        assert leak not in page, leak
