"""A student who makes mistakes, in a real browser: notebooks 01–03 in JupyterLab.

Every answer cell is answered as the released copy has it (unanswered), then wrong in each
way tests/mistakes.py lists, then right; after each answer the cells between it and its
check run again, and then the check. Each failing check must show its two lines (no
traceback of the kit) and name the mistake; the right answer must pass in the same kernel,
with no restart. Screenshots of every rung go to the test's temporary folder (printed).
"""

from __future__ import annotations

import re
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import browser_lab
import pytest
from browser_lab import REPO, Lab, Notebook
from course_run import student_cells
from mistakes import LADDERS

pytestmark = [pytest.mark.browser, pytest.mark.timeout(1800)]

CHROMIUM, sync_playwright = browser_lab.browser_or_skip()

NOTEBOOKS = ['01_create_package', '02_write_nodes', '03_launch_files']


@pytest.fixture(scope='module')
def lab(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Lab, Any, Path]]:
    scratch = tmp_path_factory.mktemp('mistakes')
    root = scratch / 'course'
    (root / 'notebooks').mkdir(parents=True)
    for name in NOTEBOOKS:
        shutil.copy(REPO / 'notebooks' / f'{name}.ipynb', root / 'notebooks')
        browser_lab.clear_outputs(root / 'notebooks' / f'{name}.ipynb')
    shots = scratch / 'shots'
    shots.mkdir()
    # lessons 01-03 in 77-79 (tests/conftest.py): apart from the course's, which may run
    # on another worker at the same time
    env = browser_lab.lab_environment(scratch, browser_lab.domain_base(76))
    with browser_lab.jupyter_lab(root, env) as running, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=browser_lab.CHROMIUM_ARGS)
        try:  # one page: each notebook opens in the JupyterLab loaded there
            page = browser.new_page(viewport={'width': 1280, 'height': 900})
            page.set_default_timeout(30_000)
            yield running, page, shots
        finally:
            browser.close()
            print(f'\nscreenshots of the mistakes: {shots}')


def _places(cells: list[dict[str, Any]]) -> dict[int, tuple[str, int]]:
    """Answer cell index -> (its grade id, the index of its check)."""
    found = {}
    for i, cell in enumerate(cells):
        meta = cell.get('metadata', {}).get('nbgrader', {})
        if meta.get('solution') and cell['cell_type'] == 'code':
            check = next(j for j in range(i + 1, len(cells))
                         if cells[j].get('metadata', {}).get('nbgrader', {}).get('grade'))
            found[i] = (meta['grade_id'], check)
    return found


def _set_source(nb: Notebook, index: int, text: str) -> None:
    """Type over a cell's source as a student does: edit mode, select all, the new text."""
    nb.select(index)
    nb.page.keyboard.press('Enter')
    nb.page.keyboard.press('Control+a')
    nb.page.keyboard.insert_text(text)
    nb.page.keyboard.press('Escape')
    shown = nb.source(index)  # the editor's lines, without their line breaks
    assert ''.join(shown.split()) == ''.join(text.split()), f'cell {index} holds\n{shown}'


def _said(nb: Notebook, index: int) -> str:
    return re.sub(r'\s+', ' ', nb.text(index))


@pytest.mark.parametrize('name', NOTEBOOKS)
def test_a_student_who_makes_mistakes(lab: tuple[Lab, Any, Path], name: str) -> None:
    import nbformat

    running, page, shots = lab
    cells = nbformat.read(REPO / 'notebooks' / f'{name}.ipynb', as_version=4).cells
    student = student_cells(name)
    places = _places(cells)
    ids = {c.get('id'): i for i, c in enumerate(cells)}
    problems: list[str] = []
    try:
        nb = Notebook(page, running, f'notebooks/{name}.ipynb')
        checks = {check: answer for answer, check in places.values()}
        count, index = nb.count(), 0
        while index < count:
            if index in places:
                answer, check = places[index]
                ladder = LADDERS[answer]
                between = [i for i in range(index + 1, check) if cells[i].cell_type == 'code']
                default = [ids[c] for c in ladder.rerun] if ladder.rerun is not None else between
                rungs = [('unanswered', student[cells[index].id].source, ladder.unanswered,
                          default)]
                rungs += [(w.mistake, w.edit(cells[index].source), w.says,
                           [ids[c] for c in w.rerun] if w.rerun is not None else default)
                          for w in ladder.wrong]
                for step, (mistake, text, says, rerun) in enumerate(rungs):
                    _set_source(nb, index, text)
                    for i in [index, *rerun, check]:
                        nb.run(i)
                    said = _said(nb, check)
                    nb.shot(nb.cell(check), shots / f'{answer}-{step}.png')
                    if not re.search(says, said, re.S) or '✗ expected' not in said \
                            or 'Try: ' not in said or 'Traceback' in said:
                        problems.append(f'{answer} ({mistake}): the check said {said!r}')
                _set_source(nb, index, cells[index].source)
                nb.run(index)
                last = index
            else:  # up to the next answer cell or check, in one stretch (run_cells)
                last = min([p - 1 for p in places if p > index]
                           + [c for c in checks if c >= index] + [count - 1])
                nb.run_cells(index, last)
            if last in checks:
                nb.shot(nb.cell(last), shots / f'{checks[last]}-right.png')
                if '✗' in nb.text(last):
                    problems.append(f'{checks[last]}: the right answer failed: '
                                    f'{_said(nb, last)}')
            index = last + 1
        problems += [f'error output: {e}' for e in nb.errors()]
    finally:
        browser_lab.close_notebooks(page, running)
    assert not problems, '\n'.join(problems)
