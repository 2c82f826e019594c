"""Exercises generated from solutions by nbgrader's own preprocessors, so the two never drift.

An instructor edits only `solutions/*.ipynb`, which are nbgrader *source* notebooks: every
cell that matters carries nbgrader's metadata (`nbgrader: {grade, solution, locked,
grade_id, points, schema_version: 3}`) and answers sit between `### BEGIN SOLUTION` and
`### END SOLUTION` lines (`<!-- ### BEGIN SOLUTION -->` in an XML file). So the same files
work in nbgrader unchanged (`nbgrader generate_assignment`, `autograde`), and
`build_exercises()` writes `exercises/*.ipynb` with the pipeline `generate_assignment`
runs: cells locked, answers replaced by nbgrader's stub, outputs cleared, checksums
computed. The course notebooks' student copies (robot_lab.grading.release) use the same
`student_notebook()`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import nbformat
from nbformat import NotebookNode

from robot_lab.errors import RobotLabError

__all__ = [
    'Check',
    'ExerciseFile',
    'build_exercises',
    'exercise_name',
    'exercise_notebook',
    'grade_id',
    'graded_checks',
    'kit_root',
    'notebook_text',
    'read_notebook',
    'student_notebook',
]


# nbformat is unannotated: typed handles on the calls used here.
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


def _nbgrader(cell: NotebookNode) -> dict[str, Any]:
    meta = cell.get('metadata', {}).get('nbgrader', {})
    return meta if isinstance(meta, dict) else {}


def grade_id(cell: NotebookNode) -> str | None:
    """The cell's nbgrader grade_id, if it is an nbgrader cell."""
    value = _nbgrader(cell).get('grade_id')
    return value if isinstance(value, str) and value else None


@dataclass(frozen=True)
class Check:
    """One autograded check cell: its grade_id (also its name), points and source."""

    cell_id: str
    points: float
    source: str


def graded_checks(nb: NotebookNode, where: str = '<notebook>') -> list[Check]:
    """The notebook's autograded test cells (nbgrader `grade` code cells), in order.

    Manually graded answers (nbgrader's markdown `grade` + `solution` cells) are not
    checks: a person reads them in nbgrader's formgrader.
    """
    checks = []
    for index, cell in enumerate(nb.cells):
        meta = _nbgrader(cell)
        if cell.cell_type != 'code' or not meta.get('grade') or meta.get('solution'):
            continue
        points, name = meta.get('points'), grade_id(cell)
        if (name is None or not isinstance(points, int | float) or isinstance(points, bool)
                or points <= 0):
            raise RobotLabError(
                f'graded cell {index} (id {cell.get("id")!r}) has no grade_id or no '
                'positive points', file=where,
                fix='give it metadata {"nbgrader": {"grade": true, "solution": false, '
                '"locked": true, "grade_id": "check-x", "points": 2, "schema_version": 3}}',
            )
        checks.append(Check(name, float(points), cell.source))
    return checks


def exercise_name(path: str | Path, nb: NotebookNode | None = None) -> str:
    """The exercise a notebook says it belongs to: its metadata, else the file name."""
    if nb is not None:
        name = nb.get('metadata', {}).get('robot_lab', {}).get('exercise')
        if isinstance(name, str) and name:
            return name
    return Path(path).stem


def _preprocessors() -> list[Any]:
    """generate_assignment's pipeline, minus the database and header steps."""
    from nbgrader.preprocessors import (  # type: ignore[import-untyped]
        CheckCellMetadata,
        ClearHiddenTests,
        ClearMarkScheme,
        ClearOutput,
        ClearSolutions,
        ComputeChecksums,
        LockCells,
    )

    # nbconvert's ClearOutput also drops run timings, which only make diffs noisy.
    clear = ClearOutput(remove_metadata_fields={'collapsed', 'scrolled', 'execution'})
    return [LockCells(), ClearSolutions(), clear, CheckCellMetadata(), ClearHiddenTests(),
            ClearMarkScheme(), ComputeChecksums(), CheckCellMetadata()]


def student_notebook(source: str | Path) -> NotebookNode:
    """The student copy of an nbgrader source notebook: what generate_assignment releases."""
    path = Path(source)
    nb = read_notebook(path)
    graded_checks(nb, str(path))  # refuse a check cell without points before handing it out
    resources: dict[str, Any] = {}
    try:
        for step in _preprocessors():
            nb, resources = step.preprocess(nb, resources)
    except Exception as err:  # nbgrader raises RuntimeError/ValidationError with a message
        raise RobotLabError(f'nbgrader refused the notebook: {err}', file=path,
                            fix='every answer between ### BEGIN SOLUTION and ### END SOLUTION '
                            'in a cell marked as a solution (nbgrader metadata), blocks '
                            'closed and not nested') from None
    return nb


def exercise_notebook(solution: str | Path) -> NotebookNode:
    """The exercise for one solution notebook, named in its metadata for the grader."""
    path = Path(solution)
    nb = student_notebook(path)
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
