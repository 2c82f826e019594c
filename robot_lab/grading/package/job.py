"""One package submission's job (run inside the sandbox): build, launch, watch, score.

`python -m robot_lab.grading.package_checks JOBDIR` reads JOBDIR/job.json (student,
source, rubric), and writes JOBDIR/report.json after every stage, so a job stopped at
its time budget still hands back what it had scored. Stages: copy the submission into a
private workspace; static checks (README, parameter file, launch file); `colcon build`
(the kit's build); the student's own launch file with the kit's launcher; an observer
session watching the graph (robot_lab.grading.roles); parameters read back from the
running nodes; a picture of the graph; everything stopped; behavioural checks scored.
"""

from __future__ import annotations

import json
import os
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.report import CheckOutcome, StudentReport
from robot_lab.grading.rubric import Rubric, load_rubric
from robot_lab.grading.submission import Submission, copy_submission, find_package

__all__ = ['JobState', 'launch_files_of', 'main', 'param_files_of', 'readme_outcome']

_LAUNCH_SUFFIXES = ('.launch.py', '.launch.xml', '.launch.yaml', '_launch.py', '.py',
                    '.xml', '.yaml')
_LINES = 12  # log / build lines shown per check


def _section(expected: str, observed: str, fix: str = '') -> str:
    text = f'**Expected:** {expected}\n\n**Observed:** {observed}'
    if fix:
        text += f'\n\n**How to fix:** {fix}'
    return text


def _code(lines: list[str] | str, limit: int = _LINES) -> str:
    items = lines.splitlines() if isinstance(lines, str) else list(lines)
    if len(items) > limit:
        items = [f'... ({len(items) - limit} earlier lines cut)', *items[-limit:]]
    body = '\n'.join(line[:300] for line in items).replace('```', "'''")
    return f'\n\n```\n{body}\n```\n'


@dataclass
class JobState:
    """What the stages found; the checks read it."""

    rubric: Rubric
    package: Path | None = None
    package_name: str = ''
    launch_files: list[Path] = field(default_factory=list)
    param_files: list[Path] = field(default_factory=list)
    built: bool | None = None
    build_lines: list[str] = field(default_factory=list)
    outcomes: dict[str, CheckOutcome] = field(default_factory=dict)
    images: list[Path] = field(default_factory=list)


def _outcome(state: JobState, check_id: str, earned: bool | float, output: str) -> None:
    check = state.rubric.check(check_id)
    if check is None:
        return
    score = check.points * (float(earned) if not isinstance(earned, bool) else earned)
    state.outcomes[check_id] = CheckOutcome(check.id, check.name, score, check.points, output)


def readme_outcome(package: Path, require: list[str]) -> tuple[bool, str]:
    """(passed, feedback): a README that names the build and the launch command."""
    readmes = sorted(p for p in package.iterdir()
                     if p.is_file() and p.name.lower().startswith('readme'))
    if not readmes:
        return False, _section('a README (README.md) in the package folder with usage instructions',
                               'no README file in ' + package.name + '/',
                               'add README.md saying how to build (`colcon build`), source '
                               '(`source install/setup.bash`) and launch '
                               '(`ros2 launch <package> <launch file>`) your system')
    text = readmes[0].read_text(errors='replace')[:100_000].lower()
    patterns = {'build': r'colcon\s+build|robot-lab\s+build',
                'launch': r'ros2\s+launch|robot-lab\s+launch'}
    missing = [what for what in require if not re.search(patterns.get(what, re.escape(what)), text)]
    if missing:
        names = {'build': '`colcon build`', 'launch': '`ros2 launch ...`'}
        return False, _section('the README gives the build and the launch command',
                               f'{readmes[0].name} does not mention: '
                               + ', '.join(names.get(m, m) for m in missing),
                               'add the commands as a user types them, e.g. `colcon build '
                               '--packages-select <pkg>` and `ros2 launch <pkg> <file>`')
    return True, _section('a README with build and launch instructions',
                          f'{readmes[0].name} gives both')


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


def _count_params(data: dict[str, dict[str, Any]]) -> int:
    return sum(len(params) for params in data.values())


