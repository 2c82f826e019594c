"""The student's copy of the course: one source (the repository), two copies.

`release_course(DIR)` writes DIR/notebooks/*.ipynb (the course notebooks) and
DIR/exercises/*.ipynb with the answers removed and the checks kept, by the same nbgrader
pipeline as the exercises (robot_lab.grading.exercises.student_notebook). Students work in
DIR, so autosave never touches the repository and the next `git pull` of the course never
conflicts.

The course may also be a released copy (one with .robot_lab/release.json, published for a
hub's students): its notebooks are then given as they are, never through nbgrader again.

A course notebook's copy shows what to expect: it keeps the source's outputs of the cells
that cannot show an answer (`keeps_output`: code cells that are neither an answer nor a
graded check, and come before the notebook's first answer cell, or are marked
`metadata.robot_lab.keep_output: true` by the author), written the way the student's own
machine would print them (`sanitise_output`: homes as `~`, the kit's venv as
`$ROBOT_LAB_VENV`). nbval's `# NBVAL_…` marker lines are the kit's test harness, not the
lesson: they are stripped (and the locked cells' nbgrader checksums recomputed). The
exercises keep nothing: their sources have no outputs.

Released again (a new notebook, a fixed typo), it adds what is new and updates what the
student has not touched, but never overwrites a file the student changed: DIR/.robot_lab
/release.json remembers the hash of every file as released. Released notebooks are signed
with nbformat's NotebookNotary (the user's Jupyter data dir), so they open trusted.
"""

from __future__ import annotations

import copy
import hashlib
import json
import os
import re
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from nbformat import NotebookNode

from robot_lab.errors import RobotLabError
from robot_lab.grading.exercises import (
    exercise_notebook,
    kit_root,
    notebook_text,
    read_notebook,
    student_notebook,
)

__all__ = ['MANIFEST', 'ReleasedFile', 'keeps_output', 'release_course', 'sanitise_output',
           'student_course_notebook']

MANIFEST = Path('.robot_lab') / 'release.json'

_NBVAL_LINE = re.compile(r'^[ \t]*# NBVAL_\w+[ \t]*\n?', re.M)
# A path that ends in the kit's venv: relative (`.venv`, as tests/test_course_hygiene.py
# cleans committed outputs) or absolute under any folder.
_VENV_PATH = re.compile(r'(?<![\w.~/$-])(?:[~/][^\s\'",:;()\[\]]*/)?\.venv(?![\w.-])')
_HOME_PATH = re.compile(r'(?<![\w.~-])(?:/home/[^/\s\'"]+|/Users/[^/\s\'"]+|/root)'
                        r'(?=/|[\s\'",:;)\]]|$)')
_WIDGET_MIME = 'application/vnd.jupyter.widget-view+json'


@dataclass(frozen=True)
class ReleasedFile:
    """One file of the student copy and what this release did with it.

    `action`: 'new' (written), 'updated' (the student had not changed it), 'unchanged'
    (as released, or changed by the student with nothing newer to give), or 'kept' (the
    student changed it and a newer version exists: left as it is, the new one not written).
    """

    path: Path  # relative to the release folder
    action: str


def _digest(text: str | bytes) -> str:
    data = text.encode() if isinstance(text, str) else text
    return hashlib.sha256(data).hexdigest()


def _nbgrader(cell: NotebookNode) -> dict[str, Any]:
    meta = cell.get('metadata', {}).get('nbgrader', {})
    return meta if isinstance(meta, dict) else {}


def keeps_output(nb: NotebookNode) -> set[str]:
    """Ids of the code cells whose outputs the student copy keeps: no answer can show there.

    Never an answer (nbgrader solution) or a graded check; otherwise a cell before the first
    answer cell (nothing above it depends on an answer), or one its author marked
    `metadata.robot_lab.keep_output: true` (its output does not depend on any answer).
    """
    kept: set[str] = set()
    answered = False
    for cell in nb.cells:
        meta = _nbgrader(cell)
        if meta.get('solution'):
            answered = True
        if cell.cell_type != 'code' or meta.get('solution') or meta.get('grade'):
            continue
        marked = cell.get('metadata', {}).get('robot_lab', {}).get('keep_output') is True
        if (not answered or marked) and cell.get('id'):
            kept.add(str(cell['id']))
    return kept


def _venv_paths() -> list[str]:
    """The kit's venv as this machine names it (longest first, so none shadows another)."""
    found = {sys.prefix, str(kit_root() / '.venv'), os.environ.get('ROBOT_LAB_VENV', '')}
    return sorted((p.rstrip('/') for p in found if len(p.strip('/')) > 1), key=len,
                  reverse=True)


def sanitise_output(text: str) -> str:
    """An output as any student's machine shows it: homes as `~`, the venv `$ROBOT_LAB_VENV`.

    (`$ROBOT_LAB_VENV` is set in the kit's Lab: its terminals and kernels.)
    """
    for venv in _venv_paths():
        text = re.sub(re.escape(venv) + r'(?![\w.-])', '$ROBOT_LAB_VENV', text)
    text = _VENV_PATH.sub('$ROBOT_LAB_VENV', text)
    home = str(Path.home()).rstrip('/')
    if len(home) > 1:
        text = re.sub(re.escape(home) + r'(?=/|[\s\'",:;)\]]|$)', '~', text)
    return _HOME_PATH.sub('~', text)


