"""The student's copy of the course: answers removed, checks kept, trusted, example outputs
of the cells no answer reaches (written as the student's machine prints them), no nbval
markers, and a student's changes never overwritten by the next release."""

from __future__ import annotations

import json
import re
import shutil
import sys
from pathlib import Path

import nbformat
import pytest
from conftest import REPO, run_cli
from nbformat.sign import NotebookNotary

from robot_lab.grading.exercises import read_notebook
from robot_lab.grading.release import (
    MANIFEST,
    keeps_output,
    release_course,
    sanitise_output,
    student_course_notebook,
)

SOURCES = {
    **{f'notebooks/{p.name}': p for p in sorted((REPO / 'notebooks').glob('*.ipynb'))},
    **{f'exercises/{p.name}': p for p in sorted((REPO / 'solutions').glob('*.ipynb'))},
}
_FENCE = re.compile(r'(BEGIN|END) SOLUTION')


def _answer_lines(nb: nbformat.NotebookNode) -> set[str]:
    """Lines between the solution fences, and whole answer cells, found nowhere else."""
    answers: set[str] = set()
    elsewhere: set[str] = set()
    for cell in nb.cells:
        meta = cell.get('metadata', {}).get('nbgrader', {})
        inside = meta.get('solution') and not _FENCE.search(cell.source)
        for line in cell.source.split('\n'):
            if _FENCE.search(line):
                inside = not inside
                continue
            (answers if inside else elsewhere).add(line.strip())
    return {line for line in answers - elsewhere if len(line) >= 12}


