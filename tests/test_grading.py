"""Exercises generated from solutions, and the grader run on real submissions.

Every grading here executes a notebook in a real kernel that starts real nodes; the checks
it scores ask those nodes over DDS. Wrong submissions must lose exactly the points of the
check that catches the mistake, and a hanging or crashing submission must end with a
clear result, with no process left behind.
"""

from __future__ import annotations

import contextlib
import csv
import json
import re
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import nbformat
import psutil
import pytest
from conftest import BIN, REPO, run_cli

from robot_lab.errors import RobotLabError
from robot_lab.grading.exercises import (
    build_exercises,
    exercise_notebook,
    read_notebook,
    student_notebook,
)
from robot_lab.grading.notebook.answer_key import student_of
from robot_lab.grading.notebook.grade import TOKEN_VAR, GradeResult, grade
from robot_lab.process import spawn, stop

SOLUTIONS = sorted((REPO / 'solutions').glob('*.ipynb'))
NAMES = [p.stem for p in SOLUTIONS]


def _graded_processes(workspace: Path) -> list[str]:
    """Processes still running from a grading that used `workspace` (kernel, nodes, ...)."""
    found = []
    for proc in psutil.process_iter():
        try:
            env = proc.environ()
            if TOKEN_VAR in env and env.get('ROBOT_LAB_WORKSPACE') == str(workspace):
                found.append(f'{proc.pid} {" ".join(proc.cmdline())}')
        except psutil.Error:
            continue
    return found


def _scores(result: GradeResult) -> dict[str, float]:
    return {c.check: c.points for c in result.checks}


def _submission(tmp_path: Path, name: str, edits: dict[str, str]) -> Path:
    """The solution of `name` with some cells' sources replaced, saved as a submission."""
    nb = read_notebook(REPO / 'solutions' / f'{name}.ipynb')
    by_id = {cell['id']: cell for cell in nb.cells}
    for cell_id, source in edits.items():
        by_id[cell_id].source = source
    path = tmp_path / f'{name}.ipynb'
    path.write_text(nbformat.writes(nb) + '\n')
    return path


# --- generating exercises -------------------------------------------------------------


def _answer(source: str, cell_type: str = 'code', grade: bool = False) -> Any:
    cell = (nbformat.v4.new_code_cell(source) if cell_type == 'code'
            else nbformat.v4.new_markdown_cell(source))
    cell.metadata['nbgrader'] = {'grade': grade, 'solution': True, 'locked': False,
                                 'grade_id': f'a{abs(hash(source))}', 'schema_version': 3,
                                 **({'points': 1} if grade else {})}
    return cell


def _student_copy(tmp_path: Path, *cells: Any) -> list[str]:
    nb = nbformat.v4.new_notebook()
    nb.metadata['kernelspec'] = {'name': 'python3', 'language': 'python'}
    nb.cells = list(cells)
    (tmp_path / 'src.ipynb').write_text(nbformat.writes(nb))
    return [c.source for c in student_notebook(tmp_path / 'src.ipynb').cells]


def test_answers_become_nbgraders_stub(tmp_path: Path) -> None:
    code = 'x = 1\nif x:\n    ### BEGIN SOLUTION\n    y = x + 1\n    ### END SOLUTION\nprint(y)'
    xml = ('%%writefile a.xml\n<launch>\n<!-- ### BEGIN SOLUTION -->\n<node/>\n'
           '<!-- ### END SOLUTION -->\n</launch>')
    assert _student_copy(tmp_path, _answer(code), _answer(xml),
                         _answer('Because.', 'markdown', grade=True)) == [
        'x = 1\nif x:\n    # YOUR CODE HERE\n    raise NotImplementedError()\nprint(y)',
        '%%writefile a.xml\n<launch>\n# YOUR CODE HERE\nraise NotImplementedError()\n</launch>',
        'YOUR ANSWER HERE',
    ]


@pytest.mark.parametrize('source', [
    '### BEGIN SOLUTION\nx = 1',
    '### BEGIN SOLUTION\n### BEGIN SOLUTION\n### END SOLUTION',
])
def test_unbalanced_fences_are_refused(tmp_path: Path, source: str) -> None:
    with pytest.raises(RobotLabError, match='nbgrader refused the notebook'):
        _student_copy(tmp_path, _answer(source))


