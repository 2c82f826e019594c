"""Exercises generated from solutions, so the two never drift apart.

An instructor edits only `solutions/*.ipynb`. In a solution, the answer sits between two
fence lines, `# BEGIN SOLUTION` and `# END SOLUTION` (any comment syntax: `<!-- BEGIN
SOLUTION -->` in markdown or XML). `build_exercises()` writes `exercises/*.ipynb` with each
fenced block replaced by a placeholder and every output cleared; graded check cells (tag
`grade`) are kept as they are, so students can run them.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import nbformat
from nbformat import NotebookNode

from robot_lab.errors import RobotLabError

__all__ = [
    'GRADE_TAG',
    'Check',
    'ExerciseFile',
    'build_exercises',
    'exercise_name',
    'exercise_notebook',
    'graded_checks',
    'kit_root',
    'notebook_text',
    'read_notebook',
    'strip_solution',
]

GRADE_TAG = 'grade'
# A fence is a line of its own, in a comment of the cell's language (#, <!-- -->, //).
_BEGIN = re.compile(r'^(?P<indent>\s*)(?P<open>#+|<!--|//)\s*BEGIN SOLUTION\s*(?P<close>-->)?\s*$')
_END = re.compile(r'^\s*(#+|<!--|//)\s*END SOLUTION\s*(-->)?\s*$')
CODE_PLACEHOLDER = 'YOUR CODE HERE'
ANSWER_PLACEHOLDER = '_YOUR ANSWER HERE_'


# nbformat is unannotated: typed handles on the three calls used here.
_read: Callable[..., NotebookNode] = nbformat.read
_writes: Callable[..., str] = nbformat.writes
new_code_cell: Callable[..., NotebookNode] = nbformat.v4.new_code_cell


def read_notebook(path: str | Path) -> NotebookNode:
    """A notebook as nbformat v4 (older ones are upgraded)."""
    return _read(str(path), as_version=4)


def notebook_text(nb: NotebookNode) -> str:
    """The file text Jupyter would save, newline-terminated, so diffs stay clean."""
    return _writes(nb) + '\n'


def kit_root() -> Path:
    """The checkout that holds solutions/ and exercises/ (the kit is installed editable)."""
    return Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Check:
    """One graded check cell: its cell id (also its name), points and source."""

    cell_id: str
    points: float
    source: str


def _points(cell: NotebookNode, where: str) -> float:
    meta = cell.get('metadata', {}).get('robot_lab', {})
    points = meta.get('points')
    if not isinstance(points, int | float) or isinstance(points, bool) or points <= 0:
        raise RobotLabError(
            f'graded cell {cell.get("id")!r} has no positive "points"', file=where,
            fix='give it metadata {"tags": ["grade"], "robot_lab": {"points": 2}}',
        )
    return float(points)


def graded_checks(nb: NotebookNode, where: str = '<notebook>') -> list[Check]:
    """The notebook's check cells (code cells tagged `grade`), in order."""
    checks = []
    for cell in nb.cells:
        if cell.cell_type == 'code' and GRADE_TAG in cell.get('metadata', {}).get('tags', []):
            checks.append(Check(str(cell.get('id', '')), _points(cell, where), cell.source))
    return checks


def _placeholder(cell_type: str, source: str, indent: str, opener: str, closer: str) -> list[str]:
    if cell_type == 'markdown':
        return [indent + ANSWER_PLACEHOLDER]
    comment = f'{indent}{opener} {CODE_PLACEHOLDER}' + (f' {closer}' if closer else '')
    if opener.startswith('#') and not source.lstrip().startswith('%%'):
        # Python: the cell must fail loudly until answered, not pass silently.
        return [comment, f'{indent}raise NotImplementedError()']
    return [comment]  # a %%writefile cell: the file gets a comment in its own syntax


