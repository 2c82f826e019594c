"""The student's copy of the course: one source (the repository), two copies.

`release_course(DIR)` writes DIR/notebooks/*.ipynb (the course notebooks) and
DIR/exercises/*.ipynb with the answers removed and the checks kept, by the same nbgrader
pipeline as the exercises (robot_lab.grading.exercises.student_notebook). Students work in
DIR, so autosave never touches the repository and the next `git pull` of the course never
conflicts.

The course may also be a released copy (one with .robot_lab/release.json, published for a
hub's students): its notebooks are then given as they are, never through nbgrader again.

Released again (a new notebook, a fixed typo), it adds what is new and updates what the
student has not touched, but never overwrites a file the student changed: DIR/.robot_lab
/release.json remembers the hash of every file as released. Released notebooks are signed
with nbformat's NotebookNotary (the user's Jupyter data dir), so they open trusted.
"""

from __future__ import annotations

import hashlib
import json
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

__all__ = ['MANIFEST', 'ReleasedFile', 'release_course']

MANIFEST = Path('.robot_lab') / 'release.json'


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
        yield Path('notebooks') / source.name, student_notebook(source)
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
