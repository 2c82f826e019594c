"""An nbgrader course of the kit's exercises, in one command: `robot-lab course nbgrader DIR`.

The kit's solutions are nbgrader source notebooks already (robot_lab.grading.exercises), so
a course needs only nbgrader's layout around them: DIR/source/exNN/<exercise>.ipynb, an
nbgrader_config.py naming the course (course_id), its folder and its exchange, and the
students' own config (course_id and exchange: what `fetch_assignment` and `submit` need).
The exchange is DIR/exchange unless another (shared) folder is named. Files already there
are kept, so an instructor's edits survive running it again.

Autograding keeps students apart by itself: under nbgrader (NBGRADER_EXECUTION=autograde)
each notebook's set-up cell gives its kernel a new workspace and a leased ROS domain
(robot_lab.grading.course).
"""

from __future__ import annotations

import re
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from nbconvert.preprocessors import Preprocessor

from robot_lab.grading.exercises import kit_root

__all__ = ['COURSE_ID', 'CourseFile', 'StudentPaths', 'student_paths', 'write_course']

COURSE_ID = 'robot_lab'
_INSTRUCTOR = """\
# nbgrader's configuration of the robot_lab course (written by `robot-lab course nbgrader`).
c = get_config()  # noqa: F821 (nbgrader's config loader provides it)
c.CourseDirectory.course_id = {course_id!r}
c.CourseDirectory.root = {root!r}
# Where release_assignment puts assignments and students' submit puts their work: every
# student must be able to reach it (on a hub, a shared folder such as /srv/nbgrader/exchange).
c.Exchange.root = {exchange!r}
# A check that starts ROS nodes and watches them needs more than nbgrader's 30 s per cell.
c.ExecutePreprocessor.timeout = 120
# Feedback shows the paths a student knows (~/robot_lab_ws), not the grader's folders.
from nbconvert.preprocessors import CSSHTMLHeaderPreprocessor  # noqa: E402
from nbgrader.preprocessors import GetGrades  # noqa: E402
from robot_lab.grading.nbgrader_course import StudentPaths  # noqa: E402
c.GenerateFeedback.preprocessors = [GetGrades, CSSHTMLHeaderPreprocessor, StudentPaths]
"""
_STUDENTS = """\
# The students' nbgrader configuration of the robot_lab course (`robot-lab course nbgrader`):
# on a hub, copy it to /etc/jupyter/nbgrader_config.py (or each student's ~/.jupyter/).
c = get_config()  # noqa: F821 (nbgrader's config loader provides it)
c.CourseDirectory.course_id = {course_id!r}
c.Exchange.root = {exchange!r}
# Validate runs the checks: one that starts ROS nodes needs more than nbgrader's 30 s.
c.ExecutePreprocessor.timeout = 120
"""


_AUTOGRADE_FOLDER = re.compile(r'(?:/[\w.-]+)*/robot_lab_autograde_\w+')


def student_paths(text: str) -> str:
    """`text` with the grader's folders as the student knows them: an autograded kernel's
    workspace is their ~/robot_lab_ws, the instructor's home is `~`, the kit is `robot_lab`."""
    text = _AUTOGRADE_FOLDER.sub('~/robot_lab_ws', text)
    text = text.replace(str(kit_root()) + '/', '')
    home = str(Path.home())
    return text.replace(home + '/', '~/') if home != '/' else text


class StudentPaths(Preprocessor):
    """nbgrader's feedback: every output with `student_paths` applied."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)  # type: ignore[no-untyped-call]
        self.enabled = True  # nbconvert runs only enabled preprocessors

    def preprocess_cell(self, cell: Any, resources: Any, index: int) -> tuple[Any, Any]:
        for output in cell.get('outputs', []):
            if 'text' in output:
                output['text'] = student_paths(str(output['text']))
            if 'traceback' in output:
                output['traceback'] = [student_paths(line) for line in output['traceback']]
            if 'evalue' in output:
                output['evalue'] = student_paths(str(output['evalue']))
            for kind, value in output.get('data', {}).items():
                if kind.startswith('text/') and isinstance(value, str):
                    output['data'][kind] = student_paths(value)
        return cell, resources


@dataclass(frozen=True)
class CourseFile:
    """A file of the course and whether this run wrote it ('wrote') or left it ('kept')."""

    path: Path
    action: str


def assignment_of(exercise: str) -> str:
    """`ex04` for `ex04_parameters`: the assignment an exercise is released as."""
    return exercise.split('_', 1)[0]


def write_course(dest: str | Path, *, course_id: str = COURSE_ID,
                 exchange: str | Path | None = None,
                 solutions: str | Path | None = None) -> list[CourseFile]:
    """Write (or complete) the nbgrader course in `dest`; each file and what was done."""
    root = Path(dest).resolve()
    shared = Path(exchange).resolve() if exchange is not None else root / 'exchange'
    files: list[CourseFile] = []

    def write(path: Path, text: str | None = None, source: Path | None = None) -> None:
        if path.exists():
            files.append(CourseFile(path, 'kept'))
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        if source is not None:
            shutil.copyfile(source, path)
        else:
            path.write_text(text or '')
        files.append(CourseFile(path, 'wrote'))

    settings = {'course_id': course_id, 'root': str(root), 'exchange': str(shared)}
    write(root / 'nbgrader_config.py', _INSTRUCTOR.format(**settings))
    write(root / 'students' / 'nbgrader_config.py', _STUDENTS.format(**settings))
    folder = Path(solutions) if solutions is not None else kit_root() / 'solutions'
    for notebook in sorted(folder.glob('*.ipynb')):
        write(root / 'source' / assignment_of(notebook.stem) / notebook.name, source=notebook)
    if not shared.exists():
        shared.mkdir(parents=True)
        shared.chmod(0o1777)  # every student submits into it, like /tmp
    return files