def test_answer_outside_a_solution_cell_is_refused(tmp_path: Path) -> None:
    plain = nbformat.v4.new_code_cell('### BEGIN SOLUTION\nx = 1\n### END SOLUTION')
    with pytest.raises(RobotLabError, match='non-solution cell'):
        _student_copy(tmp_path, plain)


def test_exercises_are_up_to_date_with_solutions() -> None:
    assert NAMES, 'no solutions/*.ipynb'
    done = run_cli('exercises', 'build', '--check')
    assert done.returncode == 0, done.stderr
    assert f'{len(NAMES)} exercises up to date' in done.stdout
    for path in SOLUTIONS:
        exercise = read_notebook(REPO / 'exercises' / path.name)
        assert exercise.metadata['robot_lab']['exercise'] == path.stem
        for cell in exercise.cells:
            assert 'BEGIN SOLUTION' not in cell.source, f'{path.name}: {cell["id"]}'
            if cell.cell_type == 'code':
                assert cell.outputs == [] and cell.execution_count is None
                # nbgrader's metadata on every code cell, checks locked, checksums computed
                meta = cell.metadata['nbgrader']
                assert meta['grade_id'] == cell['id'] and meta['checksum'], cell['id']
                if meta['grade']:
                    assert meta['locked'] and cell.metadata['editable'] is False


def test_check_reports_drift_and_build_fixes_it(tmp_path: Path) -> None:
    solutions, exercises = tmp_path / 'solutions', tmp_path / 'exercises'
    solutions.mkdir()
    shutil.copy(REPO / 'solutions' / 'ex04_parameters.ipynb', solutions)
    assert [r.up_to_date for r in build_exercises(solutions, exercises, check=True)] == [False]
    assert not exercises.exists()  # --check writes nothing
    assert [r.up_to_date for r in build_exercises(solutions, exercises)] == [False]
    assert [r.up_to_date for r in build_exercises(solutions, exercises, check=True)] == [True]
    # An instructor edits a solution: the exercise is stale until rebuilt.
    nb = read_notebook(solutions / 'ex04_parameters.ipynb')
    nb.cells[0].source += '\n\nA new hint.'
    (solutions / 'ex04_parameters.ipynb').write_text(nbformat.writes(nb) + '\n')
    args = ['--solutions', str(solutions), '--exercises', str(exercises)]
    stale = run_cli('exercises', 'build', '--check', *args)
    assert stale.returncode == 1
    assert 'ex04_parameters.ipynb is out of date' in stale.stderr
    assert run_cli('exercises', 'build', *args).returncode == 0
    assert 'A new hint.' in read_notebook(exercises / 'ex04_parameters.ipynb').cells[0].source
    # A solution removed: its exercise goes too.
    (solutions / 'ex04_parameters.ipynb').unlink()
    (solutions / 'other.ipynb').write_text(nbformat.writes(exercise_notebook(
        REPO / 'solutions' / 'ex04_parameters.ipynb')) + '\n')
    build_exercises(solutions, exercises)
    assert sorted(p.name for p in exercises.iterdir()) == ['other.ipynb']


# --- grading real submissions ----------------------------------------------------------


@pytest.fixture(scope='module')
def unanswered() -> Iterator[Any]:
    """Every generated exercise graded as handed out, in the background.

    Unanswered checks fail by waiting out their timeouts, so the exercises are graded three
    at a time (`-j 3`, one ROS domain per slot, well away from the test modules' domains)
    while the solutions are graded in the foreground; the last test collects the results.
    """
    # -j 3: three domains leased from the host's registry, none of the test modules'.
    proc = spawn([str(BIN / 'robot-lab'), 'grade', str(REPO / 'exercises'), '--json',
                  '-j', '3', '--timeout', '30'],
                 stderr=subprocess.DEVNULL)
    yield proc
    stop(proc)


@pytest.mark.parametrize('name', NAMES)
def test_solution_gets_full_marks(name: str, tmp_path: Path, unanswered: Any) -> None:
    result = grade(REPO / 'solutions' / f'{name}.ipynb', cell_timeout=45,
                   workspace=tmp_path / 'ws')
    assert result.status == 'completed', result.table()
    assert result.max_score > 0 and result.score == result.max_score, result.table()
    assert result.summary() == f'{name}: {result.max_score:g}/{result.max_score:g}'
    assert result.leftovers == [], result.table()
    assert _graded_processes(tmp_path / 'ws') == []
    # Student work went to the scratch workspace given to the kernel.
    assert any((tmp_path / 'ws').iterdir())