@pytest.fixture(scope='module')
def released(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The kit's course released once, signed in a Jupyter data dir of the test's own."""
    dest = tmp_path_factory.mktemp('student')
    with pytest.MonkeyPatch.context() as env:
        env.setenv('JUPYTER_DATA_DIR', str(dest.parent / 'jupyter-data'))
        results = release_course(dest)
    assert sorted(str(r.path) for r in results) == sorted(SOURCES)
    assert {r.action for r in results} == {'new'}
    return dest


@pytest.mark.parametrize('rel', sorted(SOURCES))
def test_release_removes_answers_and_keeps_checks(released: Path, rel: str) -> None:
    # imported here: nbgrader.utils loads nbgrader's server and exchange (3 s), which every
    # worker would pay at collection
    from nbgrader.utils import compute_checksum  # type: ignore[import-untyped]

    source, copy = read_notebook(SOURCES[rel]), read_notebook(released / rel)
    text = (released / rel).read_text()
    lines = {line.strip() for cell in copy.cells for line in cell.source.split('\n')}
    leaked = sorted(_answer_lines(source) & lines)
    assert leaked == [], f'{rel}: answer lines in the student copy: {leaked[:3]}'
    assert 'BEGIN SOLUTION' not in text
    checks = {c['id']: c.source for c in source.cells
              if c.get('metadata', {}).get('nbgrader', {}).get('grade')
              and c.cell_type == 'code'}
    # The checks as written, minus nbval's markers (the kit's test harness, not the lesson).
    assert {c['id']: c.source for c in copy.cells if c['id'] in checks} == {
        key: re.sub(r'^# NBVAL_\w+\n', '', value, flags=re.M) for key, value in checks.items()}
    assert 'NBVAL' not in text
    for cell in copy.cells:  # nbgrader validate would call a locked cell "changed" otherwise
        meta = cell.get('metadata', {}).get('nbgrader', {})
        if meta.get('checksum'):
            assert meta['checksum'] == compute_checksum(cell), cell['id']
    notary = NotebookNotary(data_dir=str(released.parent / 'jupyter-data'))
    assert notary.check_signature(copy), f'{rel} would open as "not trusted"'


def _course(root: Path, names: list[str]) -> Path:
    (root / 'notebooks').mkdir(parents=True)
    (root / 'solutions').mkdir()
    for name in names:
        shutil.copy(REPO / 'solutions' / name, root / 'solutions' / name)
    return root


def test_release_again_adds_new_updates_untouched_and_keeps_student_changes(
        tmp_path: Path) -> None:
    course = _course(tmp_path / 'course', ['ex04_parameters.ipynb', 'ex06_ros_bags.ipynb'])
    student = tmp_path / 'student'
    env = {'JUPYTER_DATA_DIR': str(tmp_path / 'jupyter-data')}
    first = run_cli('course', 'release', str(student), '--course', str(course), env=env)
    assert first.returncode == 0, first.stderr
    assert first.stdout.splitlines() == [
        'new      exercises/ex04_parameters.ipynb', 'new      exercises/ex06_ros_bags.ipynb',
        f'2 notebooks in {student}: 2 new']
    # The student works on ex04; the instructor then edits both sources and adds one.
    mine = student / 'exercises' / 'ex04_parameters.ipynb'
    nb = read_notebook(mine)
    nb.cells[0].source += '\n\nMy notes.'
    mine.write_text(nbformat.writes(nb) + '\n')
    for name in ('ex04_parameters.ipynb', 'ex06_ros_bags.ipynb'):
        source = read_notebook(course / 'solutions' / name)
        source.cells[0].source += '\n\nA clearer task.'
        (course / 'solutions' / name).write_text(nbformat.writes(source) + '\n')
    shutil.copy(REPO / 'solutions' / 'ex01_create_package.ipynb', course / 'solutions')
    results = {str(r.path): r.action for r in release_course(student, course, sign=False)}
    assert results == {'exercises/ex01_create_package.ipynb': 'new',
                       'exercises/ex04_parameters.ipynb': 'kept',
                       'exercises/ex06_ros_bags.ipynb': 'updated'}
    assert 'My notes.' in mine.read_text() and 'A clearer task.' not in mine.read_text()
    assert 'A clearer task.' in (student / 'exercises' / 'ex06_ros_bags.ipynb').read_text()
    # Released again: nothing is written, and ex04's newer version is still not given.
    again = run_cli('course', 'release', str(student), '--course', str(course), env=env)
    assert again.stdout.splitlines() == [
        'kept     exercises/ex04_parameters.ipynb  (you changed it; delete it and release '
        'again for the new version)', f'3 notebooks in {student}: 2 unchanged, 1 kept']
    assert 'My notes.' in mine.read_text()
    record = json.loads((student / MANIFEST).read_text())
    assert sorted(record['files']) == sorted(results)


def test_release_of_a_folder_without_a_course_is_refused(tmp_path: Path) -> None:
    done = run_cli('course', 'release', str(tmp_path / 'out'), '--course', str(tmp_path))
    assert done.returncode == 1
    assert done.stderr.strip() == (f'{tmp_path}: no notebooks/ or solutions/ folder here — '
                                   "fix: give the course repository's folder")


# --- example outputs: only where no answer can show, as the student's machine prints them ---

def _code_ids(nb: nbformat.NotebookNode, **nbgrader: bool) -> set[str]:
    return {c['id'] for c in nb.cells if c.cell_type == 'code' and all(
        bool(c.get('metadata', {}).get('nbgrader', {}).get(k)) == v for k, v in nbgrader.items())}


@pytest.mark.parametrize('rel', sorted(r for r in SOURCES if r.startswith('notebooks/')))
def test_copy_keeps_the_outputs_no_answer_reaches(released: Path, rel: str) -> None:
    source, copy = read_notebook(SOURCES[rel]), read_notebook(released / rel)
    shown = {c['id'] for c in copy.cells if c.cell_type == 'code' and c.get('outputs')}
    # Never an answer's output nor a graded check's, nor anything after the first answer.
    assert not shown & (_code_ids(source, solution=True) | _code_ids(source, grade=True))
    first_answer = next((i for i, c in enumerate(source.cells)
                         if c.get('metadata', {}).get('nbgrader', {}).get('solution')),
                        len(source.cells))
    after = {c['id'] for c in source.cells[first_answer:]}
    assert not shown & after, f'{rel}: outputs after the first answer: {shown & after}'
    assert shown <= keeps_output(source)
    # The source's own outputs, as printed on the student's machine.
    by_id = {c['id']: c for c in source.cells}
    for cell in copy.cells:
        if cell['id'] not in shown:
            continue
        mine = [''.join(o.get('text', '')) for o in cell.outputs if 'text' in o]
        theirs = [sanitise_output(''.join(o.get('text', ''))) for o in by_id[cell['id']].outputs
                  if 'text' in o]
        assert mine == theirs, cell['id']
    outputs = json.dumps([c.get('outputs', []) for c in copy.cells])
    for leak in (str(Path.home()) + '/', '/home/', '/root/', '.venv', sys.prefix):
        assert leak not in outputs, f'{rel}: {leak!r} in an output'


def test_every_lesson_shows_what_to_expect(released: Path) -> None:
    """Each course notebook shows at least its set-up cell's output; 01 its pkg create."""
    for rel in (r for r in SOURCES if r.startswith('notebooks/')):
        copy = read_notebook(released / rel)
        assert any(c.get('outputs') for c in copy.cells if c.cell_type == 'code'), rel
    created = read_notebook(released / 'notebooks' / '01_create_package.ipynb')
    text = json.dumps([c.get('outputs', []) for c in created.cells])
    assert 'destination directory: ~/robot_lab_ws/src' in text


def _nb(*cells: nbformat.NotebookNode) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    nb.cells = list(cells)
    for index, cell in enumerate(nb.cells):
        cell['id'] = f'c{index}'
    return nb


def _code(source: str = 'x', **meta: object) -> nbformat.NotebookNode:
    cell = nbformat.v4.new_code_cell(source)
    if meta:
        cell.metadata.update(meta)
    return cell


def test_keeps_output_rule() -> None:
    nbgrader = {'schema_version': 3, 'locked': False, 'points': 1}
    nb = _nb(_code(), nbformat.v4.new_markdown_cell('text'),
             _code(nbgrader={**nbgrader, 'grade': True, 'solution': False, 'grade_id': 'g0'}),
             _code(),
             _code(nbgrader={**nbgrader, 'grade': False, 'solution': True, 'grade_id': 'a'}),
             _code(),
             _code(robot_lab={'keep_output': True}),
             _code(nbgrader={**nbgrader, 'grade': True, 'solution': False, 'grade_id': 'g1'},
                   robot_lab={'keep_output': True}))
    # c0 and c3: before the first answer; c6: marked by its author. Never a check (c2, c7),
    # the answer (c4), or an unmarked cell after an answer (c5).
    assert keeps_output(nb) == {'c0', 'c3', 'c6'}


def test_sanitise_output_shows_homes_as_tilde_and_the_venv_by_name() -> None:
    home = str(Path.home())
    cases = {
        '/home/alice/robot_lab/.venv/bin/colcon': '$ROBOT_LAB_VENV/bin/colcon',
        'searched AMENT_PREFIX_PATH: .venv/var/robot_lab/prefix, .venv) — fix':
            'searched AMENT_PREFIX_PATH: $ROBOT_LAB_VENV/var/robot_lab/prefix, $ROBOT_LAB_VENV)'
            ' — fix',
        "The path '.venv' in the environment": "The path '$ROBOT_LAB_VENV' in the environment",
        f'{sys.prefix}/bin/ros2': '$ROBOT_LAB_VENV/bin/ros2',
        'destination: /root/robot_lab_ws/src': 'destination: ~/robot_lab_ws/src',
        '/Users/bob/robot_lab_ws:/home/carol': '~/robot_lab_ws:~',
        f'{home}/robot_lab_ws/install': '~/robot_lab_ws/install',
        # not a home, not the kit's venv
        '/var/tmp/robot_lab/domains.json my.venv /rooted ~/x': (
            '/var/tmp/robot_lab/domains.json my.venv /rooted ~/x'),
    }
    for raw, shown in cases.items():
        assert sanitise_output(raw) == shown, raw


def test_release_drops_widget_views_and_strips_markers(tmp_path: Path) -> None:
    from nbgrader.utils import compute_checksum

    widget = nbformat.v4.new_output('display_data', data={
        'application/vnd.jupyter.widget-view+json': {'model_id': 'm', 'version_major': 2},
        'text/plain': 'Plot(...)'})
    printed = nbformat.v4.new_output('stream', name='stdout',
                                     text=f'made {Path.home()}/robot_lab_ws\n')
    setup = _code('print(ws)')
    setup.outputs = [printed, widget]
    check = _code('# NBVAL_CHECK_OUTPUT\ncheck.ok()', nbgrader={
        'schema_version': 3, 'grade': True, 'solution': False, 'locked': True, 'points': 1,
        'grade_id': 'check-ok'})
    check.outputs = [nbformat.v4.new_output('stream', name='stdout', text='✓ ok\n')]
    source = tmp_path / 'lesson.ipynb'
    source.write_text(nbformat.writes(_nb(setup, check)))
    copy = student_course_notebook(source)
    assert [o.get('text') for o in copy.cells[0].outputs] == ['made ~/robot_lab_ws\n']
    assert copy.cells[1].source == 'check.ok()' and copy.cells[1].outputs == []
    assert copy.cells[1].metadata.nbgrader.checksum == compute_checksum(copy.cells[1])
