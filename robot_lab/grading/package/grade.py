"""Grade a class's package submissions: `robot-lab grade DIR --lab ch6-lab1 -o OUT`.

Each student's entry is graded by its own job (robot_lab.grading.package.sandbox) running
robot_lab.grading.package.job: N jobs at a time, each in a ROS domain of its own
(`job_domains`), a progress bar over students. A job that crashes or runs out of time
still gives its student a report (the checks it had scored, the rest at 0, the reason);
only a grader that cannot run at all fails. Outputs (robot_lab.grading.report) and the
similarity report (robot_lab.grading.package.similarity) go to OUT.
"""

from __future__ import annotations

import contextlib
import json
import os
import queue
import shutil
import sys
import tempfile
import threading
import uuid
from collections.abc import Callable, Collection, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.gradebook import ClassOutputs, write_class
from robot_lab.grading.late import LatePolicy
from robot_lab.grading.package.crash import public_text
from robot_lab.grading.package.rubric import Rubric, load_rubric, rubric_path
from robot_lab.grading.package.sandbox import (
    GRADER_PROBLEM,
    JOB_LOGS_VAR,
    check_can_contain,
    job_domains,
    run_job,
    stop_jobs,
)
from robot_lab.grading.package.submission import Submission, find_submissions, unpack
from robot_lab.grading.report import CheckOutcome, StudentReport

__all__ = ['ClassRun', 'grade_class', 'grade_package', 'grade_packages', 'not_graded',
           'resolve_rubric']


def resolve_rubric(lab: str | None, rubric: str | Path | None) -> Rubric:
    """`--rubric FILE` when given, else the shipped rubric of `--lab`."""
    if rubric is not None:
        return load_rubric(rubric)
    return load_rubric(rubric_path(lab or 'ch6-lab1'))


def grade_package(submission: Submission, rubric: Rubric, domain: int | None = None,
                  work: Path | None = None, keep: Path | None = None) -> StudentReport:
    """Grade one student's entry in a sandboxed job; never raises for the student's faults.

    `domain`: the job's ROS domain (default: one from `job_domains`); `keep`: a folder to
    copy the job's graph picture into (the job folder is removed).
    """
    if domain is None:
        with job_domains(1) as [leased]:
            return grade_package(submission, rubric, leased, work, keep)
    assert rubric.source is not None
    job_dir = Path(tempfile.mkdtemp(prefix='robot_lab_grade_', dir=work))
    try:
        try:  # unpacked here, so the job never reads the class's folder
            unpack(submission, job_dir / 'submission')
        except RobotLabError as err:
            return not_graded(submission.student, rubric, err)
        (job_dir / 'job.json').write_text(json.dumps({
            'student': submission.student, 'source': str(submission.source.resolve()),
            'rubric': str(rubric.source.resolve())}))
        run = run_job(job_dir, domain, rubric.limits, uuid.uuid4().hex)
        report = _read_report(job_dir, submission.student, rubric)
        if run.timed_out:
            report.status = 'timeout'
            report.error = (f'stopped after {rubric.limits.wall_seconds:g} s (every process '
                            'of it killed); checks not reached score 0')
        elif run.returncode != 0 or not (job_dir / 'report.json').is_file():
            report.status = 'error'
            last = public_text(run.output, job_dir).strip().splitlines()[-6:]
            report.error = (f'the grading job ended with code {run.returncode}: '
                            + ' | '.join(last))
            if run.out_of_memory:  # the kernel's SIGKILL, not a mysterious crash
                report.error = f'{_too_much_memory(rubric)} it; checks not reached score 0'
            elif run.returncode is not None and run.returncode >= 128 and run.isolated:
                report.notes.append(
                    f'the grading job was killed by signal {run.returncode - 128} from inside '
                    'its sandbox (a process of the submission signalled it); no process '
                    'outside the sandbox could be reached')
        if run.out_of_memory and report.status != 'error':
            report.notes.append(f'{_too_much_memory(rubric)} the process that went past '
                                'it, so checks that needed that process may have failed')
        for note in report.notes:
            if note.startswith(GRADER_PROBLEM):  # the instructor hears of it at once
                print(f'warning: {submission.student}: {note}', file=sys.stderr, flush=True)
        report.elapsed = run.elapsed
        if keep is None:
            report.images = []  # they live in the job folder, removed below
        else:
            kept = []
            for image in report.images:
                source = job_dir / Path(image).name
                if source.is_file():
                    target = keep / uuid.uuid4().hex[:12] / source.name
                    target.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copyfile(source, target)
                    kept.append(target)
            report.images = kept
        return report
    finally:
        logs = os.environ.get(JOB_LOGS_VAR)
        if logs:
            with contextlib.suppress(OSError):
                Path(logs).mkdir(parents=True, exist_ok=True)
                shutil.copyfile(job_dir / 'job.log', Path(logs) / f'{submission.student}.log')
        shutil.rmtree(job_dir, ignore_errors=True)


def _too_much_memory(rubric: Rubric) -> str:
    """The start of what a student reads when the whole job reached `job_memory_mb`."""
    return (f'the submission used more than {rubric.limits.job_memory_mb} MB of memory in '
            'all (its processes together); the kernel stopped')


def not_graded(student: str, rubric: Rubric, err: RobotLabError) -> StudentReport:
    """A row of zeros for an entry that holds no package, saying what to hand in."""
    why = f'{err.message} — {err.fix}' if err.fix else err.message
    checks = [CheckOutcome(c.id, c.name, 0.0, c.points,
                           'Not graded: there is no package to grade (see the top).')
              for c in rubric.checks]
    return StudentReport(student, checks, 'not graded', why, title=rubric.lab)