def test_controller_section_under_the_wrong_name_loses_that_check(tmp_path: Path) -> None:
    # A classic: the section is named after the executable, not the launched node name.
    wrong = (
        '%%writefile {params_file}\n'
        'sensor:\n  ros__parameters:\n    sensor_rate: 5\n    noise_level: 0.0\n'
        'controller_node:\n  ros__parameters:\n    control_rate: 20\n    temp_threshold: 22.0\n'
    )
    result = grade(_submission(tmp_path, 'ex04_parameters', {'write-params': wrong}),
                   cell_timeout=30, workspace=tmp_path / 'ws')
    assert _scores(result) == {'check-file-loads': 2, 'check-sensor-values': 3,
                               'check-controller-threshold': 0}, result.table()
    failed = result.checks[-1]
    assert failed.message.startswith('CheckError: ✗ expected /controller temp_threshold = 22.0')
    assert result.summary() == 'ex04_parameters: 5/8'


def test_node_publishing_the_wrong_type_loses_the_interface_check(tmp_path: Path) -> None:
    # The average goes out as a String: only the check of the node's interface catches it
    # (the value checks read `float(m.data)` of whatever type the node publishes).
    nb = read_notebook(REPO / 'solutions' / 'ex02_write_nodes.ipynb')
    source = next(c.source for c in nb.cells if c['id'] == 'write-node')
    wrong = (source.replace('from std_msgs.msg import Float32',
                            'from std_msgs.msg import Float32, String')
             .replace('self.create_publisher(Float32,', 'self.create_publisher(String,')
             .replace('Float32(data=sum(self.readings) / len(self.readings))',
                      'String(data=str(sum(self.readings) / len(self.readings)))'))
    assert wrong.count('String') == 3
    result = grade(_submission(tmp_path, 'ex02_write_nodes', {'write-node': wrong}),
                   cell_timeout=30, workspace=tmp_path / 'ws')
    assert _scores(result) == {'check-node-interface': 0, 'check-window-param': 2,
                               'check-live-average': 3, 'check-running-average': 3}, \
        result.table()
    assert 'expected /sensor/temperature_avg as Float32' in result.checks[0].message
    assert result.summary() == 'ex02_write_nodes: 8/10'


def test_edited_check_cell_is_replaced_by_the_solutions(tmp_path: Path) -> None:
    # The student "fixed" a failing check to pass: the solution's check cell is what runs.
    solutions = tmp_path / 'solutions'
    solutions.mkdir()
    _notebook(solutions, 'tiny', [('answer', 'x = 42', 0),
                                  ('check-x', "assert x == 42, f'x is {x}'", 2)])
    build_exercises(solutions, tmp_path / 'exercises')
    nb = read_notebook(tmp_path / 'exercises' / 'tiny.ipynb')
    nb.cells[0].source = 'x = 41'
    nb.cells[1].source = 'pass'
    nb.cells.append(nbformat.v4.new_code_cell('pass'))  # a check of their own: not counted
    nb.cells[-1].metadata['nbgrader'] = {'grade': True, 'solution': False, 'locked': True,
                                         'grade_id': 'mine', 'points': 5, 'schema_version': 3}
    path = tmp_path / 'submission.ipynb'  # any file name: the exercise is in the metadata
    path.write_text(nbformat.writes(nb) + '\n')
    result = grade(path, cell_timeout=10, solutions_dir=solutions, workspace=tmp_path / 'ws')
    assert result.exercise == 'tiny'
    assert [(c.check, c.points, c.max_points) for c in result.checks] == [('check-x', 0, 2)]
    assert result.checks[0].message == 'AssertionError: x is 41'


# --- submissions that hang, crash or leave processes ----------------------------------


def _notebook(tmp_path: Path, name: str, cells: list[tuple[str, str, int]]) -> Path:
    nb = nbformat.v4.new_notebook()
    for cell_id, source, points in cells:
        cell = nbformat.v4.new_code_cell(source)
        cell['id'] = cell_id
        answer = cell_id.startswith('answer')  # the student's to write; the rest is locked
        cell.metadata['nbgrader'] = {'grade': bool(points), 'solution': answer,
                                     'locked': not answer,
                                     'grade_id': cell_id, 'schema_version': 3,
                                     **({'points': points} if points else {})}
        nb.cells.append(cell)
    path = tmp_path / f'{name}.ipynb'
    path.write_text(nbformat.writes(nb) + '\n')
    return path