def _sanitised(value: Any) -> Any:
    if isinstance(value, list):
        return [sanitise_output(v) if isinstance(v, str) else v for v in value]
    return sanitise_output(value) if isinstance(value, str) else value


def _example_outputs(outputs: list[Any]) -> list[Any]:
    """The outputs a copy shows: sanitised, without widget views (their state is not there)."""
    shown = []
    for output in copy.deepcopy(outputs):
        data = output.get('data')
        if isinstance(data, dict) and _WIDGET_MIME in data:
            continue  # a widget's text fallback ("Plot(...)") says nothing without it
        for key in ('text', 'traceback'):
            if key in output:
                output[key] = _sanitised(output[key])
        if isinstance(data, dict):
            for mime in data:
                if mime.startswith('text/'):
                    data[mime] = _sanitised(data[mime])
        output.get('metadata', {}).pop('execution', None)
        shown.append(output)
    return shown


def _strip_nbval_markers(nb: NotebookNode) -> None:
    """Drop `# NBVAL_…` lines; recompute the checksum of a locked cell that had one."""
    from nbgrader.utils import compute_checksum  # type: ignore[import-untyped]

    for cell in nb.cells:
        if cell.cell_type != 'code' or not _NBVAL_LINE.search(cell.source):
            continue
        cell.source = _NBVAL_LINE.sub('', cell.source)
        meta = _nbgrader(cell)
        if meta.get('checksum'):
            meta['checksum'] = compute_checksum(cell)


def student_course_notebook(source: str | Path) -> NotebookNode:
    """A course notebook's student copy: answers removed, example outputs kept, no markers."""
    original = read_notebook(source)
    nb = student_notebook(source)
    outputs = {str(c['id']): c.get('outputs', []) for c in original.cells
               if c.cell_type == 'code' and c.get('id')}
    keep = keeps_output(original)
    for cell in nb.cells:
        if cell.cell_type == 'code' and cell.get('id') in keep:
            cell.outputs = _example_outputs(outputs.get(str(cell['id']), []))
    _strip_nbval_markers(nb)
    return nb


def _copies(root: Path) -> Iterator[tuple[Path, NotebookNode]]:
    """(path in the student copy, notebook) for every course notebook and exercise."""
    notebooks, solutions = root / 'notebooks', root / 'solutions'
    if (root / MANIFEST).is_file():  # a released copy published for students: as it is
        for folder in ('notebooks', 'exercises'):
            for path in sorted((root / folder).glob('*.ipynb')):
                yield Path(folder) / path.name, read_notebook(path)
        return
    if not notebooks.is_dir() and not solutions.is_dir():
        raise RobotLabError('no notebooks/ or solutions/ folder here', file=root,
                            fix="give the course repository's folder")
    for source in sorted(notebooks.glob('*.ipynb')):
        yield Path('notebooks') / source.name, student_course_notebook(source)
    for source in sorted(solutions.glob('*.ipynb')):
        yield Path('exercises') / source.name, exercise_notebook(source)


def _load_manifest(path: Path) -> dict[str, str]:
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as err:
        raise RobotLabError(f'cannot read the release record: {err}', file=path,
                            fix='delete it; files already there are then all kept') from None
    files = data.get('files', {}) if isinstance(data, dict) else {}
    return {str(k): str(v) for k, v in files.items()}


def release_course(dest: str | Path, root: str | Path | None = None, *,
                   sign: bool = True) -> list[ReleasedFile]:
    """Write or update the student copy of the course in `dest`; what happened to each file.

    `root` is the course repository (default: the kit's checkout). With `sign`, every
    notebook written (or already as released) is trusted in the user's Jupyter data dir.
    """
    from nbformat.sign import NotebookNotary

    notary_class: Callable[[], Any] = NotebookNotary  # nbformat is unannotated
    out = Path(dest)
    record = out / MANIFEST
    released = _load_manifest(record)
    notary = notary_class() if sign else None
    results = []
    for rel, nb in _copies(Path(root) if root is not None else kit_root()):
        text = notebook_text(nb)
        target = out / rel
        key = rel.as_posix()
        if not target.exists():
            action = 'new'
        else:
            current = _digest(target.read_bytes())
            if current == _digest(text) or released.get(key) == _digest(text):
                action = 'unchanged'  # as released, or the student's and nothing newer
            elif released.get(key) == current:
                action = 'updated'
            else:
                action = 'kept'
        if action in ('new', 'updated'):
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text)
        if action in ('new', 'updated') or (action == 'unchanged' and key not in released):
            released[key] = _digest(text)
        if notary is not None and target.read_bytes() == text.encode():
            notary.sign(nb)
        results.append(ReleasedFile(rel, action))
    record.parent.mkdir(parents=True, exist_ok=True)
    record.write_text(json.dumps({'files': dict(sorted(released.items()))}, indent=1) + '\n')
    return results
