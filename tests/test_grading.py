"""Exercises generated from solutions, and the grader run on real submissions.

Every grading here executes a notebook in a real kernel that starts real nodes; the checks
it scores ask those nodes over DDS. Wrong submissions must lose exactly the points of the
check that catches the mistake, and a hanging or crashing submission must end with a
clear result, with no process left behind.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import nbformat
import psutil
import pytest
from conftest import REPO, run_cli

from robot_lab.errors import RobotLabError
from robot_lab.grading.exercises import (
    build_exercises,
    exercise_notebook,
    read_notebook,
    strip_solution,
)
from robot_lab.grading.grade import TOKEN_VAR, GradeResult, grade

SOLUTIONS = sorted((REPO / 'solutions').glob('*.ipynb'))
NAMES = [p.stem for p in SOLUTIONS]


def _graded_processes() -> list[str]:
    """Processes still carrying a grading token (started by some graded kernel)."""
    found = []
    for proc in psutil.process_iter():
        try:
            if TOKEN_VAR in proc.environ():
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


def test_fences_become_placeholders() -> None:
    code = 'x = 1\nif x:\n    # BEGIN SOLUTION\n    y = x + 1\n    # END SOLUTION\nprint(y)'
    assert strip_solution('code', code) == (
        'x = 1\nif x:\n    # YOUR CODE HERE\n    raise NotImplementedError()\nprint(y)')
    xml = '%%writefile a.xml\n<launch>\n<!-- BEGIN SOLUTION -->\n<node/>\n<!-- END SOLUTION -->'
    assert strip_solution('code', xml) == '%%writefile a.xml\n<launch>\n<!-- YOUR CODE HERE -->'
    yaml_cell = '%%writefile p.yaml\n# BEGIN SOLUTION\na: 1\n# END SOLUTION'
    assert strip_solution('code', yaml_cell) == '%%writefile p.yaml\n# YOUR CODE HERE'
    text = 'Why?\n<!-- BEGIN SOLUTION -->\nBecause.\n<!-- END SOLUTION -->'
    assert strip_solution('markdown', text) == 'Why?\n_YOUR ANSWER HERE_'
    # Text that merely mentions the fence is left alone.
    assert strip_solution('code', "print('BEGIN SOLUTION')") == "print('BEGIN SOLUTION')"


@pytest.mark.parametrize('source', [
    '# BEGIN SOLUTION\nx = 1',
    'x = 1\n# END SOLUTION',
    '# BEGIN SOLUTION\n# BEGIN SOLUTION\n# END SOLUTION',
])
def test_unbalanced_fences_are_refused(source: str) -> None:
    with pytest.raises(RobotLabError, match='SOLUTION'):
        strip_solution('code', source, where='ex.ipynb (cell 3)')


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


def test_check_reports_drift_and_build_fixes_it(tmp_path: Path) -> None:
    solutions, exercises = tmp_path / 'solutions', tmp_path / 'exercises'
    solutions.mkdir()
    shutil.copy(REPO / 'solutions' / 'ex04_parameters.ipynb', solutions)
    args = ['--solutions', str(solutions), '--exercises', str(exercises)]
    assert run_cli('exercises', 'build', '--check', *args).returncode == 1  # nothing built yet
    assert run_cli('exercises', 'build', *args).returncode == 0
    assert run_cli('exercises', 'build', '--check', *args).returncode == 0
    # An instructor edits a solution: the exercise is stale until rebuilt.
    nb = read_notebook(solutions / 'ex04_parameters.ipynb')
    nb.cells[0].source += '\n\nA new hint.'
    (solutions / 'ex04_parameters.ipynb').write_text(nbformat.writes(nb) + '\n')
    stale = run_cli('exercises', 'build', '--check', *args)
    assert stale.returncode == 1
    assert 'ex04_parameters.ipynb is out of date' in stale.stderr
    assert [r.up_to_date for r in build_exercises(solutions, exercises)] == [False]
    assert 'A new hint.' in read_notebook(exercises / 'ex04_parameters.ipynb').cells[0].source
    # A solution removed: its exercise goes too.
    (solutions / 'ex04_parameters.ipynb').unlink()
    (solutions / 'other.ipynb').write_text(nbformat.writes(exercise_notebook(
        REPO / 'solutions' / 'ex04_parameters.ipynb')) + '\n')
    build_exercises(solutions, exercises)
    assert sorted(p.name for p in exercises.iterdir()) == ['other.ipynb']


# --- grading real submissions ----------------------------------------------------------


@pytest.mark.parametrize('name', NAMES)
def test_solution_gets_full_marks(name: str, tmp_path: Path) -> None:
    result = grade(REPO / 'solutions' / f'{name}.ipynb', cell_timeout=45,
                   workspace=tmp_path / 'ws')
    assert result.status == 'completed', result.table()
    assert result.max_score > 0 and result.score == result.max_score, result.table()
    assert result.summary() == f'{name}: {result.max_score:g}/{result.max_score:g}'
    assert result.leftovers == [], result.table()
    assert _graded_processes() == []
    # Student work went to the scratch workspace given to the kernel.
    assert any((tmp_path / 'ws').iterdir())


@pytest.mark.parametrize('name', NAMES)
def test_unanswered_exercise_scores_zero(name: str, tmp_path: Path) -> None:
    result = grade(REPO / 'exercises' / f'{name}.ipynb', cell_timeout=30,
                   workspace=tmp_path / 'ws')
    assert result.status == 'completed', result.table()
    assert result.checks and result.score == 0, result.table()
    assert all(c.message for c in result.checks), result.table()
    assert result.leftovers == [] and _graded_processes() == []


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
    assert 'temp_threshold=25.0; expected 22.0' in failed.message
    assert result.summary() == 'ex04_parameters: 5/8'


def test_flat_file_loses_every_check_with_rcls_reason(tmp_path: Path) -> None:
    flat = '%%writefile {params_file}\nsensor_rate: 5\nnoise_level: 0.0\ntemp_threshold: 22.0\n'
    result = grade(_submission(tmp_path, 'ex04_parameters', {'write-params': flat}),
                   cell_timeout=30, workspace=tmp_path / 'ws')
    assert result.score == 0, result.table()
    assert 'Cannot have a value before ros__parameters at line 1' in result.checks[0].message


def test_edited_check_cell_is_replaced_by_the_solutions(tmp_path: Path) -> None:
    # Unanswered, but the student "fixed" a check to pass: the solution's check is run.
    nb = read_notebook(REPO / 'exercises' / 'ex04_parameters.ipynb')
    for cell in nb.cells:
        if cell['id'] == 'check-file-loads':
            cell.source = 'pass'
    path = tmp_path / 'ex04_parameters.ipynb'
    path.write_text(nbformat.writes(nb) + '\n')
    result = grade(path, cell_timeout=30, workspace=tmp_path / 'ws')
    assert _scores(result)['check-file-loads'] == 0, result.table()


# --- submissions that hang, crash or leave processes ----------------------------------


def _notebook(tmp_path: Path, name: str, cells: list[tuple[str, str, int]]) -> Path:
    nb = nbformat.v4.new_notebook()
    for cell_id, source, points in cells:
        cell = nbformat.v4.new_code_cell(source)
        cell['id'] = cell_id
        if points:
            cell.metadata['tags'] = ['grade']
            cell.metadata['robot_lab'] = {'points': points}
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
    result = grade(path, cell_timeout=3, workspace=tmp_path / 'ws')
    assert _scores(result) == {'first': 1, 'after-interrupt': 2, 'never-reached': 0}
    assert result.status == 'timeout'
    assert 'cell 4 ran past 3 s and did not stop when interrupted' in result.detail
    assert result.checks[-1].message.startswith('not run (timeout')
    assert result.elapsed < 30
    # The stray process (own session, no parent-death signal) was found and killed.
    assert len(result.leftovers) == 1 and 'python' in result.leftovers[0], result.leftovers
    assert _graded_processes() == []
    assert result.summary() == 'hangs: 3/6'


def test_kernel_crash_is_reported(tmp_path: Path) -> None:
    path = _notebook(tmp_path, 'crashes', [
        ('first', 'assert True', 1),
        ('crash', 'import os, signal\nos.kill(os.getpid(), signal.SIGKILL)', 0),
        ('second', 'assert True', 1),
    ])
    result = grade(path, cell_timeout=20, workspace=tmp_path / 'ws')
    assert result.status == 'kernel died'
    assert result.detail.startswith('the kernel died while running cell 1')
    assert _scores(result) == {'first': 1, 'second': 0}
    assert result.elapsed < 20


def test_grade_cli_prints_table_and_json(tmp_path: Path) -> None:
    path = _notebook(tmp_path, 'tiny', [('ok', 'assert True', 2),
                                        ('bad', "assert 2 + 2 == 5, 'arithmetic'", 3)])
    shown = run_cli('grade', str(path))
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.splitlines()[-1] == 'tiny: 2/5'
    assert 'AssertionError: arithmetic' in shown.stdout
    as_json = run_cli('grade', str(tmp_path), '--json')
    import json

    data = json.loads(as_json.stdout)
    assert data['score'] == 2 and data['max_score'] == 5
    assert [c['passed'] for c in data['checks']] == [True, False]
    assert os.environ.get(TOKEN_VAR) is None
