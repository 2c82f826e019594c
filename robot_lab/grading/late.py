"""Late hand-ins: `--due` and a penalty per day, from the LMS's own submission time.

The time comes from the LMS, never from a file's date on the instructor's disk: Moodle's
grading worksheet has it (`Last modified (submission)`); Canvas's "Download Submissions"
marks a late file `_LATE_` in its name but gives no time, so such a hand-in counts one day
late. A day late is any part of 24 hours after the due time (rounded up, as LMSs count).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta

from robot_lab.errors import RobotLabError
from robot_lab.grading.report import StudentReport

__all__ = ['LatePolicy', 'Submitted', 'parse_due']


@dataclass(frozen=True)
class Submitted:
    """What the LMS says about one hand-in's time."""

    at: datetime | None = None  # when (naive local time, as the LMS shows it)
    late_mark: bool = False  # the LMS marked it late without a time (Canvas)


@dataclass(frozen=True)
class LatePolicy:
    """`due`: the deadline (None: only the LMS's marks count); `per_day`: the share of the
    maximum taken off per day late; `max_days`: days after which the penalty stops growing."""

    due: datetime | None
    per_day: float = 0.1
    max_days: int = 10

    def days_late(self, submitted: Submitted) -> int:
        if submitted.at is not None and self.due is not None:
            late = submitted.at - self.due
            if late <= timedelta(0):
                return 0
            return math.ceil(late / timedelta(days=1))
        return 1 if submitted.late_mark else 0

    def apply(self, reports: Sequence[StudentReport], times: Mapping[str, Submitted]) -> None:
        """Set each report's submission time, days late and penalty (points)."""
        for report in reports:
            submitted = times.get(report.student, Submitted())
            if submitted.at is not None:
                report.submitted = submitted.at.isoformat(sep=' ', timespec='minutes')
            days = self.days_late(submitted)
            report.late_days = days
            report.penalty = round(min(days, self.max_days) * self.per_day
                                   * report.max_score, 2)


_FORMATS = ('%Y-%m-%d %H:%M', '%Y-%m-%dT%H:%M', '%Y-%m-%d %H:%M:%S', '%Y-%m-%dT%H:%M:%S',
            '%Y-%m-%d')


def parse_due(text: str) -> datetime:
    """`2026-11-20 23:59` (local time, as the LMS shows times); a date alone means its end."""
    for fmt in _FORMATS:
        try:
            when = datetime.strptime(text.strip(), fmt)
        except ValueError:
            continue
        return when.replace(hour=23, minute=59) if fmt == '%Y-%m-%d' else when
    raise RobotLabError(f'--due {text!r} is not a date and time',
                        fix="write it as 'YYYY-MM-DD HH:MM', e.g. --due '2026-11-20 23:59'")
