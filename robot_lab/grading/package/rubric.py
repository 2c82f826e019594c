"""Rubrics: which checks a lab has, their points and thresholds, from a YAML file.

The kit ships one per lab (`robot_lab/grading/package/rubrics/<lab>.yaml`); an instructor copies
one, changes points or thresholds, and passes `--rubric FILE`. Check ids are the ones the
checks register (robot_lab.grading.package.registry: they name the behaviour measured); a
rubric may drop a check or give it 0 points.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robot_lab.errors import RobotLabError
from robot_lab.grading.package.registry import registered_checks

__all__ = ['Limits', 'Rubric', 'RubricCheck', 'load_rubric', 'rubric_path']

_DIR = Path(__file__).with_name('rubrics')


@dataclass(frozen=True)
class RubricCheck:
    id: str
    name: str
    points: float
    options: dict[str, Any] = field(default_factory=dict)

    def option(self, key: str, default: Any) -> Any:
        return self.options.get(key, default)


@dataclass(frozen=True)
class Limits:
    """What one submission's job may use (see robot_lab.grading.package.sandbox)."""

    wall_seconds: float = 300.0
    cpu_seconds: int = 120
    memory_mb: int = 1500
    # Every process of the job together, when a root grader can make a memory cgroup
    # (robot_lab.grading.package.cgroups): the reference Chapter 6 job peaked at 160 MB.
    job_memory_mb: int = 4096
    processes: int = 256
    file_mb: int = 256
    output_kb: int = 64


@dataclass(frozen=True)
class Rubric:
    lab: str
    title: str
    checks: list[RubricCheck]
    observe_seconds: float = 4.0
    startup_seconds: float = 12.0
    limits: Limits = Limits()
    source: Path | None = None

    def check(self, check_id: str) -> RubricCheck | None:
        return next((c for c in self.checks if c.id == check_id), None)

    @property
    def ids(self) -> list[str]:
        return [c.id for c in self.checks]


def rubric_path(lab: str) -> Path:
    """The shipped rubric of `lab`, or an error listing the labs there are."""
    path = _DIR / f'{lab}.yaml'
    if not path.is_file():
        labs = ', '.join(sorted(p.stem for p in _DIR.glob('*.yaml')))
        raise RobotLabError(f'no rubric for lab {lab!r}', fix=f'use --lab with one of: {labs}')
    return path


def _fail(path: Path, message: str, fix: str, line: int | None = None) -> RobotLabError:
    return RobotLabError(message, file=path, line=line, fix=fix)


def _entry_lines(text: str) -> list[dict[str, int]]:
    """Per entry of `checks:`, the line of each of its keys and ('') of the entry itself."""
    try:
        root = yaml.compose(text)
    except yaml.YAMLError:
        return []
    if not isinstance(root, yaml.MappingNode):
        return []
    for key, value in root.value:
        if key.value == 'checks' and isinstance(value, yaml.SequenceNode):
            return [{'': item.start_mark.line + 1,
                     **({str(k.value): k.start_mark.line + 1 for k, _ in item.value}
                        if isinstance(item, yaml.MappingNode) else {})}
                    for item in value.value]
    return []


def _limit_lines(text: str) -> dict[str, int]:
    """The line of each key of `limits:`."""
    try:
        root = yaml.compose(text)
    except yaml.YAMLError:
        return {}
    if isinstance(root, yaml.MappingNode):
        for key, value in root.value:
            if key.value == 'limits' and isinstance(value, yaml.MappingNode):
                return {str(k.value): k.start_mark.line + 1 for k, _ in value.value}
    return {}


def load_rubric(path: str | Path) -> Rubric:
    """Read and validate a rubric file; errors name the file and the fix."""
    file = Path(path)
    try:
        text = file.read_text()
        data = yaml.safe_load(text)
    except OSError as err:
        raise _fail(file, f'cannot read the rubric: {err.strerror}',
                    'give the path of a rubric YAML file') from None
    except yaml.YAMLError as err:
        mark = getattr(err, 'problem_mark', None)
        line = f' (line {mark.line + 1})' if mark is not None else ''
        raise _fail(file, f'not valid YAML{line}: {getattr(err, "problem", err)}',
                    'fix the YAML syntax (compare with the shipped rubric)') from None
    if not isinstance(data, dict) or not isinstance(data.get('checks'), list):
        raise _fail(file, 'a rubric is a mapping with a `checks:` list',
                    'copy a shipped rubric (robot_lab/grading/package/rubrics/) and edit it')
    checks = []
    registered = registered_checks()
    known = sorted(registered)
    lines = _entry_lines(text)
    for index, item in enumerate(data['checks']):
        where = lines[index] if index < len(lines) else {}
        at = where.get('')
        if not isinstance(item, dict) or item.get('id') not in known:
            got = item.get('id') if isinstance(item, dict) else item
            raise _fail(file, f'unknown check {got!r}', f'use one of: {", ".join(known)}', at)
        points = item.get('points', 1)
        if not isinstance(points, int | float) or points < 0:
            raise _fail(file, f'check {item["id"]}: points must be a number >= 0',
                        'write e.g. `points: 2`', where.get('points', at))
        options = {k: v for k, v in item.items() if k not in ('id', 'name', 'points')}
        validate = registered[item['id']].validate
        problem = validate(options) if validate is not None else None
        if problem is not None:
            key, what, fix = problem
            raise _fail(file, f'check {item["id"]}: {what}', fix, where.get(key, at))
        checks.append(RubricCheck(item['id'], str(item.get('name', item['id'])),
                                  float(points), options))
    raw_limits = data.get('limits') or {}
    if not isinstance(raw_limits, dict):
        raise _fail(file, '`limits:` is a mapping of limit: value',
                    'write e.g. `limits:` then `  job_memory_mb: 4096` on the next line')
    unknown = set(raw_limits) - set(Limits.__dataclass_fields__)
    if unknown:
        raise _fail(file, f'unknown limits: {", ".join(sorted(unknown))}',
                    f'use: {", ".join(Limits.__dataclass_fields__)}')
    limit_lines, defaults = _limit_lines(text), Limits()
    for key, value in raw_limits.items():
        whole = isinstance(getattr(defaults, key), int)  # its default says which kind
        if isinstance(value, bool) or not isinstance(value, int if whole else int | float) \
                or value <= 0:
            kind = 'a whole number' if whole else 'a number'
            raise _fail(file, f'limits: {key} must be {kind} > 0, not {value!r}',
                        f'write e.g. `{key}: {getattr(defaults, key):g}`', limit_lines.get(key))
    return Rubric(lab=str(data.get('lab', file.stem)), title=str(data.get('title', '')),
                  checks=checks, observe_seconds=float(data.get('observe_seconds', 4.0)),
                  startup_seconds=float(data.get('startup_seconds', 12.0)),
                  limits=Limits(**raw_limits), source=file)
