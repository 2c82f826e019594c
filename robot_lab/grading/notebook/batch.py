"""A class's notebooks graded: each in a fresh kernel and folder, in a domain of its own.

`grade_many` leases one ROS domain per job slot from the host's registry (never a user's,
never another job's), refuses a set that holds a student's exercise twice (its total
would add the copies up), and gives a refused notebook a result of its own ("not graded");
`student_reports` turns the results into the instructor's gradebook rows.
"""

from __future__ import annotations

import json
import queue
import subprocess
import sys
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.exercises import exercise_name, read_notebook
from robot_lab.grading.notebook.answer_key import identify, student_of
from robot_lab.grading.notebook.grade import GradeResult, grade, submissions

if TYPE_CHECKING:
    from robot_lab.grading.report import StudentReport

__all__ = ['grade_many', 'student_reports']


def grade_many(paths: list[str | Path], jobs: int = 1, domain_id: int | None = None,
               executed_dir: str | Path | None = None,
               on_result: Callable[[GradeResult], None] | None = None,
               **kwargs: Any) -> list[GradeResult]:
    """Grade several submissions, `jobs` at a time; results in submission order.

    `on_result` is called as each one finishes; `executed_dir` receives each executed
    notebook as STUDENT/EXERCISE.graded.ipynb (one file per submission, never overwritten
    by the next student's).

    Every submission runs in a ROS domain leased from the host's registry for the run
    (robot_lab.domain.lease_domains: never a user's, never another job's, never 0..N-1),
    one per job slot, so one student's nodes never answer another's checks; `domain_id`
    instead names the one domain to use (then `jobs` must be 1). With jobs > 1 each
    submission is graded by a child `robot-lab grade --json`.
    """
    from robot_lab.domain import lease_domains

    found = submissions(paths)
    _one_copy_each(paths, found, kwargs.get('solutions_dir'))
    targets = _executed_paths(found, executed_dir, kwargs.get('solutions_dir'))

    def executed(path: Path) -> Path | None:
        return targets.get(path)

    if domain_id is not None and jobs > 1:
        raise RobotLabError(f'--domain-id names one domain, but -j {jobs} grades {jobs} '
                            'notebooks at once', fix='leave out --domain-id: the grader '
                            'then leases a domain per job from the registry')
    if domain_id is not None:
        return _grade_in_turn(found, domain_id, executed, on_result, **kwargs)
    slots_needed = max(1, min(jobs, len(found)))
    with lease_domains(slots_needed, purpose='robot-lab grade') as leased:
        if jobs <= 1 or len(found) <= 1:
            return _grade_in_turn(found, leased[0], executed, on_result, **kwargs)
        slots: queue.Queue[int] = queue.Queue()
        for domain in leased:
            slots.put(domain)

        def one(path: Path) -> GradeResult:
            domain = slots.get()
            try:
                result = _grade_in_child(path, domain, executed=executed(path), **kwargs)
            finally:
                slots.put(domain)
            if on_result is not None:
                on_result(result)
            return result

        with ThreadPoolExecutor(len(leased), thread_name_prefix='robot_lab-grade') as pool:
            return list(pool.map(one, found))


def _one_copy_each(paths: list[str | Path], found: list[Path],
                   solutions_dir: str | Path | None) -> None:
    """Refuse, in one line, a set that holds a student's exercise twice (an nbgrader course
    folder holds source/, release/, submitted/ and autograded/ copies): its total would
    add the copies up."""
    for raw in paths:
        folder = Path(raw)
        if folder.is_dir() and ((folder / 'nbgrader_config.py').is_file() or all(
                (folder / part).is_dir() for part in ('source', 'submitted'))):
            raise RobotLabError('this is an nbgrader course folder: it holds the source, the '
                                'release and every student copy', file=folder,
                                fix=f'grade what students handed in: {folder / "submitted"}')
    seen: dict[tuple[str, str], Path] = {}
    for path in found:
        try:
            exercise = identify(path, read_notebook(path), solutions_dir)
        except (RobotLabError, OSError, ValueError):
            continue  # refused later, on its own row
        key = (student_of(path, exercise), exercise)
        if key in seen:
            raise RobotLabError(f'{key[0]} has two copies of {exercise}: {seen[key]} and '
                                'this one', file=path,
                                fix='give one copy per student and exercise (e.g. only an '
                                "nbgrader course's submitted/ folder)")
        seen[key] = path


