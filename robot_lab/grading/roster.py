"""The LMS's gradebook file, filled in: `--roster FILE` (Moodle or Canvas), ready to import.

- Moodle: the assignment's *grading worksheet* ("Download grading worksheet"; columns
  `Identifier` = `Participant N`, `Full name`, ..., `Grade`, `Maximum grade`, `Grade can be
  changed`, `Last modified (submission)`, ..., `Feedback comments`). Its participant number
  is the one in the "Download all submissions" folder names (`Jane Doe_N_assignsubmission_
  file_`). We fill `Grade` (scaled to its maximum) and `Feedback comments`; import it with
  "Upload grading worksheet". `Last modified (submission)` gives late hand-ins their time.
- Canvas: the gradebook export ("Export Entire Gradebook"; `Student`, `ID`, `SIS User ID`,
  `SIS Login ID`, `Section`, one column per assignment `Name (id)`, a `Points Possible` row).
  Its `ID` is the user id in "Download Submissions" file names (`login_[LATE_]ID_sub_file`).
  We fill the assignment's column (scaled to its points); import it with "Import".

Everything else in the file is written back as it was. Students found on one side only
(no hand-in, or no row) are listed, never guessed.
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

from robot_lab.errors import RobotLabError
from robot_lab.grading.late import Submitted
from robot_lab.grading.report import StudentReport, number

__all__ = ['Roster', 'RosterResult', 'read_roster']

_PARTICIPANT = re.compile(r'Participant\s+(\d+)', re.IGNORECASE)
_MOODLE_ENTRY = re.compile(r'_(\d+)$')
_CANVAS_ENTRY = re.compile(r'^(?P<login>[^_]+)_(?P<late>LATE_)?(?P<user>\d+)_\d+_.+$')
_CANVAS_FIXED = {'student', 'id', 'sis user id', 'sis login id', 'integration id',
                 'root account', 'section', 'student number'}
_CANVAS_ASSIGNMENT = re.compile(r'^.+\(\d+\)$')
_MOODLE_TIMES = ('%A, %d %B %Y, %I:%M %p', '%A, %B %d, %Y, %I:%M %p', '%A, %d %B %Y, %H:%M',
                 '%d %B %Y, %I:%M %p', '%d %B %Y, %H:%M', '%Y-%m-%d %H:%M:%S', '%Y-%m-%d %H:%M')


@dataclass
class RosterResult:
    """What was written back, and who could not be matched."""

    path: Path
    filled: int
    only_roster: list[str] = field(default_factory=list)  # a row, no hand-in graded
    only_graded: list[str] = field(default_factory=list)  # graded, no row in the file
    locked: list[str] = field(default_factory=list)  # Moodle: "Grade can be changed: No"

    def lines(self) -> list[str]:
        out = [f'wrote {self.path}: {self.filled} grade(s) filled, ready to import']
        if self.only_graded:
            out.append(f'graded but not in the roster ({len(self.only_graded)}): '
                       + ', '.join(self.only_graded))
        if self.only_roster:
            out.append(f'in the roster but not graded ({len(self.only_roster)}): '
                       + ', '.join(self.only_roster))
        if self.locked:
            out.append(f'grade locked in Moodle, left as it was: {", ".join(self.locked)}')
        return out


def _fail(path: Path, message: str, fix: str) -> RobotLabError:
    return RobotLabError(message, file=path, fix=fix)


@dataclass
class Roster:
    """One LMS file: `kind` 'moodle' or 'canvas', its rows as read (header first)."""

    path: Path
    kind: str
    rows: list[list[str]]
    bom: bool
    column: int = -1  # the grade column
    first: int = 1  # index of the first student row

    @property
    def header(self) -> list[str]:
        return self.rows[0]

    def col(self, *names: str) -> int:
        lowered = [h.strip().lower() for h in self.header]
        for name in names:
            if name.lower() in lowered:
                return lowered.index(name.lower())
        return -1

    def students(self) -> list[list[str]]:
        return self.rows[self.first:]

    def label(self, row: list[str]) -> str:
        name = row[self.col('Full name', 'Student')]
        key = row[self.col('Identifier', 'ID')]
        return f'{name} ({key})'

    # -- matching ------------------------------------------------------------------------
    def match(self, sources: Mapping[str, str]) -> dict[str, list[str]]:
        """Student id -> their row, by the LMS's own number in the hand-in's name."""
        by_key: dict[str, list[str]] = {}
        key_col = self.col('Identifier') if self.kind == 'moodle' else self.col('ID')
        for row in self.students():
            value = row[key_col] if key_col < len(row) else ''
            found = _PARTICIPANT.search(value) if self.kind == 'moodle' else None
            key = found.group(1) if found else value.strip()
            if key:
                by_key[key] = row
        matched = {}
        for student, source in sources.items():
            key = _entry_key(self.kind, student, source)
            if key is not None and key in by_key:
                matched[student] = by_key[key]
        return matched

    def times(self, sources: Mapping[str, str]) -> dict[str, Submitted]:
        """Moodle: each matched student's `Last modified (submission)`."""
        if self.kind != 'moodle':
            return {}
        when = self.col('Last modified (submission)')
        if when < 0:
            return {}
        return {student: Submitted(at=_moodle_time(row[when]))
                for student, row in self.match(sources).items()}

    # -- writing back --------------------------------------------------------------------
    def fill(self, reports: Sequence[StudentReport], sources: Mapping[str, str],
             out: Path) -> RosterResult:
        matched = self.match(sources)
        result = RosterResult(out, 0)
        result.only_graded = sorted(r.student for r in reports if r.student not in matched)
        graded_rows = {id(row) for row in matched.values()}
        result.only_roster = [self.label(row) for row in self.students()
                              if id(row) not in graded_rows and any(c.strip() for c in row)]
        maximum = self._maximum()
        changeable = self.col('Grade can be changed')
        feedback = self.col('Feedback comments')
        for report in reports:
            row = matched.get(report.student)
            if row is None:
                continue
            while len(row) < len(self.header):
                row.append('')
            if self.kind == 'moodle' and changeable >= 0 and row[changeable].strip() == 'No':
                result.locked.append(report.student)
                continue
            top = maximum(row)
            scaled = report.score / report.max_score * top if report.max_score else 0.0
            row[self.column] = f'{scaled:.2f}'
            if self.kind == 'moodle' and feedback >= 0:
                row[feedback] = comment(report)
            result.filled += 1
        text = io.StringIO()
        csv.writer(text, lineterminator='\r\n' if self.kind == 'canvas' else '\n').writerows(
            self.rows)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text.getvalue(), encoding='utf-8-sig' if self.bom else 'utf-8')
        return result

    def _maximum(self) -> _Maximum:
        if self.kind == 'moodle':
            return _Maximum(self.col('Maximum grade'), None)
        points = next((r for r in self.rows[1:self.first]
                       if r and r[0].strip() == 'Points Possible'), None)
        value = _number(points[self.column]) if points and self.column < len(points) else None
        return _Maximum(-1, value)