def test_hanging_cells_are_interrupted_and_stray_processes_killed(tmp_path: Path) -> None:
    sleeper = ("import subprocess, sys\n"
               "stray = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(300)'],"
               " start_new_session=True)")
    path = _notebook(tmp_path, 'hangs', [
        ('first', 'assert 1 + 1 == 2', 1),
        ('spin-forever', 'import time\nwhile True:\n    time.sleep(0.1)', 0),
        ('after-interrupt', 'assert True', 2),
        ('stray', sleeper, 0),
        ('deaf', 'import signal, time\nsignal.signal(signal.SIGINT, signal.SIG_IGN)\n'
                 'time.sleep(600)', 0),
        ('never-reached', 'assert True', 3),
    ])
    result = grade(path, cell_timeout=2, workspace=tmp_path / 'ws', solutions_dir=tmp_path)
    assert _scores(result) == {'first': 1, 'after-interrupt': 2, 'never-reached': 0}
    assert result.status == 'timeout'
    assert 'cell 4 ran past 2 s and did not stop when interrupted' in result.detail
    assert result.checks[1].passed and 'timed out' not in result.checks[1].message
    assert result.checks[-1].message.startswith('not run (timeout')
    assert result.elapsed < 30
    # The stray process (own session, no parent-death signal) was found and killed.
    assert len(result.leftovers) == 1 and 'python' in result.leftovers[0], result.leftovers
    assert _graded_processes(tmp_path / 'ws') == []
    assert result.summary() == 'hangs: 3/6'


def test_kernel_crash_is_reported(tmp_path: Path) -> None:
    path = _notebook(tmp_path, 'crashes', [
        ('first', 'assert True', 1),
        ('crash', 'import os, signal\nos.kill(os.getpid(), signal.SIGKILL)', 0),
        ('second', 'assert True', 1),
    ])
    result = grade(path, cell_timeout=20, workspace=tmp_path / 'ws', solutions_dir=tmp_path)
    assert result.status == 'kernel died', result.table()
    assert result.detail.startswith('the kernel died while running cell 1')
    assert _scores(result) == {'first': 1, 'second': 0}
    assert result.elapsed < 20


def test_whole_notebook_time_is_bounded(tmp_path: Path) -> None:
    path = _notebook(tmp_path, 'slow', [
        ('first', 'assert True', 1),
        ('slow', 'import time\ntime.sleep(60)', 0),
        ('second', 'assert True', 1),
    ])
    result = grade(path, cell_timeout=30, total_timeout=5, workspace=tmp_path / 'ws',
                   solutions_dir=tmp_path)
    assert result.status == 'timeout', result.table()
    assert result.detail.startswith('the notebook ran past 5 s in total, before cell 2')
    assert _scores(result) == {'first': 1, 'second': 0}
    assert result.elapsed < 12


def test_grade_cli_prints_table_and_json(tmp_path: Path) -> None:
    _notebook(tmp_path, 'tiny', [('ok', 'assert True', 2),
                                        ('bad', "assert 2 + 2 == 5, 'arithmetic'", 3)])
    # a folder of one submission, graded against itself as the instructor's copy
    as_json = run_cli('grade', str(tmp_path), '--json', '--solutions', str(tmp_path))
    assert as_json.returncode == 0, as_json.stderr
    data = json.loads(as_json.stdout)
    assert data['score'] == 2 and data['max_score'] == 5
    assert [c['passed'] for c in data['checks']] == [True, False]
    assert data['checks'][1]['message'] == 'AssertionError: arithmetic'
    table = GradeResult.from_dict(data).table().splitlines()
    assert table[-1] == 'tiny: 2/5'
    assert table[-2].split() == ['bad', '0/3', 'AssertionError:', 'arithmetic']


def test_unanswered_exercises_score_zero(unanswered: Any) -> None:
    started: list[Any] = []
    with contextlib.suppress(psutil.Error):  # graders, kernels and nodes running now
        started = psutil.Process(unanswered.pid).children(recursive=True)
    out, _ = unanswered.communicate(timeout=120)
    assert unanswered.returncode == 0
    results = {r['exercise']: r for r in json.loads(out)}
    assert sorted(results) == NAMES
    for name, result in results.items():
        assert result['status'] == 'completed', (name, result['detail'])
        assert result['checks'] and result['score'] == 0, (name, result['checks'])
        assert all(c['message'] for c in result['checks']), (name, result['checks'])
        # a message that helps: no Python error from a missing answer or a kit call
        raw = [c['message'] for c in result['checks']
               if c['message'].startswith(('NameError', 'TypeError', 'GraphError', 'BagError'))]
        assert raw == [], (name, raw)
        assert result['leftovers'] == [], (name, result['leftovers'])
    assert [p for p in started if p.is_running() and p.status() != psutil.STATUS_ZOMBIE] == []