def _read_report(job_dir: Path, student: str, rubric: Rubric) -> StudentReport:
    """The job's last report (sandbox._keep_report wrote it from the job's pipe), or a row
    that says why there is none.

    A report that does not load though the job ended well (code 0) has one known cause: a
    job runs the kit's code as it is on disk when it starts, so a kit changed while a
    class is graded (an upgrade, or an edit of the checkout) can hand back a report this
    grader's older code cannot read (a field it does not know: TypeError)."""
    path = job_dir / 'report.json'
    why = 'the grading job left no report'
    if path.is_file():
        try:
            report = StudentReport.from_dict(json.loads(path.read_text()))
            report.student = student
            return report
        except (ValueError, TypeError, KeyError) as err:
            why = (f'the grading job left a report this grader cannot read ({type(err).__name__}'
                   f': {str(err)[:200]}): was the kit changed while grading? Regrade it')
    return StudentReport(student, [CheckOutcome(c.id, c.name, 0.0, c.points,
                                                'Not reached: the grading job ended early.')
                                   for c in rubric.checks], title=rubric.lab, status='error',
                         error=why)


def _progress(total: int, enabled: bool) -> Any:
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, unit='student', desc='grading', dynamic_ncols=True)


@dataclass
class ClassRun:
    """A run over a class: this run's reports, what OUT holds now, the similarity page."""

    reports: list[StudentReport]
    outputs: ClassOutputs | None = None
    similarity: Path | None = None


def select(entries: Sequence[Submission], only: Collection[str]) -> list[Submission]:
    """The entries of the students named by `--only` (ids as in grades.csv)."""
    known = {e.student for e in entries}
    unknown = [s for s in only if s not in known]
    if unknown:
        raise RobotLabError(f'--only: no hand-in for {", ".join(unknown)}',
                            fix='use the ids of grades.csv (robot-lab grade DIR --lab LAB '
                            '--list shows them)')
    return [e for e in entries if e.student in only]


def grade_packages(
    submissions: str | Path | Sequence[str | Path],
    rubric: Rubric,
    out_dir: str | Path | None = None,
    jobs: int = 1,
    progress: bool = True,
    on_report: Callable[[StudentReport], None] | None = None,
) -> list[StudentReport]:
    """Grade every student under `submissions`; write OUT's files when `out_dir` is given."""
    return grade_class(submissions, rubric, out_dir, jobs=jobs, progress=progress,
                       on_report=on_report).reports


def grade_class(
    submissions: str | Path | Sequence[str | Path],
    rubric: Rubric,
    out_dir: str | Path | None = None,
    *,
    jobs: int = 1,
    progress: bool = True,
    on_report: Callable[[StudentReport], None] | None = None,
    only: Collection[str] | None = None,
    late: LatePolicy | None = None,
    roster: str | Path | None = None,
    roster_column: str | None = None,
    ascii_names: bool = False,
) -> ClassRun:
    """Grade a class (or, `only`, some of its students) and merge the results into OUT.

    A grader on a machine without namespaces refuses unless told --no-sandbox; before the
    first job it prints how the jobs will be contained (sandbox.check_can_contain)."""
    print(check_can_contain(limits=rubric.limits), file=sys.stderr, flush=True)
    if isinstance(submissions, str | Path):
        entries = find_submissions(submissions)
    elif len(submissions) == 1:
        entries = find_submissions(submissions[0])
    else:  # several entries named on the command line: one student each
        entries = [e for path in submissions for e in find_submissions(path)]
    everyone = entries
    if only is not None:
        entries = select(entries, only)
    jobs = max(1, min(jobs, len(entries) or 1))
    slots: queue.Queue[int] = queue.Queue()
    bar = _progress(len(entries), progress)
    lock = threading.Lock()
    out = Path(out_dir) if out_dir is not None else None
    keep = out / 'feedback' / '.images' if out is not None else None
    reports: list[StudentReport] = []

    running: set[str] = set()

    def show() -> None:  # the students being graded now
        if bar is not None:
            bar.set_postfix_str(', '.join(sorted(running)), refresh=True)

    def one(entry: Submission) -> StudentReport:
        domain = slots.get()
        try:
            with lock:
                running.add(entry.student)
                show()
            report = grade_package(entry, rubric, domain=domain, keep=keep)
        finally:
            slots.put(domain)
        with lock:
            running.discard(entry.student)
            if bar is not None:
                bar.update(1)
                show()
            if on_report is not None:
                on_report(report)
        return report

    try:
        with job_domains(jobs) as leased, ThreadPoolExecutor(
                max_workers=jobs, thread_name_prefix='grade-job') as pool:
            for domain in leased:
                slots.put(domain)
            try:
                reports = list(pool.map(one, entries))
            except KeyboardInterrupt:  # the jobs have process groups of their own
                pool.shutdown(wait=False, cancel_futures=True)
                stop_jobs()
                raise
    finally:
        stop_jobs(False)
        if bar is not None:
            bar.close()
    run = ClassRun(reports)
    if out is not None:
        run.outputs = write_class(
            out, reports, rubric.ids, only=only, late=late, roster=roster,
            roster_column=roster_column, title=rubric.lab, ascii_names=ascii_names,
            sources={e.student: e.source.name for e in entries})
        if keep is not None:
            shutil.rmtree(keep, ignore_errors=True)
        if only is None and len(everyone) > 1:
            from robot_lab.grading.package.similarity import similarity_report

            run.similarity = out / 'similarity.html'
            similarity_report(everyone, run.similarity)
    return run
