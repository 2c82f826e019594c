"""The student's copy of the course: answers removed, checks kept, trusted, and a student's
changes never overwritten by the next release."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import nbformat
import pytest
from conftest import REPO, run_cli
from nbformat.sign import NotebookNotary

from robot_lab.grading.exercises import read_notebook
from robot_lab.grading.release import MANIFEST, release_course

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
    source, copy = read_notebook(SOURCES[rel]), read_notebook(released / rel)
    text = (released / rel).read_text()
    lines = {line.strip() for cell in copy.cells for line in cell.source.split('\n')}
    leaked = sorted(_answer_lines(source) & lines)
    assert leaked == [], f'{rel}: answer lines in the student copy: {leaked[:3]}'
    assert 'BEGIN SOLUTION' not in text
    checks = {c['id']: c.source for c in source.cells
              if c.get('metadata', {}).get('nbgrader', {}).get('grade')
              and c.cell_type == 'code'}
    assert {c['id']: c.source for c in copy.cells if c['id'] in checks} == checks
    assert all(not c.get('outputs') for c in copy.cells if c.cell_type == 'code')
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