# --- forgeries: a submission that answers nothing earns nothing --------------------------

_PATCH_HELPERS = ('# forged: every checking helper passes\n'
                  'import robot_lab.grading.check as helpers\n'
                  'for name in helpers.__all__:\n'
                  '    if name != "CheckError":\n'
                  '        setattr(helpers, name, lambda *args, **kwargs: None)\n')
_SWALLOW = ('# forged: IPython swallows every error\n'
            'import sys\n'
            'get_ipython().set_custom_exc((BaseException,), lambda *args, **kwargs: None)\n'
            'sys.excepthook = lambda *args: None\n')


def _forge(exercise: Path, first_cell: str = '', checks: str | None = None,
           strip: bool = False, rename: str | None = None) -> Any:
    """The handed-out exercise, answering nothing, with one kind of forgery."""
    nb = read_notebook(exercise)
    if first_cell:
        nb.cells.insert(0, nbformat.v4.new_code_cell(first_cell))
    for cell in nb.cells:
        if checks is not None and cell.get('metadata', {}).get('nbgrader', {}).get('grade'):
            cell.source = checks
        if strip:
            cell.metadata = {}
    if strip:
        nb.metadata.pop('robot_lab', None)
    if rename:
        nb.metadata['robot_lab']['exercise'] = rename
    return nb


