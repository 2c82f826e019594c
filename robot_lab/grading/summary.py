"""`OUT/summary.html`: the class at a glance, for the instructor (one self-contained page).

The score distribution (a histogram, embedded as a data URI), the pass rate of each check
(where the class struggled), who scored 0, who was not fully graded and why, where the
grader itself failed (points kept; the `--only` that regrades them), who handed in late,
and the slowest jobs (what to look at when a run takes long).
"""

from __future__ import annotations

import base64
import html
import io
import statistics
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path

from robot_lab.grading.report import StudentReport, grader_errors, number

__all__ = ['write_summary']

SLOWEST = 5


def _histogram(scores: Sequence[float], maximum: float) -> str:
    """The score distribution as a PNG data URI (matplotlib, no GUI backend)."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    figure = Figure(figsize=(6, 2.6), dpi=100)
    axes = figure.add_subplot()
    top = max(maximum, max(scores, default=0.0), 1.0)
    bins = [x - 0.5 for x in range(int(top) + 2)] if top <= 40 else 20
    axes.hist(scores, bins=bins, color='#4c78a8', edgecolor='white')
    axes.set_xlabel(f'score (out of {number(maximum)})')
    axes.set_ylabel('students')
    axes.yaxis.set_major_locator(MaxNLocator(integer=True))
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format='png')
    return 'data:image/png;base64,' + base64.b64encode(buffer.getvalue()).decode()


def _table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    cells = ''.join(f'<th>{html.escape(h)}</th>' for h in head)
    body = ''.join('<tr>' + ''.join(f'<td>{html.escape(c)}</td>' for c in row) + '</tr>'
                   for row in rows)
    return f'<table><tr>{cells}</tr>{body}</table>'


def _people(title: str, anchor: str, rows: Sequence[Sequence[str]], head: Sequence[str],
            none: str) -> str:
    content = _table(head, rows) if rows else f'<p>{html.escape(none)}</p>'
    return f'<h2 id="{anchor}">{html.escape(title)} ({len(rows)})</h2>{content}'


def _grader_errors(reports: Sequence[StudentReport]) -> str:
    """Where the grader failed: the checks (their points kept) and why, then the regrade."""
    faults = grader_errors(reports)
    by_student = {r.student: r for r in reports}
    rows = []
    for student, checks in faults:
        report = by_student[student]
        why = '; '.join(f'{c.id}: {c.grader_error}' for c in report.checks
                        if c.grader_error) or report.error
        rows.append([student, ', '.join(checks) or '(the job)', why])
    section = _people('Grader errors (points kept)', 'grader-errors', rows,
                      ['student', 'checks', 'what failed'], 'None: the grader never failed.')
    if faults:
        section += ('<p>Regrade them once the cause is fixed (or the host is quieter): '
                    f'<code>robot-lab grade … -o OUT --only '
                    f'{html.escape(",".join(s for s, _ in faults))}</code></p>')
    return section


def write_summary(path: Path, reports: Sequence[StudentReport], title: str = '',
                  not_handed_in: Sequence[str] = ()) -> Path:
    """Write the class summary for `reports` (everyone in OUT, not only this run's)."""
    scores = [r.score for r in reports]
    maximum = max((r.max_score for r in reports), default=0.0)
    graded = [r for r in reports if r.status == 'graded']
    checks: dict[str, tuple[str, list[float], float]] = {}
    for r in reports:
        for c in r.checks:
            share = c.score / c.max_score if c.max_score else 1.0
            checks.setdefault(c.id, (c.name, [], c.max_score))[1].append(share)
    pass_rows = [[cid, name, f'{sum(1 for e in earned if e >= 1.0)}/{len(earned)}',
                  f'{sum(1 for e in earned if e >= 1.0) / len(earned):.0%}',
                  f'{statistics.fmean(earned) * top:.1f}/{number(top)}']
                 for cid, (name, earned, top) in checks.items()]
    zero = [[r.student, r.status] for r in sorted(reports, key=lambda r: r.student)
            if r.score == 0]
    short = [[r.student, r.status, r.error] for r in sorted(reports, key=lambda r: r.student)
             if r.status != 'graded']
    late = [[r.student, r.submitted or 'marked late by the LMS', str(r.late_days),
             number(r.penalty)] for r in sorted(reports, key=lambda r: r.student)
            if r.late_days]
    slowest = [[r.student, f'{r.elapsed:.1f} s', r.status]
               for r in sorted(reports, key=lambda r: -r.elapsed)[:SLOWEST]]
    stats = (f'{len(reports)} student(s), {len(graded)} fully graded; score median '
             f'{number(statistics.median(scores))}/{number(maximum)}, mean '
             f'{statistics.fmean(scores):.1f}' if reports else 'No student graded yet')
    parts = [
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8">',
        f'<title>Class summary {html.escape(title)}</title><style>'
        'body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.4}'
        'table{border-collapse:collapse;margin:.5em 0}'
        'td,th{border:1px solid #ccc;padding:.2em .6em;text-align:left}'
        'img{max-width:100%}</style></head><body>',
        f'<h1>Class summary{": " + html.escape(title) if title else ""}</h1>',
        f'<p class="stats">{html.escape(stats)}. Written {datetime.now():%Y-%m-%d %H:%M}.</p>',
    ]
    if reports:
        parts.append(f'<h2 id="distribution">Score distribution</h2><img alt="histogram of '
                     f'scores" src="{_histogram(scores, maximum)}">')
        parts.append('<h2 id="checks">Pass rate per check</h2>'
                     + _table(['check', 'name', 'passed', 'rate', 'mean points'], pass_rows))
    parts.append(_people('Scored 0', 'zero', zero, ['student', 'status'], 'Nobody.'))
    parts.append(_people('Not fully graded', 'not-graded', short,
                         ['student', 'status', 'why'], 'Everyone was fully graded.'))
    parts.append(_grader_errors(reports))
    if not_handed_in:
        parts.append(_people('In the roster, no hand-in', 'missing',
                             [[s] for s in not_handed_in], ['student'], ''))
    parts.append(_people('Late', 'late', late, ['student', 'submitted', 'days', 'penalty'],
                         'Nobody handed in late (or no --due given).'))
    parts.append('<h2 id="slowest">Slowest jobs</h2>'
                 + _table(['student', 'time', 'status'], slowest))
    parts.append('</body></html>\n')
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text('\n'.join(parts))
    return path
