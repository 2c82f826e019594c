"""One package submission's job (run inside the sandbox): the stages, then the checks.

`python -m robot_lab.grading.package.job JOBDIR` reads JOBDIR/job.json (student,
source, rubric), and writes JOBDIR/report.json after every stage, so a job stopped at
its time budget still hands back what it had scored. Stages: 'files' (the submission
copied into a private workspace; its README, parameter and launch files found), 'build'
(`colcon build`, the kit's build), 'run' (robot_lab.grading.package.live: the student's
own launch file under the kit's launcher, watched by an observer session). After each
stage the rubric's checks registered for it (robot_lab.grading.package.registry) are
scored. The grader's own failures are never a lost point: an exception in a check, a stage
that raised (`JobState.stage_faults`) or a fault a check reports (`Verdict.grader_error`)
gives the check its points, marked as a grader error for a regrade (`--only`).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path

from robot_lab.errors import RobotLabError
from robot_lab.grading.package.crash import public_text
from robot_lab.grading.package.registry import Stage, registered_checks
from robot_lab.grading.package.rubric import Rubric, RubricCheck, load_rubric
from robot_lab.grading.package.state import JobState, Verdict, section
from robot_lab.grading.package.submission import find_package
from robot_lab.grading.report import CheckOutcome, StudentReport

__all__ = ['launch_files_of', 'main', 'param_files_of', 'run_job', 'score_stage']

_LAUNCH_SUFFIXES = ('.launch.py', '.launch.xml', '.launch.yaml', '_launch.py', '.py',
                    '.xml', '.yaml')


def _outcome(state: JobState, check_id: str, verdict: Verdict) -> None:
    check = state.rubric.check(check_id)
    if check is None:
        return
    state.outcomes[check_id] = CheckOutcome(check.id, check.name,
                                            check.points * min(1.0, verdict.fraction),
                                            check.points, verdict.text())


def _where(err: BaseException) -> str:
    """`Type: message (file.py:line)`: the grader's failure, for the instructor."""
    frames = traceback.extract_tb(err.__traceback__)
    where = f' ({Path(frames[-1].filename).name}:{frames[-1].lineno})' if frames else ''
    return f'{type(err).__name__}: {err}{where}'


def _grader_error(state: JobState, check: RubricCheck, why: str, text: str = '') -> None:
    """The check's points kept and the check marked: the grader failed, not the package."""
    state.grader_errors.append(f'{check.id}: {why}')
    state.outcomes[check.id] = CheckOutcome(
        check.id, check.name, check.points, check.points,
        f'**Grader error:** the grader failed while scoring this check ({why}); the points '
        'are kept and the instructor has been told to regrade it. This is not a fault in '
        'your package.' + (f'\n\nWhat the grader saw before it failed:\n\n{text}'
                           if text else ''), grader_error=why)


def score_stage(state: JobState, stage: Stage) -> None:
    """Score the rubric's checks registered for `stage`, in the rubric's order."""
    registered = registered_checks()
    # A stage that raised leaves its checks and the later stages' without all their data.
    fault = '; '.join(f'{s} stage: {why}' for s, why in state.stage_faults.items())
    for check in state.rubric.checks:
        entry = registered.get(check.id)
        if entry is None or entry.stage != stage:
            continue
        try:
            verdict = entry.run(state, check)
        except Exception as err:  # the grader's own fault: the student keeps the points
            _grader_error(state, check, _where(err))
            continue
        own = state.check_faults.get(check.id, '')
        seen = section(verdict.expected, verdict.observed)  # no fix: nothing for them to fix
        if verdict.grader_error:
            _grader_error(state, check, verdict.grader_error, seen)
        elif (fault or own) and verdict.fraction < 1:
            _grader_error(state, check, own or fault, seen)
        else:
            _outcome(state, check.id, verdict)


def param_files_of(package: Path) -> list[Path]:
    """YAML files of the package that look like parameter files (not launch files)."""
    found = []
    for path in sorted(package.rglob('*.y*ml')):
        rel = path.relative_to(package)
        if any(part in ('build', 'install', 'log', 'test') for part in rel.parts):
            continue
        if path.name.endswith(('.launch.yaml', '.launch.yml')) or rel.parts[0] == 'launch':
            continue
        found.append(path)
    return found


def launch_files_of(package: Path) -> list[Path]:
    folder = package / 'launch'
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.rglob('*') if p.is_file() and p.name.endswith(_LAUNCH_SUFFIXES)
                  and '__pycache__' not in p.parts)


