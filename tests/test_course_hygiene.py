"""The committed course: notebooks students write in, with outputs any machine could show.

Committed notebooks (notebooks/, exercises/, solutions/) are what a student sees before
running anything, so they must not carry the paths or the e-mail of the machine that ran
them. The course notebooks are the source `robot-lab course release` strips: their answers
sit in nbgrader solution cells, each followed by a graded check, and the lab's real
commands run in `!`/`%%bash` cells. These tests read the files only (no kernel, no ROS).

To clean a notebook's outputs after running it (`jupyter nbconvert --execute --inplace`):

    .venv/bin/python tests/test_course_hygiene.py --workspace "$ROBOT_LAB_WORKSPACE" NB...

replaces the workspace with `~/robot_lab_ws`, the checkout with relative paths and the home
folder with `~`, and drops nbconvert's per-cell timestamps.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.no_ros  # reads files only: no ROS_DOMAIN_ID slot

ROOT = Path(__file__).resolve().parents[1]
COMMITTED = ('notebooks', 'exercises', 'solutions')
COURSE = ROOT / 'notebooks'

# Absolute paths a notebook's run leaves behind (a path of its own, not inside another one
# such as the kit's /var/tmp/robot_lab registry); the checkout and $HOME of this machine too.
_MACHINE_PATH = re.compile('|'.join(
    [r'(?<![\w.~-])(?:/root|/tmp|/home|/Users)/',
     *(re.escape(f'{p}/') for p in sorted({str(ROOT), str(Path.home())}, key=len,
                                          reverse=True))]))
_EMAIL = re.compile(r'[\w.+-]+@[A-Za-z0-9-]+(?:\.[A-Za-z0-9-]+)+')
# RFC 2606 documentation domain: the lab's own placeholder maintainer, `you@example.com`.
_PLACEHOLDER_EMAIL = re.compile(r'@example\.(?:com|org|net)$')
_BEGIN, _END = 'BEGIN SOLUTION', 'END SOLUTION'

# Commands of the two labs; each must run somewhere in a `!` line or a `%%bash` cell.
SEED_COMMANDS = {
    'ros2 pkg create': r'ros2 pkg create\b',
    'colcon build': r'colcon build\b',
    'source install/setup.bash': r'(?:source|\.) install/setup\.bash\b',
    'ros2 run': r'ros2 run \S',
    'ros2 launch': r'ros2 launch \S',
    'ros2 node list': r'ros2 node list\b',
    'ros2 topic echo': r'ros2 topic echo \S',
    'ros2 param set': r'ros2 param set \S',
    'ros2 bag record': r'ros2 bag record\b',
    'ros2 bag play': r'ros2 bag play\b',
    'ros2 bag info': r'ros2 bag info\b',
}
MIN_ANSWERS = {'01': 2, '02': 2, '03': 2, '04': 2, '05': 2, '06': 2, '07': 3}
MIN_TOTAL_ANSWERS = 20


def _notebooks(folders: tuple[str, ...] = COMMITTED) -> list[Path]:
    return sorted(p for d in folders for p in (ROOT / d).glob('*.ipynb'))


def _load(path: Path) -> dict[str, Any]:
    nb: dict[str, Any] = json.loads(path.read_text(encoding='utf-8'))
    return nb


def _source(cell: dict[str, Any]) -> str:
    src = cell.get('source', '')
    return ''.join(src) if isinstance(src, list) else str(src)


def _output_texts(cell: dict[str, Any]) -> Iterator[str]:
    for out in cell.get('outputs', []):
        for value in [out.get('text'), *out.get('data', {}).values(), out.get('traceback')]:
            if isinstance(value, list):
                yield ''.join(str(v) for v in value)
            elif isinstance(value, str):
                yield value


def _nbgrader(cell: dict[str, Any]) -> dict[str, Any]:
    meta: dict[str, Any] = cell.get('metadata', {}).get('nbgrader', {})
    return meta


def _is_answer(cell: dict[str, Any]) -> bool:
    return cell['cell_type'] == 'code' and bool(_nbgrader(cell).get('solution'))


def _is_check(cell: dict[str, Any]) -> bool:
    return cell['cell_type'] == 'code' and bool(_nbgrader(cell).get('grade'))


def _rel(path: Path) -> str:
    return str(path.relative_to(ROOT))


# --- no machine paths, no e-mail -------------------------------------------------------


def _leaks(path: Path) -> list[str]:
    found = []
    for index, cell in enumerate(_load(path)['cells']):
        texts = [('source', _source(cell))] + [('output', t) for t in _output_texts(cell)]
        for where, text in texts:
            hit = _MACHINE_PATH.search(text)
            if hit:
                snippet = text[max(0, hit.start() - 20):hit.start() + 40].replace('\n', ' ')
                found.append(f'{_rel(path)} cell {index} {where}: path {snippet!r}')
            for address in _EMAIL.findall(text):
                if not _PLACEHOLDER_EMAIL.search(address):
                    found.append(f'{_rel(path)} cell {index} {where}: e-mail {address!r}')
    return found


@pytest.mark.parametrize('path', _notebooks(), ids=_rel)
def test_no_machine_paths_or_email(path: Path) -> None:
    leaks = _leaks(path)
    assert not leaks, ('\n'.join(leaks) + '\nclean the outputs: .venv/bin/python '
                       'tests/test_course_hygiene.py --workspace WS ' + _rel(path))


# --- the course is written by the student -------------------------------------------------


def _course() -> list[Path]:
    return _notebooks(('notebooks',))


def _number(path: Path) -> str:
    return path.name[:2]


def test_answer_cells_per_notebook() -> None:
    counts = {_number(p): sum(map(_is_answer, _load(p)['cells'])) for p in _course()}
    short = {n: f'{counts.get(n, 0)} < {want}' for n, want in MIN_ANSWERS.items()
             if counts.get(n, 0) < want}
    assert not short, f'answer cells per notebook (seen {counts}): too few in {short}'
    assert sum(counts.values()) >= MIN_TOTAL_ANSWERS, counts


@pytest.mark.parametrize('path', _course(), ids=_rel)
def test_nbgrader_cells_are_well_formed(path: Path) -> None:
    """What ClearSolutions and `nbgrader validate` need: ids, markers, points, locks."""
    cells = _load(path)['cells']
    problems = []
    ids = [_nbgrader(c)['grade_id'] for c in cells if _nbgrader(c)]
    if len(ids) != len(set(ids)):
        problems.append(f'duplicate grade_id in {ids}')
    for index, cell in enumerate(cells):
        meta, src = _nbgrader(cell), _source(cell)
        where = f'cell {index} ({meta.get("grade_id", cell.get("id"))})'
        begins, ends = src.count(_BEGIN), src.count(_END)
        if _is_answer(cell):
            if begins == 0 or begins != ends:
                problems.append(f'{where}: answer cell needs balanced {_BEGIN}/{_END} markers')
            if meta.get('locked') or meta.get('schema_version') != 3:
                problems.append(f'{where}: answer cell must be unlocked, schema_version 3')
        elif begins or ends:
            problems.append(f'{where}: solution markers outside a solution cell')
        if _is_check(cell):
            if not meta.get('locked') or not (meta.get('points') or 0) > 0:
                problems.append(f'{where}: a check cell is locked and has points > 0')
            if _BEGIN in src:
                problems.append(f'{where}: a check cell holds no answer')
    assert not problems, f'{_rel(path)}:\n' + '\n'.join(problems)


@pytest.mark.parametrize('path', _course(), ids=_rel)
def test_every_answer_is_checked_and_hinted(path: Path) -> None:
    cells = _load(path)['cells']
    assert any(map(_is_check, cells)), f'{_rel(path)} has no graded check cell'
    problems = []
    for index, cell in enumerate(cells):
        if not _is_answer(cell):
            continue
        rest = cells[index + 1:]
        upto = next((i for i, c in enumerate(rest) if _is_answer(c)), len(rest))
        following = rest[:upto]
        name = _nbgrader(cell)['grade_id']
        if not any(map(_is_check, following)):
            problems.append(f'{name}: no graded check before the next answer')
        hints = ''.join(_source(c) for c in following if c['cell_type'] == 'markdown')
        if 'Hint 1' not in hints or 'Hint 2' not in hints:
            problems.append(f'{name}: no tiered hints (Hint 1, Hint 2) after it')
    assert not problems, f'{_rel(path)}:\n' + '\n'.join(problems)


@pytest.mark.parametrize('path', _course(), ids=_rel)
def test_notebook_opens_with_goals_and_time_and_ends_with_recap(path: Path) -> None:
    cells = _load(path)['cells']
    first, last = _source(cells[0]), _source(cells[-1])
    assert re.search(r'\d+\s*minutes', first), f'{_rel(path)}: first cell gives no time estimate'
    assert first.count('\n- ') + first.count('\n* ') >= 3, f'{_rel(path)}: no goal bullets'
    assert 'Recap' in last and 'Next' in last, f'{_rel(path)}: last cell needs Recap and Next'


def _shell_lines(cells: list[dict[str, Any]]) -> Iterator[str]:
    for cell in cells:
        if cell['cell_type'] != 'code':
            continue
        src = _source(cell)
        if re.match(r'\s*%%(?:bash|sh|script bash)\b', src):
            yield src
        else:
            yield from (line for line in src.splitlines() if line.lstrip().startswith('!'))


def test_seed_commands_run_in_shell_cells() -> None:
    lines = [line for p in _course() for line in _shell_lines(_load(p)['cells'])]
    missing = [name for name, pattern in SEED_COMMANDS.items()
               if not any(re.search(pattern, line) for line in lines)]
    assert not missing, f'no `!`/`%%bash` cell in notebooks/ runs: {", ".join(missing)}'


def _answers_text() -> str:
    parts = []
    for path in _course():
        for cell in filter(_is_answer, _load(path)['cells']):
            inside = False
            for line in _source(cell).splitlines():
                if _BEGIN in line:
                    inside = True
                elif _END in line:
                    inside = False
                elif inside:
                    parts.append(line)
    return '\n'.join(parts)


@pytest.mark.parametrize('api', ['add_on_set_parameters_callback', 'ParameterDescriptor'])
def test_students_write_parameter_callbacks_and_descriptors(api: str) -> None:
    assert api in _answers_text(), f'no answer region in notebooks/ uses {api}'


# --- what a released copy's checks say ------------------------------------------------


def _released_files() -> list[tuple[str, str, str]]:
    """(notebook, file name, text) of each `%%writefile` answer after ClearSolutions."""
    import nbformat
    from nbgrader.preprocessors import ClearSolutions  # type: ignore[import-untyped]

    read: Any = nbformat.read  # unannotated
    found = []
    for path in _course():
        nb = read(str(path), as_version=4)
        released, _ = ClearSolutions().preprocess(nb, {})
        for cell in released.cells:
            if _is_answer(cell) and cell.source.startswith('%%writefile '):
                head, _, body = cell.source.partition('\n')
                found.append((path.name, Path(head.split()[-1]).name, body + '\n'))
    return found


def test_released_answers_are_named_by_their_checks(tmp_path: Path) -> None:
    """A student's file that still holds the release's placeholder fails its check, saying so."""
    from robot_lab.grading import check

    released = _released_files()
    assert len(released) >= 6, released
    for notebook, name, text in released:
        assert 'NotImplementedError' in text, (notebook, name)
        file = tmp_path / name
        file.write_text(text)
        with pytest.raises(check.CheckError, match='placeholder') as failed:
            check.answered(file, 'your answer')
        assert f'{name}' in str(failed.value) and 'Try:' in str(failed.value)
    setup_py = next(text for _nb, name, text in released if name == 'setup.py')
    package = tmp_path / 'my_robot_system'
    package.mkdir()
    (package / 'setup.py').write_text(setup_py)
    with pytest.raises(check.CheckError, match=r'line \d+'):
        check.setup_py(package, {'sensor_node': 'my_robot_system.sensor_node:main'})


# --- cleaning outputs ------------------------------------------------------------------


def scrub(path: Path, workspace: str | None = None) -> int:
    """Rewrite `path`'s outputs without machine paths; the number of cells changed."""
    nb = _load(path)
    swaps = []
    if workspace:
        swaps.append((str(Path(workspace)), '~/robot_lab_ws'))
    swaps += [(f'{ROOT}/', ''), (str(ROOT), '.'), (f'{Path.home()}/', '~/')]
    changed = 0
    for cell in nb['cells']:
        cell.get('metadata', {}).pop('execution', None)
        before = json.dumps(cell.get('outputs', []), ensure_ascii=False)
        after = before
        for old, new in swaps:
            after = after.replace(json.dumps(old)[1:-1], json.dumps(new)[1:-1])
        if after != before:
            cell['outputs'] = json.loads(after)
            changed += 1
    path.write_text(json.dumps(nb, indent=1, ensure_ascii=False) + '\n', encoding='utf-8')
    return changed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=scrub.__doc__)
    parser.add_argument('--workspace', default=os.environ.get('ROBOT_LAB_WORKSPACE'),
                        help='the workspace the notebooks ran in (shown as ~/robot_lab_ws)')
    parser.add_argument('notebooks', nargs='+', type=Path)
    args = parser.parse_args(argv)
    for path in args.notebooks:
        print(f'{path}: {scrub(path.resolve(), args.workspace)} cell(s) cleaned')
        for leak in _leaks(path.resolve()):
            print(f'  still: {leak}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