def test_forgeries_score_what_an_unanswered_exercise_scores(tmp_path: Path) -> None:
    # A tiny exercise (no ROS, fast) and the real ex04, whose checks ask running nodes.
    solutions = tmp_path / 'solutions'
    solutions.mkdir()
    shutil.copy(REPO / 'solutions' / 'ex04_parameters.ipynb', solutions)
    _notebook(solutions, 'tiny', [
        ('setup', 'from robot_lab.grading import check', 0),
        ('answer', '### BEGIN SOLUTION\nx = 42\n### END SOLUTION', 0),
        ('check-helper', "check.eventually(lambda: x == 42, 'x is 42', timeout=0.2)", 2),
        ('check-assert', "assert x == 42, 'x is not 42'", 3),
    ])
    build_exercises(solutions, tmp_path / 'exercises')
    tiny = tmp_path / 'exercises' / 'tiny.ipynb'
    ex04 = tmp_path / 'exercises' / 'ex04_parameters.ipynb'
    forged = {
        # Both at once: either defence failing alone would give marks.
        'patch-and-swallow/ex04_parameters': _forge(ex04, _PATCH_HELPERS + _SWALLOW),
        'patch-helpers/tiny': _forge(tiny, _PATCH_HELPERS),
        'swallow-errors/tiny': _forge(tiny, _SWALLOW),
        'checks-pass/tiny': _forge(tiny, checks='pass'),
        'stripped/tiny': _forge(tiny, checks='pass', strip=True),
        'renamed/tiny': _forge(tiny, checks='pass', rename='tiny_v2'),
        'model/tiny': read_notebook(solutions / 'tiny.ipynb'),  # the answer: full marks
    }
    class_dir = tmp_path / 'class'
    for name, nb in forged.items():
        (class_dir / name).parent.mkdir(parents=True, exist_ok=True)
        (class_dir / f'{name}.ipynb').write_text(nbformat.writes(nb) + '\n')
    done = run_cli('grade', str(class_dir), '--json', '-j', '2', '--solutions', str(solutions),
                   '--timeout', '20',
                   '--executed', str(tmp_path / 'executed'), '-o', str(tmp_path / 'out'),
                   timeout=300)
    # One notebook was refused: the grader ran (exit 0, the rule of labs too) and stderr
    # names it.
    assert done.returncode == 0, done.stderr
    assert 'could not grade' in done.stderr and 'renamed' in done.stderr, done.stderr
    results = {f'{r["student"]}/{r["exercise"]}': r for r in json.loads(done.stdout)}
    assert sorted(results) == sorted(forged), sorted(results)
    assert results.pop('model/tiny')['score'] == 5
    for name, r in results.items():
        assert r['score'] == 0, (name, r['checks'])
        if name == 'renamed/tiny':
            assert r['status'] == 'error' and r['checks'] == []
            assert "refused: its metadata names exercise 'tiny_v2'" in r['detail']
        else:
            assert r['status'] == 'completed' and r['max_score'] > 0, (name, r['detail'])
    # The checks ran the real helpers and said why they failed.
    messages = [c['message'] for c in results['patch-and-swallow/ex04_parameters']['checks']]
    assert messages[0].startswith('CheckError: ✗ expected robot_params.yaml'), messages
    swallowed = [c['message'] for c in results['swallow-errors/tiny']['checks']]
    assert swallowed == ["NameError: name 'x' is not defined"] * 2, swallowed
    # One executed notebook per student, named after the exercise.
    kept = sorted(str(p.relative_to(tmp_path / 'executed'))
                  for p in (tmp_path / 'executed').rglob('*.ipynb'))
    assert kept == sorted(f'{n}.graded.ipynb' for n in forged if n != 'renamed/tiny'), kept
    # -o OUT: the gradebook, feedback and Gradescope results, one per student.
    with (tmp_path / 'out' / 'grades.csv').open() as f:
        rows = {row['student']: row for row in csv.DictReader(f)}
    assert sorted(rows) == sorted(name.split('/')[0] for name in forged)
    assert rows['model'] == {'student': 'model', 'score': '5', 'max_score': '5',
                             'tiny/check-helper': '2', 'tiny/check-assert': '3',
                             'ex04_parameters/check-file-loads': '0',
                             'ex04_parameters/check-sensor-values': '0',
                             'ex04_parameters/check-controller-threshold': '0'}
    assert rows['renamed']['score'] == 'not graded'  # refused: a row that says so
    assert {row['score'] for name, row in rows.items()
            if name not in ('model', 'renamed')} == {'0'}
    for student, row in rows.items():
        feedback = (tmp_path / 'out' / 'feedback' / f'{student}.md').read_text()
        assert feedback.startswith(f'# Feedback for {student}')
        if student == 'renamed':
            continue
        columns = [float(v) for k, v in row.items() if k not in ('student', 'score',
                                                                  'max_score')]
        assert float(row['score']) == sum(columns)  # the total is its columns' sum
        gradescope = json.loads((tmp_path / 'out' / 'results' / f'{student}.json').read_text())
        assert gradescope['score'] == float(rows[student]['score'])
    assert "refused: its metadata names exercise 'tiny_v2'" in (
        tmp_path / 'out' / 'feedback' / 'renamed.md').read_text()
    assert 'x is 42' in (tmp_path / 'out' / 'feedback' / 'model.md').read_text()


_MACHINE_PATH = re.compile(r'(?<![\w.~])/(root|home|tmp|work|Users|var/folders)/')
_EMAIL = re.compile(r'[\w.+-]+@(?!example\.(com|org|net)\b)[\w-]+(\.[\w-]+)+')


@pytest.mark.parametrize('path', [*SOLUTIONS, *sorted((REPO / 'exercises').glob('*.ipynb'))],
                         ids=lambda p: f'{p.parent.name}/{p.name}')
def test_committed_notebooks_hold_no_machine_paths_or_emails(path: Path) -> None:
    # What a run left in the file must not show where it ran or who ran it. Placeholder
    # addresses in reserved example domains (RFC 2606, package.xml's maintainer) are fine.
    text = path.read_text()
    assert not _MACHINE_PATH.search(text), _MACHINE_PATH.search(text)
    assert not _EMAIL.search(text), _EMAIL.search(text)


@pytest.mark.parametrize(('path', 'student'), [
    ('class/alice/ex04_parameters.ipynb', 'alice'),
    ('class/alice_ex04_parameters.ipynb', 'alice'),
    ('course/submitted/bob/week4/ex04_parameters.ipynb', 'bob'),  # nbgrader
    ('dl/Jane Doe_1234567_assignsubmission_file_/ex04_parameters.ipynb', 'Jane Doe_1234567'),
    ('dl/doejane_12345_67890_ex04_parameters.ipynb', 'doejane'),  # Canvas
])
def test_student_id_comes_from_the_file_or_folder_name(path: str, student: str) -> None:
    assert student_of(path, 'ex04_parameters') == student