def _write(job_dir: Path, state: JobState, student: str, status: str = 'graded',
           error: str = '', started: float = 0.0) -> None:
    from robot_lab.grading.package.sandbox import BLOCKED, NOT_SET_UP, REPORT_FD_VAR

    # Paths as the student knows them (<pkg>/node.py), never the job's or the kit's.
    for outcome in state.outcomes.values():
        outcome.output = public_text(outcome.output, job_dir)
    checks = [state.outcomes.get(c.id) or CheckOutcome(
        c.id, c.name, 0.0, c.points, 'Not reached: the grading job ended before this check.')
        for c in state.rubric.checks]
    if state.grader_errors and status == 'graded':
        status, error = 'grader error', '; '.join(state.grader_errors)
    notes = [public_text(n, job_dir) for n in [*NOT_SET_UP, *state.blocked, *BLOCKED]]
    report = StudentReport(student, checks, status, error, list(state.images),
                           state.rubric.lab, time.monotonic() - started, notes=notes)
    data = json.dumps(report.to_dict())
    fd = os.environ.get(REPORT_FD_VAR)
    if fd:  # the grader's pipe: out of reach of the student's processes
        view = memoryview((data + '\n').encode())
        while view:
            view = view[os.write(int(fd), view):]
        return
    tmp = job_dir / 'report.json.tmp'
    tmp.write_text(data)
    tmp.replace(job_dir / 'report.json')


def _build(state: JobState, ws: Path) -> None:
    from robot_lab.pkg.build import build

    result = build(ws, progress=False)
    state.built = result.ok
    if result.ok:
        state.build_note = f'built {", ".join(result.finished)} in {result.duration:.1f} s'
    else:
        state.build_lines = result.report_lines() or result.output[-12:]


def _workspace(package: Path, unpacked: Path, ws: Path) -> Path:
    """The student's package (and, from a workspace, its sibling packages) in ws/src."""
    (ws / 'src').mkdir(parents=True, exist_ok=True)
    ignore = shutil.ignore_patterns('build', 'install', 'log', '__pycache__')
    target = ws / 'src' / _package_name(package)
    shutil.copytree(package, target, symlinks=True, ignore=ignore)
    if package != unpacked:  # a workspace: the lab's package may depend on its siblings
        for sibling in sorted(package.parent.iterdir()):
            if (sibling != package and (sibling / 'package.xml').is_file()
                    and not (ws / 'src' / _package_name(sibling)).exists()):
                shutil.copytree(sibling, ws / 'src' / _package_name(sibling), symlinks=True,
                                ignore=ignore)
    return target


def run_job(job_dir: Path, rubric: Rubric | None = None) -> int:
    """Grade the job in `job_dir`; `rubric` read before the sandbox hid its file."""
    from robot_lab.grading.package import live

    job = json.loads((job_dir / 'job.json').read_text())
    rubric = rubric or load_rubric(job['rubric'])
    student = str(job['student'])
    state = JobState(rubric)
    started = time.monotonic()
    ws = job_dir / 'ws'
    unpacked = job_dir / 'submission'  # the grader unpacked it (package.grade)
    try:
        package = find_package(unpacked, shown=Path(job['source']).name)
    except RobotLabError as err:
        for check in rubric.checks:
            _outcome(state, check.id, Verdict(False, 'a ROS 2 package', err.message,
                                              err.fix or ''))
        _write(job_dir, state, student, started=started)
        return 0
    try:
        target = _workspace(package, unpacked, ws)
        state.package = target
        state.package_name = target.name
        state.param_files = param_files_of(target)
        state.launch_files = launch_files_of(target)
    except Exception as err:  # copying and listing the files: the grader's own calls
        state.stage_faults['files'] = _where(err)
        state.live.grader_fault = state.stage_faults['files']
    stages: tuple[tuple[Stage, Callable[[], None]], ...] = (
        ('files', lambda: None), ('build', lambda: _build(state, ws)),
        ('run', lambda: live.run_system(job_dir, ws, state)))
    for stage, prepare in stages:
        if state.package is not None and not state.stage_faults:
            try:
                prepare()
            except Exception as err:  # the grader's own fault: its checks keep the points
                traceback.print_exc()
                state.stage_faults[stage] = _where(err)
                state.live.grader_fault = state.live.grader_fault or state.stage_faults[stage]
                if not state.live.not_run:
                    state.live.not_run = (f'the grader failed in the {stage} stage: '
                                          f'{state.stage_faults[stage]}')
        score_stage(state, stage)
        _write(job_dir, state, student, started=started)
        _stage(stage, started)
    return 0


def _stage(what: str, started: float) -> None:
    print(f'[{time.monotonic() - started:6.2f} s] {what} done', flush=True)


def _package_name(package: Path) -> str:
    match = re.search(r'<name>\s*([^<\s]+)\s*</name>', (package / 'package.xml').read_text(
        errors='replace'))
    return match.group(1) if match else package.name


def main(argv: list[str] | None = None) -> int:
    from robot_lab.grading.package.sandbox import REPORT_FD_VAR, enter

    args = sys.argv[1:] if argv is None else argv
    job_dir = Path(args[0])
    job = json.loads((job_dir / 'job.json').read_text())
    rubric = load_rubric(job['rubric'])
    if os.environ.get(REPORT_FD_VAR):  # not for the student's processes
        os.set_inheritable(int(os.environ[REPORT_FD_VAR]), False)
    enter(rubric.limits, bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')), job_dir)
    return run_job(job_dir, rubric)


if __name__ == '__main__':
    sys.exit(main())