def strip_solution(cell_type: str, source: str, where: str = '<cell>') -> str:
    """`source` with each fenced solution block replaced by its placeholder."""
    out: list[str] = []
    inside: re.Match[str] | None = None
    for number, line in enumerate(source.split('\n'), start=1):
        begin = _BEGIN.match(line)
        if inside is None:
            if begin:
                inside = begin
                continue
            if _END.match(line):
                raise RobotLabError(
                    f'END SOLUTION without BEGIN SOLUTION at line {number} of the cell',
                    file=where, fix='add the matching BEGIN SOLUTION line above it',
                )
            out.append(line)
        elif begin:
            raise RobotLabError(
                f'BEGIN SOLUTION inside another solution block at line {number} of the cell',
                file=where, fix='close the first block with END SOLUTION (blocks do not nest)',
            )
        elif _END.match(line):
            out.extend(_placeholder(cell_type, source, inside['indent'], inside['open'],
                                    inside['close'] or ''))
            inside = None
    if inside is not None:
        raise RobotLabError(
            'BEGIN SOLUTION without END SOLUTION', file=where,
            fix='close the block with an END SOLUTION line',
        )
    return '\n'.join(out)


def exercise_name(path: str | Path, nb: NotebookNode | None = None) -> str:
    """The exercise a notebook belongs to: its metadata, else the file name."""
    if nb is not None:
        name = nb.get('metadata', {}).get('robot_lab', {}).get('exercise')
        if isinstance(name, str) and name:
            return name
    return Path(path).stem


def exercise_notebook(solution: str | Path) -> NotebookNode:
    """The exercise for one solution notebook: answers replaced, outputs cleared."""
    path = Path(solution)
    nb = read_notebook(path)
    where = str(path)
    graded_checks(nb, where)  # refuse a check cell without points before handing it out
    for index, cell in enumerate(nb.cells):
        cell_where = f'{where} (cell {index}, id {cell.get("id")})'
        if cell.cell_type in ('code', 'markdown'):
            cell.source = strip_solution(cell.cell_type, cell.source, cell_where)
        if cell.cell_type == 'code':
            cell.outputs = []
            cell.execution_count = None
            cell.metadata.pop('execution', None)
    meta: dict[str, Any] = nb.metadata.setdefault('robot_lab', {})
    meta['exercise'] = path.stem
    meta['generated_from'] = f'solutions/{path.name}'
    return nb


@dataclass(frozen=True)
class ExerciseFile:
    """One exercise as generated: where it goes and whether the file on disk matches."""

    solution: Path
    exercise: Path
    up_to_date: bool


def build_exercises(
    solutions_dir: str | Path | None = None,
    exercises_dir: str | Path | None = None,
    check: bool = False,
    names: Iterable[str] | None = None,
) -> list[ExerciseFile]:
    """Generate exercises/<name>.ipynb from every solutions/<name>.ipynb.

    With `check=True` nothing is written; the result says which files are stale.
    Exercises whose solution is gone count as stale (and are removed when writing).
    """
    root = kit_root()
    solutions = Path(solutions_dir) if solutions_dir is not None else root / 'solutions'
    exercises = Path(exercises_dir) if exercises_dir is not None else root / 'exercises'
    wanted = set(names) if names is not None else None
    sources = sorted(p for p in solutions.glob('*.ipynb')
                     if wanted is None or p.stem in wanted)
    if not sources and wanted is None:
        raise RobotLabError('no solution notebooks found', file=solutions,
                            fix='put solutions/<name>.ipynb there, then rerun')
    results = []
    for source in sources:
        target = exercises / source.name
        text = notebook_text(exercise_notebook(source))
        current = target.read_text() if target.is_file() else None
        results.append(ExerciseFile(source, target, current == text))
        if not check and current != text:
            exercises.mkdir(parents=True, exist_ok=True)
            target.write_text(text)
    if wanted is None:
        for orphan in sorted(exercises.glob('*.ipynb')):
            if not (solutions / orphan.name).is_file():
                results.append(ExerciseFile(solutions / orphan.name, orphan, False))
                if not check:
                    orphan.unlink()
    return results