def _grade_in_turn(found: list[Path], domain: int,
                   executed: Callable[[Path], Path | None],
                   on_result: Callable[[GradeResult], None] | None,
                   **kwargs: Any) -> list[GradeResult]:
    """Grade one submission after the other in `domain`, each in a fresh kernel and folder."""
    results = []
    for path in found:
        try:
            results.append(grade(path, domain_id=domain, executed=executed(path), **kwargs))
        except RobotLabError as err:  # one unreadable file must not stop the batch
            results.append(_refused(path, str(err)))
        if on_result is not None:
            on_result(results[-1])
    return results


def _grade_in_child(path: Path, domain: int, cell_timeout: float = 60.0,
                    solutions_dir: str | Path | None = None,
                    executed: str | Path | None = None,
                    total_timeout: float | None = 900.0, **_ignored: Any) -> GradeResult:
    """`robot-lab grade --json` for one submission in a child process (its own kernel)."""
    from robot_lab.process import spawn

    cmd = [sys.executable, '-c', 'from robot_lab.cli import entry; entry()', 'grade', '--json',
           '--timeout', str(cell_timeout), '--domain-id', str(domain), str(path)]
    if total_timeout is not None:
        cmd += ['--total-timeout', str(total_timeout)]
    if solutions_dir is not None:
        cmd += ['--solutions', str(solutions_dir)]
    if executed is not None:
        cmd += ['--executed-as', str(executed)]
    child = spawn(cmd, stderr=subprocess.PIPE)  # this pool thread lives until it ends
    out, err = child.communicate()
    try:
        return GradeResult.from_dict(json.loads(out))
    except (ValueError, KeyError, TypeError):
        said = err.decode(errors='replace').strip()
        if child.returncode == 1 and said and '\n' not in said:  # refused: the CLI's one line
            return _refused(path, said)
        return _refused(path, f'the grader for this submission exited {child.returncode}: '
                        + said[-300:])


def _refused(path: Path, why: str) -> GradeResult:
    """A submission that was not graded (unreadable, or of no known exercise)."""
    return GradeResult(str(path), exercise_name(path), student_of(path, path.stem),
                       status='error', detail=why)


def _executed_paths(found: list[Path], executed_dir: str | Path | None,
                    solutions_dir: str | Path | None) -> dict[Path, Path]:
    """Where each executed notebook goes: DIR/<student>/<exercise>.graded.ipynb, unique."""
    from robot_lab.grading.report import safe_name

    if executed_dir is None:
        return {}
    out = Path(executed_dir)
    out.mkdir(parents=True, exist_ok=True)
    targets: dict[Path, Path] = {}
    for path in found:
        try:
            exercise = identify(path, read_notebook(path), solutions_dir)
        except (RobotLabError, OSError, ValueError):
            continue  # refused: nothing runs, nothing to keep
        folder = out / safe_name(student_of(path, exercise))
        target, n = folder / f'{exercise}.graded.ipynb', 2
        while target in targets.values():
            target, n = folder / f'{exercise}-{n}.graded.ipynb', n + 1
        folder.mkdir(parents=True, exist_ok=True)
        targets[path] = target
    return targets


def student_reports(results: list[GradeResult]) -> list[StudentReport]:
    """The graded notebooks as the instructor's outputs see them: one report per student,
    each check named `<exercise>/<grade_id>` (two exercises may share a check's name)."""
    from robot_lab.grading.report import CheckOutcome, StudentReport

    reports: dict[str, StudentReport] = {}
    graded = {r.student for r in results if r.checks}
    for r in results:
        if r.status == 'error' and not r.checks:  # refused: a visible "not graded" row
            name = f'{r.student} ({Path(r.notebook).name})' if r.student in graded else \
                r.student
            refused = reports.setdefault(name, StudentReport(name, status='not graded'))
            refused.title = ', '.join(filter(None, [refused.title, Path(r.notebook).name]))
            refused.error = '; '.join(filter(None, [refused.error, r.detail]))
            continue
        report = reports.setdefault(r.student, StudentReport(r.student))
        report.title = ', '.join(filter(None, [report.title, r.exercise]))
        report.elapsed += r.elapsed
        for c in r.checks:
            if c.passed:
                output = f'```\n{c.output}\n```' if c.output else 'Passed.'
            else:
                output = f'```\n{c.message}\n```'
                if r.status != 'completed' and c.message.startswith('not run'):
                    output += f'\n\nThe run ended early: {r.detail}'
            report.checks.append(CheckOutcome(f'{r.exercise}/{c.check}', c.check, c.points,
                                              c.max_points, output))
    return list(reports.values())