@dataclass(frozen=True)
class _Maximum:
    column: int
    fixed: float | None

    def __call__(self, row: list[str]) -> float:
        if self.fixed is not None:
            return self.fixed
        if 0 <= self.column < len(row):
            value = _number(row[self.column])
            if value is not None:
                return value
        return 100.0


def _number(text: str) -> float | None:
    try:
        return float(text.replace(',', '.').strip())
    except ValueError:
        return None


def _entry_key(kind: str, student: str, source: str) -> str | None:
    if kind == 'moodle':
        found = _MOODLE_ENTRY.search(student)
        return found.group(1) if found else None
    found = _CANVAS_ENTRY.match(source)
    return found['user'] if found else None


def canvas_late(source: str) -> bool:
    """Canvas marks a late hand-in in the downloaded file's name."""
    found = _CANVAS_ENTRY.match(source)
    return bool(found and found['late'])


def _moodle_time(text: str) -> datetime | None:
    text = ' '.join(text.split())
    if not text or text == '-':
        return None
    for fmt in _MOODLE_TIMES:
        try:
            return datetime.strptime(text, fmt)
        except ValueError:
            continue
    return None


def comment(report: StudentReport) -> str:
    """A short feedback comment for the LMS: the score and what to look at."""
    missed = [c.id for c in report.checks if not c.passed]
    parts = [f'{number(report.score)}/{number(report.max_score)}.']
    if not missed:
        parts.append('All checks passed.')
    elif len(missed) == len(report.checks) and report.score == 0:
        parts.append('No check met (nothing could be graded: the feedback file says why).')
    else:
        parts.append(f'Not met: {", ".join(missed)}.')
    if report.late_days:
        parts.append(f'Late {report.late_days} day(s): -{number(report.penalty)}.')
    if report.status != 'graded':
        parts.append(f'Grading ended early ({report.status}).')
    parts.append('Details in the feedback file.')
    return ' '.join(parts)


def read_roster(path: str | Path, assignment: str | None = None, lab: str = '') -> Roster:
    """Read a Moodle grading worksheet or a Canvas gradebook export; find its grade column."""
    file = Path(path)
    try:
        raw = file.read_bytes()
    except OSError as err:
        raise _fail(file, f'cannot read the roster: {err.strerror}',
                    'give the CSV downloaded from Moodle or Canvas') from None
    bom = raw.startswith(b'\xef\xbb\xbf')
    rows = [r for r in csv.reader(io.StringIO(raw.decode('utf-8-sig', errors='replace')))]
    if not rows:
        raise _fail(file, 'the roster is empty', 'download it again from the LMS')
    header = [h.strip().lower() for h in rows[0]]
    if 'identifier' in header and 'grade' in header:
        roster = Roster(file, 'moodle', rows, bom)
        roster.column = roster.col('Grade')
        return roster
    if 'student' in header and 'id' in header:
        roster = Roster(file, 'canvas', rows, bom)
        roster.first = 1
        while (roster.first < len(rows) and rows[roster.first]
               and not rows[roster.first][1].strip()):
            roster.first += 1  # "Points Possible" (and Canvas's posting-policy rows)
        roster.column = _canvas_column(file, rows[0], assignment, lab)
        return roster
    raise _fail(file, 'not a Moodle grading worksheet nor a Canvas gradebook export',
                "Moodle: the assignment's 'Download grading worksheet'; Canvas: Grades > "
                'Export > Export Entire Gradebook')


def _canvas_column(file: Path, header: list[str], assignment: str | None, lab: str) -> int:
    columns = [(i, h) for i, h in enumerate(header)
               if h.strip().lower() not in _CANVAS_FIXED and _CANVAS_ASSIGNMENT.match(h.strip())]
    if assignment:
        chosen = [(i, h) for i, h in columns if h.strip() == assignment
                  or h.strip().rsplit(' (', 1)[0] == assignment]
    elif len(columns) == 1:
        chosen = columns
    else:
        key = lab.lower().replace('-', ' ')
        chosen = [(i, h) for i, h in columns if key and key in h.lower().replace('-', ' ')]
    if len(chosen) != 1:
        names = '; '.join(h for _i, h in columns) or 'none'
        raise _fail(file, f'which assignment column to fill? ({names})',
                    "name it: --roster-column 'Lab 1 (1234)'")
    return chosen[0][0]