def _params_file_check(state: JobState) -> None:
    from robot_lab.errors import ParamFileError
    from robot_lab.params import load_param_file

    check = state.rubric.check('params_file')
    minimum = int(check.option('min_parameters', 3)) if check else 3
    assert state.package is not None
    files = state.param_files
    if not files:
        _outcome(state, 'params_file', False, _section(
            f'a parameter file (e.g. config/params.yaml) with at least {minimum} parameters',
            'no .yaml file in the package besides launch files',
            'add config/params.yaml in the ros__parameters layout '
            '(`node_name:` / `  ros__parameters:` / `    name: value`) and install it '
            "with data_files in setup.py: ('share/' + package_name + '/config', "
            "glob('config/*.yaml'))"))
        return
    notes, best = [], 0
    for path in files:
        rel = path.relative_to(state.package)
        try:
            count = _count_params(load_param_file(path))
        except ParamFileError as err:
            notes.append(f'{rel}: {err}')
            continue
        notes.append(f'{rel}: {count} parameter(s)')
        best = max(best, count)
    passed = best >= minimum
    fix = '' if passed else (
        'rcl accepts only `node_name:` / `  ros__parameters:` / `    name: value`; '
        'fix the line named above' if best == 0 and any(':' in n and 'parameter(s)' not in n
                                                         for n in notes)
        else f'give the nodes at least {minimum} parameters in the file')
    _outcome(state, 'params_file', passed, _section(
        f'a parameter file valid under rcl rules with at least {minimum} parameters',
        '\n\n'.join(f'`{n}`' if 'parameter(s)' in n else n for n in notes), fix))


def launch_files_of(package: Path) -> list[Path]:
    folder = package / 'launch'
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.rglob('*') if p.is_file() and p.name.endswith(_LAUNCH_SUFFIXES)
                  and '__pycache__' not in p.parts)


def _write(job_dir: Path, state: JobState, student: str, status: str = 'graded',
           error: str = '', started: float = 0.0) -> None:
    # Paths as the student knows them: src/<pkg>/..., install/<pkg>/..., not the job's.
    prefix = f'{job_dir.resolve()}/ws/'
    for outcome in state.outcomes.values():
        outcome.output = outcome.output.replace(prefix, '').replace(f'{job_dir}/ws/', '')
    checks = [state.outcomes.get(c.id) or CheckOutcome(
        c.id, c.name, 0.0, c.points, 'Not reached: the grading job ended before this check.')
        for c in state.rubric.checks]
    report = StudentReport(student, checks, status, error, list(state.images),
                           state.rubric.lab, time.monotonic() - started)
    tmp = job_dir / 'report.json.tmp'
    tmp.write_text(json.dumps(report.to_dict()))
    tmp.replace(job_dir / 'report.json')


def _build_check(state: JobState, ws: Path) -> None:
    from robot_lab.pkg.build import build

    result = build(ws, progress=False)
    state.built = result.ok
    if result.ok:
        _outcome(state, 'builds', True, _section(
            '`colcon build` finishes without errors',
            f'built {", ".join(result.finished)} in {result.duration:.1f} s'))
        return
    lines = result.report_lines() or result.output[-_LINES:]
    state.build_lines = lines
    _outcome(state, 'builds', False, _section(
        '`colcon build` finishes without errors',
        'the build failed; colcon says:' + _code(lines, 20),
        'fix the file and line named above, then run `colcon build` yourself before handing in'))


def run_job(job_dir: Path) -> int:
    from robot_lab.grading import live

    job = json.loads((job_dir / 'job.json').read_text())
    rubric = load_rubric(job['rubric'])
    student = str(job['student'])
    state = JobState(rubric)
    started = time.monotonic()
    ws = job_dir / 'ws'
    try:
        unpacked = copy_submission(Submission(student, Path(job['source'])), job_dir / 'submission')
        package = find_package(unpacked)
    except RobotLabError as err:
        for check in rubric.checks:
            _outcome(state, check.id, False, _section('a ROS 2 package', str(err),
                                                      err.fix or ''))
        _write(job_dir, state, student, started=started)
        return 0
    import shutil

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
    state.package = target
    state.package_name = target.name
    state.param_files = param_files_of(target)
    state.launch_files = launch_files_of(target)
    require = rubric.check('readme')
    passed, text = readme_outcome(target, list(require.option('require', ['build', 'launch'])
                                               if require else []))
    _outcome(state, 'readme', passed, text)
    _params_file_check(state)
    _write(job_dir, state, student, started=started)
    _stage('static checks', started)
    _build_check(state, ws)
    _write(job_dir, state, student, started=started)
    _stage('build', started)
    live.run_live_checks(job_dir, ws, state, _outcome, _section, _code)
    _write(job_dir, state, student, started=started)
    _stage('launch, watch, stop', started)
    return 0


def _stage(what: str, started: float) -> None:
    print(f'[{time.monotonic() - started:6.2f} s] {what} done', flush=True)


def _package_name(package: Path) -> str:
    match = re.search(r'<name>\s*([^<\s]+)\s*</name>', (package / 'package.xml').read_text(
        errors='replace'))
    return match.group(1) if match else package.name


def main(argv: list[str] | None = None) -> int:
    from robot_lab.grading.sandbox import enter

    args = sys.argv[1:] if argv is None else argv
    job_dir = Path(args[0])
    job = json.loads((job_dir / 'job.json').read_text())
    enter(load_rubric(job['rubric']).limits, bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')))
    return run_job(job_dir)

if __name__ == '__main__':
    sys.exit(main())
