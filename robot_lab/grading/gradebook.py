"""A class's grading kept in OUT, so an instructor can come back to it.

`OUT/gradebook.json` records every student's report. With it a run can regrade a few
students (`--only`: their rows replaced, everyone else's untouched), tell whose scores
changed since the last run (after a rubric change), and rebuild grades.csv, summary.html and
the LMS roster from the whole class without grading anyone again.
"""

from __future__ import annotations

import json
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.errors import RobotLabError
from robot_lab.grading.late import LatePolicy, Submitted
from robot_lab.grading.report import StudentReport, number, write_outputs
from robot_lab.grading.roster import RosterResult, canvas_late, read_roster
from robot_lab.grading.summary import write_summary

__all__ = ['ClassOutputs', 'ScoreChange', 'load_record', 'write_class']

RECORD = 'gradebook.json'


@dataclass(frozen=True)
class ScoreChange:
    student: str
    before: str  # '13/13'
    after: str

    def __str__(self) -> str:
        return f'{self.student} {self.before} → {self.after}'


@dataclass
class ClassOutputs:
    """What a run wrote to OUT and what it found."""

    everyone: list[StudentReport]
    changes: list[ScoreChange] = field(default_factory=list)
    roster: RosterResult | None = None
    previous: int = 0  # students in the record before this run


def load_record(out: Path) -> list[StudentReport]:
    """The reports of the last run(s) in OUT (none: an empty list)."""
    path = out / RECORD
    if not path.is_file():
        return []
    try:
        data = json.loads(path.read_text())
        return [StudentReport.from_dict(d) for d in data['students']]
    except (ValueError, KeyError, TypeError) as err:
        raise RobotLabError(f'cannot read the class record: {err}', file=path,
                            fix='grade the whole class again into a new OUT folder') from None


def _score(report: StudentReport) -> str:
    return f'{number(report.score)}/{number(report.max_score)}'


def score_changes(before: Sequence[StudentReport],
                  after: Sequence[StudentReport]) -> list[ScoreChange]:
    """Students graded both times whose score (or its maximum) changed."""
    old = {r.student: r for r in before}
    return [ScoreChange(r.student, _score(old[r.student]), _score(r))
            for r in sorted(after, key=lambda r: r.student)
            if r.student in old and _score(old[r.student]) != _score(r)]


def write_class(out: Path, graded: Sequence[StudentReport], columns: Sequence[str], *,
                only: Collection[str] | None = None, sources: Mapping[str, str] | None = None,
                late: LatePolicy | None = None, roster: str | Path | None = None,
                roster_column: str | None = None, title: str = '',
                ascii_names: bool = False) -> ClassOutputs:
    """Merge this run's reports into OUT and write the class's files.

    `only`: this run regraded these students; everyone else keeps their row and feedback.
    `sources`: student -> the name of what they handed in (the LMS's file/folder name).
    """
    sources = dict(sources or {})
    table = read_roster(roster, roster_column, title) if roster is not None else None
    if late is not None:
        times: dict[str, Submitted] = {s: Submitted(late_mark=canvas_late(name))
                                       for s, name in sources.items()}
        if table is not None:
            times.update(table.times(sources))
        late.apply(graded, times)
    previous = load_record(out)
    if only is None:
        everyone = list(graded)
    else:
        regraded = {r.student for r in graded}
        everyone = [r for r in previous if r.student not in regraded] + list(graded)
        known = {s: n for s, n in _sources(out).items() if s not in regraded}
        sources = {**known, **sources}
    everyone.sort(key=lambda r: r.student)
    result = ClassOutputs(everyone, score_changes(previous, everyone), previous=len(previous))
    write_outputs(out, everyone, columns=columns, ascii_names=ascii_names,
                  only=None if only is None else {r.student for r in graded})
    for r in everyone:
        r.images = []  # copied into feedback/ already; the record keeps no temp paths
    (out / RECORD).write_text(json.dumps(
        {'title': title, 'columns': list(columns), 'sources': sources,
         'students': [r.to_dict() for r in everyone]}, indent=1, ensure_ascii=False) + '\n')
    missing: list[str] = []
    if table is not None:
        result.roster = table.fill(everyone, sources, out / f'{table.kind}-grades.csv')
        missing = result.roster.only_roster
    write_summary(out / 'summary.html', everyone, title, not_handed_in=missing)
    return result


def _sources(out: Path) -> dict[str, str]:
    try:
        data = json.loads((out / RECORD).read_text())
        return {str(k): str(v) for k, v in data.get('sources', {}).items()}
    except (OSError, ValueError, AttributeError):
        return {}
